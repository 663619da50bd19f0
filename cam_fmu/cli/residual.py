"""`cam-fmu residual SCENE [--laws A,B,...] [--zeta Z] [--r R1:R2] [--limit X] [--train-hz F] [--json] [--out DIR]`.

The residual vibration after a rise (the follower train's end mass ringing in the following dwell, its amplitude
as a fraction of the lift) against r = rise time / the train's natural period, for the scene's rise law and the
laws named (presets and polynomials: `cam-fmu curve --list`, polynomial_345, polynomial_4567), undamped or at the
damping ratio ``--zeta`` (default: the scene's train's, else 0). The curve is the closed form
(vibration/spectral.py); at ``--check`` ratios of the range the drive itself is run (reference/train_residual.py:
the scene in the speed drive's scipy reference with the train, the cam at the speed that makes the rise last r
natural periods, the end mass's envelope sqrt(e^2 + ((e' + zeta w_n e) / w_d)^2) read in the following dwell and
carried back to the dwell's start by exp(zeta w_n dt)) and the largest difference to the closed form printed. A
polynomial law is not a cam program's law: it has the closed form only. ``--limit X``: the ratio r_limit above
which the residual stays within X (the top speed: in 1/min for the scene's rise angle with ``--train-hz`` or the
scene's train). Writes DIR/<scene>_residual.png (no --no-plot). ``--json`` prints one object: scene, zeta,
train_hz, drive_train_hz (the train's frequency in the drive runs [Hz]: train_hz, else 50), rise_angle [rad], r,
and per law its residual (closed form), drive_checked_at (the ratios run through the drive), drive_residual (the
drive's residual there, null for a polynomial law), drive_max_difference (the largest |drive - closed form|, null
without a drive run) and (with --limit) r_limit and rpm_max.
"""
from __future__ import annotations

import argparse
import json
import math
import sys


