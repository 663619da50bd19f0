"""The per-step cost of cam.fmu's x86_64 Linux binary from zig (glibc 2.17) against the system gcc's, in one run.

    cam-fmu bench toolchain
    python -m cam_fmu.tools.bench.toolchain      # the same, as JSON

Both binaries from the same sources and flags (``engine_fmu.build``: the default zig build, and
``--platforms host``: the system C compiler, the former build), fig. 6 at 1 ms, in the C host
(``c_floor/loop.c``) and in fmpy's tight loop (``loops.fmpy_loop_us``), the two alternated, best of the
rounds: zig's time over gcc's. A timing, not a test.
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

from ...fmu import engine_fmu
from .loops import _unzip, c_host_us, compile_loop, fmpy_loop_us


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
            "fmpy_ratio": fmpy["zig"] / fmpy["gcc"], "same_values": values["zig"] == values["gcc"]}


def run(ctx) -> int:
    """The benchmark ``toolchain`` of ``cam-fmu bench``: 15 rounds (--quick: 3)."""
    r = measure(ctx.tmp / "toolchain", rounds=3 if ctx.quick else 15)
    for loop in ("c_host", "fmpy"):
        ctx.say(f"# toolchain {loop}: zig {r[f'{loop}_us']['zig']:.3f} us/step, gcc {r[f'{loop}_us']['gcc']:.3f} us/step: "
                f"zig / gcc = {r[f'{loop}_ratio']:.3f}")
    ctx.say(f"# toolchain: the last outputs are {'the same bits' if r['same_values'] else 'NOT the same bits'}")
    return 0


def main() -> int:
    with tempfile.TemporaryDirectory(prefix="cam_toolchain_") as tmp:
        print(json.dumps(measure(Path(tmp)), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
