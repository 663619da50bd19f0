"""Design checks of a disc cam: pressure angle, radius of curvature, undercut;
warnings that say where; the smallest prime-circle radius that passes.

Checks (limits in `Limits`, defaults in brackets):

- pressure angle: max |alpha| over the cycle <= max_pressure_angle [30 deg,
  the usual limit for a translating follower];
- radius of curvature: on the convex parts of the inner contour (the plate
  cam's surface, where the roller stress is highest) rho_inner = rho_p - r_r
  >= min_radius_of_curvature [default: r_r, i.e. rho_p >= 2 r_r, the rule of
  thumb of keeping the pitch curve's radius at two roller radii or more];
- undercut: the inner contour must not reverse, rho_p outside (0, r_r); with
  ``groove=True`` also the outer wall, rho_p outside (-r_r, 0).

Extremes are found on a grid of 7200 angles plus both sides of every
breakpoint, then refined by golden-section search on the exact expressions
(angles to ~1e-9 rad); undercut ranges by bisection on rho_p = r_r.
Units: m and rad (the report's ``to_json_dict`` converts to mm and deg).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .disc_cam import DiscCam, Program
from .motion_law import golden_max

__all__ = ["Limits", "CheckReport", "DesignWarning", "PressureAngleAdvice", "check_design", "pressure_angle_advice",
           "smallest_base_radius"]

TWO_PI = 2.0 * math.pi
GRID = 7200


@dataclass(frozen=True)
class Limits:
    """max_pressure_angle [rad]; min_radius_of_curvature [m] of the inner contour
    on convex parts (None: the roller radius); groove: check the outer wall too."""

    max_pressure_angle: float = math.radians(30.0)
    min_radius_of_curvature: float | None = None
    groove: bool = False

    def __post_init__(self):
        a = self.max_pressure_angle
        if not (math.isfinite(a) and 0.0 < a < 0.5 * math.pi):
            raise ValueError(f"max_pressure_angle must lie in (0, 90) deg, got {math.degrees(a)!r} deg")
        r = self.min_radius_of_curvature
        if r is not None and not (math.isfinite(r) and r >= 0.0):
            raise ValueError(f"min_radius_of_curvature must be a finite number >= 0 mm, got {r * 1e3!r} mm")


@dataclass(frozen=True)
class DesignWarning:
    check: str                      # "pressure_angle", "radius_of_curvature", "undercut", "groove_undercut"
    message: str
    at: tuple[float, ...] = ()      # angles [rad] where it occurs (range ends for undercut)
    advice: "PressureAngleAdvice | None" = None  # the pressure angle's: what lowers it, computed

    def to_json_dict(self) -> dict:
        out = {"check": self.check, "message": self.message, "at_deg": [math.degrees(a) for a in self.at]}
        if self.advice is not None:
            out["advice"] = self.advice.to_json_dict()
        return out


@dataclass(frozen=True)
class PressureAngleAdvice:
    """What lowers a cam's max pressure angle, each change computed on the cam (m, rad): the in-line follower's
    (e = 0), the offset that gives the least (|e| < r_b) and that least, and the smallest prime-circle radius
    at which the max pressure angle meets the limit at the cam's own offset."""

    inline: float                   # max |alpha| at e = 0, the same r_b [rad]
    best_offset: float              # e [m] of the least max |alpha| at this r_b
    best: float                     # that least [rad]
    base_radius: float              # smallest r_b [m] with max |alpha| <= the limit at the cam's offset

    def to_json_dict(self) -> dict:
        return {"inline_max_pressure_angle_deg": math.degrees(self.inline),
                "best_offset_mm": self.best_offset * 1e3,
                "best_offset_max_pressure_angle_deg": math.degrees(self.best),
                "base_radius_mm": self.base_radius * 1e3}


