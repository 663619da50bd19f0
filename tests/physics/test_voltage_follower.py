"""The spring-closed follower on a voltage-driven cam in the scipy reference (physics/voltage_follower.py,
reference/voltage_flight.py; docs/model.md section 13.6), against independent checks: the energy balance of
section 9 with the spring's energy, the closed-form jump speed of a simple-harmonic rise on a heavy flywheel, the
contact force from the numerically differentiated follower path, the closed-form flight, the restitution law.

Jump speed of a simple-harmonic rise of lift h over the angle b: omega_jump^2 = (F0 + k h) / (m (h/2) (pi/b)^2).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.fmu.engine import DriveSimulator
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.follower import Flight
from cam_fmu.physics.parameters import ParameterError
from cam_fmu.physics.signals import constant
from cam_fmu.reference.voltage_flight import VoltageFollowerRun
from cam_fmu.reference.integrate import output_grid, simulate_reference

C_M = 0.015 * 9.80665
# The paper's cam held by a return spring, horizontal, without guide friction, on a flywheel J_cam = 0.05 kg m2
# (the spring's torque, up to 7 N m, is far beyond the motor's 0.09 N m: the flywheel carries the shaft through).
SPRING = dict(drive="voltage", closure="spring", gamma=math.pi, F_spring0=20.0, k_spring=800.0, mu=0.0,
              omega0=60.0, J_cam=0.05)
U = 11.0  # V


def run(params: dict, stop: float, interval: float, u: float = U, energy: bool = False):
    model = DriveModel(params)
    body = VoltageFollowerRun(model, constant(u), 1e-12, 1e-13, energy, None)
    return model, body, body.run(output_grid(stop, interval))


def stored(model: DriveModel, r: dict) -> np.ndarray:
    """J, the stored energy from the outputs: cam side and follower kinetic, spring F0 s + k s^2/2, gravity -F_gx s
    (L = 0), and a compliant shaft's rotor J_m omega_m^2/2 and twist k phi^2/2."""
    energy = (0.5 * model.J_0 * r["omega"] ** 2 + 0.5 * model.m * r["v"] ** 2 + model.F_spring0 * r["s"]
              + 0.5 * model.k_spring * r["s"] ** 2 - model.F_gx * r["s"])
    if model.compliant:
        energy = energy + 0.5 * model.J_m * r["omega_m"] ** 2 + 0.5 * model.k_shaft * (r["theta_m"] - r["theta"]) ** 2
    return energy


def balance(model: DriveModel, r: dict) -> np.ndarray:
    """J, E_in less every loss (copper, shaft, guide, damper, impacts) less the change of the stored energy: 0."""
    losses = r["E_copper"] + r["E_shaft"] + r["E_guide"] + r["E_damp"] + r["E_impact"]
    return r["E_in"] - losses - (stored(model, r) - stored(model, r)[0])


@pytest.mark.parametrize("e", [1.0, 0.5])
def test_energy_balance_holds_over_many_bounces(e):
    """E_in - E_copper - E_shaft - E_impact = the change of the stored energy (section 9 with the spring); c_e = c_m."""
    params = dict(SPRING, c_e=C_M, restitution=e, shaft_friction=False)
    model, body, r = run(params, 0.3, 1e-4, energy=True)
    assert len(body.impacts) >= 20 and len(body.lift_offs) >= 1  # e = 1: it never settles after the first
    balance = r["E_in"] - r["E_copper"] - r["E_shaft"] - r["E_impact"] - (stored(model, r) - stored(model, r)[0])
    scale = np.max(np.abs(r["E_in"])) + np.max(stored(model, r))
    assert np.max(np.abs(balance)) < 1e-9 * scale, np.max(np.abs(balance))
    if e == 1.0:
        assert r["E_impact"][-1] == 0.0
    else:
        assert r["E_impact"][-1] > 1e-4


