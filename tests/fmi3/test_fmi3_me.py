"""cam3.fmu as an FMI 3.0 Model Exchange FMU (csrc/fmi/fmi3_me.c over the same model functions as fmi2_me.c):
fmpy's CVode and Euler integrate it on every case tests/fmu_me runs with FMI 2.0 (its cases, helpers and
tolerances, imported, not copied) and must agree with co-simulation to those tolerances, with FMI 2.0 Model Exchange
to the bit (one event update, one model), and refuse wrong call orders, bad states and bad arguments as FMI 2.0 does,
with the FMI 3.0 call named."""
from __future__ import annotations

import zipfile
from ctypes import POINTER, byref, c_double, c_size_t
from typing import Any
from xml.etree import ElementTree

import fmpy
import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Model, FMU3Slave
from fmpy.validation import validate_fmu

from fmu_me import test_engine_fmu_me as me2
from fmu_me import test_follower_me as follower2
from cam_fmu.physics.variables import OUTPUT_NAMES

NX, NZ = me2.NX, 4


def both(key, fmu3, fmu2, **options: Any):
    """The same fmpy run of a tests/fmu_me scene on FMI 3.0 and FMI 2.0 Model Exchange."""
    return (me2.simulate(*key, fmu3, "ModelExchange", **dict(options, start=dict(options.get("start", {})))),
            me2.simulate(*key, fmu2, "ModelExchange", **dict(options, start=dict(options.get("start", {})))))


def assert_same(three, two, names=OUTPUT_NAMES) -> None:
    """FMI 3.0 and FMI 2.0 Model Exchange: the same result to the bit, the same events, no error."""
    (r3, e3, err3), (r2, e2, err2) = three, two
    assert err3 == err2 == []
    assert len(r3) == len(r2) > 10 and e3 == e2
    for name in names:
        assert np.array_equal(r3[name], r2[name]), name


@pytest.fixture(scope="module")
def cosim(cam3_fmu_path):
    """tests/fmu_me's scenes in co-simulation (cam3.fmu's, bit for bit cam.fmu's: tests/fmi3/test_fmi3.py)."""
    return {key: me2.simulate(*key, cam3_fmu_path, "CoSimulation")[0] for key in me2.SCENES}


def test_the_model_description_declares_model_exchange_beside_co_simulation(cam3_fmu_path, engine_fmu_path):
    assert validate_fmu(str(cam3_fmu_path)) == []
    md3, md2 = fmpy.read_model_description(str(cam3_fmu_path)), fmpy.read_model_description(str(engine_fmu_path))
    assert md3.modelExchange.modelIdentifier == md3.coSimulation.modelIdentifier == "cam"
    assert md3.modelExchange.needsCompletedIntegratorStep
    # fmpy reads FMI 2.0's attribute name only, so the FMI 3.0 one is read from the file
    with zipfile.ZipFile(cam3_fmu_path) as archive:
        root = ElementTree.fromstring(archive.read("modelDescription.xml"))
    assert root.find("ModelExchange").get("providesDirectionalDerivatives") == "true"
    assert root.find("CoSimulation").get("providesDirectionalDerivatives") == "false"
    # the same dependencies as FMI 2.0's ModelStructure (by value reference here, by index there)
    deps3 = {u.variable.name: sorted(v.name for v in u.dependencies) for u in md3.outputs + md3.derivatives}
    deps2 = {u.variable.name: sorted(v.name for v in u.dependencies) for u in md2.outputs + md2.derivatives}
    assert deps3 == deps2 and deps3["der(x_i)"] == sorted(["x_omega", "x_i", "x_omega_m", "u"])
    assert md3.numberOfContinuousStates == md2.numberOfContinuousStates == NX
    assert md3.numberOfEventIndicators == md2.numberOfEventIndicators == NZ
    # the same states and derivatives in the same order, at FMI 2.0's value references
    assert [(d.variable.name, d.variable.derivative.name, d.variable.valueReference) for d in md3.derivatives] == \
        [(d.variable.name, d.variable.derivative.name, d.variable.valueReference) for d in md2.derivatives]
    names = {v.name: v for v in md3.modelVariables}
    assert [e.variable.name for e in md3.eventIndicators] == ["z_event_1", "z_event_2", "z_event_3", "z_breakpoint"]
    assert all(e.variable.valueReference > names["time"].valueReference for e in md3.eventIndicators)
    assert names["x_theta"].unit == "rad" and names["der(x_omega)"].unit == "rad/s2"


