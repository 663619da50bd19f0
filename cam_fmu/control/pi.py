"""The sampled PI speed controller of pi_speed.fmu, as plain Python (no FMU, ``math`` only).

One sample per communication step h (the sample period is the step size)::

    w      = omega_set (parameter) or the input omega_setpoint (external_setpoint = true)
    e      = w - omega_meas                                  speed error [rad/s]
    u_ff   = k_ff ((R / c_m) (M_load + J_load (w - w_prev) / h) + c_e w)   (k_ff = parameter feedforward, 0..1)
    v      = u_ff + kp e + I                                  unclamped command [V]
    u      = min(max(v, u_min), u_max)                        output clamp [V]
    I     += ki h e   unless v > u_max and e > 0, or v < u_min and e < 0   (anti-windup:
                                                               conditional integration)

Finite inputs can overflow a double (e = 1e308 - (-1e308); ki h e with h = 1e300 s): where e, the
setpoint's rate, u_ff, v or the new I is not finite the sample raises SimulationError naming it and
changes nothing (pi_speed.fmu: fmi2Error with that message), never an output that is NaN or infinite.

The feedforward is the armature voltage that holds the speed w against the
load torque M and the inertia J that cam.fmu reports (its outputs ``M`` and
``J``): R i + c_e w with c_m i = M + J dw/dt (L and the current's dynamics
neglected). Timing (no direct feedthrough, as every co-simulation master
assumes): the sample taken in the step from t to t + h uses the inputs at t
and is published at t + h; before the first step the output is the law
applied to the inputs at initialisation, without integrating.

``PARAMETERS`` is the controller's one parameter table (the FMU's variables,
its model description and the docs come from it); ``INPUTS``/``OUTPUTS``
likewise.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

from ..errors import SimulationError
from ..physics.parameters import KGF, ParameterError, ParameterSpec

_P = ParameterSpec
PARAMETERS: tuple[ParameterSpec, ...] = (
    _P("omega_set", "rad/s", 5.0, "speed setpoint (used unless external_setpoint)", low=-1e4, high=1e4),
    _P("kp", "V/(rad/s)", 2.0, "proportional gain", low=0.0, high=1e4),
    _P("ki", "V/rad", 20.0, "integral gain", low=0.0, high=1e6),
    _P("u_min", "V", -24.0, "lower clamp of the armature voltage", low=-1e4, high=1e4),
    _P("u_max", "V", 24.0, "upper clamp of the armature voltage", low=-1e4, high=1e4),
    _P("feedforward", "1", 0.0, "weight of the load-torque feedforward (R/c_m)(M + J dw/dt) + c_e w from the inputs M_load, J_load: 0 off, 1 full (a Real: ecos 0.7.2 ignores Boolean SSP parameter values)", low=0.0, high=1.0),
    _P("external_setpoint", "", False, "take the setpoint from the input omega_setpoint instead of the parameter omega_set", kind="boolean"),
    _P("R", "Ohm", 19.0, "armature resistance assumed by the feedforward", low=0.0, high=1e4, low_open=True),
    _P("c_e", "V/(rad/s)", 0.146, "back-EMF constant assumed by the feedforward", low=0.0, high=100.0, low_open=True),
    _P("c_m", "N.m/A", 0.015 * KGF, "torque constant assumed by the feedforward", low=0.0, high=100.0, low_open=True),
)
BY_NAME: dict[str, ParameterSpec] = {p.name: p for p in PARAMETERS}

INPUTS: tuple[tuple[str, str, float, str], ...] = (
    ("omega_meas", "rad/s", 0.0, "measured speed (connect cam.omega)"),
    ("omega_setpoint", "rad/s", 0.0, "speed setpoint (used when external_setpoint = true)"),
    ("M_load", "N.m", 0.0, "load torque for the feedforward (connect cam.M)"),
    ("J_load", "kg.m2", 0.0, "inertia for the feedforward (connect cam.J)"),
)
OUTPUTS: tuple[tuple[str, str, str], ...] = (
    ("u", "V", "armature voltage command, clamped to [u_min, u_max] (connect to cam.u)"),
    ("error", "rad/s", "speed error w - omega_meas of the last sample"),
    ("integral", "V", "state I of the integrator"),
    ("u_ff", "V", "feedforward part of the command (0 without feedforward)"),
)
UNITS: dict[str, str] = {row[0]: row[1] for row in INPUTS + OUTPUTS}  # type: ignore[operator]


def defaults() -> dict[str, Any]:
    return {p.name: p.default for p in PARAMETERS}


def resolve(overrides: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Defaults updated with ``overrides``, each checked; u_min <= u_max."""
    values = defaults()
    for name, value in (overrides or {}).items():
        if name not in BY_NAME:
            raise ParameterError(f"unknown controller parameter {name!r}; known: {', '.join(BY_NAME)}")
        values[name] = BY_NAME[name].check(value)
    if values["u_min"] > values["u_max"]:
        raise ParameterError(f"parameters 'u_min' = {values['u_min']!r} V > 'u_max' = {values['u_max']!r} V: "
                             "allowed u_min <= u_max")
    return values


