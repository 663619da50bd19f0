"""The reflected-load map (control.reflect) for every follower type other than the translating roller, against closed
forms written here (docs/model.md 16): a cycloidal rise and return of 90 deg each between dwells, s(theta) by hand;
q = s (translating) or psi = lift_angle s / h (an arm), I_f = m or J_arm + m L^2. At constant speed
J(theta) = J_m + J_cam + I_f q'^2 and M = I_f q' q'' omega^2 without friction and gravity; the arm's weight torque
W cos(psi + psi_0) psi' with W = (G L + m_arm g_n r_cm_arm) sin(gamma); the flat face's friction on its lever; a
compliant shaft's two-mass frequencies from the eigenproblem of the rotor and the cam side J_cam + I_f q'^2."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.control.reflect import PARTS, FreeFollowerError, reflected_map, summary

H, BETA, R_B = 0.02, math.pi / 2, 0.08  # m, rad, m
G_N = 9.80665  # m/s2
BASE = dict(rise_law="cycloidal", return_law="cycloidal", rise_angle=BETA, upper_dwell=BETA, return_angle=BETA,
            lower_dwell=BETA, lift=H, r_b=R_B, closure="kinematic", m=0.4, G=4.0, J_m=4.41e-5, J_cam=2e-4)
ARM = dict(arm_length=0.15, pivot_distance=0.18, J_arm=2e-3, m_arm=0.2, r_cm_arm=0.07, psi_0=0.3)
KINDS = {"translating_flat": dict(follower_type="translating_flat"),
         "oscillating_roller": dict(follower_type="oscillating_roller", lift_angle=0.3, **ARM),
         "oscillating_flat": dict(follower_type="oscillating_flat", lift_angle=0.15, **ARM)}
QUIET = dict(gravity=False, mu=0.0, shaft_friction=False)


def lift(theta: float) -> tuple[float, float, float]:
    """(s, s', s'') [m, m/rad, m/rad2] of the cycloidal rise, upper dwell, cycloidal return, lower dwell."""
    theta %= 2.0 * math.pi
    if theta < BETA:
        x, sign, base = theta / BETA, 1.0, 0.0
    elif theta < 2 * BETA:
        return H, 0.0, 0.0
    elif theta < 3 * BETA:
        x, sign, base = (theta - 2 * BETA) / BETA, -1.0, H
    else:
        return 0.0, 0.0, 0.0
    w = 2.0 * math.pi * x
    return (base + sign * H * (x - math.sin(w) / (2.0 * math.pi)), sign * H / BETA * (1.0 - math.cos(w)),
            sign * 2.0 * math.pi * H / BETA ** 2 * math.sin(w))


def coordinate(kind: str, theta: float) -> tuple[float, float, float, float]:
    """(q, q', q'', I_f): the follower's coordinate and inertia of ``kind`` by hand."""
    s, s1, s2 = lift(theta)
    p = KINDS[kind]
    if kind.startswith("oscillating"):
        k = p["lift_angle"] / H
        return k * s, k * s1, k * s2, p["J_arm"] + BASE["m"] * p["arm_length"] ** 2
    return s, s1, s2, BASE["m"]


@pytest.mark.parametrize("rpm", [90.0, -240.0])
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_kinds_map_is_its_closed_form_without_friction_and_gravity(kind, rpm):
    result = reflected_map(dict(BASE, **QUIET, **KINDS[kind]), rpm, points=720)
    omega = rpm * 2.0 * math.pi / 60.0
    for k, theta in enumerate(result["theta"]):
        _, q1, q2, I_f = coordinate(kind, float(theta))
        assert result["J"][k] == pytest.approx(BASE["J_m"] + BASE["J_cam"] + I_f * q1 * q1, rel=1e-12)
        assert result["M"][k] == pytest.approx(I_f * q1 * q2 * omega ** 2, rel=1e-9, abs=1e-15)
        assert result["M_inertial"][k] == pytest.approx(I_f * q1 * q2 * omega ** 2, rel=1e-9, abs=1e-15)
        assert result["M_gravity"][k] == 0.0 and result["M_guide"][k] == 0.0 and result["M_shaft"][k] == 0.0
    found = summary(result, rpm)  # the largest q' is at mid-rise: q' = 2 h / beta (times lift_angle / h)
    _, q1_peak, _, I_f = coordinate(kind, BETA / 2)
    assert found["J_max"] == pytest.approx(BASE["J_m"] + BASE["J_cam"] + I_f * q1_peak ** 2, rel=1e-12)
    assert found["f_r_min"] is None  # a rigid shaft: no resonance


@pytest.mark.parametrize("kind", ["oscillating_roller", "oscillating_flat"])
def test_an_arms_weight_is_its_torque_about_the_pivot_reflected(kind):
    gamma = 1.2
    params = dict(BASE, **KINDS[kind], gamma=gamma, mu=0.0, M_f=0.012)
    result = reflected_map(params, 60.0, points=360)
    p = KINDS[kind]
    W = (BASE["G"] * p["arm_length"] + p["m_arm"] * G_N * p["r_cm_arm"]) * math.sin(gamma)
    omega = 2.0 * math.pi
    for k, theta in enumerate(result["theta"]):
        q, q1, q2, I_f = coordinate(kind, float(theta))
        assert result["M_gravity"][k] == pytest.approx(W * math.cos(q + p["psi_0"]) * q1, rel=1e-9, abs=1e-15)
        assert result["M_shaft"][k] == 0.012
        assert result["M"][k] == pytest.approx(0.012 + I_f * q1 * q2 * omega ** 2 + W * math.cos(q + p["psi_0"]) * q1,
                                               rel=1e-9, abs=1e-15)


def test_a_flat_faces_friction_acts_on_its_lever():
    """Translating flat face: the face slides on the cam r_b + s from its axis, M_guide = mu |P| (r_b + s) sgn(omega)
    with P = m s'' omega^2 - F_gx; the parts add up to M."""
    params = dict(BASE, **KINDS["translating_flat"], mu=0.05, gamma=1.2, beta=0.3)
    F_gx = BASE["G"] * math.sin(1.2) * math.cos(0.3)
    for rpm in (120.0, -120.0):
        result = reflected_map(params, rpm, points=360)
        omega, d = rpm * 2.0 * math.pi / 60.0, math.copysign(1.0, rpm)
        for k, theta in enumerate(result["theta"]):
            s, s1, s2 = lift(float(theta))
            P = BASE["m"] * s2 * omega ** 2 - F_gx
            assert result["M_guide"][k] == pytest.approx(0.05 * abs(P) * (R_B + s) * d, rel=1e-9, abs=1e-15)
            assert result["M_gravity"][k] == pytest.approx(-F_gx * s1, rel=1e-9, abs=1e-15)
            assert result["M"][k] == pytest.approx(sum(result[part][k] for part in PARTS), rel=1e-12, abs=1e-15)


def _modal_frequencies(k: float, J_m: float, J_c: float) -> tuple[float, float]:
    """The undamped frequencies [Hz] from the two-mass eigenproblem (numpy), and clamping the rotor."""
    resonance = max(np.linalg.eigvals(np.diag([1.0 / J_m, 1.0 / J_c]) @ np.array([[k, -k], [-k, k]])).real)
    return math.sqrt(resonance) / (2.0 * math.pi), math.sqrt(k / J_c) / (2.0 * math.pi)


@pytest.mark.parametrize("kind", list(KINDS))
def test_a_compliant_shaft_under_every_kind_resonates_with_its_inertia(kind):
    params = dict(BASE, **QUIET, **KINDS[kind], k_shaft=50.0, d_shaft=1e-3)
    result = reflected_map(params, 60.0, points=720)
    for k in range(0, 720, 13):
        _, q1, _, I_f = coordinate(kind, float(result["theta"][k]))
        J_c = BASE["J_cam"] + I_f * q1 * q1
        assert result["J"][k] == pytest.approx(BASE["J_m"] + J_c, rel=1e-12)
        f_r, f_a = _modal_frequencies(50.0, BASE["J_m"], J_c)
        assert result["f_r"][k] == pytest.approx(f_r, rel=1e-9)
        assert result["f_a"][k] == pytest.approx(f_a, rel=1e-12)
    found = summary(result, 60.0)
    _, q1_peak, _, I_f = coordinate(kind, BETA / 2)  # the follower weighs most at mid-rise
    assert found["f_a_min"] == pytest.approx(math.sqrt(50.0 / (BASE["J_cam"] + I_f * q1_peak ** 2)) / (2 * math.pi),
                                             rel=1e-9)
    assert found["f_a_max"] == pytest.approx(math.sqrt(50.0 / BASE["J_cam"]) / (2 * math.pi), rel=1e-12)


@pytest.mark.parametrize("kind", list(KINDS))
def test_a_spring_closed_kind_is_refused_as_the_roller_is(kind):
    params = dict(BASE, **KINDS[kind], closure="spring", k_spring=1000.0, F_spring0=20.0)
    with pytest.raises(FreeFollowerError, match="closure 'spring'"):
        reflected_map(params, 60.0)
    with pytest.raises(ValueError, match="J_cam"):
        reflected_map(dict(BASE, **KINDS[kind], J_cam=0.0, k_shaft=50.0), 60.0)


@pytest.mark.parametrize("kind", ["oscillating_roller", "oscillating_flat"])
def test_an_arms_friction_acts_on_its_lever(kind):
    """The roller arm's pivot: mu |P| |psi'|; the flat arm's face, whose line lies d sin(delta) from the cam axis at
    delta = asin(r_b / d) + psi: mu |P| tan(delta) (1 - psi') (docs/model.md 16), with P = I_f psi'' omega^2 (no
    gravity); sgn(omega) on both."""
    params = dict(BASE, **KINDS[kind], mu=0.05, gravity=False, shaft_friction=False)
    delta0 = math.asin(R_B / KINDS[kind]["pivot_distance"])
    for rpm in (150.0, -150.0):
        result = reflected_map(params, rpm, points=360)
        omega, d = rpm * 2.0 * math.pi / 60.0, math.copysign(1.0, rpm)
        for k, theta in enumerate(result["theta"]):
            q, q1, q2, I_f = coordinate(kind, float(theta))
            P = I_f * q2 * omega ** 2
            lever = abs(q1) if kind == "oscillating_roller" else math.tan(delta0 + q) * (1.0 - q1)
            assert result["M_guide"][k] == pytest.approx(0.05 * abs(P) * lever * d, rel=1e-9, abs=1e-15)
            assert result["M"][k] == pytest.approx(P * q1 + result["M_guide"][k], rel=1e-12, abs=1e-15)
