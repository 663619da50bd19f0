"""Peak RSS of a long cam.fmu run: does memory stay flat over 1e6 communication steps?

    cam-fmu bench memory [--quick]          # 1e6 steps (--quick: 2e4)
    python -m cam_fmu.tools.bench.memory [--steps 1000000] [--fmu FILE] [--comm 1e-3] [--json]

Runs cam.fmu (fig. 6 at the defaults, u = 3.5 V) through fmpy's ``FMU2Slave``
in a manual loop: ``doStep`` then ``getReal`` of theta and omega, nothing
recorded (``simulate_fmu``'s recorder grows by design). The RSS (VmRSS of
/proc/self/status) and the peak RSS (``resource.getrusage``, ru_maxrss) are
sampled at 10 evenly spaced points; the growth is counted from the first
sample, taken after a warm-up of ``steps / 10`` steps, to the end.

At 1 ms steps, 1e6 steps are 1000 s of simulated time (about 160 cam turns at
3.5 V). A leak of one small Python object per step (~30-60 bytes) shows as
tens of MB; the test (tests/tools/test_bench_memory.py) bounds the growth per step.
"""
from __future__ import annotations

import argparse
import json
import resource
import sys
from pathlib import Path

SAMPLES = 10


def rss_kib() -> int:
    """Resident set size now [KiB] (VmRSS), or the peak where /proc is missing."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return peak_kib()


def peak_kib() -> int:
    return int(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)  # KiB on Linux


def run_memory(fmu: Path, steps: int, comm: float = 1e-3, start_values: dict | None = None,
               on_step=None) -> dict:
    """Run ``steps`` communication steps (after ``steps // 10`` warm-up steps); sample the RSS.

    ``on_step(outputs)``: called after every step (the test injects a leak through it, to show that
    the measurement sees one)."""
    import tempfile

    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from ...experiments.scenes import find_scene

    scene = find_scene("paper_fig6")
    values = dict(scene.primary.start_values())
    values.update(start_values or {})
    md = read_model_description(str(fmu))
    vr = {v.name: v for v in md.modelVariables}
    warmup = max(1, steps // SAMPLES)
    with tempfile.TemporaryDirectory(prefix="cam_mem_") as tmp:
        unzip = extract(str(fmu), unzipdir=tmp)
        slave = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                          instanceName="mem")
        slave.instantiate()
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        for name, value in values.items():
            v = vr[name]
            if v.type == "Real":
                slave.setReal([v.valueReference], [float(value)])
            elif v.type == "Boolean":
                slave.setBoolean([v.valueReference], [bool(value)])
            elif v.type == "Integer":
                slave.setInteger([v.valueReference], [int(value)])
            else:
                slave.setString([v.valueReference], [str(value)])
        slave.setReal([vr["u"].valueReference], [float(scene.u.value(0.0) if scene.u else 3.5)])
        slave.exitInitializationMode()
        refs = [vr["theta"].valueReference, vr["omega"].valueReference]
        t, k = 0.0, 0

        def advance(count: int) -> list:
            nonlocal t, k
            out = None
            for _ in range(count):
                slave.doStep(currentCommunicationPoint=t, communicationStepSize=comm)
                out = slave.getReal(refs)
                if on_step is not None:
                    on_step(out)
                k += 1
                t = k * comm  # no drift of the master clock over 1e6 steps
            return out

        advance(warmup)
        points = [round(steps * j / (SAMPLES - 1)) for j in range(SAMPLES)]  # 0 .. steps
        samples, done = [], 0
        for p in points:
            last = advance(p - done)
            done = p
            samples.append({"step": p, "rss_kib": rss_kib(), "peak_kib": peak_kib()})
        theta, omega = (last if last is not None else slave.getReal(refs))
        slave.terminate()
        slave.freeInstance()
    growth = samples[-1]["rss_kib"] - samples[0]["rss_kib"]
    return {"fmu": str(fmu), "steps": steps, "warmup": warmup, "comm_step": comm, "t_end": t,
            "theta": theta, "omega": omega, "samples": samples, "growth_kib": growth,
            "peak_growth_kib": samples[-1]["peak_kib"] - samples[0]["peak_kib"],
            "bytes_per_step": growth * 1024.0 / steps}


def format_report(r: dict) -> str:
    lines = [f"# cam.fmu memory: {r['steps']} communication steps of {r['comm_step']:g} s after {r['warmup']} "
             f"warm-up steps (t_end = {r['t_end']:g} s, theta = {r['theta']:.6g} rad, omega = {r['omega']:.6g} rad/s)",
             f"{'step':>10}{'RSS [MiB]':>12}{'peak [MiB]':>12}"]
    for s in r["samples"]:
        lines.append(f"{s['step']:>10d}{s['rss_kib'] / 1024:>12.2f}{s['peak_kib'] / 1024:>12.2f}")
    lines.append(f"# growth from the first sample to the end: RSS {r['growth_kib'] / 1024:+.2f} MiB, "
                 f"peak {r['peak_growth_kib'] / 1024:+.2f} MiB = {r['bytes_per_step']:+.2f} bytes per step")
    return "\n".join(lines)


def run(ctx) -> int:
    """The benchmark ``memory`` of ``cam-fmu bench``: 1e6 steps (--quick: 2e4)."""
    ctx.say(format_report(run_memory(ctx.fmu, 20_000 if ctx.quick else 1_000_000)))
    return 0


def main(argv: list[str] | None = None) -> int:
    from ...fmu.build import ensure_fmu

    p = argparse.ArgumentParser(prog="python -m cam_fmu.tools.bench.memory", description=__doc__.split("\n\n")[0])
    p.add_argument("--steps", type=int, default=1_000_000, help="communication steps after the warm-up")
    p.add_argument("--comm", type=float, default=1e-3, help="communication step [s]")
    p.add_argument("--fmu", type=Path, default=None, help="FMU (default: models/cam.fmu, rebuilt when stale)")
    p.add_argument("--json", action="store_true", help="print the result as JSON (last line)")
    args = p.parse_args(argv)
    if args.steps < SAMPLES:
        p.error(f"--steps must be at least {SAMPLES}")
    fmu = ensure_fmu(args.fmu, log=lambda text: print(text, file=sys.stderr))
    result = run_memory(fmu, args.steps, args.comm)
    print(format_report(result))
    if args.json:
        print(json.dumps(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
