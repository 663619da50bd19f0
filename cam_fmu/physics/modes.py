"""The named modes and events of the drive's hybrid system (docs/model.md sections 10 and 13.7).

A follower of its own is in one ``Mode``: where the follower is (``Follower``) and what the shaft does (``Shaft``,
with its direction); the rigid drive's mode (formulations/consistent.py, the engine's CamMode) names its state in the
same two. The events that change a mode are the members of ``Event``; each reference run applies them through its
one table of transitions (reference/hybrid.py). Standard library only.
"""
from __future__ import annotations

import enum
from dataclasses import dataclass


class Follower(enum.Enum):
    """Where the follower is. ``sign`` is the flank's: +1 pushes along +X (a spring-closed cam's only flank, a
    groove's lower flank at s_cam - c), -1 a groove's upper flank (s_cam + c), 0 off the flanks."""

    LOWER = "on the lower flank"    # the flank pushing along +X
    UPPER = "on the upper flank"    # a groove's flank at s_cam + c
    FLIGHT = "in flight"            # off the flanks, moving (a rigid drive's follower free in the gap)
    HALTED = "halted"               # off the flanks at v = 0, held by the guide's static friction

    @property
    def sign(self) -> float:
        """+1, -1 on a flank, 0 off them (the ``contact`` output)."""
        return 1.0 if self is Follower.LOWER else (-1.0 if self is Follower.UPPER else 0.0)

    @property
    def on_flank(self) -> bool:
        return self in (Follower.LOWER, Follower.UPPER)

    @staticmethod
    def flank(sign: float) -> "Follower":
        """The follower on the flank of ``sign`` (+1 or -1), off the flanks for 0."""
        return Follower.LOWER if sign > 0.0 else (Follower.UPPER if sign < 0.0 else Follower.FLIGHT)


class Shaft(enum.Enum):
    """What the cam's shaft does: turning (``Mode.direction`` its sense), stopped (the speed drive's imposed speed is
    0), stuck (held by its static friction; a voltage drive's stop leads here or, by the break-away rule, on)."""

    TURNING = "turning"
    STOPPED = "stopped"
    STUCK = "stuck"


class Event(enum.Enum):
    """The events of docs/model.md's tables (10 and 13.7); each run maps those it has to its transitions."""

    LIFT_OFF = "lift-off"              # a flank's force reaches 0 (a rigid drive's backlash: contact loss)
    TOUCH_LOWER = "touch-down +1"      # a gap to the +1 flank closes: an impact
    TOUCH_UPPER = "touch-down -1"      # a gap to the -1 flank closes: an impact
    HALT = "halt"                      # the flying follower's v reaches 0 under guide friction
    STOP = "stop"                      # the shaft's speed reaches 0: stuck, or on by the break-away rule
    BREAK_AWAY = "break-away"          # the stuck shaft's torque overcomes its static friction
    SIDE = "side"                      # the guide's side force changes sign: the friction's branch
    BREAKPOINT = "breakpoint"          # a profile breakpoint: the piece ends there, no transition
    SPEED_STEP = "omega_ref step"      # a jump of the imposed speed (not a root: applied at a restart)


@dataclass
class Mode:
    """The discrete state: the follower's place, the shaft's state and direction (+1, -1; kept while stuck)."""

    follower: Follower = Follower.LOWER
    shaft: Shaft = Shaft.TURNING
    direction: float = 1.0

    @property
    def contact(self) -> float:
        """+1, -1 on a flank, 0 off them."""
        return self.follower.sign

    @property
    def heading(self) -> float:
        """The shaft's direction while it turns, 0 stuck (what the shaft's friction opposes)."""
        return 0.0 if self.shaft is Shaft.STUCK else self.direction
