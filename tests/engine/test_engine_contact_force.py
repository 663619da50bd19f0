"""The output N_contact, the cam's normal force on the follower's roller (docs/model.md 4.2, 13.1), for every
formulation and drive, against what is independent of the engine's formula for it:

- closed forms at constant speed on a simple-harmonic cam (lift h over pi, return over pi: s = h/2 (1 - cos theta)
  all round): N cos(alpha) = m s'' omega^2 + F_spring0 + k_spring s - F_gx with tan(alpha) = s' / (r_b + s);
- the published load torque: the lateral component N sin(alpha) at the lever arm r_b + s_cam is M_l = M - M_f
  sgn(omega) (docs/model.md 4.3), the power the contact passes, N cos(alpha) v, is M_l omega;
- the follower's path: N cos(alpha) = m s_dd - F_gx with s_dd the second difference of the published s;
- the sides of the contact: 0 in flight and free in the clearance, never < 0 with a spring, < 0 exactly on a
  groove's upper flank;
- at rest (both drives, the engine and the reference): N cos(alpha) = F_spring0 + k_spring s - F_gx on the flank
  that force presses the follower to.

The engine against the scipy reference on every shipped scene is tests/fmu_cs/test_fmu_vs_reference.py (and
tests/engine/test_engine_follower.py, test_engine_voltage_follower.py); FMI 3.0 against FMI 2.0 bit for bit is
tests/fmi3/test_fmi3.py; Model Exchange is tests/fmu_me/test_engine_fmu_me.py.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.experiments.scenes import find_scene
from cam_fmu.fmu.engine import DriveSimulator

H, MASS, G, R_B = 0.05, 0.4, 4.0, 0.1
SHM = dict(lift=H, rise_law="simple_harmonic", return_law="simple_harmonic", mu=0.0)
VERTICAL = dict(gamma=math.pi / 2, beta=math.pi)   # lifts the follower against gravity: F_gx = -G


def run(params: dict, times: np.ndarray, u: float = 0.0, omega: float = 0.0) -> dict[str, np.ndarray]:
    """The engine stepped over ``times`` with the inputs held: its outputs there."""
    sim = DriveSimulator(params)
    sim.set_inputs(u=u, omega_ref=omega, omega_dot_ref=0.0)
    rows = [sim.outputs()]
    for t0, t1 in zip(times[:-1], times[1:]):
        sim.do_step(float(t0), float(t1 - t0), u=u, omega_ref=omega, omega_dot_ref=0.0)
        rows.append(sim.outputs())
    return {name: np.array([row[name] for row in rows]) for name in rows[0]}


@pytest.mark.parametrize("closure, extra, F0, k, F_gx", [
    ("kinematic", {}, 0.0, 0.0, 0.0),
    ("kinematic", VERTICAL, 0.0, 0.0, -G),
    ("spring", dict(k_spring=2000.0, F_spring0=20.0), 20.0, 2000.0, 0.0),
    ("spring", dict(VERTICAL, k_spring=500.0, F_spring0=5.0), 5.0, 500.0, -G),
], ids=["kinematic", "kinematic-vertical", "spring", "spring-vertical"])
def test_the_closed_form_at_constant_speed(closure, extra, F0, k, F_gx):
    """Below the jump speed (the spring's: omega_jump^2 = (F0 + k h + G_vertical) / (m h/2) at the top) the
    follower rides the cam; the guide is frictionless, so N cos(alpha) is the force along X alone."""
    omega = 0.9 * math.sqrt((F0 + k * H - F_gx) / (MASS * H / 2)) if closure == "spring" else 40.0
    times = np.linspace(0.0, 2 * math.pi / omega, 2001)
    got = run(dict(SHM, drive="speed", closure=closure, m=MASS, G=G, r_b=R_B, **extra), times, omega=omega)
    theta = got["theta"]
    s, s1, s2 = H / 2 * (1 - np.cos(theta)), H / 2 * np.sin(theta), H / 2 * np.cos(theta)
    cos_alpha = (R_B + s) / np.hypot(R_B + s, s1)
    expected = (MASS * s2 * omega ** 2 + F0 + k * s - F_gx) / cos_alpha
    assert np.max(np.abs(theta - omega * times)) < 1e-9
    assert np.max(np.abs(got["N_contact"] - expected)) < 1e-9 * np.max(np.abs(expected))
    if closure == "kinematic":   # the groove pulls where the cam decelerates the follower: N < 0 there
        assert np.min(got["N_contact"]) < -0.5 * MASS * H / 2 * omega ** 2
    else:
        assert np.min(got["N_contact"]) > 0.0


# Every formulation and drive with the follower on the cam somewhere: (params, u [V], omega_ref [rad/s]).
DRIVES = {
    "consistent": ({}, 3.5, 0.0),
    "backlash": ({"c": 5e-4}, 3.5, 0.0),
    "vertical": (dict(VERTICAL, G=2.0), 12.0, 0.0),
    "compliant": ({"k_shaft": 50.0, "J_cam": 14e-6}, 3.5, 0.0),
    "inductance": ({"L": 1e-3}, 3.5, 0.0),
    "paper": ({"formulation": "paper"}, 3.5, 0.0),
    "paper-backlash": ({"formulation": "paper", "c": 5e-4}, 3.5, 0.0),
    "speed": ({"drive": "speed"}, 0.0, 30.0),
    "speed-backlash": ({"drive": "speed", "c": 5e-4, **VERTICAL}, 0.0, 30.0),
    "spring-speed": (dict(find_scene("spring_bounce").primary.params), 0.0, 60.0),
    "groove-speed": (dict(find_scene("groove_crossover").primary.params), 0.0, 10.0),
    "spring-voltage": (dict(find_scene("spring_voltage").primary.params), 11.0, 0.0),
    "groove-voltage": (dict(find_scene("groove_voltage").primary.params), 1.6, 0.0),
}


@pytest.mark.parametrize("name", DRIVES)
def test_the_contact_force_carries_the_published_load_torque(name):
    """M - M_f sgn(omega) = N sin(alpha) (r_b + s_cam): the contact's lateral component at its lever arm, the
    guide friction included (N is the whole force of the contact); and, where v = s' omega (every formulation but
    the paper's backward differences), the power N cos(alpha) v = (M - M_f sgn(omega)) omega."""
    params, u, omega = DRIVES[name]
    stop = 0.6 if omega == 0.0 else 2 * 2 * math.pi / omega
    got = run(params, np.linspace(0.0, stop, 601), u=u, omega=omega)   # 1 ms steps: the paper's h_max
    moving = got["omega"] != 0.0
    assert np.count_nonzero(moving) > 590 and np.count_nonzero(got["N_contact"]) > 150
    M_f = params.get("M_f", 0.012)
    load = (got["M"] - M_f * np.sign(got["omega"]))[moving]
    N, alpha = got["N_contact"][moving], got["alpha"][moving]
    scale = np.max(np.abs(load)) + 1e-300
    lever = params.get("r_b", R_B) + got["s_cam"][moving]
    assert np.max(np.abs(N * np.sin(alpha) * lever - load)) < 1e-12 * scale
    if params.get("formulation") != "paper":
        power = load * got["omega"][moving]
        assert np.max(np.abs(N * np.cos(alpha) * got["v"][moving] - power)) < 1e-12 * np.max(np.abs(power))


@pytest.mark.parametrize("extra, u", [({}, 6.0), (VERTICAL, 15.0)], ids=["horizontal", "vertical"])
def test_the_contact_force_moves_the_follower_along_its_path(extra, u):
    """A frictionless guide under the voltage drive on the smooth simple-harmonic cam, speeding up to 50 and 165 rad/s:
    N cos(alpha) = m s_dd - F_gx with s_dd the second difference of
    the published path (to 1e-3 of the force's peak: the difference's own error, h^2 s''''/12, is below that; measured 1.3e-4 vertical)."""
    h = 5e-5
    got = run(dict(SHM, G=G, **extra), np.arange(0.0, 0.5, h), u=u)
    s_dd = (got["s"][2:] - 2 * got["s"][1:-1] + got["s"][:-2]) / h ** 2
    F_gx = -G if extra else 0.0
    force = got["N_contact"][1:-1] * np.cos(got["alpha"][1:-1])
    assert np.max(force) > 20.0 and np.min(force) < -20.0 and got["theta"][-1] > 10.0
    assert np.max(np.abs(force - (MASS * s_dd - F_gx))) < 1e-3 * np.max(np.abs(force))


@pytest.mark.parametrize("name", ["spring_jump", "spring_bounce", "spring_voltage"])
def test_a_spring_closed_follower_is_pushed_never_pulled_and_free_in_flight(name, reference_runs):
    scene = find_scene(name)
    for r in scene.runs:
        ref = reference_runs.run(scene, r)
        u, omega = (scene.u.value(0.0), 0.0) if r.params["drive"] == "voltage" else (0.0, scene.omega_ref.value(0.0))
        got = run(dict(r.params), ref["time"], u=u, omega=omega)
        off = got["s"] - got["s_cam"] > 2e-12   # in flight (touch-down is located 1 pm inside the flank)
        assert np.all(got["N_contact"] >= 0.0), r.label
        assert np.all(got["N_contact"][off] == 0.0) and np.all(got["N_contact"][~off] > 0.0), r.label
        assert np.array_equal(off, ref["contact"] == 0.0), r.label   # flight where the reference flies
        if r.label == "below_0.98":   # the margin at 0.98 omega_jump: 8.38 N (docs/model.md 13.6)
            assert not off.any() and np.min(got["N_contact"]) > 8.0


@pytest.mark.parametrize("name", ["groove_crossover", "groove_voltage"])
def test_a_grooves_upper_flank_pushes_with_a_negative_force(name, reference_runs):
    """+1 flank (s = s_cam - c): N > 0; -1 flank (s = s_cam + c): N < 0; crossing the clearance: 0."""
    scene = find_scene(name)
    for r in scene.runs:
        if r.params["closure"] != "form":
            continue
        ref = reference_runs.run(scene, r)
        u, omega = (scene.u.value(0.0), 0.0) if r.params["drive"] == "voltage" else (0.0, scene.omega_ref.value(0.0))
        got = run(dict(r.params), ref["time"], u=u, omega=omega)
        gap, c, N = got["s"] - got["s_cam"], r.params["c"], got["N_contact"]
        lower, upper = np.abs(gap + c) < 1e-15, np.abs(gap - c) < 1e-15
        assert np.all(N[lower] >= 0.0) and np.all(N[upper] <= 0.0) and np.all(N[~(lower | upper)] == 0.0), r.label
        assert np.count_nonzero(N[upper] < 0.0) > 10 and np.count_nonzero(N[lower] > 0.0) > 10, r.label
        assert np.array_equal(np.sign(N), np.sign(ref["N_contact"])), r.label


def test_the_kinematic_rule_reports_no_force_while_the_follower_rests_in_the_clearance():
    """The paper's backlash (docs/model.md 6.2): free in the gap no force, both flanks take the follower along."""
    for extra in ({}, {"formulation": "paper"}, {"drive": "speed"}):
        c = 5e-4
        speed = extra.get("drive") == "speed"
        got = run(dict(c=c, closure="kinematic", **extra), np.linspace(0.0, 0.6, 601), u=0.0 if speed else 3.5, omega=30.0 if speed else 0.0)
        gap, N = got["s"] - got["s_cam"], got["N_contact"]
        free = np.abs(np.abs(gap) - c) > 1e-12
        assert free.any() and np.all(N[free] == 0.0), extra
        assert np.count_nonzero(N[~free]) > 100, extra


# At rest (omega = 0; the voltage drive's shaft held by its static friction M_f at u = 0, the speed drive's
# omega_ref = 0) the follower lies on the flank the static force along X presses it to, and that flank carries the
# spring and gravity: N cos(alpha) = F_spring0 + k_spring s - F_gx, F_gx = G sin(gamma) cos(beta) (docs/model.md
# 4.1), at s = s_cam + c on a groove's upper flank (the force < 0) and s = s_cam - c on the lower (> 0).
# (params, flank: -1 upper, +1 lower); the simple-harmonic cam at theta0 = 1 rad, where s' != 0 (alpha != 0).
AT_REST = {
    "groove-upper": (dict(closure="form", c=5e-4, gamma=math.pi / 2, beta=0.0), -1),   # gravity pulls along the rise
    "groove-lower": (dict(closure="form", c=5e-4, **VERTICAL), +1),
    "groove-tilted-upper": (dict(closure="form", c=5e-4, gamma=math.pi / 3, beta=math.pi / 4), -1),
    "groove-tilted-lower": (dict(closure="form", c=5e-4, gamma=2.0, beta=2.5), +1),
    "spring-vertical": (dict(closure="spring", k_spring=500.0, F_spring0=5.0, **VERTICAL), +1),
    "spring-against-gravity": (dict(closure="spring", k_spring=500.0, F_spring0=5.0, gamma=math.pi / 2, beta=0.0), +1),
}


@pytest.mark.parametrize("drive", ["voltage", "speed"])
@pytest.mark.parametrize("name", AT_REST)
def test_at_rest_the_flank_carries_the_spring_and_gravity(name, drive):
    """The engine and the scipy reference against the closed form of the static contact force: each flank's sign,
    s on that flank, v = a = 0 and omega exactly 0, over 50 ms (the guide's friction carries nothing at rest)."""
    from cam_fmu.physics.signals import constant
    from cam_fmu.reference.integrate import simulate_reference
    extra, flank = AT_REST[name]
    theta0, c = 1.0, extra.get("c", 0.0)
    params = dict(SHM, drive=drive, m=MASS, G=G, r_b=R_B, theta0=theta0, M_f=1.0, mu=0.05, **extra)
    s_cam, s1 = H / 2 * (1 - math.cos(theta0)), H / 2 * math.sin(theta0)
    s = s_cam - flank * c
    F_gx = G * math.sin(extra["gamma"]) * math.cos(extra["beta"])
    expected = (extra.get("F_spring0", 0.0) + extra.get("k_spring", 0.0) * s - F_gx) / math.cos(math.atan2(s1, R_B + s_cam))
    assert abs(expected) > 1.0 and np.sign(expected) == flank and abs(F_gx) > 1.0
    assert abs(expected * s1) < 1.0   # the shaft's static friction M_f holds the load torque: the shaft stays
    times = np.linspace(0.0, 0.05, 51)
    got = run(params, times)
    ref = simulate_reference(params, 0.05, 1e-3, u=constant(0.0), omega_ref=constant(0.0))
    for label, out in (("engine", got), ("reference", ref)):
        assert np.all(out["omega"] == 0.0) and np.all(out["theta"] == theta0), label
        assert np.max(np.abs(out["s"] - s)) < 1e-15 and np.all(out["v"] == 0.0) and np.all(out["a"] == 0.0), label
        assert np.max(np.abs(out["N_contact"] - expected)) < 1e-12 * abs(expected), label