def test_restitution_law_and_momentum_at_each_impact():
    """Every touch-down above the Zeno guard sends the follower back at -e times its relative speed."""
    model, body, r = run(dict(SPRING, restitution=0.5), 0.25, 1e-4)
    bounces = [(before, after) for _, before, after in body.impacts if after != 0.0]
    assert len(bounces) >= 10
    for before, after in bounces:
        assert before < 0.0 and after == pytest.approx(-0.5 * before, rel=1e-12, abs=1e-15)


def test_less_than_elastic_settles_on_the_cam():
    """e = 0.5: each sequence of bounces ends (Zeno guard) with the follower on the cam, finitely many impacts."""
    model, body, r = run(dict(SPRING, restitution=0.5), 0.25, 1e-4)
    assert r["contact"][-1] == 1.0 and r["s"][-1] == r["s_cam"][-1]
    assert np.max(r["s"] - r["s_cam"]) > 1e-4 and 10 < len(body.impacts) < 200
    assert np.all(r["s"] >= r["s_cam"] - 2e-12)  # never inside the cam by more than the touch-down's 1 pm


@pytest.mark.parametrize("mu, ratio, leaves", [(0.0, 0.98, False), (0.0, 1.02, True),
                                               (0.5, 0.995, False), (0.5, 1.005, True)])
def test_jump_speed_on_a_heavy_flywheel_is_the_closed_form(mu, ratio, leaves):
    """J_cam = 100 kg m2 at u = c_e omega (no current): the cam turns at nearly constant speed, and the follower
    leaves it iff omega > omega_jump of the simple-harmonic closed form, omega_jump^2 = (F0 + k h - f0) / (m (h/2)
    (pi/b)^2). With guide friction mu = 0.5 on a horizontal mounting (f0 = mu G = 2 N) the follower starts down at the
    top of the stroke and the friction pushes it along +X against the spring: 0.84 % below the frictionless speed
    (1.005 of it is 0.9966 of that)."""
    H, B, MASS, K, F0 = 0.05, math.pi, 0.4, 2000.0, 20.0
    omega_jump = math.sqrt((F0 + K * H - mu * 4.0) / (MASS * H / 2 * (math.pi / B) ** 2))
    omega = ratio * omega_jump
    params = dict(SPRING, k_spring=K, F_spring0=F0, lift=H, rise_law="simple_harmonic", mu=mu,
                  return_law="simple_harmonic", J_cam=100.0, omega0=omega, shaft_friction=False)
    model, body, r = run(params, 2 * 2 * math.pi / omega, 2e-5, u=0.146 * omega)
    assert np.max(np.abs(r["omega"] / omega - 1.0)) < 1e-4
    assert (len(body.lift_offs) > 0) == leaves
    assert (np.max(r["s"] - r["s_cam"]) > 1e-9) == leaves


def test_contact_force_is_the_follower_path_differentiated():
    """In contact N cos(alpha) = m s_dd + F0 + k s, with s_dd the numerical second difference of the output path:
    the coupled equations' omega_dot inside N, checked without them (a light flywheel: omega swings by 8 %)."""
    model, body, r = run(dict(SPRING, restitution=0.5), 0.1, 1e-5)
    dt = 1e-5
    s_dd = (r["s"][2:] - 2 * r["s"][1:-1] + r["s"][:-2]) / dt ** 2
    inside = (r["contact"][2:] == 1) & (r["contact"][1:-1] == 1) & (r["contact"][:-2] == 1)
    force = r["N_contact"][1:-1] * np.cos(r["alpha"][1:-1])
    closed = model.m * s_dd + model.F_spring0 + model.k_spring * r["s"][1:-1]
    assert np.count_nonzero(inside) > 5000 and np.ptp(r["omega"]) > 1.0
    assert np.max(np.abs((force - closed)[inside])) < 1e-3 * np.max(np.abs(force))
    assert np.all(r["N_contact"] >= 0.0) and np.all(r["N_contact"][r["contact"] == 0] == 0.0)


