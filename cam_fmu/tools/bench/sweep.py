"""The sweep's benchmark: N cases of fig. 6 on a local dask cluster against the engine's own single run.

    cam-fmu bench --sweep [N] [--workers W] [--out DIR]      (python -m cam_fmu.tools.bench.sweep N ...)

Measured in one process, one after another:

- ``engine_s``: the engine's own run of a case, the mean over the cases the serial sweep runs (cases differ in
  cost: one mid-range case, m = 0.5 kg and mu = 0.15, ran 24 % faster than the mean over the sample, and made
  the sweep look 1.4 x dearer than its 1.1 x): a new DriveSimulator from the case's
  parameters, ``run`` of the scene's input table (built once before) and the metrics, the least a case can
  cost; ``engine_setup_s`` adds the scene's set-up (read, input table, communication steps), which a sweep
  does once per process;
- ``serial``: ``serial_cases`` cases through the sweep in this process (cases and Parquet writes included,
  the one-time start: imports, the pilot case, not): seconds a case and ``overhead`` = that / engine_s
  (target <= 1.3);
- ``cluster``: the N cases on a LocalCluster of W workers (its start included in ``wall_s``, not in ``run_s``,
  the time from the first batch submitted to the last written): cases/s, cases/s per worker, ``ratio`` =
  cases/s / (W / engine_s) (target >= 0.8) and the per-case overhead W run_s / N / engine_s;
- CPU: the driver's (with the local scheduler) and its child processes' (workers, nannies) CPU seconds a case,
  against the engine's run's CPU time (``engine_cpu_s``): on a shared machine, where the workers get less than
  a core each, the cost that the wall clock hides;
- disk: the Parquet dataset's bytes a case;
- memory: the driver's and each worker's RSS sampled as the batches finish (psutil), the peak of each over the
  first quarter and over the whole run (flat: the two close).

The cases: a random sample over m = 0.2..0.8 kg and mu = 0..0.3 (fig. 6, 2 s each), metrics peak_i, peak_M,
ripple, rms_M. Timing on a shared machine is noisy: compare the ratios of one run.
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

VARY = ("m=0.2:0.8", "mu=0:0.3")
METRICS = ("peak_i", "peak_M", "ripple", "rms_M")


def engine_seconds(cases: int = 2000, stop_time: float | None = None) -> tuple[float, float, float]:
    """Mean times [s] of the engine's own run over the first ``cases`` cases of the sweep's design (the cases the
    serial sweep runs: their costs differ, so the baseline is measured on the same ones): (wall time of drive,
    run and metrics on a prebuilt input table; the same with the scene's set-up from nothing, every tenth case;
    the CPU time of the first, time.process_time)."""
    from ...experiments import sweep
    from ...fmu.engine import DriveSimulator
    from ...physics.variables import OUTPUT_NAMES

    values = _plan(cases, stop_time).design.values(0, cases)
    setup = sweep._setup("paper_fig6", stop_time)
    total = [0.0, 0.0]
    cpu = time.process_time()
    for k in range(cases):
        case = {name: column[k] for name, column in values.items()}
        t0 = time.perf_counter()
        sim = DriveSimulator({**setup.overrides, **case})
        sim.set_inputs(*setup.first)
        out = sim.run(setup.table)
        r = {name: out[:, j] for j, name in enumerate(OUTPUT_NAMES)}
        r["time"] = setup.times
        [sweep.METRICS[m][2](r) for m in METRICS]
        t1 = time.perf_counter()
        total[0] += t1 - t0
        if k % 10 == 0:
            cpu -= time.process_time()
            sweep._SETUPS.clear()
            sweep.run_case("paper_fig6", case, METRICS, stop_time=stop_time)
            total[1] += time.perf_counter() - t1
            cpu += time.process_time()
    return total[0] / cases, total[1] / len(range(0, cases, 10)), (time.process_time() - cpu) / cases


def _plan(n: int, stop_time: float | None = None):
    from ...experiments.scenes import find_scene
    from ...experiments.sweep import Design, parse_vary
    from ...experiments.sweep_run import Plan

    return Plan("paper_fig6", find_scene("paper_fig6"), Design(tuple(parse_vary(v) for v in VARY), ("random", n)),
                METRICS, stop_time=stop_time)


class _Memory:
    """RSS [MiB] of this process and of its child processes (the local cluster's workers), sampled at most
    every 0.5 s; peaks over the first quarter of the cases and over all."""

    def __init__(self) -> None:
        import psutil

        self.me = psutil.Process()
        self.last = 0.0
        self.driver = [0.0, 0.0]
        self.workers: dict[int, list[float]] = {}
        self.cpu: dict[int, float] = {}  # CPU seconds (user + system) of each child process at its last sample

    def __call__(self, done: int, total: int, failed: int = 0) -> None:
        now = time.monotonic()
        if now - self.last < 0.5 and done < total:
            return
        self.last = now
        early = done <= total / 4
        rss = self.me.memory_info().rss / 2 ** 20
        self.driver = [max(self.driver[0], rss if early else 0.0), max(self.driver[1], rss)]
        for child in self.me.children(recursive=True):
            try:
                rss = child.memory_info().rss / 2 ** 20
                times = child.cpu_times()
            except Exception:  # noqa: BLE001 - a process gone meanwhile
                continue
            self.cpu[child.pid] = times.user + times.system
            peaks = self.workers.setdefault(child.pid, [0.0, 0.0])
            peaks[:] = [max(peaks[0], rss if early else 0.0), max(peaks[1], rss)]


def run(n: int = 100_000, workers: int = 2, serial_cases: int | None = None, out: Path | None = None,
        stop_time: float | None = None) -> dict:
    """The measurements (module docstring) as a dict; OUT/sweep_bench.json when ``out`` is given."""
    from ...experiments.sweep_run import run_sweep

    serial_n = serial_cases or min(n, 2000)
    engine_s, setup_s, engine_cpu_s = engine_seconds(serial_n, stop_time)
    result: dict = {"cases": n, "workers": workers, "engine_s": engine_s, "engine_setup_s": setup_s,
                    "engine_cpu_s": engine_cpu_s,
                    "stop_time_s": stop_time or 2.0}
    with tempfile.TemporaryDirectory(prefix="cam_fmu_sweep_bench_") as tmp:
        marks: dict = {}
        serial = run_sweep(_plan(serial_n, stop_time), Path(tmp) / "serial", serial=True,
                           started=lambda where, batch, todo: marks.setdefault("serial", time.perf_counter()))
        per_case = (time.perf_counter() - marks["serial"]) / serial_n
        result["serial"] = {"cases": serial_n, "wall_s": serial.seconds, "case_s": per_case,
                            "overhead": per_case / engine_s, "batch_size": serial.batch_size}
        memory = _Memory()
        cpu0 = memory.me.cpu_times()
        t0 = time.perf_counter()
        summary = run_sweep(_plan(n, stop_time), Path(tmp) / "cluster", workers=workers, progress=memory,
                            started=lambda where, batch, todo: marks.setdefault("start", time.perf_counter()))
        end = time.perf_counter()
        cpu1 = memory.me.cpu_times()
        driver_cpu = cpu1.user + cpu1.system - cpu0.user - cpu0.system
        run_s = end - marks.get("start", t0)
        disk = sum(f.stat().st_size for f in (Path(tmp) / "cluster").rglob("*.parquet"))
        rate = n / run_s
        result["cluster"] = {
            "wall_s": end - t0, "run_s": run_s, "cases_per_s": rate, "cases_per_s_per_worker": rate / workers,
            "ratio": rate / (workers / engine_s), "overhead": workers * run_s / n / engine_s,
            "batch_size": summary.batch_size, "failed": summary.failed,
            "cpu_s_per_case": (driver_cpu + sum(memory.cpu.values())) / n, "disk_bytes_per_case": disk / n,
            "driver_rss_mib": {"first_quarter": memory.driver[0], "peak": memory.driver[1]},
            "worker_rss_mib": [{"first_quarter": a, "peak": b} for a, b in memory.workers.values()],
        }
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        (out / "sweep_bench.json").write_text(json.dumps(result, indent=1) + "\n")
    return result


def report(result: dict) -> str:
    s, c = result["serial"], result["cluster"]
    workers = ", ".join(f"{w['first_quarter']:.0f}/{w['peak']:.0f}" for w in c["worker_rss_mib"])
    return "\n".join([
        f"engine's own run of a case (fig. 6, {result['stop_time_s']:g} s): {result['engine_s'] * 1e3:.2f} ms "
        f"({result['engine_setup_s'] * 1e3:.1f} ms with the scene's set-up)",
        f"serial sweep: {s['cases']} cases, {s['case_s'] * 1e3:.2f} ms a case = {s['overhead']:.2f} x the engine's run "
        f"(target <= 1.3)",
        f"local cluster of {result['workers']} workers: {result['cases']} cases in {c['wall_s']:.1f} s wall "
        f"({c['run_s']:.1f} s running, batches of {c['batch_size']}), {c['cases_per_s']:.0f} cases/s, "
        f"{c['cases_per_s_per_worker']:.0f} per worker; ratio to workers / engine time {c['ratio']:.2f} "
        f"(target >= 0.8); per-case overhead {c['overhead']:.2f} x; CPU a case (driver, scheduler and workers) "
        f"{c['cpu_s_per_case'] * 1e3:.2f} ms = {c['cpu_s_per_case'] / result['engine_cpu_s']:.2f} x the engine's run's "
        f"CPU ({result['engine_cpu_s'] * 1e3:.2f} ms)",
        f"Parquet: {c['disk_bytes_per_case']:.0f} bytes a case; RSS [MiB] first quarter/peak: driver {c['driver_rss_mib']['first_quarter']:.0f}/"
        f"{c['driver_rss_mib']['peak']:.0f}, workers {workers}",
    ])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m cam_fmu.tools.bench.sweep", description=__doc__.split("\n")[0])
    p.add_argument("cases", type=int, nargs="?", default=100_000)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--out", type=Path, default=None)
    p.add_argument("--stop-time", type=float, default=None,
                   help="seconds of each case (default: the scene's 2 s); shorter runs measure memory over 10^6 cases")
    args = p.parse_args(argv)
    result = run(args.cases, args.workers, out=args.out, stop_time=args.stop_time)
    print(report(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