@dataclass(frozen=True)
class CheckReport:
    """Results of `check_design`: values [m, rad], where they occur, warnings."""

    base_radius: float
    roller_radius: float
    offset: float | None                 # None: an oscillating follower (no offset)
    max_pressure_angle: float
    max_pressure_angle_at: float
    min_pitch_radius: float              # smallest rho_p on convex parts
    min_radius_of_curvature: float       # inner contour there: min_pitch_radius - r_r (< 0: undercut)
    min_radius_at: float
    min_concave_radius: float | None     # smallest |rho_p| on concave parts (None: nowhere concave)
    min_concave_radius_at: float | None
    undercut: bool
    undercut_ranges: tuple[tuple[float, float], ...]
    groove_undercut: bool
    groove_undercut_ranges: tuple[tuple[float, float], ...]
    limits: Limits
    warnings: tuple[DesignWarning, ...] = field(default_factory=tuple)

    @property
    def ok(self) -> bool:
        return not self.warnings

    def to_json_dict(self) -> dict:
        deg, mm = math.degrees, (lambda v: None if v is None else v * 1e3)
        lim = self.limits
        return {
            "base_radius_mm": mm(self.base_radius),
            "roller_radius_mm": mm(self.roller_radius),
            "offset_mm": mm(self.offset),
            "base_circle_radius_mm": mm(self.base_radius - self.roller_radius),
            "max_pressure_angle_deg": deg(self.max_pressure_angle),
            "max_pressure_angle_at_deg": deg(self.max_pressure_angle_at),
            "min_radius_of_curvature_mm": mm(self.min_radius_of_curvature),
            "min_radius_of_curvature_at_deg": deg(self.min_radius_at),
            "min_pitch_radius_of_curvature_mm": mm(self.min_pitch_radius),
            "min_concave_radius_of_curvature_mm": mm(self.min_concave_radius),
            "min_concave_radius_of_curvature_at_deg":
                None if self.min_concave_radius_at is None else deg(self.min_concave_radius_at),
            "undercut": self.undercut,
            "undercut_ranges_deg": [[deg(a), deg(b)] for a, b in self.undercut_ranges],
            "groove_undercut": self.groove_undercut,
            "groove_undercut_ranges_deg": [[deg(a), deg(b)] for a, b in self.groove_undercut_ranges],
            "limits": {"max_pressure_angle_deg": round(deg(lim.max_pressure_angle), 9),
                       "min_radius_of_curvature_mm": mm(_min_radius(lim, self.roller_radius)),
                       "groove": lim.groove},
            "ok": self.ok,
            "warnings": [w.to_json_dict() for w in self.warnings],
        }


def _min_radius(limits: Limits, roller_radius: float) -> float:
    r = limits.min_radius_of_curvature
    return roller_radius if r is None else r


def _grid(program: Program) -> np.ndarray:
    bp = np.array(program.breakpoints(), dtype=float)
    extra = np.concatenate([bp, bp + 1e-9, bp - 1e-9]) % TWO_PI
    return np.unique(np.concatenate([np.linspace(0.0, TWO_PI, GRID, endpoint=False), extra]))


def _refined_max(f, grid: np.ndarray, values: np.ndarray) -> tuple[float, float]:
    """(max value, angle) of f: grid maximum, then golden search between its neighbours."""
    k = int(np.argmax(values))
    best_v, best_t = float(values[k]), float(grid[k])
    n = len(grid)
    a = float(grid[k - 1]) if k > 0 else float(grid[-1]) - TWO_PI
    b = float(grid[k + 1]) if k < n - 1 else float(grid[0]) + TWO_PI
    t, v = golden_max(f, a, b, 1e-10)
    if v > best_v:
        best_v, best_t = v, t % TWO_PI
    return best_v, best_t


def _ranges(grid: np.ndarray, mask: np.ndarray, g) -> tuple[tuple[float, float], ...]:
    """Angle ranges [rad] where mask holds, ends refined by bisection on the sign
    of g(theta) (g > 0 inside).  Angles reduced to [0, 2 pi): a range across
    0 deg comes out as (start, end) with start > end."""
    if not mask.any():
        return ()
    if mask.all():
        return ((0.0, TWO_PI),)
    n = len(grid)
    k0 = int(np.argmin(mask))                        # an angle outside every range
    order = (np.arange(n) + k0) % n
    th = grid[order] + np.where(order < k0, TWO_PI, 0.0)   # unwrapped, increasing
    m = mask[order]

    def edge(out: float, inside: float) -> float:
        for _ in range(60):
            mid = 0.5 * (out + inside)
            if g(mid) > 0.0:
                inside = mid
            else:
                out = mid
        return 0.5 * (out + inside)

    result = []
    k = 0
    while k < n:
        if not m[k]:
            k += 1
            continue
        j = k
        while j + 1 < n and m[j + 1]:
            j += 1
        end_out = th[j + 1] if j + 1 < n else th[0] + TWO_PI
        result.append((edge(float(th[k - 1]), float(th[k])) % TWO_PI,
                       edge(float(end_out), float(th[j])) % TWO_PI))
        k = j + 1
    return tuple(result)


