"""Parameter sweeps of a scene on cam.fmu: serial, or on dask.distributed (a local cluster or a scheduler).

A sweep runs a scene's primary run once per case: the cartesian product of
the varied parameters (``--vary m=0.2:0.6:5`` = 5 values from 0.2 to 0.6;
``--vary rise_law=paper,cycloidal`` = a list), everything else as in the
scene. Each case yields one table row: the varied values and the metrics.

Every process (the serial caller or a dask worker) loads the FMU once
(``_runner``: a process-local FmuRunner keyed by the FMU's path and mtime) and
resets the instance between cases, so a case's result does not depend on
where or after which case it ran: dask results equal serial ones bit for bit.

Before anything runs, every case is checked as `simulate` checks a scene
(``check_cases``: parameters through parameters.resolve, the drive's input
signal through scenes.check_drive_inputs), and the sweep has at most
limits.MAX_CASES cases. A case that then fails while it runs (the FMU refuses
it, a step cannot be completed) does not stop the sweep: its row keeps the
varied values, ``status`` = "failed", ``message`` = the FMU's own reason and
NaN metrics (``status`` = "ok" and an empty message otherwise).
"""
from __future__ import annotations

import contextlib
import csv
import itertools
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..physics import parameters as _parameters
from .limits import MAX_CASES


class SweepError(ValueError):
    """Bad sweep specification; the message names the option and the allowed values."""


class SweepInterrupted(KeyboardInterrupt):
    """An interrupt (SIGINT, Ctrl-C) during a sweep: ``rows`` are the cases that finished, in case order
    (``cases`` their numbers from 1), of ``total``."""

    def __init__(self, rows: list[dict], cases: list[int], total: int) -> None:
        super().__init__(f"interrupted after {len(rows)} of {total} cases")
        self.rows, self.cases, self.total = rows, cases, total


