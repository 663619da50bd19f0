"""Followers of every kind in the drive's reference (docs/model.md 16), against independent sources: the load torque
at constant speed from the law's closed form written here, the energy balance of docs/model.md 9 with friction and
gravity, and today's reference for the translating roller, bit for bit."""
from __future__ import annotations

import math

import numpy as np
import pytest
from closed_forms import cycloid_program

from cam_fmu.physics.follower_kind import FollowerKind
from cam_fmu.physics.follower_load import arm_inertia_torque
from cam_fmu.physics.parameters import KGF, ParameterError, resolve
from cam_fmu.physics.signals import Signal, constant
from cam_fmu.physics.train import Train
from cam_fmu.reference import simulate_reference

OMEGA = 10.0  # rad/s
RISE = math.pi / 2  # rad: cycloidal rise, dwell, cycloidal return, dwell, 90 deg each
TURN = 2.0 * math.pi / OMEGA  # s
H = 0.02  # m, the lift
SCENE = dict(drive="speed", rise_law="cycloidal", return_law="cycloidal", rise_angle=RISE, upper_dwell=RISE,
             return_angle=RISE, lower_dwell=RISE, lift=H, closure="kinematic", m=0.4, G=4.0)
ARM = dict(arm_length=0.15, pivot_distance=0.18, J_arm=2e-3, m_arm=0.2, r_cm_arm=0.07, psi_0=0.3)
KINDS = {"translating_flat": FollowerKind("translating_flat"),
         "oscillating_roller": FollowerKind("oscillating_roller", lift_angle=0.3, **ARM),
         "oscillating_flat": FollowerKind("oscillating_flat", lift_angle=0.15, **ARM)}


