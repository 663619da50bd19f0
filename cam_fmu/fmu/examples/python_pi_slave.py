"""An example of a block written in Python: a sampled PI speed controller as an FMI 2.0 co-simulation FMU.

Build it with pythonfmu (``cam-fmu python-block --dest out/python_pi.fmu``, or pythonfmu's own
``pythonfmu build -f python_pi_slave.py``) and close the speed loop around cam.fmu with
``cam-fmu cosim --controller out/python_pi.fmu``. It is a user's file: it imports nothing of cam_fmu,
only pythonfmu and the standard library, so copy it and change the law.

The law (one sample per communication step h; the command is published at the step's end):
    e = omega_set - omega_meas;  v = kp e + I;  u = min(max(v, u_min), u_max)
    I += ki h e unless the clamp is active and e pushes further into it (anti-windup)

What it needs where it runs: pythonfmu's binary embeds the Python it was built with. The machine that
runs the FMU needs a CPython of the same minor version as its shared library (libpython3.X), with
pythonfmu's run-time part (bundled in the FMU), found through PATH or PYTHONHOME. Hosts written in C (ecos,
OMSimulator, the FMU Compliance Checker) must be started with that libpython preloaded. cam.fmu and
pi_speed.fmu, written in C, need none of this.
"""
from __future__ import annotations

import math

from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status


class PythonPi(Fmi2Slave):
    """PI speed controller in Python: u = clamp(kp e + I), I += ki h e (conditional integration)."""

    author = "cam_fmu example"
    description = "A sampled PI speed controller written in Python (a pythonfmu example)"

    def __init__(self, **kwargs) -> None:
        super().__init__(**kwargs)
        self.omega_meas = 0.0
        self.omega_set = 5.0
        self.kp = 2.0
        self.ki = 20.0
        self.u_min = -24.0
        self.u_max = 24.0
        self.u = 0.0
        self.error = 0.0
        self.integral = 0.0
        self.register_variable(Real("omega_meas", causality=Fmi2Causality.input,
                                    variability=Fmi2Variability.continuous, description="measured speed [rad/s]"))
        for name, text in (("u", "armature voltage command [V]"), ("error", "speed error [rad/s]"),
                           ("integral", "integrator state [V]")):
            self.register_variable(Real(name, causality=Fmi2Causality.output, variability=Fmi2Variability.discrete,
                                        initial=Fmi2Initial.calculated, description=text))
        for name, text in (("omega_set", "speed setpoint [rad/s]"), ("kp", "proportional gain [V/(rad/s)]"),
                           ("ki", "integral gain [V/rad]"), ("u_min", "lower clamp [V]"), ("u_max", "upper clamp [V]")):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed,
                                        initial=Fmi2Initial.exact, description=text))

    def _law(self) -> tuple[float, float, float]:
        e = self.omega_set - self.omega_meas
        v = self.kp * e + self.integral
        return e, v, min(max(v, self.u_min), self.u_max)

    def exit_initialization_mode(self) -> None:
        if not (math.isfinite(self.u_min) and math.isfinite(self.u_max) and self.u_min <= self.u_max):
            self.log(f"parameters u_min = {self.u_min} V, u_max = {self.u_max} V: allowed finite u_min <= u_max",
                     Fmi2Status.error)
            raise ValueError("u_min > u_max")
        self.error, _v, self.u = self._law()

    def do_step(self, current_time: float, step_size: float) -> bool:
        if not math.isfinite(self.omega_meas):
            self.log(f"input omega_meas = {self.omega_meas} is not finite at t = {current_time} s", Fmi2Status.error)
            raise ValueError("omega_meas is not finite")
        e, v, u = self._law()
        if not ((v > self.u_max and e > 0.0) or (v < self.u_min and e < 0.0)):
            self.integral += self.ki * step_size * e
        self.error, self.u = e, u
        return True
