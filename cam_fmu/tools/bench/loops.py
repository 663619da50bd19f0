"""Tight loops of the C engine, measured in one run: fig. 6 at the defaults (rk45), 1 ms steps.

- **C host**: fmi2DoStep plus fmi2GetReal of two outputs per step, in a tight loop in a small C host
  (``c_floor/loop.c``), for cam.fmu and for the C floor FMU (``c_floor.py``: the same variables, a
  trivial model);
- **fmpy**: the same loop through fmpy's ``FMU2Slave`` (doStep, getReal of theta and omega), cam.fmu
  against the C floor FMU, the two alternated;
- **in process**: one run of fig. 6 (2 s, 2000 steps) in one engine call (``engine.simulator.run_scene``),
  against the C host's 2000 steps of cam.fmu.

Every figure is the best of its rounds (the least disturbed by the other work of a shared machine), and
each ratio's two sides are measured in the same run. Timings, not tests: the tests check the logic.
"""
from __future__ import annotations

import json
import subprocess
import time
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

STOP, STEP = 2.0, 1e-3  # s: fig. 6 at 1 ms

HERE = Path(__file__).resolve().parent
LOOP_SOURCE = HERE / "c_floor" / "loop.c"


def _unzip(fmu: Path, folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(folder)
    return folder


def _description(folder: Path) -> tuple[str, str, dict[str, int]]:
    root = ET.parse(folder / "modelDescription.xml").getroot()
    identifier = root.find("CoSimulation").get("modelIdentifier")
    vrs = {v.get("name"): int(v.get("valueReference")) for v in root.iter("ScalarVariable")}
    return root.get("guid"), identifier, vrs


def compile_loop(dest: Path) -> Path:
    """``c_floor/loop.c`` compiled against the official FMI 2.0 headers (vendored)."""
    from ...engine.build import find_compiler
    from .c_floor import fmi2_include_dir

    cmd = [find_compiler(), "-std=c99", "-O2", "-Wall", "-Wextra", f"-I{fmi2_include_dir()}", str(LOOP_SOURCE),
           "-o", str(dest), "-ldl"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"compiling {LOOP_SOURCE.name} failed:\n{proc.stderr}")
    return dest


def c_host_us(loop: Path, folder: Path, rounds: int = 7) -> tuple[float, list[float]]:
    """(best us per step, the last theta and omega) of the unzipped FMU in ``folder`` in the C loop."""
    guid, identifier, vrs = _description(folder)
    proc = subprocess.run([str(loop), str(folder / "binaries" / "linux64" / f"{identifier}.so"),
                           str(folder / "resources"), guid, str(int(round(STOP / STEP))), repr(STEP),
                           str(vrs["theta"]), str(vrs["omega"]), str(rounds)], capture_output=True, text=True,
                          timeout=600)
    if proc.returncode != 0:
        raise RuntimeError(f"the C loop failed on {identifier}: {proc.stderr[-2000:]}")
    result = json.loads(proc.stdout.strip().splitlines()[-1])
    return result["ns_per_step"] / 1e3, result["values"]


def fmpy_loop_us(folders: dict[str, Path], rounds: int = 7) -> dict[str, float]:
    """Best us per step of each unzipped FMU through fmpy's FMU2Slave, the FMUs alternated per round."""
    from fmpy.fmi2 import FMU2Slave

    best = {name: float("inf") for name in folders}
    n = int(round(STOP / STEP))
    for _ in range(rounds):
        for name, folder in folders.items():
            guid, identifier, vrs = _description(folder)
            fmu = FMU2Slave(guid=guid, unzipDirectory=str(folder), modelIdentifier=identifier, instanceName=name)
            fmu.instantiate()
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
            fmu.exitInitializationMode()
            refs = [vrs["theta"], vrs["omega"]]
            do_step, get_real = fmu.doStep, fmu.getReal
            started = time.perf_counter()
            for k in range(n):
                do_step(k * STEP, STEP)
                get_real(refs)
            best[name] = min(best[name], (time.perf_counter() - started) / n * 1e6)
            fmu.terminate()
            fmu.freeInstance()
    return best


def in_process_ms(rounds: int = 15) -> float:
    """Best wall time [ms] of one fig. 6 run (2000 steps, 3.5 V) in one engine call: a new drive from the
    parameters (the program, its checks), the steps and their outputs into one array."""
    import numpy as np

    from ...engine.simulator import run_scene

    table = np.array([(k * STEP, STEP, 3.5, 1.0, 0.0) for k in range(int(round(STOP / STEP)))])
    best = float("inf")
    for _ in range(rounds):
        started = time.perf_counter()
        run_scene({}, table)
        best = min(best, (time.perf_counter() - started) * 1e3)
    return best


def measure(cam_fmu: Path, c_floor: Path, tmp: Path, quick: bool = False) -> dict:
    """The three loops, cam.fmu against the C floor FMU ``c_floor``, unzipped into ``tmp``."""
    tmp = Path(tmp) / "loops"
    tmp.mkdir(parents=True, exist_ok=True)
    rounds = 3 if quick else 7
    folders = {"cam": _unzip(cam_fmu, tmp / "cam"), "c_floor": _unzip(c_floor, tmp / "c_floor")}
    loop = compile_loop(tmp / "loop")
    cam_c, values = c_host_us(loop, folders["cam"], rounds)
    floor_c, _ = c_host_us(loop, folders["c_floor"], rounds)
    fmpy = fmpy_loop_us(folders, rounds)
    return {"c_host_us": cam_c, "c_host_floor_us": floor_c, "theta_end": values[0],
            "fmpy_us": fmpy["cam"], "fmpy_floor_us": fmpy["c_floor"], "fmpy_ratio": fmpy["cam"] / fmpy["c_floor"],
            "in_process_ms": in_process_ms(5 if quick else 15)}


def report(r: dict) -> list[str]:
    """One line per loop: the figure and its ratio to the baseline of the same run."""
    steps = int(round(STOP / STEP))
    return [
        f"# loop C host: doStep + 2 getReal {r['c_host_us']:.3f} us/step (the C floor FMU {r['c_host_floor_us']:.3f} "
        f"us: cam.fmu's model {r['c_host_us'] - r['c_host_floor_us']:.3f} us)",
        f"# loop fmpy FMU2Slave: {r['fmpy_us']:.2f} us/step = {r['fmpy_ratio']:.3f}x the C floor FMU "
        f"({r['fmpy_floor_us']:.2f} us)",
        f"# loop in process: fig. 6 (2 s, {steps} steps) in one engine call {r['in_process_ms']:.2f} ms = "
        f"{r['in_process_ms'] * 1e3 / (steps * r['c_host_us']):.2f}x the C host's {steps} steps",
    ]


def run(ctx) -> int:
    for line in report(measure(ctx.fmu, ctx.c_floor(), ctx.tmp, ctx.quick)):
        ctx.say(line)
    return 0