@contextlib.contextmanager
def sigint_ignored():
    """SIGINT ignored while the block starts processes: they inherit the disposition (Python and asyncio install
    no KeyboardInterrupt handler where SIGINT is ignored), so a Ctrl-C to the terminal's process group reaches only
    this process, which stops the sweep; dask's worker processes print no traceback."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


class _InterruptFlag:
    """SIGINT sets ``event`` instead of raising KeyboardInterrupt (in the main thread; elsewhere nothing changes);
    ``restore`` puts the former handler back."""

    def __init__(self) -> None:
        import signal
        import threading

        self.event = threading.Event()
        self.previous = None
        if threading.current_thread() is threading.main_thread():
            self.previous = signal.signal(signal.SIGINT, lambda signum, frame: self.event.set())

    def is_set(self) -> bool:
        return self.event.is_set()

    def wait(self, seconds: float) -> None:
        self.event.wait(seconds)

    def restore(self) -> None:
        import signal

        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)
            self.previous = None


def _interrupted(rows: Sequence[dict | None]) -> SweepInterrupted:
    done = [k for k, row in enumerate(rows) if row is not None]
    return SweepInterrupted([rows[k] for k in done], [k + 1 for k in done], len(rows))  # type: ignore[misc]


def _ripple(r: Mapping[str, np.ndarray]) -> float:
    t, w = r["time"], r["omega"]
    window = w[t >= t[0] + 0.5 * (t[-1] - t[0]) - 1e-12]
    return float(window.max() - window.min())


# name -> (unit, description, function of the run's outputs)
METRICS: dict[str, tuple[str, str, Callable[[Mapping[str, np.ndarray]], float]]] = {
    "peak_i": ("A", "largest |armature current|", lambda r: float(np.max(np.abs(r["i"])))),
    "peak_M": ("N.m", "largest |load torque|", lambda r: float(np.max(np.abs(r["M"])))),
    "peak_voltage": ("V", "largest |armature voltage| (speed drive: the voltage needed)",
                     lambda r: float(np.max(np.abs(r["voltage"])))),
    "ripple": ("rad/s", "peak-to-peak omega over the second half of the run", _ripple),
    "mean_omega": ("rad/s", "mean omega over the second half of the run",
                   lambda r: float(np.mean(r["omega"][r["time"] >= r["time"][-1] / 2]))),
    "final_omega": ("rad/s", "omega at the end of the run", lambda r: float(r["omega"][-1])),
}
DEFAULT_METRICS = ("peak_i", "peak_M", "ripple")


@dataclass(frozen=True)
class Vary:
    name: str
    values: tuple[Any, ...]


def parse_vary(text: str) -> Vary:
    """'NAME=START:STOP:N' (N values, linear, both ends included) or 'NAME=a,b,c' (a list)."""
    name, sep, spec = text.partition("=")
    name = name.strip()
    if not sep or not name or not spec.strip():
        raise SweepError(f"--vary {text!r}: expected NAME=START:STOP:N or NAME=a,b,c")
    if name not in _parameters.BY_NAME:
        raise SweepError(f"--vary {text!r}: unknown parameter {name!r}; known: {', '.join(_parameters.BY_NAME)}")
    pspec = _parameters.BY_NAME[name]
    if ":" in spec:
        parts = spec.split(":")
        try:
            start, stop, n = float(parts[0]), float(parts[1]), int(parts[2])
            if len(parts) != 3:
                raise ValueError
        except (ValueError, IndexError):
            raise SweepError(f"--vary {text!r}: expected NAME=START:STOP:N with numbers START, STOP "
                             "and an integer N >= 1") from None
        if n < 1 or (n == 1 and start != stop) or n > MAX_CASES:
            raise SweepError(f"--vary {text!r}: N = {n}: allowed 2 <= N <= {MAX_CASES} "
                             f"(or N = 1 with START = STOP)")
        raw = [float(v) for v in np.linspace(start, stop, n)]
    else:
        raw = [v.strip() for v in spec.split(",")]
    try:
        values = tuple(pspec.check(v) for v in raw)
    except _parameters.ParameterError as exc:
        raise SweepError(f"--vary {text!r}: {exc}") from None
    return Vary(name, values)


def cases(varies: Sequence[Vary]) -> list[dict[str, Any]]:
    """The cartesian product of the varied values, in a fixed order (the first --vary changes slowest)."""
    names = [v.name for v in varies]
    if len(set(names)) != len(names):
        raise SweepError(f"--vary names a parameter twice: {', '.join(names)}")
    n = math.prod(len(v.values) for v in varies)
    if n > MAX_CASES:
        raise SweepError(f"--vary: {' x '.join(str(len(v.values)) for v in varies)} = {n} cases; "
                         f"at most {MAX_CASES} in one sweep")
    return [dict(zip(names, combo)) for combo in itertools.product(*(v.values for v in varies))]


def check_cases(scene: Any, todo: Sequence[Mapping[str, Any]]) -> None:
    """SweepError for the first case `simulate` would refuse as a scene: a parameter out of range or
    inconsistent with the others, a drive without its input signal (``--vary drive=speed`` on a voltage
    scene). ``scene``: the experiments.scenes.Scene swept."""
    from .scenes import SceneError, check_drive_inputs

    for case in todo:
        label = ", ".join(f"{k}={v}" for k, v in case.items())
        try:
            params = _parameters.resolve({**scene.primary.overrides, **case})
            check_drive_inputs(params["drive"], scene.u, scene.omega_ref, f"{scene.name}, case {label}")
        except (_parameters.ParameterError, SceneError) as exc:
            raise SweepError(f"--vary: {exc}") from None


# ------------------------------------------------------------------- one case
_RUNNERS: dict[tuple[str, float], Any] = {}


def _runner(fmu: str):
    """This process's FmuRunner for ``fmu`` (loaded once, reset between cases)."""
    key = (str(Path(fmu).resolve()), os.stat(fmu).st_mtime)
    if key not in _RUNNERS:
        from .fmpy_runner import FmuRunner

        _RUNNERS[key] = FmuRunner(fmu, name=f"sweep{os.getpid()}")
    return _RUNNERS[key]


