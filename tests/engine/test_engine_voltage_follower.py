"""The C engine's spring-closed follower on a voltage-driven cam (csrc/src/voltage_follower.c; docs/model.md 13.6)
against the scipy reference (physics/voltage_follower.py, reference/voltage_flight.py: DOP853 at rtol 1e-12 where
the engine takes fixed Runge-Kutta steps), and against invariants; under ASan/UBSan in
tests/engine/test_engine_follower.py (follower_driver.c's voltage case)."""
from __future__ import annotations

import numpy as np
import pytest

from cam_fmu.experiments.runner import _reference
from cam_fmu.experiments.scenes import find_scene
from cam_fmu.fmu.engine import DriveSimulator
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.parameters import ParameterError


def engine_run(params: dict, u: float, times: np.ndarray) -> dict[str, np.ndarray]:
    """The engine stepped over ``times`` at the constant voltage u [V]: its outputs there."""
    sim = DriveSimulator(params)
    sim.set_inputs(u=u, omega_ref=0.0, omega_dot_ref=0.0)
    rows = [sim.outputs()]
    for t0, t1 in zip(times[:-1], times[1:]):
        sim.do_step(float(t0), float(t1 - t0), u=u)
        rows.append(sim.outputs())
    return {name: np.array([row[name] for row in rows]) for name in rows[0]}


SCENE = find_scene("spring_voltage")


@pytest.mark.parametrize("name, label", [(name, run.label) for name in ("spring_voltage", "groove_voltage")
                                         for run in find_scene(name).runs])
def test_the_engine_is_the_reference(name, label):
    scene = find_scene(name)
    run = next(r for r in scene.runs if r.label == label)
    ref = _reference(scene, run)
    got = engine_run(dict(run.params), scene.u.value(0.0), ref["time"])
    assert np.max(ref["impacts"]) > 1 and np.max(np.abs(ref["s"] - ref["s_cam"])) >= 1e-4   # it leaves and lands
    if run.params["closure"] == "form":   # within the groove's clearance; a spring's follower never inside the cam
        assert np.max(np.abs(got["s"] - got["s_cam"])) <= run.params["c"] + 2e-12
    assert np.min(got["s"] - got["s_cam"]) >= -run.params["c"] - 2e-12
    assert np.max(np.abs(got["theta"] - ref["theta"])) < 1e-9        # rad (measured 1.3e-10)
    assert np.max(np.abs(got["omega"] - ref["omega"])) < 1e-7        # rad/s (measured 5.9e-9)
    assert np.max(np.abs(got["s"] - ref["s"])) < 1e-10               # m (measured 9.4e-12)
    assert np.max(np.abs(got["v"] - ref["v"])) < 2e-8                # m/s (measured 2.0e-9)
    assert np.max(np.abs(got["a"] - ref["a"])) < 2e-6                # m/s2 (measured 2.5e-7)
    for key in ("M", "i", "J", "N_contact"):
        assert np.max(np.abs(got[key] - ref[key])) < 1e-8 * np.max(np.abs(ref[key])), key


def test_elastic_bounces_keep_the_energy_and_less_settles():
    """e = 1, no friction, c_e = c_m: the engine's stored energy (shaft, follower, spring) equals the reference's,
    whose balance against E_in - E_copper holds to 1e-11 (tests/physics/test_voltage_follower.py); the engine's own
    energy bound holds at every step (a step that created energy would be refused). e = 0.5 ends on the cam."""
    params = dict(SCENE.primary.params, restitution=1.0, shaft_friction=False, c_e=0.015 * 9.80665)
    model = DriveModel(params)
    times = np.linspace(0.0, 0.3, 3001)
    got = engine_run(params, 11.0, times)
    from cam_fmu.reference.integrate import simulate_reference
    from cam_fmu.physics.signals import constant
    ref = simulate_reference(params, 0.3, 1e-4, u=constant(11.0), energy=True)

    def stored(r):
        return (0.5 * model.J_0 * r["omega"] ** 2 + 0.5 * model.m * r["v"] ** 2 + model.F_spring0 * r["s"]
                + 0.5 * model.k_spring * r["s"] ** 2)

    assert ref["impacts"][-1] >= 20
    assert np.max(np.abs(stored(got) - stored(ref))) < 1e-7 * np.max(stored(ref))
    balance = ref["E_in"] - ref["E_copper"] - (stored(got) - stored(got)[0])
    assert np.max(np.abs(balance)) < 1e-7 * np.max(stored(ref))
    damped = engine_run(dict(SCENE.primary.params), 11.0, np.linspace(0.0, 0.25, 2501))
    assert damped["s"][-1] == damped["s_cam"][-1] and np.max(damped["s"] - damped["s_cam"]) > 1e-4


