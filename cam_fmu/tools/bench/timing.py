"""Timed runs through the one fmpy runner: best wall time of repeats, floor and FMU alternated."""
from __future__ import annotations

import gc
import math
import time
from pathlib import Path

from ...experiments.fmpy_runner import FmuRunner


class RunError(RuntimeError):
    pass


class TimedRunner(FmuRunner):
    """An FmuRunner whose ``run`` times repeated simulations (garbage collection off while timing)."""

    def run(self, start_values, stop_time, comm_step, input_array, repeats: int, min_time: float):
        """(result, best wall time [s], repeats done) or raise RunError with the FMU's message."""
        best, result, done = math.inf, None, 0
        total = 0.0
        while done < repeats and (done == 0 or total < min_time):
            gc.collect()
            gc.disable()
            try:
                t0 = time.perf_counter()
                result = self.simulate(start_values, stop_time, comm_step, input_array)
                wall = time.perf_counter() - t0
            except Exception as exc:  # noqa: BLE001  (an FMI error is a result, not a crash)
                gc.enable()
                raise RunError(self.error_text(exc, start_values, stop_time, comm_step, input_array)) from None
            finally:
                gc.enable()
            best = min(best, wall)
            total += wall
            done += 1
        return result, best, done


def paired(floor: TimedRunner, cam: TimedRunner, values, stop_time, comm, inputs, repeats, min_time):
    """Alternate floor and FMU runs (each best of its repeats): (result, FMU wall, floor wall, repeats).

    Pairing puts both measurements in the same seconds, so the ratio survives slow load changes on a
    shared machine better than a floor measured once per block.
    """
    best, best_floor, total, done, result = math.inf, math.inf, 0.0, 0, None
    while done < repeats and (done == 0 or total < min_time):
        best_floor = min(best_floor, floor.run({}, stop_time, comm, inputs, 1, 0.0)[1])
        result, wall, _ = cam.run(values, stop_time, comm, inputs, 1, 0.0)
        best = min(best, wall)
        total += wall
        done += 1
    return result, best, best_floor, done


def _reached(result, stop_time: float, n: int) -> bool:
    return (result is not None and len(result) == n + 1
            and math.isclose(float(result["time"][-1]), stop_time, rel_tol=1e-9, abs_tol=1e-12))


def input_array(u, stop_time: float):
    """fmpy input table for a voltage-drive signal (omega_ref, omega_dot_ref held at their start values)."""
    from ...experiments.runner import signals_table

    return signals_table({"u": u}, stop_time)
