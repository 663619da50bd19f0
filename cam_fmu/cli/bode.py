"""`cam-fmu bode SCENE [--set NAME=VALUE ...] (--theta DEG | --u0 V) [--fmin --fmax --points] [--json] [--out DIR]`.

The frequency response from the motor voltage u to the rotor's speed omega_m and the cam's
speed omega (control.frequency; docs/control.md section 5), measured on the C engine by
small-signal simulation around an operating point: ``--theta DEG`` freezes the cam at that
angle (held at rest by the voltage that balances gravity; shaft and guide friction and
backlash off), ``--u0 V`` lets it turn under that constant voltage (default: the frozen angle
0). With a frozen angle the analytic response of the linearised two-mass system is computed
beside the measurement, and the largest difference is printed. Every resonance (local maximum of
|H|) and anti-resonance (local minimum) of either output on the grid is located: refined on the
engine by golden-section search to 1e-3 relative in f (control.frequency.locate_extrema), and,
at a frozen angle, on the analytic curve beside it. Writes DIR/<scene>_bode.csv and
DIR/<scene>_bode.png (the extrema marked); ``--json`` prints the summary (operating point, the
extrema with their kind, the largest difference to the analytic response) as one JSON object.
At a frozen angle every extremum is a mode of the drive at rest (``cause`` 'mode'). While the cam turns
(``--u0``), each is labelled by what it is (control.frequency.turning_cause): the compliant shaft's resonance
or anti-resonance (``cause`` 'shaft': in the band f_r(theta), f_a(theta) spans over a turn at the turning
speed, control.reflect), the turning's own harmonic k (``cause`` 'turning harmonic', ``harmonic`` k: a peak at
k times the turning frequency ``f_turn``), or neither (a peak or dip of the fit between the harmonics); the
last two are called a 'peak' or 'dip', never a resonance.
Progress: a bar on stderr over the grid's frequencies, then one over the extrema located
(experiments.progress.ProgressBar: on a terminal or with CAM_FMU_PROGRESS=1, never with 0).

Frequencies out of reach are refused before anything runs, naming the reachable range
(experiments.frequency.OperatingPoint.reachable: the work of one run is bounded); so is a speed
drive (drive = 'speed'), whose u plays no part, and a follower that can leave the cam (closures 'form'
and 'spring'): the response holds the follower on the cam.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("bode", help="frequency response from the motor voltage to the motor and cam speed",
                              description="Small-signal frequency response of a scene's drive around an operating point.")
    p.add_argument("scene", metavar="SCENE", help="a shipped scene's name (e.g. compliant_shaft) or a scene file (.toml)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="override a parameter (repeatable); a value may carry its unit, "
                   "e.g. --set k_shaft=50 --set c=0.5mm")
    point = p.add_mutually_exclusive_group()
    point.add_argument("--theta", type=float, metavar="DEG", help="freeze the cam at this angle [deg] (default 0)")
    point.add_argument("--u0", type=float, metavar="V", help="let the cam turn under this constant voltage [V]")
    p.add_argument("--fmin", type=float, default=1.0, help="lowest frequency [Hz] (default 1)")
    p.add_argument("--fmax", type=float, default=1000.0, help="highest frequency [Hz] (default 1000)")
    p.add_argument("--points", type=int, default=31, help="frequencies, log-spaced (default 31)")
    p.add_argument("--amplitude", type=float, default=1e-3, help="sine amplitude [V] (default 1e-3)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--no-plot", action="store_true", help="write the CSV file only")
    return p


def shaft_bands(params, f_turn: float) -> dict[str, list[float]] | None:
    """{'resonance': [f_r_min, f_r_max], 'anti-resonance': [f_a_min, f_a_max]} [Hz]: what a compliant shaft's
    two-mass resonance and anti-resonance span over a turn at f_turn [Hz] (control.reflect); None when rigid."""
    from ..control.reflect import reflected_map, summary

    found = summary(reflected_map(params, 60.0 * f_turn), 60.0 * f_turn)
    if found["f_r_min"] is None:
        return None
    return {"resonance": [found["f_r_min"], found["f_r_max"]], "anti-resonance": [found["f_a_min"], found["f_a_max"]]}


def run(args) -> int:
    import numpy as np

    from ..control.frequency import (EXTREMUM_TOLERANCE, analytic_response, locate_extrema, refine_extremum,
                                     turning_cause)
    from ..experiments.frequency import measured_response, operating_point
    from ..experiments.progress import ProgressBar
    from ..experiments.scenes import find_scene
    from .simulate import apply_sets

    if not (0.0 < args.fmin < args.fmax and math.isfinite(args.fmax)) or not 2 <= args.points <= 1000:
        raise ValueError(f"--fmin {args.fmin} --fmax {args.fmax} --points {args.points}: allowed "
                         "0 < fmin < fmax < inf and 2 <= points <= 1000")
    if not (math.isfinite(args.amplitude) and args.amplitude > 0.0):
        raise ValueError(f"--amplitude {args.amplitude!r} V: allowed > 0")
    scene = apply_sets(find_scene(args.scene), args.set)
    params = scene.primary.params
    from ..physics.drive import own_follower

    if own_follower(params):
        kinematic = (" (or --set closure=kinematic: the paper's rule, the follower resting in the clearance until a "
                     "flank takes it along)") if params["closure"] == "form" else ""
        raise ValueError(f"scene {scene.name}: closure {params['closure']!r}: the frequency response linearises the "
                         "drive with the follower on the cam (backlash off, the kinematic rule); a follower that can "
                         f"leave the cam has no small-signal model there (docs/model.md section 13){kinematic}")
    f = np.geomspace(args.fmin, args.fmax, args.points)
    theta0 = None if args.u0 is not None else math.radians(args.theta or 0.0)
    try:
        point = operating_point(params, theta0, args.u0)
    except ValueError as exc:
        raise ValueError(f"scene {scene.name}: {exc}") from None
    point.check(f, names=("--fmin", "--fmax"))  # before anything runs or is allocated
    grid = ProgressBar(f"bode {scene.name} (frequencies)")
    try:
        measured = measured_response(params, f, amplitude=args.amplitude, point=point, progress=grid)
    finally:
        grid.close()
    analytic = analytic_response(params, theta0, f) if theta0 is not None else None
    search = ProgressBar(f"bode {scene.name} (extrema located)")
    try:
        extrema = locate_extrema(measured, lambda fk: measured_response(params, [fk], amplitude=args.amplitude,
                                                                        point=point), progress=search)
    finally:
        search.close()
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {args.out!r} exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    columns = {"f [Hz]": f}
    for name, H in (("motor", measured.motor), ("cam", measured.cam)):
        columns[f"{name}_gain [(rad/s)/V]"] = np.abs(H)
        columns[f"{name}_phase [deg]"] = np.degrees(np.angle(H))
    if analytic is not None:
        for name, H in (("motor", analytic.motor), ("cam", analytic.cam)):
            columns[f"{name}_gain_analytic [(rad/s)/V]"] = np.abs(H)
            columns[f"{name}_phase_analytic [deg]"] = np.degrees(np.angle(H))
    csv = out / f"{scene.name}_bode.csv"
    with csv.open("w", encoding="utf-8") as handle:
        handle.write(",".join(columns) + "\n")
        for k in range(len(f)):
            handle.write(",".join(repr(float(column[k])) for column in columns.values()) + "\n")
    summary = {"operating_point": measured.note, "u0": measured.u0, "amplitude": args.amplitude,
               "extremum_tolerance": EXTREMUM_TOLERANCE, "f_turn": point.f_turn, "shaft_bands": None, "extrema": []}
    if point.f_turn is not None:
        summary["shaft_bands"] = shaft_bands(params, point.f_turn)
    for ex in extrema:
        entry = {"output": ex.output, "kind": ex.kind, "f": ex.f, "gain": ex.gain, "cause": "mode", "harmonic": None}
        if point.f_turn is not None:
            bands = summary["shaft_bands"]  # the cam's speed has no anti-resonance: the rotor stands still there
            if bands is not None and ex.output == "cam":
                bands = {"resonance": bands["resonance"], "anti-resonance": None}
            entry["cause"], entry["harmonic"] = turning_cause(ex.f, ex.kind, point.f_turn, point.span(ex.f), bands)
            if entry["cause"] != "shaft":  # a maximum or minimum of the fit, not a resonance of the drive
                entry["kind"] = "peak" if ex.kind == "resonance" else "dip"
        if analytic is not None:  # the same search on the linearised drive's curve, a little wider than the engine's
            def exact(fk: float, output: str = ex.output) -> float:
                return abs(getattr(analytic_response(params, theta0, [fk]), output)[0])

            entry["f_analytic"], entry["gain_analytic"], _ = refine_extremum(
                exact, ex.f / (1.0 + 8 * EXTREMUM_TOLERANCE), ex.f * (1.0 + 8 * EXTREMUM_TOLERANCE), ex.kind, 1e-7)
        summary["extrema"].append(entry)
    causes = None  # what each extremum of a turning drive is, in the figure's labels
    if point.f_turn is not None:
        causes = [{"turning harmonic": f"harmonic {e['harmonic']}", "shaft": "shaft", "neither": ""}[e["cause"]]
                  for e in summary["extrema"]]
    written = [csv]
    if not args.no_plot:
        from ..plots.bode import plot_bode

        curve = None  # the linearised drive's curve drawn densely, through its resonances' peaks
        if analytic is not None:
            dense = np.union1d(np.geomspace(args.fmin, args.fmax, 2000), [ex.f for ex in extrema])
            curve = analytic_response(params, theta0, dense)
        written.append(plot_bode(measured, curve, f"{scene.name}: {measured.note}", out / f"{scene.name}_bode.png",
                                 extrema, causes))
    if analytic is not None:
        for name in ("motor", "cam"):
            exact, seen = getattr(analytic, name), getattr(measured, name)
            summary[f"{name}_difference"] = float(np.max(np.abs(seen - exact)) / np.max(np.abs(exact)))
    if args.json:
        print(json.dumps(summary))
        return 0
    print(measured.note)
    bands = summary["shaft_bands"]
    if point.f_turn is not None:
        print(f"the cam turns at {point.f_turn:.6g} Hz: a peak at a multiple of it is the turning's own harmonic "
              "(a sine in step with the load's harmonic drives the turning's phase, and the fit sees the turning's own "
              "speed), not a resonance; "
              + ("the shaft is rigid: no mechanical resonance" if bands is None else
                 f"the shaft's resonance over a turn {bands['resonance'][0]:.4g} to {bands['resonance'][1]:.4g} Hz, "
                 f"the rotor's anti-resonance {bands['anti-resonance'][0]:.4g} to {bands['anti-resonance'][1]:.4g} Hz"))
    for entry in summary["extrema"]:
        line = (f"{entry['output']} speed: {entry['kind']} at {entry['f']:.5g} Hz, |H| = {entry['gain']:.4g} (rad/s)/V")
        if "f_analytic" in entry:
            line += f" (linearised: {entry['f_analytic']:.5g} Hz, {entry['gain_analytic']:.4g})"
        if entry["cause"] == "turning harmonic":
            line += (f": the turning's harmonic {entry['harmonic']} ({entry['harmonic']} x {point.f_turn:.6g} Hz), "
                     "not a resonance")
        elif entry["cause"] == "shaft":
            line += f": in the band the shaft's {entry['kind']} spans over a turn"
        elif entry["cause"] == "neither":
            line += (": between the turning's harmonics, not a resonance" if entry["kind"] == "peak" else
                     ": between the turning's harmonics, not an anti-resonance") + \
                ("" if bands is None else " (outside the shaft's band)")
        print(line)
    if not summary["extrema"]:
        print(f"no resonance or anti-resonance between {args.fmin:g} and {args.fmax:g} Hz")
    if analytic is not None:
        for name in ("motor", "cam"):
            print(f"{name} speed: largest difference to the analytic response {summary[name + '_difference']:.2e} "
                  "of its peak")
    for path in written:
        print(path)
    sys.stdout.flush()
    return 0
