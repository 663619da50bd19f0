"""The C engine through its Python binding (``DriveSimulator``): checks, errors, state, whole-scene runs.

The engine's numbers are held elsewhere: to the record of the former engine
(tests/engine/test_engine_baseline.py), to the scipy reference (tests/fmu_cs/test_fmu_vs_reference.py)
and to closed forms. Here: the parameter checks generated into C against the Python
model's own (``physics.parameters.resolve`` and ``physics.drive.DriveModel``), the
errors of the guards and of the work bound, and state round trips to the bit.
"""
from __future__ import annotations

import struct

import pytest

from cam_fmu.engine.simulator import DriveSimulator, run_scene
from cam_fmu.errors import SimulationError, StepRejected
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.parameters import ParameterError, resolve
from cam_fmu.physics.variables import OUTPUT_NAMES


def _bits(outputs: dict) -> bytes:
    """The outputs' exact bits (0.0 and -0.0 differ here, unlike ==)."""
    return struct.pack(f"{len(OUTPUT_NAMES)}d", *(outputs[name] for name in OUTPUT_NAMES))


def _error(make, *step):
    try:
        sim = make()
        if step:
            sim.do_step(*step)
    except Exception as exc:  # the class and the text are what is compared
        return type(exc), str(exc)
    return None


@pytest.mark.parametrize("scene_params", [{}, {"c": 5e-4}, {"L": 1e-3}, {"formulation": "paper"},
                                          {"drive": "speed"}, {"solver": "rk4", "h_max": 1e-4}],
                         ids=lambda p: ",".join(f"{k}={v}" for k, v in p.items()) or "defaults")
def test_a_state_round_trip_continues_to_the_bit(scene_params):
    h = 1e-3
    through, stopped = DriveSimulator(scene_params), DriveSimulator(scene_params)
    for k in range(300):
        through.do_step(k * h, h, 3.5, 5.0)
        stopped.do_step(k * h, h, 3.5, 5.0)
    resumed = DriveSimulator(scene_params)
    resumed.set_state_array(stopped.state_array())
    for k in range(300, 600):
        for sim in (through, resumed):
            sim.do_step(k * h, h, 3.5, 5.0)
    assert _bits(through.outputs()) == _bits(resumed.outputs())
    assert through.outputs()["theta"] > 1.0  # it moved


def test_a_whole_scene_in_one_call_equals_the_step_loop_to_the_bit():
    h, n = 1e-3, 500
    table = [(k * h, h, 3.5 if k < 250 else 7.0, 1.0, 0.0) for k in range(n)]
    rows = run_scene({"c": 5e-4}, table)
    sim = DriveSimulator({"c": 5e-4})
    for k, row in enumerate(table):
        sim.do_step(*row)
        assert struct.pack(f"{len(OUTPUT_NAMES)}d", *rows[k]) == _bits(sim.outputs()), k


@pytest.mark.parametrize("params", [
    {"R": 0.0}, {"L": 1e-12}, {"mu": "lots"}, {"solver": "rk99"}, {"backlash": "maybe"}, {"unknown": 1.0},
    {"rise_angle": 3.0}, {"max_steps": 0.5}, {"rise_law": "custom", "rise_T3": 1.5}, {"lift": -1.0},
    {"mu": 0.5, "r_b": 0.01},
], ids=lambda p: ",".join(p))
def test_a_bad_parameter_is_the_python_models_error(params):
    """The C engine's checks (generated from physics/parameters.py, with drive.py's model checks written
    in C) refuse what the Python model refuses, with the same class and text."""
    python, engine = _error(lambda: DriveModel(params)), _error(lambda: DriveSimulator(params))
    assert python is not None and python[0] is ParameterError
    assert engine == python


def _probes():
    """For every parameter, values on and beyond its range's edges (or bad choices/texts)."""
    from cam_fmu.physics.parameters import PARAMETERS
    probes = []
    for spec in PARAMETERS:
        if spec.kind == "real":
            values = [spec.low, spec.high, spec.low - 1.0 - abs(spec.low), 2.0 * spec.high + 1.0, 0.0,
                      float("nan"), float("-inf"), "1e-3", "x", None]
        elif spec.kind == "boolean":
            values = [True, 0, "yes", "Off", "maybe"]
        elif spec.choices:
            values = [*spec.choices, "nope", 3]
        else:
            continue
        probes += [pytest.param({spec.name: value}, id=f"{spec.name}={value!r}") for value in values]
    return probes


