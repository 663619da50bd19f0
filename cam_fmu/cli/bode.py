"""`cam-fmu bode SCENE [--set NAME=VALUE ...] (--theta DEG | --u0 V) [--fmin --fmax --points] [--json] [--out DIR]`.

The frequency response from the motor voltage u to the rotor's speed omega_m and the cam's
speed omega (control.frequency; docs/control.md section 5), measured on the C engine by
small-signal simulation around an operating point: ``--theta DEG`` freezes the cam at that
angle (held at rest by the voltage that balances gravity; shaft and guide friction and
backlash off), ``--u0 V`` lets it turn under that constant voltage (default: the frozen angle
0). With a frozen angle the analytic response of the linearised two-mass system is computed
beside the measurement, and the largest difference is printed. Writes DIR/<scene>_bode.csv and
DIR/<scene>_bode.png; ``--json`` prints the summary (operating point, the peaks of |H| and
where they are, the largest difference to the analytic response) as one JSON object.
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
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="override a parameter (repeatable)")
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


def run(args) -> int:
    import numpy as np

    from ..control.frequency import analytic_response
    from ..experiments.frequency import measured_response
    from ..experiments.scenes import find_scene
    from .simulate import apply_sets

    if not (0.0 < args.fmin < args.fmax and math.isfinite(args.fmax)) or not 2 <= args.points <= 1000:
        raise ValueError(f"--fmin {args.fmin} --fmax {args.fmax} --points {args.points}: allowed "
                         "0 < fmin < fmax < inf and 2 <= points <= 1000")
    scene = apply_sets(find_scene(args.scene), args.set)
    params = scene.primary.params
    f = np.geomspace(args.fmin, args.fmax, args.points)
    theta0 = None if args.u0 is not None else math.radians(args.theta or 0.0)
    measured = measured_response(params, f, theta0=theta0, u0=args.u0, amplitude=args.amplitude)
    analytic = analytic_response(params, theta0, f) if theta0 is not None else None
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
    written = [csv]
    if not args.no_plot:
        from ..plots.bode import plot_bode

        written.append(plot_bode(measured, analytic, f"{scene.name}: {measured.note}", out / f"{scene.name}_bode.png"))
    summary = {"operating_point": measured.note, "u0": measured.u0, "amplitude": args.amplitude}
    for name, H in (("motor", measured.motor), ("cam", measured.cam)):
        k = int(np.argmax(np.abs(H)))
        summary[f"{name}_peak_gain"], summary[f"{name}_peak_f"] = float(abs(H[k])), float(f[k])
    if analytic is not None:
        for name in ("motor", "cam"):
            exact, seen = getattr(analytic, name), getattr(measured, name)
            summary[f"{name}_difference"] = float(np.max(np.abs(seen - exact)) / np.max(np.abs(exact)))
    if args.json:
        print(json.dumps(summary))
        return 0
    print(measured.note)
    for name in ("motor", "cam"):
        line = f"{name} speed: peak {summary[name + '_peak_gain']:.4g} (rad/s)/V at {summary[name + '_peak_f']:.4g} Hz"
        if analytic is not None:
            line += f"; largest difference to the analytic response {summary[name + '_difference']:.2e} of its peak"
        print(line)
    for path in written:
        print(path)
    sys.stdout.flush()
    return 0