def check_design(cam: DiscCam, limits: Limits | None = None) -> CheckReport:
    """Run the checks on `cam` (a DiscCam, or any roller follower's cam with its interface: an
    OscillatingRollerCam) and return the values, where they occur and the warnings."""
    limits = limits or Limits()
    r_r = cam.roller_radius
    grid = _grid(cam.program)

    alpha = np.abs(cam.pressure_angle(grid))
    a_max, a_at = _refined_max(lambda t: abs(cam.pressure_angle(t)), grid, alpha)

    kappa = cam.pitch_curvature(grid)
    k_max, k_at = _refined_max(cam.pitch_curvature, grid, kappa)       # most convex point
    rho_min = 1.0 / k_max                                               # k_max > 0: a closed curve bulges somewhere
    kc_max, kc_at = _refined_max(lambda t: -cam.pitch_curvature(t), grid, -kappa)
    concave = kc_max > 0.0
    inv_r = 1.0 / r_r if r_r > 0.0 else math.inf     # a knife edge (r_r = 0) cannot undercut
    under = _ranges(grid, kappa > inv_r, lambda t: cam.pitch_curvature(t) - inv_r)
    if limits.groove:
        groove = _ranges(grid, kappa < -inv_r, lambda t: -cam.pitch_curvature(t) - inv_r)
    else:
        groove = ()

    warnings = []
    if a_max > limits.max_pressure_angle:
        if isinstance(cam, DiscCam):
            advice = pressure_angle_advice(cam, limits.max_pressure_angle)
            text = _pressure_angle_text(cam, a_max, a_at, advice, limits.max_pressure_angle)
        else:   # an arm: a larger base radius or another pivot (follower_checks.smallest_base_radius_for)
            advice, text = None, "raise the base radius or move the pivot"
        warnings.append(DesignWarning(
            "pressure_angle",
            f"max pressure angle {math.degrees(a_max):.4g} deg at theta = {math.degrees(a_at):.5g} deg "
            f"exceeds the limit {math.degrees(limits.max_pressure_angle):.4g} deg ({text})", (a_at,), advice))
    rho_c = rho_min - r_r
    rho_lim = _min_radius(limits, r_r)
    if under:
        spans = ", ".join(f"{math.degrees(a):.5g}..{math.degrees(b):.5g} deg" for a, b in under)
        warnings.append(DesignWarning(
            "undercut",
            f"undercut: the contour reverses where the pitch curve's radius of curvature is below "
            f"the roller radius {r_r * 1e3:.4g} mm (smallest {rho_min * 1e3:.4g} mm at theta = "
            f"{math.degrees(k_at):.5g} deg), at theta = {spans}",
            tuple(x for ab in under for x in ab)))
    elif rho_c < rho_lim:
        warnings.append(DesignWarning(
            "radius_of_curvature",
            f"min radius of curvature of the contour {rho_c * 1e3:.4g} mm at theta = "
            f"{math.degrees(k_at):.5g} deg is below the limit {rho_lim * 1e3:.4g} mm", (k_at,)))
    if groove:
        spans = ", ".join(f"{math.degrees(a):.5g}..{math.degrees(b):.5g} deg" for a, b in groove)
        warnings.append(DesignWarning(
            "groove_undercut",
            f"groove undercut: the outer wall reverses where the concave pitch curve's radius is "
            f"below the roller radius {r_r * 1e3:.4g} mm, at theta = {spans}",
            tuple(x for ab in groove for x in ab)))
    return CheckReport(
        base_radius=cam.base_radius, roller_radius=r_r, offset=getattr(cam, "offset", None),
        max_pressure_angle=a_max, max_pressure_angle_at=a_at,
        min_pitch_radius=rho_min, min_radius_of_curvature=rho_c, min_radius_at=k_at,
        min_concave_radius=(1.0 / kc_max) if concave else None,
        min_concave_radius_at=kc_at if concave else None,
        undercut=bool(under), undercut_ranges=under,
        groove_undercut=bool(groove), groove_undercut_ranges=groove,
        limits=limits, warnings=tuple(warnings))


def _max_pressure_angle(s: np.ndarray, s1: np.ndarray, r_b: float, e: float) -> float:
    """max |alpha| [rad] on the grid's s, s' of a prime circle r_b [m] and offset e [m]."""
    return float(np.max(np.abs(np.arctan2(s1 - e, math.sqrt(r_b * r_b - e * e) + s))))


