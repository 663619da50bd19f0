"""The follower of its own for every kind in the C engine (docs/model.md 16.3): a translating flat face, an
oscillating roller and an oscillating flat face lifting off, flying and striking the cam, checked against what the
test writes itself: the energy stored in the cam side and the follower (kinetic, spring, weight) of a coasting drive,
kept across flights and elastic impacts; the impact's momentum and restitution from the event log; an arm's flight
against the harmonic closed form of I_f psi'' = -L (F0 + k L psi); the jump speed of a spring-closed follower at
constant speed from the cycloid's closed form, the contact held at 0.98 of it and lost at 1.02."""
from __future__ import annotations

import math

import numpy as np
import pytest
from closed_forms import cycloid_program

from cam_fmu.engine.simulator import DriveSimulator
from cam_fmu.physics.parameters import defaults

G_N = 9.80665
RISE = math.pi / 2   # rad: a cycloidal rise, dwell, cycloidal return, dwell
LIFT = 0.02          # m
SCENE = dict(rise_law="cycloidal", return_law="cycloidal", rise_angle=RISE, upper_dwell=RISE, return_angle=RISE,
             lower_dwell=RISE, lift=LIFT, r_b=0.08, m=0.4, G=4.0, M_f=0.0, mu=0.0, J_cam=2e-3)
ARM = dict(arm_length=0.15, pivot_distance=0.18, J_arm=2e-3, m_arm=0.2, r_cm_arm=0.07, psi_0=0.3)
KINDS = {"translating_flat": dict(follower_type="translating_flat", beta=0.3),
         "oscillating_roller": dict(follower_type="oscillating_roller", lift_angle=0.3, **ARM),
         "oscillating_flat": dict(follower_type="oscillating_flat", lift_angle=0.15, **ARM)}
CLOSURES = {"form": dict(closure="form", c=5e-4), "spring": dict(closure="spring", k_spring=500.0, F_spring0=5.0)}
# A drive that coasts: the motor's torque c_m (u - c_e omega) / R at u = 0 is below 1e-14 N m.
COAST = dict(R=1e4, c_e=1e-6, c_m=1e-6, omega0=60.0, drive="voltage", formulation="consistent", gravity=True,
             gamma=1.2)