@pytest.mark.parametrize("name", ["spring_voltage", "groove_voltage"])
def test_a_state_saved_in_flight_repeats_the_run(name):
    scene = find_scene(name)
    u, c = scene.u.value(0.0), scene.primary.params["c"]
    sim = DriveSimulator(dict(scene.primary.params))
    sim.set_inputs(u=u, omega_ref=0.0, omega_dot_ref=0.0)
    t, k = 0.0, 0
    while abs(abs(sim.outputs()["s"] - sim.outputs()["s_cam"]) - c) < 1e-6:   # on a flank
        sim.do_step(t, 1e-4, u=u)
        t, k = t + 1e-4, k + 1
        assert k < 5000
    saved, state = sim.state_array(), sim.get_state()   # the whole engine state, as fmi2GetFMUstate saves it

    def go() -> list[dict]:
        rows, tt = [], t
        for _ in range(500):
            sim.do_step(tt, 1e-4, u=u)
            tt += 1e-4
            rows.append(sim.outputs())
        return rows

    first = go()
    sim.set_state_array(saved)
    assert go() == first
    sim.set_state(state)   # the binding's dict of the state, as JSON would carry it
    assert go() == first


def test_the_shaft_stopping_is_refused_with_the_reason():
    """A flywheel too light to carry the spring through: the shaft stops, which the engine refuses (never a wrong
    answer with status OK), as the reference does."""
    from cam_fmu.errors import SimulationError
    sim = DriveSimulator(dict(SCENE.primary.params, J_cam=2e-3))
    sim.set_inputs(u=11.0, omega_ref=0.0, omega_dot_ref=0.0)
    with pytest.raises(SimulationError, match="the shaft stops"):
        for k in range(2500):
            sim.do_step(k * 1e-4, 1e-4, u=11.0)


def test_the_engine_refuses_what_it_does_not_compute():
    with pytest.raises(ParameterError, match="'k_shaft'"):
        DriveSimulator(dict(SCENE.primary.params, k_shaft=100.0))


@pytest.mark.parametrize("change, u", [
    (dict(k_spring=0.0, F_spring0=30.0), 11.0),          # a preload only: parabolic flight, 0.24 m off the cam
    (dict(F_spring0=0.0, k_spring=900.0), 11.0),         # no preload: 12 touch-downs
    (dict(restitution=1.0, omega0=120.0, J_cam=0.2), 20.0),   # e = 1 at twice the speed: 0.54 m off the cam
])
def test_extremes_are_the_reference(change, u):
    from cam_fmu.physics.signals import constant
    from cam_fmu.reference.integrate import simulate_reference
    params = dict(SCENE.primary.params, **change)
    ref = simulate_reference(params, 0.12, 1e-4, u=constant(u))
    got = engine_run(params, u, ref["time"])
    assert np.max(ref["s"] - ref["s_cam"]) > 1e-3
    assert np.max(np.abs(got["s"] - ref["s"])) < 1e-10            # m (measured 9e-12)
    assert np.max(np.abs(got["omega"] - ref["omega"])) < 1e-7     # rad/s (measured 3e-9)
    assert np.min(got["s"] - got["s_cam"]) >= -2e-12
