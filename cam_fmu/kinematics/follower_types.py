"""The follower types and their parameters: which type uses which, and the cam geometry of each.

| follower_type        | cam class (module)                   | parameters it uses (SI units)                    |
| -------------------- | ------------------------------------ | ------------------------------------------------ |
| translating_roller   | DiscCam (disc_cam)                   | r_roller [m] (0: knife edge), offset [m]          |
| translating_flat     | TranslatingFlatCam (flat_cam)        | none beyond base_radius                          |
| oscillating_roller   | OscillatingRollerCam (rocker_cam)    | r_roller, arm_length, pivot_distance [m], lift_angle [rad] |
| oscillating_flat     | OscillatingFlatCam (flat_cam)        | arm_length, pivot_distance [m], lift_angle [rad] |

Every type uses base_radius [m] (the cam axis to the follower's reference point at zero lift: the roller
centre, or the face).  A parameter keeps its unit and meaning whatever the type; one that the type does not
use is refused when it is set away from its default (None; offset: 0), naming the type.
"""

from __future__ import annotations

import math

from .disc_cam import DiscCam, Program
from .flat_cam import OscillatingFlatCam, TranslatingFlatCam
from .rocker_cam import OscillatingRollerCam

__all__ = ["FOLLOWER_TYPES", "USES", "UNITS", "make_cam", "follower_type_of", "with_base_radius"]

FOLLOWER_TYPES = ("translating_roller", "translating_flat", "oscillating_roller", "oscillating_flat")
USES = {
    "translating_roller": ("r_roller", "offset"),
    "translating_flat": (),
    "oscillating_roller": ("r_roller", "arm_length", "pivot_distance", "lift_angle"),
    "oscillating_flat": ("arm_length", "pivot_distance", "lift_angle"),
}
UNITS = {"r_roller": "m", "offset": "m", "arm_length": "m", "pivot_distance": "m", "lift_angle": "rad"}
DEFAULTS = {"r_roller": None, "offset": 0.0, "arm_length": None, "pivot_distance": None, "lift_angle": None}
_CLASSES = {DiscCam: "translating_roller", TranslatingFlatCam: "translating_flat",
            OscillatingRollerCam: "oscillating_roller", OscillatingFlatCam: "oscillating_flat"}


def _check_type(follower_type: str) -> str:
    if follower_type not in FOLLOWER_TYPES:
        raise ValueError(f"follower_type must be one of {', '.join(FOLLOWER_TYPES)}, got {follower_type!r}")
    return follower_type


def make_cam(program: Program, base_radius: float, follower_type: str = "translating_roller", *,
             r_roller: float | None = None, offset: float = 0.0, arm_length: float | None = None,
             pivot_distance: float | None = None, lift_angle: float | None = None):
    """The cam of `follower_type` for `program` (SI units).  ValueError naming the parameter: one the type
    needs and is missing, one it does not use and is set away from its default, or one out of its range."""
    uses = USES[_check_type(follower_type)]
    given = {"r_roller": r_roller, "offset": offset, "arm_length": arm_length,
             "pivot_distance": pivot_distance, "lift_angle": lift_angle}
    for name, value in given.items():
        if name not in uses and value != DEFAULTS[name]:
            users = [t for t in FOLLOWER_TYPES if name in USES[t]]
            raise ValueError(f"{name} is not used by follower_type {follower_type!r} (only by "
                             f"{' and '.join(users)}): leave it at its default, got {value!r} {UNITS[name]}")
        if name in uses and value is None:
            raise ValueError(f"follower_type {follower_type!r} needs {name} [{UNITS[name]}]")
    for name in uses:
        if not math.isfinite(float(given[name])):
            raise ValueError(f"{name} must be a finite number [{UNITS[name]}], got {given[name]!r}")
    if follower_type == "translating_roller":
        return DiscCam(program, base_radius, r_roller, offset)
    if follower_type == "translating_flat":
        return TranslatingFlatCam(program, base_radius)
    if follower_type == "oscillating_roller":
        return OscillatingRollerCam(program, base_radius, r_roller, arm_length, pivot_distance, lift_angle)
    return OscillatingFlatCam(program, base_radius, arm_length, pivot_distance, lift_angle)


def follower_type_of(cam) -> str:
    """The follower_type name of a cam object."""
    return _CLASSES[type(cam)]


def with_base_radius(cam, base_radius: float):
    """The same cam and follower with another base radius [m] (ValueError when that cannot be built)."""
    kind = follower_type_of(cam)
    kw = {"r_roller": getattr(cam, "roller_radius", None), "offset": getattr(cam, "offset", 0.0),
          "arm_length": getattr(cam, "arm_length", None), "pivot_distance": getattr(cam, "pivot_distance", None),
          "lift_angle": getattr(cam, "lift_angle", None)}
    return make_cam(cam.program, base_radius, kind, **{k: v for k, v in kw.items() if k in USES[kind]})
