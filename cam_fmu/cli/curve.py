"""`cam-fmu curve`: characteristic values and plots of a harmonic-trapezoid motion law."""

from __future__ import annotations

import argparse
import json
import math
import sys


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "curve",
        help="characteristic values and plots of a harmonic-trapezoid motion law",
        description="Characteristic values (Vm, Amp, Amm, Am, Jm, Qm and where they occur) of "
                    "the general harmonic-trapezoid law given by a preset or by T1..T6; "
                    "optionally a plot of the law and of a cam program built on it.")
    law = p.add_mutually_exclusive_group()
    law.add_argument("--preset", metavar="NAME", help="preset law (see --list); default: paper")
    law.add_argument("--T", nargs=6, type=float, metavar=("T1", "T2", "T3", "T4", "T5", "T6"),
                     help="split points 0 <= T1 <= ... <= T6 <= 1")
    p.add_argument("--list", action="store_true", help="list the presets with their T values and exit")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    p.add_argument("--plot", metavar="FILE.png",
                   help="write S, V, A, J, Q of the law and the cam program's displacement diagram")
    g = p.add_argument_group("cam program (table and plot; defaults: the paper's profile)")
    ret = g.add_mutually_exclusive_group()
    ret.add_argument("--return-preset", metavar="NAME", help="return law preset (default: the rise law)")
    ret.add_argument("--return-T", nargs=6, type=float, metavar=("T1", "T2", "T3", "T4", "T5", "T6"),
                     help="return law split points")
    g.add_argument("--lift-mm", type=float, default=1.5 * math.pi * 35.0,
                   help="lift h [mm] (default 3*pi*35/2 = 164.93, the paper's)")
    g.add_argument("--rise-deg", type=float, default=180.0, help="rise angle [deg] (default 180)")
    g.add_argument("--upper-dwell-deg", type=float, default=0.0, help="upper dwell [deg] (default 0)")
    g.add_argument("--return-deg", type=float, default=180.0, help="return angle [deg] (default 180)")
    g.add_argument("--lower-dwell-deg", type=float, default=None,
                   help="lower dwell [deg] (default: what is left of 360)")
    g.add_argument("--base-radius-mm", type=float, default=100.0,
                   help="base-circle radius r_b [mm] for the pressure angle (default 100)")
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


def _program(args, rise_law):
    from ..kinematics.cam_program import CamProgram
    from ..kinematics.presets import law

    if args.return_T is not None:
        ret = law(args.return_T)
    elif args.return_preset is not None:
        ret = law(args.return_preset)
    else:
        ret = rise_law
    lower = args.lower_dwell_deg
    if lower is None:
        used = args.rise_deg + args.upper_dwell_deg + args.return_deg
        if used > 360.0 + 1e-9:
            raise ValueError(f"rise + upper dwell + return = {used:g} deg exceeds 2*pi (360 deg)")
        lower = max(0.0, 360.0 - used)
    return CamProgram(rise_law, ret, lift=args.lift_mm * 1e-3,
                      rise_angle=math.radians(args.rise_deg), upper_dwell=math.radians(args.upper_dwell_deg),
                      return_angle=math.radians(args.return_deg), lower_dwell=math.radians(lower))


def run(args) -> int:
    from ..kinematics.characteristics import characteristics
    from ..kinematics.presets import PRESETS, law

    if args.list:
        width = max(map(len, PRESETS))
        for name, T in PRESETS.items():
            print(f"{name:<{width}}  " + " ".join(f"{t:<8.6g}" for t in T))
        return 0
    for option, value in (("--base-radius-mm", args.base_radius_mm), ("--lift-mm", args.lift_mm)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{option} {value:g}: allowed a number > 0 [mm]")
    try:
        if args.T is not None:
            name, m = "T = " + " ".join(f"{t:g}" for t in args.T), law(args.T)
        else:
            name = args.preset or "paper"
            m = law(name)
        program = _program(args, m) if (args.plot or not args.json) else None
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
    if args.plot:
        from ..plots.curve import plot_law_and_program
        plot_law_and_program(m, program, args.plot, title=name, characteristics=c)
        if not args.json:
            print(f"plot written to {args.plot}")
    return 0
