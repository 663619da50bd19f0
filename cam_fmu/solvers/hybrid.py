"""One communication step of a hybrid system: a stepper, its events and profile breakpoints.

Every solver stops at the hybrid events (stick, backlash contact) by
re-stepping to the located zero, and applies the transition there; every step
also ends at the profile breakpoint it would cross (segment ends: the third
derivative of s jumps). Fixed-step solvers take min(h_max, stability limit at
the state); rk45 controls its own step. More than ``max_steps`` internal steps
in one communication step is an error naming the setting.
"""
from __future__ import annotations

import math
from typing import Any

from .base import HybridSystem, SimulationError, StepRejected, Stepper
from .events import locate


class HybridIntegrator:
    """Advances a HybridSystem with one fixed-step Stepper (rk45 runs in the drive kernel, same rules)."""

    def __init__(self, stepper: Stepper, max_steps: int) -> None:
        self.stepper = stepper
        self.max_steps = max_steps
        # (state, event values) at the end of the last step without an event: the next step starts
        # there, so its start values need no second evaluation (two profile evaluations per step).
        self._events_at: tuple[list, tuple] | None = None

    def advance(self, system: HybridSystem, y: list[float], mode: Any, u: float, h: float,
                time: float) -> tuple[list[float], int]:
        """(y at t + h, internal steps taken); mode is updated in place."""
        stepper = self.stepper
        t = 0.0
        steps = 0
        self._events_at = None
        system.settle(y, u, mode)
        f = system.rhs(u, mode)
        while h - t > 1e-12 * h:
            if mode.stuck and not system.has_current:
                break  # nothing evolves until the input changes
            steps += 1
            if steps > self.max_steps:
                raise StepRejected(self.max_steps_message(system, time + t, h))
            remaining = h - t
            if mode.stuck:
                dt = remaining
                y_new = system.stuck_state(y, u, dt)
            else:
                dt, y_new, retries = self._stable_step(system, f, y, remaining, u, mode)
                steps += retries
                dt, y_new = self._stop_at_breakpoint(system, f, y, y_new, dt, u, mode)
            hit = self._first_event(system, f, y, y_new, dt, u, mode)
            if hit is None:
                y, t = y_new, t + dt
                continue
            name, tau, y_event = hit
            y, t = y_event, t + tau
            system.apply_event(y, u, mode, name)
            f = system.rhs(u, mode)  # the mode changed
        return y, steps

    def max_steps_message(self, system: HybridSystem, time: float, h: float) -> str:
        """The error text when a communication step of h [s] needed more than max_steps internal steps."""
        return (f"solver {self.stepper.name!r} needed more than max_steps = {self.max_steps} internal steps "
                f"in one communication step of {h:g} s at t = {time:g} s: {self._advice(system)}")

    def _advice(self, system: HybridSystem) -> str:
        """What to change when the work bound is hit, for this solver."""
        stepper = self.stepper
        if stepper.adaptive:
            text = "raise max_steps, loosen rtol/atol or shorten the communication step"
            if system.has_current and not stepper.exact_electrical_pole:
                text += "; with L > 0 the electrical pole is stiff: use solver 'etdrk4'"
            return text
        return (f"raise max_steps or h_max (now {stepper.h_max:g} s), or shorten the communication step; "
                f"{stepper.name!r} takes steps no longer than its stability limit")

    def _stable_step(self, system: HybridSystem, f, y, remaining: float, u: float, mode):
        """One fixed step inside the stability and resolution limits along the whole step: (dt, y_new, retries).

        Two limits: stability (h times the fastest rate of the dynamics within the
        method's stability factor) and resolution (the cam turns at most
        ``resolution`` of the profile's finest angular detail per step: a step
        cannot resolve a shorter feature). Both are taken at the start and checked
        again at the end of the step; where the step ends faster (omega grows to
        1300 rad/s at 100 V), it is retaken with the limits of the faster end.
        Measured before: rk4 at 100 V gave theta(0.5 s) = 38.96 rad against 67.98,
        each step sweeping more than a whole profile feature; now 4e-3 rad off.
        """
        stepper = self.stepper
        electrical = not stepper.exact_electrical_pole
        stab, res = stepper.stability, stepper.resolution
        rate = system.stiffness_rate(y, mode, electrical)
        sweep = system.profile_rate(y)
        retries = 0
        while True:
            dt = min(remaining, stepper.h_max, stab / rate if rate > 0.0 else math.inf,
                     res / sweep if sweep > 0.0 else math.inf)
            y_new = stepper.step(f, y, dt, system, u, mode)
            if all(map(math.isfinite, y_new)):
                rate_end = system.stiffness_rate(y_new, mode, electrical)
                sweep_end = system.profile_rate(y_new)
            else:
                rate_end = sweep_end = math.inf
            if (dt * rate_end <= 1.25 * stab and dt * sweep_end <= 1.25 * res) or retries >= 30:
                swept = dt * max(sweep, sweep_end)
                if swept > stepper.max_sweep:
                    raise SimulationError(
                        f"solver {stepper.name!r} with h_max = {stepper.h_max:g} s turns the cam through "
                        f"{swept:.3g} of the profile's finest feature in one step (omega = {y_new[1]:.4g} rad/s), "
                        f"more than {stepper.max_sweep:g}: its first-order error is large there; reduce h_max "
                        f"below {stepper.max_sweep / max(sweep, sweep_end):.3g} s or use solver 'rk4' or 'rk45'")
                return dt, y_new, retries
            rate = max(rate, rate_end if math.isfinite(rate_end) else 4.0 * stab / dt)
            sweep = max(sweep, sweep_end if math.isfinite(sweep_end) else 4.0 * res / dt)
            retries += 1

    def _stop_at_breakpoint(self, system: HybridSystem, f, y, y_new, dt: float, u: float, mode):
        """Shorten a step so that it ends at the first profile breakpoint it crosses.

        Where the third derivative of s jumps, a fixed-step method stepping
        across loses its order. Measured on fig. 6 at 1 ms: rk4's theta error
        stopped falling near 1e-6 rad as h_max went from 2.5e-4 to 1e-4 s (now
        7.6e-7 and 6.4e-9 rad at 2.5e-4 and 1.25e-4 s), and rk45's error at
        rtol 1e-8 was 1.3e-5 rad, dominated by these crossings (now 8.5e-9 rad
        at the same cost). The step is cut at the located crossing (just past
        it), so every step sees one smooth piece of the profile.
        """
        target = system.first_breakpoint_passed(y[0], y_new[0])
        if target is None:
            return dt, y_new
        direction = mode.direction
        stepper = self.stepper

        def gap(state):
            return direction * (target - state[0])

        return locate(gap, lambda tau: stepper.step(f, y, tau, system, u, mode), gap(y), gap(y_new), dt, y_new)

    def _first_event(self, system: HybridSystem, f, y, y_new, dt: float, u: float, mode):
        """Earliest event in (0, dt]: (name, time from step start, state there), or None."""
        cached = self._events_at
        self._events_at = None
        before = cached[1] if cached is not None and cached[0] is y else system.event_values(y, u, mode)
        if not before:
            return None
        after = system.event_values(y_new, u, mode)
        names = system.event_names(mode)
        # A function already at or below zero at the step's start is decided by where it goes:
        # into the event (g1 < 0, or it started below zero) fires it at once; away from it (g1 > 0
        # from exactly 0) does not. A zero at the start is never lost.
        for k, (g0, g1) in enumerate(zip(before, after)):
            if g0 < 0.0 or (g0 == 0.0 and g1 < 0.0):
                return names[k], 0.0, list(y)
        fired = [k for k, (g0, g1) in enumerate(zip(before, after)) if g0 > 0.0 and g1 <= 0.0]
        if not fired:
            self._events_at = (y_new, after)
            return None
        stepper = self.stepper
        if mode.stuck:
            def advance(tau):
                return system.stuck_state(y, u, tau)
        else:
            def advance(tau):
                return stepper.step(f, y, tau, system, u, mode)
        best = None
        for k in fired:
            tau, y_root = locate(lambda s: system.event_values(s, u, mode)[k], advance, before[k], after[k], dt, y_new)
            if best is None or tau < best[1]:
                best = (names[k], tau, y_root)
        return best
