"""The follower's kind in the drive: translating or oscillating, roller or flat face (docs/model.md 16).

The kind is the drive's parameters follower_type and an arm's fields (physics/parameters.py FOLLOWER_KIND_PARAMETERS,
``FollowerKind.from_parameters``; the C engine runs it without friction, docs/model.md 16.1), or for the reference
this description, ``simulate_reference(..., follower=FollowerKind(...))``. ``translating_roller`` (the default) is
today's follower, bit for bit. An oscillating follower turns about its pivot by psi(theta) = lift_angle * S(theta)
(S = s / h the law's normalised lift); its own fields:

    arm_length      L [m]      pivot to the roller centre (or to the face's reference point); the follower's mass
                               m and weight G sit there
    pivot_distance  d [m]      cam axis to the pivot
    lift_angle      [rad]      the arm's swing, 0 < lift_angle < pi
    J_arm           [kg m2]    the arm about its pivot, without m
    m_arm           [kg]       the arm's own mass (its weight m_arm g_n acts at r_cm_arm)
    r_cm_arm        [m]        pivot to the arm's own centre of mass, along the arm
    psi_0           [rad]      the arm's angle above the horizontal (of the cam's plane) at psi = 0

A field that the type does not use is refused when it is set away from its default, naming the type (the rule of
kinematics/follower_types.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, Mapping

from ..kinematics.follower_types import FOLLOWER_TYPES
from .parameters import ParameterError

__all__ = ["FollowerKind", "ARM_FIELDS", "RANGES"]

# The fields only an oscillating follower uses, and the allowed range of each [low, high] (SI units).
ARM_FIELDS = ("arm_length", "pivot_distance", "lift_angle", "J_arm", "m_arm", "r_cm_arm", "psi_0")
RANGES = {"arm_length": (0.0, 10.0, "m"), "pivot_distance": (0.0, 20.0, "m"), "lift_angle": (0.0, math.pi, "rad"),
          "J_arm": (0.0, 1e3, "kg.m2"), "m_arm": (0.0, 1e4, "kg"), "r_cm_arm": (-10.0, 10.0, "m"),
          "psi_0": (-math.pi, math.pi, "rad")}
OPEN_BELOW = ("arm_length", "pivot_distance", "lift_angle")  # > low, not >= low
NEEDED = ("arm_length", "pivot_distance", "lift_angle")  # an oscillating follower has no default for these


@dataclass(frozen=True)
class FollowerKind:
    """The follower's type and an arm's data (module doc; SI units)."""

    follower_type: str = "translating_roller"
    arm_length: float | None = None
    pivot_distance: float | None = None
    lift_angle: float | None = None
    J_arm: float = 0.0
    m_arm: float = 0.0
    r_cm_arm: float = 0.0
    psi_0: float = 0.0

    def __post_init__(self) -> None:
        if self.follower_type not in FOLLOWER_TYPES:
            raise ParameterError(f"follower parameter 'follower_type' = {self.follower_type!r}: allowed one of "
                                 f"{', '.join(repr(t) for t in FOLLOWER_TYPES)}")
        defaults = {f.name: f.default for f in fields(self)}
        for name in ARM_FIELDS:
            value = getattr(self, name)
            if not self.oscillating:
                if value != defaults[name]:
                    raise ParameterError(f"follower parameter '{name}' = {value!r} is not used by follower_type "
                                         f"{self.follower_type!r} (only by the oscillating types): leave it at "
                                         f"its default {defaults[name]!r}")
                continue
            low, high, unit = RANGES[name]
            if value is None:
                raise ParameterError(f"follower_type {self.follower_type!r} needs follower parameter '{name}' "
                                     f"[{unit}]: allowed {'(' if name in OPEN_BELOW else '['}{low:g}, {high:g}]")
            above = value > low if name in OPEN_BELOW else value >= low
            if not (isinstance(value, (int, float)) and math.isfinite(value) and above and value <= high):
                left = "(" if name in OPEN_BELOW else "["
                raise ParameterError(f"follower parameter '{name}' = {value!r} {unit}: allowed "
                                     f"{left}{low:g}, {high:g}] {unit}")
        if self.oscillating and self.lift_angle >= math.pi:
            raise ParameterError(f"follower parameter 'lift_angle' = {self.lift_angle!r} rad: allowed (0, pi) rad")

    @classmethod
    def from_parameters(cls, p: Mapping[str, Any]) -> "FollowerKind":
        """The kind the resolved drive parameters ``p`` name (physics/parameters.py FOLLOWER_KIND_PARAMETERS; an
        arm's three needed fields are 0 there when not set)."""
        if not str(p["follower_type"]).startswith("oscillating"):
            return cls(p["follower_type"])
        return cls(p["follower_type"], **{name: p[name] for name in ARM_FIELDS})

    @property
    def oscillating(self) -> bool:
        """Does the follower turn about a pivot (an arm)?"""
        return self.follower_type.startswith("oscillating")

    @property
    def flat(self) -> bool:
        """Does a flat face touch the cam (it slides on it)?"""
        return self.follower_type.endswith("flat")

    @property
    def default(self) -> bool:
        """Is this today's follower, the translating roller (the drive bit for bit)?"""
        return self.follower_type == "translating_roller"
