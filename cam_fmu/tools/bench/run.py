"""`cam-fmu bench`: the speed-accuracy trade of cam.fmu, measured through fmpy.

    cam-fmu bench [--quick] [--out DIR]

For every solver over a grid of internal settings (fixed-step solvers: h_max;
rk45: rtol with atol = rtol / 100) and communication steps, on the scenes
paper_fig6, backlash and inductance (the shipped scenes; the primary run of
each), it runs cam.fmu through ``fmpy.simulate_fmu`` (one instance,
reset between runs, best of a few repeats) and reports per run:

- ``theta_err`` [rad], ``omega_err`` [rad/s]: max |FMU - reference| over the
  communication points, the reference being ``reference.simulate_reference``
  (scipy, rtol 1e-12; its own theta accuracy is ~1e-8 rad, so smaller errors
  are not resolved);
- ``us_per_step``: wall time of the whole ``simulate_fmu`` call (set-up,
  initialisation, the step loop with input setting and output recording) per
  communication step; ``rtf``: simulated seconds per wall second;
- ``cost_ratio``: us_per_step / the floor's us_per_step at the same
  communication step. The floor is a trivial C FMU with the same inputs and
  outputs (``c_floor.py``: two states, one Euler step per doStep), built into a
  temporary folder and timed in the same process, just before each FMU run
  (alternating, best of the repeats of each): what fmpy costs with (nearly) no
  model at all. Each block of runs (scene x communication step) also starts
  with a floor row of its own. (Against the trivial pythonfmu slave, which the
  per-step table still shows, cam.fmu's cheapest settings now cost less than 1.)

Rows of kind ``floor`` (ratio 1 by construction) and ``reference`` (the scipy
reference's own wall time, once per scene on the finest grid) are in the table
too. An FMU run that fails with an FMI error is a row with the error text.

Fixed-step solvers never step past a communication point, so h_max >= the
communication step all mean one internal step per communication step: the grid
runs that setting once, as h_max = the communication step.

Outputs: one printed row per run (as it goes), OUT/bench.csv, OUT/bench.png
(error against cost ratio, log-log, one panel per scene, one line per solver
and communication step) and OUT/choices.csv (per scene and communication step,
the cheapest setting reaching each accuracy level). Default OUT: out/bench.

Then, per shipped scene at the defaults (1 ms communication steps; ``--quick``:
fig. 6 only), the per-step table (``perstep.py``, OUT/scenes.csv): cam.fmu, the
pythonfmu floor and a C floor (``c_floor.py``: the same variables, a trivial C
model), run alternately through ``simulate_fmu``, each once recording theta and
omega and once every output: us/step and cam.fmu's ratios to both floors. On
fig. 6 the cost per effect (OUT/effects.csv: each effect switched, all off), the
Pareto front of the grid (column ``pareto`` of bench.csv, drawn on bench.png),
and the engine's targets on tight loops (``targets.py``: a C host, fmpy's
FMU2Slave, one in-process run). Memory: ``python -m cam_fmu.tools.bench.memory``.

Timing on a shared machine is noisy: compare ratios measured in the same run,
not absolute times across runs. The FMU runs in this process, which already
imported the checkout's ``cam_fmu``: the FMU's slave script then uses these
modules rather than its bundled copies (same code when the FMU is up to date,
which ``ensure_fmu`` checks against the bundled sources' modification times).
"""

import math
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable

from ...experiments.fmu_file import check_cam_variables
from ...fmu.build import ensure_fmu
from .cases import CASES, COMM_STEPS, References, load_cases, settings_grid
from .c_floor import build_c_floor_fmu
from .floor import build_floor_fmu
from .perstep import EFFECT_COLUMNS, SCENE_COLUMNS, run_perstep
from . import targets
from .report import (CHOICE_COLUMNS, HEADER, _row, choose, format_choices, format_pareto, format_row, goal_verdict,
                     pareto, plot, target_verdict, write_csv)
from .timing import RunError, TimedRunner, _reached, input_array, paired


