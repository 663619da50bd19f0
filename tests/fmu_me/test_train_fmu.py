"""The follower train in cam.fmu (FMI 2.0 co-simulation and Model Exchange under fmpy's CVode) and cam3.fmu (FMI 3.0
co-simulation): the end mass's outputs and the motor's against the scipy reference (reference/train_voltage.py),
written apart from the engine (docs/model.md 14.6)."""
from __future__ import annotations

import fmpy
import numpy as np
import pytest

from cam_fmu.physics.parameters import defaults
from cam_fmu.reference.integrate import simulate_reference

STOP, STEP, U = 0.6, 0.01, 3.5
TRAIN = {"k_train": 2e4, "d_train": 2.0, "m_end": 0.2, "M_f": 0.0, "mu": 0.0, "u": U}
NAMES = ["theta", "omega", "M", "s_end", "v_end", "a_end", "F_train"]
# max |FMU - reference| / max |reference| measured: co-simulation 2e-7 (the engine at its rtol 1e-10), Model Exchange
# 3e-7 .. 4e-6 with CVode at rtol 1e-10 (a_end, F_train the largest: the train's force is a small difference)
BOUNDS = {"CoSimulation": 2e-6, "ModelExchange": 4e-5}


@pytest.fixture(scope="module")
def reference() -> dict:
    return simulate_reference(dict(defaults(), **{k: v for k, v in TRAIN.items() if k != "u"}), STOP, STEP)


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
def test_cam_fmu_runs_the_train_as_the_reference_does(engine_fmu_path, reference, fmi_type):
    options = {"relative_tolerance": 1e-10} if fmi_type == "ModelExchange" else {}
    result = fmpy.simulate_fmu(str(engine_fmu_path), fmi_type=fmi_type, start_values=TRAIN, stop_time=STOP,
                               output_interval=STEP, output=NAMES, **options)
    rows = [np.nonzero(np.isclose(result["time"], t, rtol=0.0, atol=1e-9))[0][-1] for t in reference["time"]]
    for name in NAMES:
        got = result[name][rows]
        error = np.max(np.abs(got - reference[name])) / np.max(np.abs(reference[name]))
        assert error < BOUNDS[fmi_type], (fmi_type, name, error)
    assert result["F_train"].min() < -1.0 < 1.0 < result["F_train"].max()   # the train rings through both signs


def test_cam3_fmu_runs_the_train_as_the_reference_does(cam3_fmu_path, reference):
    result = fmpy.simulate_fmu(str(cam3_fmu_path), start_values=TRAIN, stop_time=STOP, output_interval=STEP,
                               output=NAMES)
    for name in NAMES:
        error = np.max(np.abs(result[name] - reference[name])) / np.max(np.abs(reference[name]))
        assert error < BOUNDS["CoSimulation"], (name, error)


def test_the_speed_drive_fmu_runs_the_train_as_the_reference_does(engine_fmu_path):
    """cam.fmu's speed drive (co-simulation) at 25 rad/s with the train: measured 5e-9 of each output's largest."""
    from cam_fmu.physics.signals import constant

    start = {k: v for k, v in TRAIN.items() if k != "u"}
    reference = simulate_reference(dict(defaults(), **start, drive="speed"), STOP, STEP, omega_ref=constant(25.0))
    result = fmpy.simulate_fmu(str(engine_fmu_path), start_values=dict(start, drive="speed", omega_ref=25.0),
                               stop_time=STOP, output_interval=STEP, output=NAMES + ["voltage"])
    for name in NAMES[2:] + ["voltage"]:
        error = np.max(np.abs(result[name] - reference[name])) / np.max(np.abs(reference[name]))
        assert error < 1e-7, (name, error)


def test_a_train_the_engine_cannot_run_is_an_fmi_error_with_its_reason(engine_fmu_path):
    logged: list[str] = []

    def logger(*args):
        logged.append(args[-1].decode() if isinstance(args[-1], bytes) else str(args[-1]))

    with pytest.raises(Exception):
        fmpy.simulate_fmu(str(engine_fmu_path), start_values=dict(TRAIN, c=1e-3, closure="kinematic"), stop_time=0.1,
                          output_interval=0.01, logger=logger)
    assert any("k_train" in text and "c = 0.001 m" in text for text in logged), logged


