"""The C engine (cam_fmu.engine) against today's DriveSimulator: the consistent formulation with rk45.

The engine is a port of the kernel's rk45 path with the order of floating-point
operations kept, so the two implementations must agree to the last bit at every
communication step of every shipped voltage scene, in the internal step count,
in the state reached, and in the class and text of their errors.
"""
from __future__ import annotations

import struct

import pytest

from cam_fmu.engine.simulator import EngineSimulator, run_scene
from cam_fmu.errors import SimulationError, StepRejected
from cam_fmu.experiments.scenes import find_scene, scene_names
from cam_fmu.fmu.engine import DriveSimulator
from cam_fmu.physics.parameters import ParameterError, resolve
from cam_fmu.physics.variables import INPUT_STARTS, OUTPUT_NAMES


def _voltage_cases():
    """(scene, params) of every voltage scene's runs, consistent with rk45 (a scene's duplicate runs once)."""
    cases = []
    for name in scene_names():
        scene = find_scene(name)
        if scene.drive != "voltage":
            continue
        seen = []
        for run in scene.runs:
            params = dict(run.overrides, solver="rk45", formulation="consistent")
            if resolve(params) in seen:
                continue
            seen.append(resolve(params))
            cases.append(pytest.param(scene, params, id=f"{name}-{run.label}"))
    return cases


CASES = _voltage_cases()


def _inputs(scene, k: int, h: float) -> tuple[float, float]:
    t = k * h
    u = scene.u.value(t) if scene.u is not None else INPUT_STARTS["u"]
    w = scene.omega_ref.value(t) if scene.omega_ref is not None else INPUT_STARTS["omega_ref"]
    return u, w


def _bits(outputs: dict) -> bytes:
    """The outputs' exact bits (0.0 and -0.0 differ here, unlike ==)."""
    return struct.pack(f"{len(OUTPUT_NAMES)}d", *(outputs[name] for name in OUTPUT_NAMES))


def test_every_voltage_scene_is_covered():
    names = {case.values[0].name for case in CASES}
    voltage = {name for name in scene_names() if find_scene(name).drive == "voltage"}
    assert names == voltage and len(voltage) >= 4 and len(CASES) >= 7


@pytest.mark.parametrize("scene, params", CASES)
def test_bit_identical_outputs_at_every_communication_step(scene, params):
    old, new = DriveSimulator(params), EngineSimulator(params)
    h = scene.output_interval
    n = round(scene.stop_time / h)
    assert _bits(old.outputs()) == _bits(new.outputs())
    table = []
    for k in range(n):
        u, w = _inputs(scene, k, h)
        old.do_step(k * h, h, u, w)
        new.do_step(k * h, h, u, w)
        table.append((k * h, h, u, w, 0.0))
        if _bits(old.outputs()) != _bits(new.outputs()):
            diff = {name: (a, b) for (name, a), b in zip(old.outputs().items(), new.outputs().values()) if a != b}
            pytest.fail(f"step {k} (t = {(k + 1) * h:g} s): outputs differ {diff}")
    assert old.steps_taken == new.steps_taken > 0
    assert old.time == new.time
    a, b = old.get_state(), new.get_state()
    assert (a["y"], a["mode"], a["h_next"], a["energy"]) == (b["y"], b["mode"], b["h_next"], b["energy"])
    # the whole scene in one engine call gives the same bits as the steps one by one
    rows = run_scene(params, table)
    assert struct.pack(f"{len(rows[-1])}d", *rows[-1]) == _bits(new.outputs())


