"""The C engine's follower as a body of its own (csrc/src/follower.c; docs/model.md section 13) against the scipy
reference (physics/speed_follower.py, reference/flight.py: a numerical flight where the engine takes the closed
form) and against closed forms; under AddressSanitizer and UBSan (tests/engine_c/follower_driver.c).

Jump speed of a simple-harmonic rise of lift h over the angle b (tests/physics/test_follower.py):
omega_jump^2 = (F0 + k h) / (m (h/2) (pi/b)^2), at the top of the stroke.
"""
from __future__ import annotations

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest

from cam_fmu.engine import codegen
from cam_fmu.engine.build import CSRC, INCLUDE, SOURCES
from cam_fmu.experiments.scenes import find_scene
from cam_fmu.fmu.engine import DriveSimulator
from native_support import require

DRIVER = Path(__file__).resolve().parents[1] / "engine_c" / "follower_driver.c"
FLAGS = ["-std=c99", "-O1", "-g", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror", "-pedantic",
         "-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]
H, B, MASS, K, F0 = 0.05, math.pi, 0.4, 2000.0, 20.0
SHM = dict(drive="speed", closure="spring", k_spring=K, F_spring0=F0, mu=0.0, M_f=0.0, lift=H,
           rise_law="simple_harmonic", return_law="simple_harmonic")


def engine_run(params: dict, omega: float, times: np.ndarray) -> dict[str, np.ndarray]:
    """The engine stepped over ``times`` at the constant speed omega [rad/s]: its outputs there."""
    sim = DriveSimulator(params)
    sim.set_inputs(u=0.0, omega_ref=omega, omega_dot_ref=0.0)
    rows = [sim.outputs()]
    for t0, t1 in zip(times[:-1], times[1:]):
        sim.do_step(float(t0), float(t1 - t0), omega_ref=omega, omega_dot_ref=0.0)
        rows.append(sim.outputs())
    return {name: np.array([row[name] for row in rows]) for name in rows[0]}


@pytest.mark.parametrize("name", ["spring_jump", "spring_bounce", "groove_crossover"])
def test_the_engine_is_the_reference(name, reference_runs):
    scene = find_scene(name)
    for run in scene.runs:
        ref = reference_runs.run(scene, run)
        got = engine_run(dict(run.params), scene.omega_ref.value(0.0), ref["time"])
        assert np.max(np.abs(got["theta"] - ref["theta"])) < 1e-11
        assert np.max(np.abs(got["s"] - ref["s"])) < 1e-10, run.label   # m (measured 2e-12)
        assert np.max(np.abs(got["v"] - ref["v"])) < 1e-8, run.label    # m/s (measured 5e-10)
        assert np.max(np.abs(got["a"] - ref["a"])) < 1e-7, run.label    # m/s2 (measured 4e-9)
        for key in ("M", "i", "voltage", "N_contact"):
            assert np.max(np.abs(got[key] - ref[key])) < 1e-9 * max(1.0, np.max(np.abs(ref[key]))), (run.label, key)


def test_the_engine_is_the_reference_over_many_crossings_of_a_vertical_groove():
    """Gravity along the stroke, no spring, e = 0.9: tens of impacts on both flanks, each flight a parabola (the case
    where the reference's steps had to be bounded, reference/flight.py FLIGHT_ANGLE). Measured: s to 2.3e-12 m."""
    from cam_fmu.experiments.signals import constant
    from cam_fmu.physics.drive import DriveModel
    from cam_fmu.reference.flight import FollowerRun

    params = dict(drive="speed", closure="form", c=1e-3, restitution=0.9, gamma=math.pi / 2, mu=0.0, M_f=0.0)
    omega = 100.0
    times = np.linspace(0.0, 2 * math.pi / omega, 2001)
    run = FollowerRun(DriveModel(params), constant(omega), 1e-12, 1e-13)
    ref = run.run(times, 0.0)
    got = engine_run(params, omega, times)
    assert len(run.impacts) >= 10 and {1.0, -1.0} <= {math.copysign(1.0, w) for _, w, _ in run.impacts}
    assert np.max(np.abs(got["s"] - ref["s"])) < 1e-10
    assert np.max(np.abs(got["v"] - ref["v"])) < 1e-7


VERTICAL = dict(drive="speed", closure="form", c=1e-3, restitution=0.9, gamma=math.pi / 2, mu=0.0, M_f=0.0)
W0, W1, RAMP = 40.0, 100.0, 0.12   # rad/s, rad/s, s: omega_ref ramps from W0 to W1 over RAMP


@pytest.fixture(scope="module")
def ramp_reference():
    """The reference over the ramp in the vertical groove (20 impacts on both flanks): times, rows, impacts."""
    from cam_fmu.physics.drive import DriveModel
    from cam_fmu.physics.signals import Signal
    from cam_fmu.reference.flight import FollowerRun

    run = FollowerRun(DriveModel(VERTICAL), Signal((0.0, RAMP), (W0, W1)), 1e-12, 1e-13)
    times = np.linspace(0.0, RAMP, 241)
    return times, run.run(times, 0.0), run.impacts


def ramp_run(settings: dict, times: np.ndarray) -> dict[str, np.ndarray]:
    """The engine in the vertical groove with ``settings``, omega_ref and omega_dot_ref set at each point."""
    alpha = (W1 - W0) / RAMP
    sim = DriveSimulator(dict(VERTICAL, **settings))
    sim.set_inputs(u=0.0, omega_ref=W0, omega_dot_ref=alpha)
    rows = [sim.outputs()]
    for t0, t1 in zip(times[:-1], times[1:]):
        sim.do_step(float(t0), float(t1 - t0), omega_ref=W0 + alpha * float(t0), omega_dot_ref=alpha)
        rows.append(sim.outputs())
    return {name: np.array([row[name] for row in rows]) for name in rows[0]}


@pytest.mark.parametrize("settings, s_tol, v_tol", [
    (dict(solver="rk23", rtol=1e-9, atol=1e-12), 3e-8, 2e-5),   # measured 6.4e-9 m, 4.1e-6 m/s
    (dict(solver="rk4", h_max=1e-4), 1e-8, 4e-6),               # measured 1.2e-9 m, 7.8e-7 m/s
    (dict(solver="etdrk4", h_max=1e-4), 1e-8, 4e-6),            # (no pole here: rk4's steps)
])
def test_every_solver_runs_the_speed_drives_follower(settings, s_tol, v_tol, ramp_reference):
    """Issue 38: the speed drive's follower of its own takes any solver with its settings. Under a ramp of omega_ref
    the cam's angle stays the closed form theta = W0 t + alpha t^2 / 2 whatever the method (set exactly after each
    step); the follower's 20 impacts agree with the reference to the method's accuracy."""
    times, ref, impacts = ramp_reference
    got = ramp_run(settings, times)
    alpha = (W1 - W0) / RAMP
    assert len(impacts) >= 15
    assert np.max(np.abs(got["theta"] - (W0 * times + 0.5 * alpha * times ** 2))) < 1e-12
    assert np.max(np.abs(got["s"] - ref["s"])) < s_tol
    assert np.max(np.abs(got["v"] - ref["v"])) < v_tol


def test_euler_runs_the_speed_drives_follower_at_first_order(ramp_reference):
    """Explicit Euler on the same ramp up to the second impact: the error halves with h_max (measured 8.0e-6, 4.0e-6,
    2.0e-6 m at 4, 2, 1 us) while theta stays exact (euler alone would be off by alpha h^2 / 2 per step)."""
    times, ref, impacts = ramp_reference
    before = times < impacts[1][0]
    errors = []
    for h_max in (4e-6, 2e-6, 1e-6):
        got = ramp_run(dict(solver="euler", h_max=h_max), times)
        assert np.max(np.abs(got["theta"] - ref["theta"])) < 1e-12
        errors.append(np.max(np.abs(got["s"] - ref["s"])[before]))
    assert errors[0] < 2e-5 and all(1.7 < a / b < 2.3 for a, b in zip(errors, errors[1:])), errors


@pytest.mark.parametrize("ratio, leaves", [(0.98, False), (1.02, True)])
def test_jump_speed_in_the_speed_drive(ratio, leaves):
    omega_jump = math.sqrt((F0 + K * H) / (MASS * H / 2 * (math.pi / B) ** 2))
    omega = ratio * omega_jump
    times = np.linspace(0.0, 2 * 2 * math.pi / omega, 4001)
    got = engine_run(SHM, omega, times)
    assert (np.max(got["s"] - got["s_cam"]) > 1e-9) == leaves
    assert np.all(got["s"] >= got["s_cam"] - 2e-12)


def test_restitution_one_keeps_the_flight_energy_and_less_settles():
    """e = 1 without friction: between impacts the follower's energy m v^2/2 + F0 s + k s^2/2 is constant (only the
    output intervals holding an impact change it); e = 0.5 ends the bouncing with the follower back on the cam."""
    omega = 1.3 * math.sqrt((F0 + K * H) / (MASS * H / 2 * (math.pi / B) ** 2))
    times = np.linspace(0.0, 2 * math.pi / omega, 8001)
    elastic = engine_run(dict(SHM, restitution=1.0), omega, times)
    flying = np.flatnonzero(elastic["s"] - elastic["s_cam"] > 1e-9)
    energy = 0.5 * MASS * elastic["v"] ** 2 + F0 * elastic["s"] + 0.5 * K * elastic["s"] ** 2
    pairs = flying[np.isin(flying + 1, flying)]  # two consecutive rows in flight: an impact between them or none
    kept = np.abs(energy[pairs + 1] - energy[pairs]) <= 1e-9 * np.max(energy[flying])
    assert len(pairs) > 1000 and np.count_nonzero(~kept) <= 0.02 * len(pairs)  # only the intervals with an impact
    scene = find_scene("spring_bounce")   # restitution 0.5: the follower rises up to 4.9 mm, then settles
    damped = engine_run(dict(scene.primary.params), 60.0, np.linspace(0.0, scene.stop_time, 2201))
    assert damped["s"][-1] == damped["s_cam"][-1] and np.max(damped["s"] - damped["s_cam"]) > 4e-3


GROOVE = dict(drive="speed", closure="form", c=0.05, restitution=1.0, gamma=-math.pi / 2, mu=0.0, M_f=0.0)


def stepped_runs(params: dict, before: float, after: float, t_step: float, stop: float, n: int):
    """(model, times, engine, reference, the reference's impacts) with omega_ref stepping from ``before`` to ``after``
    [rad/s] at t_step [s]: the engine stepped by a host that sets omega_ref at each communication point."""
    from cam_fmu.physics.drive import DriveModel
    from cam_fmu.physics.signals import Signal
    from cam_fmu.reference.flight import FollowerRun

    model = DriveModel(params)
    times = np.linspace(0.0, stop, n + 1)
    omega_ref = Signal((0.0, t_step, t_step), (before, before, after))
    run = FollowerRun(model, omega_ref, 1e-12, 1e-13)
    ref = run.run(times, model.params["theta0"])
    sim = DriveSimulator(params)
    sim.set_inputs(u=0.0, omega_ref=before, omega_dot_ref=0.0)
    rows = [sim.outputs()]
    for t0, t1 in zip(times[:-1], times[1:]):
        sim.do_step(float(t0), float(t1 - t0), omega_ref=omega_ref.value(float(t0)), omega_dot_ref=0.0)
        rows.append(sim.outputs())
    got = {name: np.array([row[name] for row in rows]) for name in rows[0]}
    return model, times, got, ref, run.impacts


def test_a_step_of_omega_to_zero_lets_the_follower_fly_and_land_with_its_energy():
    """Issue 39.3: the flank rides the rise at 1.05 m/s when omega_ref steps from 15 rad/s to 0. A flank only pushes:
    the follower flies on with 1.05 m/s, turns under gravity and lands on the stopped flank, again and again
    (restitution 1, no friction): its energy m v^2/2 - F_gx s stays what it was at the step, in the engine and the
    reference (before the fix the speed fell to 0 at the step and the energy from 0.438 to 0.222 J of the issue's
    scene)."""
    model, times, got, ref, impacts = stepped_runs(GROOVE, 15.0, 0.0, 0.1, 0.6, 600)
    k = 100   # the row at the step: its left limit in the engine (omega = 15 rad/s before it)
    assert got["v"][k] == pytest.approx(1.05, abs=1e-12)
    energy_at_step = 0.5 * model.m * got["v"][k] ** 2 - model.F_gx * got["s"][k]
    assert len(impacts) >= 2 and all(t > 0.1 for t, _, _ in impacts)   # it lands on the stopped flank, twice
    for out in (got, ref):
        after = slice(k + 1, None)
        energy = 0.5 * model.m * out["v"][after] ** 2 - model.F_gx * out["s"][after]
        assert np.max(np.abs(energy - energy_at_step)) < 1e-9 * energy_at_step
        assert np.max(out["s"][after] - out["s_cam"][after]) > 0.0   # it rose above the flank's middle
    assert np.max(np.abs(got["s"] - ref["s"])) < 1e-10
    rows = np.arange(len(times)) != k   # at the step the reference reports its right limit with the follower on the flank
    assert np.max(np.abs(got["v"][rows] - ref["v"][rows])) < 1e-8


@pytest.mark.parametrize("e", [1.0, 0.5])
def test_a_step_of_omega_up_strikes_the_resting_follower(e):
    """Issue 39.3: the follower rests on the rise's flank (s' = 0.07 m/rad at theta0 = 1 rad) when omega_ref steps
    from 0 to 15 rad/s: the flank strikes it, v+ = (1 + e) s' omega+ from rest (the impact law with an imposed
    speed), then it flies under gravity alone: v = v+ - g t, s = s0 + v+ t - g t^2 / 2 after the step."""
    params = dict(GROOVE, restitution=e, theta0=1.0)
    model, times, got, ref, impacts = stepped_runs(params, 0.0, 15.0, 0.1, 0.2, 200)
    s_cam0, s1, _, _ = model.program.derivatives(1.0)
    v_plus, g, s0 = (1.0 + e) * s1 * 15.0, -model.F_gx / model.m, s_cam0 - model.c
    assert s1 * 15.0 == pytest.approx(1.05, rel=1e-3) and impacts[0][0] == 0.1
    assert got["v"][100] == 0.0   # the engine's left limit at the step: at rest
    for out in (got, ref):
        t = times[101:104] - 0.1
        assert np.max(np.abs(out["v"][101:104] - (v_plus - g * t))) < 1e-9
        assert np.max(np.abs(out["s"][101:104] - (s0 + v_plus * t - 0.5 * g * t * t))) < 1e-10


def test_a_state_saved_in_flight_repeats_its_run():
    scene = find_scene("spring_bounce")
    sim = DriveSimulator(dict(scene.primary.params))
    sim.set_inputs(u=0.0, omega_ref=60.0, omega_dot_ref=0.0)
    k = 0
    while sim.outputs()["s"] - sim.outputs()["s_cam"] < 1e-4:
        sim.do_step(k * 1e-4, 1e-4, omega_ref=60.0)
        k += 1
    state = sim.state_array()   # the whole state, as the FMUs save it

    def onwards():
        rows = []
        for j in range(k, k + 400):
            sim.do_step(j * 1e-4, 1e-4, omega_ref=60.0)
            rows.append((sim.outputs()["s"], sim.outputs()["v"]))
        return rows
    first = onwards()
    sim.set_state_array(state)
    assert onwards() == first


@pytest.mark.external  # the sanitizers (a tool beyond Python and gcc's compiler), as test_engine_sanitize's
def test_the_follower_is_clean_under_asan_and_ubsan(tmp_path):
    gcc = require("gcc")
    generated = [str(p) for p in codegen.write(tmp_path / "generated") if p.suffix == ".c"]
    exe = tmp_path / "follower_driver"
    cmd = [gcc, *FLAGS, f"-I{INCLUDE}", f"-I{tmp_path / 'generated'}", *sorted(str(p) for p in SOURCES.glob("*.c")),
           *generated, str(CSRC / "fmi" / "instance.c"), str(DRIVER), "-o", str(exe), "-lm"]
    built = subprocess.run(cmd, capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    proc = subprocess.run([str(exe)], capture_output=True, text=True, timeout=600,
                          env={"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0", "UBSAN_OPTIONS": "print_stacktrace=1"})
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr[-3000:]
    assert proc.returncode == 0 and proc.stdout.strip().endswith("ok"), proc.stderr[-3000:]
    assert [line.split()[0] for line in proc.stdout.splitlines()[:-1]] == ["spring", "spring", "form", "spring", "form",
                                                                 "spring", "stuck", "stopped"]
    # the three before "stuck": voltage, the last with mu, k_shaft; "stuck": from rest, saved while stuck;
    # "stopped": the cam stuck under the flying follower