def run_case(scene_ref: str, fmu: str, case: Mapping[str, Any], metrics: Sequence[str],
             stop_time: float | None = None) -> dict[str, Any]:
    """Run one case of the scene ``scene_ref`` (a name or a file) on ``fmu``; return the values and metrics."""
    from ..physics.variables import OUTPUT_NAMES
    from .runner import input_table
    from .scenes import find_scene

    scene = find_scene(scene_ref)
    if stop_time is not None:
        scene = scene.with_stop_time(stop_time)
    run = scene.primary
    params = _parameters.resolve({**run.overrides, **case})
    start_values = {name: params[name] for name in {**run.overrides, **case}}
    row = dict(case)
    try:
        result = _runner(fmu).simulate(start_values, scene.stop_time, scene.output_interval, input_table(scene),
                                       outputs=OUTPUT_NAMES, check_end=True)
    except Exception as exc:  # noqa: BLE001 - the case fails, the sweep goes on (module docstring)
        text = " ".join(str(exc).split()) or type(exc).__name__
        row.update({m: math.nan for m in metrics}, status="failed", message=text)
        return row
    r = {name: np.asarray(result[name], dtype=float) for name in ("time",) + OUTPUT_NAMES}
    row.update({m: METRICS[m][2](r) for m in metrics}, status="ok", message="")
    return row


# ------------------------------------------------------------------- the sweep
def run_sweep(scene_ref: str, fmu: str | Path, varies: Sequence[Vary], metrics: Sequence[str] = DEFAULT_METRICS,
              workers: int | None = None, scheduler: str | None = None, serial: bool = False,
              stop_time: float | None = None, progress: Callable[[int, int], None] | None = None) -> list[dict]:
    """Every case's row, in case order. ``serial``: in this process; else on dask (``scheduler`` or a
    LocalCluster of ``workers`` processes, default one per core, one thread each)."""
    bad = [m for m in metrics if m not in METRICS]
    if bad:
        raise SweepError(f"--metric {', '.join(bad)}: allowed {', '.join(METRICS)}")
    todo = cases(varies)
    from .scenes import find_scene

    scene = find_scene(scene_ref)
    check_cases(scene if stop_time is None else scene.with_stop_time(stop_time), todo)
    fmu = str(Path(fmu).resolve())
    rows: list[dict | None] = [None] * len(todo)
    if serial:
        try:
            for k, case in enumerate(todo):
                rows[k] = run_case(scene_ref, fmu, case, metrics, stop_time)
                if progress:
                    progress(k + 1, len(todo))
        except KeyboardInterrupt:
            raise _interrupted(rows) from None
        return rows  # type: ignore[return-value]
    from distributed import Client, LocalCluster, as_completed

    cluster = None
    interrupted = False
    # The worker processes ignore a Ctrl-C to the process group (sigint_ignored) and log errors only: closing the
    # cluster after an interrupt cancels the cases they run, which each would report as a warning.
    with sigint_ignored(), _environment(DASK_LOGGING__DISTRIBUTED="error"):
        if scheduler:
            client = Client(scheduler, timeout="30s")
        else:
            n = workers or os.cpu_count() or 1
            if n < 1:
                raise SweepError(f"--workers {n}: allowed >= 1")
            # no dashboard; the scheduler's own HTTP server on a free port (its default, 8787, may be taken by
            # another cluster on the machine: distributed then warns on stderr)
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                   host="127.0.0.1", scheduler_kwargs={"dashboard_address": "127.0.0.1:0"})
            client = Client(cluster)
    futures: list = []
    stop = _InterruptFlag()  # Ctrl-C sets a flag: a KeyboardInterrupt inside the client's calls left dask's
    try:                      # event loop logging tracebacks (a cancelled sync, the workers' heartbeats)
        futures = [client.submit(run_case, scene_ref, fmu, case, tuple(metrics), stop_time, pure=False, key=f"case-{k}-{os.getpid()}-{id(todo)}")
                   for k, case in enumerate(todo)]
        index = {f.key: k for k, f in enumerate(futures)}
        finished, done = as_completed(futures), 0
        while not finished.is_empty() and not stop.is_set():
            batch = finished.next_batch(block=False)
            if not batch:
                stop.wait(0.05)
            for future in batch:
                rows[index[future.key]] = future.result()
                done += 1
                if progress:
                    progress(done, len(todo))
        interrupted = stop.is_set()
    except KeyboardInterrupt:  # before the flag's handler was in place
        interrupted = True
    finally:
        stop.restore()
        with sigint_ignored(), _quiet("distributed"):  # shutting down after an interrupt: no second one, no noise
            client.close()
            if cluster is not None:
                cluster.close()
    if interrupted:
        raise _interrupted(rows)
    return rows  # type: ignore[return-value]