def test_the_shipped_train_scene_runs_in_cam_fmu_as_in_the_reference(engine_fmu_path):
    """`train_voltage` (both runs, 1 s at 12 V with shaft and guide friction) through cam.fmu against the reference:
    measured 6.9e-8 rad and 2.2e-7 of omega's peak (zeta 0.016), 2e-9 and 6e-9 (zeta 0.08), the train's force and
    the load torque within 5.2e-7 of their peaks; the lighter damping rings harder through the second half."""
    from cam_fmu.experiments.runner import run_scene
    from cam_fmu.experiments.scenes import find_scene

    scene = find_scene("train_voltage")
    fmu = run_scene(scene, engine="fmu", fmu_path=engine_fmu_path)
    reference = run_scene(scene, engine="reference")
    for label in fmu:
        for name in ("theta", "omega", "s_end", "F_train", "M"):
            error = np.max(np.abs(fmu[label][name] - reference[label][name])) / np.max(np.abs(reference[label][name]))
            assert error < 5e-6, (label, name, error)
    tail = slice(len(fmu["damped"]["time"]) // 2, None)
    assert np.abs(fmu["damped"]["F_train"][tail]).max() > np.abs(fmu["damped_more"]["F_train"][tail]).max()


# A train on a follower of its own (docs/model.md 14.6): a spring-closed follower that the train and the speed pull
# off the cam, and a groove's follower flying across its clearance, the train ringing through it all.
OWN = {"spring": dict(closure="spring", k_spring=800.0, F_spring0=20.0, restitution=0.5, omega0=60.0, J_cam=0.05,
                      u=11.0),   # the scene spring_voltage's
       "groove": dict(closure="form", c=5e-4, restitution=0.5, u=6.0)}


@pytest.mark.parametrize("closure", list(OWN))
def test_cam_fmu_model_exchange_runs_a_train_on_a_follower_of_its_own_as_co_simulation(engine_fmu_path, closure):
    """Model Exchange under fmpy's CVode (rtol 1e-10, the FMU's event indicators locating every lift-off and
    touch-down) against co-simulation (the engine's rk45 with its own locator), two integrators and two event loops
    on one model: theta within 1e-6 of its largest, the train's force within 1e-4 of its swing (measured 6.7e-9 and
    2.9e-7 on the spring, 1.5e-9 and 3.6e-6 in the groove), and the follower flies."""
    start = {**TRAIN, **OWN[closure]}
    names = NAMES + ["N_contact"]
    runs = {fmi_type: fmpy.simulate_fmu(str(engine_fmu_path), fmi_type=fmi_type, start_values=start, stop_time=0.4,
                                        output_interval=STEP, output=names, relative_tolerance=1e-10)
            for fmi_type in ("CoSimulation", "ModelExchange")}
    cs, me = runs["CoSimulation"], runs["ModelExchange"]
    rows = [np.nonzero(np.isclose(me["time"], t, rtol=0.0, atol=1e-9))[0][-1] for t in cs["time"]]
    assert np.max(np.abs(me["theta"][rows] - cs["theta"])) < 1e-6 * np.max(np.abs(cs["theta"]))
    assert np.max(np.abs(me["F_train"][rows] - cs["F_train"])) < 1e-4 * np.ptp(cs["F_train"])
    assert np.any(cs["N_contact"] == 0.0) and np.ptp(cs["F_train"]) > 1.0


def test_cam_fmu_runs_a_train_on_the_speed_drives_follower_of_its_own_as_the_reference_does(engine_fmu_path):
    """The speed drive (spring_jump's cam above its jump speed, 60 rad/s) with a train on its follower of its own, in
    co-simulation (the speed drive's only interface: Model Exchange refuses it, docs/model.md 13) against the scipy
    reference (reference/train_flight.py's TrainSpeedFollowerRun): s and s_end within 1e-6 of the lift, and the
    follower flies."""
    from cam_fmu.experiments.scenes import find_scene

    scene = find_scene("spring_jump")
    params = dict(next(r for r in scene.runs if r.label == "above_1.02").overrides, k_train=2e4, d_train=2.0,
                  m_end=0.1)
    reference = simulate_reference(dict(defaults(), **params), scene.stop_time, 1e-3, omega_ref=scene.omega_ref)
    assert np.any(reference["N_contact"] == 0.0)
    result = fmpy.simulate_fmu(str(engine_fmu_path), start_values=dict(params, omega_ref=60.0),
                               stop_time=scene.stop_time, output_interval=1e-3, output=["s", "s_end", "N_contact"])
    assert np.array_equal(result["time"], reference["time"])
    for name in ("s", "s_end"):
        error = np.max(np.abs(result[name] - reference[name]))
        assert error < 1e-6 * defaults()["lift"], (name, error)
    assert np.array_equal(result["N_contact"] == 0.0, reference["N_contact"] == 0.0)