@pytest.mark.parametrize("key", me2.SCENES, ids=lambda k: "/".join(p for p in k if p))
def test_cvode_agrees_with_co_simulation_and_with_fmi2_to_the_bit(cam3_fmu_path, engine_fmu_path, cosim, key):
    three, two = both(key, cam3_fmu_path, engine_fmu_path, solver="CVode", relative_tolerance=me2.CVODE_RTOL)
    assert_same(three, two)
    me = me2.on_grid(three[0], cosim[key]["time"])
    for name, bound in me2.CVODE_BOUNDS.items():
        assert me2.difference(me, cosim[key], name) < bound, name


@pytest.mark.parametrize("key", me2.SCENES, ids=lambda k: "/".join(p for p in k if p))
def test_explicit_euler_agrees_to_its_first_order_and_with_fmi2_to_the_bit(cam3_fmu_path, engine_fmu_path, cosim, key):
    three, two = both(key, cam3_fmu_path, engine_fmu_path, solver="Euler", step_size=me2.EULER_STEP,
                      output_interval=me2.EULER_STEP)
    assert_same(three, two)
    assert me2.difference(me2.on_grid(three[0], cosim[key]["time"]), cosim[key], "theta") < me2.EULER_THETA[key]


@pytest.mark.parametrize("name", me2.STIFF)
def test_cvode_agrees_on_the_stiff_drives(cam3_fmu_path, engine_fmu_path, name):
    """The inductance and the compliant shaft (every state moves), against co-simulation at tests/fmu_me's bounds."""
    reference = me2.simulate(name, None, cam3_fmu_path, "CoSimulation", start=me2.STIFF[name])[0]
    three, two = both((name, None), cam3_fmu_path, engine_fmu_path, solver="CVode",
                      relative_tolerance=me2.CVODE_RTOL, start=me2.STIFF[name])
    assert_same(three, two)
    me = me2.on_grid(three[0], reference["time"])
    for output, bound in me2.STIFF_BOUNDS[name].items():
        assert me2.difference(me, reference, output) < bound, output


@pytest.mark.parametrize("key", follower2.RUNS, ids=lambda k: f"{k[0]}-{k[1]}-e{k[2]}")
def test_the_follower_of_its_own_lifts_off_and_touches_down_as_in_co_simulation(cam3_fmu_path, engine_fmu_path,
                                                                                  key):
    """Closures 'spring' and 'form' (a free follower's gap and rate as states): FMI 3.0 finds co-simulation's
    transitions at its times with its outputs (tests/fmu_me/test_follower_me.py's bounds) and is FMI 2.0's run."""
    scene, start = follower2.start_of(*key)
    cs = follower2.simulate(start, scene.stop_time, "CoSimulation", follower2.CS_STEP, fmu=cam3_fmu_path)
    runs = [follower2.simulate(start, scene.stop_time, "ModelExchange", scene.output_interval, fmu=fmu,
                               relative_tolerance=follower2.RTOL) for fmu in (cam3_fmu_path, engine_fmu_path)]
    assert_same(*runs, names=follower2.NAMES)
    me, events, _ = runs[0]
    cs_events = cs[1]
    assert len(events) == len(cs_events) > 0 and [k for k, _ in events] == [k for k, _ in cs_events]
    kept, horizon = follower2.held(start, cs_events)   # an elastic run: its first transitions (follower2 says why)
    assert max(abs(a - b) for (_, a), (_, b) in list(zip(events, cs_events))[:kept]) < follower2.EVENT_TIME
    grid = follower2.on_grid(me, cs[0]["time"][::round(scene.output_interval / follower2.CS_STEP)])
    reference = cs[0][::round(scene.output_interval / follower2.CS_STEP)]
    grid, reference = grid[reference["time"] <= horizon], reference[reference["time"] <= horizon]
    for name, bound in follower2.BOUNDS.items():
        assert me2.difference(grid, reference, name) < bound, name


