"""The scipy reference's runs, each computed once per test session (conftest.py's ``reference_runs`` fixture).

Several layers compare against the same reference runs (a scene's runs in cli/, engine/, fmu_cs/; a scene at
1 ms took up to 16 s each time). A run is keyed by everything ``simulate_reference`` reads: the parameters, the
stop time, the output interval, the input signals and the integrator's settings, so two tests share a run only
when they ask for the same computation. Every caller gets its own copy of the arrays.

A run read from the cache costs its reader nothing in this session, but a session without the test that
computed it (the fast loop) computes it in the reader: ``CHARGED`` adds up the seconds of the runs served from
the cache, which the duration record (markers.py) charges to the reading test, so that `slow` does not depend on
which test came first.
"""
from __future__ import annotations

from typing import Any, Mapping

import time

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

    def __init__(self) -> None:
        self._runs: dict[tuple, tuple[Result, float]] = {}  # key -> (run, seconds it took)
        self.computed = 0  # runs integrated (the rest were served from the cache)

    def _get(self, key: tuple, compute) -> Result:
        if key in self._runs:
            CHARGED[0] += self._runs[key][1]
        else:
            start = time.perf_counter()
            result = compute()
            self._runs[key] = (result, time.perf_counter() - start)
            self.computed += 1
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
