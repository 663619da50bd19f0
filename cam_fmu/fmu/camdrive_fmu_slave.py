"""The FMI 2.0 co-simulation slave of cam.fmu (pythonfmu 0.7.0).

Thin by design: it registers the FMI variables (inputs ``u`` and ``omega_ref``,
the outputs of ``physics.variables.OUTPUTS`` and every parameter of
``physics.parameters.PARAMETERS`` under the same name and unit) and maps the FMI
calls onto ``fmu.engine.DriveSimulator``, the same physics code the reference uses.

The module name ``camdrive_fmu_slave`` is deliberately unique: pythonfmu imports
the slave script as a *top-level* module of the host process, and module names
are process-global (two FMUs whose scripts share a module name cannot both load
in one process).

Imports at run time: pythonfmu, ``cam_fmu.physics.parameters``,
``cam_fmu.physics.variables`` and ``cam_fmu.fmu.engine`` (numpy at most). Never scipy: it crashes native hosts at Py_Finalize.

Errors. On linux64, cam.fmu's own binary (cam_fmu/fmu/native, docs/fmu.md) maps an
exception raised here to fmi2Error with its text in the log (``logStatusError``),
and ``StepDiscarded`` to fmi2Discard; the instance stays recoverable (fmi2Reset,
fmi2SetFMUstate). The rest of this paragraph describes pythonfmu's win64 binary:
pythonfmu 0.7.0's C++ wrapper turns *every* Python exception raised in
an FMI call (fmi2SetReal/Boolean/String, fmi2EnterInitializationMode,
fmi2ExitInitializationMode, fmi2DoStep, fmi2Get*, state calls) into
``pythonfmu::fatal_error``: the call returns **fmi2Fatal** and the wrapper logs
``"Fatal py exception encountered: [doStep] PyObject_CallMethod\\nunknown error"``
(without the exception text) through the host's logger callback. There is no
way from Python to obtain plain fmi2Error (only a C++ ``std::exception`` that is not ``fatal_error`` gives it),
and the only other non-OK status reachable from Python is fmi2Discard (a falsy
``do_step`` return), which fmpy treats as a silent early stop WITHOUT raising.
fmi2Fatal is therefore the best available status that makes every importer
stop: fmpy raises ``FMICallException`` (status 4). Our message (naming the
variable and its allowed range) reaches the log as an fmi2Error-status message
queued with ``self.log`` just before the exception, which the wrapper flushes
before its own fatal line; both only with logging on (fmpy:
``debug_logging=True``). The message is also printed to stderr.

Values are checked where they enter: a parameter in its setter (fmi2SetReal /
fmi2SetString / fmi2SetBoolean fails), the angle sum when the simulator is
built (fmi2ExitInitializationMode fails), an input in its setter and again in
do_step, the simulator's own errors in do_step (fmi2DoStep fails). Outputs are
checked to be finite before they are published: never NaN outputs.

cam.fmu's own binary answers the per-step gets and sets in C from its exchange
(``exchange_layout``, docs/fmu.md): it checks each input against the same
INPUT_RANGES and sends every value outside them here, for the message.
"""
from __future__ import annotations

import copy
import math
import sys
from array import array
from typing import Any, Dict

from pythonfmu import Boolean, Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real, String
from pythonfmu.enums import Fmi2Status
from pythonfmu.default_experiment import DefaultExperiment

from cam_fmu.fmu import engine as _simulator
from cam_fmu.physics import parameters as _parameters
from cam_fmu.physics import variables as _variables

MODEL_NAME = "cam"
DESCRIPTION = (
    "Electromechanical cam drive: DC motor (R, L, c_e, c_m) driving a disc cam with an "
    "in-line roller follower (friction, gravity, backlash); voltage or speed drive. "
    "Default experiment: the paper's fig. 6 scene (u = 3.5 V, horizontal mounting)."
)
# The paper's fig. 6 scene: 0..2 s, 1 ms communication step (the one place it is set;
# the model description is written from it and a test checks the paper_fig6 scene against it).
DEFAULT_EXPERIMENT = DefaultExperiment(start_time=0.0, stop_time=2.0, step_size=1e-3)