@pytest.mark.parametrize("start, words", [
    ({"formulation": "paper"}, ("formulation 'paper'", "co-simulation only", "formulation 'consistent'")),
    ({"drive": "speed"}, ("drive 'speed'", "co-simulation only", "drive 'voltage'"))])
def test_what_is_no_ode_is_refused_at_initialisation_with_its_reason(cam3_fmu_path, start, words):
    logged: list[str] = []
    with pytest.raises(FMICallException, match="fmi3ExitInitializationMode"):
        fmpy.simulate_fmu(str(cam3_fmu_path), fmi_type="ModelExchange", start_values=start, stop_time=0.1,
                          logger=lambda *args: logged.append(args[-1].decode()))
    assert len(logged) == 1 and logged[0].startswith("fmi3ExitInitializationMode: ")
    assert all(w in logged[0] for w in words), logged[0]


class Host:
    """An FMI 3.0 Model Exchange host call by call (fmpy's FMU3Model), collecting the log."""

    def __init__(self, fmu):
        self.md = fmpy.read_model_description(str(fmu))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.log: list[tuple[int, str]] = []
        self.model = FMU3Model(guid=self.md.guid, unzipDirectory=fmpy.extract(str(fmu)), modelIdentifier="cam",
                               instanceName="me3")
        self.model.instantiate(logMessage=self._log)

    def _log(self, _env, status, _category, message):
        self.log.append((status, message.decode()))

    def start(self, **values):
        self.model.enterInitializationMode(startTime=0.0)
        for name, value in values.items():
            setter = self.model.setBoolean if isinstance(value, bool) else self.model.setString \
                if isinstance(value, str) else self.model.setFloat64
            setter([self.vr[name]], [value])
        self.model.exitInitializationMode()
        while self.model.updateDiscreteStates()[0]:
            pass
        self.model.enterContinuousTimeMode()

    def array(self, call, n: int) -> np.ndarray:
        values = np.zeros(n)
        call(values.ctypes.data_as(POINTER(c_double)), n)
        return values

    def euler(self, t: float, h: float) -> np.ndarray:
        """One explicit Euler step with event handling (tests/fmu_me's euler_step, FMI 3.0's calls)."""
        x = self.array(self.model.getContinuousStates, NX)
        new = x + h * self.array(self.model.getContinuousStateDerivatives, NX)
        self.model.setTime(t + h)
        self.model.setContinuousStates(new.ctypes.data_as(POINTER(c_double)), NX)
        if self.model.completedIntegratorStep()[0]:
            self.model.enterEventMode()
            while self.model.updateDiscreteStates()[0]:
                pass
            self.model.enterContinuousTimeMode()
        return new

    def errors(self) -> list[str]:
        return [text for status, text in self.log if status == 3]


