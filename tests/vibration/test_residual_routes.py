"""The residual vibration after a rise, each route against an independent source: the cycloidal's closed form,
the test's own quadrature of the spectrum integral (scipy.integrate.quad), the impulse-response convolution for
the damped train, and the train's energy balance."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from cam_fmu.kinematics.motion_law import MotionLaw
from cam_fmu.kinematics.presets import LAW_NAMES, named_law
from cam_fmu.vibration.spectral import residual
from cam_fmu.vibration.train import residual_ode, run_train


def cycloidal_closed_form(r: float) -> float:
    """|sin(pi r)| / (pi r |r^2 - 1|), its limit 1/2 at r = 1."""
    if abs(r - 1.0) < 1e-12:
        return 0.5
    return abs(math.sin(math.pi * r)) / (math.pi * r * abs(r * r - 1.0))


def breaks(law) -> list[float]:
    return sorted(set((0.0,) + law.T + (1.0,))) if isinstance(law, MotionLaw) else [0.0, 1.0]


def quad_pieces(f, law) -> float:
    """int_0^1 f by scipy's quad over the law's smooth pieces."""
    edges = breaks(law)
    return sum(quad(f, a, b, epsabs=1e-13, epsrel=1e-11, limit=200)[0] for a, b in zip(edges, edges[1:]) if b > a)


def acceleration(law):
    return lambda u: law.scalar(u)[2] if 0.0 < u < 1.0 else 0.0


def undamped_by_quadrature(law, r: float) -> float:
    """|int_0^1 A(u) exp(i 2 pi r u) du| / (2 pi r)."""
    W, A = 2 * math.pi * r, acceleration(law)
    re = quad_pieces(lambda u: A(u) * math.cos(W * u), law)
    im = quad_pieces(lambda u: A(u) * math.sin(W * u), law)
    return math.hypot(re, im) / W


def damped_by_convolution(law, r: float, zeta: float) -> float:
    """e(1) and e'(1) of e'' + 2 zeta W e' + W^2 e = -A from rest, by the impulse response
    h(t) = exp(-zeta W t) sin(W_d t) / W_d, then the free ringing's amplitude at u = 1."""
    W = 2 * math.pi * r
    Wd = W * math.sqrt(1 - zeta * zeta)
    A = acceleration(law)
    h = lambda t: math.exp(-zeta * W * t) * math.sin(Wd * t) / Wd
    dh = lambda t: math.exp(-zeta * W * t) * (math.cos(Wd * t) - zeta * W / Wd * math.sin(Wd * t))
    e = -quad_pieces(lambda u: A(u) * h(1 - u), law)
    de = -quad_pieces(lambda u: A(u) * dh(1 - u), law)
    return math.hypot(e, (de + zeta * W * e) / Wd)


def test_cycloidal_undamped_by_the_integrated_train_against_its_closed_form():
    r = np.linspace(1.0, 6.0, 101)           # r = 1, 1.05, ..., 6: the zeros r = 2..6 among them
    got = residual_ode(named_law("cycloidal"), r)
    want = np.array([cycloidal_closed_form(x) for x in r])
    assert np.max(np.abs(got - want)) < 1e-4
    assert np.max(np.abs(got - want)) < 1e-9  # what it is (DOP853 at rtol 1e-11): far inside the 1e-4
    assert np.all(got[r == np.round(r)][1:] < 1e-9)   # zero at r = 2, 3, 4, 5, 6


def test_cycloidal_closed_form_route():
    r = np.linspace(1.0, 6.0, 501)
    want = np.array([cycloidal_closed_form(x) for x in r])
    assert np.max(np.abs(residual(named_law("cycloidal"), r) - want)) < 1e-12


@pytest.mark.parametrize("name", LAW_NAMES)
def test_any_law_both_routes_against_the_quadrature(name):
    law = named_law(name)
    r = np.array([0.3, 0.75, 1.0, 1.7, 2.5, 3.2, 4.9])
    want = np.array([undamped_by_quadrature(law, x) for x in r])
    assert np.max(np.abs(residual_ode(law, r) - want)) < 1e-9
    assert np.max(np.abs(residual(law, r) - want)) < 1e-11


def test_a_quarter_wave_in_resonance_with_the_train():
    # The modified sine's first quarter sine lasts 1/8: a = pi / (2 L) = 4 pi equals W = 2 pi r at r = 2, where
    # the segment's closed form is 0/0 and quadrature takes over.
    law = named_law("modified_sine")
    for r in (2.0, 2.0 + 1e-9, 2.0 - 1e-7):
        assert residual(law, r)[0] == pytest.approx(undamped_by_quadrature(law, r), abs=1e-11)


@pytest.mark.parametrize("name", ["cycloidal", "modified_sine", "constant_acceleration", "polynomial_4567",
                                  "paper"])
@pytest.mark.parametrize("zeta", [0.02, 0.1, 0.5])
def test_damped_against_the_impulse_response_convolution(name, zeta):
    law = named_law(name)
    r = np.array([0.6, 1.3, 2.0, 2.7, 4.1])
    want = np.array([damped_by_convolution(law, x, zeta) for x in r])
    assert np.max(np.abs(residual(law, r, zeta) - want)) < 1e-11
    assert np.max(np.abs(residual_ode(law, r, zeta) - want)) < 1e-9


@pytest.mark.parametrize("zeta", [0.0, 0.05, 0.3])
def test_energy_balance_of_the_train(zeta):
    """kinetic + spring energy + the damper's loss = the work the follower did, along the whole run."""
    run = run_train(named_law("modified_trapezoid"), 1.83, zeta, dwell=3.0, samples=400)
    assert np.max(np.abs(run.energy_error)) < 1e-9
    assert run.work_in[-1] > 0.0
    if zeta:
        # the damper took energy over the dwell: the ringing decayed by exp(-zeta W t) over 3 periods
        assert run.damper_loss[-1] > 0.0
        assert run.dwell_peak < run.residual
    else:
        assert run.damper_loss[-1] == 0.0


def test_the_dwell_rings_at_the_residual_amplitude():
    run = run_train(named_law("cycloidal"), 1.5, 0.0, dwell=2.0, samples=2000)
    # 2000 samples over 2 periods: the sampled peak is within 1 - cos(pi / 1000) of the amplitude
    assert run.residual * (1 - 1e-5) <= run.dwell_peak <= run.residual * (1 + 1e-9)
    assert run.residual == pytest.approx(cycloidal_closed_form(1.5), abs=1e-10)


@pytest.mark.parametrize("bad, match", [(0.0, "r = rise time"), (-1.0, "r = rise time"),
                                        (float("nan"), "r = rise time")])
def test_refused_ratios(bad, match):
    with pytest.raises(ValueError, match=match):
        residual(named_law("cycloidal"), bad)
    with pytest.raises(ValueError, match=match):
        run_train(named_law("cycloidal"), bad)


@pytest.mark.parametrize("zeta", [-0.1, 1.0, 2.0, float("inf")])
def test_refused_damping(zeta):
    with pytest.raises(ValueError, match=r"zeta .*\[0, 1\)"):
        residual(named_law("cycloidal"), 2.0, zeta)
