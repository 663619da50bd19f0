"""The scipy reference's runs, each computed once per test session (conftest.py's ``reference_runs`` fixture).

Several layers compare against the same reference runs (a scene's runs in cli/, engine/, fmu_cs/; a scene at
1 ms took up to 16 s each time). A run is keyed by everything ``simulate_reference`` reads: the parameters, the
stop time, the output interval, the input signals and the integrator's settings, so two tests share a run only
when they ask for the same computation. Every caller gets its own copy of the arrays.

Under pytest-xdist the workers share the runs: each run is kept in the session's shared folder
(session_share.py) as a pickle with the seconds it took, written by the worker that integrated it under a lock
of its own, so that the other worker waits for it and reads it rather than integrating it again.

A run read from the cache costs its reader nothing in this session, but a session without the test that
computed it (the fast loop) computes it in the reader: ``CHARGED`` adds up the seconds of the runs served from
the cache, which the duration record (markers.py) charges to the reading test, so that `slow` does not depend on
which test came first.
"""
from __future__ import annotations

import hashlib
import pickle
import time
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from cam_fmu.experiments.runner import _reference
from cam_fmu.experiments.scenes import Run, Scene
from cam_fmu.physics.signals import Signal
from cam_fmu.reference import simulate_reference

Result = dict[str, np.ndarray]
CHARGED = [0.0]  # seconds of the runs served from the cache since the duration record last read it


def _key(params: Mapping[str, Any] | None, stop_time: float, output_interval: float, u: Signal | None,
         omega_ref: Signal | None, settings: Mapping[str, Any]) -> tuple:
    return (repr(sorted((params or {}).items())), float(stop_time), float(output_interval), repr(u),
            repr(omega_ref), tuple(sorted(settings.items())))


def _copy(result: Result) -> Result:
    return {name: np.array(values, copy=True) for name, values in result.items()}


class ReferenceRuns:
    """The session's reference runs: ``simulate`` as ``simulate_reference``, ``run`` and ``scene`` as the
    scene runner's reference engine (``experiments.runner``)."""

    def __init__(self, folder: Path | None = None) -> None:
        self._runs: dict[tuple, tuple[Result, float]] = {}  # key -> (run, seconds it took)
        self.computed = 0  # runs integrated by this process (the rest were served from the cache)
        self.folder = folder  # where the session's processes keep their runs (None: this process only)
        if folder is not None:
            folder.mkdir(parents=True, exist_ok=True)

    def _compute(self, compute) -> tuple[Result, float]:
        start = time.perf_counter()
        result = compute()
        self.computed += 1
        return result, time.perf_counter() - start

    def _shared(self, key: tuple, compute) -> tuple[Result, float]:
        """The run from the session's folder, integrated here (and kept there) when no process has yet."""
        from session_share import locked

        name = hashlib.sha256(repr(key).encode()).hexdigest()[:32]
        kept = self.folder / f"{name}.pickle"
        with locked(self.folder / f"{name}.lock"):
            if kept.is_file():
                stored_key, result, seconds = pickle.loads(kept.read_bytes())
                if stored_key == key:
                    CHARGED[0] += seconds  # served from the cache, as from this process's memory
                    return result, seconds
            result, seconds = self._compute(compute)
            kept.write_bytes(pickle.dumps((key, result, seconds)))
            return result, seconds

    def _get(self, key: tuple, compute) -> Result:
        if key in self._runs:
            CHARGED[0] += self._runs[key][1]
        elif self.folder is not None:
            self._runs[key] = self._shared(key, compute)
        else:
            self._runs[key] = self._compute(compute)
        return _copy(self._runs[key][0])

    def simulate(self, params: Mapping[str, Any] | None, stop_time: float, output_interval: float,
                 u: Signal | None = None, omega_ref: Signal | None = None, **settings: Any) -> Result:
        """``simulate_reference(params, stop_time [s], output_interval [s], u, omega_ref, **settings)``."""
        return self._get(_key(params, stop_time, output_interval, u, omega_ref, settings),
                         lambda: simulate_reference(params, stop_time, output_interval, u=u, omega_ref=omega_ref,
                                                    **settings))

    def run(self, scene: Scene, run: Run) -> Result:
        """One run of ``scene`` on the reference, as ``run_scene(scene, 'reference')[run.label]``."""
        return self._get(_key(run.overrides, scene.stop_time, scene.output_interval, scene.u, scene.omega_ref, {}),
                         lambda: _reference(scene, run))

    def scene(self, scene: Scene) -> dict[str, Result]:
        """Every run of ``scene`` on the reference, as ``run_scene(scene, 'reference')``."""
        return {run.label: self.run(scene, run) for run in scene.runs}
