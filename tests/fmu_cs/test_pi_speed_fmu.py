"""pi_speed.fmu, the PI speed controller in C on the shared FMI glue, against control/pi.py (the same law in
Python, written separately): every sample to the bit, and the FMI rules cam.fmu keeps (ranges named,
statuses, no direct feedthrough, states checked). The C FMU is loaded in this process, as FMPy's own tests do.
"""
from __future__ import annotations

import math
import re
import random
import struct

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Model, FMU2Slave

from cam_fmu.control import pi

OUTPUTS = [name for name, _u, _d in pi.OUTPUTS]
INPUTS = [name for name, _u, _s, _d in pi.INPUTS]


@pytest.fixture(scope="module")
def unzipped(pi_speed_fmu_path, tmp_path_factory):
    folder = extract(str(pi_speed_fmu_path), str(tmp_path_factory.mktemp("pi_speed")))
    return folder, read_model_description(str(pi_speed_fmu_path))


def status_of(call) -> int:
    """The FMI status of call(): 0 when fmpy raises nothing, else the status its exception carries."""
    try:
        call()
    except FMICallException as exc:
        return exc.status
    return 0


def callbacks(messages: list[str]):
    """fmpy's callbacks with a logger that keeps each message."""
    from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                           fmi2CallbackLoggerTYPE)
    from fmpy.fmi2 import calloc, free

    def logger(env, instance, status, category, message):
        messages.append(message.decode(errors="replace"))

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(logger)
    cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    return cb


class Logged:
    """An instance of pi_speed.fmu (fmpy's FMU2Slave) with its log kept in ``messages``."""

    def __init__(self, unzipped, name: str = "pi") -> None:
        folder, md = unzipped
        self.md = md
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.messages: list[str] = []
        self.cb = callbacks(self.messages)  # kept alive as long as the instance
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier="pi_speed", instanceName=name)
        self.fmu.instantiate(callbacks=self.cb)

    def status_of_set(self, name: str, value: float) -> int:
        """fmi2SetReal's status (fmpy raises for Error and Fatal: its status is taken from the exception)."""
        return status_of(lambda: self.fmu.setReal([self.vr[name]], [value]))

    def start(self, params: dict, inputs: dict, start_time: float = 0.0) -> None:
        self.fmu.setupExperiment(startTime=start_time)
        for name, value in params.items():
            if isinstance(value, bool):
                self.fmu.setBoolean([self.vr[name]], [value])
            else:
                self.fmu.setReal([self.vr[name]], [float(value)])
        self.set_inputs(inputs)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def set_inputs(self, inputs: dict) -> None:
        self.fmu.setReal([self.vr[n] for n in inputs], [float(v) for v in inputs.values()])

    def outputs(self) -> list[float]:
        return self.fmu.getReal([self.vr[n] for n in OUTPUTS])


def _random_case(rng: random.Random) -> dict:
    u_min = rng.uniform(-30, 0)
    return {"omega_set": rng.uniform(-50, 50), "kp": rng.choice([0.0, rng.uniform(0, 10)]),
            "ki": rng.uniform(0, 200), "u_min": u_min, "u_max": rng.uniform(u_min, 30),
            "feedforward": rng.choice([0.0, 1.0, rng.uniform(0, 1)]), "external_setpoint": rng.random() < 0.5,
            "R": rng.uniform(0.5, 50), "c_e": rng.uniform(0.01, 1), "c_m": rng.uniform(0.01, 1)}


@pytest.mark.parametrize("seed", range(6))
def test_every_sample_equals_the_python_controller_to_the_bit(unzipped, seed):
    """Random parameters (clamps, feedforward, external setpoint), random inputs and step sizes: the FMU's
    outputs before the first step and after each of 400 steps equal control.pi's, bit for bit (the C law
    does the same operations in the same order, with no fused multiply-add)."""
    rng = random.Random(seed)
    params = _random_case(rng)
    inputs = {n: rng.uniform(-20, 20) for n in INPUTS}
    slave = Logged(unzipped)
    slave.start(params, inputs)
    ctrl = pi.PiSpeedController(params)
    ctrl.initialize(**inputs)
    assert slave.outputs() == [ctrl.outputs()[n] for n in OUTPUTS]
    t, clamped = 0.0, 0
    for _ in range(400):
        inputs = {n: rng.uniform(-20, 20) if rng.random() < 0.3 else v for n, v in inputs.items()}
        h = rng.choice([1e-3, 2e-4, rng.uniform(1e-5, 1e-2)])
        slave.set_inputs(inputs)
        assert status_of(lambda: slave.fmu.doStep(t, h)) == 0
        ctrl.sample(h, **inputs)
        t += h
        assert slave.outputs() == [ctrl.outputs()[n] for n in OUTPUTS]
        clamped += ctrl.u in (params["u_min"], params["u_max"])
    slave.fmu.terminate()
    slave.fmu.freeInstance()
    assert clamped > 0 or seed % 2, "the case never reached a clamp: the anti-windup branch went untested"


