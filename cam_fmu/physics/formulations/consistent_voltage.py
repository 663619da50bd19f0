"""The consistent formulation under a voltage input, as the engine steps it (its state lives in the kernel).

``HybridDrive`` (consistent.py) holds the physics of the modes and events;
this class keeps the state in the engine's drive kernel, where rk45 advances it
compiled, and hands the fixed-step solvers to ``solvers.hybrid.HybridIntegrator``.
Part of the run-time engine (not of the readable model): it imports ``solvers``;
the kernel is handed to it, so importing it does not import the kernel.
"""
from __future__ import annotations

import math
from typing import Any

from ...errors import SimulationError, StepRejected
from ...solvers.dopri import step_floor_message
from ..drive import DriveModel
from .base import Formulation
from .consistent import CURRENT, EVENT_NAMES, OMEGA, THETA, HybridDrive, Mode


class ConsistentVoltage(Formulation):
    """The energy-consistent drive under the voltage input u, stepped by the engine's integrator.

    The state lives in ``kernel``, the engine's ``DriveKernel`` of this model
    (``y`` and ``mode`` read and write it): rk45 advances it there, compiled,
    and calls back into ``HybridDrive`` for the transitions (events, rest); the
    fixed-step solvers advance it through ``solvers.hybrid.HybridIntegrator``.
    """

    energy_bounded = True

    def __init__(self, model: DriveModel, u: float, kernel: Any) -> None:
        p = model.params
        self.hybrid = HybridDrive(model)
        self.kernel = kernel
        self.y, self.mode = self.hybrid.initial(p["theta0"], p["omega0"], p["i0"])
        self.u = u
        self._settle(u)
        kernel.apply_event = self._apply_event
        kernel.settle_python = self._settle
        kernel.fail = self._fail
        self._integrator: Any = None  # the one advancing the kernel (its messages name its settings)
        self._configured: Any = None  # the integrator whose rk45 settings the kernel holds

    # ------------------------------------------------------------ the state, kept in the kernel
    @property
    def y(self) -> list[float]:
        k = self.kernel
        return [k.y0, k.y1, k.y2][: self.hybrid.size]

    @y.setter
    def y(self, y: list[float]) -> None:
        k = self.kernel
        k.y0, k.y1 = y[THETA], y[OMEGA]
        k.y2 = y[CURRENT] if len(y) > CURRENT else 0.0

    @property
    def mode(self) -> Mode:
        k = self.kernel
        return Mode(bool(k.stuck), k.direction, k.contact, k.s_free, k.side)

    @mode.setter
    def mode(self, mode: Mode) -> None:
        k = self.kernel
        k.stuck, k.direction, k.contact, k.s_free, k.side = mode.stuck, mode.direction, mode.contact, \
            mode.s_free, mode.side

    def _settle(self, u: float) -> None:
        y, mode = self.y, self.mode
        self.hybrid.settle(y, u, mode)
        self.y, self.mode = y, mode

    def _apply_event(self, code: int, u: float) -> None:
        y, mode = self.y, self.mode
        self.hybrid.apply_event(y, u, mode, EVENT_NAMES[code])
        self.y, self.mode = y, mode

    def _fail(self, kind: int, time: float, value: float) -> None:
        """The kernel's errors at ``time`` [s]: kind 0, the rk45 step fell below its floor ``value`` [s];
        kind 1, more than max_steps steps in the communication step ``value`` [s]."""
        integrator = self._integrator
        if kind == 0:
            raise StepRejected(step_floor_message(integrator.stepper, value, time))
        raise StepRejected(integrator.max_steps_message(self.hybrid, time, value))

    # ------------------------------------------------------------ Formulation
    def set_inputs(self, u: float, omega_ref: float, omega_dot_ref: float) -> None:
        if u == self.u:
            return  # settled for this input already (each advance settles again at its start)
        self.u = u
        self._settle(u)  # at rest: stuck, or starting now

    def advance(self, h: float, integrator: Any, time: float) -> int:
        kernel = self.kernel
        kernel.snapshot()
        self._integrator = integrator
        try:
            if integrator.stepper.adaptive:
                return self._advance_rk45(integrator, kernel.advance, self.u, h, time)
            kernel.k1_valid = False
            y, mode = self.y, self.mode
            y, steps = integrator.advance(self.hybrid, y, mode, self.u, h, time)
            self.y, self.mode = y, mode
            return steps
        except StepRejected:
            kernel.rollback()  # a rejected step leaves the state as before it (fmi2Discard)
            raise

    def advance_checked(self, h: float, integrator: Any, time: float, out: Any, budget: Any, u: float,
                        kernel: Any) -> int:
        if not integrator.stepper.adaptive:
            return super().advance_checked(h, integrator, time, out, budget, u, kernel)
        self._integrator = integrator
        try:  # rk45: the step, the outputs and their checks in one compiled call
            verdict = self._advance_rk45(integrator, kernel.advance_checked, self.u, h, time, out, budget)
        except StepRejected:
            kernel.rollback()
            raise
        self.steps = kernel.steps
        return verdict

    def _advance_rk45(self, integrator: Any, advance: Any, *args: Any) -> int:
        """``advance(*args)`` of the kernel with the stepper's settings; its step size carried over."""
        kernel, stepper = self.kernel, integrator.stepper
        if self._configured is not integrator:  # the settings are fixed for an integrator's life
            kernel.h_max, kernel.rtol, kernel.atol = stepper.h_max, stepper.rtol, stepper.atol
            kernel.max_steps = integrator.max_steps
            self._configured = integrator
        kernel.h_next = stepper.h_next  # the engine's state (set_state may change it)
        try:
            return advance(*args)
        finally:
            stepper.h_next = kernel.h_next

    def omega_dot_at_end(self) -> float | None:
        """omega_dot at the state reached, when rk45's last stage computed it under the input held."""
        k = self.kernel
        return k.k1_1 if k.k1_valid and not k.stuck and k.fsal_u == self.u else None

    def outputs(self, integrator: Any) -> dict[str, float]:
        return self.hybrid.outputs(self.y, self.u, self.mode, self.omega_dot_at_end())

    def fill_outputs(self, integrator: Any, buffer: Any) -> None:
        k = self.kernel
        known = k.k1_valid and not k.stuck and k.fsal_u == self.u
        k.outputs(self.u, k.k1_1, known, buffer)

    def get_state(self) -> dict[str, Any]:
        return {"y": list(self.y), "mode": self.mode.to_dict()}

    def set_state(self, state: dict[str, Any]) -> None:
        """The engine's state: this formulation's entries and the input held."""
        y = [float(x) for x in state["y"]]
        if len(y) != self.hybrid.size:
            raise SimulationError(f"state 'y' has length {len(y)}, this drive's state has {self.hybrid.size} "
                                  "(theta, omega" + (", i)" if self.hybrid.has_current else ")"))
        mode = Mode(**state["mode"])
        values = y + [mode.s_free, mode.direction, mode.side]
        if not all(math.isfinite(v) for v in values) or mode.direction not in (1.0, -1.0) \
                or mode.side not in (1.0, -1.0) or mode.contact not in (-1, 0, 1):
            raise SimulationError(f"state 'y' = {y} or mode {mode} is not finite or not a valid mode")
        self.u, self.y, self.mode = float(state["u"]), y, mode
        self.kernel.k1_valid = False
