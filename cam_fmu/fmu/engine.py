"""The drive stepped from one communication point to the next (the FMU's engine).

``DriveSimulator`` joins one formulation (physics.formulations, chosen from
the parameters ``drive`` and ``formulation``) and one solver (solvers.SOLVERS,
parameter ``solver``) and owns the time, the inputs and the state; it holds
no physics. The FMU class only maps FMI variables onto it. numpy is imported
on this path (through kinematics.cam_program), scipy never (scipy in an FMU
crashes native hosts at teardown); the per-step arithmetic is ``math`` on floats
in the drive kernel.

Solvers (consistent formulation, voltage drive):
- ``euler``, ``rk4``: fixed internal step min(h_max, stability limit): a step
  beyond the explicit method's stability limit is split, never taken.
- ``rk45``: Dormand-Prince 5(4) with error control (rtol, atol); its step size
  is carried across communication steps; failing to meet the tolerance within
  ``max_steps`` or above the smallest step raises SimulationError.
- ``etdrk4``: exponential RK4, exact on the electrical pole -R/L: stable and
  accurate with L > 0 at steps far above L/R.
The paper formulation runs its own fixed-step algorithm with T = the largest
step <= h_max that divides the communication step; the speed drive is exact.
"""
from __future__ import annotations

import math
from array import array
from typing import Any, Mapping

from ..kernel.drive_kernel import DriveKernel, EnergyBudget
from ..physics.drive import DriveModel
from ..physics.formulations import formulation_for
from ..physics.variables import INPUT_RANGES, INPUT_STARTS, INPUTS, OUTPUT_NAMES, OUTPUTS, check_input
from ..solvers import SOLVERS, SimulationError
from ..solvers.hybrid import HybridIntegrator

__all__ = ["DriveSimulator", "SimulationError", "INPUTS", "OUTPUTS"]

_OMEGA, _THETA, _S, _I, _J, _S_CAM = (OUTPUT_NAMES.index(name) for name in ("omega", "theta", "s", "i", "J", "s_cam"))
(_U_LO, _U_HI), (_W_LO, _W_HI), (_A_LO, _A_HI) = (INPUT_RANGES[name] for name in ("u", "omega_ref", "omega_dot_ref"))