@pytest.mark.parametrize("params", [dict(SPRING), dict(SPRING, mu=0.3)])
def test_flight_is_the_closed_form_until_touch_down(params):
    """From each located lift-off to the next touch-down the follower's path is Flight.state, to 1e-9 m; with guide
    friction f0 = mu (|G_y| + |N_g|) (horizontal: mu G = 1.2 N), its halts included."""
    model, body, r = run(dict(params, restitution=0.0), 0.25, 1e-5)
    f0 = model.mu * (abs(model.G_y) + model.N_g)
    flight = Flight(model.m, model.k_spring, model.F_spring0, model.F_gx, f0)
    checked = 0
    for t_lift, s0, v0 in body.lift_offs:
        land = min((t for t, _, _ in body.impacts if t > t_lift), default=math.inf)
        rows = np.flatnonzero((r["time"] > t_lift) & (r["time"] < land))
        for k in rows:
            assert r["s"][k] == pytest.approx(flight.state(r["time"][k] - t_lift, s0, v0)[0], abs=1e-9)
        checked += len(rows)
    assert checked > 100 and (f0 > 1.0) == (model.mu > 0.0)


def test_the_reference_dispatches_the_voltage_follower():
    """simulate_reference runs the spring closure in the voltage drive; a shaft that stops swings back (the
    break-away rule at rest), with the stop located, not stepped over: omega is exactly 0 at most at isolated rows."""
    r = simulate_reference(dict(SPRING, restitution=0.5), 0.1, 1e-3, u=constant(U))
    assert r["impacts"][-1] > 0 and "N_contact" in r
    r = simulate_reference(dict(SPRING, J_cam=2e-3), 0.25, 1e-3, u=constant(U))
    assert np.min(r["omega"]) < -50.0 and np.max(r["omega"]) > 59.9


# paper_fig6's drive from rest (omega0 = 0, 3.5 V, L = 0, default mu = 0.001 and M_f) with c_e = c_m, so that the
# balance of section 9 closes: a groove, a spring that stalls the cam on the rise (it swings back and sticks), and
# the light-flywheel spring cam that stops and turns back with guide friction; a vertical groove coasting at u = 0
# against M_f = 0.3 N.m whose cam stops under the flying follower, which lands on it (e = 0.5) and turns it back.
STOP_IN_FLIGHT = dict(closure="form", c=5e-4, gamma=math.pi / 2, beta=math.pi, omega0=8.0, theta0=0.5, M_f=0.3,
                      restitution=0.5)


@pytest.mark.parametrize("params, u, stop", [
    (dict(closure="form", c=5e-4), 3.5, 2.0),
    (dict(closure="spring", k_spring=500.0, F_spring0=5.0), 3.5, 2.0),
    (dict(SPRING, J_cam=2e-3, mu=0.05), U, 0.25),
    (STOP_IN_FLIGHT, 0.0, 0.1),
])
def test_the_energy_balance_holds_through_stick_and_slip(params, u, stop):
    """E_in - E_copper - E_shaft - E_guide - E_impact = the change of the stored energy (measured 2.0e-14 J, 2.7e-13
    J, 2.8e-11 J and 5.3e-10 J of 1.6e-3 J, 0.047 J, 3.7 J and 0.073 J), through the stuck intervals (omega exactly 0,
    E_in = E_copper there with L = 0) and the stops; the landings on the stuck cam keep the restitution law."""
    from cam_fmu.experiments.scenes import find_scene
    base = dict(find_scene("paper_fig6").primary.params) if "drive" not in params else {}
    model = DriveModel(dict(base, **params))
    params = dict(base, **params, c_e=model.c_m)
    model, body, r = run(params, stop, 1e-3, u=u, energy=True)
    balance = (r["E_in"] - r["E_copper"] - r["E_shaft"] - r["E_guide"] - r["E_damp"] - r["E_impact"]
               - (stored(model, r) - stored(model, r)[0]))
    # the stop under the flying follower: 5.3e-10 J, at the stop that ends a slow backward swing at 66 ms (the piece
    # ends on DOP853's dense output there, one long smooth step)
    assert np.max(np.abs(balance)) < (1e-8 if params.get("M_f") == 0.3 else 1e-9) * np.max(stored(model, r))
    assert r["E_shaft"][-1] > 0.0 and r["E_guide"][-1] > 0.0
    stuck = np.flatnonzero(r["omega"] == 0.0)
    if params.get("k_spring") == 500.0:   # stuck from 48 ms on: nothing moves, the motor's power all in copper
        assert len(stuck) > 1900 and np.ptp(r["theta"][stuck[10:]]) == 0.0
        assert np.ptp((r["E_in"] - r["E_copper"])[stuck[10:]]) < 1e-15
    if params.get("M_f") == 0.3:   # stuck with the follower in flight, landings on the cam at rest turn it back
        assert np.sum(r["contact"][stuck] == 0.0) >= 10 and np.min(r["omega"]) < -1.0   # 14 ms stuck in flight
        on_stuck = [(before, after) for t, before, after in body.impacts
                    if r["omega"][max(int(t / 1e-3), 0)] == 0.0 and r["contact"][max(int(t / 1e-3), 0)] == 0.0]
        assert on_stuck and all(after == pytest.approx(-0.5 * before, rel=1e-12) for before, after in on_stuck)