@contextlib.contextmanager
def _environment(**values: str):
    """os.environ with ``values`` inside the block (what processes started there inherit)."""
    saved = {name: os.environ.get(name) for name in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


@contextlib.contextmanager
def _quiet(logger: str):
    """The logger ``logger`` and its children silent below CRITICAL inside the block."""
    import logging

    log = logging.getLogger(logger)
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        log.setLevel(level)


def write_table(rows: Sequence[Mapping[str, Any]], varies: Sequence[Vary], metrics: Sequence[str],
                path: str | Path) -> Path:
    """CSV: one row per case, headers with units ('m [kg]', 'peak_i [A]'); numbers with 17 digits (exact);
    then each case's status ('ok', 'failed') and message (the reason of a failed case, quoted)."""
    names = [v.name for v in varies] + list(metrics)
    units = {v.name: _parameters.BY_NAME[v.name].unit for v in varies}
    units.update({m: METRICS[m][0] for m in metrics})
    path = Path(path)
    with open(path, "w", encoding="utf-8", newline="") as fh:
        out = csv.writer(fh, lineterminator="\n")
        out.writerow([f"{n} [{units[n]}]" if units[n] else n for n in names] + ["status", "message"])
        for row in rows:
            out.writerow([repr(row[n]) if isinstance(row[n], float) else str(row[n]) for n in names]
                         + [row.get("status", "ok"), row.get("message", "")])
    return path


def failed(rows: Sequence[Mapping[str, Any]]) -> list[tuple[int, Mapping[str, Any]]]:
    """(case number from 1, row) of every failed case."""
    return [(k, row) for k, row in enumerate(rows, start=1) if row.get("status") == "failed"]


def plot_table(rows: Sequence[Mapping[str, Any]], varies: Sequence[Vary], metrics: Sequence[str],
               path: str | Path, title: str = "") -> Path:
    """One panel per (metric, varied parameter): the metric against the parameter, one line per
    combination of the other varied parameters."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(metrics), len(varies), figsize=(4.5 * len(varies), 2.8 * len(metrics)),
                             squeeze=False)
    for j, vary in enumerate(varies):
        others = [v.name for v in varies if v.name != vary.name]
        groups: dict[tuple, list] = {}
        for row in rows:
            groups.setdefault(tuple(row[o] for o in others), []).append(row)
        numeric = all(isinstance(x, float) for x in vary.values)
        for i, metric in enumerate(metrics):
            ax = axes[i, j]
            for key, group in groups.items():
                xs = [g[vary.name] for g in group]
                pos = xs if numeric else [vary.values.index(x) for x in xs]
                label = ", ".join(f"{o}={_short(v)}" for o, v in zip(others, key)) or None
                ax.plot(pos, [g[metric] for g in group], "o-", ms=3, lw=1, label=label)
            if not numeric:
                ax.set_xticks(range(len(vary.values)), [str(v) for v in vary.values], rotation=30, fontsize=8)
            unit = _parameters.BY_NAME[vary.name].unit
            ax.set_xlabel(f"{vary.name} [{unit}]" if unit else vary.name)
            ax.set_ylabel(f"{metric} [{METRICS[metric][0]}]")
            ax.grid(True, alpha=0.3)
            if len(groups) > 1 and len(groups) <= 8 and i == 0:
                ax.legend(fontsize="x-small")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _short(value: Any) -> str:
    return f"{value:.4g}" if isinstance(value, float) else str(value)
