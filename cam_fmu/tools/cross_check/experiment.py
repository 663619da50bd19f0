"""The experiment every cross-check folder records: the paper's fig. 6 start-up, delayed by a step of u.

The drive rests with u = 0 V for STEP_TIME, then u steps to the fig. 6 scene's
voltage (3.5 V) and the scene runs its full duration: the reference depends on the
input file (a run that ignores it starts 0.5 s early). Other inputs are held at
their start values. Parameters stay at the FMU's defaults (an importer sets none),
which are the fig. 6 scene's parameters (tested).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

STEP_TIME = 0.5  # s: u = 0 V before, the scene's voltage from here on
STEP_INPUT = "u"  # the input that steps
OUTPUTS = ("omega", "theta", "s", "i", "M")  # the reference's columns (the rules advise at most 10)
REL_TOL = 1e-6  # passed to the importer: CVode's rtol (model exchange), fmi2SetupExperiment's (co-simulation)


@dataclass(frozen=True)
class Experiment:
    """What the reference run does [s, V]."""

    scene: str
    stop_time: float
    step_size: float  # communication step (co-simulation) and output interval
    u_after: float
    step_time: float = STEP_TIME
    rel_tol: float = REL_TOL


def fig6_experiment() -> Experiment:
    """The experiment from the shipped scene paper_fig6: its voltage, its duration plus the rest before
    the step, its output interval."""
    from ...experiments.scenes import find_scene

    scene = find_scene("paper_fig6")
    if scene.u is None or len(set(scene.u.values)) != 1:
        raise ValueError("scene 'paper_fig6': the cross-check expects a constant voltage u")
    return Experiment(scene.name, STEP_TIME + scene.stop_time, scene.output_interval, scene.u.values[0])


def input_table(md: Any, exp: Experiment) -> np.ndarray | None:
    """fmpy's structured input array (time, then every input of the model description ``md``) or None
    for a model without inputs. ``u`` jumps at step_time (a repeated time stamp, as the rules' example);
    every other input is held at its start value (0 when it has none)."""
    inputs = [v for v in md.modelVariables if v.causality == "input"]
    if not inputs:
        return None
    held = {v.name: float(v.start) if v.start is not None else 0.0 for v in inputs}

    def row(t: float, u: float) -> tuple[float, ...]:
        return (t, *(u if name == STEP_INPUT else held[name] for name in held))

    rows = [row(0.0, 0.0), row(exp.step_time, 0.0), row(exp.step_time, exp.u_after), row(exp.stop_time, exp.u_after)]
    return np.array(rows, dtype=[("time", np.float64)] + [(name, np.float64) for name in held])


def reference_outputs(md: Any) -> list[str]:
    """The reference's columns: OUTPUTS the model has, in that order; a model with none of them gets its
    first five outputs."""
    names = [v.name for v in md.modelVariables if v.causality == "output"]
    chosen = [name for name in OUTPUTS if name in names]
    return chosen or names[:5]


def opt_lines(exp: Experiment, fmi_type: str) -> list[str]:
    """The ``{model}_ref.opt`` lines (``Name, value``; fmpy's reader takes no comments). Model exchange
    runs CVode, a variable-step solver: StepSize 0 (the rules' convention) and the output grid in
    OutputIntervalLength."""
    step = exp.step_size if fmi_type == "cs" else 0.0
    return [f"StartTime, {0.0!r}", f"StopTime, {exp.stop_time!r}", f"StepSize, {step!r}",
            f"RelTol, {exp.rel_tol!r}", f"OutputIntervalLength, {exp.step_size!r}"]


def simulate(fmu: str, fmi_type: str, opts: dict[str, float], inputs: np.ndarray | None,
             outputs: list[str]) -> np.ndarray:
    """One run of ``fmu`` through fmpy as an importer runs a cross-check entry: from the ``_ref.opt``
    values ``opts`` (StopTime, StepSize, RelTol, OutputIntervalLength) and the ``_in.csv`` table."""
    from fmpy import simulate_fmu

    interval = opts.get("OutputIntervalLength") or opts["StepSize"]
    kwargs: dict[str, Any] = {}
    if fmi_type == "me":
        kwargs["solver"] = "CVode"
    return simulate_fmu(fmu, fmi_type="CoSimulation" if fmi_type == "cs" else "ModelExchange",
                        start_time=opts["StartTime"], stop_time=opts["StopTime"], output_interval=interval,
                        relative_tolerance=opts["RelTol"], input=inputs, output=outputs, **kwargs)
