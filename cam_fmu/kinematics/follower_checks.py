"""Checks of a cam for every follower type: geometry that cannot be built (refused), the flat face's checks
(radius of curvature, the face the contact needs) and the smallest base radius that passes.

- Refused (ValueError naming the parameter and the limit), by `refuse_unbuildable`, before anything is drawn:
  an oscillating roller whose pressure angle reaches 90 deg (delta0 + lift_angle >= 180 deg) or whose cam
  sweeps over the pivot (its contour reaches d from the axis); an oscillating
  flat face whose contact runs off to infinity (psi' >= 1) or behind the pivot (delta0 + lift_angle >= 90
  deg); a flat face whose contour's radius of curvature rho is <= 0 somewhere (a cusp: translating,
  rho = r_b + s + s''); the message gives the smallest base radius that keeps rho > 0.  (The arm that cannot
  reach the cam, the pivot inside the base circle: the cam classes' constructors.)
- Roller types: design_checks.check_design (pressure angle, radius of curvature, undercut).
- Flat faces: `check_flat`: the smallest rho and where, a warning below ``Limits.min_radius_of_curvature``
  (None: 0); the contact's extent along the face (translating: offsets -s' from the axis, width
  max s' - min s'; oscillating: distances from the pivot).  The pressure angle is 0.
- `smallest_base_radius_for`: the smallest r_b [m] that can be built and passes the checks; the translating
  roller's is design_checks.smallest_base_radius, the others' a scan of the range their parameters allow (an
  arm's or an oscillating face's: 64 radii in geometric steps; a translating face's: doubling from 1 um), the
  first passing radius refined by bisection to ``tol``.

Extremes on design_checks' grid (7200 angles and both sides of every breakpoint), refined by golden section.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .design_checks import CheckReport, DesignWarning, Limits, _grid, _refined_max, check_design, smallest_base_radius
from .disc_cam import DiscCam
from .flat_cam import FlatFaceCam, OscillatingFlatCam, TranslatingFlatCam
from .follower_types import follower_type_of, with_base_radius
from .rocker_cam import OscillatingRollerCam

__all__ = ["FlatReport", "check_flat", "check_follower", "refuse_unbuildable", "smallest_base_radius_for",
           "base_radius_range"]

SCAN = 64


@dataclass(frozen=True)
class FlatReport:
    """Results of `check_flat` [m, rad]: the contour's smallest radius of curvature, the contact's extent
    along the face (translating: from the axis, towards +Y; oscillating: from the pivot), warnings."""

    follower_type: str
    base_radius: float
    min_radius_of_curvature: float
    min_radius_at: float
    face_min: float
    face_min_at: float
    face_max: float
    face_max_at: float
    limits: Limits
    warnings: tuple[DesignWarning, ...] = field(default_factory=tuple)

    @property
    def face_width(self) -> float:
        """The face the contact needs [m]: face_max - face_min."""
        return self.face_max - self.face_min

    @property
    def ok(self) -> bool:
        return not self.warnings

    def to_json_dict(self) -> dict:
        deg = math.degrees
        return {"follower_type": self.follower_type, "base_radius_mm": self.base_radius * 1e3,
                "base_circle_radius_mm": self.base_radius * 1e3,
                "max_pressure_angle_deg": 0.0,
                "min_radius_of_curvature_mm": self.min_radius_of_curvature * 1e3,
                "min_radius_of_curvature_at_deg": deg(self.min_radius_at),
                "face_extent_mm": [self.face_min * 1e3, self.face_max * 1e3],
                "face_extent_at_deg": [deg(self.face_min_at), deg(self.face_max_at)],
                "face_width_mm": self.face_width * 1e3,
                "limits": {"min_radius_of_curvature_mm": _flat_min_radius(self.limits) * 1e3},
                "ok": self.ok, "warnings": [w.to_json_dict() for w in self.warnings]}


def _flat_min_radius(limits: Limits) -> float:
    return 0.0 if limits.min_radius_of_curvature is None else limits.min_radius_of_curvature


def _extreme(f, grid: np.ndarray, sign: float = 1.0) -> tuple[float, float]:
    """(value, angle) of the max (sign 1) or min (sign -1) of f, refined."""
    v, t = _refined_max(lambda x: sign * f(x), grid, sign * np.asarray(f(grid)))
    return sign * v, t


def _rho_refusal(cam: FlatFaceCam, rho: float, at: float) -> str:
    what = "r_b + s + s''" if isinstance(cam, TranslatingFlatCam) else "p + d2p/dphi2"
    try:
        r_min = smallest_base_radius_for(cam, Limits())
        hint = f"base_radius must be > {r_min * 1e3:.6g} mm (to 1e-3 mm) with these parameters"
    except ValueError as exc:
        hint = str(exc)
    return (f"base_radius r_b = {cam.base_radius * 1e3:.6g} mm: the flat face's contour has radius of curvature "
            f"{what} = {rho * 1e3:.6g} mm <= 0 at theta = {math.degrees(at):.6g} deg (a cusp, it cannot be made); "
            f"{hint}")


def _unbuildable(cam, explain: bool = True) -> str | None:
    """The refusal's message, or None when the geometry can be built; without `explain` the message of a
    flat face's rho <= 0 is short (it would search the smallest base radius: the search's own predicate)."""
    if isinstance(cam, OscillatingRollerCam):
        top = math.pi - cam.delta0
        if cam.lift_angle >= top:
            return (f"lift_angle = {math.degrees(cam.lift_angle):.6g} deg turns the arm to 180 deg at the pivot "
                    f"(delta0 + lift_angle), where the pressure angle reaches 90 deg: lift_angle must be < "
                    f"180 deg - delta0 = {math.degrees(top):.6g} deg (delta0 = {math.degrees(cam.delta0):.6g} deg, "
                    f"the angle at the pivot between the cam axis and the roller at zero lift)")
        grid = _grid(cam.program)
        reach, at = _extreme(lambda t: np.hypot(*cam.contour(t)), grid)
        if reach >= cam.pivot_distance:
            return (f"pivot_distance d = {cam.pivot_distance * 1e3:.6g} mm: the cam's contour reaches "
                    f"{reach * 1e3:.6g} mm from its axis (at theta = {math.degrees(at):.6g} deg) and would sweep "
                    f"over the pivot; d must be > {reach * 1e3:.6g} mm")
        return None
    if isinstance(cam, DiscCam):
        return None
    grid = _grid(cam.program)
    if isinstance(cam, OscillatingFlatCam):
        top = 0.5 * math.pi - cam.delta0
        if cam.lift_angle >= top:
            return (f"lift_angle = {math.degrees(cam.lift_angle):.6g} deg turns the face past the perpendicular to "
                    f"the cam axis: the contact would run behind the pivot; lift_angle must be < 90 deg - delta0 = "
                    f"{math.degrees(top):.6g} deg (sin delta0 = r_b / d)")
        rate, at = _extreme(lambda t: cam.arm.derivatives(t)[1], grid)
        if rate >= 1.0:
            return (f"lift_angle = {math.degrees(cam.lift_angle):.6g} deg: the arm turns faster than the cam, "
                    f"psi' = {rate:.6g} >= 1 at theta = {math.degrees(at):.6g} deg, and the contact runs off to "
                    f"infinity along the face; lift_angle must be < {math.degrees(cam.lift_angle / rate):.6g} deg")
    rho, at = _extreme(cam.radius_of_curvature, grid, -1.0)
    if rho <= 0.0:
        return _rho_refusal(cam, rho, at) if explain else "rho <= 0"
    return None


def refuse_unbuildable(cam) -> None:
    """ValueError naming the parameter and the limit when `cam`'s geometry cannot be built (module doc)."""
    msg = _unbuildable(cam)
    if msg is not None:
        raise ValueError(msg)


