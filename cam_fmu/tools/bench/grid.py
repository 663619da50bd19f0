"""The error grid: every solver over a grid of settings and communication steps, cam.fmu through fmpy.

For every solver over a grid of internal settings (fixed-step solvers: h_max; rk45: rtol with atol =
rtol / 100) and communication steps, on the scenes paper_fig6, backlash, inductance, groove_voltage,
spring_voltage and spring_jump (the speed drive's follower lifting off; ``cases.py``), cam.fmu runs through
``fmpy.simulate_fmu`` (one instance, reset between runs, best of a few repeats); per run:

- ``theta_err`` [rad], ``omega_err`` [rad/s]: max |FMU - reference| over the communication points, the
  reference being ``reference.simulate_reference`` (scipy, rtol 1e-12; its own theta accuracy is ~1e-9 rad);
  empty for the speed drive, whose theta and omega are its input's (imposed, exact);
- ``s_err`` [m]: the same for the follower's position s; the speed drive's cases are ranked by it;
- ``us_per_step``: wall time of the whole ``simulate_fmu`` call per communication step; ``rtf``: simulated
  seconds per wall second;
- ``cost_ratio``: us_per_step over the C floor's (``c_floor.py``: the same variables, a trivial model),
  the two run alternately (``timing.paired``). Each block (scene x comm step) starts with a floor row.

Rows of kind ``ref`` hold the scipy reference's own wall time. A run that fails with an FMI error is a row
with its message. Outputs: a printed row per run, OUT/bench.csv (with the Pareto front, column
``pareto``), OUT/choices.csv (the cheapest setting per accuracy level) and OUT/bench.png.
"""
from __future__ import annotations

import math
import sys

from .cases import CASES, COMM_STEPS, References, load_cases, settings_grid
from .report import (CHOICE_COLUMNS, HEADER, _row, choose, format_choices, format_pareto, format_row, pareto, plot,
                     write_csv)
from .timing import RunError, _reached, input_array, paired


def run(ctx) -> int:
    """The grid into OUT/bench.csv, OUT/choices.csv, OUT/bench.png; 1 when a run stopped early silently."""
    import numpy as np

    comm_steps = (1e-3,) if ctx.quick else COMM_STEPS
    cases = load_cases(ctx.cases or (("fig6",) if ctx.quick else CASES))
    repeats, floor_repeats, min_time = 3, 5, 1.0
    floor, cam = ctx.runner("c_floor"), ctx.runner("cam")
    refs = References(comm_steps)
    rows: list[dict] = []
    ctx.say(f"# cam.fmu: {ctx.fmu}; scenes: " + ", ".join(f"{c.name} ({c.source})" for c in cases))
    ctx.say("# theta_err, omega_err, s_err: max |FMU - reference| [rad], [rad/s], [m] (the speed drive: s only); "
            "ratio: us/step over the C floor's at the same comm step; * = default settings")
    ctx.say(HEADER)

    def emit(row: dict) -> None:
        rows.append(row)
        ctx.say(format_row(row))

    for case in cases:
        ref_step, ref_wall = refs.compute(case)
        n_ref = int(round(case.stop_time / ref_step))
        pending_ref = _row(case=case.name, kind="ref", solver="scipy", setting="rtol=1e-12", comm_step=ref_step,
                           n_steps=n_ref, status="ok", reached_stop=True, t_end=case.stop_time, wall_s=ref_wall,
                           us_per_step=ref_wall / n_ref * 1e6, rtf=case.stop_time / ref_wall, repeats=1,
                           default=False)  # its ratio needs the floor at its comm step: emitted with that block
        inputs = input_array(case.u, case.stop_time, case.omega_ref)
        for comm in comm_steps:
            n = int(round(case.stop_time / comm))
            ref = refs.get(case, comm)
            res, wall, done = floor.run({}, case.stop_time, comm, inputs, floor_repeats, min_time)
            floor_us = wall / n * 1e6
            reached = _reached(res, case.stop_time, n)
            emit(_row(case=case.name, kind="floor", solver="floor", setting="-", comm_step=comm, n_steps=n,
                      status="ok" if reached else "early stop", reached_stop=reached, t_end=float(res["time"][-1]),
                      wall_s=wall, us_per_step=floor_us, rtf=case.stop_time / wall, floor_us_per_step=floor_us,
                      cost_ratio=1.0, repeats=done, default=False))
            if pending_ref is not None and math.isclose(comm, ref_step):
                pending_ref.update(floor_us_per_step=floor_us, cost_ratio=pending_ref["us_per_step"] / floor_us)
                emit(pending_ref)
                pending_ref = None
            for setting in settings_grid(comm, ctx.quick):
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
                           rtf=case.stop_time / wall, repeats=done, floor_us_per_step=pair_floor / n * 1e6,
                           cost_ratio=wall / pair_floor)
                if reached:
                    row["s_err"] = float(np.max(np.abs(res["s"] - ref["s"])))
                    if case.omega_ref is None:
                        row["theta_err"] = float(np.max(np.abs(res["theta"] - ref["theta"])))
                        row["omega_err"] = float(np.max(np.abs(res["omega"] - ref["omega"])))
                emit(row)
        if pending_ref is not None:  # the reference's grid is not one of the comm steps
            emit(pending_ref)

    front = pareto(rows)
    write_csv(rows, ctx.out / "bench.csv")
    choices = choose(rows)
    write_csv(choices, ctx.out / "choices.csv", columns=CHOICE_COLUMNS)
    ctx.say("")
    ctx.say(format_choices(choices))
    ctx.say("")
    ctx.say(format_pareto(front))
    try:
        plot(rows, ctx.out / "bench.png")
        ctx.say(f"# wrote {ctx.out / 'bench.csv'}, {ctx.out / 'choices.csv'}, {ctx.out / 'bench.png'}")
    except ImportError as exc:  # matplotlib is optional
        ctx.say(f"# wrote {ctx.out / 'bench.csv'}, {ctx.out / 'choices.csv'}; no plot ({exc})")
    silent = [r for r in rows if r["status"] == "early stop"]
    if silent:
        print(f"# {len(silent)} run(s) stopped early without an error (fmi2Discard?)", file=sys.stderr)
    return 1 if silent else 0