def test_euler_steps_by_hand_are_fmi2s_to_the_bit(cam3_fmu_path, engine_fmu_path):
    """The same explicit Euler loop through each version's calls, over the backlash scene's impacts: the same
    states at every step, and the event indicators as variables are fmi3GetEventIndicators' values."""
    host = Host(cam3_fmu_path)
    host.start(backlash=True, closure="kinematic", c=5e-4, gamma=np.pi)
    # FMI 2.0: the same settings through its own calls
    logged = me2.Logged()
    model2, vr2 = me2.raw_model(engine_fmu_path, logged)
    model2.setupExperiment(startTime=0.0)
    model2.enterInitializationMode()
    model2.setBoolean([vr2["backlash"]], [True])
    model2.setString([vr2["closure"]], ["kinematic"])
    model2.setReal([vr2["c"], vr2["gamma"]], [5e-4, np.pi])
    model2.exitInitializationMode()
    while model2.newDiscreteStates()[0]:
        pass
    model2.enterContinuousTimeMode()
    h = 1e-4
    indicators = [vr for vr in (host.vr[f"z_event_{k}"] for k in (1, 2, 3))] + [host.vr["z_breakpoint"]]
    for k in range(2000):
        x3 = host.euler(k * h, h)
        x2 = me2.euler_step(model2, k * h, h)
        assert np.array_equal(x3, x2), k
        z = host.array(host.model.getEventIndicators, NZ)
        assert host.model.getFloat64(indicators) == z.tolist()
    assert x3[0] > 0.1 and host.errors() == []  # rad: the cam turned past the engagements
    assert host.model.getNumberOfContinuousStates() == NX and host.model.getNumberOfEventIndicators() == NZ
    host.model.terminate()
    host.model.freeInstance()
    model2.terminate()
    model2.freeInstance()


def refused(call, *args) -> bool:
    return me2.refused(call, *args)


def test_calls_out_of_order_and_bad_states_are_errors_as_in_fmi2(cam3_fmu_path):
    host = Host(cam3_fmu_path)
    model = host.model
    assert refused(model.setTime, 0.0) and refused(model.enterEventMode)
    model.enterInitializationMode(startTime=0.0)
    assert refused(model.updateDiscreteStates)
    model.exitInitializationMode()  # -> event mode
    assert refused(model.setContinuousStates, np.zeros(NX).ctypes.data_as(POINTER(c_double)), NX)
    assert refused(model.completedIntegratorStep)
    model.updateDiscreteStates()
    model.enterContinuousTimeMode()
    assert refused(model.updateDiscreteStates) and refused(model.enterContinuousTimeMode)
    assert refused(model.getEventIndicators, np.zeros(3).ctypes.data_as(POINTER(c_double)), 3)  # 4 of them
    bad = np.array([0.0, np.nan, 0.0, 0.0, 0.0, 0.0, 0.0])
    assert refused(model.setContinuousStates, bad.ctypes.data_as(POINTER(c_double)), NX)
    assert refused(model.setContinuousStates, np.zeros(6).ctypes.data_as(POINTER(c_double)), 6)
    assert refused(model.setTime, float("inf"))
    assert refused(model.setFloat64, [host.vr["c"]], [1e-3])  # a parameter, fixed after initialisation
    assert refused(model.getDirectionalDerivative, [host.vr["der(x_omega)"]], [host.vr["R"]], [1.0])
    do_step = model.dll.fmi3DoStep
    assert do_step(model.component, c_double(0.0), c_double(1e-3), True, None, None, None, None) == 3
    # the refused requests changed nothing: the instance goes on
    assert host.array(model.getContinuousStates, NX).tolist() == [0.0] * NX
    assert model.completedIntegratorStep() == (False, False)
    texts = host.errors()
    assert texts[0] == "fmi3SetTime: not allowed in state 'instantiated'"
    assert "fmi3SetContinuousStates: not allowed in state 'event mode'" in texts
    assert "fmi3UpdateDiscreteStates: not allowed in state 'continuous-time mode'" in texts
    assert "fmi3GetEventIndicators: event indicators: 3 given, cam.fmu has 4 (the model description's count)" in texts
    assert "fmi3SetContinuousStates: continuous state 'x_omega' = nan is not finite" in texts
    assert "fmi3SetContinuousStates: continuous states: 6 given, cam.fmu has 9 (the model description's count)" in texts
    assert any(t.startswith("fmi3SetTime: time = inf s must be finite") for t in texts)
    assert "fmi3DoStep: not allowed in state 'continuous-time mode'" in texts
    assert any(t.startswith("fmi3GetDirectionalDerivative: ") and "('R') is no known" in t for t in texts)
    model.terminate()
    model.freeInstance()


