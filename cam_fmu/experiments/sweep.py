"""Parameter sweeps of a scene: one case on the C engine or an FMU, its metrics, the tables.

The cases: sweep_cases.py; running them in batches, streamed to Parquet: sweep_run.py; the files: sweep_store.py.

A case runs on the C engine in this process (``engine``: a new DriveSimulator from the scene's start values,
its input table in one ``run`` call: the communication steps fmpy takes on cam.fmu, ``fmpy_schedule``) or on
an FMU through fmpy (``fmu``: a process-local FmuRunner, reset between cases). Both are the same C code: the
metrics agree to the bit. A case that fails while it runs does not stop the sweep: its row keeps the varied
values, ``status`` = "failed", ``message`` = the engine's (or FMU's) own reason and NaN metrics (``status`` =
"ok" and an empty message otherwise).
"""
from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence

import numpy as np

from ..physics import parameters as _parameters
from .sweep_cases import (Design, SweepError, Vary, cases, check_cases, check_design,  # noqa: F401 - the API
                          parse_sample, parse_vary)

ENGINES = ("engine", "fmu")


# ------------------------------------------------------------------- metrics
def _second_half(r: Mapping[str, np.ndarray]) -> np.ndarray:
    """Mask of the samples of the run's second half (t >= t_end / 2)."""
    return r["time"] >= r["time"][-1] / 2


def _ripple(r: Mapping[str, np.ndarray]) -> float:
    t, w = r["time"], r["omega"]
    window = w[t >= t[0] + 0.5 * (t[-1] - t[0]) - 1e-12]
    return float(window.max() - window.min())


def _rms(name: str) -> Callable[[Mapping[str, np.ndarray]], float]:
    return lambda r: float(np.sqrt(np.mean(np.square(r[name][_second_half(r)]))))


def _peak_acceleration(r: Mapping[str, np.ndarray]) -> float:
    """Largest |d omega_m / dt| between consecutive output samples [rad/s2] (the rotor: omega_m)."""
    return float(np.max(np.abs(np.diff(r["omega_m"]) / np.diff(r["time"]))))


def _energy_per_turn(r: Mapping[str, np.ndarray]) -> float:
    """Electrical energy drawn (integral of voltage x i, trapezoids) over the second half, per cam turn
    (the cam's angle gained there / 2 pi) [J]; inf when the cam did not turn while energy was drawn."""
    keep = _second_half(r)
    t, p = r["time"][keep], r["voltage"][keep] * r["i"][keep]
    energy = float(np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(t)))
    turns = abs(float(r["theta"][keep][-1] - r["theta"][keep][0])) / (2 * math.pi)
    return energy / turns if turns > 0 else (math.inf if energy else 0.0)


# name -> (unit, description, function of the run's outputs)
METRICS: dict[str, tuple[str, str, Callable[[Mapping[str, np.ndarray]], float]]] = {
    "peak_i": ("A", "largest |armature current|", lambda r: float(np.max(np.abs(r["i"])))),
    "peak_M": ("N.m", "largest |load torque|", lambda r: float(np.max(np.abs(r["M"])))),
    "peak_voltage": ("V", "largest |armature voltage| (speed drive: the voltage needed)",
                     lambda r: float(np.max(np.abs(r["voltage"])))),
    "ripple": ("rad/s", "peak-to-peak omega over the second half of the run", _ripple),
    "mean_omega": ("rad/s", "mean omega over the second half of the run",
                   lambda r: float(np.mean(r["omega"][_second_half(r)]))),
    "final_omega": ("rad/s", "omega at the end of the run", lambda r: float(r["omega"][-1])),
    "rms_M": ("N.m", "rms load torque over the second half of the run (thermal sizing)", _rms("M")),
    "rms_i": ("A", "rms armature current over the second half of the run (thermal sizing)", _rms("i")),
    "peak_accel": ("rad/s2", "largest |rotor acceleration| d omega_m/dt between output samples", _peak_acceleration),
    "energy_per_turn": ("J", "electrical energy drawn (voltage x i) per cam turn over the second half",
                        _energy_per_turn),
}
DEFAULT_METRICS = ("peak_i", "peak_M", "ripple")


def header(name: str) -> str:
    """A column's header with its unit: 'm [kg]', 'peak_i [A]', 'rise_law' (no unit)."""
    unit = METRICS[name][0] if name in METRICS else _parameters.BY_NAME[name].unit
    return f"{name} [{unit}]" if unit else name


def check_metrics(metrics: Sequence[str]) -> list[str]:
    bad = [m for m in metrics if m not in METRICS]
    if bad or not metrics:
        raise SweepError(f"--metric {','.join(bad) or repr(','.join(metrics))}: allowed {', '.join(METRICS)}")
    return list(metrics)


