"""Locating zeros of event functions inside one step (``math`` only)."""
from __future__ import annotations

from typing import Callable

from .base import Vector

EVENT_ITERATIONS = 60


def locate(g: Callable[[Vector], float], advance: Callable[[float], Vector], g_lo: float, g_hi: float,
           dt: float, y_hi: Vector) -> tuple[float, list[float]]:
    """Illinois false position for the zero of g(advance(tau)) in (0, dt] [s].

    Returns the time and the state just past the zero (g <= 0 there), so the
    transition is applied on the far side of the event.
    """
    lo, hi = 0.0, dt
    side = 0
    for _ in range(EVENT_ITERATIONS):
        if hi - lo <= 1e-13 * max(dt, 1e-300) + 1e-15:
            break
        tau = hi - g_hi * (hi - lo) / (g_hi - g_lo) if g_hi != g_lo else 0.5 * (lo + hi)
        if not lo < tau < hi:
            tau = 0.5 * (lo + hi)
        y_tau = advance(tau)
        g_tau = g(y_tau)
        if g_tau <= 0.0:
            hi, g_hi, y_hi = tau, g_tau, y_tau
            if side == -1:
                g_lo *= 0.5
            side = -1
        else:
            lo, g_lo = tau, g_tau
            if side == 1:
                g_hi *= 0.5
            side = 1
    return hi, list(y_hi)
