"""`cam-fmu polydyne SCENE --rpm N [--train-hz F] [--zeta Z] [--step-deg D] [--json] [--out DIR]`.

The cam profile that makes the follower train's end mass follow the scene's laws exactly at the design speed
(``--law NAME``: both strokes' law instead; vibration/polydyne.py: y = s + z, k z + d z' = m s'', over the
turn), as a
motion table (DIR/<scene>_polydyne.csv, 'angle_deg,lift_mm', and DIR/<scene>_polydyne.toml: the scene's
[parameters] with motion_table set to it). The table's rise, through the drive's interpolation, drives the
integrated train at the design speed and across +-10 % (``--band``): its residual after the rise against the
plain law's; and the table runs through the drive (the C engine's speed drive with the train, the end mass's
ringing read in the dwell after the rise: reference/train_residual.py's measurement, experiments.engine_runs):
``polydyne_drive`` per speed, ``residual_polydyne_drive`` at the design speed. Needs the train's natural frequency (--train-hz, or a scene with k_train and m_end) and a law whose
acceleration is continuous; names where the jerk jumps (the corrected cam's velocity jumps there).
"""
from __future__ import annotations

import argparse
import json
import math
import sys

RPM = 2.0 * math.pi / 60.0


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("polydyne", help="the cam profile that cancels the train's vibration at one speed",
                              description="Polydyne correction of the scene's laws for the follower train at a "
                                          "design speed, written as a motion table.")
    p.add_argument("scene", metavar="SCENE", help="a shipped scene's name or a scene file (.toml)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="override a parameter")
    p.add_argument("--law", default=None, help="the law of both strokes, any name of `residual --laws` "
                                               "(default: the scene's rise and return laws)")
    p.add_argument("--rpm", type=float, required=True, help="the design cam speed [1/min]")
    p.add_argument("--train-hz", type=float, default=None, help="the train's natural frequency [Hz]")
    p.add_argument("--zeta", type=float, default=None, help="the train's damping ratio in [0, 1) (default: "
                                                            "the scene's train's, else 0)")
    p.add_argument("--step-deg", type=float, default=0.1, help="the table's row spacing in a stroke (default 0.1)")
    p.add_argument("--band", type=float, default=0.1, help="relative speed band to report (default 0.1: +-10 %%)")
    p.add_argument("--speeds", type=int, default=11, help="speeds across the band (default 11)")
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    return p


def run(args) -> int:
    import numpy as np

    from ..kinematics.presets import named_law
    from ..physics.parameters import law_spec
    from ..vibration.polydyne import StrokeProgram, jerk_jumps, polydyne_table, table_residual, table_rise
    from ..vibration.spectral import check_zeta, residual
    from ..experiments.engine_runs import simulate_engine
    from ..reference.train_residual import drive_residual
    from ._train_scene import out_dir, scene_and_law, train_of

    scene, label, rise_law = scene_and_law(args.scene, args.set)
    params = scene.primary.params
    return_law = named_law(law_spec(params, "return"))
    if args.law is not None:
        label, rise_law = args.law, named_law(args.law)
        return_law = rise_law
    scene_hz, scene_zeta = train_of(params)
    f_n = scene_hz if args.train_hz is None else args.train_hz
    if f_n is None:
        raise ValueError(f"scene {scene.name} has no train (k_train, m_end; an arm's k_train_arm, J_end): give its "
                         "natural frequency with --train-hz F [Hz]")
    if not (math.isfinite(f_n) and f_n > 0.0):
        raise ValueError(f"--train-hz {f_n!r}: allowed a frequency > 0 [Hz]")
    if not (math.isfinite(args.rpm) and 0.0 < args.rpm <= 1e6):
        raise ValueError(f"--rpm {args.rpm!r}: allowed a cam speed in (0, 1e6] 1/min")
    if not (math.isfinite(args.band) and 0.0 <= args.band < 1.0) or not 1 <= args.speeds <= 201:
        raise ValueError(f"--band {args.band!r} / --speeds {args.speeds}: allowed a band in [0, 1) and 1..201 speeds")
    zeta = check_zeta(args.zeta if args.zeta is not None else (scene_zeta or 0.0))
    omega = args.rpm * RPM
    beta_rise, beta_ret = float(params["rise_angle"]), float(params["return_angle"])
    lift = float(params["lift"])
    r_rise, r_ret = beta_rise / omega * f_n, beta_ret / omega * f_n
    program = StrokeProgram(rise_law, return_law, lift, beta_rise, float(params["upper_dwell"]), beta_ret)
    text = polydyne_table(program, omega, f_n, zeta, args.step_deg)
    rise = table_rise(text, beta_rise, lift)
    factors = np.linspace(1.0 - args.band, 1.0 + args.band, args.speeds) if args.speeds > 1 else np.ones(1)
    rows = []
    table_params = dict(params, motion_table=text)
    for f in sorted(set(factors.tolist()) | {1.0}):
        r = r_rise / f
        rows.append({"rpm": args.rpm * f, "r": r, "plain": float(residual(rise_law, r, zeta)[0]),
                     "polydyne": table_residual(rise, beta_rise, lift, r, zeta),
                     "polydyne_drive": drive_residual(table_params, r, zeta, train_hz=f_n, rtol=1e-10, atol=1e-12,
                                                      simulate=simulate_engine, table_ok=True).residual})
    design = next(row for row in rows if row["rpm"] == args.rpm)
    destination = out_dir(args.out)
    csv_path = destination / f"{scene.name}_polydyne.csv"
    csv_path.write_text(text, encoding="utf-8")
    toml_path = destination / f"{scene.name}_polydyne.toml"
    toml_path.write_text(f"# cam-fmu polydyne {scene.name} --rpm {args.rpm:g}: train {f_n:g} Hz, zeta {zeta:g}\n"
                         f'[parameters]\nmotion_table = """\n{text}"""\n', encoding="utf-8")
    notes = [f"the {name} law's jerk jumps at T = " + ", ".join(f"{t:g}" for t, _ in jumps)
             + ": the corrected cam's follower velocity jumps there (by J / W^2), which the table's cubic rounds"
             for name, jumps in (("rise", jerk_jumps(rise_law)), ("return", jerk_jumps(return_law))) if jumps]
    out = {"scene": scene.name, "law": label, "rpm": args.rpm, "train_hz": f_n, "zeta": zeta, "r_rise": r_rise,
           "r_return": r_ret, "residual_plain": design["plain"], "residual_polydyne": design["polydyne"],
           "residual_polydyne_drive": design["polydyne_drive"],
           "band": rows, "notes": notes, "files": [str(csv_path), str(toml_path)]}
    if args.json:
        print(json.dumps(out))
        return 0
    print(f"scene {scene.name}: rise law {label} at {args.rpm:g} 1/min with a {f_n:g} Hz train (zeta {zeta:g}): "
          f"r = {r_rise:.6g}")
    print(f"  residual after the rise / lift: plain law {design['plain']:.4g}, polydyne table "
          f"{design['polydyne']:.4g} (through the drive: {design['polydyne_drive']:.4g})")
    for row in rows:
        print(f"  {row['rpm']:10.6g} 1/min  r = {row['r']:.5g}  plain {row['plain']:.4g}  polydyne "
              f"{row['polydyne']:.4g}  through the drive {row['polydyne_drive']:.4g}")
    for note in notes:
        print("  note: " + note)
    print(csv_path)
    print(toml_path)
    sys.stdout.flush()
    return 0