@pytest.mark.parametrize("params, words", [
    (dict(SPRING, formulation="paper"), "formulation 'consistent'"),
    (dict(SPRING, mu=0.5, r_b=1e-3), "self-lock in its guide.*allowed: mu tan"),
])
def test_what_is_not_modelled_is_refused_with_the_reason_by_both(params, words):
    """The reference and the C engine refuse the same cases with the same words."""
    with pytest.raises(ParameterError, match=words) as python:
        DriveModel(params)
    with pytest.raises(ParameterError) as engine:
        DriveSimulator(params)
    assert str(engine.value) == str(python.value)



GROOVE = dict(drive="voltage", closure="form", c=5e-4, gamma=math.pi, mu=0.0, omega0=10.0, J_cam=0.05)


@pytest.mark.parametrize("e", [1.0, 0.5])
def test_groove_crossover_keeps_the_energy_balance_and_the_clearance(e):
    """closure 'form' at about 10 rad/s: the follower crosses the 1 mm gap and strikes the upper flank (w > 0 towards
    it); the balance of section 9 holds over every crossing; it never leaves the clearance by more than 1 pm."""
    params = dict(GROOVE, restitution=e, c_e=C_M, shaft_friction=False)
    model, body, r = run(params, 0.63, 1e-4, u=1.6, energy=True)
    balance = r["E_in"] - r["E_copper"] - r["E_shaft"] - r["E_impact"] - (stored(model, r) - stored(model, r)[0])
    assert np.max(np.abs(balance)) < 1e-9 * np.max(stored(model, r))
    assert any(before > 0.0 for _, before, _ in body.impacts) and len(body.impacts) > 10
    assert np.max(np.abs(r["s"] - r["s_cam"])) <= 5e-4 + 1e-12
    for _, before, after in body.impacts:
        if after != 0.0:
            assert after == pytest.approx(-e * before, rel=1e-12, abs=1e-15)
    if e < 1.0:
        assert -1.0 in r["contact"] and r["E_impact"][-1] > 0.0


# Guide friction (docs/model.md 13.6): a vertical cam lifting against gravity (F_gx = -G, N_g = 0), one with gravity
# sideways (G_y = G: the side force changes sign within the stroke), horizontal (N_g = G), and the groove.
FRICTION = [dict(SPRING, mu=0.1, gamma=math.pi / 2, beta=math.pi), dict(SPRING, mu=0.05, gamma=math.pi / 2,
                                                                         beta=math.pi / 2),
            dict(SPRING, mu=0.05), dict(GROOVE, mu=0.05)]


