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


def speed_engaged(program, theta: float, s: float, omega: float, c: float) -> bool:
    """Is the follower at s [m] dragged by the cam at theta moving at omega (not free in the gap)?"""
    if c == 0.0:
        return True
    s_cam, s1, _, _ = program.derivatives(theta)
    gap = s_cam - s
    return abs(gap) >= c * (1.0 - 1e-9) and gap * s1 * omega > 0.0
