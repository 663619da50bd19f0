"""Dormand-Prince 5(4) with error control: the solver ``rk45`` (the default).

Its step, error control, breakpoint and event handling run in the drive kernel
(``kernel/drive_kernel.py``: ``DriveKernel.attempt`` and ``advance``), compiled
where the extension loads; this class carries its settings and its messages.
"""
from __future__ import annotations

from .base import Stepper


class DormandPrince45(Stepper):
    """Adaptive Dormand-Prince 5(4) with error control (rtol, atol); h_max caps its step.

    The smallest step is 1e-12 of the communication step: relative to the step's
    own time scale, never to the absolute time (a master may start at t = 1.7e9 s).
    theta's error is scaled by at most 2 pi: it grows without bound but enters
    the physics mod 2 pi, so its accuracy does not decay over many turns (scaled
    by |theta|, rk45 lost 1e-4 rad within 1 s at 100 V, ~100 turns).
    """

    name = "rk45"
    adaptive = True


def step_floor_message(stepper: Stepper, floor: float, time: float) -> str:
    """The error text when rk45's step fell below its floor [s] at ``time`` [s]."""
    return (f"solver 'rk45' cannot meet rtol = {stepper.rtol:g}, atol = {stepper.atol:g}: its step fell "
            f"below {floor:g} s (1e-12 of the communication step) at t = {time:g} s: loosen rtol/atol, "
            "or check the inputs and parameters for a near-singular drive")
