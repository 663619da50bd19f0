"""`cam-fmu contour`: disc-cam geometry, design checks and export for manufacturing."""

from __future__ import annotations

import argparse
import json
import math
import sys

from ..kinematics.follower_types import FOLLOWER_TYPES
from ._program_options import LIFT_MM_DEFAULT, add_law_options, add_program_options, build_program, rise_law

PROG = "cam-fmu contour"
OPTIONS = {"r_roller": "--roller-radius-mm", "offset": "--offset-mm", "arm_length": "--arm-length-mm",
           "pivot_distance": "--pivot-distance-mm", "lift_angle": "--lift-angle-deg"}


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "contour",
        help="disc cam with any follower: contour, curvature, undercut, pressure angle, export",
        description="Geometry of a disc cam with a translating or oscillating, roller (or knife-edge) or "
                    "flat-faced follower for a cam program or a motion table: pitch curve, cam contour, "
                    "radius of curvature, undercut or cusp, pressure angle, the face a flat follower needs; "
                    "checks with warnings, the smallest base radius that passes them, peak follower motion "
                    "at a cam speed, CSV/DXF export and a figure.  Conventions: docs/cam_design.md.")
    add_law_options(p)
    add_program_options(p, "cam program (defaults: the paper's profile)")
    p.add_argument("--table", metavar="FILE.csv",
                   help="motion table 'angle_deg, lift_mm' (optional header line, periodic over 360 deg) "
                        "instead of the law options; a shape-preserving periodic cubic through the rows")
    g = p.add_argument_group("follower and checks")
    g.add_argument("--follower-type", choices=FOLLOWER_TYPES, default="translating_roller",
                   help="the follower (default translating_roller); an option a type does not use is refused")
    g.add_argument("--roller-radius-mm", type=float, default=None,
                   help="roller radius r_r [mm], 0 <= r_r < r_b (0: a knife edge); roller types need it")
    g.add_argument("--offset-mm", type=float, default=0.0,
                   help="translating roller's offset e [mm], |e| < r_b; e > 0 lowers the pressure angle on the rise")
    g.add_argument("--arm-length-mm", type=float, default=None,
                   help="oscillating: pivot to the roller centre (or the face's reference point) L [mm]")
    g.add_argument("--pivot-distance-mm", type=float, default=None,
                   help="oscillating: cam axis to the arm's pivot d [mm]")
    g.add_argument("--lift-angle-deg", type=float, default=None,
                   help="oscillating: the arm's swing [deg], psi = lift_angle * S (S the program's normalised lift)")
    g.add_argument("--max-pressure-angle-deg", type=float, default=30.0,
                   help="pressure angle limit [deg] (default 30)")
    g.add_argument("--min-radius-mm", type=float, default=None,
                   help="smallest allowed radius of curvature of the contour on convex parts [mm] "
                        "(default: the roller radius)")
    g.add_argument("--groove", action="store_true",
                   help="grooved cam: also check and export the outer wall")
    g.add_argument("--rpm", type=float, default=None, help="cam speed [rpm] for peak follower v, a, j")
    o = p.add_argument_group("output")
    o.add_argument("--json", action="store_true", help="print one JSON object instead of a report")
    o.add_argument("--points", type=int, default=3600, help="points per curve in the exports (default 3600)")
    o.add_argument("--export-csv", metavar="FILE.csv", help="write the contour (x_mm, y_mm, closed)")
    o.add_argument("--export-dxf", metavar="FILE.dxf",
                   help="write closed polylines on layers CONTOUR, PITCH, BASE_CIRCLE (mm)")
    o.add_argument("--plot", metavar="FILE.png", help="write the cam figure")
    return p


def _error(msg: str) -> int:
    print(f"{PROG}: error: {msg}", file=sys.stderr)
    return 2


def _check_follower_options(args, kind: str) -> None:
    """The follower's options: those the type needs given, those it does not use left out, ranges."""
    from ..kinematics.follower_types import DEFAULTS, USES

    uses = USES[kind]
    if not (math.isfinite(args.base_radius_mm) and args.base_radius_mm > 0.0):
        raise ValueError(f"--base-radius-mm must be a number > 0, got {args.base_radius_mm:g}")
    for param, opt in OPTIONS.items():
        value = getattr(args, opt[2:].replace("-", "_"))
        if param not in uses and value != DEFAULTS[param]:
            users = " and ".join(t for t in FOLLOWER_TYPES if param in USES[t])
            raise ValueError(f"{opt} is not used by --follower-type {kind} (only by {users}): leave it out, "
                             f"got {value:g}")
        if param in uses and value is None:
            raise ValueError(f"--follower-type {kind} needs {opt}")
    if kind.startswith("oscillating") and args.lift_mm != LIFT_MM_DEFAULT:
        raise ValueError(f"--lift-mm is not used by --follower-type {kind}: its amplitude is --lift-angle-deg, "
                         f"got --lift-mm {args.lift_mm:g}")
    if args.groove and "r_roller" not in uses:
        raise ValueError(f"--groove is for roller followers, not --follower-type {kind}")
    if "r_roller" in uses:
        if not (math.isfinite(args.roller_radius_mm) and args.roller_radius_mm >= 0.0):
            raise ValueError(f"--roller-radius-mm must be a number >= 0 (0: a knife edge), got "
                             f"{args.roller_radius_mm:g}")
        if args.roller_radius_mm >= args.base_radius_mm:
            raise ValueError(f"--roller-radius-mm {args.roller_radius_mm:g} must be < --base-radius-mm "
                             f"{args.base_radius_mm:g} (r_b is the prime-circle radius, to the roller centre; "
                             f"the cam's base circle r_b - r_r would vanish)")
    if not math.isfinite(args.offset_mm) or abs(args.offset_mm) >= args.base_radius_mm:
        raise ValueError(f"--offset-mm must satisfy |e| < r_b = {args.base_radius_mm:g} mm, got {args.offset_mm:g}")
    for opt in ("--arm-length-mm", "--pivot-distance-mm", "--lift-angle-deg"):
        v = getattr(args, opt[2:].replace("-", "_"))
        if v is not None and not (math.isfinite(v) and v > 0.0):
            raise ValueError(f"{opt} must be a number > 0, got {v:g}")


