"""Run a scene's runs on an engine: the scipy reference or the FMU (through fmpy).

``run_scene(scene, engine)`` returns ``{label: {"time": array, <output>: array, ...}}``
in the order of the scene's runs (the first is the primary run). Every result
holds 'time' and every name of physics.variables.OUTPUTS, in SI units.

- ``reference``: reference.simulate_reference with the run's parameters and the
  scene's input signals (continuous in time, breaks located exactly).
- ``fmu``: cam.fmu (fmu_file.ensure_fmu: built first when missing or stale)
  simulated through the one fmpy runner (fmpy_runner.FmuRunner): start values = the run's parameter overrides,
  input = the scene's signals as a table (fmpy applies them at each
  communication point and the FMU holds them over the step), communication
  step = the scene's output interval. A run that stops before stop_time (fmpy
  treats an fmi2Discard as a silent early stop) raises EngineError.
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from ..physics.variables import INPUTS, OUTPUT_NAMES
from .fmu_file import FmuFileError, ensure_fmu
from .scenes import Run, Scene
from .signals import Signal, as_table, constant

ENGINES = ("reference", "fmu")


class EngineError(RuntimeError):
    """A run that did not complete; the message names the scene, the run and the engine."""


def run_scene(scene: Scene, engine: str = "reference", fmu_path: str | Path | None = None,
              progress: Callable[[int, int], None] | None = None) -> dict[str, dict[str, np.ndarray]]:
    """Every run of ``scene`` on ``engine`` ('reference' or 'fmu'), keyed by run label.

    ``progress(done, total)`` (e.g. progress.ProgressBar) is called as the work goes on:
    per run on the reference (one scipy call per run: done/total = runs), per
    communication step on the FMU (done/total = steps over all runs)."""
    if engine not in ENGINES:
        raise ValueError(f"engine {engine!r}: allowed {', '.join(map(repr, ENGINES))}")
    if engine == "reference":
        results = {}
        total = len(scene.runs)
        if progress is not None:
            progress(0, total)
        for k, run in enumerate(scene.runs, start=1):
            results[run.label] = _reference(scene, run)
            if progress is not None:
                progress(k, total)
        return results
    try:
        fmu = ensure_fmu(fmu_path)
    except FmuFileError as exc:
        raise EngineError(str(exc)) from None
    return _fmu_runs(scene, fmu, progress)


# ------------------------------------------------------------------ reference
def _reference(scene: Scene, run: Run) -> dict[str, np.ndarray]:
    from ..reference import simulate_reference  # scipy: only on this path

    try:
        return simulate_reference(run.overrides, scene.stop_time, scene.output_interval,
                                  u=scene.u, omega_ref=scene.omega_ref)
    except Exception as exc:  # noqa: BLE001 - re-raised with the scene and run named
        raise EngineError(f"scene {scene.name!r}, run {run.label!r}, engine 'reference': {exc}") from exc


# ------------------------------------------------------------------------ fmu
def input_signals(scene: Scene) -> dict[str, Signal | None]:
    """The scene's signal for each FMU input (None: held at its start value); omega_dot_ref is
    the slope of omega_ref."""
    return {"u": scene.u, "omega_ref": scene.omega_ref,
            "omega_dot_ref": scene.omega_ref.slope_signal() if scene.omega_ref else None}


def input_table(scene: Scene) -> np.ndarray:
    """The scene's input signals as fmpy's structured input array (time, u, omega_ref, omega_dot_ref)."""
    return signals_table(input_signals(scene), scene.stop_time)


def signals_table(given: Mapping[str, Signal | None], stop: float) -> np.ndarray:
    """fmpy's structured input array for the FMU's inputs from 0 to ``stop`` [s].

    An input not given is held at the FMU's start value (the drive ignores it).
    Jumps are repeated time stamps (left value, then right value), as fmpy reads them.
    """
    signals = every_input(given)
    times: set[float] = {0.0, stop}
    for sig in signals.values():
        times.update(t for t in as_table(sig, stop)[0] if 0.0 <= t <= stop)
    rows: list[tuple[float, ...]] = []
    for t in sorted(times):
        jump = any(_jumps_at(sig, t) for sig in signals.values())
        if jump and t > 0.0:
            rows.append((t, *(_left_value(sig, t) for sig in signals.values())))
        rows.append((t, *(sig.value(t) for sig in signals.values())))
    dtype = [("time", np.float64)] + [(name, np.float64) for name in signals]
    return np.array(rows, dtype=dtype)


def every_input(given: Mapping[str, Signal | None]) -> dict[str, Signal]:
    """A signal for every FMU input, in INPUTS order: an input not given is held at its start value."""
    return {name: given.get(name) or constant(start) for name, _unit, start, _desc in INPUTS}


def _jumps_at(sig: Signal, t: float) -> bool:
    return sig.hold and t in sig.times or sig.times.count(t) > 1


def _left_value(sig: Signal, t: float) -> float:
    """The value just before t (t > 0)."""
    if not _jumps_at(sig, t):
        return sig.value(t)
    k = sig.times.index(t)
    if sig.hold:
        return sig.values[k - 1] if k else sig.values[0]
    return sig.values[k]  # first of the repeated stamps: the value before the jump


def _fmu_runs(scene: Scene, fmu: Path, progress: Callable[[int, int], None] | None = None) -> dict[str, dict[str, np.ndarray]]:
    """All runs on one instance of the FMU, reset between runs.

    No fmi2FreeInstance: with it, the process aborted at exit in about half of
    the runs under pytest ("corrupted double-linked list"); without it, never.
    The instance goes with the process.
    """
    from .fmpy_runner import FmuRunner

    runner = FmuRunner(fmu, name=scene.name)
    results = {}
    steps = max(1, round(scene.stop_time / scene.output_interval))
    total = steps * len(scene.runs)
    for k, run in enumerate(scene.runs):
        on_step = None
        if progress is not None:
            progress(k * steps, total)

            def on_step(time: float, _base: int = k * steps) -> None:
                progress(min(total, _base + round(time / scene.output_interval)), total)
        try:
            result = runner.simulate(run.start_values(), scene.stop_time, scene.output_interval,
                                     input_table(scene), outputs=OUTPUT_NAMES, check_end=True, on_step=on_step)
        except Exception as exc:  # noqa: BLE001 - re-raised with the scene and run named
            raise EngineError(f"scene {scene.name!r}, run {run.label!r}, engine 'fmu' ({fmu}): {exc}") from exc
        results[run.label] = {name: np.asarray(result[name], dtype=float) for name in ("time",) + OUTPUT_NAMES}
    return results