def test_outputs_before_initialisation_are_the_law_on_the_inputs(unzipped):
    """Before exitInitializationMode the outputs are the law on the parameters and inputs as set (what a master
    reads to start a loop), not 0: kp (w - omega_meas) with the default kp = 2 V/(rad/s), w = 5 rad/s."""
    slave = Logged(unzipped)
    slave.fmu.setupExperiment(startTime=0.0)
    slave.fmu.enterInitializationMode()
    slave.set_inputs({"omega_meas": 1.5})
    u, error, integral, u_ff = slave.outputs()
    assert (u, error, integral, u_ff) == (2.0 * 3.5, 3.5, 0.0, 0.0)


@pytest.mark.parametrize("name, value, allowed", [
    ("kp", -1.0, "[0, 10000] V/(rad/s)"), ("ki", math.inf, "[0, 1e+06] V/rad"), ("feedforward", 1.5, "[0, 1]"),
    ("R", 0.0, "(0, 10000] Ohm"), ("omega_set", math.nan, "[-10000, 10000] rad/s")])
def test_a_parameter_out_of_range_is_refused_with_its_name_and_range(unzipped, name, value, allowed):
    slave = Logged(unzipped)
    assert pi.BY_NAME[name].allowed() == allowed  # the message's range is the Python table's text
    slave.fmu.setupExperiment(startTime=0.0)
    slave.fmu.enterInitializationMode()
    before = slave.fmu.getReal([slave.vr[name]])[0]
    assert slave.status_of_set(name, value) == 3  # fmi2Error
    assert slave.fmu.getReal([slave.vr[name]])[0] == before  # nothing written
    assert any(f"parameter '{name}'" in m and allowed in m for m in slave.messages), slave.messages
    slave.fmu.freeInstance()


def test_u_min_above_u_max_is_refused_at_initialisation(unzipped):
    slave = Logged(unzipped, "c")
    slave.fmu.setupExperiment(startTime=0.0)
    slave.fmu.setReal([slave.vr["u_min"], slave.vr["u_max"]], [5.0, 1.0])
    slave.fmu.enterInitializationMode()
    assert status_of(slave.fmu.exitInitializationMode) == 3
    assert any("'u_min' = 5 V > 'u_max' = 1 V" in m for m in slave.messages), slave.messages
    # the error state: no step until Reset
    assert status_of(lambda: slave.fmu.doStep(0.0, 1e-3)) == 3
    slave.fmu.reset()
    slave.fmu.setupExperiment(startTime=0.0)
    slave.fmu.enterInitializationMode()
    slave.fmu.exitInitializationMode()  # defaults: allowed again
    slave.fmu.freeInstance()


def test_inputs_take_any_finite_value_and_refuse_the_rest(unzipped):
    slave = Logged(unzipped)
    slave.start({}, {"omega_meas": 1.0})
    slave.set_inputs({"omega_meas": -1e300, "M_load": 1e-300})
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(Exception):
            slave.set_inputs({"omega_meas": bad})
    assert slave.fmu.getReal([slave.vr["omega_meas"]])[0] == -1e300  # the refused value was not written
    with pytest.raises(Exception):
        slave.fmu.setReal([slave.vr["u"]], [1.0])  # an output is never set


def test_no_direct_feedthrough(unzipped):
    """A new input changes no output before the next doStep (the model description declares none)."""
    slave = Logged(unzipped)
    slave.start({"feedforward": 1.0}, {"omega_meas": 1.0, "M_load": 0.01, "J_load": 1e-4})
    slave.fmu.doStep(0.0, 1e-3)
    before = slave.outputs()
    slave.set_inputs({"omega_meas": 9.0, "M_load": 0.5, "J_load": 1e-2, "omega_setpoint": 3.0})
    assert slave.outputs() == before
    slave.fmu.doStep(1e-3, 1e-3)
    assert slave.outputs() != before
    unknowns = {u.variable.name: u.dependencies for u in slave.md.outputs}
    assert set(unknowns) == set(OUTPUTS) and all(deps == [] for deps in unknowns.values())


def test_parameters_are_fixed_after_initialisation(unzipped):
    slave = Logged(unzipped)
    slave.start({}, {})
    with pytest.raises(Exception):
        slave.fmu.setReal([slave.vr["kp"]], [1.0])
    with pytest.raises(Exception):
        slave.fmu.setBoolean([slave.vr["external_setpoint"]], [True])
    assert slave.fmu.getReal([slave.vr["kp"]])[0] == pi.BY_NAME["kp"].default


