"""Options shared by subcommands that take a motion law and a cam program
(`curve`, `contour`): building them on a parser and turning them into objects.
Not a subcommand (not in SUBCOMMANDS); light imports only."""

from __future__ import annotations

import argparse
import math

LIFT_MM_DEFAULT = 1.5 * math.pi * 35.0      # the paper's lift [mm]


def add_law_options(p: argparse.ArgumentParser) -> None:
    """--preset NAME | --T T1..T6 (the rise law)."""
    law = p.add_mutually_exclusive_group()
    law.add_argument("--preset", metavar="NAME", help="preset law (see `cam-fmu curve --list`); default: paper")
    law.add_argument("--T", nargs=6, type=float, metavar=("T1", "T2", "T3", "T4", "T5", "T6"),
                     help="split points 0 <= T1 <= ... <= T6 <= 1")


def add_program_options(p: argparse.ArgumentParser, title: str) -> argparse._ArgumentGroup:
    """The cam program group: return law, lift, phase angles, base radius."""
    g = p.add_argument_group(title)
    ret = g.add_mutually_exclusive_group()
    ret.add_argument("--return-preset", metavar="NAME", help="return law preset (default: the rise law)")
    ret.add_argument("--return-T", nargs=6, type=float, metavar=("T1", "T2", "T3", "T4", "T5", "T6"),
                     help="return law split points")
    g.add_argument("--lift-mm", type=float, default=LIFT_MM_DEFAULT,
                   help="lift h [mm] (default 3*pi*35/2 = 164.93, the paper's)")
    g.add_argument("--rise-deg", type=float, default=180.0, help="rise angle [deg] (default 180)")
    g.add_argument("--upper-dwell-deg", type=float, default=0.0, help="upper dwell [deg] (default 0)")
    g.add_argument("--return-deg", type=float, default=180.0, help="return angle [deg] (default 180)")
    g.add_argument("--lower-dwell-deg", type=float, default=None,
                   help="lower dwell [deg] (default: what is left of 360)")
    g.add_argument("--base-radius-mm", type=float, default=100.0,
                   help="prime-circle radius r_b [mm], cam axis to roller centre at zero lift (default 100)")
    return g


def rise_law(args):
    """(name, MotionLaw) of --preset / --T (default: the paper law)."""
    from ..kinematics.presets import law

    if args.T is not None:
        return "T = " + " ".join(f"{t:g}" for t in args.T), law(args.T)
    name = args.preset or "paper"
    return name, law(name)


def build_program(args, rise):
    """The CamProgram of the options, with `rise` (a MotionLaw) as the rise law."""
    from ..kinematics.cam_program import CamProgram
    from ..kinematics.presets import law

    if args.return_T is not None:
        ret = law(args.return_T)
    elif args.return_preset is not None:
        ret = law(args.return_preset)
    else:
        ret = rise
    lower = args.lower_dwell_deg
    if lower is None:
        used = args.rise_deg + args.upper_dwell_deg + args.return_deg
        if used > 360.0 + 1e-9:
            raise ValueError(f"rise + upper dwell + return = {used:g} deg exceeds 2*pi (360 deg)")
        lower = max(0.0, 360.0 - used)
    return CamProgram(rise, ret, lift=args.lift_mm * 1e-3,
                      rise_angle=math.radians(args.rise_deg), upper_dwell=math.radians(args.upper_dwell_deg),
                      return_angle=math.radians(args.return_deg), lower_dwell=math.radians(lower))
