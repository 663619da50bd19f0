"""The frequency response at a frozen angle (control.frequency, experiments.frequency) for every follower type other
than the translating roller: the linearised drive's resonance against sqrt(k_g / J(theta)) and the two-mass closed
form with the kind's J(theta) (test_reflect_kinds' hand-written cam: q, q', q'', I_f), its response against the C
engine's small-signal simulation (every type) and the scipy reference's (an oscillating roller, simulated here)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.control.frequency import analytic_response, frozen_parameters, linear_model, settle_time
from cam_fmu.control.reflect import two_mass_frequencies
from cam_fmu.experiments.frequency import measured_response
from cam_fmu.physics.signals import Signal, constant
from cam_fmu.reference.integrate import simulate_reference
from test_reflect_kinds import BASE, BETA, G_N, KINDS, coordinate

GRAVITY = {"translating_flat": dict(gamma=math.pi / 2, beta=math.pi),  # vertical, gravity against the rise
           "oscillating_roller": dict(gamma=1.2), "oscillating_flat": dict(gamma=1.2)}
THETA0 = {"translating_flat": 0.3, "oscillating_roller": 0.5, "oscillating_flat": 0.5}  # rad: k_g > 0 there


def stiffness(kind: str, theta: float) -> float:
    """k_g = d2V/dtheta2 [N m/rad] by hand: G s'' for a translating face held up by the cam (gamma = pi/2,
    beta = pi: gravity along -X); W (cos(psi + psi_0) psi'' - sin(psi + psi_0) psi'^2) for an arm."""
    q, q1, q2, _ = coordinate(kind, theta)
    if kind == "translating_flat":
        return BASE["G"] * q2
    p = KINDS[kind]
    W = (BASE["G"] * p["arm_length"] + p["m_arm"] * G_N * p["r_cm_arm"]) * math.sin(GRAVITY[kind]["gamma"])
    return W * (math.cos(q + p["psi_0"]) * q2 - math.sin(q + p["psi_0"]) * q1 * q1)


def frozen(kind: str) -> dict:
    return dict(BASE, **KINDS[kind], **GRAVITY[kind], mu=0.0)


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_linear_drive_rings_at_gravitys_stiffness_over_the_kinds_inertia(kind):
    """Without back-EMF (c_e ~ 0) the rigid drive held at theta0 is an undamped oscillator: its pole at
    sqrt(k_g / J(theta0)); with a compliant shaft (gravity off) the two-mass resonance with J_c = J_cam + I_f q'^2."""
    theta0 = THETA0[kind]
    _, q1, _, I_f = coordinate(kind, theta0)
    k_g = stiffness(kind, theta0)
    assert k_g > 0.0
    A, _, _ = linear_model(dict(frozen(kind), c_e=1e-6), theta0)
    pole = max(np.linalg.eigvals(A).imag)
    assert pole == pytest.approx(math.sqrt(k_g / (BASE["J_m"] + BASE["J_cam"] + I_f * q1 * q1)), rel=1e-6)
    shaft = dict(BASE, **KINDS[kind], gravity=False, c_e=1e-6, k_shaft=50.0)
    A, _, _ = linear_model(shaft, theta0)
    f_r, f_a = two_mass_frequencies(50.0, BASE["J_m"], BASE["J_cam"] + I_f * q1 * q1)
    assert max(np.linalg.eigvals(A).imag) / (2.0 * math.pi) == pytest.approx(f_r, rel=1e-6)
    dip = analytic_response(shaft, theta0, [0.9 * f_a, f_a, 1.1 * f_a]).motor
    assert abs(dip[1]) < 1e-6 * min(abs(dip[0]), abs(dip[2]))


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_holding_voltage_is_the_kinds_weight_torque(kind):
    theta0 = THETA0[kind]
    q, q1, _, _ = coordinate(kind, theta0)
    p = KINDS[kind]
    if kind == "translating_flat":
        M_g = BASE["G"] * q1  # gravity along -X: the cam lifts the weight G
    else:
        W = (BASE["G"] * p["arm_length"] + p["m_arm"] * G_N * p["r_cm_arm"]) * math.sin(GRAVITY[kind]["gamma"])
        M_g = W * math.cos(q + p["psi_0"]) * q1
    _, u0 = frozen_parameters(frozen(kind), theta0)
    R, c_m = 19.0, 0.015 * G_N  # the defaults (physics/parameters.py): R [ohm], c_m [N m/A]
    assert u0 == pytest.approx(R * M_g / c_m, rel=1e-12)


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_engine_responds_as_the_kinds_linearised_drive_at_a_frozen_angle(kind):
    """The C engine's small-signal response (bode's measurement) against the linear model, below, at and above the
    resonance. Measured: at most 3.9e-5 of the peak, at the lowest frequency (1 Hz): the settling's remainder, e^-8 of
    the start's transient (8 time constants of the slowest pole, experiments.frequency); it does not change with the
    amplitude (1e-5 .. 1e-3 V) or h_max (1e-5 s)."""
    theta0 = THETA0[kind]
    f = np.geomspace(1.0, 30.0, 5)
    exact = analytic_response(frozen(kind), theta0, f)
    seen = measured_response(frozen(kind), f, theta0=theta0)
    assert np.max(np.abs(seen.cam - exact.cam)) / np.max(np.abs(exact.cam)) < 2e-4
    assert seen.u0 == exact.u0


def _harmonic(t: np.ndarray, y: np.ndarray, w: float) -> complex:
    X = np.column_stack([np.ones_like(t), np.cos(w * t), np.sin(w * t)])
    c = np.linalg.lstsq(X, y, rcond=None)[0]
    return complex(c[1], -c[2])


def test_the_reference_responds_as_the_oscillating_rollers_linearised_drive():
    """The scipy reference (reference/follower_kind.py) driven by u0 + a sin(2 pi f t), held 64 times a period, less
    its run at u0 alone, over ten periods after settling; the input's first harmonic that of the staircase
    (exact sum). A lighter follower (m = 0.1 kg) settles faster. The reference holds the cam at rest under u0:
    the equilibrium the linear model is taken at. Measured: 3.6e-5 .. 4.4e-5 relative (the settling's remainder and the
fit's aliasing of the staircase's harmonics)."""
    params = dict(frozen("oscillating_roller"), m=0.1, G=1.0)
    theta0 = THETA0["oscillating_roller"]
    p, u0 = frozen_parameters(params, theta0)
    rest = simulate_reference(p, 0.5, 0.01, u=constant(u0))
    assert np.max(np.abs(rest["omega"])) < 1e-12 and np.max(np.abs(rest["theta"] - theta0)) < 1e-12
    settle, amplitude, holds, periods = settle_time(params, theta0), 1e-3, 64, 10
    for f in (2.0, 3.3, 6.0):  # the resonance is at 3.3 Hz
        w, hold = 2.0 * math.pi * f, 1.0 / (f * holds)
        n = (math.ceil(settle * f) + periods) * holds
        starts = np.arange(n) * hold
        sine = amplitude * np.sin(w * (starts + 0.5 * hold))
        stop = n * hold
        excited = simulate_reference(p, stop, hold / 4, u=Signal(tuple(starts), tuple(u0 + sine), hold=True),
                                     rtol=1e-10, atol=1e-12)
        base = simulate_reference(p, stop, hold / 4, u=constant(u0), rtol=1e-10, atol=1e-12)
        t = excited["time"]
        window = t >= stop - periods / f - 1e-12
        Y = _harmonic(t[window], (excited["omega"] - base["omega"])[window], w)
        measured = starts[-periods * holds:]
        U = (2.0 * np.sum(sine[-periods * holds:] * np.exp(-1j * w * measured)) * (1.0 - np.exp(-1j * w * hold))
             / (1j * w) / (periods / f))
        H = analytic_response(params, theta0, [f]).cam[0]
        assert abs(Y / U - H) < 2e-4 * abs(H), f


@pytest.mark.parametrize("kind", list(KINDS))
def test_a_turning_kind_settles_over_its_heaviest_inertias_time_constants(kind):
    """The turning operating point (bode --u0) waits 8 mechanical time constants R J / (c_e c_m) at the heaviest
    J = J_m + J_cam + I_f q'^2 (mid-rise here) before it measures; it turns at the speed the engine reached."""
    from cam_fmu.experiments.frequency import operating_point

    point = operating_point(frozen(kind), u0=40.0)
    _, q1, _, I_f = coordinate(kind, BETA / 2)
    R, c_m, c_e = 19.0, 0.015 * G_N, 0.146  # the defaults (physics/parameters.py)
    assert point.settle == pytest.approx(8.0 * R * (BASE["J_m"] + BASE["J_cam"] + I_f * q1 * q1) / (c_e * c_m),
                                         rel=1e-12)
    assert point.f_turn > 0.1 and "turning under u0 = 40 V" in point.note
