"""A follower train on the follower of its own in the scipy reference (physics/train_follower.py,
reference/train_flight.py; docs/model.md 14.6), against what the test writes itself: the energy balance of section 9
with the train's spring, damper, end mass and weight, on a spring-closed cam and in a groove, with guide and shaft
friction under tilted gravity; on a cam at rest the end mass ringing as the damped oscillator's closed form on the
held follower, and the lift-off where the train's pull, A k_train cos(w t), overcomes the flank's static force; and
the C engine (csrc/src/voltage_follower.c) against the reference on the shipped scene spring_voltage with the train
and in a groove with friction."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.engine.simulator import DriveSimulator
from cam_fmu.experiments.scenes import find_scene
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.parameters import defaults
from cam_fmu.physics.signals import Signal, constant
from cam_fmu.physics.train import Train
from cam_fmu.reference.integrate import output_grid, simulate_reference
from cam_fmu.reference.train_flight import TrainFollowerRun

G_N = 9.80665
SCENE = find_scene("spring_voltage")
TRAIN = dict(k_train=2e4, d_train=5.0, m_end=0.2)   # a 50 Hz train, damping ratio 0.04
FRICTION = dict(mu=0.05, gamma=1.2, beta=0.3)        # guide friction, gravity tilted out of the stroke
GROOVE = dict(closure="form", c=5e-4, k_spring=0.0, F_spring0=0.0, restitution=0.5)
COMPLIANT = dict(k_shaft=100.0, d_shaft=0.01)   # a compliant shaft between the rotor and the cam
CLOSURES = {"spring": dict(), "groove": GROOVE, "compliant": COMPLIANT}


def weights(p: dict) -> tuple[float, float]:
    """N: the follower's and the end mass's weight along X (F_gx, F_ex), gravity tilted by gamma and beta."""
    along = math.sin(p["gamma"]) * math.cos(p["beta"])
    return p["G"] * along, p["m_end"] * G_N * along


def stored(p: dict, r: dict) -> np.ndarray:
    """J, the stored energy from the outputs: the cam side's (J_m + J_cam), the follower's and the end mass's kinetic
    energy, the return spring's F0 s + k s^2 / 2, the train's k_train (s - s_end)^2 / 2, both weights' potential and
    L i^2 / 2; on a compliant shaft the rotor's J_m omega_m^2 / 2 and the shaft's k_shaft (theta_m - theta)^2 / 2."""
    F_gx, F_ex = weights(p)
    s, stretch = r["s"], r["s"] - r["s_end"]
    if p["k_shaft"] > 0.0:
        rotor = (0.5 * p["J_cam"] * r["omega"] ** 2 + 0.5 * p["J_m"] * r["omega_m"] ** 2
                 + 0.5 * p["k_shaft"] * (r["theta_m"] - r["theta"]) ** 2)
    else:
        rotor = 0.5 * (p["J_m"] + p["J_cam"]) * r["omega"] ** 2
    return (rotor + 0.5 * p["m"] * r["v"] ** 2
            + 0.5 * p["m_end"] * r["v_end"] ** 2 + p["F_spring0"] * s + 0.5 * p["k_spring"] * s * s - F_gx * s
            + 0.5 * p["k_train"] * stretch * stretch - F_ex * r["s_end"] + 0.5 * p["L"] * r["i"] ** 2)


@pytest.mark.parametrize("closure", list(CLOSURES))
def test_the_energy_balance_holds_with_the_train_through_flights_impacts_and_friction(closure):
    """E_in - E_copper - E_shaft - E_guide - E_damp - E_impact = the change of the stored energy (c_e = c_m, so the
    motor converts without loss; E_damp the train damper's d_train (v - v_e)^2 and a compliant shaft's): measured
    3.8e-9 J on the spring (3.8e-9 J with the compliant shaft) and 1.1e-8 J in the groove, of 90 J (E_in and the
    stored energy's largest), through 41, 41 and 156 impacts."""
    p = dict(SCENE.primary.params, **TRAIN, **FRICTION, **CLOSURES[closure])
    p["c_e"] = DriveModel(p).c_m
    u, stop = SCENE.u.value(0.0), (0.4 if closure == "groove" else 0.25)
    run = TrainFollowerRun(DriveModel(p), constant(u), 1e-12, 1e-13, True, None)
    r = run.run(output_grid(stop, 1e-3))
    energy = stored(p, r)
    balance = (r["E_in"] - r["E_copper"] - r["E_shaft"] - r["E_guide"] - r["E_damp"] - r["E_impact"]
               - (energy - energy[0]))
    scale = np.max(np.abs(r["E_in"])) + np.max(np.abs(energy))
    assert np.max(np.abs(balance)) < 1e-9 * scale, np.max(np.abs(balance))
    # every loss takes part: the follower flies and strikes, the guide rubs, the train's damper works
    assert len(run.impacts) > 20 and len(run.lift_offs) >= 2 and np.sum(r["contact"] == 0.0) > 50
    assert min(r["E_guide"][-1], r["E_damp"][-1], r["E_impact"][-1], r["E_shaft"][-1]) > 0.1
    assert np.ptp(r["F_train"]) > 100.0
    if closure == "groove":
        assert -1.0 in r["contact"]   # the upper flank carries it too


# The cam at rest on its upper dwell (omega0 = 0, u = 0: the shaft stuck under its friction M_f), the follower on its
# spring-closed flank, the end mass let go A from its rest.
RISE = math.pi / 2
HELD = dict(rise_law="cycloidal", return_law="cycloidal", rise_angle=RISE, upper_dwell=RISE, return_angle=RISE,
            lower_dwell=RISE, lift=0.02, r_b=0.08, m=0.4, G=4.0, M_f=0.012, mu=0.0, J_cam=2e-3, gravity=True,
            gamma=1.2, beta=0.3, drive="voltage", formulation="consistent", closure="spring", k_spring=500.0,
            F_spring0=5.0, omega0=0.0, theta0=2.0, k_train=2e4, m_end=0.2)


def held_cam(A: float, d_train: float, stop: float) -> tuple[dict, TrainFollowerRun, dict]:
    p = dict(defaults(), **HELD, d_train=d_train)
    run = TrainFollowerRun(DriveModel(p), constant(0.0), 1e-12, 1e-13, False, None, end_offset=A)
    return p, run, run.run(output_grid(stop, 1e-4))


def test_the_end_mass_rings_as_the_damped_oscillator_on_the_held_follower():
    """A = 0.2 mm, d_train = 5 N s/m (zeta 0.04): the follower stays on its flank, the cam stuck, and x_e - x_rest
    follows A exp(-zeta w t) (cos(w_d t) + zeta w / w_d sin(w_d t)) (measured within 8.4e-15 m of 0.2 mm)."""
    A, d_train = 2e-4, 5.0
    p, run, r = held_cam(A, d_train, 0.03)
    F_gx, F_ex = weights(p)
    rest = p["lift"] + F_ex / p["k_train"]   # the weight's deflection below the follower at s = h
    k, m_e = p["k_train"], p["m_end"]
    w = math.sqrt(k / m_e)
    zeta = d_train / (2 * math.sqrt(k * m_e))
    w_d = w * math.sqrt(1 - zeta * zeta)
    t = r["time"]
    expected = A * np.exp(-zeta * w * t) * (np.cos(w_d * t) + zeta * w / w_d * np.sin(w_d * t))
    assert np.max(np.abs(r["s_end"] - rest - expected)) < 1e-12
    assert np.all(r["contact"] == 1.0) and np.all(r["N_contact"] > 0.0)
    assert np.all(r["s"] == p["lift"]) and np.all(r["omega"] == 0.0) and np.all(r["theta"] == p["theta0"])
    # the flank carries the spring, the follower's weight and the train's force
    assert np.allclose(r["N_contact"], p["F_spring0"] + p["k_spring"] * p["lift"] - F_gx + r["F_train"],
                       rtol=1e-13, atol=1e-12)


def test_the_train_pulls_the_follower_off_when_its_ringing_overcomes_the_spring():
    """A = -2 mm, undamped: the flank's force is P0 + k_train |A| cos(w t) with P0 = F0 + k h - F_gx - F_ex (the
    spring, both weights), so the follower leaves at t = arccos(-P0 / (k_train |A|)) / w, the reference's lift-off
    event on the stuck cam (measured 3.9e-15 s from it, at 5.74 ms)."""
    A = -2e-3
    p, run, r = held_cam(A, 0.0, 0.01)
    F_gx, F_ex = weights(p)
    P0 = p["F_spring0"] + p["k_spring"] * p["lift"] - F_gx - F_ex
    w = math.sqrt(p["k_train"] / p["m_end"])
    expected = math.acos(-P0 / (p["k_train"] * abs(A))) / w
    assert run.lift_offs and abs(run.lift_offs[0][0] - expected) < 1e-12, run.lift_offs
    before = r["time"] < expected
    assert np.all(r["contact"][before] == 1.0) and r["contact"][-1] == 0.0 and r["N_contact"][-1] == 0.0
    assert np.all(r["omega"] == 0.0)   # the cam stays stuck; the follower flies off its dwell


def test_a_follower_pulled_off_against_guide_friction_is_held_until_the_pull_beats_it():
    """The same let-go with guide friction, gravity along Y (G_y = G: f0 = mu G at no contact force): the flank's force
    P0 + k_train |A| cos(w t) reaches 0 (the lift-off) with the follower at rest, which the guide's static friction
    holds until the train's pull passes f0, at t = arccos(-(P0 + f0) / (k_train |A|)) / w: the reference's release
    event (measured 9.4e-14 s from it; its hysteresis of 1e-9 N is 1.6e-13 s there), and the follower then flies."""
    A, mu = -2e-3, 0.3
    p = dict(defaults(), **dict(HELD, mu=mu, gamma=math.pi / 2, beta=math.pi / 2), d_train=0.0)
    run = TrainFollowerRun(DriveModel(p), constant(0.0), 1e-12, 1e-13, True, None, end_offset=A)
    r = run.run(output_grid(0.012, 1e-4))
    P0, f0 = p["F_spring0"] + p["k_spring"] * p["lift"], mu * p["G"]
    w = math.sqrt(p["k_train"] / p["m_end"])
    lift_off, release = (math.acos(-(P0 + f) / (p["k_train"] * abs(A))) / w for f in (0.0, f0))
    assert abs(run.lift_offs[0][0] - lift_off) < 1e-12 and abs(run.releases[0] - release) < 1e-12, run.releases
    held = (r["time"] > lift_off) & (r["time"] < release)
    assert np.any(held) and np.all(r["v"][held] == 0.0) and np.all(r["s"][held] == p["lift"])
    assert np.all(r["contact"][held] == 0.0) and np.all(r["v"][r["time"] > release] > 0.0)   # off the flank


def test_the_reference_routes_a_train_with_a_follower_of_its_own():
    """simulate_reference with k_train > 0 and closure 'spring' is this run; a Train given apart is the same run."""
    p = dict(SCENE.primary.params, **TRAIN)
    routed = simulate_reference(p, 0.02, 1e-3, u=SCENE.u)
    run = TrainFollowerRun(DriveModel(p), SCENE.u, 1e-12, 1e-13, False, None).run(output_grid(0.02, 1e-3))
    given = simulate_reference(dict(p, k_train=0.0, d_train=0.0, m_end=0.0), 0.02, 1e-3, u=SCENE.u,
                               train=Train(**TRAIN))
    for name in ("theta", "s", "s_end", "F_train"):
        assert np.array_equal(routed[name], run[name]) and np.array_equal(given[name], run[name])
    assert np.ptp(routed["F_train"]) > 1.0


# ----------------------------------------------------------------------------- the C engine against the reference
NAMES = ("theta", "omega", "s", "v", "s_end", "v_end", "F_train", "M", "N_contact")
STOP, STEP = 0.25, 1e-3   # s
# (parameters beyond the scene's primary run with the train, bound on every NAME's max |engine - reference| relative to
# the reference's largest |value|): measured at most 8.3e-10 on the spring (v), 4.6e-8 in the groove (F_train,
# at its last rows, after 105 impacts: the reference at rtol 1e-11 differs from itself at 1e-12 by 4.4e-8, the run's
# own conditioning), with friction and a compliant shaft 5.7e-11 (omega_m) and 1.8e-9 (M_shaft, of 0.16 N m)
ENGINE = {"spring": (dict(), 5e-9), "groove": (dict(GROOVE, **FRICTION), 2e-7),
          "compliant": (dict(COMPLIANT, **FRICTION), 5e-9)}


def engine_run(params: dict, u: Signal) -> dict[str, np.ndarray]:
    """The engine's outputs on the grid, the input held over each step at its value at its start."""
    sim = DriveSimulator(params)
    grid = np.arange(int(round(STOP / STEP)) + 1) * STEP
    sim.set_inputs(u.value(0.0), 0.0, 0.0)
    rows = [sim.outputs()]
    for t in grid[:-1]:
        sim.do_step(float(t), STEP, u=u.value(float(t)), omega_ref=0.0, omega_dot_ref=0.0)
        rows.append(sim.outputs())
    return {name: np.array([r[name] for r in rows]) for name in rows[0]}


def worst(engine: dict, reference: dict, name: str) -> float:
    """max |engine - reference| over the grid relative to the reference's largest |value|."""
    return float(np.max(np.abs(engine[name] - reference[name]) / np.max(np.abs(reference[name]))))


@pytest.mark.parametrize("case", list(ENGINE))
def test_the_engine_runs_the_train_on_a_follower_of_its_own_as_the_reference(case):
    extra, bound = ENGINE[case]
    p = dict(SCENE.primary.params, **TRAIN, **extra)
    engine = engine_run(p, SCENE.u)
    reference = simulate_reference(p, STOP, STEP, u=SCENE.u)
    for name in NAMES + (("omega_m", "M_shaft") if "k_shaft" in extra else ()):
        assert worst(engine, reference, name) < bound, (name, worst(engine, reference, name))
    assert np.sum(reference["contact"] == 0.0) > 100 and reference["impacts"][-1] > 40   # it flies and strikes
    assert np.ptp(reference["F_train"]) > 100.0
