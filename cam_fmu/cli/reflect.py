"""`cam-fmu reflect SCENE [--set NAME=VALUE ...] [--rpm N] [--json] [--out DIR]`: what the motor sees.

Over one turn of the cam at a constant speed (``--rpm``, default: the scene's mean
cam speed is not known before a run, so 60 1/min), the inertia J(theta) the motor
drives and the load torque M(theta) with its inertial, gravity and friction parts
(control.reflect; docs/control.md). Writes DIR/<scene>_reflect.csv (SI units in the
header) and DIR/<scene>_reflect.png, and prints the extremes with the angles where
they occur; ``--json`` prints them as one JSON object instead (keys J_min, J_max
[kg m^2], M_min, M_max [N m], f_r_min, f_r_max, f_a_min, f_a_max [Hz], each with its
theta_<key> [rad]; the resonance keys are null when the drive-train is rigid,
k_shaft = 0; and assumes, what the map assumes of the follower). It holds the follower on the cam at
every angle (closure 'kinematic', a clearance ignored; 'form' where it cannot fly: c = 0, no follower mass or the
paper's formulation) and refuses closure 'spring' and 'form' with a clearance, whose follower can leave the cam,
advising only commands that run on that scene (``advice``): for 'spring', `cam-fmu jump` (where and at what speed
it leaves the cam); for 'form', whose groove holds the follower on both flanks (`jump` refuses it), the map with
`--set closure=kinematic` (the clearance ignored) and `cam-fmu simulate` (its flights, N_contact = 0). With a
compliant shaft the CSV adds the columns f_r and f_a [Hz] and the figure a third panel. With a follower train
(k_train > 0, rigid shaft) the map is the train's low-frequency limit (the end mass carried with the follower in J
and M) and the CSV and JSON add f_r_train, f_a_train [Hz], the resonance and anti-resonance the train makes
(control.reflect). Every follower type: a translating flat face or an arm with the kind's own J(theta) and load
(docs/model.md 16.2).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("reflect", help="the inertia and load torque the motor sees over one turn of the cam",
                              description="The reflected-load map of a scene's cam drive at a constant cam speed.")
    p.add_argument("scene", metavar="SCENE", help="a shipped scene's name (e.g. paper_fig6) or a scene file (.toml)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="override a parameter (repeatable), e.g. --set m=0.6; a value may carry its unit, "
                        "e.g. --set m=600g")
    p.add_argument("--rpm", type=float, default=60.0, help="cam speed [1/min] (default 60)")
    p.add_argument("--points", type=int, default=3600, help="angles over the turn (default 3600)")
    p.add_argument("--json", action="store_true", help="print the extremes as JSON")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--no-plot", action="store_true", help="write the CSV file only")
    return p


def advice(closure: str, scene: str, sets: list[str]) -> str:
    """What to run instead of the map for a follower of ``closure`` that can leave the cam: whole command lines on
    the same scene and overrides (``sets``: the --set values), each one the scene accepts."""
    import shlex

    def command(*words: str) -> str:
        return "`" + shlex.join(["cam-fmu", *words[:1], scene, *(w for s in sets for w in ("--set", s)),
                                 *words[1:]]) + "`"

    if closure == "spring":
        return f"where and at what cam speed it leaves the cam: {command('jump')}"
    return (f"a groove's follower flies across its clearance between the flanks; the map with the follower held on "
            f"the cam, the clearance ignored: "
            f"{command('reflect', '--set', 'closure=kinematic')}; its flights over time (N_contact = 0 in "
            f"flight): {command('simulate')}")


def run(args) -> int:
    from ..control.reflect import UNITS, FreeFollowerError, reflected_map, summary
    from ..experiments.scenes import find_scene
    from .simulate import apply_sets

    scene = apply_sets(find_scene(args.scene), args.set)
    try:
        result = reflected_map(scene.primary.params, args.rpm, args.points)
    except FreeFollowerError as exc:
        raise ValueError(f"scene {scene.name}: {exc}; {advice(exc.closure, args.scene, args.set)}") from None
    except ValueError as exc:
        raise ValueError(f"scene {scene.name}: {exc}") from None
    columns = list(result)
    extremes = summary(result, args.rpm)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {args.out!r} exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    csv = out / f"{scene.name}_reflect.csv"
    with csv.open("w", encoding="utf-8") as f:
        f.write(",".join(f"{name} [{UNITS[name]}]" for name in columns) + "\n")
        for k in range(len(result["theta"])):
            f.write(",".join(repr(float(result[name][k])) for name in columns) + "\n")
    written = [csv]
    if not args.no_plot:
        from ..plots.reflect import plot_reflected

        written.append(plot_reflected(result, f"{scene.name}: what the motor sees at {args.rpm:g} 1/min",
                                      out / f"{scene.name}_reflect.png"))
    if args.json:
        print(json.dumps(extremes))
        return 0
    print(f"assumes {extremes['assumes']}")
    for key in ("J", "M"):
        unit = "kg m^2" if key == "J" else "N m"
        print(f"{key}: {extremes[key + '_min']:.6g} .. {extremes[key + '_max']:.6g} {unit} (min at "
              f"{extremes['theta_' + key + '_min']:.4f} rad, max at {extremes['theta_' + key + '_max']:.4f} rad)")
    pairs = [(key, what) for key, what in (("f_r", "resonance"), ("f_a", "anti-resonance"),
                                           ("f_r_train", "the train's resonance"),
                                           ("f_a_train", "the train's anti-resonance"))
             if extremes.get(key + "_min") is not None]
    if not pairs:
        print("resonance: none (the drive-train is rigid, k_shaft = 0, and carries no train, k_train = 0)")
    for key, what in pairs:
        print(f"{what}: {extremes[key + '_min']:.6g} .. {extremes[key + '_max']:.6g} Hz (min at "
              f"{extremes['theta_' + key + '_min']:.4f} rad, max at {extremes['theta_' + key + '_max']:.4f} rad)")
    for path in written:
        print(path)
    sys.stdout.flush()
    return 0
