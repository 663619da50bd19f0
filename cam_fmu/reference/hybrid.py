"""The reference's one hybrid loop: integrate to the next event with solve_ivp's events, apply its transition.

Every drive and closure runs through ``HybridRun.pieces`` (the rigid drive in integrate.py, the speed drive's
follower in flight.py, the voltage drive's in voltage_flight.py). A run gives the mode's events, right-hand side and
solve_ivp options of a piece (``_piece``; each event function carries its ``physics.modes.Event`` as ``kind``), what
is applied at a restart (``_settle``: the input's break, an event function that jumped below 0), the transition of
each event (``TRANSITIONS``, one table per run) and the output row (``_row``).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy.integrate import solve_ivp

from ..physics.modes import Event
from ..physics.signals import Signal

# J: the energy integrals a voltage-driven run can carry after its state: E_in = int u i dt, E_copper = int R i^2 dt,
# E_shaft = int M_f |omega| dt, E_guide = int f |v| dt, E_damp = int d_shaft (omega_m - omega)^2 dt.
ENERGY = ("E_in", "E_copper", "E_shaft", "E_guide", "E_damp")
# Events at one instant in a row before the run is refused (each transition changes the mode; a cycle means
# a model error, never a hang).
MAX_STALL = 1000


def next_breakpoint(breakpoints: list[float], theta: float, direction: float) -> float:
    """The first of the profile's breakpoints [rad] (sorted over one turn, with 0 and 2 pi) strictly ahead of theta
    [rad] in the direction of motion."""
    two_pi = 2.0 * math.pi
    base = math.floor(theta / two_pi) * two_pi
    local = theta - base
    eps = 1e-12 * max(1.0, abs(theta))
    if direction > 0:
        for b in breakpoints:
            if b > local + eps:
                return base + b
        return base + two_pi + breakpoints[1]
    for b in reversed(breakpoints):
        if b < local - eps:
            return base + b
    return base - two_pi + breakpoints[-2]


def piece_input(signal: Signal, end: float) -> Callable[[float], tuple[float, float]]:
    """(value, slope) of ``signal`` as a function of t within a piece that ends at ``end`` [s]: at the end, an input's
    break, the piece's own (the left limit). solve_ivp evaluates the right-hand side and the events at the end point;
    with the value after the break there, an event that the break itself makes (a break-away at a step of u) was
    located a rounding before the break and applied there with the input before it, 1000 times over."""
    def at(t: float) -> tuple[float, float]:
        if t < end:
            return signal.value(t), signal.slope(t)
        return signal.left_value(end), signal.left_slope(end)
    return at


def collect(rows: list[dict[str, float]], grid: np.ndarray) -> dict[str, np.ndarray]:
    """The rows on ``grid`` [s] as arrays by output name, with ``time``."""
    return {"time": grid.copy(), **{name: np.array([row[name] for row in rows]) for name in rows[0]}}


def event(kind: Event, fn: Callable) -> Callable:
    """``fn`` as a terminal event of solve_ivp, firing where it falls through 0, marked with its ``kind``."""
    fn.terminal, fn.direction, fn.kind = True, -1, kind
    return fn


class HybridRun:
    """A hybrid run integrated piece by piece with solve_ivp, stopping at each event and input break.

    Subclasses give ``_piece(t, y, mode)`` -> (events, rhs, solve_ivp options), ``_settle(t, y, mode, after_event)``
    -> (mode, y), ``_row(t, y, mode, left)`` and ``TRANSITIONS`` (Event -> method(t, y, mode, kind) -> (mode, y)), and
    set ``rtol`` and ``label`` (the errors' prefix).
    """

    label = "reference"
    # s: a time shorter than the flight the last rebound starts, or 0. A step of the integrator holding the whole
    # bounce would see the gap <= 0 at its end and locate the touch-down at its start, where the gap is 0.
    rebound = 0.0
    TRANSITIONS: dict = {}

    def _near(self, t: float) -> float:
        """s, how close a grid time or an input break counts as t."""
        return 1e-15 * max(1.0, t)

    def _inside(self, t: float) -> float:
        """s, how far before a piece's end t a grid time must lie to be read from the piece's dense output."""
        return 0.0

    def _origin(self, y: list) -> float:
        """rad, subtracted from theta while a piece is integrated (rtol then acts on the angle from it)."""
        return 0.0

    def _rows_first(self, t: float, after_event: bool) -> bool:
        """Are the rows due at a restart t the state's before ``_settle`` (an input's left limit)?"""
        return True

    def _stall(self, t: float) -> None:
        """Count an event at t; refuse the run after MAX_STALL in a row at one instant."""
        self._stalled = self._stalled + 1 if t - self._t_last <= 1e-14 * max(1.0, t) else 0
        if self._stalled > MAX_STALL:
            raise RuntimeError(f"{self.label}: {MAX_STALL} events at t = {t!r} s without end")
        self._t_last = t

    def _impact(self, t: float, before: float, after: float, rebounds: bool, scale: float) -> None:
        """Count an impact at t [s] (the relative speeds before and after [m/s]); a rebound keeps the next piece
        shorter than its bounce: the relative acceleration is at most ``scale`` A [m/s2] near here, so the gap stays
        > 0 for about 2 |w| / A."""
        self.impacts.append((t, before, after))
        if rebounds and after != 0.0:
            self.rebound = abs(after) / (2.0 * scale)

    def pieces(self, grid: np.ndarray, t: float, y: list, mode, breaks: list[float]) -> dict[str, np.ndarray]:
        """Rows on ``grid`` from (t, y, mode), stopping at each event and input break [s]."""
        stop = float(grid[-1])
        breaks = breaks + [stop]
        rows, k_out, after_event = [], 0, False
        self._stalled, self._t_last = 0, -math.inf

        def emit(t: float, y, mode, left: bool) -> None:
            nonlocal k_out
            while k_out < len(grid) and grid[k_out] <= t + self._near(t):
                rows.append(self._row(float(grid[k_out]), y, mode, left))
                k_out += 1

        while True:
            first = self._rows_first(t, after_event)
            if first:
                emit(t, y, mode, True)
            if first and t >= stop - self._near(stop):
                break
            mode, y = self._settle(t, y, mode, after_event)
            emit(t, y, mode, False)
            if t >= stop - self._near(stop):
                break
            t_end = next(b for b in breaks if b > t + self._near(t))
            self.piece_end = t_end   # the piece's input up to t_end is its own (piece_input)
            events, rhs, options = self._piece(t, y, mode)
            if self.rebound > 0.0:  # the first piece after a rebound is shorter than the bounce it starts
                t_end = min(t_end, t + self.rebound)
                options["max_step"] = min(options.get("max_step", math.inf), self.rebound / 8.0)
                self.rebound = 0.0
            base = self._origin(y)
            # A rejected trial step of an explicit method can overflow (u = 100 V): the error control discards it.
            with np.errstate(over="ignore", invalid="ignore"):
                sol = solve_ivp(rhs, (t, t_end), [y[0] - base, *y[1:]], rtol=self.rtol, events=events or None,
                                dense_output=True, **options)
            if sol.status < 0:
                raise RuntimeError(f"{self.label}: failed at t = {t}: {sol.message}")
            t_new = float(sol.t[-1])
            while k_out < len(grid) and grid[k_out] < t_new - self._inside(t_new):
                yk = list(sol.sol(grid[k_out]))   # outputs inside this piece, from its dense output
                yk[0] += base
                rows.append(self._row(float(grid[k_out]), yk, mode, False))
                k_out += 1
            y = list(sol.y[:, -1])
            y[0] += base
            after_event = sol.status == 1
            if after_event:
                fired = next(j for j, te in enumerate(sol.t_events) if len(te))
                self._stall(t_new)
                mode, y = self.TRANSITIONS[events[fired].kind](self, t_new, y, mode, events[fired].kind)
            t = t_new
        return collect(rows, grid)


class VoltageRun(HybridRun):
    """A run of a voltage-driven cam (the input u [V]): DOP853, or Radau with a fast electrical pole (L/R < 1 ms)
    unless ``method`` says, with the energy integrals if ``energy``, stopping at the profile's breakpoints."""

    def __init__(self, model, u: Signal, rtol: float, atol: float, energy: bool, method: str | None) -> None:
        self.u, self.rtol, self.atol, self.energy = u, rtol, atol, energy
        stiff = model.L > 0.0 and model.L / model.R < 1e-3
        self.method = method or ("Radau" if stiff else "DOP853")
        self.breakpoints = sorted(set(model.program.breakpoints()) | {0.0}) + [2.0 * math.pi]