@pytest.mark.parametrize("params", FRICTION)
def test_guide_friction_only_removes_energy_and_the_balance_closes(params):
    """E_in - E_copper - E_shaft - E_guide - E_impact = the change of the stored energy, with E_guide = int f |v| dt
    (in contact f = mu (|N_r| + |N_g|) from the coupled equations, in flight mu (|G_y| + |N_g|)) growing."""
    u, stop = (1.6, 0.63) if params["closure"] == "form" else (U, 0.25)
    model, body, r = run(dict(params, restitution=0.5, c_e=C_M), stop, 1e-4, u=u, energy=True)
    scale = np.max(np.abs(r["E_in"])) + np.max(np.abs(stored(model, r)))
    assert np.max(np.abs(balance(model, r))) < 1e-10 * scale, np.max(np.abs(balance(model, r)))
    assert np.all(np.diff(r["E_guide"]) >= 0.0) and r["E_guide"][-1] > 1e-3
    assert len(body.impacts) > 5 and len(body.lift_offs) >= 1


def test_guide_friction_in_contact_is_the_follower_balance():
    """In contact the output N_contact satisfies the follower's balance along X with the guide's friction opposing v:
    N cos(alpha) = m s_dd + F0 + k s - F_gx + sgn(v) mu (|N sin(alpha) + G_y| + |N_g|), s_dd the second difference of
    the output path (a light flywheel: omega swings, so omega_dot is in it)."""
    params = dict(FRICTION[0], restitution=0.5, mu=0.3)
    model, body, r = run(params, 0.1, 1e-5)
    dt = 1e-5
    s_dd = (r["s"][2:] - 2 * r["s"][1:-1] + r["s"][:-2]) / dt ** 2
    inside = (r["contact"][2:] == 1) & (r["contact"][1:-1] == 1) & (r["contact"][:-2] == 1)
    N, alpha = r["N_contact"][1:-1], r["alpha"][1:-1]
    f = model.mu * (np.abs(N * np.sin(alpha) + model.G_y) + model.N_g)
    closed = (model.m * s_dd + model.F_spring0 + model.k_spring * r["s"][1:-1] - model.F_gx
              + np.sign(r["v"][1:-1]) * f)
    assert np.count_nonzero(inside) > 5000 and np.max(f[inside]) > 1.0
    assert np.max(np.abs((N * np.cos(alpha) - closed)[inside])) < 1e-3 * np.max(np.abs(N))


def test_a_compliant_shaft_keeps_the_balance_with_its_elastic_energy():
    """k_shaft > 0 with the damper and guide friction: E_in - losses (E_damp = int d (omega_m - omega)^2 dt) equals the
    change of the stored energy with the rotor's J_m omega_m^2/2 and the shaft's k phi^2/2; the shaft carries torque."""
    params = dict(SPRING, k_shaft=100.0, d_shaft=0.01, restitution=0.5, c_e=C_M, mu=0.05)
    model, body, r = run(params, 0.15, 1e-4, energy=True)
    scale = np.max(np.abs(r["E_in"])) + np.max(np.abs(stored(model, r)))
    assert np.max(np.abs(balance(model, r))) < 1e-10 * scale, np.max(np.abs(balance(model, r)))
    assert r["E_damp"][-1] > 1e-6 and np.max(np.abs(r["M_shaft"])) > 0.02 and len(body.impacts) > 3


def test_a_stiff_shaft_reaches_the_rigid_drive():
    """Before the first lift-off (40 ms, the follower on the cam), the compliant drive's theta approaches the rigid
    drive's as k_shaft grows, as the static twist M / k does: a factor 10 per decade, within 20 % (measured 4.6e-7,
    4.6e-8, 4.6e-9 rad at k_shaft = 1e2, 1e3, 1e4 N.m/rad with the damping ratio held)."""
    rigid = run(dict(SPRING), 0.04, 1e-4)[2]
    distance = []
    for k in (1e2, 1e3, 1e4):
        r = run(dict(SPRING, k_shaft=k, d_shaft=2e-3 * math.sqrt(k)), 0.04, 1e-4)[2]
        assert np.all(r["contact"] == 1.0)
        distance.append(np.max(np.abs(r["theta"] - rigid["theta"])))
    assert distance[0] > 1e-7
    for far, near in zip(distance[:-1], distance[1:]):
        assert 8.0 < far / near < 12.0, distance
