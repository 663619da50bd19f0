"""`cam-fmu curve`: characteristic values and plots of a harmonic-trapezoid motion law."""

from __future__ import annotations

import argparse
import json
import math
import sys

from ._program_options import add_law_options, add_program_options, build_program, rise_law


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "curve",
        help="characteristic values and plots of a harmonic-trapezoid motion law",
        description="Characteristic values (Vm, Amp, Amm, Am, Jm, Qm and where they occur) of "
                    "the general harmonic-trapezoid law given by a preset or by T1..T6; "
                    "optionally a plot of the law and of a cam program built on it.")
    add_law_options(p)
    p.add_argument("--list", action="store_true", help="list the presets with their T values and exit")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    p.add_argument("--plot", metavar="FILE.png",
                   help="write S, V, A, J, Q of the law and the cam program's displacement diagram")
    add_program_options(p, "cam program (table and plot; defaults: the paper's profile)")
    return p


def _fmt(x) -> str:
    return "-" if x is None else f"{x:.6g}"


def _table(name: str, c) -> str:
    rows = [("Vm", c.Vm, c.at["Vm"]), ("Amp", c.Amp, c.T[0]), ("Amm", c.Amm, c.T[4]),
            ("Am", c.Am, c.at["Am"])]
    lines = [f"law: {name}", "T = (" + ", ".join(f"{t:.6g}" for t in c.T) + ")",
             f"{'quantity':<9}{'value':>14}{'at T':>12}"]
    lines += [f"{q:<9}{_fmt(v):>14}{_fmt(t):>12}" for q, v, t in rows]
    if c.jerk_unbounded:
        lines.append(f"{'Jm':<9}{'unbounded':>14}{'':>12}   (A jumps at T = "
                     + ", ".join(f"{t:.6g}" for t in c.jumps) + ")")
    else:
        lines.append(f"{'Jm':<9}{_fmt(c.Jm):>14}{_fmt(c.at['Jm']):>12}")
    lines.append(f"{'Qm':<9}{_fmt(c.Qm):>14}{_fmt(c.at['Qm']):>12}")
    return "\n".join(lines)


def run(args) -> int:
    from ..kinematics.characteristics import characteristics
    from ..kinematics.presets import PRESETS

    if args.list:
        width = max(map(len, PRESETS))
        for name, T in PRESETS.items():
            print(f"{name:<{width}}  " + " ".join(f"{t:<8.6g}" for t in T))
        return 0
    for option, value in (("--base-radius-mm", args.base_radius_mm), ("--lift-mm", args.lift_mm)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{option} {value:g}: allowed a number > 0 [mm]")
    try:
        name, m = rise_law(args)
        program = build_program(args, m) if (args.plot or not args.json) else None
    except ValueError as exc:
        print(f"cam-fmu curve: error: {exc}", file=sys.stderr)
        return 2
    c = characteristics(m)
    if args.json:
        print(json.dumps(c.to_json_dict()))
    else:
        print(_table(name, c))
        rb = args.base_radius_mm * 1e-3
        alpha, where = program.max_pressure_angle(rb)
        print(f"\ncam program: lift {program.lift * 1e3:.6g} mm, rise {args.rise_deg:g} deg, "
              f"upper dwell {args.upper_dwell_deg:g} deg, return {args.return_deg:g} deg, "
              f"lower dwell {math.degrees(program.lower_dwell):.6g} deg")
        print(f"max pressure angle (r_b = {args.base_radius_mm:g} mm): "
              f"{math.degrees(alpha):.4g} deg at theta = {math.degrees(where):.6g} deg")
        if alpha > math.radians(30.0):
            print(f"warning: the max pressure angle {math.degrees(alpha):.4g} deg exceeds 30 deg, the usual "
                  f"limit for a translating follower; see `cam-fmu contour` for the full design checks")
    if args.plot:
        from ..plots.curve import plot_law_and_program
        plot_law_and_program(m, program, args.plot, title=name, characteristics=c)
        if not args.json:
            print(f"plot written to {args.plot}")
    return 0
