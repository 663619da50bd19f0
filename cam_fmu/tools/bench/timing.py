"""Timed runs through the one fmpy runner: best wall time of repeats, floor and FMU alternated."""
from __future__ import annotations

import gc
import math
import time

from ...experiments.fmpy_runner import FmuRunner


class RunError(RuntimeError):
    pass


class TimedRunner(FmuRunner):
    """An FmuRunner whose ``run`` times repeated simulations (garbage collection off while timing)."""

    def run(self, start_values, stop_time, comm_step, input_array, repeats: int, min_time: float, outputs=None):
        """(result, best wall time [s], repeats done) or raise RunError with the FMU's message.

        ``outputs``: the variables fmpy records (None: every output, fmpy's default)."""
        best, result, done = math.inf, None, 0
        total = 0.0
        while done < repeats and (done == 0 or total < min_time):
            gc.collect()
            gc.disable()
            try:
                t0 = time.perf_counter()
                result = self.simulate(start_values, stop_time, comm_step, input_array, outputs=outputs)
                wall = time.perf_counter() - t0
            except Exception as exc:  # noqa: BLE001  (an FMI error is a result, not a crash)
                gc.enable()
                raise RunError(self.error_text(exc, start_values, stop_time, comm_step, input_array,
                                               outputs=outputs)) from None
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


def alternated(entries, stop_time, comm, inputs, outputs, rounds: int):
    """Run every entry once per round, ``rounds`` rounds: {name: (result or None, best wall [s] or nan,
    error or "")}.

    ``entries``: {name: (TimedRunner, start values)}; several names may share a runner. Alternating
    puts every measurement of a comparison in the same seconds (see ``paired``). An entry that fails
    is reported once with the FMU's message and left out of the later rounds.
    """
    best = {name: math.inf for name in entries}
    results: dict = {name: None for name in entries}
    errors = {name: "" for name in entries}
    for _round in range(rounds):
        for name, (runner, values) in entries.items():
            if errors[name]:
                continue
            try:
                res, wall, _ = runner.run(values, stop_time, comm, inputs, 1, 0.0, outputs=outputs)
            except RunError as exc:
                errors[name] = str(exc)
                continue
            results[name] = res
            best[name] = min(best[name], wall)
    return {name: (results[name], best[name] if not errors[name] else math.nan, errors[name]) for name in entries}


def _reached(result, stop_time: float, n: int) -> bool:
    return (result is not None and len(result) == n + 1
            and math.isclose(float(result["time"][-1]), stop_time, rel_tol=1e-9, abs_tol=1e-12))


def input_array(u, stop_time: float, omega_ref=None):
    """fmpy input table of the voltage u and, for the speed drive, omega_ref (signals.Signal; the inputs not given
    held at their start values)."""
    from ...experiments.runner import signals_table

    return signals_table({"u": u, "omega_ref": omega_ref}, stop_time)