def _build(args):
    from ..kinematics.design_checks import Limits
    from ..kinematics.follower_checks import refuse_unbuildable
    from ..kinematics.follower_types import make_cam
    from ..kinematics.physical import MAX_RPM

    if args.table is not None:
        from ..kinematics.motion_table import program_from_table_text
        try:
            with open(args.table) as f:
                text = f.read()
        except OSError as exc:
            raise ValueError(f"--table: cannot read {args.table!r}: {exc.strerror}") from None
        program, name = program_from_table_text(text), f"table {args.table}"
    else:
        name, m = rise_law(args)
        program = build_program(args, m)
    kind = args.follower_type
    _check_follower_options(args, kind)
    if args.rpm is not None and not (math.isfinite(args.rpm) and 0.0 < args.rpm <= MAX_RPM):
        raise ValueError(f"--rpm must be a number > 0 and <= {MAX_RPM:g}, got {args.rpm:g}")
    if not (0.0 < args.max_pressure_angle_deg < 90.0):
        raise ValueError(f"--max-pressure-angle-deg must lie in (0, 90), got {args.max_pressure_angle_deg:g}")
    if args.min_radius_mm is not None and not (math.isfinite(args.min_radius_mm) and args.min_radius_mm >= 0.0):
        raise ValueError(f"--min-radius-mm must be a number >= 0, got {args.min_radius_mm:g}")
    if args.points < 16:
        raise ValueError(f"--points must be >= 16, got {args.points}")
    mm = (lambda v: None if v is None else v * 1e-3)  # noqa: E731
    cam = make_cam(program, args.base_radius_mm * 1e-3, kind, r_roller=mm(args.roller_radius_mm),
                   offset=args.offset_mm * 1e-3, arm_length=mm(args.arm_length_mm),
                   pivot_distance=mm(args.pivot_distance_mm),
                   lift_angle=None if args.lift_angle_deg is None else math.radians(args.lift_angle_deg))
    refuse_unbuildable(cam)
    limits = Limits(math.radians(args.max_pressure_angle_deg),
                    None if args.min_radius_mm is None else args.min_radius_mm * 1e-3, args.groove)
    return name, cam, limits


def _text(name, cam, d) -> str:
    f = lambda v: "-" if v is None else f"{v:.6g}"  # noqa: E731
    follower = (f"e = {d['offset_mm']:g} mm" if d["offset_mm"] is not None else
                f"oscillating: L = {d['arm_length_mm']:g} mm, d = {d['pivot_distance_mm']:g} mm, lift angle "
                f"{d['lift_angle_deg']:g} deg")
    lines = [f"cam: {name}; r_b = {d['base_radius_mm']:g} mm (prime circle), r_r = {d['roller_radius_mm']:g} mm, "
             f"{follower}, base circle of the contour {d['base_circle_radius_mm']:.6g} mm",
             f"max pressure angle            {f(d['max_pressure_angle_deg'])} deg at theta = "
             f"{f(d['max_pressure_angle_at_deg'])} deg",
             f"min radius of curvature       {f(d['min_radius_of_curvature_mm'])} mm (contour, convex) at theta = "
             f"{f(d['min_radius_of_curvature_at_deg'])} deg; pitch {f(d['min_pitch_radius_of_curvature_mm'])} mm",
             f"min concave radius (pitch)    {f(d['min_concave_radius_of_curvature_mm'])} mm at theta = "
             f"{f(d['min_concave_radius_of_curvature_at_deg'])} deg",
             f"undercut                      {'yes' if d['undercut'] else 'no'}"
             + "".join(f"  [{a:.5g}, {b:.5g}] deg" for a, b in d["undercut_ranges_deg"]),
             f"smallest r_b meeting the checks {f(d['smallest_base_radius_mm'])} mm"
             + ("" if d.get("smallest_base_radius_error") is None else f" ({d['smallest_base_radius_error']})")]
    if "speed" in d and "peak_arm_rate_rad_s" in d["speed"]:
        sp = d["speed"]
        lines += [f"at {sp['rpm']:g} rpm: peak arm rate {sp['peak_arm_rate_rad_s']:.6g} rad/s, angular acceleration "
                  f"{sp['peak_arm_acceleration_rad_s2']:.6g} rad/s^2"]
    elif "speed" in d:
        sp = d["speed"]
        jerk = "unbounded (acceleration jumps)" if sp["jerk_unbounded"] else \
            f"{sp['peak_jerk_m_s3']:.6g} m/s^3 at theta = {sp['peak_jerk_at_deg']:.6g} deg"
        lines += [f"at {sp['rpm']:g} rpm: peak velocity {sp['peak_velocity_m_s']:.6g} m/s at theta = "
                  f"{sp['peak_velocity_at_deg']:.6g} deg, acceleration {sp['peak_acceleration_m_s2']:.6g} m/s^2 "
                  f"at theta = {sp['peak_acceleration_at_deg']:.6g} deg, jerk {jerk}"]
    lines += [f"warning: {w['message']}" for w in d["warnings"]]
    for key in ("csv", "dxf", "plot"):
        if key in d.get("files", {}):
            lines.append(f"{key} written to {d['files'][key]}")
    return "\n".join(lines)


