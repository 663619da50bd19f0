"""The follower's kind in the C engine (docs/model.md 16): a translating flat face, an oscillating roller and an
oscillating flat face in the consistent voltage drive (rk45, rk4 and rk23) and the speed drive, against the scipy
reference (physics/kind_drive.py KindDriveModel, written apart), with gravity tilted and shaft friction, and with each
type's friction (mu: the face's sliding, the arm's pivot); the reference takes the kind from the parameters as the
engine does; what the engine does not run yet, geometry that cannot be built and a follower its friction would wedge,
refused by name."""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from cam_fmu.engine.simulator import DriveSimulator
from cam_fmu.physics.follower_kind import FollowerKind
from cam_fmu.physics.parameters import ParameterError, defaults
from cam_fmu.physics.signals import Signal, constant
from cam_fmu.reference.integrate import simulate_reference

RISE = math.pi / 2  # rad: cycloidal rise, dwell, return, dwell of 90 deg each
SCENE = dict(rise_law="cycloidal", return_law="cycloidal", rise_angle=RISE, upper_dwell=RISE, return_angle=RISE,
             lower_dwell=RISE, lift=0.02, r_b=0.08, closure="kinematic", m=0.4, G=4.0, M_f=0.012, mu=0.0,
             gamma=1.2, J_cam=2e-4)   # gravity tilted out of the vertical; shaft friction on, guide friction off
ARM = dict(arm_length=0.15, pivot_distance=0.18, J_arm=2e-3, m_arm=0.2, r_cm_arm=0.07, psi_0=0.3)
KINDS = {"translating_flat": dict(follower_type="translating_flat", beta=0.3),
         "oscillating_roller": dict(follower_type="oscillating_roller", lift_angle=0.3, **ARM),
         "oscillating_flat": dict(follower_type="oscillating_flat", lift_angle=0.15, **ARM)}
STOP, STEP = 0.9, 0.01  # s
# V: forward, back, then too little to turn the cam against its load (stops and break-aways)
VOLTS = Signal((0.0, 0.3, 0.3, 0.6, 0.6), (40.0, 40.0, -12.0, -12.0, 1.0), hold=True)
SPEED = Signal((0.0, 0.5), (5.0, 30.0))  # rad/s: a ramp
NAMES = ("theta", "omega", "i", "M", "J", "s", "v", "a", "alpha", "N_contact", "psi", "psi_dot", "voltage")
# (drive parameters, bound on every NAMES' difference relative to its largest value): measured at most 2.2e-8 .. 1.9e-7
# (rk45 at the engine's default tolerances; the largest the oscillating roller's alpha), 2.6e-9 .. 9.1e-9 (rk4 at h_max
# 25 us; at 0.1 ms 1e-6 .. 8.5e-6), 2.3e-7 .. 5.0e-7 (rk23 at the engine's tolerances), 1.3e-13 (the speed drive: the
# same formulas at the same imposed angles)
DRIVES = {"rk45": (dict(), 1e-6), "rk4": (dict(solver="rk4", h_max=2.5e-5), 1e-6), "rk23": (dict(solver="rk23"), 2e-6),
          "speed": (dict(drive="speed"), 1e-6)}


def engine_run(params: dict) -> dict[str, np.ndarray]:
    """The engine's outputs on the grid, the inputs held over each step at their value at its start; "events" the
    names of the events it logged."""
    sim = DriveSimulator(params)
    grid = np.arange(int(round(STOP / STEP)) + 1) * STEP
    sim.set_inputs(VOLTS.value(0.0), SPEED.value(0.0), SPEED.slope(0.0))
    rows = [sim.outputs()]
    for t in grid[:-1]:
        sim.do_step(t, STEP, u=VOLTS.value(t), omega_ref=SPEED.value(t), omega_dot_ref=SPEED.slope(t))
        rows.append(sim.outputs())
    return {**{name: np.array([r[name] for r in rows]) for name in rows[0]},
            "events": np.array([event["name"] for event in sim.events()])}


def worst(engine: dict, reference: dict, name: str) -> float:
    """max |engine - reference| over the grid, relative to the reference's largest |value| (absolute where it is 0)."""
    scale = float(np.max(np.abs(reference[name])))
    return float(np.max(np.abs(engine[name] - reference[name]))) / (scale if scale > 0.0 else 1.0)


