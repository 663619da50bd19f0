"""The per-step cost of cam.fmu's x86_64 Linux binary from zig (glibc 2.17) against the system gcc's, in one run.

    python -m cam_fmu.tools.bench.toolchain

Both binaries from the same sources and flags (``engine_fmu.build``: the default zig build, and
``--platforms host``: the system C compiler, the former build), fig. 6 at 1 ms, in the C host
(``c_floor/loop.c``) and in fmpy's tight loop (``targets.fmpy_loop_us``), the two alternated, best of the
rounds. A timing, not a test: the goal is zig/gcc <= 1.05 in both.
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

from ...fmu import engine_fmu
from .targets import _unzip, c_host_us, compile_loop, fmpy_loop_us

GOAL = 1.05  # zig / gcc per step


def measure(tmp: Path, rounds: int = 15) -> dict:
    """us per step of the two builds in the C host and through fmpy (best of ``rounds``, the order of the two
    swapped every round), and their ratios."""
    folders = {}
    for name, platforms in (("gcc", ["host"]), ("zig", ["x86_64-linux"])):
        fmu = engine_fmu.build(tmp / name / "cam.fmu", platforms=platforms)
        folders[name] = _unzip(fmu, tmp / name / "x")
    loop = compile_loop(tmp / "loop")
    c_host = {name: float("inf") for name in folders}
    fmpy = dict(c_host)
    values = {}
    for k in range(rounds):  # alternated: both see the same load of a shared machine
        for name in (("gcc", "zig") if k % 2 == 0 else ("zig", "gcc")):
            us, values[name] = c_host_us(loop, folders[name], rounds=3)
            c_host[name] = min(c_host[name], us)
            fmpy[name] = min(fmpy[name], fmpy_loop_us({name: folders[name]}, rounds=1)[name])
    return {"c_host_us": c_host, "fmpy_us": fmpy, "c_host_ratio": c_host["zig"] / c_host["gcc"],
            "fmpy_ratio": fmpy["zig"] / fmpy["gcc"], "same_values": values["zig"] == values["gcc"], "goal": GOAL}


def main() -> int:
    with tempfile.TemporaryDirectory(prefix="cam_toolchain_") as tmp:
        print(json.dumps(measure(Path(tmp)), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
