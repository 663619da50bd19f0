"""`cam-fmu bench`: speed-accuracy benchmark of cam.fmu through fmpy (CSV, PNG)."""
from __future__ import annotations

import argparse
from pathlib import Path

DEFAULT_OUT = Path("out") / "bench"


def add_parser(subparsers) -> argparse.ArgumentParser:
    from ..tools.bench import BENCHMARKS, DEFAULT  # the registry: no heavy import

    p = subparsers.add_parser(
        "bench", help="speed-accuracy benchmark of cam.fmu through fmpy (CSV, PNG)",
        description="Runs cam.fmu through fmpy for every solver over a grid of settings and communication "
                    "steps on the fig6, backlash and inductance scenes, then per shipped scene at the defaults "
                    "against a C floor, the cost per effect on fig6 and tight loops; prints one row per run "
                    "and writes OUT/bench.csv, OUT/choices.csv, OUT/scenes.csv, OUT/effects.csv and "
                    "OUT/bench.png. Benchmarks: " + "; ".join(f"{name}: {what}" + ("" if default else " (on request)")
                                                               for name, (_m, default, what) in BENCHMARKS.items()),
)
    p.add_argument("names", nargs="*", metavar="NAME",
                   help=f"benchmarks to run (default: {' '.join(DEFAULT)}; also: "
                        f"{' '.join(n for n in BENCHMARKS if n not in DEFAULT)})")
    p.add_argument("--quick", action="store_true",
                   help="small runs: the grid on fig6 only, comm step 1 ms, one setting per solver (two for rk45); "
                        "the per-step table on fig6 only")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output folder (default: out/bench)")
    p.add_argument("--fmu", type=Path, default=None,
                   help="FMU to measure (default: models/cam.fmu, rebuilt when older than its sources)")
    return p


def run(args) -> int:
    from ..tools.bench import BENCHMARKS, DEFAULT, run as run_bench

    unknown = [name for name in args.names if name not in BENCHMARKS]
    if unknown:
        raise ValueError(f"benchmark {', '.join(map(repr, unknown))}: allowed {', '.join(map(repr, BENCHMARKS))}")
    return run_bench(args.names or DEFAULT, args.out, quick=args.quick, fmu_path=args.fmu)
