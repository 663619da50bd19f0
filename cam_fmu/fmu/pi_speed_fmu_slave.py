"""The FMI 2.0 co-simulation slave of pi_speed.fmu (pythonfmu 0.7.0): a sampled PI speed controller.

Thin: it registers the variables of ``control.pi`` (INPUTS, OUTPUTS,
PARAMETERS, same names and units) and maps the FMI calls onto
``control.pi.PiSpeedController``: exit_initialization_mode publishes the
initial output (the law on the inputs as set), do_step(t, h) takes one sample
from the inputs at t and publishes it (outputs change only in doStep: no
direct feedthrough).

The module name ``pi_speed_fmu_slave`` is unique (pythonfmu imports the script
as a top-level module; module names are process-global), and so is the class
name. Imports at run time: pythonfmu and ``cam_fmu.control.pi`` (math only). The project's
Python-hosting binary answers fmi2GetReal of the outputs and inputs and fmi2SetReal of
finite inputs in C (``exchange_layout``, docs/fmu.md); only fmi2DoStep enters Python per step.
Errors are reported as in camdrive_fmu_slave: logged, printed to stderr, raised
(pythonfmu returns fmi2Fatal).
"""
from __future__ import annotations

import math
import sys
from array import array
from typing import Any, Dict

from pythonfmu import Boolean, Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real, String
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

from cam_fmu.control import pi as _pi
from cam_fmu.physics.parameters import ParameterError

MODEL_NAME = "pi_speed"
DESCRIPTION = ("Sampled PI speed controller (one sample per communication step) with conditional-integration "
               "anti-windup, output clamp [u_min, u_max] and optional load-torque feedforward from cam.fmu's M and J.")
DEFAULT_EXPERIMENT = DefaultExperiment(start_time=0.0, stop_time=2.0, step_size=1e-3)


class PiSpeedSlave(Fmi2Slave):
    """pi_speed.fmu: u = clamp(u_ff + kp e + I), I += ki h e (conditional integration)."""

    author = "cam_fmu"
    description = DESCRIPTION
    default_experiment = DEFAULT_EXPERIMENT

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.modelName = MODEL_NAME
        self._params: Dict[str, Any] = _pi.defaults()
        self._inputs: Dict[str, float] = {name: float(start) for name, _u, start, _d in _pi.INPUTS}
        self._ctrl = _pi.PiSpeedController(self._params)
        self._initialized = False
        for name, _unit, _start, desc in _pi.INPUTS:
            self.register_variable(Real(name, causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                                        description=desc, getter=self._input_getter(name),
                                        setter=self._input_setter(name)))
        for name, _unit, desc in _pi.OUTPUTS:
            self.register_variable(Real(name, causality=Fmi2Causality.output, variability=Fmi2Variability.discrete,
                                        initial=Fmi2Initial.calculated, description=desc,
                                        getter=self._output_getter(name)))
        kinds = {"real": Real, "boolean": Boolean, "string": String}
        for spec in _pi.PARAMETERS:
            self.register_variable(kinds[spec.kind](
                spec.name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
                initial=Fmi2Initial.exact, description=spec.description,
                getter=self._param_getter(spec.name), setter=self._param_setter(spec.name)))

    def _input_getter(self, name: str):
        return lambda: self._inputs[name]

    def _input_setter(self, name: str):
        def setter(value: Any) -> None:
            number = float(value)
            if not math.isfinite(number):  # a NaN in would be a NaN command out, with status OK
                self._fail(f"input {name!r} = {number!r} [{_pi.UNITS[name]}] is not finite: allowed any finite value")
            self._inputs[name] = number
        return setter

    def _output_getter(self, name: str):
        def getter() -> float:
            if not self._initialized:
                self._start()
            return self._ctrl.outputs()[name]
        return getter

    def _param_getter(self, name: str):
        return lambda: self._params[name]

    def _param_setter(self, name: str):
        spec = _pi.BY_NAME[name]

        def setter(value: Any) -> None:
            if self._initialized:
                self._fail(f"parameter {name!r} is 'fixed': set it before fmi2ExitInitializationMode")
            try:
                self._params[name] = spec.check(value)
            except ParameterError as exc:
                self._fail(str(exc))
        return setter

    def _fail(self, message: str) -> None:
        self.log(message, Fmi2Status.error)
        print(f"[pi_speed.fmu {self.instance_name}] error: {message}", file=sys.stderr, flush=True)
        raise ValueError(message)

    def _start(self) -> None:
        try:
            self._ctrl = _pi.PiSpeedController(self._params)
            self._ctrl.initialize(**self._inputs)
        except ParameterError as exc:
            self._fail(str(exc))

    def exit_initialization_mode(self) -> None:
        self._start()
        self._initialized = True

    def do_step(self, current_time: float, step_size: float) -> bool:
        if not self._initialized:
            self.exit_initialization_mode()
        try:
            self._ctrl.sample(step_size, **self._inputs)
        except ParameterError as exc:
            self._fail(f"at t = {current_time!r} s: {exc}")
        return True  # a falsy return would become a silent fmi2Discard

    # ----------------------------------------------------------------- the exchange (the Python-hosting binary)
    def exchange_layout(self) -> tuple:
        """(output value references, input value references, input ranges): the variables whose
        fmi2GetReal (and fmi2SetReal within range, for inputs) the binary answers in C, without Python.
        The ranges are the finite doubles: a NaN or an infinity goes to Python, for its message."""
        by_name = {var.name: vr for vr, var in self.vars.items()}
        finite = (-1.7976931348623157e308, 1.7976931348623157e308)
        return (tuple(by_name[name] for name, _u, _d in _pi.OUTPUTS),
                tuple(by_name[name] for name, _u, _s, _d in _pi.INPUTS),
                tuple(finite for _ in _pi.INPUTS))

    def published_outputs(self) -> array | None:
        """The outputs as an FMI get would return them, or None before they are calculated."""
        if not self._initialized:
            return None
        values = self._ctrl.outputs()
        return array("d", [values[name] for name, _u, _d in _pi.OUTPUTS])

    def input_values(self) -> array:
        """The inputs in INPUTS order (C doubles)."""
        return array("d", [self._inputs[name] for name, _u, _s, _d in _pi.INPUTS])

    def take_inputs(self, values: list) -> None:
        """Inputs in INPUTS order, already checked against their ranges by the binary."""
        self._inputs.update(zip((name for name, _u, _s, _d in _pi.INPUTS), values))

    def _get_fmu_state(self) -> Dict[str, Any]:
        return {"params": dict(self._params), "inputs": dict(self._inputs), "initialized": self._initialized,
                "ctrl": self._ctrl.get_state()}

    def _set_fmu_state(self, state: Dict[str, Any]) -> None:
        self._params = dict(state["params"])
        self._inputs = {k: float(v) for k, v in state["inputs"].items()}
        self._initialized = bool(state["initialized"])
        self._ctrl = _pi.PiSpeedController(self._params)
        self._ctrl.set_state(state["ctrl"])