DRIVE_HZ = 50.0  # Hz, the train's frequency in the drive runs without one given (the residual does not depend on it)


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("residual", help="the residual vibration after a rise against r, per law",
                              description="Residual vibration of the follower train (a spring-mass) after a rise, "
                                          "against r = rise time / the train's natural period.")
    p.add_argument("scene", metavar="SCENE", help="a shipped scene's name or a scene file (.toml)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="override a parameter")
    p.add_argument("--laws", default="", help="more laws, comma-separated (e.g. cycloidal,modified_sine)")
    p.add_argument("--zeta", type=float, default=None,
                   help="the train's damping ratio in [0, 1) (default: the scene's train's, else 0)")
    p.add_argument("--r", default="0.5:6", metavar="R1:R2", help="range of r (default 0.5:6)")
    p.add_argument("--points", type=int, default=551, help="points of r (default 551)")
    p.add_argument("--check", type=int, default=12,
                   help="ratios at which the drive is run with the train as a check (default 12)")
    p.add_argument("--limit", type=float, default=None, help="a residual tolerance (fraction of the lift)")
    p.add_argument("--train-hz", type=float, default=None, help="the train's natural frequency [Hz], for rpm")
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--no-plot", action="store_true", help="no figure")
    return p


def laws_of(scene_label: str, scene_law, names: str) -> dict:
    """label -> law: the scene's first, then each name of ``names`` (comma-separated) not already in."""
    from ..kinematics.presets import named_law

    out = {f"scene: {scene_label}": scene_law}
    for name in (n.strip() for n in names.split(",")):
        if name and name not in out and name != scene_label:
            out[name] = named_law(name)
    return out


def drive_overrides(label: str, item) -> dict | None:
    """The parameters that make the scene's cam rise by ``label``'s law: none for the scene's own, the preset's
    name for a named MotionLaw, None for a law the cam program cannot carry (a polynomial)."""
    from ..kinematics.motion_law import MotionLaw

    if label.startswith("scene: "):
        return {}
    return {"rise_law": label} if isinstance(item, MotionLaw) else None


def run(args) -> int:
    import numpy as np

    from ..vibration.limit import largest_failing_ratio, top_speed_rpm
    from ..vibration.spectral import check_ratios, check_zeta, residual
    from ..reference.train_residual import drive_residual
    from ._train_scene import out_dir, parse_range, scene_and_law, train_of

    scene, label, law = scene_and_law(args.scene, args.set)
    params = scene.primary.params
    scene_hz, scene_zeta = train_of(params)
    train_hz = scene_hz if args.train_hz is None else args.train_hz
    if train_hz is not None and not (math.isfinite(train_hz) and train_hz > 0.0):
        raise ValueError(f"--train-hz {train_hz!r}: allowed a frequency > 0 [Hz]")
    zeta = check_zeta(args.zeta if args.zeta is not None else (scene_zeta or 0.0))
    r1, r2 = parse_range(args.r, "--r")
    if not (0.0 < r1 < r2 and math.isfinite(r2)):
        raise ValueError(f"--r {args.r}: allowed R1:R2 with 0 < R1 < R2")
    if not 2 <= args.points <= 100000:
        raise ValueError(f"--points {args.points}: allowed 2..100000")
    if not 0 <= args.check <= 1000:
        raise ValueError(f"--check {args.check}: allowed 0..1000")
    laws = laws_of(label, law, args.laws)
    r = check_ratios(np.linspace(r1, r2, args.points))
    r_check = np.linspace(r1, r2, args.check) if args.check else np.empty(0)
    drive_hz = train_hz or DRIVE_HZ
    out = {"scene": scene.name, "zeta": zeta, "train_hz": train_hz, "drive_train_hz": drive_hz,
           "rise_angle": float(params["rise_angle"]),
           "r": r.tolist(), "laws": {}}
    for name, item in laws.items():
        R = residual(item, r, zeta)
        entry = {"residual": R.tolist(), "drive_checked_at": [], "drive_residual": None,
                 "drive_max_difference": None, "r_limit": None, "rpm_max": None}
        overrides = drive_overrides(name, item)
        if r_check.size and overrides is not None:
            driven = np.array([drive_residual({**params, **overrides}, float(x), zeta, drive_hz).residual
                               for x in r_check])
            entry.update(drive_checked_at=r_check.tolist(), drive_residual=driven.tolist(),
                         drive_max_difference=float(np.max(np.abs(driven - residual(item, r_check, zeta)))))
        if args.limit is not None:
            lim = largest_failing_ratio(item, args.limit, zeta)
            entry["r_limit"] = lim.r_limit
            if train_hz is not None:
                rpm = top_speed_rpm(lim.r_limit, float(params["rise_angle"]), train_hz)
                entry["rpm_max"] = None if math.isinf(rpm) else rpm
        out["laws"][name] = entry
    written = []
    if not args.no_plot:
        from ..plots.residual import plot_residual

        destination = out_dir(args.out)
        written.append(plot_residual({k: (r, v["residual"]) for k, v in out["laws"].items()},
                                     f"{scene.name}: residual vibration after the rise (zeta = {zeta:g})",
                                     destination / f"{scene.name}_residual.png", limit=args.limit))
    if args.json:
        print(json.dumps(out))
        return 0
    print(f"scene {scene.name}: residual / lift after the rise over r = {r1:g}..{r2:g}, zeta = {zeta:g}"
          + (f", train {train_hz:g} Hz" if train_hz is not None else ""))
    for name, entry in out["laws"].items():
        R = np.asarray(entry["residual"])
        k = int(np.argmax(R))
        line = f"  {name:<28} worst {R[k]:.4g} at r = {r[k]:.4g}"
        if entry["drive_max_difference"] is not None:
            line += f"; the drive run agrees to {entry['drive_max_difference']:.1e}"
        elif r_check.size:
            line += "; not a cam program's law: not run through the drive"
        if entry["r_limit"] is not None:
            line += f"; within {args.limit:g} for r > {entry['r_limit']:.6g}"
            if entry["rpm_max"] is not None:
                line += f" (top speed {entry['rpm_max']:.6g} 1/min)"
        print(line)
    for path in written:
        print(path)
    sys.stdout.flush()
    return 0
