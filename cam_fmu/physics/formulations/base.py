"""The contract of a formulation: how the drive's state advances over one communication step.

The co-simulation engine holds one formulation and one integrator and knows
no physics: it hands the formulation the inputs, asks it to advance by h [s]
and reads its outputs. A formulation that is an ODE with events (the
consistent one) uses the integrator it is given; the others step themselves.
"""
from __future__ import annotations

from array import array
from typing import Any


class Formulation:
    """One way of computing the drive's motion. Subclasses implement every method."""

    steps = 0  # internal steps of the last advance_checked
    energy_bounded = False  # True: a voltage drive, whose states respect physics.energy's bound
    own_reference = False  # True: its reference is the same algorithm (agreement to rounding)

    def advice(self, stepper: Any) -> str:
        """What to change when a state breaks a bound the model implies (names the setting)."""
        return (f"solver {stepper.name!r} with h_max = {stepper.h_max:g} s: reduce h_max or the "
                "communication step, or use solver 'rk45'")

    def set_inputs(self, u: float, omega_ref: float, omega_dot_ref: float) -> None:
        """Inputs held from now on [V, rad/s, rad/s2] (they may re-decide stick/slip)."""
        raise NotImplementedError

    def advance(self, h: float, integrator: Any, time: float) -> int:
        """Advance by h [s] from ``time`` [s]; return the internal steps taken."""
        raise NotImplementedError

    def advance_checked(self, h: float, integrator: Any, time: float, out: Any, budget: Any, u: float,
                        kernel: Any) -> int:
        """``advance`` (its step count into ``steps``), then the outputs into ``out`` and the kernel's
        verdict on them under the input u [V] (``DriveKernel.publishable``: 0 publish, else what is wrong)."""
        self.steps = self.advance(h, integrator, time)
        self.fill_outputs(integrator, out)
        return kernel.publishable(out, budget, u, h)

    def outputs(self, integrator: Any) -> dict[str, float]:
        """Every output of physics.variables.OUTPUTS at the current state."""
        raise NotImplementedError

    def fill_outputs(self, integrator: Any, buffer: Any) -> None:
        """The outputs, in OUTPUTS order, into ``buffer`` (a formulation on the hot path overrides this)."""
        buffer[:] = array("d", self.outputs(integrator).values())

    def get_state(self) -> dict[str, Any]:
        """The formulation's own state, JSON-serialisable."""
        raise NotImplementedError

    def set_state(self, state: dict[str, Any]) -> None:
        raise NotImplementedError