def _geometry(cam) -> dict:
    """The follower's own parameters in the report (mm, deg)."""
    out = {}
    for name, unit in (("arm_length", "mm"), ("pivot_distance", "mm"), ("lift_angle", "deg")):
        v = getattr(cam, name, None)
        if v is not None:
            out[f"{name}_{unit}"] = math.degrees(v) if unit == "deg" else v * 1e3
    if hasattr(cam, "pivot"):
        out["pivot_mm"] = [cam.pivot[0] * 1e3, cam.pivot[1] * 1e3]
    return out


def _num(v) -> str:
    return "-" if v is None else f"{v:.6g}"


def _flat_text(name, d) -> str:
    where = "from the follower's axis" if d["follower_type"] == "translating_flat" else "from the pivot"
    lo, hi = d["face_extent_mm"]
    return "\n".join([
        f"cam: {name}; {d['follower_type']}, r_b = {d['base_radius_mm']:g} mm (base circle)",
        f"min radius of curvature       {d['min_radius_of_curvature_mm']:.6g} mm (contour) at theta = "
        f"{d['min_radius_of_curvature_at_deg']:.6g} deg",
        f"contact along the face        {lo:.6g} .. {hi:.6g} mm {where}: face width {d['face_width_mm']:.6g} mm",
        "pressure angle                0 deg (the contact normal is the face's own motion)",
        f"smallest r_b meeting the checks {_num(d['smallest_base_radius_mm'])} mm"
        + ("" if d.get("smallest_base_radius_error") is None else f" ({d['smallest_base_radius_error']})")]
        + [f"warning: {w['message']}" for w in d["warnings"]])


def run(args) -> int:
    from ..kinematics.follower_checks import check_follower, smallest_base_radius_for
    from ..kinematics.follower_types import follower_type_of

    try:
        name, cam, limits = _build(args)
    except ValueError as exc:
        return _error(str(exc))
    report = check_follower(cam, limits)
    d = report.to_json_dict()
    kind = follower_type_of(cam)
    d["follower_type"] = kind
    d.update(_geometry(cam))
    try:
        d["smallest_base_radius_mm"] = smallest_base_radius_for(cam, limits, tol=1e-6) * 1e3
        d["smallest_base_radius_error"] = None
    except ValueError as exc:
        d["smallest_base_radius_mm"], d["smallest_base_radius_error"] = None, str(exc)
    if args.rpm is not None:
        from ..kinematics.physical import follower_peaks
        peaks = follower_peaks(cam.program, args.rpm)
        d["speed"] = peaks.to_json_dict() if kind.startswith("translating") else \
            peaks.arm_json_dict(cam.lift_angle / cam.program.lift)
    files = {}
    try:
        if args.export_csv:
            from ..kinematics.export import write_contour_csv
            files["csv"] = str(write_contour_csv(args.export_csv, cam, args.points))
        if args.export_dxf:
            from ..kinematics.export import write_dxf
            files["dxf"] = str(write_dxf(args.export_dxf, cam, args.points, groove=args.groove))
        if args.plot:
            title = f"Disc cam: {name}"
            if kind == "translating_roller":
                from ..plots.cam import plot_cam
                files["plot"] = str(plot_cam(cam, args.plot, report, title=title, groove=args.groove))
            else:
                from ..plots.follower import plot_follower
                files["plot"] = str(plot_follower(cam, args.plot, report, title=f"{title}, {kind}"))
    except OSError as exc:
        return _error(f"cannot write {exc.filename!r}: {exc.strerror}")
    d["files"] = files
    if args.json:
        print(json.dumps(d))
    else:
        print(_text(name, cam, d) if "roller_radius_mm" in d else _flat_text(name, d))
        for key in ("csv", "dxf", "plot"):
            if key in files and "roller_radius_mm" not in d:
                print(f"{key} written to {files[key]}")
    return 0