def run_bench(out: Path, quick: bool = False, fmu_path: Path | None = None,
              log: Callable[[str], None] | None = None) -> list[dict]:
    """Run the benchmark; write OUT/bench.csv, OUT/choices.csv and OUT/bench.png; return the rows."""
    import numpy as np

    def say(text: str) -> None:
        (log or print)(text)
        sys.stdout.flush()

    fmu_path = check_cam_variables(ensure_fmu(fmu_path, log=say))  # another FMU: refused before any run
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    comm_steps = (1e-3,) if quick else COMM_STEPS
    cases = load_cases(("fig6",) if quick else CASES)
    repeats, floor_repeats, min_time = 3, 5, 1.0
    rows: list[dict] = []

    with tempfile.TemporaryDirectory(prefix="cam_bench_") as tmp:
        tmp = Path(tmp)
        floor_fmu = build_c_floor_fmu(tmp)
        floor = TimedRunner(floor_fmu, tmp, "floor")
        py_floor = TimedRunner(build_floor_fmu(tmp), tmp, "py_floor")
        cam = TimedRunner(fmu_path, tmp, "cam")
        refs = References(comm_steps)
        say(f"# cam.fmu: {fmu_path}; floor: {floor_fmu.name}; scenes: "
            + ", ".join(f"{c.name} ({c.source})" for c in cases))
        say("# theta_err, omega_err: max |FMU - reference| [rad], [rad/s]; ratio: us/step over the floor's "
            "at the same comm step; * = default settings")
        say(HEADER)

        def emit(row: dict) -> None:
            rows.append(row)
            say(format_row(row))

        for case in cases:
            ref_step, ref_wall = refs.compute(case)
            n_ref = int(round(case.stop_time / ref_step))
            ref_row = _row(case=case.name, kind="ref", solver="scipy", setting="rtol=1e-12", comm_step=ref_step,
                           n_steps=n_ref, status="ok", reached_stop=True, t_end=case.stop_time, wall_s=ref_wall,
                           us_per_step=ref_wall / n_ref * 1e6, rtf=case.stop_time / ref_wall, repeats=1,
                           default=False)
            pending_ref = ref_row  # its ratio needs the floor at its comm step: emitted with that block
            inputs = input_array(case.u, case.stop_time)
            for comm in comm_steps:
                n = int(round(case.stop_time / comm))
                ref = refs.get(case, comm)
                # the floor, just before this block
                res, wall, done = floor.run({}, case.stop_time, comm, inputs, floor_repeats, min_time)
                floor_us = wall / n * 1e6
                reached = _reached(res, case.stop_time, n)
                emit(_row(case=case.name, kind="floor", solver="floor", setting="-", comm_step=comm, n_steps=n,
                          status="ok" if reached else "early stop", reached_stop=reached,
                          t_end=float(res["time"][-1]), wall_s=wall, us_per_step=floor_us,
                          rtf=case.stop_time / wall, floor_us_per_step=floor_us, cost_ratio=1.0, repeats=done,
                          default=False))
                if pending_ref is not None and math.isclose(comm, ref_step):
                    pending_ref.update(floor_us_per_step=floor_us, cost_ratio=pending_ref["us_per_step"] / floor_us)
                    emit(pending_ref)
                    pending_ref = None
                for setting in settings_grid(comm, quick):
                    base = dict(case=case.name, kind="fmu", solver=setting.solver, setting=setting.label,
                                h_max=setting.h_max, rtol=setting.rtol, atol=setting.atol,
                                default=setting.is_default, comm_step=comm, n_steps=n)
                    values = dict(case.start_values, **setting.start_values())
                    try:
                        res, wall, pair_floor, done = paired(floor, cam, values, case.stop_time, comm, inputs,
                                                             repeats, min_time)
                    except RunError as exc:
                        emit(_row(**base, status="error", reached_stop=False, error=str(exc)))
                        continue
                    reached = _reached(res, case.stop_time, n)
                    row = _row(**base, status="ok" if reached else "early stop", reached_stop=reached,
                               t_end=float(res["time"][-1]), wall_s=wall, us_per_step=wall / n * 1e6,
                               rtf=case.stop_time / wall, repeats=done, floor_us_per_step=pair_floor / n * 1e6)
                    row["cost_ratio"] = wall / pair_floor
                    if reached:
                        row["theta_err"] = float(np.max(np.abs(res["theta"] - ref["theta"])))
                        row["omega_err"] = float(np.max(np.abs(res["omega"] - ref["omega"])))
                    emit(row)
            if pending_ref is not None:  # the reference's grid is not one of the comm steps
                emit(pending_ref)

        scene_rows, effect_rows = run_perstep(tmp, cam, py_floor, quick, say, repeats=5)
        del floor, py_floor, cam
        measured = targets.measure(fmu_path, tmp, quick)

    front = pareto(rows)
    write_csv(rows, out / "bench.csv")
    write_csv(scene_rows, out / "scenes.csv", columns=SCENE_COLUMNS)
    write_csv(effect_rows, out / "effects.csv", columns=EFFECT_COLUMNS)
    choices = choose(rows)
    write_csv(choices, out / "choices.csv", columns=CHOICE_COLUMNS)
    say("")
    say(format_choices(choices))
    say("")
    say(format_pareto(front))
    say("")
    say(target_verdict(rows))
    say(goal_verdict(scene_rows))
    for line in targets.verdict(measured):
        say(line)
    written = ", ".join(str(out / name) for name in ("bench.csv", "choices.csv", "scenes.csv", "effects.csv"))
    try:
        plot(rows, out / "bench.png")
        say(f"# wrote {written}, {out / 'bench.png'} in {time.perf_counter() - started:.0f} s")
    except ImportError as exc:  # matplotlib is optional
        say(f"# wrote {written}; no plot ({exc})")
    return rows
