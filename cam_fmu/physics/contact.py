"""Backlash between cam and follower (paper eqs. 6-8): the play operator.

The follower holds its position inside the gap of half-width c [m] and is
dragged at s_cam -/+ c (docs/model.md section 6). ``math`` only.
"""
from __future__ import annotations

import math

TWO_PI = 2.0 * math.pi


def play(s_cam: float, s_prev: float, c: float) -> float:
    """Backlash play operator (continuous form): follower position [m]."""
    if s_cam > s_prev + c:
        return s_cam - c
    if s_cam < s_prev - c:
        return s_cam + c
    return s_prev


def follower_along(program, s: float, start: float, end: float, c: float) -> float:
    """Follower position [m] after the cam turns from start to end [rad] with play c [m].

    The play operator sees every breakpoint passed on the way, where the
    extrema of s_cam lie, not only the end point (speed drive). Its cost does
    not grow with the angle swept: once the cam has turned a whole turn, s_cam
    has passed its maximum and its minimum, which wipes out the follower's
    earlier history, so the follower's position is periodic in theta from then
    on and whole turns after the first change nothing (tested against turning
    them one by one).
    """
    if c == 0.0:
        return program.derivatives(end)[0]
    turns = math.floor(abs(end - start) / TWO_PI)
    if turns >= 2:
        direction = 1.0 if end > start else -1.0
        s = _play_along(program, s, start, start + direction * TWO_PI, c)
        start = start + direction * TWO_PI * turns
    return _play_along(program, s, start, end, c)


def _play_along(program, s: float, start: float, end: float, c: float) -> float:
    for angle in program.breakpoints_passed(start, end):
        s = play(program.derivatives(angle)[0], s, c)
    return play(program.derivatives(end)[0], s, c)


def speed_engaged(program, theta: float, s: float, omega: float, c: float, omega_dot: float = 0.0,
                  F_gx: float = 0.0) -> bool:
    """Is the follower at s [m] carried by the cam at theta moving at omega (not free in the gap)?

    Moving: where it sits at an edge of the gap that the cam pushes forward. At rest (omega = 0):
    under a force along the stroke (gravity, F_gx [N]) it lies on the cam at the edge that force
    pushes it to (``rest_position``), so the cam carries it; without one, where the cam's
    acceleration omega_dot [rad/s2] pushes it. So the holding torque at rest does not vanish
    with a clearance, and results converge to those of c = 0 as c -> 0.
    """
    if c == 0.0:
        return True
    s_cam, s1, _, _ = program.derivatives(theta)
    if omega == 0.0 and F_gx != 0.0:
        return True
    gap = s_cam - s
    return abs(gap) >= c * (1.0 - 1e-9) and gap * s1 * (omega if omega != 0.0 else omega_dot) > 0.0


def rest_position(s_cam: float, c: float, F_gx: float, s: float) -> float:
    """Where the follower lies at rest [m]: on the cam at the edge of the gap that the force along the
    stroke F_gx [N] pushes it to (s_cam + c for F_gx > 0), or where it is without such a force."""
    if c == 0.0 or F_gx == 0.0:
        return s
    return s_cam + c if F_gx > 0.0 else s_cam - c