def test_a_host_that_steps_over_an_impact_without_event_mode_gets_an_error(cam3_fmu_path):
    """backlash: as FMI 2.0's, the host that ignores the request for event mode is stopped, the clearance named."""
    host = Host(cam3_fmu_path)
    host.start(backlash=True, closure="kinematic", c=5e-4, gamma=np.pi)
    h, asked = 1e-4, []
    with pytest.raises(FMICallException):
        for k in range(1000):
            x = host.array(host.model.getContinuousStates, NX)
            dx = host.array(host.model.getContinuousStateDerivatives, NX)
            host.model.setTime((k + 1) * h)
            host.model.setContinuousStates((x + h * dx).ctypes.data_as(POINTER(c_double)), NX)
            asked.append(host.model.completedIntegratorStep()[0])
    assert asked[-1] and sum(asked) == 1
    (text,) = host.errors()
    assert text.startswith("fmi3CompletedIntegratorStep: the follower is ") and "beyond the clearance" in text
    assert 0.036 < len(asked) * h < 0.039  # s: the first engagement (0.0372 s in co-simulation)
    host.model.freeInstance()


def test_a_saved_state_replays_the_same_trajectory(cam3_fmu_path):
    host = Host(cam3_fmu_path)
    host.start()
    h = 1e-4
    for k in range(200):
        host.euler(k * h, h)
    saved = host.model.deserializeFMUState(host.model.serializeFMUState(host.model.getFMUState()))
    first = [host.euler((200 + k) * h, h).copy() for k in range(300)]
    host.model.setFMUState(saved)
    again = [host.euler((200 + k) * h, h).copy() for k in range(300)]
    assert np.array_equal(np.array(first), np.array(again)) and first[-1][0] > 0.05
    host.model.terminate()
    host.model.freeInstance()


def test_a_co_simulation_instance_refuses_model_exchange_calls(cam3_fmu_path):
    md = fmpy.read_model_description(str(cam3_fmu_path))
    log: list[str] = []
    cs = FMU3Slave(guid=md.guid, unzipDirectory=fmpy.extract(str(cam3_fmu_path)), modelIdentifier="cam",
                   instanceName="cs")
    cs.instantiate(logMessage=lambda _e, _s, _c, message: log.append(message.decode()))
    cs.enterInitializationMode(startTime=0.0)
    cs.exitInitializationMode()
    n = c_size_t(99)
    assert cs.dll.fmi3GetNumberOfContinuousStates(cs.component, byref(n)) == 3 and n.value == 0
    assert cs.dll.fmi3EnterContinuousTimeMode(cs.component) == 3
    indicator = next(v.valueReference for v in md.modelVariables if v.name == "z_breakpoint")
    assert refused(cs.getFloat64, [indicator])
    assert any("this instance is a co-simulation one" in m for m in log)
    assert any("event indicator 3 is Model Exchange's" in m for m in log)
    cs.doStep(0.0, 1e-3)
    assert cs.getFloat64([next(v.valueReference for v in md.modelVariables if v.name == "time")]) == [1e-3]
    cs.terminate()
    cs.freeInstance()


def test_the_bench_measures_both_versions_on_the_same_calls_and_bits(cam3_fmu_path, engine_fmu_path):
    """`cam-fmu bench fmi3_me`'s measurement: the same bits, the same FMI calls but FMI 2.0's fmi2SetupExperiment,
    and a ratio of two positive wall times of the same run (its value is docs/performance.md's, not a bound)."""
    from cam_fmu.tools.bench.fmi3_me import measure

    r = measure(engine_fmu_path, cam3_fmu_path, rounds=1)
    assert r["same_bits"] and r["calls"]["fmi2"] == r["calls"]["fmi3"] + 1 > 1000
    assert all(0.0 < r["best_s"][k] < float("inf") for k in ("fmi2", "fmi3"))
    assert r["ratio_best"] == r["best_s"]["fmi3"] / r["best_s"]["fmi2"]
