"""A follower of its own for every kind in the reference (docs/model.md 16.3), against independent sources: the flight
against its closed form (an arm under the spring: harmonic in psi; a flat face under gravity: a parabola), the impact
law with numbers written here, the energy balance of docs/model.md 9 with the stored energy written here from the
outputs, and the jump speed computed here on a fine grid from the cycloidal law's closed form."""
from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from closed_forms import cycloid_program

from cam_fmu.physics.follower_kind import FollowerKind
from cam_fmu.physics.kind_drive import KindDriveModel
from cam_fmu.physics.kind_follower import KindSpeedFollower, KindVoltageFollower
from cam_fmu.physics.parameters import resolve
from cam_fmu.physics.signals import Signal, constant
from cam_fmu.reference import simulate_reference

G_N = 9.80665  # m/s2, standard gravity
RISE = math.pi / 2  # rad: cycloidal rise, dwell, cycloidal return, dwell, 90 deg each
H = 0.02  # m, the lift
SCENE = dict(drive="speed", rise_law="cycloidal", return_law="cycloidal", rise_angle=RISE, upper_dwell=RISE,
             return_angle=RISE, lower_dwell=RISE, lift=H, m=0.4, G=4.0, r_b=0.08)
ARM = dict(arm_length=0.15, pivot_distance=0.18, J_arm=2e-3, m_arm=0.2, r_cm_arm=0.07, psi_0=0.3)
KINDS = {"translating_flat": FollowerKind("translating_flat"),
         "oscillating_roller": FollowerKind("oscillating_roller", lift_angle=0.3, **ARM),
         "oscillating_flat": FollowerKind("oscillating_flat", lift_angle=0.15, **ARM)}
QUIET = dict(gravity=False, guide_friction=False, shaft_friction=False)


