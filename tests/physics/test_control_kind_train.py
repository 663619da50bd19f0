"""reflect's map and bode's linear model with the follower train on the other follower types (control.kind_view,
docs/model.md 14.6 and 16): a translating flat's train along s (k_train, d_train, m_end) and an arm's torsional one
(k_train_arm, d_train_arm, J_end). Against closed forms written here in each kind's own terms (an arm's psi' =
lift_angle s' / h, its torsion spring and end inertia, never the lift-unit scaling the code uses), against the same
map without a train and the end mass carried on the follower (its low-frequency limit), and against the C engine's
small-signal response (bode's measurement: the nonlinear drive, simulated)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.control.frequency import analytic_response, frozen_parameters, linear_model
from cam_fmu.control.reflect import PARTS, reflected_map, summary
from cam_fmu.experiments.frequency import measured_response
from test_reflect_kinds import BASE, G_N, KINDS, coordinate, lift

# A train of about 40 Hz on its own on every kind: along s on the flat, about the arm's pivot on an arm.
TRAIN = {"translating_flat": dict(k_train=1.3e4, m_end=0.2),
         "oscillating_roller": dict(k_train_arm=130.0, J_end=2e-3),
         "oscillating_flat": dict(k_train_arm=130.0, J_end=2e-3)}
DAMPER = {"translating_flat": dict(d_train=2.0), "oscillating_roller": dict(d_train_arm=0.02),
          "oscillating_flat": dict(d_train_arm=0.02)}


def spring_and_end(kind: str) -> tuple[float, float]:
    """(k, m): the train's stiffness [N/m or N m/rad] and end mass [kg or kg m2] in the kind's own coordinate."""
    t = TRAIN[kind]
    return (t["k_train"], t["m_end"]) if kind == "translating_flat" else (t["k_train_arm"], t["J_end"])


def closed_form(kind: str, theta: float) -> tuple[float, float]:
    """(f_r, f_a) [Hz] by hand, rigid shaft: the cam side J_c = J_m + J_cam + I_f q'^2 seen from the follower's
    coordinate is an inertia J_c / q'^2 on the train's spring with the end: f_r = sqrt(k (1/m + q'^2/J_c)) / 2 pi;
    the end alone on the spring (the cam held by the anti-resonance): f_a = sqrt(k / m) / 2 pi."""
    _, q1, _, I_f = coordinate(kind, theta)
    k, m = spring_and_end(kind)
    J_c = BASE["J_m"] + BASE["J_cam"] + I_f * q1 * q1
    return math.sqrt(k * (1.0 / m + q1 * q1 / J_c)) / (2.0 * math.pi), math.sqrt(k / m) / (2.0 * math.pi)


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_trains_resonance_and_anti_resonance_are_the_closed_forms(kind):
    """Undamped, gravity off, no back-EMF: the linear model's oscillatory pole is f_r (at three angles of the rise),
    |H| dips to nothing at f_a, and reflect's f_r_train, f_a_train columns are the same closed forms."""
    quiet = dict(BASE, **KINDS[kind], **TRAIN[kind], c_e=1e-6, gravity=False, mu=0.0)
    for theta in (0.3, 0.8, 1.3):
        f_r, f_a = closed_form(kind, theta)
        A, _, _ = linear_model(quiet, theta)
        assert max(np.linalg.eigvals(A).imag) / (2.0 * math.pi) == pytest.approx(f_r, rel=1e-9)
        dip = analytic_response(quiet, theta, [0.99 * f_a, f_a, 1.01 * f_a]).cam
        assert abs(dip[1]) < 1e-6 * min(abs(dip[0]), abs(dip[2]))
    ring = reflected_map(quiet, 300.0, points=16)
    for theta, f_r, f_a in zip(ring["theta"], ring["f_r_train"], ring["f_a_train"]):
        assert (f_r, f_a) == pytest.approx(closed_form(kind, float(theta)), rel=1e-12)
    found = summary(ring, 300.0)
    assert found["f_r_train_max"] == pytest.approx(max(ring["f_r_train"])) and found["f_r_min"] is None


def carried(kind: str) -> dict:
    """The drive without a train whose follower carries the end rigidly: m + m_end and its weight on the flat (mounted
    vertically, the weight along X), J_arm + J_end on an arm (the end inertia turns with it, about its own centre)."""
    if kind == "translating_flat":
        return dict(m=BASE["m"] + TRAIN[kind]["m_end"], G=BASE["G"] + TRAIN[kind]["m_end"] * G_N)
    return dict(J_arm=KINDS[kind]["J_arm"] + TRAIN[kind]["J_end"])


@pytest.mark.parametrize("rpm", [120.0, -300.0])
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_map_is_the_end_carried_on_the_follower_at_low_frequency(kind, rpm):
    """J, M and every part of M with the train are those of the drive that carries the end on the follower (with the
    kind's friction mu = 0.05 and gravity, so the end's inertial force and weight join the friction's P), to
    rounding; the map without the train's end is not (the end matters here)."""
    mounting = dict(gamma=math.pi / 2, beta=math.pi) if kind == "translating_flat" else dict(gamma=1.2)
    common = dict(BASE, **KINDS[kind], **mounting, mu=0.05, M_f=0.01)
    got = reflected_map(dict(common, **TRAIN[kind], **DAMPER[kind]), rpm, points=90)
    rigid = reflected_map(dict(common, **carried(kind)), rpm, points=90)
    for name in ("J", "M", *PARTS):
        scale = np.max(np.abs(rigid[name])) or 1.0
        assert np.max(np.abs(got[name] - rigid[name])) <= 1e-12 * scale, name
    bare = reflected_map(common, rpm, points=90)
    assert np.max(np.abs(got["M"] - bare["M"])) > 0.05 * np.max(np.abs(bare["M"]))
    assert np.all(got["f_a_train"] == got["f_a_train"][0]) and "f_r" not in got


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_holding_voltage_holds_the_ends_weight_too(kind):
    """At rest at theta0 the train's spring holds its end: a flat mounted vertically (gravity against the rise) is held
    by R (G + m_end g_n) s' / c_m; an arm's torsional end has no weight along its stroke, so its voltage is the
    arm's alone (test_frequency_kinds' W cos(psi + psi_0) psi')."""
    mounting = dict(gamma=math.pi / 2, beta=math.pi) if kind == "translating_flat" else dict(gamma=1.2)
    params = dict(BASE, **KINDS[kind], **mounting, mu=0.0)
    theta0 = 0.5
    _, u0 = frozen_parameters(dict(params, **TRAIN[kind]), theta0)
    _, u_bare = frozen_parameters(params, theta0)
    R, c_m = 19.0, 0.015 * G_N  # the defaults (physics/parameters.py): R [ohm], c_m [N m/A]
    if kind == "translating_flat":
        s1 = lift(theta0)[1]
        assert u0 == pytest.approx(R * (BASE["G"] + TRAIN[kind]["m_end"] * G_N) * s1 / c_m, rel=1e-12)
        assert u0 > u_bare
    else:
        assert u0 == u_bare


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_engine_responds_as_the_linearised_drive_with_the_kinds_train(kind):
    """bode's measurement on the C engine (the nonlinear drive with its train, excited by a small sine about the
    frozen angle) against the linear model with the end's two states, below, around and above the train's resonance
    (a damped train: an undamped one rings through the measuring window). Measured: 8.1e-6 .. 4.4e-5 of the peak,
    the largest at 2 Hz (the settling's remainder, as without a train); the same model without the train is 0.18 ..
    0.63 of the peak off."""
    mounting = dict(gamma=math.pi / 2, beta=math.pi) if kind == "translating_flat" else dict(gamma=1.2)
    params = dict(BASE, **KINDS[kind], **mounting, **TRAIN[kind], **DAMPER[kind], mu=0.0)
    theta0 = 0.5
    f_r, f_a = closed_form(kind, theta0)
    f = np.array([2.0, 0.8 * f_a, f_a, f_r, 1.5 * f_r])
    exact = analytic_response(params, theta0, f)
    seen = measured_response(params, f, theta0=theta0)
    for name in ("cam", "motor"):
        error = np.max(np.abs(getattr(seen, name) - getattr(exact, name))) / np.max(np.abs(getattr(exact, name)))
        assert error < 1e-4, (name, error)
    assert seen.u0 == exact.u0