# ------------------------------------------------------------------- one case
def fmpy_schedule(inputs: np.ndarray, stop_time: float, interval: float) -> tuple[np.ndarray, np.ndarray,
                                                                                  np.ndarray]:
    """The communication steps fmpy's simulate_fmu takes on cam.fmu (FMI 2.0/3.0 co-simulation, variable steps
    allowed) for the structured ``inputs`` (runner.input_table): (initial inputs (u, omega_ref, omega_dot_ref),
    table (t, h, u, omega_ref, omega_dot_ref) per step, the time after each step), each number computed as
    fmpy computes it (its loop, its interpolation), so that DriveSimulator.run on the table repeats cam.fmu's
    run to the bit."""
    from fmpy.simulation import Input

    t = inputs[inputs.dtype.names[0]]
    table = np.stack([inputs[name] for name in inputs.dtype.names[1:]]).astype(np.float64)
    events = sorted({math.inf, *(float(x) for x in t[np.where(np.diff(t) == 0)])}) if t.size >= 2 else [math.inf]
    first = np.array(Input.interpolate(time=0.0, t=t, table=table)[0], dtype=np.float64)
    rows, times = [], []
    time, n_steps = 0.0, 0
    while not (time > stop_time or math.isclose(time, stop_time)):  # fmpy's simulateCS loop, FMI 2.0 branch
        regular = 0.0 + (n_steps + 1) * interval
        point = regular
        event = next((e for e in events if e > time and not math.isclose(e, time)), math.inf)
        if point > event and not math.isclose(point, event):
            point = event
        if point > stop_time and not math.isclose(point, stop_time):
            point = stop_time
        values = Input.interpolate(time=time, t=t, table=table, after_event=True)[0]
        rows.append((time, point - time, *values))
        time = point
        times.append(time)
        if math.isclose(time, regular):
            n_steps += 1
    return first, np.array(rows, dtype=np.float64).reshape(-1, 5), np.array(times, dtype=np.float64)


@dataclass
class _Setup:
    """What every case of one scene shares, built once per process: the scene, its primary run's overrides,
    fmpy's input table and the engine's schedule."""

    scene: Any
    overrides: dict
    inputs: np.ndarray
    first: np.ndarray
    table: np.ndarray
    times: np.ndarray


_SETUPS: dict[tuple, _Setup] = {}
_RUNNERS: dict[tuple[str, float], Any] = {}


def _setup(scene_ref: str, stop_time: float | None) -> _Setup:
    key = (scene_ref, stop_time)
    if key not in _SETUPS:
        from .runner import input_table
        from .scenes import find_scene

        scene = find_scene(scene_ref)
        if stop_time is not None:
            scene = scene.with_stop_time(stop_time)
        inputs = input_table(scene)
        _SETUPS[key] = _Setup(scene, dict(scene.primary.overrides), inputs,
                              *fmpy_schedule(inputs, scene.stop_time, scene.output_interval))
    return _SETUPS[key]


def _runner(fmu: str):
    """This process's FmuRunner for ``fmu`` (loaded once, reset between cases)."""
    key = (str(Path(fmu).resolve()), os.stat(fmu).st_mtime)
    if key not in _RUNNERS:
        from .fmpy_runner import FmuRunner

        _RUNNERS[key] = FmuRunner(fmu, name=f"sweep{os.getpid()}")
    return _RUNNERS[key]


def _outputs_engine(setup: _Setup, start_values: Mapping[str, Any]) -> dict[str, np.ndarray]:
    from ..fmu.engine import DriveSimulator
    from ..physics.variables import OUTPUT_NAMES

    sim = DriveSimulator(start_values)
    sim.set_inputs(*setup.first)
    out = np.empty((len(setup.table) + 1, len(OUTPUT_NAMES)))
    out[0] = list(sim.outputs().values())  # the outputs at t = 0 (fmpy's first sample)
    out[1:] = sim.run(setup.table)
    r = {name: out[:, j] for j, name in enumerate(OUTPUT_NAMES)}
    r["time"] = np.concatenate(([0.0], setup.times))
    return r


def _outputs_fmu(setup: _Setup, fmu: str, start_values: Mapping[str, Any]) -> dict[str, np.ndarray]:
    from ..physics.variables import OUTPUT_NAMES

    result = _runner(fmu).simulate(dict(start_values), setup.scene.stop_time, setup.scene.output_interval,
                                   setup.inputs, outputs=OUTPUT_NAMES, check_end=True)
    return {name: np.asarray(result[name], dtype=float) for name in ("time",) + OUTPUT_NAMES}


def case_outputs(scene_ref: str, case: Mapping[str, Any], engine: str = "engine", fmu: str | None = None,
                 stop_time: float | None = None) -> dict[str, np.ndarray]:
    """The time series of one case (``time`` and every output, fmpy's samples: t = 0 and after each step)."""
    setup = _setup(scene_ref, stop_time)
    params = _parameters.resolve({**setup.overrides, **case})
    start_values = {name: params[name] for name in {**setup.overrides, **case}}
    return _outputs_engine(setup, start_values) if engine == "engine" else _outputs_fmu(setup, fmu, start_values)


