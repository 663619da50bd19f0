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
                    "steps on the fig6, backlash, inductance, groove_voltage, spring_voltage and spring_jump scenes, "
                    "then per shipped scene at the defaults "
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
    p.add_argument("--case", action="append", default=[], metavar="CASE", dest="cases",
                   help="a case of the grid (a scene named above), repeatable (default: all; fig6 with --quick)")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output folder (default: out/bench)")
    p.add_argument("--fmu", type=Path, default=None,
                   help="FMU to measure (default: models/cam.fmu, rebuilt when older than its sources)")
    p.add_argument("--sweep", type=int, nargs="?", const=100_000, default=None, metavar="N",
                   help="instead: the sweep's benchmark, N cases of fig. 6 (default 100000) on a local cluster of "
                        "--workers against the engine's own run (cam_fmu/tools/bench/sweep.py)")
    p.add_argument("--workers", type=int, default=2, help="--sweep: local cluster workers (default 2)")
    return p


def run(args) -> int:
    if args.sweep is not None:  # its own arguments (cases, workers), not a run(ctx) of the registry
        from ..tools.bench import sweep

        return sweep.main([str(args.sweep), "--workers", str(args.workers), "--out", str(args.out)])
    from ..tools.bench import BENCHMARKS, DEFAULT, run as run_bench

    unknown = [name for name in args.names if name not in BENCHMARKS]
    if unknown:
        raise ValueError(f"benchmark {', '.join(map(repr, unknown))}: allowed {', '.join(map(repr, BENCHMARKS))}")
    from ..tools.bench.cases import CASES

    wrong = [name for name in args.cases if name not in CASES]
    if wrong:
        raise ValueError(f"--case {', '.join(map(repr, wrong))}: allowed {', '.join(map(repr, CASES))}")
    return run_bench(args.names or DEFAULT, args.out, quick=args.quick, fmu_path=args.fmu, cases=args.cases)