class FmuError(RuntimeError):
    """An error reported to the importer; the message names the variable and the allowed range.

    cam.fmu's linux64 binary returns fmi2Error for it (and for any other exception),
    with the text in the log (category logStatusError)."""


class StepDiscarded(FmuError):
    """The step cannot be completed at this size (max_steps, step floor): fmi2Discard, retry a shorter step."""

    fmi_status = "discard"


class CamDriveSlave(Fmi2Slave):
    """cam.fmu: the cam drive as an FMI 2.0 co-simulation slave."""

    author = "cam_fmu"
    description = DESCRIPTION
    default_experiment = DEFAULT_EXPERIMENT
    errors_reach_logger = False  # set by the linux64 binary's bridge: no stderr copy of an error (see _fail)

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.modelName = MODEL_NAME
        self._params: Dict[str, Any] = _parameters.defaults()
        self._inputs: Dict[str, float] = {name: float(start) for name, _u, start, _d in _variables.INPUTS}
        # the published outputs in OUTPUTS order: the simulator's own buffer once it exists (no copy per step)
        self._values = array("d", [0.0] * len(_variables.OUTPUTS))
        self._sim = None  # DriveSimulator, built at exit_initialization_mode or on first use
        self._initialized = False  # True after exit_initialization_mode: parameters are fixed

        for name, _unit, _start, desc in _variables.INPUTS:
            self.register_variable(Real(
                name, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                description=desc, getter=self._input_getter(name), setter=self._input_setter(name)))
        for index, (name, _unit, desc) in enumerate(_variables.OUTPUTS):
            self.register_variable(Real(
                name, causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                initial=Fmi2Initial.calculated, description=desc, getter=self._output_getter(index),
                setter=self._output_setter(name)))
        # value reference -> input name / output index: the packed transfers (get_real_packed)
        self._input_names = {vr: var.name for vr, var in self.vars.items() if var.name in self._inputs}
        self._output_index = {vr: _variables.OUTPUT_NAMES.index(var.name) for vr, var in self.vars.items()
                              if var.name in _variables.OUTPUT_NAMES}
        kinds = {"real": Real, "boolean": Boolean, "string": String}
        for spec in _parameters.PARAMETERS:
            self.register_variable(kinds[spec.kind](
                spec.name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
                initial=Fmi2Initial.exact, description=spec.description,
                getter=self._param_getter(spec.name), setter=self._param_setter(spec.name)))

    # ----------------------------------------------------------------- variables
    def _input_getter(self, name: str):
        return lambda: self._inputs[name]

    def _input_setter(self, name: str):
        def setter(value: Any) -> None:
            try:
                self._inputs[name] = _variables.check_input(name, value)
            except (TypeError, ValueError) as exc:
                self._fail(str(exc))
        return setter

    def _output_getter(self, index: int):
        def getter() -> float:
            if self._sim is None:
                self._build()  # outputs are 'calculated' from the parameters at start time
            return self._values[index]
        return getter

    def _output_setter(self, name: str):
        def setter(_value: Any) -> None:
            self._fail(f"variable {name!r} is an output: it cannot be set (set the inputs "
                       f"{', '.join(repr(n) for n in _variables.INPUT_NAMES)} or the parameters)")
        return setter

    def _param_getter(self, name: str):
        return lambda: self._params[name]

    def _param_setter(self, name: str):
        spec = _parameters.BY_NAME[name]

        def setter(value: Any) -> None:
            if self._initialized:
                self._fail(f"parameter {name!r} has variability 'fixed': it can only be set before "
                           f"fmi2ExitInitializationMode (allowed {spec.allowed()})")
            try:
                self._params[name] = spec.check(value)
            except _parameters.ParameterError as exc:
                self._fail(str(exc))
            self._sim = None  # rebuilt from the new values on first use
        return setter

    # ----------------------------------------------------------------- packed transfers
    # The binary's fallback when its exchange cannot answer: outputs not yet calculated, an input value out
    # of range (its message), requests that mix in other variables (then pythonfmu's per-variable path).
    def get_real_packed(self, vrs: bytes) -> bytes | None:
        """fmi2GetReal of outputs only, values packed as C doubles; None: not only outputs (use get_real)."""
        indices = _resolved(vrs, self._output_index)
        if indices is None:
            return None
        if self._sim is None:
            self._build()  # outputs are 'calculated' from the parameters at start time
        values = self._values
        return array("d", [values[k] for k in indices]).tobytes()

    def set_real_packed(self, vrs: bytes, values: bytes) -> bool:
        """fmi2SetReal of inputs only (packed C doubles), each checked against its range; False: not only inputs."""
        names = _resolved(vrs, self._input_names)
        if names is None:
            return False
        inputs = self._inputs
        for name, value in zip(names, array("d", values)):
            try:
                inputs[name] = _variables.check_input(name, value)
            except ValueError as exc:
                self._fail(str(exc))
        return True

    # ----------------------------------------------------------------- the exchange (cam.fmu's own binary)
    def exchange_layout(self) -> tuple:
        """(output value references in OUTPUTS order, input value references, input ranges): the
        variables whose fmi2GetReal (and fmi2SetReal within range, for inputs) the binary answers in C."""
        by_name = {var.name: vr for vr, var in self.vars.items()}
        return (tuple(by_name[name] for name in _variables.OUTPUT_NAMES),
                tuple(by_name[name] for name in _variables.INPUT_NAMES),
                tuple(_variables.INPUT_RANGES[name] for name in _variables.INPUT_NAMES))

    def published_outputs(self) -> array | None:
        """The outputs as an FMI get would return them, or None before they are calculated."""
        return None if self._sim is None else self._values

    def input_values(self) -> array:
        """The inputs in INPUT_NAMES order (C doubles)."""
        return array("d", [self._inputs[name] for name in _variables.INPUT_NAMES])

    def take_inputs(self, values: list) -> None:
        """Inputs in INPUT_NAMES order, already checked against INPUT_RANGES by the binary."""
        self._inputs.update(zip(_variables.INPUT_NAMES, values))

    # ----------------------------------------------------------------- helpers
    def _fail(self, message: str, error: type = FmuError) -> None:
        """Report an error: log it, print it to stderr, raise (pythonfmu returns fmi2Fatal).

        pythonfmu 0.7.0 forwards the queued ``self.log`` message (status fmi2Error,
        category logStatusError) followed by its own fmi2Fatal line, but only when
        the importer turned logging on (fmpy: ``debug_logging=True``); its fatal
        line does not contain the exception text. stderr is the fallback a user
        sees when logging is off; the project's own linux64 binary, which logs every
        error even with logging off, sets ``errors_reach_logger`` and has no such line.
        """
        self.log(message, Fmi2Status.error)
        if not self.errors_reach_logger:
            print(f"[cam.fmu {self.instance_name}] error: {message}", file=sys.stderr, flush=True)
        raise error(message)

    def _build(self) -> None:
        try:
            sim = _simulator.DriveSimulator(self._params)
            sim.set_inputs(**self._inputs)  # initial outputs see the inputs set before initialisation
        except (_parameters.ParameterError, _simulator.SimulationError) as exc:
            self._fail(str(exc))
        for name, value in sim.outputs().items():  # the initial outputs (do_step checks every later state)
            if not math.isfinite(value):
                self._fail(f"output {name!r} = {value!r} at t = {sim.time!r} s is not finite "
                           "(check the solver settings 'solver', 'h_max', 'rtol', 'atol')")
        self._sim = sim
        self._values = sim.values  # DriveSimulator.do_step refreshes it in place, after its checks

    # ----------------------------------------------------------------- FMI calls
    def exit_initialization_mode(self) -> None:
        if self._initialized:
            self._fail("fmi2ExitInitializationMode was called again after initialisation: the instance is "
                       "in step mode and keeps its state; use fmi2Reset to start over")
        self._build()
        self._initialized = True

    def do_step(self, current_time: float, step_size: float) -> bool:
        if self._sim is None:
            self._build()
            self._initialized = True
        try:  # inputs were checked in their setters, and are again in DriveSimulator.do_step
            inputs = self._inputs
            self._sim.do_step(current_time, step_size, inputs["u"], inputs["omega_ref"], inputs["omega_dot_ref"])
        except (_parameters.ParameterError, _simulator.SimulationError) as exc:
            # The engine's StepRejected (max_steps, step floor) means "not at this step size":
            # fmi2Discard, with the state as before the step; everything else is fmi2Error.
            discard = getattr(exc, "fmi_status", None) == "discard"
            self._fail(f"at t = {current_time!r} s: {exc}", StepDiscarded if discard else FmuError)
        return True  # a falsy return would become a silent fmi2Discard

    def _get_fmu_state(self) -> Dict[str, Any]:
        return {
            "version": STATE_VERSION,
            "params": dict(self._params),
            "inputs": dict(self._inputs),
            "outputs": dict(zip(_variables.OUTPUT_NAMES, self._values)),
            "initialized": self._initialized,
            "sim": None if self._sim is None else copy.deepcopy(self._sim.get_state()),
        }

    def _set_fmu_state(self, state: Dict[str, Any]) -> None:
        """Restore a state, validated whole before anything changes (a bad blob is fmi2Error)."""
        try:
            params, inputs, outputs, initialized, sim = _checked_state(state)
        except (KeyError, TypeError, ValueError, _parameters.ParameterError, _simulator.SimulationError) as exc:
            self._fail(f"FMU state rejected: {exc}")
        self._params, self._inputs = params, inputs
        self._initialized, self._sim = initialized, sim
        self._values = sim.values if sim is not None else array("d", outputs.values())
        if sim is not None:
            self._values[:] = array("d", outputs.values())  # the outputs as published when the state was taken