def cycloidal(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(s, s', s'') of the scene's program (tests/closed_forms.py: the cycloid's closed form, rise and mirrored return,
    dwells)."""
    return cycloid_program(theta, RISE, H)


def inertia(kind: FollowerKind, m: float = 0.4) -> float:
    """I_f: m for a translating face, J_arm + m L^2 for an arm."""
    return kind.J_arm + m * kind.arm_length ** 2 if kind.oscillating else m


def coordinate(kind: FollowerKind, theta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, q', q'') from the closed form: s, or psi = lift_angle s / h."""
    k = kind.lift_angle / H if kind.oscillating else 1.0
    s, s1, s2 = cycloidal(theta)
    return k * s, k * s1, k * s2


def flights(out: dict) -> list[np.ndarray]:
    """Index runs of rows in one flight: contact 0 and no impact between them."""
    free = (out["contact"] == 0.0)
    runs, start = [], None
    for j in range(len(free) + 1):
        inside = j < len(free) and free[j] and (start is None or out["impacts"][j] == out["impacts"][start])
        if inside and start is None:
            start = j
        elif not inside and start is not None:
            runs.append(np.arange(start, j))
            start = j if j < len(free) and free[j] else None
    return runs


def test_arm_flight_under_the_spring_is_harmonic_in_psi():
    """Gravity off: in flight (J_arm + m L^2) psi'' = -L (F0 + k L psi), harmonic with omega_n = sqrt(k L^2 / I_f)
    about psi_eq = -F0 / (k L); each flight's rows against the closed form from its first row."""
    kind, k, F0 = KINDS["oscillating_roller"], 2000.0, 20.0
    out = simulate_reference(dict(SCENE, **QUIET, closure="spring", k_spring=k, F_spring0=F0), 0.3, 5e-5,
                             omega_ref=constant(60.0), follower=kind)
    L, I_f = kind.arm_length, inertia(kind)
    wn, psi_eq = math.sqrt(k * L * L / I_f), -F0 / (k * L)
    runs = [r for r in flights(out) if len(r) > 20]
    assert len(runs) >= 3 and out["impacts"][-1] >= 3
    worst = 0.0
    for r in runs:
        t = out["time"][r] - out["time"][r[0]]
        psi0, rate0 = out["psi"][r[0]], out["psi_dot"][r[0]]
        psi = psi_eq + (psi0 - psi_eq) * np.cos(wn * t) + rate0 / wn * np.sin(wn * t)
        worst = max(worst, float(np.max(np.abs(out["psi"][r] - psi))))
        assert np.allclose(out["s"][r], out["psi"][r] * H / kind.lift_angle, rtol=1e-14, atol=0.0)
        assert not np.any(out["N_contact"][r])
    assert worst < 1e-9  # rad


def test_flat_face_flight_under_gravity_is_a_parabola():
    """A vertical cam lifting a flat face against gravity (F_gx = -G), a constant preload, no rate: in flight
    m s'' = -(F0 + G), each flight's rows on the parabola from its first row."""
    kind, F0, m, G = KINDS["translating_flat"], 1.0, 0.4, 4.0
    scene = dict(SCENE, closure="spring", k_spring=0.0, F_spring0=F0, gravity=True, gamma=math.pi / 2,
                 beta=math.pi, guide_friction=False, shaft_friction=False)
    out = simulate_reference(scene, 0.5, 5e-5, omega_ref=constant(30.0), follower=kind)
    runs = [r for r in flights(out) if len(r) > 20]
    assert len(runs) >= 2
    worst = 0.0
    for r in runs:
        t = out["time"][r] - out["time"][r[0]]
        s = out["s"][r[0]] + out["v"][r[0]] * t - 0.5 * (F0 + G) / m * t * t
        worst = max(worst, float(np.max(np.abs(out["s"][r] - s))))
        assert np.max(np.abs(out["a"][r] + (F0 + G) / m)) < 1e-12
        assert not np.any(out["psi"][r])
    assert worst < 1e-10  # m


@pytest.mark.parametrize("name", list(KINDS))
def test_touch_down_keeps_the_momentum_and_reverses_w_by_e(name):
    """The impact in q on the voltage-driven cam: J_0 omega + I_f q' q_f_dot kept, w = q_f_dot - q' omega -> -e w,
    loss (1 - e^2) m_eff w^2 / 2 with m_eff = I_f J_0 / (J_0 + I_f q'^2); at imposed speed omega is kept and
    w -> -e w. Numbers (q', I_f, J_0) written here."""
    kind, e, theta, omega = KINDS[name], 0.5, 0.6, 20.0
    params = dict(SCENE, **QUIET, drive="voltage", closure="spring", k_spring=100.0, F_spring0=5.0, restitution=e,
                  J_cam=2e-4)
    J_0 = resolve(params)["J_m"] + 2e-4
    I_f = inertia(kind)
    q, q1, _ = (float(x[0]) for x in coordinate(kind, np.array([theta])))
    body = KindVoltageFollower(KindDriveModel(params, kind))
    body.heading = 1.0
    w = -0.4 if not kind.oscillating else -0.4 / kind.arm_length  # m/s, or rad/s about the pivot
    rate = q1 * omega + w
    after, state, hit = body.land([theta, omega, 0.0, q, rate], 0.0, 1.0)
    assert after == 0.0  # it rebounds
    assert state[3] == pytest.approx(q, abs=1e-15)
    momentum = J_0 * omega + I_f * q1 * rate
    assert J_0 * state[1] + I_f * q1 * state[4] == pytest.approx(momentum, rel=1e-13)
    assert state[4] - q1 * state[1] == pytest.approx(-e * w, rel=1e-12)
    m_eff = I_f * J_0 / (J_0 + I_f * q1 * q1)
    assert hit.loss == pytest.approx(0.5 * (1 - e * e) * m_eff * w * w, rel=1e-12)
    assert state[1] < omega  # the cam is braked by the follower it strikes from above
    speed = KindSpeedFollower(KindDriveModel(dict(params, drive="speed"), kind))
    after, rate_after, _ = speed.land(theta, omega, 0.0, rate, 1.0)
    assert after == 0.0 and rate_after - q1 * omega == pytest.approx(-e * w, rel=1e-12)


def test_a_slow_arm_touch_down_is_plastic_below_the_zeno_height_along_its_path():
    """The Zeno guard's height is 1 nm along the roller's path: an arm's rebound w^2 < 2 A 1e-9 / L [rad/s] is
    plastic, one above it rebounds (A the acceleration scale the body reports, rad/s2)."""
    kind = KINDS["oscillating_roller"]
    params = dict(SCENE, **QUIET, drive="speed", closure="spring", k_spring=100.0, F_spring0=5.0, restitution=0.5)
    body = KindSpeedFollower(KindDriveModel(params, kind))
    theta, omega = 0.6, 5.0
    q1 = float(coordinate(kind, np.array([theta]))[1][0])
    A = body.acceleration_scale(theta, omega, 0.0)
    limit = math.sqrt(2.0 * A * 1e-9 / kind.arm_length)  # the rebound's relative rate at 1 nm along the path
    for factor, plastic in ((0.9, True), (1.1, False)):
        w_in = -factor * limit / 0.5  # rad/s before: the rebound is e = 0.5 of it
        after, rate, _ = body.land(theta, omega, 0.0, q1 * omega + w_in, 1.0)
        assert (after == 1.0) is plastic
        assert (rate == pytest.approx(q1 * omega, abs=1e-15)) is plastic


def stored(kind: FollowerKind, out: dict, p: dict) -> np.ndarray:
    """J: (1/2) J_0 omega^2 + (1/2) I_f q_f_dot^2 + V_close(q_f) + (1/2) L i^2, written from 16.3 and the outputs
    (the vertical cam plane: gamma = 90 deg; a translating face lifts against gravity, beta = 180 deg)."""
    J_0 = p["J_m"] + p["J_cam"]
    k, F0 = p["k_spring"], p["F_spring0"]
    if kind.oscillating:
        L = kind.arm_length
        q, qd = out["psi"], out["psi_dot"]
        W = p["G"] * L + kind.m_arm * G_N * kind.r_cm_arm
        V = L * F0 * q + 0.5 * k * L * L * q * q + W * np.sin(q + kind.psi_0)
    else:
        q, qd = out["s"], out["v"]
        V = F0 * q + 0.5 * k * q * q + p["G"] * q
    return 0.5 * J_0 * out["omega"] ** 2 + 0.5 * inertia(kind, p["m"]) * qd ** 2 + V + 0.5 * p["L"] * out["i"] ** 2


BALANCE = {  # closure -> its parameters; each run lifts off and strikes the cam
    "spring": dict(closure="spring", k_spring=50.0, F_spring0=0.5),
    "form": dict(closure="form", backlash=True, c=3e-4),
}


@pytest.mark.parametrize("closure", list(BALANCE))
@pytest.mark.parametrize("name", list(KINDS))
def test_energy_balance_with_friction_gravity_and_impacts(name, closure):
    """docs/model.md 9 with 16.3's stored energy: its change is E_in - E_copper - E_shaft - E_guide - E_impact, the
    cam driven forward at 40 V, back at -12 V, then 1 V (stops, flights, impacts), mu = 0.05, gravity on."""
    kind = KINDS[name]
    params = dict(SCENE, **BALANCE[closure], drive="voltage", gravity=True, gamma=math.pi / 2,
                  beta=0.0 if kind.oscillating else math.pi, mu=0.05, guide_friction=True, shaft_friction=True,
                  M_f=0.012, L=1e-3, restitution=0.5, J_cam=2e-4)
    params["c_e"] = resolve(params)["c_m"]  # the motor's power balance: back-EMF constant = torque constant
    p = resolve(params)
    u = Signal((0.0, 0.12, 0.2), (40.0, -12.0, 1.0), hold=True)
    out = simulate_reference(params, 0.3, 5e-4, u=u, follower=kind, energy=True)
    assert out["impacts"][-1] >= 2 and np.any(out["contact"] == 0.0)
    assert out["E_guide"][-1] > 1e-4
    E = stored(kind, out, p)
    books = out["E_in"] - out["E_copper"] - out["E_shaft"] - out["E_guide"] - out["E_impact"]
    error = np.max(np.abs((E - E[0]) - books))
    assert error < 1e-10 * out["E_in"].max(), (error, out["E_in"].max())


def jump_speed(kind: FollowerKind, k: float, F0: float) -> float:
    """rad/s: min over q'' < 0 of sqrt(Q_close(q) / (I_f |q''|)) on a grid of 2,000,001 angles over a turn, from the
    cycloid's closed form (gravity off: Q_close = l (F0 + k l q), l = L for an arm, 1 for a face)."""
    theta = np.linspace(0.0, 2.0 * math.pi, 2_000_001)
    q, _, q2 = coordinate(kind, theta)
    l = kind.arm_length if kind.oscillating else 1.0
    Q = l * (F0 + k * l * q)
    falling = q2 < 0.0
    return float(np.sqrt(np.min(Q[falling] / (inertia(kind) * -q2[falling]))))


@pytest.mark.parametrize("name", ["oscillating_roller", "translating_flat"])
def test_spring_closed_follower_jumps_at_the_closed_form_speed(name):
    """At constant speed (gravity off) the contact holds through a turn at 0.98 omega_jump and is lost at 1.02."""
    kind, k, F0 = KINDS[name], 2000.0, 20.0
    omega_jump = jump_speed(kind, k, F0)
    scene = dict(SCENE, **QUIET, closure="spring", k_spring=k, F_spring0=F0)
    for factor, held in ((0.98, True), (1.02, False)):
        omega = factor * omega_jump
        turn = 2.0 * math.pi / omega
        out = simulate_reference(scene, 1.05 * turn, turn / 2000, omega_ref=constant(omega), follower=kind)
        assert bool(np.all(out["contact"] == 1.0) and out["impacts"][-1] == 0.0) is held, factor
        if not held:  # the lift-off happens where the law decelerates the follower
            j = int(np.argmax(out["contact"] == 0.0))
            assert coordinate(kind, out["theta"][j:j + 1])[2][0] < 0.0


def test_translating_roller_own_follower_is_not_routed_through_the_kind():
    """follower=None and FollowerKind() give the translating roller's follower of its own (13), equal arrays."""
    scene = dict(SCENE, **QUIET, closure="spring", k_spring=2000.0, F_spring0=20.0)
    a = simulate_reference(scene, 0.1, 1e-3, omega_ref=constant(60.0))
    b = simulate_reference(scene, 0.1, 1e-3, omega_ref=constant(60.0), follower=FollowerKind())
    assert a.keys() == b.keys() and all(np.array_equal(a[n], b[n]) for n in a)
    assert a["impacts"][-1] > 0


def test_cli_runs_a_spring_closed_rocker_on_the_reference(tmp_path):
    """`cam-fmu simulate packaging_rocker --engine reference` with closure 'spring' runs: the arm's own angle leaves
    the cam's (the rows in flight) and the CSV has psi, psi_dot, contact, impacts."""
    run = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "simulate", "packaging_rocker", "--engine",
                          "reference", "--out", str(tmp_path), "--stop-time", "0.05", "--no-plot",
                          "--set", "closure=spring", "--set", "k_spring=200", "--set", "F_spring0=2"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    header = (tmp_path / "packaging_rocker.csv").read_text().splitlines()[0]
    for column in ("psi [rad]", "psi_dot [rad/s]", "contact", "impacts"):
        assert column in header


@pytest.mark.parametrize("name, closure", [("oscillating_flat", "spring"), ("translating_flat", "form"),
                                           ("oscillating_roller", "form")])
def test_speed_drive_rows_on_the_flank_are_the_closed_form(name, closure):
    """At 20 rad/s (gravity in a vertical plane, friction off) on the +1 flank: q_f = q - c_q, P = I_f q'' omega^2 +
    Q_close(q_f), M = P q', J = J_0 + I_f q'^2, N_contact 16's (P on a translating face, P (1 - psi') / (d cos(delta0 +
    psi)) on an oscillating one), all written here from the cycloid's closed form; rows in flight M = 0, J = J_0,
    N_contact = 0."""
    kind, omega, k, F0, c = KINDS[name], 20.0, 300.0, 3.0, 3e-4
    extra = dict(closure="spring", k_spring=k, F_spring0=F0) if closure == "spring" else \
        dict(closure="form", backlash=True, c=c, restitution=0.3)
    scene = dict(SCENE, **extra, gravity=True, gamma=math.pi / 2, beta=0.0 if kind.oscillating else math.pi,
                 guide_friction=False, shaft_friction=False)
    out = simulate_reference(scene, 2 * math.pi / omega, 2e-4, omega_ref=constant(omega), follower=kind)
    p = resolve(scene)
    J_0, I_f = p["J_m"] + p["J_cam"], inertia(kind)
    q, q1, q2 = coordinate(kind, out["theta"])
    l = kind.arm_length if kind.oscillating else 1.0
    c_q = c / l if closure == "form" else 0.0
    q_f = q - c_q
    if kind.oscillating:  # dV/dq: the arm's weight about its pivot
        slope = (p["G"] * l + kind.m_arm * G_N * kind.r_cm_arm) * np.cos(q_f + kind.psi_0)
    else:  # F_gx = -G: the face lifted against gravity
        slope = p["G"]
    k_, F0_ = (k, F0) if closure == "spring" else (0.0, 0.0)
    P = I_f * q2 * omega ** 2 + l * (F0_ + k_ * l * q_f) + slope
    on = out["contact"] == 1.0
    assert on.sum() > 100
    if closure == "form":
        assert np.any(out["contact"] != 1.0)  # it crosses the groove somewhere in the turn
    own = out["psi"] if kind.oscillating else out["s"]
    scale = np.max(np.abs(P * q1))
    assert np.max(np.abs(own[on] - q_f[on])) < 1e-15
    assert np.max(np.abs(out["M"][on] - (P * q1)[on])) < 1e-12 * scale
    assert np.max(np.abs(out["J"][on] - (J_0 + I_f * q1 ** 2)[on])) < 1e-15
    if name == "oscillating_flat":
        delta0 = math.asin(p["r_b"] / kind.pivot_distance)
        N = P * (1.0 - q1) / (kind.pivot_distance * np.cos(delta0 + q))
    else:
        N = P if not kind.oscillating else None
    if N is not None:
        assert np.max(np.abs(out["N_contact"][on] - N[on])) < 1e-12 * np.max(np.abs(N))
    off = out["contact"] == 0.0
    assert not np.any(out["M"][off]) and not np.any(out["N_contact"][off])
    assert np.all(out["J"][off] == J_0)