@dataclass
class PiSpeedController:
    """The sampled PI law above; ``sample`` advances it by one step, ``output`` is the published sample."""

    params: dict[str, Any]

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        self.params = resolve(params)
        self.integral = 0.0
        self.w_prev: float | None = None
        self.u = 0.0
        self.error = 0.0
        self.u_ff = 0.0

    def setpoint(self, omega_setpoint: float) -> float:
        return float(omega_setpoint) if self.params["external_setpoint"] else self.params["omega_set"]

    def _law(self, omega_meas: float, omega_setpoint: float, M_load: float, J_load: float,
             h: float | None) -> tuple[float, float, float, float, float]:
        """(w, e, u_ff, v, u) on the inputs; raises SimulationError where one is not finite (an overflow of finite
        inputs: e = 1e308 - -1e308), naming it, before anything changes."""
        p = self.params
        w = self.setpoint(omega_setpoint)
        e = w - float(omega_meas)
        self._finite(e, "the speed error 'error' = w - omega_meas", w, omega_meas)
        u_ff = 0.0
        if p["feedforward"] > 0.0:
            w_dot = 0.0 if (h is None or self.w_prev is None) else (w - self.w_prev) / h
            self._finite(w_dot, "the setpoint's rate (w - w_prev) / h", w, omega_meas)
            u_ff = p["feedforward"] * (p["R"] / p["c_m"] * (float(M_load) + float(J_load) * w_dot) + p["c_e"] * w)
            self._finite(u_ff, "the feedforward 'u_ff'", w, omega_meas)
        v = u_ff + p["kp"] * e + self.integral
        self._finite(v, "the unclamped command u_ff + kp error + integral", w, omega_meas)
        u = min(max(v, p["u_min"]), p["u_max"])
        return w, e, u_ff, v, u

    def _finite(self, value: float, what: str, w: float, omega_meas: float) -> None:
        """Raise SimulationError naming ``what`` where ``value`` is not finite (pi_speed.fmu's fmi2Error)."""
        if not math.isfinite(value):
            raise SimulationError(f"{what} is not finite (an overflow): setpoint w = {w!r} rad/s, omega_meas = "
                                  f"{float(omega_meas)!r} rad/s, integral = {self.integral!r} V, kp = "
                                  f"{self.params['kp']!r} V/(rad/s), ki = {self.params['ki']!r} V/rad "
                                  "(the state is as before)")

    def initialize(self, omega_meas: float, omega_setpoint: float = 0.0, M_load: float = 0.0,
                   J_load: float = 0.0) -> float:
        """The output before the first step: the law on the inputs at initialisation, no integration."""
        w, e, u_ff, _v, u = self._law(omega_meas, omega_setpoint, M_load, J_load, None)
        self.w_prev, self.error, self.u_ff, self.u = w, e, u_ff, u
        return u

    def sample(self, h: float, omega_meas: float, omega_setpoint: float = 0.0, M_load: float = 0.0,
               J_load: float = 0.0) -> float:
        """One sample at the start of a step of length h [s] (inputs at t); returns u published at t + h."""
        if not (math.isfinite(h) and h > 0.0):
            raise ParameterError(f"sample period (communication step) h = {h!r} s: allowed (0, inf)")
        for name, value in (("omega_meas", omega_meas), ("omega_setpoint", omega_setpoint),
                            ("M_load", M_load), ("J_load", J_load)):
            if not math.isfinite(float(value)):
                raise ParameterError(f"input {name!r} = {value!r} [{UNITS[name]}] is not finite: allowed any finite value")
        p = self.params
        w, e, u_ff, v, u = self._law(omega_meas, omega_setpoint, M_load, J_load, h)
        integral = self.integral
        if not ((v > p["u_max"] and e > 0.0) or (v < p["u_min"] and e < 0.0)):
            integral += p["ki"] * h * e
        self._finite(integral, "the integral 'integral' + ki h error", w, omega_meas)
        self.integral, self.w_prev, self.error, self.u_ff, self.u = integral, w, e, u_ff, u
        return u

    def outputs(self) -> dict[str, float]:
        return {"u": self.u, "error": self.error, "integral": self.integral, "u_ff": self.u_ff}

    def get_state(self) -> dict[str, Any]:
        return {"integral": self.integral, "w_prev": self.w_prev, "u": self.u, "error": self.error, "u_ff": self.u_ff}

    def set_state(self, state: Mapping[str, Any]) -> None:
        self.integral = float(state["integral"])
        self.w_prev = None if state["w_prev"] is None else float(state["w_prev"])
        self.u, self.error, self.u_ff = float(state["u"]), float(state["error"]), float(state["u_ff"])
