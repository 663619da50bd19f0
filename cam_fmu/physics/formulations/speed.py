"""The speed drive: omega(t) is imposed; the torque, current and voltage it needs are outputs.

Over a communication step omega(t) = omega_ref + omega_dot_ref (t - t_k), so a
ramp of omega is exact in co-simulation (docs/model.md section 8).
"""
from __future__ import annotations

import math
from typing import Any

from ...errors import SimulationError
from ..contact import follower_along, speed_engaged
from ..drive import DriveModel
from ..variables import output_record
from .base import Formulation


def speed_drive_outputs(model: DriveModel, theta: float, omega: float, omega_dot: float, s: float, engaged: bool) -> dict[str, float]:
    """Torque, inertia, current and voltage needed for a given motion.

    c_m i = J_m omega_dot + M (consistent formulation); the voltage adds
    L di/dt, with di/dt = omega dM/dtheta at constant speed (central difference,
    1e-6 rad).
    """
    direction = 1.0 if omega > 0.0 else (-1.0 if omega < 0.0 else 0.0)
    load = model.load(theta, omega, omega_dot, direction, engaged)
    i = (model.J_m * omega_dot + load.M) / model.c_m
    voltage = model.motor.voltage(i, omega)
    if model.L > 0.0 and omega != 0.0:
        d = 1e-6
        dM = (model.load(theta + d, omega, omega_dot, direction, engaged).M
              - model.load(theta - d, omega, omega_dot, direction, engaged).M) / (2 * d)
        voltage += model.L * omega * dM / model.c_m
    s_cam = model.program.derivatives(theta)[0]
    return output_record(omega=omega, theta=theta, s=s, i=i, M=load.M, J=load.J, v=load.v, a=load.a,
                         alpha=load.alpha, s_cam=s_cam, voltage=voltage)


class SpeedDrive(Formulation):
    """theta follows omega_ref + omega_dot_ref t; the play operator sees every extremum of s_cam."""

    own_reference = True

    def __init__(self, model: DriveModel, omega_ref: float) -> None:
        self.model = model
        self.theta = model.params["theta0"]
        self.speed = omega_ref  # rad/s, omega at the current time
        self.omega_ref = omega_ref
        self.omega_dot_ref = 0.0
        self.s = model.program.derivatives(self.theta)[0]

    def set_inputs(self, u: float, omega_ref: float, omega_dot_ref: float) -> None:
        self.omega_ref, self.omega_dot_ref = omega_ref, omega_dot_ref
        self.speed = omega_ref

    def advance(self, h: float, integrator: Any, time: float) -> int:
        model = self.model
        end = self.theta + (self.omega_ref + 0.5 * self.omega_dot_ref * h) * h
        self.speed = self.omega_ref + self.omega_dot_ref * h
        self.s = follower_along(model.program, self.s, self.theta, end, model.c)
        self.theta = end
        return 1

    def outputs(self, integrator: Any) -> dict[str, float]:
        model = self.model
        engaged = speed_engaged(model.program, self.theta, self.s, self.speed, model.c)
        return speed_drive_outputs(model, self.theta, self.speed, self.omega_dot_ref, self.s, engaged)

    def get_state(self) -> dict[str, Any]:
        return {"theta": self.theta, "s": self.s, "speed": self.speed}

    def set_state(self, state: dict[str, Any]) -> None:
        """The engine's state: this formulation's entries and the inputs held."""
        names = ("theta", "s", "speed", "omega_ref", "omega_dot_ref")
        bad = [name for name in names if not math.isfinite(float(state[name]))]
        if bad:
            raise SimulationError(f"state entries {bad} of the speed drive are not finite")
        self.theta = float(state["theta"])
        self.s = float(state["s"])
        self.speed = float(state["speed"])
        self.omega_ref = float(state["omega_ref"])
        self.omega_dot_ref = float(state["omega_dot_ref"])
