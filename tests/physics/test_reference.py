"""The scipy reference: power balance, L -> 0, its own accuracy, and the FMU stepper against it.

Claimed accuracy of simulate_reference at its defaults (rtol 1e-12, atol 1e-13) on
the fig. 6 run (u = 3.5 V, 2 s, from rest): theta to 5e-8 rad, omega to 5e-6 rad/s.
Measured here: default vs halved tolerances 2.0e-8 rad / 2.3e-6 rad/s (omega's worst
is at the spikes where J drops 45x; its median difference is 2e-10 rad/s); halved vs
LSODA (a different method, multistep, stiff-capable) 2.3e-9 rad.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.physics.formulations import consistent as hybrid_module
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.formulations.consistent import HybridDrive
from cam_fmu.reference import simulate_reference
from cam_fmu.fmu.engine import DriveSimulator
from test_drive_closed_form import DEFAULTS

C_M = DEFAULTS["c_m"]
THETA_CLAIM, OMEGA_CLAIM = 5e-8, 5e-6  # rad, rad/s


@pytest.fixture(scope="module")
def fig6():
    return simulate_reference({}, 2.0, 1e-3)


# ------------------------------------------------------------- power balance
def _missing(params, out):
    """E_in - E_copper - E_shaft - E_guide - Delta(stored) at every output [J]."""
    model = DriveModel(params)
    stored = np.array([model.energy(th, w, i) for th, w, i in zip(out["theta"], out["omega"], out["i"])])
    # stored = 1/2 J omega^2 - F_gx s + 1/2 L i^2, recomputed independently:
    s1 = np.array([model.program.derivatives(th)[1] for th in out["theta"]])
    check = 0.5 * (DEFAULTS["J_m"] + DEFAULTS["m"] * s1 ** 2) * out["omega"] ** 2 - model.F_gx * out["s"] \
        + 0.5 * model.L * out["i"] ** 2
    np.testing.assert_allclose(stored, check, rtol=1e-12, atol=1e-15)
    return out["E_in"] - out["E_copper"] - out["E_shaft"] - out["E_guide"] - (stored - stored[0])


BALANCE = {
    # name: (params, stop time [s], tolerance [J], measured [J])
    "horizontal": (dict(c_e=C_M), 2.0, 1e-10, 1.3e-12),
    "tilted": (dict(c_e=C_M, gamma=math.radians(100.0), beta=math.radians(200.0)), 2.0, 1e-10, 8e-15),
    "inductance": (dict(c_e=C_M, L=1e-3), 0.3, 1e-10, 8.3e-13),
}


@pytest.mark.parametrize("case", list(BALANCE))
def test_power_balance_voltage_drive(case):
    """E_in = E_copper + E_shaft + E_guide + Delta(kinetic + gravity potential + magnetic)
    at every output time, for a lossless converter (c_e = c_m in SI units).
    Tolerance 1e-10 J on E_in = 0.17..1.3 J; measured max |imbalance| in BALANCE."""
    params, stop, tol, _ = BALANCE[case]
    kw = dict(rtol=1e-10, atol=1e-12) if "L" in params else {}
    out = simulate_reference(params, stop, 1e-3, energy=True, **kw)
    assert out["E_in"][-1] > 0.1 if stop > 1 else out["E_in"][-1] > 0.01
    assert out["E_shaft"][-1] > 0 and out["E_guide"][-1] > 0
    assert np.max(np.abs(_missing(params, out))) < tol


def test_power_balance_with_the_papers_constants():
    """With the paper's c_e = 0.146 V s/rad and c_m = 0.1471 N m/A the motor converts
    c_e omega i of electrical power into c_m omega i of mechanical power: it creates
    (c_m/c_e - 1) = 0.75 % of the converted energy. The balance closes only with that term:
    missing = (1 - c_m/c_e) (E_in - E_copper) (to 1e-9 J, measured 7.6e-13 J; both are -1.4697e-3 J)."""
    out = simulate_reference({}, 2.0, 1e-3, energy=True)
    missing = _missing({}, out)
    expected = (1 - C_M / DEFAULTS["c_e"]) * (out["E_in"] - out["E_copper"])
    assert expected[-1] == pytest.approx(-1.47e-3, abs=1e-5)
    assert np.max(np.abs(missing - expected)) < 1e-9


# ------------------------------------------------------------------- L -> 0
@pytest.fixture
def event_guard(monkeypatch):
    """Fail (instead of hanging) when the reference applies more than 200 transitions."""
    original = HybridDrive.apply_event
    count = [0]

    def guarded(self, y, u, mode, name):
        count[0] += 1
        if count[0] > 200:
            raise RuntimeError(f"more than 200 transitions: the last was {name!r} at y = {list(y)}, {mode}")
        original(self, y, u, mode, name)

    monkeypatch.setattr(hybrid_module.HybridDrive, "apply_event", guarded)


def _l_differences(inductances, stop=0.3):
    base = simulate_reference({}, stop, 1e-3)
    d_theta, d_omega = [], []
    for L in inductances:
        out = simulate_reference(dict(L=L), stop, 1e-3, rtol=1e-10, atol=1e-12)
        d_theta.append(np.max(np.abs(out["theta"] - base["theta"])))
        d_omega.append(np.max(np.abs(out["omega"][5:] - base["omega"][5:])))
    return d_theta, d_omega


def _assert_proportional(d_theta, d_omega, factor):
    for d in (d_theta, d_omega):
        for big, small in zip(d, d[1:]):
            assert 0.7 * factor < big / small < 1.3 * factor, d


def test_inductance_to_zero_converges_to_L0(event_guard):
    """Differences to L = 0 over 0.3 s shrink in proportion to L (L = 1e-3, 1e-4 H):
    ratio within 10 +- 30 % (measured: theta 4.44e-4 -> 4.43e-5 rad, omega 2.7e-2 -> 2.7e-3 rad/s)."""
    d_theta, d_omega = _l_differences((1e-3, 1e-4))
    assert d_theta[0] < 1e-3
    _assert_proportional(d_theta, d_omega, 10.0)


def test_inductance_to_zero_converges_to_L0_down_to_1e5(event_guard):
    """The same with L = 1e-5 H too (L/R = 0.5 us). It hung once: a break-away at the
    located threshold was re-stuck by the next settle() and fired again, forever."""
    d_theta, d_omega = _l_differences((1e-3, 1e-4, 1e-5))
    _assert_proportional(d_theta, d_omega, 10.0)


# --------------------------------------------------------- reference accuracy
def test_halving_the_tolerance_changes_less_than_claimed(fig6):
    half = simulate_reference({}, 2.0, 1e-3, rtol=5e-13, atol=5e-14)
    d_theta = np.abs(fig6["theta"] - half["theta"])
    d_omega = np.abs(fig6["omega"] - half["omega"])
    assert d_theta.max() < THETA_CLAIM
    assert d_omega.max() < OMEGA_CLAIM
    assert np.median(d_omega) < 1e-8  # the omega worst case is local (the spikes)
    # and the differences are not zero: the tolerances are really applied
    assert d_theta.max() > 0


def test_second_integrator_agrees(fig6):
    """LSODA on the same hybrid right-hand side, events and breakpoints (measured 2.2e-8 rad)."""
    other = simulate_reference({}, 2.0, 1e-3, method="LSODA")
    assert np.max(np.abs(fig6["theta"] - other["theta"])) < THETA_CLAIM
    assert np.max(np.abs(fig6["omega"] - other["omega"])) < OMEGA_CLAIM
    assert fig6["theta"][-1] == pytest.approx(13.2343, abs=1e-4)  # 2.1 turns in 2 s
    assert fig6["omega"].max() == pytest.approx(43.39, abs=0.01)  # the spike where J is smallest


def test_simulator_default_matches_reference_fig6(fig6):
    """DriveSimulator with its default settings (rk45, rtol 1e-10) on the fig. 6 run at
    1 ms communication steps: theta error < 1e-6 rad (the accuracy target; measured 2.8e-9)."""
    sim = DriveSimulator({})
    sim.set_inputs(3.5, 1.0)
    theta, omega = [sim.outputs()["theta"]], [sim.outputs()["omega"]]
    for k in range(2000):
        sim.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
        out = sim.outputs()
        theta.append(out["theta"])
        omega.append(out["omega"])
    assert np.max(np.abs(np.array(theta) - fig6["theta"])) < 1e-6
    assert np.max(np.abs(np.array(omega) - fig6["omega"])) < 1e-3