def cycloidal(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(s, s', s'') of the scene's program (tests/closed_forms.py: the cycloid's closed form, rise and mirrored return,
    dwells)."""
    return cycloid_program(theta, RISE, H)


@pytest.mark.parametrize("name", list(KINDS))
def test_constant_speed_load_torque_is_the_closed_form(name):
    """Friction and gravity off, omega constant: M = (J_arm + m L^2) psi' psi'' omega^2 (an arm, psi = lift_angle s / h)
    and m s' s'' omega^2 (a translating face); J = J_0 + (J_arm + m L^2) psi'^2, resp. J_0 + m s'^2; psi, psi_dot."""
    kind = KINDS[name]
    scene = dict(SCENE, gravity=False, guide_friction=False, shaft_friction=False)
    out = simulate_reference(scene, TURN, TURN / 997, omega_ref=constant(OMEGA), follower=kind)
    s, s1, s2 = cycloidal(out["theta"])
    J_0 = resolve(scene)["J_m"] + resolve(scene)["J_cam"]
    if kind.oscillating:
        k = kind.lift_angle / H
        I_f, q, q1, q2 = kind.J_arm + 0.4 * kind.arm_length ** 2, k * s, k * s1, k * s2
    else:
        I_f, q, q1, q2 = 0.4, np.zeros_like(s), s1, s2
    M = I_f * q1 * q2 * OMEGA ** 2
    assert np.max(np.abs(M)) > 1e-3  # N m: the follower loads the cam
    assert np.max(np.abs(out["M"] - M)) < 1e-13 * np.max(np.abs(M))
    assert np.max(np.abs(out["J"] - (J_0 + I_f * q1 ** 2))) < 1e-14
    assert np.max(np.abs(out["s"] - s)) < 1e-15 and np.max(np.abs(out["v"] - s1 * OMEGA)) < 1e-13
    if kind.oscillating:  # follower_load's constant-speed term agrees
        arm = arm_inertia_torque(0.4, kind.J_arm, kind.arm_length, q1, q2, OMEGA)
        assert np.max(np.abs(out["M"] - arm)) < 1e-13 * np.max(np.abs(M))
        assert np.max(np.abs(out["psi"] - q)) < 1e-15
        assert np.max(np.abs(out["psi_dot"] - q1 * OMEGA)) < 1e-13
    else:
        assert not np.any(out["psi"]) and not np.any(out["psi_dot"])


@pytest.mark.parametrize("name", ["oscillating_roller", "oscillating_flat"])
def test_constant_speed_arm_gravity_is_the_closed_form(name):
    """Gravity on (a vertical cam plane), friction off: the arm's weight adds (G L + m_arm g_n r_cm) cos(psi + psi_0)
    psi' to the torque: the follower's weight G at L, the arm's own at r_cm_arm."""
    kind = KINDS[name]
    scene = dict(SCENE, gravity=True, gamma=math.pi / 2, beta=0.0, guide_friction=False, shaft_friction=False)
    out = simulate_reference(scene, TURN, TURN / 997, omega_ref=constant(OMEGA), follower=kind)
    s, s1, s2 = cycloidal(out["theta"])
    k = kind.lift_angle / H
    psi, psi1, psi2 = k * s, k * s1, k * s2
    moment = 4.0 * kind.arm_length + kind.m_arm * KGF * kind.r_cm_arm
    M = (kind.J_arm + 0.4 * kind.arm_length ** 2) * psi1 * psi2 * OMEGA ** 2 + moment * np.cos(psi + kind.psi_0) * psi1
    assert np.max(np.abs(out["M"] - M)) < 1e-13 * np.max(np.abs(M))


def _stored(out: dict[str, np.ndarray], kind: FollowerKind, scene: dict) -> np.ndarray:
    """(1/2) J omega^2 + (1/2) L i^2 + the potential [J], written from the outputs: an arm's
    (G L + m_arm g_n r_cm) sin(psi + psi_0) (vertical plane), a translating face's G s (lifted against gravity)."""
    p = resolve(scene)
    if kind.oscillating:
        V = (p["G"] * kind.arm_length + kind.m_arm * KGF * kind.r_cm_arm) * np.sin(out["psi"] + kind.psi_0)
    else:
        V = p["G"] * out["s"]
    return 0.5 * out["J"] * out["omega"] ** 2 + 0.5 * p["L"] * out["i"] ** 2 + V


REVERSING = Signal((0.0, 0.3, 0.3, 0.6, 0.6), (12.0, 12.0, -6.0, -6.0, 1.0), hold=True)  # V: forward, back, stall
VOLTAGE = dict(SCENE, drive="voltage", gravity=True, gamma=math.pi / 2, mu=0.05, M_f=0.012, inductance=True, L=1e-3,
               J_cam=2e-4)


@pytest.mark.parametrize("name", list(KINDS))
@pytest.mark.parametrize("u, turns", [(constant(40.0), True), (REVERSING, False)])
def test_voltage_drive_energy_balance_with_friction_and_gravity(name, u, turns):
    """docs/model.md 9 with c_e = c_m: stored energy (from the outputs) - its start = E_in - E_copper - E_shaft -
    E_guide (the kind's friction loss), to 1e-11 of the electrical work: the cam turning at 40 V (0.25 s, over a
    turns), or driven forward, reversed and left to stall under gravity (1 s: stops, break-aways, the friction's branch
    changing)."""
    kind = KINDS[name]
    scene = dict(VOLTAGE, c_e=resolve({})["c_m"], beta=0.0 if kind.oscillating else math.pi)
    out = simulate_reference(scene, 0.25 if turns else 1.0, 1e-3, u=u, energy=True, follower=kind)
    stored = _stored(out, kind, scene)
    work = out["E_in"] - out["E_copper"] - out["E_shaft"] - out["E_guide"]
    scale = np.max(np.abs(out["E_in"]))
    assert out["E_guide"][-1] > 1e-4 * scale and out["E_shaft"][-1] > 1e-3 * scale  # both frictions act
    assert np.ptp(stored) > 5e-3 * scale  # energy moves in and out of the follower
    if turns:
        assert out["theta"][-1] > 2.0 * math.pi
    else:
        assert np.any(out["omega"] < 0.0)
    assert np.max(np.abs(stored - stored[0] - work)) < 1e-11 * scale


@pytest.mark.parametrize("drive", ["speed", "voltage"])
def test_translating_roller_and_no_kind_are_todays_reference_bit_for_bit(drive):
    """follower=None, FollowerKind() and no argument: every output equal, the energy integrals too."""
    scene = dict(SCENE, drive=drive, gravity=True, gamma=math.pi / 2, beta=math.pi, closure="form")
    kwargs = dict(omega_ref=constant(OMEGA), u=constant(12.0), energy=drive == "voltage")
    plain = simulate_reference(scene, TURN, TURN / 50, **kwargs)
    for follower in (None, FollowerKind(), FollowerKind("translating_roller")):
        same = simulate_reference(scene, TURN, TURN / 50, follower=follower, **kwargs)
        assert same.keys() == plain.keys() and not np.any(same["psi"]) and not np.any(same["psi_dot"])
        for name in plain:
            assert np.array_equal(plain[name], same[name]), name


@pytest.mark.parametrize("fields, word", [
    (dict(follower_type="rocker"), "follower_type"),
    (dict(follower_type="translating_flat", arm_length=0.1), "arm_length.*translating_flat"),
    (dict(follower_type="translating_roller", J_arm=1e-3), "J_arm.*translating_roller"),
    (dict(follower_type="oscillating_roller", arm_length=0.15, lift_angle=0.3), "pivot_distance"),
    (dict(follower_type="oscillating_roller", arm_length=-0.15, pivot_distance=0.2, lift_angle=0.3), "arm_length"),
    (dict(follower_type="oscillating_flat", arm_length=0.15, pivot_distance=0.2, lift_angle=4.0), "lift_angle"),
    (dict(follower_type="oscillating_flat", arm_length=0.15, pivot_distance=0.2, lift_angle=0.1, J_arm=math.nan),
     "J_arm"),
])
def test_bad_follower_kind_is_refused_by_name(fields, word):
    with pytest.raises(ParameterError, match=word):
        FollowerKind(**fields)


@pytest.mark.parametrize("scene, kind, word", [
    # a clearance needs a follower of its own (16.3): the kinematic rule, or 'form' without a mass, is refused
    (dict(SCENE, backlash=True, c=1e-4, closure="kinematic"), "translating_flat", "'c'"),
    (dict(SCENE, backlash=True, c=1e-4, closure="form", m=0.0, J_arm=0.0), "oscillating_roller", "'c'"),
    (dict(SCENE, drive="voltage", formulation="paper"), "oscillating_flat", "formulation"),
    (dict(SCENE, drive="voltage", k_shaft=100.0, J_cam=1e-4), "translating_flat", "k_shaft"),
    (dict(SCENE, gravity=True, gamma=math.pi / 2, beta=1.0), "oscillating_roller", "beta"),
    (dict(SCENE, r_b=0.2), "oscillating_flat", "pivot"),  # d = 0.18 m inside the base circle
    (dict(SCENE, lift=0.1, r_b=0.01), "translating_flat", "r_b"),  # rho = r_b + s + s'' < 0: a cusp
    # J_0 + m s' (s' - mu (r_b + s)) < 0 on the rise: the face's friction would wedge it
    (dict(SCENE, drive="voltage", mu=0.5, J_cam=0.0), "translating_flat", "'mu'.*wedge"),
])
def test_kind_where_the_reference_cannot_run_it_is_refused(scene, kind, word):
    with pytest.raises(ParameterError, match=word):
        simulate_reference(scene, 0.1, 0.01, omega_ref=constant(OMEGA), follower=KINDS[kind])


@pytest.mark.parametrize("kind", ["oscillating_roller", "oscillating_flat"])
def test_train_on_an_arm_is_refused(kind):
    """An arm's train is torsional, set by its own parameters (tests/engine/test_engine_train_arm.py): a train given
    along X is refused; the translating flat's runs (tests/engine/test_engine_train_flat_reference.py)."""
    with pytest.raises(ParameterError, match="train.*follower_type"):
        simulate_reference(SCENE, 0.1, 0.01, omega_ref=constant(OMEGA), follower=KINDS[kind],
                           train=Train(k_train=1e6, m_end=1.0))


@pytest.mark.parametrize("name", list(KINDS))
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_friction_power_is_the_drive_equations_on_either_branch(name, side):
    """The power balance of each instant, on the friction branch the integrator holds, also where P has crossed 0
    and the event that flips the branch has not fired yet (an integrator's step past the root): the motor's power
    less the shaft's friction = d/dt (1/2 J omega^2 + V) + friction_power(load, side), with J' = 2 I_f q' q'' and
    dV/dt = dV/dq q' omega written here. E_guide integrates this loss (|P| would have a kink inside the step)."""
    from cam_fmu.physics.kind_drive import KindDriveModel

    kind = KINDS[name]
    scene = dict(VOLTAGE, drive="voltage", beta=0.0 if kind.oscillating else math.pi)
    model = KindDriveModel(scene, kind)
    p = resolve(scene)
    k = kind.lift_angle / H if kind.oscillating else 1.0
    I_f = (kind.J_arm + 0.4 * kind.arm_length ** 2) if kind.oscillating else 0.4
    crossed = 0
    for theta in np.linspace(0.05, 2.0 * math.pi - 0.05, 37):
        for omega, torque in ((35.0, 0.2), (-20.0, -0.05), (80.0, 0.0)):
            d = math.copysign(1.0, omega)
            omega_dot = model.omega_dot(theta, omega, torque, d, side=side)
            load = model.load(theta, omega, omega_dot, d)
            s, s1, s2 = (float(x[0]) for x in cycloidal(np.array([theta])))
            q, q1, q2 = k * s, k * s1, k * s2
            if kind.oscillating:
                dV = (p["G"] * kind.arm_length + kind.m_arm * KGF * kind.r_cm_arm) * math.cos(q + kind.psi_0)
            else:
                dV = p["G"]  # lifted against its weight
            J = p["J_m"] + p["J_cam"] + I_f * q1 * q1
            rate = J * omega * omega_dot + I_f * q1 * q2 * omega ** 3 + dV * q1 * omega
            balance = torque * omega - p["M_f"] * abs(omega) - rate - model.friction_power(load, side)
            assert abs(balance) < 1e-12 * (abs(torque * omega) + abs(rate) + 1.0), (theta, omega)
            if side * load.P >= 0.0:  # the branch holds: the load torque's power feeds the follower and the loss
                follower = I_f * q1 * q1 * omega * omega_dot + I_f * q1 * q2 * omega ** 3 + dV * q1 * omega
                assert load.M * omega == pytest.approx(follower + p["M_f"] * abs(omega) + load.loss, rel=1e-12,
                                                       abs=1e-12)
            else:
                crossed += 1
    assert crossed > 0  # some states lie past P's zero on the held branch


@pytest.mark.parametrize("name", ["translating_flat", "oscillating_flat"])
def test_flat_face_friction_torque_from_the_envelopes_contact(name):
    """Speed drive at 10 rad/s, gravity and shaft friction off, mu = 0.05: the friction's share of the torque,
    M - P q', is mu |N| times the sliding speed over omega, taken from the contact point of the contour (the
    envelope, kinematics/flat_cam.py) turned to the fixed frame: the cam's surface speed there along the face,
    |omega| |(-y, x) . t| (the face's own points move across it: along a translating face not at all, an
    oscillating face passes through its pivot), with N = P / l, l the contact's distance from the pivot (P along X
    on a translating face); P = I_f q'' omega^2 at constant speed."""
    from cam_fmu.physics.kind_drive import KindDriveModel

    kind = KINDS[name]
    scene = dict(SCENE, gravity=False, shaft_friction=False, mu=0.05)
    cam = KindDriveModel(scene, kind).cam
    out = simulate_reference(scene, TURN, TURN / 97, omega_ref=constant(OMEGA), follower=kind)
    theta = out["theta"]
    s, s1, s2 = cycloidal(theta)
    cx, cy = cam.contour(theta)
    x, y = np.cos(theta) * cx - np.sin(theta) * cy, np.sin(theta) * cx + np.cos(theta) * cy  # the fixed frame
    if kind.oscillating:
        k, d, r_b = kind.lift_angle / H, kind.pivot_distance, resolve(scene)["r_b"]
        I_f, q, q1, q2 = kind.J_arm + 0.4 * kind.arm_length ** 2, k * s, k * s1, k * s2
        l = np.hypot(x - r_b, y - math.sqrt(d * d - r_b * r_b))
        slide = np.abs(y * np.sin(q) + x * np.cos(q))  # (-y, x) . (-sin psi, cos psi)
    else:
        I_f, q1, q2, l, slide = 0.4, s1, s2, 1.0, np.abs(x)
    P = I_f * q2 * OMEGA ** 2
    friction = 0.05 * np.abs(P) / l * slide
    assert np.max(friction) > 1e-3  # N m
    assert np.max(np.abs(out["M"] - P * q1 - friction)) < 1e-12 * np.max(friction)


def test_roller_arm_contact_force_carries_the_torque():
    """Speed drive at 10 rad/s with friction and gravity: the contact's torque about the pivot, N_contact L cos(alpha),
    times psi' is the cam's load torque less the shaft's friction (virtual work, as 4.3's identity for the
    translating roller); alpha the pressure angle of the triangle (15.1) written here."""
    kind = KINDS["oscillating_roller"]
    scene = dict(SCENE, gravity=True, gamma=math.pi / 2, beta=0.0, mu=0.05)
    out = simulate_reference(scene, TURN, TURN / 97, omega_ref=constant(OMEGA), follower=kind)
    s, s1, _ = cycloidal(out["theta"])
    k, L, d, r_b = kind.lift_angle / H, kind.arm_length, kind.pivot_distance, resolve(scene)["r_b"]
    delta = math.acos((d * d + L * L - r_b * r_b) / (2 * d * L)) + k * s
    alpha = np.arctan2(d * np.cos(delta) - L * (1.0 - k * s1), d * np.sin(delta))
    assert np.max(np.abs(out["alpha"] - alpha)) < 1e-12
    torque = out["N_contact"] * L * np.cos(alpha) * k * s1
    load = out["M"] - resolve(scene)["M_f"]
    assert np.max(np.abs(load)) > 0.1  # N m
    assert np.max(np.abs(torque - load)) < 1e-12 * np.max(np.abs(load))


@pytest.mark.parametrize("name", list(KINDS))
def test_voltage_drive_is_lagranges_equation_integrated_here(name):
    """Voltage drive at 40 V, L = 0, gravity on, friction off: the reference's theta(t) and omega(t) are those of
    Lagrange's equation written here and integrated by scipy's Radau (not the reference's DOP853 and events):
    (J_0 + I_f q'^2) omega' = c_m (u - c_e omega) / R - I_f q' q'' omega^2 - dV/dq q', q and its derivatives from
    the cycloidal law's closed form (its acceleration is continuous at the breakpoints)."""
    from scipy.integrate import solve_ivp

    kind = KINDS[name]
    scene = dict(VOLTAGE, inductance=False, shaft_friction=False, guide_friction=False,
                 beta=0.0 if kind.oscillating else math.pi)
    p = resolve(scene)
    J_0, u = p["J_m"] + p["J_cam"], 40.0
    k = kind.lift_angle / H if kind.oscillating else 1.0
    I_f = (kind.J_arm + 0.4 * kind.arm_length ** 2) if kind.oscillating else 0.4
    W = p["G"] * kind.arm_length + kind.m_arm * KGF * kind.r_cm_arm if kind.oscillating else 0.0

    def rhs(t, y):
        s, s1, s2 = (float(x[0]) for x in cycloidal(np.array([y[0]])))
        q, q1, q2 = k * s, k * s1, k * s2
        dV = W * math.cos(q + kind.psi_0) if kind.oscillating else p["G"]
        torque = p["c_m"] * (u - p["c_e"] * y[1]) / p["R"]
        return [y[1], (torque - I_f * q1 * q2 * y[1] ** 2 - dV * q1) / (J_0 + I_f * q1 * q1)]

    grid = np.linspace(0.0, 0.3, 31)
    own = solve_ivp(rhs, (0.0, 0.3), [0.0, 0.0], method="Radau", t_eval=grid, rtol=1e-11, atol=1e-12)
    out = simulate_reference(scene, 0.3, 0.01, u=constant(u), follower=kind)
    assert out["theta"][-1] > 1.0  # rad: the cam turns through the rise
    assert np.max(np.abs(out["theta"] - own.y[0])) < 1e-8
    assert np.max(np.abs(out["omega"] - own.y[1])) < 1e-7 * np.max(np.abs(own.y[1]))