def run_case(scene_ref: str, case: Mapping[str, Any], metrics: Sequence[str], engine: str = "engine",
             fmu: str | None = None, stop_time: float | None = None) -> dict[str, Any]:
    """One case's row: the varied values, the metrics, status and message."""
    row = dict(case)
    try:
        r = case_outputs(scene_ref, case, engine, fmu, stop_time)
    except Exception as exc:  # noqa: BLE001 - the case fails, the sweep goes on (module docstring)
        text = " ".join(str(exc).split()) or type(exc).__name__
        row.update({m: math.nan for m in metrics}, status="failed", message=text)
        return row
    row.update({m: METRICS[m][2](r) for m in metrics}, status="ok", message="")
    return row


def run_batch(job: Mapping[str, Any]) -> dict[str, list]:
    """The rows of one batch as columns: ``job`` = {scene_ref, stop_time, metrics, engine, fmu, start,
    values (name -> list)}; columns 'case' (numbers from start + 1: cases count from 1), the varied names, the metrics, status,
    message. A dask task (module-level, picklable)."""
    names = list(job["values"])
    n = len(job["values"][names[0]]) if names else 0
    columns: dict[str, list] = {"case": list(range(job["start"] + 1, job["start"] + n + 1))}
    columns.update({name: list(vals) for name, vals in job["values"].items()})
    for m in job["metrics"]:
        columns[m] = []
    columns["status"], columns["message"] = [], []
    for k in range(n):
        case = {name: job["values"][name][k] for name in names}
        row = run_case(job["scene_ref"], case, job["metrics"], job["engine"], job["fmu"], job["stop_time"])
        for m in job["metrics"]:
            columns[m].append(row[m])
        columns["status"].append(row["status"])
        columns["message"].append(row["message"])
    return columns


# ------------------------------------------------------------------ tables
def write_table(rows: Iterable[Mapping[str, Any]], names: Sequence[str], metrics: Sequence[str],
                path: str | Path) -> Path:
    """CSV: one row per case, first its number ``case`` (from 1, as in the Parquet table), then the varied values
    and the metrics with units in the headers ('m [kg]', 'peak_i [A]'), numbers with 17 digits (exact), then
    the case's status ('ok', 'failed') and message (the reason of a failed case, quoted)."""
    columns = list(names) + list(metrics)
    path = Path(path)
    with open(path, "w", encoding="utf-8", newline="") as fh:
        out = csv.writer(fh, lineterminator="\n")
        out.writerow(["case"] + [header(n) for n in columns] + ["status", "message"])
        for row in rows:
            out.writerow([str(row["case"])]
                         + [repr(row[n]) if isinstance(row[n], float) else str(row[n]) for n in columns]
                         + [row.get("status", "ok"), row.get("message", "")])
    return path


def plot_table(rows: Sequence[Mapping[str, Any]], varies: Sequence[Vary], metrics: Sequence[str],
               path: str | Path, title: str = "") -> Path:
    """One panel per (metric, varied parameter): the metric against the parameter, one line per
    combination of the other varied parameters (a grid), or every case as a point (a sample)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sampled = any(v.kind == "range" for v in varies)
    fig, axes = plt.subplots(len(metrics), len(varies), figsize=(4.5 * len(varies), 2.8 * len(metrics)),
                             squeeze=False)
    for j, vary in enumerate(varies):
        others = [] if sampled else [v.name for v in varies if v.name != vary.name]
        groups: dict[tuple, list] = {}
        for row in rows:
            groups.setdefault(tuple(row[o] for o in others), []).append(row)
        for i, metric in enumerate(metrics):
            ax = axes[i, j]
            for key, group in groups.items():
                xs = [g[vary.name] for g in group]
                pos = xs if vary.numeric else [vary.values.index(x) for x in xs]
                label = ", ".join(f"{o}={_short(v)}" for o, v in zip(others, key)) or None
                ax.plot(pos, [g[metric] for g in group], "o" if sampled else "o-", ms=2 if sampled else 3, lw=1,
                        label=label)
            if not vary.numeric:
                ax.set_xticks(range(len(vary.values)), [str(v) for v in vary.values], rotation=30, fontsize=8)
            ax.set_xlabel(header(vary.name))
            ax.set_ylabel(header(metric))
            ax.grid(True, alpha=0.3)
            if len(groups) > 1 and len(groups) <= 8 and i == 0:
                ax.legend(fontsize="x-small")
    if title:
        fig.suptitle(title, fontsize=10)
    from ..plots import save_figure

    return save_figure(plt, fig, path)


def _short(value: Any) -> str:
    return f"{value:.4g}" if isinstance(value, float) else str(value)