def test_state_round_trip_is_bit_exact_and_a_bad_state_is_refused(unzipped):
    slave = Logged(unzipped)
    slave.start({"ki": 50.0, "feedforward": 0.5}, {"omega_meas": 0.5, "M_load": 0.02, "J_load": 1e-4})
    t = 0.0
    for _ in range(10):
        slave.fmu.doStep(t, 1e-3)
        t += 1e-3
    state = slave.fmu.getFMUState()
    blob = slave.fmu.serializeFMUState(state)

    def run() -> list[list[float]]:
        rows, time = [], t
        for k in range(20):
            slave.set_inputs({"omega_meas": 0.5 + 0.1 * k})
            slave.fmu.doStep(time, 1e-3)
            time += 1e-3
            rows.append(slave.outputs())
        return rows

    first = run()
    slave.fmu.setFMUState(state)
    assert run() == first
    slave.fmu.setFMUState(slave.fmu.deserializeFMUState(blob))
    assert run() == first
    # a truncated blob, and one whose parameter kp is negative (the double's bytes edited), are refused and
    # leave the instance where it was
    with pytest.raises(Exception):
        slave.fmu.deserializeFMUState(blob[:-8])
    kp_at = 16 + (11 + [p.name for p in pi.PARAMETERS].index("kp")) * 8  # the glue's header, then doubles
    assert struct.unpack("<d", blob[kp_at:kp_at + 8])[0] == pi.BY_NAME["kp"].default
    bad = bytearray(blob)
    bad[kp_at:kp_at + 8] = struct.pack("<d", -1.0)
    with pytest.raises(Exception):   # by a checksum at deserialising, or by the range check at setting
        slave.fmu.setFMUState(slave.fmu.deserializeFMUState(bytes(bad)))
    slave.fmu.setFMUState(state)
    assert run() == first


def test_model_exchange_is_refused_with_a_message(unzipped):
    folder, md = unzipped
    messages: list[str] = []
    cb = callbacks(messages)
    model = FMU2Model(guid=md.guid, unzipDirectory=folder, modelIdentifier="pi_speed", instanceName="me")
    with pytest.raises(Exception):
        model.instantiate(callbacks=cb)
    assert any("pi_speed.fmu is fmi2CoSimulation (1) only" in m for m in messages), messages
    assert md.modelExchange is None and md.coSimulation is not None


def test_a_cam_state_is_not_a_pi_speed_state(unzipped, cam_fmu_path, tmp_path):
    """States carry their model: a serialised cam.fmu state given to pi_speed.fmu is refused, naming it."""
    cam_md = read_model_description(str(cam_fmu_path))
    cam = FMU2Slave(guid=cam_md.guid, unzipDirectory=extract(str(cam_fmu_path), str(tmp_path / "cam")),
                    modelIdentifier="cam", instanceName="cam")
    cam.instantiate()
    cam.setupExperiment(startTime=0.0)
    cam.enterInitializationMode()
    cam.exitInitializationMode()
    blob = cam.serializeFMUState(cam.getFMUState())
    cam.terminate()
    cam.freeInstance()
    slave = Logged(unzipped, "d")
    with pytest.raises(Exception):
        slave.fmu.deserializeFMUState(blob)
    assert any("not a serialised pi_speed state" in m for m in slave.messages), slave.messages
    slave.fmu.freeInstance()


# Finite inputs the FMU accepts whose law overflows a double: (parameters, inputs, step h [s], the quantity named).
OVERFLOWS = {
    "error": (dict(kp=0.0, external_setpoint=True), dict(omega_setpoint=1e308, omega_meas=-1e308), 1e-3,
              "the speed error 'error'"),
    "integral": (dict(kp=0.0, ki=1e6), dict(omega_meas=1000.0), 1e300, "the integral 'integral'"),
    "command": (dict(kp=1e4, external_setpoint=True), dict(omega_setpoint=1e305, omega_meas=-1e305), 1e-3,
                "the unclamped command"),
    "feedforward": (dict(feedforward=1.0, R=1e4, c_m=1e-6), dict(M_load=1e300), 1e-3, "the feedforward 'u_ff'"),
    "setpoint rate": (dict(feedforward=1.0, external_setpoint=True), dict(omega_setpoint=1e300), 1e-310,
                      "the setpoint's rate"),
}