STATE_VERSION = 2  # of the dictionary _get_fmu_state returns (serialised as JSON)


def _resolved(vrs: bytes, table: Dict[int, Any]) -> list | None:
    """The table's entries for packed value references (C unsigned ints), or None if one is not in it."""
    found = [table.get(vr) for vr in array("I", vrs)]
    return None if None in found else found


def _checked_state(state: Any):
    """(params, inputs, outputs, initialized, simulator) from a state, or an error naming what is wrong."""
    if not isinstance(state, dict) or state.get("version") != STATE_VERSION:
        found = state.get("version") if isinstance(state, dict) else type(state).__name__
        raise ValueError(f"state version {found!r}, expected {STATE_VERSION} (a state of another cam.fmu build?)")
    params = {}
    for name, value in dict(state["params"]).items():
        if name not in _parameters.BY_NAME:
            raise ValueError(f"unknown parameter {name!r}")
        params[name] = _parameters.BY_NAME[name].check(value)
    if set(params) != set(_parameters.BY_NAME):
        raise ValueError(f"parameters missing: {sorted(set(_parameters.BY_NAME) - set(params))}")
    inputs = {name: _variables.check_input(name, state["inputs"][name]) for name in _variables.INPUT_NAMES}
    outputs = {name: float(state["outputs"][name]) for name in _variables.OUTPUT_NAMES}
    bad = [name for name, value in outputs.items() if not math.isfinite(value)]
    if bad:
        raise ValueError(f"outputs {bad} are not finite")
    sim = None
    if state["sim"] is not None:
        sim = _simulator.DriveSimulator(params)
        sim.set_state(copy.deepcopy(state["sim"]))
    return params, inputs, outputs, bool(state["initialized"]), sim