def test_a_state_round_trip_continues_to_the_bit():
    scene = find_scene("backlash")
    params = dict(scene.runs[0].overrides)
    h = scene.output_interval
    through, stopped = EngineSimulator(params), EngineSimulator(params)
    for k in range(300):
        through.do_step(k * h, h, 3.5, 1.0)
        stopped.do_step(k * h, h, 3.5, 1.0)
    saved = stopped.get_state()
    resumed = EngineSimulator(params)
    resumed.set_state(saved)
    old = DriveSimulator(params)
    old.set_state({key: value for key, value in saved.items() if key != "engine"})
    for k in range(300, 600):
        for sim in (through, resumed, old):
            sim.do_step(k * h, h, 3.5, 1.0)
    assert _bits(through.outputs()) == _bits(resumed.outputs()) == _bits(old.outputs())


def _error(make, *step):
    try:
        sim = make()
        if step:
            sim.do_step(*step)
    except Exception as exc:  # the class and the text are what is compared
        return type(exc), str(exc)
    return None


@pytest.mark.parametrize("params", [
    {"R": 0.0}, {"L": 1e-12}, {"mu": "lots"}, {"solver": "rk99"}, {"backlash": "maybe"}, {"unknown": 1.0},
    {"rise_angle": 3.0}, {"max_steps": 0.5}, {"rise_law": "custom", "rise_T3": 1.5}, {"lift": -1.0},
    {"mu": 0.5, "r_b": 0.01},
], ids=lambda p: ",".join(p))
def test_a_bad_parameter_is_the_same_error(params):
    old, new = _error(lambda: DriveSimulator(params)), _error(lambda: EngineSimulator(params))
    assert old is not None and old[0] is ParameterError
    assert new == old


def test_max_steps_is_the_same_step_rejected_and_leaves_the_state():
    params = {"max_steps": 50.0, "L": 1e-3}
    old, new = DriveSimulator(params), EngineSimulator(params)
    before = new.get_state()
    errors = [_error(lambda sim=sim: sim, 0.0, 1e-2, 3.5, 1.0) for sim in (old, new)]
    assert errors[0][0] is StepRejected and "max_steps = 50" in errors[0][1]
    assert errors[1] == errors[0]
    after = new.get_state()
    assert (after["y"], after["mode"], after["time"]) == (before["y"], before["mode"], before["time"])
    for sim in (old, new):  # a shorter step then succeeds, from the same state in both
        sim.do_step(0.0, 1e-4, 3.5, 1.0)
    assert _bits(old.outputs()) == _bits(new.outputs())


@pytest.mark.parametrize("step", [(0.0, 0.0, 3.5, 1.0), (0.0, float("nan"), 3.5, 1.0), (0.0, 1e-3, 2e4, 1.0),
                                  (0.0, 1e-3, 3.5, -1e5), (0.0, 1e-3, 3.5, 1.0, float("inf"))])
def test_a_bad_step_or_input_is_the_same_error(step):
    old, new = _error(DriveSimulator, *step), _error(EngineSimulator, *step)
    assert old is not None and old[0] is SimulationError
    assert new == old


def test_the_energy_guard_is_the_same_error():
    """A state whose books say the source delivered far less than the drive holds: energy was created."""
    sims = [DriveSimulator(), EngineSimulator()]
    for sim in sims:
        for k in range(200):
            sim.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
    state = sims[0].get_state()
    state["energy"] = dict(state["energy"], work_in=-1.0)
    for sim in sims:
        sim.set_state(state)
    errors = [_error(lambda sim=sim: sim, 0.2, 1e-3, 3.5, 1.0) for sim in sims]
    assert errors[0][0] is SimulationError and "energy was created" in errors[0][1]
    _same_but_the_rk45_advice(errors[0], errors[1])


def _baseline_cases():
    """The recorded cases (tests/data/engine_baseline) of the consistent voltage drive with rk45."""
    from cam_fmu.tools import baseline
    cases = []
    for data in baseline.load().values():
        for case in data["cases"]:
            p = resolve(case["params"])
            if (p["drive"], p["formulation"], p["solver"]) == ("voltage", "consistent", "rk45"):
                cases.append(pytest.param(case, id=case["name"]))
    return cases


BASELINE = _baseline_cases()