def check_flat(cam: FlatFaceCam, limits: Limits | None = None) -> FlatReport:
    """The flat face's checks (module doc); the cam must be buildable (`refuse_unbuildable`)."""
    limits = limits or Limits()
    grid = _grid(cam.program)
    rho, at = _extreme(cam.radius_of_curvature, grid, -1.0)
    lo, lo_at = _extreme(cam.face_position, grid, -1.0)
    hi, hi_at = _extreme(cam.face_position, grid, 1.0)
    warnings = []
    rho_lim = _flat_min_radius(limits)
    if rho < rho_lim:
        warnings.append(DesignWarning(
            "radius_of_curvature", f"min radius of curvature of the contour {rho * 1e3:.4g} mm at theta = "
            f"{math.degrees(at):.5g} deg is below the limit {rho_lim * 1e3:.4g} mm", (at,)))
    return FlatReport(follower_type_of(cam), cam.base_radius, rho, at, lo, lo_at, hi, hi_at, limits,
                      tuple(warnings))


def check_follower(cam, limits: Limits | None = None) -> CheckReport | FlatReport:
    """check_design for a roller (translating or oscillating), check_flat for a flat face."""
    return check_flat(cam, limits) if isinstance(cam, FlatFaceCam) else check_design(cam, limits)


def base_radius_range(cam) -> tuple[float, float]:
    """The open range of base radii [m] that the cam's other parameters allow (the triangle of an arm, the
    pivot outside the base circle, a flat face's delta0 + lift_angle < 90 deg)."""
    if isinstance(cam, OscillatingRollerCam):
        d, L, r_r = cam.pivot_distance, cam.arm_length, cam.roller_radius
        return max(abs(d - L), r_r), min(d + L, d + r_r)
    if isinstance(cam, OscillatingFlatCam):
        return 0.0, cam.pivot_distance * math.cos(cam.lift_angle)
    return 0.0, 1000.0


def _passes(cam, r_b: float, limits: Limits) -> bool:
    try:
        other = with_base_radius(cam, r_b)
    except ValueError:
        return False
    return _unbuildable(other, explain=False) is None and check_follower(other, limits).ok


def smallest_base_radius_for(cam, limits: Limits | None = None, tol: float = 1e-6) -> float:
    """The smallest base radius [m] (to `tol`) at which `cam`'s follower can be built and passes the checks
    (module doc); ValueError when none in the range its parameters allow."""
    limits = limits or Limits()
    if isinstance(cam, DiscCam):
        return smallest_base_radius(cam.program, cam.roller_radius, cam.offset, limits, tol)[0]
    lo, hi = base_radius_range(cam)
    start = max(lo, 1e-6)
    radii = start * (hi / start) ** (np.arange(1, SCAN + 1) / (SCAN + 1)) if hi < 1000.0 else \
        start * 2.0 ** np.arange(1, 31)
    prev = lo
    for r in radii:
        r = float(r)
        if _passes(cam, r, limits):
            a, b = prev, r
            while b - a > tol:
                mid = 0.5 * (a + b)
                a, b = (a, mid) if _passes(cam, mid, limits) else (mid, b)
            return b
        prev = r
    raise ValueError(f"no base radius in ({lo * 1e3:.6g}, {hi * 1e3:.6g}) mm meets the checks with the "
                     f"{follower_type_of(cam)} follower's other parameters")