@pytest.mark.parametrize("drive", list(DRIVES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_engine_runs_every_kind_as_the_reference_does(kind, drive):
    extra, bound = DRIVES[drive]
    params = dict(defaults(), **SCENE, **KINDS[kind], **extra)
    engine = engine_run(params)
    reference = simulate_reference(params, STOP, STEP, u=VOLTS, omega_ref=SPEED)
    for name in NAMES:
        assert worst(engine, reference, name) < bound, (name, worst(engine, reference, name))
    assert np.ptp(engine["theta"]) > 1.0   # rad: the cam turns (and the follower moves through the law)
    if KINDS[kind]["follower_type"].startswith("oscillating"):
        assert np.max(engine["psi"]) > 0.5 * params["lift_angle"]
        assert np.allclose(engine["psi"], params["lift_angle"] / params["lift"] * engine["s"], rtol=0, atol=1e-15)
    else:
        assert not np.any(engine["psi"]) and not np.any(engine["psi_dot"])
    if drive != "speed":   # it stops and breaks away: the held cam under shaft friction
        assert np.min(engine["omega"]) < 0.0 < np.max(engine["omega"])


FRICTION = 0.05  # mu: each type's friction, where the follower slides (a face) or turns on its pivot (an arm)


# the drives of the frictionless runs, and rk45 with the armature's inductance: the held cam's torque then changes
# with the current, so the break-away is an event located in the step (measured 3.2e-8 .. 3.8e-7)
FRICTION_DRIVES = {**DRIVES, "rk45_L": (dict(L=1e-3), 1e-6)}


@functools.cache
def friction_reference(kind: str, drive: str) -> dict[str, np.ndarray]:
    """The reference with the type's friction, integrated by Radau. Its default, DOP853, took one step of 0.21 ms
    from a side event (P through 0 at theta = 1.5618 rad, the oscillating roller at 43 rad/s) over the breakpoint at
    the rise's end, pi/2, and its dense output there was 2e-6 .. 5.1e-6 rad/s off the engine's (every solver and
    step) while Radau and LSODA agree with the engine to 1e-10 at that instant: the 1 V stall later magnifies it
    into 7e-6 rad of theta."""
    extra = {"speed": dict(drive="speed"), "rk45_L": dict(L=1e-3)}.get(drive, {})   # the reference has no solver
    params = {**defaults(), **SCENE, **KINDS[kind], "mu": FRICTION, **extra}
    method = None if drive == "speed" else "Radau"
    return simulate_reference(params, STOP, STEP, u=VOLTS, omega_ref=SPEED, method=method)


@pytest.mark.parametrize("drive", list(FRICTION_DRIVES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_engine_runs_every_kind_with_its_friction_as_the_reference_does(kind, drive):
    """M = M_f d + P q' + mu |P| lambda d (docs/model.md 16), the drive equation solved on the branch sgn(P), its
    side events, stops and break-aways: every output within the frictionless runs' bounds of the reference's; the
    friction moves M by far more than that bound (the same run without it)."""
    extra, bound = FRICTION_DRIVES[drive]
    params = {**defaults(), **SCENE, **KINDS[kind], **extra, "mu": FRICTION}
    engine = engine_run(params)
    reference = friction_reference(kind, drive if drive in ("speed", "rk45_L") else "voltage")
    for name in NAMES:
        assert worst(engine, reference, name) < bound, (name, worst(engine, reference, name))
    without = engine_run({**params, "mu": 0.0})
    assert worst(without, reference, "M") > 1e3 * bound   # the friction is in the comparison
    if drive != "speed":   # the branch of sgn(P) changes, the held cam stops and breaks away under the friction
        assert "side_force" in engine["events"] and "stop" in engine["events"]
        assert np.min(engine["omega"]) < 0.0 < np.max(engine["omega"])
    if drive == "rk45_L":
        assert "break_away" in engine["events"]


def flat_wedge_threshold(h: float, r_b: float, J_0: float, m: float) -> float:
    """The smallest mu at which a translating flat face on SCENE's cycloidal rise and return wedges:
    J_0 + m s' (s' - mu (r_b + s)) reaches 0 (kind_drive's refusal), s and s' the cycloid's closed form written here,
    on a grid of 0.001 deg (the engine's test: 0.1 deg)."""
    x = np.linspace(0.0, 1.0, 90001)[1:-1]   # the rise's fraction, ends excluded (s' = 0 there)
    rate = h / RISE * (1.0 - np.cos(2 * np.pi * x))   # |s'| on the rise and, mirrored, the return
    rise = h * (x - np.sin(2 * np.pi * x) / (2 * np.pi))
    lift = np.concatenate([rise, h - rise])   # s on the rise, and on the return at the same |s'|
    rate = np.concatenate([rate, rate])
    return float(np.min((J_0 + m * rate ** 2) / (m * rate * (r_b + lift))))


@pytest.mark.parametrize("factor,wedges", [(0.97, False), (1.03, True)])
def test_a_flat_face_wedges_where_the_closed_form_says(factor, wedges):
    """mu just below the closed form's threshold runs, just above it is refused by the engine with the reference's
    message, naming mu and r_b."""
    base = {**defaults(), **SCENE, **KINDS["translating_flat"], "J_cam": 0.0}
    mu = factor * flat_wedge_threshold(base["lift"], base["r_b"], base["J_m"], base["m"])
    assert 0.0 < mu < 0.5
    params = {**base, "mu": mu}
    if not wedges:
        DriveSimulator(params)
        return
    with pytest.raises(ParameterError) as engine_error:
        DriveSimulator(params)
    with pytest.raises(ParameterError) as reference_error:
        simulate_reference(params, 0.1, 0.01, u=constant(40.0))
    assert str(engine_error.value) == str(reference_error.value)
    assert f"'mu' = {mu!r}" in str(engine_error.value) and "wedge" in str(engine_error.value)


def test_an_oscillating_face_its_friction_would_wedge_is_refused_alike():
    """An oscillating flat face (lambda = tan(delta) (1 - psi')) wedged at mu = 0.5 without J_cam: the engine's message
    is the reference's, to the degree and the kg m2."""
    params = {**defaults(), **SCENE, **KINDS["oscillating_flat"], "mu": 0.5, "J_cam": 0.0}
    with pytest.raises(ParameterError) as engine_error:
        DriveSimulator(params)
    with pytest.raises(ParameterError) as reference_error:
        simulate_reference(params, 0.1, 0.01, u=constant(40.0))
    assert str(engine_error.value) == str(reference_error.value)
    assert "oscillating_flat follower by its friction" in str(engine_error.value)


def test_the_reference_takes_the_kind_from_the_parameters():
    """simulate_reference with the kind as parameters is the run with follower=FollowerKind(...), bit for bit."""
    arm = KINDS["oscillating_roller"]
    params = dict(defaults(), **SCENE, drive="speed")
    named = simulate_reference(dict(params, **arm), 0.2, 0.01, omega_ref=constant(10.0))
    given = simulate_reference(params, 0.2, 0.01, omega_ref=constant(10.0), follower=FollowerKind(**arm))
    assert set(named) == set(given) and all(np.array_equal(named[k], given[k]) for k in named)


def test_the_translating_roller_has_no_arm_outputs():
    """The default type: psi and psi_dot are 0 in the engine and the reference (the rest is the baseline's)."""
    params = dict(defaults(), **SCENE)
    engine = engine_run(params)
    assert np.ptp(engine["s"]) > 0.0 and not np.any(engine["psi"]) and not np.any(engine["psi_dot"])


def refusal(params: dict) -> str:
    with pytest.raises(ParameterError) as exc:
        DriveSimulator({**defaults(), **SCENE, **params})
    return str(exc.value)


@pytest.mark.parametrize("params,names", [
    (dict(arm_length=0.15), ("'arm_length'", "'translating_roller'")),
    (dict(follower_type="translating_flat", psi_0=0.1), ("'psi_0'", "'translating_flat'")),
    (dict(follower_type="oscillating_flat", lift_angle=0.1, pivot_distance=0.18), ("'arm_length'", "needs it")),
    (dict(KINDS["oscillating_roller"], beta=0.2), ("'beta'", "psi_0")),
    (dict(KINDS["translating_flat"], closure="kinematic", c=1e-4), ("'c' = 0.0001", "closure 'kinematic': c = 0")),
    (dict(KINDS["translating_flat"], k_shaft=100.0), ("'follower_type'", "k_shaft = 100.0")),
    (dict(KINDS["oscillating_flat"], k_train=1e4, m_end=0.1), ("'follower_type'", "k_train = 10000.0")),
    (dict(KINDS["oscillating_flat"], formulation="paper"), ("'follower_type'", "paper")),
    (dict(KINDS["oscillating_flat"], solver="etdrk4"), ("'follower_type'", "etdrk4")),
    (dict(KINDS["oscillating_roller"], arm_length=0.05), ("'arm_length' = 0.05", "cannot reach")),
    (dict(KINDS["oscillating_roller"], lift_angle=3.0), ("'lift_angle' = 3.0", "90 deg")),
    (dict(KINDS["oscillating_flat"], pivot_distance=0.07), ("'pivot_distance' = 0.07", "inside the base circle")),
    (dict(KINDS["oscillating_flat"], lift_angle=1.3), ("'lift_angle' = 1.3", "perpendicular")),
    # the contour on a 0.1 deg grid (kinematics/follower_checks.py refuse_unbuildable's checks, in C)
    (dict(KINDS["translating_flat"], r_b=0.005), ("'r_b' = 0.005", "r_b + s + s'' = -27.85", "r_b > 0.03285")),
    (dict(KINDS["oscillating_flat"], lift_angle=0.6, pivot_distance=0.1), ("'r_b' = 0.08", "p + d2p/dphi2 = -1526")),
    (dict(KINDS["oscillating_flat"], lift_angle=1.0, pivot_distance=0.5), ("'lift_angle' = 1.0", "psi' >= 1")),
    (dict(KINDS["oscillating_roller"], pivot_distance=0.1, arm_length=0.1, lift_angle=1.0),
     ("'pivot_distance' = 0.1", "158.087 mm", "sweep over the pivot")),
])
def test_what_the_engine_does_not_run_is_refused_by_name(params, names):
    message = refusal(params)
    assert all(name in message for name in names), message


@pytest.mark.parametrize("params", [dict(KINDS["oscillating_roller"], arm_length=0.05),
                                    dict(KINDS["oscillating_flat"], pivot_distance=0.07)])
def test_the_reference_refuses_the_same_geometry(params):
    """The geometry the engine refuses, the reference refuses too (kinematics/follower_checks.py, written apart)."""
    with pytest.raises(ParameterError):
        simulate_reference(dict(defaults(), **SCENE, **params, drive="speed"), 0.1, 0.01, omega_ref=constant(10.0))


def test_the_residual_through_the_drive_refuses_a_geometry_the_type_cannot_make():
    """The residual through the drive runs every type (tests/vibration/test_residual_drive.py); a flat face on a base
    circle that its contour would need a cusp for is refused by name, as the drive refuses it."""
    from cam_fmu.reference.train_residual import residual_scene

    params = dict(SCENE, **KINDS["translating_flat"], r_b=0.02)
    with pytest.raises(ParameterError, match="follower_type 'translating_flat' with 'r_b' = 0.02 m.*cusp"):
        residual_scene(params)


# A follower of its own for every type (docs/model.md 16.3): on a spring about the pivot or along the stroke (soft
# enough that every type flies at 40 V and in the ramp) and in a 0.3 mm groove, restitution 0.5, with each type's
# friction and the tilted gravity (an arm's weight in the speed drive too); max |engine - reference| relative to each
# output's largest, measured: the voltage drive 1.7e-11 .. 3.4e-8 (rk45 at the engine's tolerances; the oscillating
# face's v the largest), the speed drive 3.6e-12 .. 5.0e-11.
OWN = {"spring": dict(closure="spring", k_spring=100.0, F_spring0=1.0, restitution=0.5),
       "groove": dict(closure="form", c=3e-4, restitution=0.5)}
OWN_BOUNDS = {"voltage": 5e-7, "speed": 1e-9}


@pytest.mark.parametrize("drive", list(OWN_BOUNDS))
@pytest.mark.parametrize("closure", list(OWN))
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_engine_flies_every_kind_as_the_reference_does(kind, closure, drive):
    """Lift-offs, flights and impacts of each type in both drives against the reference (physics/kind_follower.py,
    written apart): every output within OWN_BOUNDS of its largest; the follower flies (rows off the cam) and strikes
    (the reference's impacts), and the engine's flight rows are the reference's."""
    params = {**defaults(), **SCENE, **KINDS[kind], **OWN[closure], "mu": 0.05, "drive": drive}
    engine = engine_run(params)
    reference = simulate_reference(params, STOP, STEP, u=VOLTS, omega_ref=SPEED)
    for name in NAMES:
        assert worst(engine, reference, name) < OWN_BOUNDS[drive], (name, worst(engine, reference, name))
    flying = engine["N_contact"] == 0.0
    assert np.sum(flying) >= 10 and reference["impacts"][-1] >= 3
    assert np.array_equal(flying, reference["contact"] == 0.0)