def test_the_baseline_holds_scenes_and_extremes_of_this_path():
    names = [case.values[0]["name"] for case in BASELINE]
    assert len(names) >= 15 and sum(name.startswith("extremes/") for name in names) >= 8


@pytest.mark.parametrize("case", BASELINE)
def test_the_engine_reproduces_the_recorded_baseline_to_the_bit(case, monkeypatch):
    """The recorded run (the Cython-kernel engine) replayed on the C engine: every sample, the final
    outputs and the error (class, step, message) exactly equal."""
    from cam_fmu.fmu import engine as python_engine
    from cam_fmu.tools import baseline
    monkeypatch.setattr(python_engine, "DriveSimulator", EngineSimulator)
    result = baseline.replay(case)
    recorded = case["result"]
    assert result["error"] == recorded["error"]
    assert result["steps"] == recorded["steps"]
    assert result["outputs"] == recorded["outputs"] and result["final"] == recorded["final"]


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
            # the other formulations and solvers are not yet in the C engine: their choices are probed as laws'
            values = [spec.default, "nope", 3] + ([spec.choices[0]] if spec.name.endswith("_law") else [])
        else:
            continue
        probes += [pytest.param({spec.name: value}, id=f"{spec.name}={value!r}") for value in values]
    return probes


@pytest.mark.parametrize("params", _probes())
def test_every_parameter_is_checked_with_the_same_message(params):
    """The C engine's checks (generated from physics/parameters.py) against ParameterSpec.check and
    resolve: the same refusal with the same text, or both accept (then the same first outputs)."""
    old, new = _error(lambda: DriveSimulator(params)), _error(lambda: EngineSimulator(params))
    assert new == old
    if old is None and resolve(params)["drive"] == "voltage" and resolve(params)["formulation"] == "consistent" \
            and resolve(params)["solver"] == "rk45":
        assert _bits(DriveSimulator(params).outputs()) == _bits(EngineSimulator(params).outputs())


def _from_state(params, steps, change, step):
    """Both engines: ``steps`` steps at 3.5 V, the state changed by ``change``, then ``step``: the error."""
    sims = [DriveSimulator(params), EngineSimulator(params)]
    for sim in sims:
        for k in range(steps):
            sim.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
    state = sims[0].get_state()
    change(state, sims[0].outputs())
    for sim in sims:
        sim.set_state(state)
    return [_error(lambda sim=sim: sim, *step) for sim in sims]


def test_the_step_floor_is_the_same_step_rejected():
    """A diverging state (omega = 1e200: the right-hand side overflows) drives rk45's step below its floor."""
    def change(state, out):
        state["y"] = [0.5, 1e200]
        state["mode"] = dict(state["mode"], stuck=False)
    old, new = _from_state({}, 0, change, (0.0, 1e-3, 3.5, 1.0))
    assert old[0] is StepRejected and "its step fell below 1e-15 s" in old[1]
    assert new == old


def test_the_clearance_guard_is_the_same_error():
    """A follower 10 mm off the cam in a 0.5 mm gap, held at rest (u = 0): a missed contact."""
    def change(state, out):
        state["y"] = [state["y"][0], 0.0]
        state["mode"] = dict(state["mode"], stuck=True, contact=0, s_free=out["s_cam"] + 0.01)
    old, new = _from_state({"c": 5e-4}, 100, change, (0.1, 1e-3, 0.0, 1.0))
    assert old[0] is SimulationError and "a contact event was missed" in old[1]
    _same_but_the_rk45_advice(old, new)


def _same_but_the_rk45_advice(old, new):
    """The same error and text, but for the advice to a user of rk45, which the C engine changes on
    purpose (issue 19, item 13): it names rtol and atol and no longer advises the solver in use."""
    assert new[0] is old[0]
    head, _, advice = old[1].partition("; solver 'rk45' with ")
    assert advice and new[1].startswith(head + "; solver 'rk45' with rtol = ")
    assert "rtol/atol" in new[1] and "use solver 'rk45'" not in new[1]
