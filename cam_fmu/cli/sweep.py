"""`cam-fmu sweep SCENE --vary NAME=START:STOP:N [--vary NAME=a,b,c] [--metric peak_i,...]
[--workers N | --scheduler ADDRESS | --serial] [--out DIR]`.

Runs the scene's primary run on cam.fmu once per case (the cartesian product
of the --vary values) on dask.distributed: by default a local cluster with one
worker process per core; --scheduler ADDRESS (tcp://host:port) uses a running
dask cluster; --serial runs in this process. Writes DIR/<scene>_sweep.csv (one
row per case: varied values and metrics, unit headers) and
DIR/<scene>_sweep.png (each metric against each varied parameter), with a
progress bar on stderr.

Every case is checked before any runs, as `simulate` checks a scene (exit 2 on
the first bad one). A case that fails while it runs keeps its row (status
"failed", its message, NaN metrics); the sweep goes on, names every failed case
on stderr at the end and exits with status 1 (0: every case ran).

An interrupt (Ctrl-C, SIGINT) stops the sweep and keeps what finished: the
table holds the rows of the cases that finished (in case order, with their
varied values), one line on stderr says how many of how many, exit status 130.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "sweep", help="parameter sweep of a scene on cam.fmu (dask.distributed): table + figure",
        description="Run a scene's primary run once per combination of the --vary values on cam.fmu, "
                    "in parallel on dask.distributed; write one table row per case and a figure.")
    p.add_argument("scene", metavar="SCENE", help="a shipped scene's name (e.g. paper_fig6) or a scene file (.toml)")
    p.add_argument("--vary", action="append", required=True, metavar="NAME=START:STOP:N|NAME=a,b,c",
                   help="a parameter and its values (repeatable): N values from START to STOP, or a list")
    p.add_argument("--metric", default="peak_i,peak_M,ripple", metavar="M1,M2,...",
                   help="metrics per case (default peak_i,peak_M,ripple); allowed: peak_i, peak_M, "
                        "peak_voltage, ripple, mean_omega, final_omega")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, metavar="N",
                       help="worker processes of the local dask cluster (default: one per core)")
    where.add_argument("--scheduler", metavar="ADDRESS", default=None,
                       help="address of a running dask scheduler, e.g. tcp://10.0.0.5:8786")
    where.add_argument("--serial", action="store_true", help="run the cases in this process, one after another")
    p.add_argument("--fmu", metavar="FILE.fmu", default=None, help="FMU to run (default: models/cam.fmu, built when stale)")
    p.add_argument("--stop-time", type=float, default=None, metavar="T", help="override the scene's stop_time [s]")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--no-plot", action="store_true", help="write the table only")
    return p


def run(args) -> int:
    from ..experiments.fmu_file import check_cam_variables, ensure_fmu
    from ..experiments.progress import ProgressBar
    from ..experiments.scenes import find_scene
    from ..experiments.sweep import (METRICS, SweepError, SweepInterrupted, cases, check_cases, failed, parse_vary,
                                     plot_table, run_sweep, write_table)

    scene = find_scene(args.scene)  # checked here: a bad scene fails before any worker starts
    if args.stop_time is not None:
        scene = scene.with_stop_time(args.stop_time)
    varies = [parse_vary(text) for text in args.vary]
    metrics = [m.strip() for m in args.metric.split(",") if m.strip()]
    bad = [m for m in metrics if m not in METRICS]
    if bad or not metrics:
        raise SweepError(f"--metric {','.join(bad) or repr(args.metric)}: allowed {', '.join(METRICS)}")
    todo = cases(varies)
    check_cases(scene, todo)  # what simulate would refuse, refused before the FMU is built or a worker starts
    n_cases = len(todo)
    if args.workers is not None and args.workers < 1:
        raise SweepError(f"--workers {args.workers}: allowed >= 1")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise SweepError(f"--out {args.out!r} exists and is not a directory")
    fmu = check_cam_variables(ensure_fmu(args.fmu, log=lambda m: print(m, file=sys.stderr)))  # before any case
    scene_ref = str(scene.path.resolve()) if scene.path else args.scene
    engine = "serial" if args.serial else (args.scheduler or f"local cluster, {args.workers or 'one per core'} workers")
    print(f"# {scene.name}: {n_cases} cases on {engine}", file=sys.stderr)
    t0 = time.perf_counter()
    bar = ProgressBar(f"sweep {scene.name}")
    try:
        rows = run_sweep(scene_ref, fmu, varies, metrics, workers=args.workers, scheduler=args.scheduler,
                         serial=args.serial, stop_time=args.stop_time, progress=bar)
    except SweepInterrupted as stop:  # keep what finished: their rows, in case order; one line, no traceback
        bar.close()
        out.mkdir(parents=True, exist_ok=True)
        path = write_table(stop.rows, varies, metrics, out / f"{scene.name}_sweep.csv")
        print(f"cam-fmu sweep: interrupted: {len(stop.rows)} of {stop.total} cases finished, kept in {path}",
              file=sys.stderr)
        return 130
    elapsed = time.perf_counter() - t0
    out.mkdir(parents=True, exist_ok=True)
    print(write_table(rows, varies, metrics, out / f"{scene.name}_sweep.csv"))
    if not args.no_plot:
        print(plot_table(rows, varies, metrics, out / f"{scene.name}_sweep.png",
                         title=f"{scene.name}: sweep of {', '.join(v.name for v in varies)} on cam.fmu"))
    print(f"# {n_cases} cases in {elapsed:.1f} s ({engine})", file=sys.stderr)
    bad = failed(rows)
    for k, row in bad:
        values = ", ".join(f"{v.name}={row[v.name]}" for v in varies)
        print(f"# case {k} ({values}) failed: {row['message']}", file=sys.stderr)
    if bad:
        print(f"cam-fmu sweep: {len(bad)} of {n_cases} cases failed (rows kept, status 'failed')", file=sys.stderr)
        return 1
    return 0