def law(theta: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The program's lift s [m] and its theta-derivatives s', s'' at theta [rad] (tests/closed_forms.py: the cycloid's
    closed form)."""
    return cycloid_program(theta, RISE, LIFT)


def inertia(p: dict) -> float:
    """I_f [kg, or kg m2 about an arm's pivot]."""
    return p["J_arm"] + p["m"] * p["arm_length"] ** 2 if p["follower_type"].startswith("oscillating") else p["m"]


def stored_energy(p: dict, out: dict) -> float:
    """J: the cam side's and the follower's kinetic energy, the spring's and the weight's potential, from the
    outputs (psi, psi_dot for an arm; s, v for a translating face)."""
    J0 = p["J_m"] + p["J_cam"]
    F0, k = p.get("F_spring0", 0.0), p.get("k_spring", 0.0)
    if p["follower_type"].startswith("oscillating"):
        L, q = p["arm_length"], out["psi"]
        W = (p["G"] * L + p["m_arm"] * G_N * p["r_cm_arm"]) * math.sin(p["gamma"])
        return (0.5 * J0 * out["omega"] ** 2 + 0.5 * inertia(p) * out["psi_dot"] ** 2 + L * F0 * q
                + 0.5 * k * L * L * q * q + W * math.sin(q + p["psi_0"]))
    F_gx = p["G"] * math.sin(p["gamma"]) * math.cos(p["beta"])
    q = out["s"]
    return 0.5 * J0 * out["omega"] ** 2 + 0.5 * p["m"] * out["v"] ** 2 + F0 * q + 0.5 * k * q * q - F_gx * q


def coast(kind: str, closure: str, restitution: float, steps: int = 1000):
    """The coasting drive's parameters, outputs every ms and its event log."""
    p = dict(defaults(), **SCENE, **KINDS[kind], **CLOSURES[closure], **COAST, restitution=restitution)
    sim = DriveSimulator(p)
    sim.set_inputs(0.0, 0.0, 0.0)
    rows = [sim.outputs()]
    for k in range(steps):
        sim.do_step(k * 1e-3, 1e-3, u=0.0, omega_ref=0.0, omega_dot_ref=0.0)
        rows.append(sim.outputs())
    return p, rows, sim.events()


@pytest.mark.parametrize("closure", list(CLOSURES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_a_coasting_drive_keeps_its_energy_through_flights_and_elastic_impacts(kind, closure):
    """Restitution 1, no friction, no motor torque: the stored energy written in the test from the outputs stays
    constant while the follower flies and strikes (measured 3.5e-11 .. 3.6e-10 J of 3.9 J over 1 s)."""
    p, rows, events = coast(kind, closure, 1.0)
    energy = np.array([stored_energy(p, out) for out in rows])
    assert np.max(np.abs(energy - energy[0])) < 1e-9 * energy[0]
    touches = [e for e in events if e["name"] in ("engage_up", "engage_down")]
    assert len(touches) >= 10   # it flies and lands, over and over
    assert sum(out["N_contact"] == 0.0 for out in rows) > 100
    if kind.startswith("oscillating"):   # the arm's own angle leaves the cam's: the gap in rad, c / L in a groove
        psi_cam = p["lift_angle"] / LIFT * law(np.array([out["theta"] for out in rows]))[0]
        gap = np.array([out["psi"] for out in rows]) - psi_cam
        assert np.max(np.abs(gap)) > 1e-4
        if closure == "form":
            assert np.max(np.abs(gap)) < p["c"] / p["arm_length"] * (1 + 1e-9)


@pytest.mark.parametrize("kind", list(KINDS))
def test_an_impact_keeps_the_momentum_and_reverses_the_relative_rate_by_restitution(kind):
    """From the event log's state before and after each rebound in a groove: J_0 omega + I_f q' q_f_dot is kept
    and the follower's rate relative to the flank struck goes from w to -e w (e = 0.6), with q' from the cycloid."""
    e = 0.6
    p, _, events = coast(kind, "form", e, steps=400)
    J0, I = p["J_m"] + p["J_cam"], inertia(p)
    scale = p["lift_angle"] / LIFT if kind.startswith("oscillating") else 1.0
    along = p["arm_length"] if kind.startswith("oscillating") else 1.0   # the gap's slots: m along the path
    checked = 0
    for event in events:
        if event["name"] not in ("engage_up", "engage_down"):
            continue
        before, after, left = event["before"], event["after"], event["mode_before"]["left"]
        flank = 1 if event["name"] == "engage_up" else -1
        q1 = scale * float(law(before[0])[1])
        if left != flank or after[-1] == 0.0:   # a rebound off the flank it left: w and -e w relative to it
            continue
        w_before, w_after = left * before[-1], left * after[-1]   # the gap's rate is signed by the flank left
        momentum = [J0 * x[1] + I * q1 * (q1 * x[1] + left * x[-1] / along) for x in (before, after)]
        assert abs(momentum[1] - momentum[0]) < 1e-12 * abs(momentum[0])
        assert abs(w_after + e * w_before) < 1e-12 * abs(w_before)
        checked += 1
    assert checked >= 5


@pytest.mark.parametrize("kind", ["oscillating_roller", "oscillating_flat"])
def test_an_arms_flight_is_the_harmonic_of_its_spring_about_the_pivot(kind):
    """Gravity off, closure spring: from each lift-off (gap and rate 0, psi = psi(theta), psi_dot = psi' omega) the
    engine's psi follows psi_eq + (psi_0 - psi_eq) cos(w t) + psi_dot_0 / w sin(w t), w = sqrt(k L^2 / I_f),
    psi_eq = -F0 / (k L), until it lands (rk45 at the engine's tolerances: measured within 8.8e-14 rad)."""
    p = dict(defaults(), **SCENE, **KINDS[kind], **CLOSURES["spring"], **COAST, restitution=0.3)
    p["gravity"] = False
    sim = DriveSimulator(p)
    sim.set_inputs(0.0, 0.0, 0.0)
    times, rows = [0.0], [sim.outputs()]
    for k in range(600):
        sim.do_step(k * 2e-4, 2e-4, u=0.0, omega_ref=0.0, omega_dot_ref=0.0)
        times.append((k + 1) * 2e-4)
        rows.append(sim.outputs())
    L, k_s, F0, I = p["arm_length"], p["k_spring"], p["F_spring0"], inertia(p)
    w, psi_eq, scale = math.sqrt(k_s * L * L / I), -F0 / (k_s * L), p["lift_angle"] / LIFT
    events = sim.events()
    compared = 0
    for n, event in enumerate(events):
        if event["name"] != "contact":
            continue
        t0, theta0, omega0 = event["time"], event["after"][0], event["after"][1]
        psi0, psi_dot0 = scale * float(law(theta0)[0]), scale * float(law(theta0)[1]) * omega0
        end = events[n + 1]["time"] if n + 1 < len(events) else times[-1]
        for t, out in zip(times, rows):
            if t0 < t < end:
                tau = t - t0
                expected = psi_eq + (psi0 - psi_eq) * math.cos(w * tau) + psi_dot0 / w * math.sin(w * tau)
                assert abs(out["psi"] - expected) < 1e-11, (t, out["psi"], expected)
                assert out["N_contact"] == 0.0
                compared += 1
    assert compared >= 20


def jump_speed(p: dict) -> float:
    """rad/s: min over q'' < 0 of sqrt(C(q) / (I_f |q''|)) on the rise, C the spring's closing force (torque)."""
    theta = np.linspace(0.0, RISE, 400001)
    s, _, s2 = law(theta)
    if p["follower_type"].startswith("oscillating"):
        scale, L = p["lift_angle"] / LIFT, p["arm_length"]
        q, q2 = scale * s, scale * s2
        C = L * (p["F_spring0"] + p["k_spring"] * L * q)
    else:
        q, q2 = s, s2
        C = p["F_spring0"] + p["k_spring"] * q
    falling = q2 < 0.0
    return float(np.min(np.sqrt(C[falling] / (inertia(p) * np.abs(q2[falling])))))


@pytest.mark.parametrize("kind", list(KINDS))
def test_a_spring_closed_follower_holds_at_098_of_its_jump_speed_and_leaves_at_102(kind):
    """The speed drive at constant speed, gravity off: no output row off the cam over 1.5 turns at 0.98 omega_jump;
    at 1.02 the follower flies (rows with N_contact = 0 and the follower's lift away from the cam's)."""
    p = dict(defaults(), **SCENE, **KINDS[kind], closure="spring", k_spring=2000.0, F_spring0=20.0, drive="speed",
             gravity=False)
    omega_jump = jump_speed(p)
    for factor, flies in ((0.98, False), (1.02, True)):
        omega = factor * omega_jump
        sim = DriveSimulator(p)
        sim.set_inputs(0.0, omega, 0.0)
        rows = []
        for k in range(int(3 * math.pi / omega / 1e-4)):
            sim.do_step(k * 1e-4, 1e-4, u=0.0, omega_ref=omega, omega_dot_ref=0.0)
            rows.append(sim.outputs())
        off = [out for out in rows if out["N_contact"] == 0.0]
        lift = np.array([out["s"] for out in rows]) - law(np.array([out["theta"] for out in rows]))[0]
        if flies:
            assert len(off) > 10 and np.max(np.abs(lift)) > 1e-6
        else:
            assert not off and np.max(np.abs(lift)) < 1e-15
            assert min(out["N_contact"] for out in rows) > 0.0


def test_an_arm_whose_gap_in_lift_units_exceeds_the_clearance_runs_within_its_groove():
    """lift_angle 0.1 rad on a 20 mm lift and a 150 mm arm: the arm's gap c / L = 3.3e-3 rad is 0.67 mm of the law's
    lift, more than c = 0.5 mm. The clearance guard measures along the roller's path (L psi), so the run is not
    refused, and the follower's distance from the cam along it never exceeds c."""
    p = dict(defaults(), **SCENE, **{**KINDS["oscillating_roller"], "lift_angle": 0.1}, **CLOSURES["form"], **COAST,
             restitution=0.5)
    sim = DriveSimulator(p)
    sim.set_inputs(0.0, 0.0, 0.0)
    along, lift_units = [], []
    for k in range(300):
        sim.do_step(k * 1e-3, 1e-3, u=0.0, omega_ref=0.0, omega_dot_ref=0.0)
        out = sim.outputs()
        along.append(p["arm_length"] * (out["psi"] - p["lift_angle"] / LIFT * float(law(out["theta"])[0])))
        lift_units.append(out["s"] - out["s_cam"])
    assert max(abs(a) for a in along) > 0.9 * p["c"]   # it crosses the groove
    assert max(abs(a) for a in along) <= p["c"] * (1 + 1e-9) + 1e-12
    assert max(abs(g) for g in lift_units) > p["c"]   # where a guard in the law's units would have refused