@pytest.mark.parametrize("params", _probes())
def test_every_parameter_is_checked_as_the_python_model_checks_it(params):
    """Refused by both with the same text, or accepted by both."""
    assert _error(lambda: DriveSimulator(params)) == _error(lambda: DriveModel(params))


def test_max_steps_is_a_step_rejected_that_leaves_the_state():
    sim = DriveSimulator({"max_steps": 50.0, "L": 1e-3})
    before = sim.state_array()
    error = _error(lambda: sim, 0.0, 1e-2, 3.5, 1.0)
    assert error[0] is StepRejected and "max_steps = 50" in error[1]
    assert sim.state_array() == before
    sim.do_step(0.0, 1e-4, 3.5, 1.0)  # a shorter step then succeeds
    assert sim.outputs()["i"] > 0.0


@pytest.mark.parametrize("step, names", [((0.0, 0.0, 3.5, 1.0), "communication step"),
                                         ((0.0, float("nan"), 3.5, 1.0), "communication step"),
                                         ((0.0, 1e-3, 2e4, 1.0), "'u'"), ((0.0, 1e-3, 3.5, -1e5), "'omega_ref'"),
                                         ((0.0, 1e-3, 3.5, 1.0, float("inf")), "'omega_dot_ref'")])
def test_a_bad_step_or_input_is_an_error_naming_it(step, names):
    error = _error(DriveSimulator, *step)
    assert error is not None and error[0] is SimulationError and names in error[1], error


def test_a_state_whose_books_disagree_with_its_energy_is_not_restored():
    """A state whose books say the source delivered far less than the drive holds: energy was created. The
    restore refuses it with the step guard's verdict (it used to restore, and the next step refused it)."""
    sim = DriveSimulator()
    for k in range(200):
        sim.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
    saved, before = sim.get_state(), sim.outputs()
    state = dict(saved, energy=dict(saved["energy"], work_in=-1.0))
    error = _error(lambda: sim.set_state(state))
    assert error[0] is SimulationError and "more energy than its account" in error[1]
    assert sim.outputs() == before and sim.get_state() == saved  # nothing restored
    sim.do_step(0.2, 1e-3, 3.5, 1.0)  # the drive as it was goes on


def test_the_step_floor_is_a_step_rejected_naming_rtol():
    """A diverging state (omega = 1e150: the right-hand side overflows) drives rk45's step below its floor;
    at omega = 1e200 the outputs themselves overflow, and the restore refuses it."""
    sim = DriveSimulator()
    state = sim.get_state()
    state["mode"] = dict(state["mode"], stuck=False)
    state["y"] = [0.5, 1e200]
    error = _error(lambda: sim.set_state(state))
    assert error[0] is SimulationError and "is none the drive can reach" in error[1]
    state["y"] = [0.5, 1e150]
    sim.set_state(state)
    error = _error(lambda: sim, 0.0, 1e-3, 3.5, 1.0)
    assert error[0] is StepRejected and "its step fell below 1e-15 s" in error[1] and "rtol" in error[1]


def test_a_follower_beyond_the_clearance_is_not_restored():
    """A follower 10 mm off the cam in a 0.5 mm gap: no state the drive can be in (the step guard that names a
    missed contact sees the same thing; the restore now refuses it first)."""
    sim = DriveSimulator({"c": 5e-4, "closure": "kinematic"})
    for k in range(100):
        sim.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
    state, out = sim.get_state(), sim.outputs()
    state["y"] = [state["y"][0], 0.0]
    state["mode"] = dict(state["mode"], stuck=True, contact=0, s_free=out["s_cam"] + 0.01)
    error = _error(lambda: sim.set_state(state))
    assert error[0] is SimulationError and "beyond the clearance c = 0.0005 m" in error[1] and "s_free" in error[1]
    assert sim.outputs() == out


def test_resolve_and_the_model_agree_on_what_they_accept():
    """The probe's oracle is DriveModel: it must itself run resolve's checks first."""
    assert _error(lambda: resolve({"R": 0.0}))[1] == _error(lambda: DriveModel({"R": 0.0}))[1]
