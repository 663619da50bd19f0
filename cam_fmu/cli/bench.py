"""`cam-fmu bench`: speed-accuracy benchmark of cam.fmu through fmpy (CSV, PNG)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

DEFAULT_OUT = Path("out") / "bench"


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "bench", help="speed-accuracy benchmark of cam.fmu through fmpy (CSV, PNG)",
        description="Runs cam.fmu through fmpy for every solver over a grid of settings and communication "
                    "steps on the fig6, backlash and inductance scenes, then per shipped scene at the defaults "
                    "against a pythonfmu and a C floor, and the cost per effect on fig6; prints one row per run "
                    "and writes OUT/bench.csv, OUT/choices.csv, OUT/scenes.csv, OUT/effects.csv and "
                    "OUT/bench.png.")
    p.add_argument("--quick", action="store_true",
                   help="small grid: fig6 only, comm step 1 ms, one setting per solver (two for rk45); "
                        "per-step table on fig6 only")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output folder (default: out/bench)")
    p.add_argument("--fmu", type=Path, default=None,
                   help="FMU to measure (default: models/cam.fmu, rebuilt when older than its sources)")
    return p


def run(args) -> int:
    from ..tools.bench.run import run_bench

    rows = run_bench(args.out, quick=args.quick, fmu_path=args.fmu)
    silent = [r for r in rows if r["status"] == "early stop"]
    if silent:
        print(f"# {len(silent)} run(s) stopped early without an error (fmi2Discard?)", file=sys.stderr)
        return 1
    return 0
