"""What one command may allocate, checked before it runs: a bound, not a guess at the machine's memory.

MAX_STEPS bounds the communication steps (= output rows) of one run: `simulate` (stop_time /
output_interval), `cosim` (stop time / step size of the SSP or the options) and each sweep case. A row
holds every output (about 20 doubles), so a run at the bound keeps about 200 MB of results.
MAX_CASES bounds the cases of one `sweep` (the product of the --vary counts, a sample's N, a Saltelli design's
N (d + 2)); a sweep's memory does not grow with it (experiments/sweep_run.py), its disk does (the Parquet
bytes a case: `cam-fmu bench --sweep`).
"""
from __future__ import annotations

import math
from typing import Type

MAX_STEPS = 1_000_000
MAX_CASES = 10_000_000


def check_steps(span: float, step: float, what: str, error: Type[Exception] = ValueError) -> None:
    """Raise ``error`` when ``span / step`` [s / s] exceeds MAX_STEPS; ``what`` names the two settings."""
    n = span / step if step > 0 and math.isfinite(span) else math.inf
    if not n <= MAX_STEPS:
        raise error(f"{what}: {span:g} s / {step:g} s = {n:.3g} steps; at most {MAX_STEPS:,} steps per run "
                    f"(a longer step or a shorter run)")