def pressure_angle_advice(cam: DiscCam, limit: float) -> PressureAngleAdvice:
    """What lowers the max pressure angle of ``cam`` (module of the offset's effect: tan alpha = (s' - e) /
    (sqrt(r_b^2 - e^2) + s), an offset e > 0 lowers it on the rise, s' > 0, and raises it on the return):
    the in-line follower's, the best offset at this prime circle (a scan of |e| < r_b refined by golden section
    to 1e-6 r_b) and the smallest prime circle meeting ``limit`` [rad] at the cam's offset (bisection to 1e-6
    m; the pressure angle falls as r_b grows). Values refined as ``check_design`` refines them."""
    grid = _grid(cam.program)
    s, s1, _, _ = cam._derivs(grid)
    r_b, e, r_r = cam.base_radius, cam.offset, cam.roller_radius

    def exact(r: float, off: float) -> float:
        other = DiscCam(cam.program, r, r_r, off)
        return _refined_max(lambda t: abs(other.pressure_angle(t)), grid, np.abs(other.pressure_angle(grid)))[0]

    span = 0.98 * r_b
    scan = np.linspace(-span, span, 197)
    k = int(np.argmin([_max_pressure_angle(s, s1, r_b, x) for x in scan]))
    lo, hi = scan[max(k - 1, 0)], scan[min(k + 1, len(scan) - 1)]
    best_offset = golden_max(lambda x: -_max_pressure_angle(s, s1, r_b, x), float(lo), float(hi), 1e-6 * r_b)[0]
    if abs(best_offset) < 1e-6 * r_b:  # within the search's resolution of in line (a symmetric program)
        best_offset = 0.0
    lo, hi = max(r_r, abs(e)) * (1.0 + 1e-9) + 1e-12, r_b
    while _max_pressure_angle(s, s1, hi, e) > limit:
        lo, hi = hi, 2.0 * hi
        if hi > 1000.0:
            break
    while hi - lo > 1e-6:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _max_pressure_angle(s, s1, mid, e) <= limit else (mid, hi)
    while exact(hi, e) > limit and hi < 1000.0:  # the refined maximum, a hair above the grid's
        hi *= 1.0 + 1e-6
    return PressureAngleAdvice(inline=exact(r_b, 0.0), best_offset=best_offset, best=exact(r_b, best_offset),
                               base_radius=hi)


def _pressure_angle_text(cam: DiscCam, a_max: float, a_at: float, advice: PressureAngleAdvice, limit: float) -> str:
    """The warning's advice in words: the offset's part in the excess, what to change, the numbers computed."""
    deg, e, best = math.degrees, cam.offset, advice.best_offset
    side = "rise" if cam._derivs(a_at)[1] > 0.0 else "return"
    parts = []
    if e != 0.0 and advice.inline < a_max:
        parts.append(f"the offset e = {e * 1e3:.4g} mm raises it on the {side}")
    if advice.best < a_max * (1.0 - 1e-6):
        meets = "meets the limit" if advice.best <= limit else "still above the limit"
        if best == 0.0:
            parts.append(f"remove the offset: in line, e = 0, it is {deg(advice.best):.4g} deg, the least ({meets})")
        else:
            verb = ("offset the follower by" if e == 0.0 else "reverse the offset to" if best * e < 0.0
                    else "reduce the offset to" if abs(best) < abs(e) else "increase the offset to")
            parts.append(f"{verb} e = {best * 1e3:.4g} mm: {deg(advice.best):.4g} deg, the least ({meets})")
    parts.append(f"{'or ' if parts else ''}raise the base radius: r_b = {advice.base_radius * 1e3:.5g} mm meets the "
                 f"limit at e = {e * 1e3:.4g} mm")
    return "; ".join(parts)


def smallest_base_radius(program: Program, roller_radius: float, offset: float = 0.0,
                         limits: Limits | None = None, tol: float = 1e-6) -> tuple[float, CheckReport]:
    """Smallest prime-circle radius r_b [m] (to `tol`) at which `check_design`
    gives no warning, and its report.  Bisection: assumes that a design which
    passes keeps passing at a larger r_b (true of the pressure angle; of the
    curvature for the usual laws).  Raises ValueError if none up to 1000 m."""
    limits = limits or Limits()

    def report(r_b):
        return check_design(DiscCam(program, r_b, roller_radius, offset), limits)

    lo = max(roller_radius, abs(offset)) * (1.0 + 1e-9) + 1e-12
    hi = 2.0 * lo
    rep = report(hi)
    while not rep.ok:
        lo, hi = hi, 2.0 * hi
        if hi > 1000.0:
            raise ValueError("no base radius up to 1000 m meets the limits "
                             f"({', '.join(w.check for w in rep.warnings)})")
        rep = report(hi)
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        r = report(mid)
        if r.ok:
            hi, rep = mid, r
        else:
            lo = mid
    return hi, rep
