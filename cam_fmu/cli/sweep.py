"""`cam-fmu sweep SCENE --vary NAME=START:STOP:N|NAME=LOW:HIGH|NAME=a,b,c ... [--sample KIND:N [--seed S] |
--sensitivity [N]] [--metric M1,...] [--engine engine|fmu] [--fmu FILE] [--workers N | --scheduler ADDRESS |
--serial] [--batch-size B] [--resume | --overwrite] [--out DIR]`.

Runs the scene's primary run once per case (a full grid of the --vary values, a sample over ranges, or a
Saltelli design for Sobol indices) on the C engine in-process (default) or an FMU through fmpy, in batches on
dask.distributed (by default a local cluster with one worker process per core; --scheduler ADDRESS uses a
running cluster; --serial runs in this process). Each finished batch is written at once to
DIR/<scene>_sweep.parquet/ (one file per batch, the specification beside it in DIR/<scene>_sweep.json;
--resume continues a sweep from what is there; one sweep writes a folder at a time). Sweeps of at
most CSV_MAX_CASES cases also get DIR/<scene>_sweep.csv (column case, unit headers, case order) and DIR/<scene>_sweep.png;
--sensitivity adds DIR/<scene>_sensitivity.csv, a table on stdout and DIR/<scene>_sensitivity.png.

Every case is checked before any runs, as `simulate` checks a scene (exit 2 on the first bad one; above
sweep.CHECK_ALL_UP_TO cases, every combination of each parameter's extremes). A case that fails while it
runs keeps its row (status "failed", its message, NaN metrics); the sweep goes on, names the failed cases on
stderr at the end and exits with status 1 (0: every case ran).

An interrupt (Ctrl-C, SIGINT) stops the sweep and keeps what finished (exit 130): the Parquet dataset holds
every finished batch (serial: the current batch's finished cases too), and the CSV of a small sweep their rows.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

CSV_MAX_CASES = 10_000  # a sweep up to this many cases also gets its CSV table and figure
NAMED_FAILURES = 20  # failed cases named on stderr at the end (then a count)


def add_parser(subparsers) -> argparse.ArgumentParser:
    from ..experiments.sweep import METRICS

    p = subparsers.add_parser(
        "sweep", help="parameter sweep of a scene (C engine or FMU, on dask): Parquet table, CSV + figure",
        description="Run a scene's primary run once per case (a grid of the --vary values, a sample over ranges, "
                    "or a Saltelli design for Sobol indices), in batches on dask.distributed; stream each "
                    "finished batch to a Parquet dataset.")
    p.add_argument("scene", metavar="SCENE", help="a shipped scene's name (e.g. paper_fig6) or a scene file (.toml)")
    p.add_argument("--vary", action="append", required=True, metavar="NAME=START:STOP:N|NAME=LOW:HIGH|NAME=a,b,c",
                   help="a parameter and its values (repeatable): N values from START to STOP (a grid), a range "
                        "LOW:HIGH (--sample, --sensitivity), or a list (categorical); values may carry their unit, "
                        "e.g. c=0mm:0.5mm:6")
    design = p.add_mutually_exclusive_group()
    design.add_argument("--sample", metavar="KIND:N", default=None,
                        help="N cases sampled over the ranges: lhs:N (Latin hypercube), sobol:N (scrambled Sobol), "
                             "random:N (uniform); lists are sampled uniformly")
    design.add_argument("--sensitivity", type=int, nargs="?", const=256, default=None, metavar="N",
                        help="Saltelli design of N (d + 2) cases over the ranges (N default 256, a power of 2), "
                             "then first-order and total Sobol indices of every metric (SALib)")
    p.add_argument("--seed", type=int, default=0, help="seed of --sample and --sensitivity (default 0)")
    p.add_argument("--metric", default="peak_i,peak_M,ripple", metavar="M1,M2,...",
                   help=f"metrics per case (default peak_i,peak_M,ripple); allowed: {', '.join(METRICS)}")
    p.add_argument("--engine", choices=("engine", "fmu"), default=None,
                   help="engine: the C engine in this process (default); fmu: an FMU through fmpy")
    p.add_argument("--fmu", metavar="FILE.fmu", default=None,
                   help="FMU to run (implies --engine fmu; default models/cam.fmu, built when stale)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, metavar="N",
                       help="worker processes of the local dask cluster (default: one per core)")
    where.add_argument("--scheduler", metavar="ADDRESS", default=None,
                       help="address of a running dask scheduler, e.g. tcp://10.0.0.5:8786")
    where.add_argument("--serial", action="store_true", help="run the cases in this process, one after another")
    p.add_argument("--batch-size", type=int, default=None, metavar="B",
                   help="cases per batch (default: about 1 s of work, at least 4 batches per worker)")
    again = p.add_mutually_exclusive_group()
    again.add_argument("--resume", action="store_true",
                       help="continue the sweep in DIR/<scene>_sweep.parquet (the same options only)")
    again.add_argument("--overwrite", action="store_true", help="replace an earlier sweep's dataset")
    p.add_argument("--stop-time", type=float, default=None, metavar="T", help="override the scene's stop_time [s]")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--no-plot", action="store_true", help="write the tables only")
    return p


def run(args) -> int:
    from ..experiments.progress import ProgressBar
    from ..experiments.scenes import find_scene
    from ..experiments.sweep import Design, SweepError, check_design, check_metrics, parse_sample, parse_vary
    from ..experiments.sweep_lock import hold
    from ..experiments.sweep_run import Plan, run_sweep
    from ..experiments.sweep_store import dataset_path, failed_on_disk, iter_rows, lock_path

    scene = find_scene(args.scene)  # checked here: a bad scene fails before any worker starts
    if args.stop_time is not None:
        scene = scene.with_stop_time(args.stop_time)
    varies = tuple(parse_vary(text) for text in args.vary)
    metrics = check_metrics([m.strip() for m in args.metric.split(",") if m.strip()])
    if args.sensitivity is not None and args.sensitivity < 1:
        raise SweepError(f"--sensitivity {args.sensitivity}: allowed N >= 1 (base samples; a power of 2)")
    sample = ("saltelli", args.sensitivity) if args.sensitivity is not None else (
        parse_sample(args.sample) if args.sample else None)
    design = Design(varies, sample, args.seed)
    n_cases = len(design)
    check_design(scene, design)  # what simulate would refuse, refused before the FMU is built or a worker starts
    if args.workers is not None and args.workers < 1:
        raise SweepError(f"--workers {args.workers}: allowed >= 1")
    if args.batch_size is not None and args.batch_size < 1:
        raise SweepError(f"--batch-size {args.batch_size}: allowed >= 1")
    engine = args.engine or ("fmu" if args.fmu else "engine")
    if args.fmu and engine != "fmu":
        raise SweepError(f"--fmu {args.fmu}: runs an FMU, --engine {engine} the C engine: give one of them")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise SweepError(f"--out {args.out!r} exists and is not a directory")
    fmu = None
    if engine == "fmu":
        from ..experiments.fmu_file import check_cam_variables
        from ..fmu.build import ensure_fmu

        fmu = str(Path(check_cam_variables(ensure_fmu(args.fmu, log=lambda m: print(m, file=sys.stderr)))).resolve())
    scene_ref = str(scene.path.resolve()) if scene.path else args.scene
    plan = Plan(scene_ref, scene, design, metrics, engine, fmu, args.stop_time)
    bar = ProgressBar(f"sweep {scene.name}")

    def started(where: str, batch: int, to_run: int) -> None:
        print(f"# {scene.name}: {n_cases} cases ({to_run} to run) on {where}, engine {engine}, batches of {batch}",
              file=sys.stderr)
        bar.start = time.monotonic()  # the rate and the time left from here: the cluster is up
        bar(n_cases - to_run, n_cases, 0)

    folder = dataset_path(out, scene.name)
    with hold(lock_path(folder), folder):  # one writer, from the first check of the folder to its last read
        summary = run_sweep(plan, out, args.workers, args.scheduler, args.serial, args.resume, args.overwrite,
                            args.batch_size, progress=bar, started=started,
                            notes=lambda line: print(f"# {scene.name}: {line}", file=sys.stderr), locked=True)
        bar.close()
        names = [v.name for v in varies]
        small = n_cases <= CSV_MAX_CASES
        table = None
        if small:
            from ..experiments.sweep import write_table

            rows = list(iter_rows(folder))
            table = write_table(rows, names, metrics, out / f"{scene.name}_sweep.csv")
        if summary.interrupted:
            print(f"cam-fmu sweep: interrupted: {summary.done} of {n_cases} cases finished, kept in "
                  f"{table or folder}", file=sys.stderr)
            return 130
        print(folder)
        if table:
            print(table)
            if not args.no_plot:
                from ..experiments.sweep import plot_table

                print(plot_table(rows, varies, metrics, out / f"{scene.name}_sweep.png",
                                 title=f"{scene.name}: sweep of {', '.join(names)} ({engine})"))
        if args.sensitivity is not None:
            from ..experiments.sensitivity import report

            report(plan, folder, out, plot=not args.no_plot)
        failures = failed_on_disk(folder) if summary.failed or args.resume else 0
        rate = summary.ran / summary.seconds if summary.seconds > 0 else 0.0
        print(f"# {scene.name}: {summary.ran} cases in {summary.seconds:.1f} s ({rate:,.0f} cases/s, "
              f"{summary.workers} worker{'s' * (summary.workers != 1)}), {summary.failed} failed; "
              f"{summary.done} of {n_cases} on disk", file=sys.stderr)
        if failures:
            shown = 0
            for row in iter_rows(folder, ["case", *names, "status", "message"]):
                if row["status"] != "failed":
                    continue
                if shown == NAMED_FAILURES:
                    print(f"# ... and more (status 'failed' in {folder})", file=sys.stderr)
                    break
                values = ", ".join(f"{v}={row[v]}" for v in names)
                print(f"# case {row['case']} ({values}) failed: {row['message']}", file=sys.stderr)
                shown += 1
            print(f"cam-fmu sweep: {failures} of {n_cases} cases failed (rows kept, status 'failed')",
                  file=sys.stderr)
            return 1
        return 0
