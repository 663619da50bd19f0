"""The largest fixed step that resolves the train (cam_fmu/engine/train_step.py) against closed forms and
against the methods run step by step on the train's free ringing (independent of the stability polynomials)."""
from __future__ import annotations

import math

import pytest

from cam_fmu.engine.train_step import check_step, largest_step

K, M = 4.0e5, 0.1  # N/m, kg: omega_n = 2000 rad/s


def _step(solver: str, f, y: tuple[float, float], h: float) -> tuple[float, float]:
    """One step of explicit Euler or classical RK4 on y' = f(y), written out."""
    if solver == "euler":
        d = f(y)
        return y[0] + h * d[0], y[1] + h * d[1]
    k1 = f(y)
    k2 = f((y[0] + h / 2 * k1[0], y[1] + h / 2 * k1[1]))
    k3 = f((y[0] + h / 2 * k2[0], y[1] + h / 2 * k2[1]))
    k4 = f((y[0] + h * k3[0], y[1] + h * k3[1]))
    return (y[0] + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]),
            y[1] + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]))


def _ringing_error(solver: str, d: float, steps: int) -> float:
    """Error over one natural period, in ``steps`` steps, of the free ringing from x = 1 against its closed form,
    as sqrt(x error^2 + (v error / omega_d)^2) relative to the envelope (undamped: the mode's own error)."""
    wn = math.sqrt(K / M)
    zeta = d / (2 * math.sqrt(K * M))
    wd = wn * math.sqrt(1 - zeta ** 2)
    f = lambda y: (y[1], -(K * y[0] + d * y[1]) / M)  # noqa: E731
    period = 2 * math.pi / wn
    h = period / steps
    y = (1.0, 0.0)
    for _ in range(steps):
        y = _step(solver, f, y, h)
    t = period
    env = math.exp(-zeta * wn * t)
    x = env * (math.cos(wd * t) + zeta * wn / wd * math.sin(wd * t))
    v = -env * wn ** 2 / wd * math.sin(wd * t)
    return math.hypot(y[0] - x, (y[1] - v) / wd) / env


@pytest.mark.parametrize("solver", ["euler", "rk4"])
@pytest.mark.parametrize("d", [0.0, 20.0])  # zeta 0 and 0.05
def test_step_limit_against_the_method_run_step_by_step(solver, d):
    tol = 1e-3
    h = largest_step(solver, K, d, M, tol)
    period = 2 * math.pi * math.sqrt(M / K)
    fine = math.ceil(period / h)            # a step at or below the limit
    coarse = math.floor(period / (2 * h))   # a step at least twice the limit
    assert _ringing_error(solver, d, fine) <= 1.05 * tol
    assert _ringing_error(solver, d, coarse) > tol


def test_step_limit_closed_forms_undamped():
    # error over a period of R(z)^N against e^(Nz), z = i x, N = 2 pi / x, small x: euler pi x; rk4 2 pi x^4 / 120
    wn = math.sqrt(K / M)
    tol = 1e-5
    assert largest_step("euler", K, 0.0, M, tol) * wn == pytest.approx(tol / math.pi, rel=1e-3)
    assert largest_step("rk4", K, 0.0, M, tol) * wn == pytest.approx((60 * tol / math.pi) ** 0.25, rel=1e-3)


def test_refusal_names_k_train_the_step_and_the_step_that_would_do():
    h = largest_step("rk4", K, 0.0, M)
    check_step("rk4", 0.99 * h, K, 0.0, M)           # resolved: no refusal
    check_step("rk4", 1.0, 0.0, 0.0, 0.0)            # rigid train: nothing to resolve
    check_step("rk45", 1.0, K, 0.0, M)               # error control chooses its step
    with pytest.raises(ValueError) as err:
        check_step("rk4", 2e-4, K, 0.0, M)
    text = str(err.value)
    assert "'k_train' = 400000.0 N/m" in text and "step 0.0002 s" in text and f"step <= {h:.4g} s" in text
    with pytest.raises(ValueError, match="'etdrk4'.*k_train = 0"):
        check_step("etdrk4", 1e-6, K, 0.0, M)
    with pytest.raises(ValueError, match="'m_end'"):
        check_step("rk4", 1e-6, K, 0.0, 0.0)