@pytest.mark.parametrize("name", OVERFLOWS)
def test_an_overflow_is_an_error_naming_it_never_a_nan_with_ok(unzipped, name):
    """Finite inputs whose error, feedforward, command or integral is beyond a double (kp = 0 with e = 1e308 -
    (-1e308) gave u = NaN with OK; ki = 1e6 and a 1e300 s step an infinite integral that u_max hid and the FMU's own
    state check then refused): fmi2Error, the logger names the quantity, the state stays the last good one (saved,
    serialised and set again), and control/pi.py raises SimulationError naming the same quantity, unchanged."""
    from cam_fmu.errors import SimulationError
    params, bad, h, what = OVERFLOWS[name]
    slave = Logged(unzipped)
    slave.start(params, {})
    ctrl = pi.PiSpeedController(params)
    ctrl.initialize(**{n: 0.0 for n in INPUTS})
    assert status_of(lambda: slave.fmu.doStep(0.0, 1e-3)) == 0
    ctrl.sample(1e-3, **{n: 0.0 for n in INPUTS})
    good = slave.outputs()
    assert good == [ctrl.outputs()[n] for n in OUTPUTS] and all(map(math.isfinite, good))
    state = slave.fmu.getFMUState()
    slave.set_inputs(bad)
    assert status_of(lambda: slave.fmu.doStep(1e-3, h)) == 3   # fmi2Error
    assert any(what in m and "is not finite (an overflow)" in m for m in slave.messages), slave.messages
    assert slave.outputs() == good   # nothing written
    with pytest.raises(SimulationError, match=re.escape(what)):
        ctrl.sample(h, **dict({n: 0.0 for n in INPUTS}, **bad))
    assert [ctrl.outputs()[n] for n in OUTPUTS] == good
    # the state before the refused step is a state the FMU takes back, serialised too, and goes on from
    blob = slave.fmu.serializeFMUState(state)
    slave.fmu.setFMUState(slave.fmu.deserializeFMUState(blob))
    slave.set_inputs({n: 0.0 for n in INPUTS})
    assert status_of(lambda: slave.fmu.doStep(1e-3, 1e-3)) == 0
    ctrl.sample(1e-3, **{n: 0.0 for n in INPUTS})
    assert slave.outputs() == [ctrl.outputs()[n] for n in OUTPUTS]
    slave.fmu.freeInstance()


def test_an_overflow_at_initialisation_is_an_error_and_outputs_before_it_are_refused(unzipped):
    """The law on the inputs at initialisation overflows (kp = 0, w = 1e308, omega_meas = -1e308): reading the
    outputs before it and exitInitializationMode are fmi2Error naming the error, never u = NaN."""
    slave = Logged(unzipped)
    slave.fmu.setupExperiment(startTime=0.0)
    slave.fmu.setReal([slave.vr["kp"]], [0.0])
    slave.fmu.setBoolean([slave.vr["external_setpoint"]], [True])
    slave.set_inputs({"omega_setpoint": 1e308, "omega_meas": -1e308})
    slave.fmu.enterInitializationMode()
    assert status_of(lambda: slave.fmu.getReal([slave.vr["u"]])) == 3
    assert status_of(slave.fmu.exitInitializationMode) == 3
    assert sum("the speed error 'error' = w - omega_meas is not finite" in m for m in slave.messages) == 2
    slave.fmu.freeInstance()


def test_extreme_samples_stay_finite_or_fail_together_and_every_saved_state_is_taken_back(unzipped):
    """Random inputs up to 1e308 and steps up to 1e300 s on ki = 1e6: at every sample either the FMU and
    control/pi.py give the same finite outputs, or both refuse (fmi2Error; SimulationError) and the state saved
    before it goes on; every state the FMU saves, serialised, is one it sets again (before, an infinite integral
    was saved and then refused)."""
    from cam_fmu.errors import SimulationError
    rng = random.Random(7)
    params = dict(kp=rng.choice([0.0, 1e-3]), ki=1e6, external_setpoint=True, feedforward=0.5)
    slave = Logged(unzipped)
    slave.start(params, {})
    ctrl = pi.PiSpeedController(params)
    ctrl.initialize(**{n: 0.0 for n in INPUTS})
    t, refused, accepted = 0.0, 0, 0
    for _ in range(300):
        inputs = {n: rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-3, 308) for n in INPUTS}
        h = 10.0 ** rng.uniform(-6, 300)
        state = slave.fmu.getFMUState()
        slave.fmu.setFMUState(slave.fmu.deserializeFMUState(slave.fmu.serializeFMUState(state)))
        slave.set_inputs(inputs)
        status = status_of(lambda: slave.fmu.doStep(t, h))
        try:
            ctrl.sample(h, **inputs)
        except SimulationError:
            assert status == 3
            refused += 1
            slave.fmu.setFMUState(state)
        else:
            assert status == 0
            accepted += 1
            t += h
            assert slave.outputs() == [ctrl.outputs()[n] for n in OUTPUTS]
            assert all(map(math.isfinite, slave.outputs()))
        slave.fmu.freeFMUState(state)
    assert refused > 10 and accepted > 10, (refused, accepted)
    slave.fmu.freeInstance()