class DriveSimulator:
    """One cam drive, advanced by ``do_step`` (times in s, SI units throughout)."""

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        self.model = model = DriveModel(params)
        p = model.params
        self.stepper = SOLVERS[p["solver"]](p)
        self.integrator = HybridIntegrator(self.stepper, int(p["max_steps"]))
        self.time = 0.0
        self.u = INPUT_STARTS["u"]
        self.omega_ref = INPUT_STARTS["omega_ref"]
        self.omega_dot_ref = INPUT_STARTS["omega_dot_ref"]
        self.steps_taken = 0  # internal steps, for benchmarks
        # The hot path (profile, right-hand side, rk45 with events, the checks of the outputs): one per drive.
        self.kernel = DriveKernel(model.program, model.J_m, model.m, model.M_f, model.F_gx, model.G_y, model.N_g,
                                  model.mu, model.r_b, model.c, model.R, model.L, model.c_e, model.c_m)
        self.formulation = formulation_for(model, self.u, self.omega_ref, self.kernel)
        self.budget: EnergyBudget | None = None  # set at the first step (voltage drive)
        # The outputs in OUTPUTS order: ``values`` holds the published ones (the FMU reads it), ``_scratch``
        # those of a step not yet checked; ``_stale`` until the current state's are computed.
        self.values = array("d", [0.0] * len(OUTPUT_NAMES))
        self._scratch = array("d", self.values)
        self._stale = True

    # ------------------------------------------------------------ public
    def set_inputs(self, u: float, omega_ref: float, omega_dot_ref: float = 0.0) -> None:
        """Inputs used by ``outputs`` before the first step [V, rad/s, rad/s2]."""
        if not (_U_LO <= u <= _U_HI and _W_LO <= omega_ref <= _W_HI and _A_LO <= omega_dot_ref <= _A_HI):
            u = _checked_input("u", u)  # the first one out of its range raises, naming it
            omega_ref = _checked_input("omega_ref", omega_ref)
            omega_dot_ref = _checked_input("omega_dot_ref", omega_dot_ref)
        self.u, self.omega_ref, self.omega_dot_ref = float(u), float(omega_ref), float(omega_dot_ref)
        self.formulation.set_inputs(self.u, self.omega_ref, self.omega_dot_ref)
        self._stale = True

    def do_step(self, t: float, h: float, u: float, omega_ref: float, omega_dot_ref: float = 0.0) -> None:
        """Advance from t to t + h [s] with inputs held over the step (FMI co-simulation).

        Speed drive: omega(t) = omega_ref + omega_dot_ref (t - t_k) over the step.
        The outputs reached are in ``values`` only once every check passed.
        """
        if not (h > 0.0 and math.isfinite(h)):
            raise SimulationError(f"communication step size = {h!r} s: allowed (0, inf)")
        self.set_inputs(u, omega_ref, omega_dot_ref)
        if self.budget is None and self.formulation.energy_bounded:
            out = self.values if not self._stale else self._fill(self.values)
            self.budget = EnergyBudget(self.model, out[_THETA], out[_OMEGA], out[_I], out[_S], out[_J])
        out, formulation = self._scratch, self.formulation
        # the step, its outputs into out and the kernel's verdict on them (the energy budget books the step)
        verdict = formulation.advance_checked(h, self.integrator, self.time, out, self.budget, self.u, self.kernel)
        self.steps_taken += formulation.steps
        self.time = t + h
        if verdict:
            self._refuse(verdict, out)
        self.values[:] = out
        self._stale = False

    def _fill(self, buffer: array) -> array:
        self.formulation.fill_outputs(self.integrator, buffer)
        return buffer

    def _refuse(self, verdict: int, out: array) -> None:
        """Raise the error the kernel's verdict on a step's outputs stands for, naming the cause."""
        if verdict == 1:
            name, value = next((n, v) for n, v in zip(OUTPUT_NAMES, out) if not math.isfinite(v))
            raise SimulationError(
                f"output {name!r} became {value!r} at t = {self.time:g} s with solver "
                f"{self.stepper.name!r}, h_max = {self.stepper.h_max:g} s: reduce h_max or use 'rk45'/'etdrk4'")
        if verdict == 2:
            raise SimulationError(
                f"the follower is {abs(out[_S] - out[_S_CAM]):.6g} m from the cam at t = {self.time:g} s, beyond "
                f"the clearance c = {self.model.c:g} m: a contact event was missed; "
                f"{self.formulation.advice(self.stepper)}")
        excess, tolerance = self.budget.excess(out[_OMEGA], out[_S], out[_J], out[_I])
        raise SimulationError(
            f"the state at t = {self.time:g} s holds {excess:.6g} J more energy than the source "
            f"delivered (tolerance {tolerance:.3g} J): energy was created, the result cannot be "
            f"trusted; {self.formulation.advice(self.stepper)}")

    def outputs(self) -> dict[str, float]:
        """Current value of every output in OUTPUTS (computed once per state)."""
        if self._stale:
            self._fill(self.values)
            self._stale = False
        return dict(zip(OUTPUT_NAMES, self.values))

    def get_state(self) -> dict[str, Any]:
        """Complete internal state, JSON-serialisable."""
        state: dict[str, Any] = {
            "time": self.time, "u": self.u, "omega_ref": self.omega_ref, "omega_dot_ref": self.omega_dot_ref,
            "h_next": self.stepper.h_next, "steps_taken": self.steps_taken,
        }
        state.update(self.formulation.get_state())
        state["energy"] = None if self.budget is None else self.budget.to_dict()
        return state

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state from get_state; SimulationError names what is wrong (checked before use)."""
        for key in ("time", "u", "omega_ref", "omega_dot_ref", "h_next"):
            if not math.isfinite(float(state[key])):
                raise SimulationError(f"state entry {key!r} = {state[key]!r} is not finite")
        self._stale = True
        self.time = float(state["time"])
        self.u = float(state["u"])
        self.omega_ref = float(state["omega_ref"])
        self.omega_dot_ref = float(state["omega_dot_ref"])
        self.stepper.h_next = float(state["h_next"])
        self.steps_taken = int(state["steps_taken"])
        self.formulation.set_state(dict(state))
        energy = state.get("energy")
        if energy is None:
            self.budget = None
        else:
            out = self.outputs()
            self.budget = EnergyBudget(self.model, out["theta"], out["omega"], out["i"], out["s"], out["J"])
            self.budget.restore(energy)


def _checked_input(name: str, value: float) -> float:
    try:
        return check_input(name, value)
    except ValueError as exc:
        raise SimulationError(str(exc)) from None
