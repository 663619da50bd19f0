"""The bench's cases (scenes), solver settings and reference results."""
from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from typing import Any, Sequence

from ...experiments.scenes import find_scene
from ...physics.parameters import defaults
from ...physics.signals import constant
from ...physics.variables import INPUT_STARTS
from ...engine.solvers import SOLVERS

SOLVER_KEYS = ("solver", "h_max", "rtol", "atol", "max_steps")
FIXED_STEP_H = (1e-3, 2.5e-4, 1e-4)  # s, h_max of euler, rk4, etdrk4
RK45_RTOL = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10)  # atol = rtol / 100 (1e-10 is the default)
# each adaptive solver's rtol grid: rk23 (third order) is for loose tolerances, where it is cheaper than rk45
ADAPTIVE_RTOL = {"rk45": RK45_RTOL, "rk23": (1e-5, 1e-6, 1e-7, 1e-8)}
ADAPTIVE_RTOL_QUICK = {"rk45": (1e-6, 1e-10), "rk23": (1e-6,)}
COMM_STEPS = (1e-4, 1e-3, 1e-2)  # s
# the last three: followers of their own; spring_jump is the speed drive's (its theta is imposed: ranked by s)
CASES = ("fig6", "backlash", "inductance", "groove_voltage", "spring_voltage", "spring_jump")
# the error each case is ranked by and its accuracy levels in the choice table: theta [rad], or s [m] where the
# drive imposes theta
LEVELS = {"theta_err": (1e-3, 1e-6, 1e-8), "s_err": (1e-5, 1e-8, 1e-11)}

# shipped scenes and the run measured (None: the primary one); spring_jump's above_1.02 lifts off the cam
CASE_SCENES = {"fig6": ("paper_fig6", None), "backlash": ("backlash", None), "inductance": ("inductance", None),
               "groove_voltage": ("groove_voltage", None), "spring_voltage": ("spring_voltage", None),
               "spring_jump": ("spring_jump", "above_1.02")}

# the CSV columns: report.COLUMNS


@dataclass
class Case:
    name: str
    start_values: dict[str, Any]  # FMU start values (no solver settings)
    u: Any  # signals.Signal
    stop_time: float
    source: str  # scene name and run
    omega_ref: Any = None  # signals.Signal of the speed drive's input (None: the voltage drive)


@functools.lru_cache(maxsize=None)
def error_column(case: str) -> str:
    """'s_err' for a case whose input is omega_ref (the speed drive: its theta is the input's integral, exact),
    else 'theta_err'."""
    return "s_err" if case in CASE_SCENES and find_scene(CASE_SCENES[case][0]).omega_ref is not None else "theta_err"


def load_cases(names: Sequence[str]) -> list[Case]:
    """The benchmark cases: a run (CASE_SCENES) of each shipped scene, in the voltage or the speed drive."""
    cases = []
    for name in names:
        scene_name, label = CASE_SCENES[name]
        scene = find_scene(scene_name)
        run = scene.primary if label is None else next(r for r in scene.runs if r.label == label)
        values = {k: v for k, v in run.start_values().items() if k not in SOLVER_KEYS}
        values["drive"] = scene.drive
        cases.append(Case(name, values, scene.u or constant(INPUT_STARTS["u"]), scene.stop_time,
                          scene.name + ("" if label is None else f" {label}"), scene.omega_ref))
    return cases


@dataclass(frozen=True)
class Setting:
    solver: str
    h_max: float
    rtol: float
    atol: float

    @property
    def label(self) -> str:
        return f"rtol={self.rtol:g}" if SOLVERS[self.solver].adaptive else f"h={self.h_max:g}"

    @property
    def is_default(self) -> bool:
        d = defaults()
        return (self.solver, self.h_max, self.rtol, self.atol) == (d["solver"], d["h_max"], d["rtol"], d["atol"])

    def start_values(self) -> dict[str, Any]:
        return {"solver": self.solver, "h_max": self.h_max, "rtol": self.rtol, "atol": self.atol}


def settings_grid(comm_step: float, quick: bool) -> list[Setting]:
    """Solver settings run at one communication step (fixed-step h_max capped at the step, deduplicated).

    The solvers come from the registry: every fixed-step solver over FIXED_STEP_H, every
    adaptive one over its ADAPTIVE_RTOL (atol = rtol / 100).
    """
    h_default = defaults()["h_max"]
    fixed = [name for name, cls in SOLVERS.items() if not cls.adaptive]
    adaptive = [name for name, cls in SOLVERS.items() if cls.adaptive]
    if quick:
        return ([Setting(solver, min(1e-3, comm_step), 1e-10, 1e-12) for solver in fixed]
                + [Setting(solver, h_default, rtol, rtol / 100.0) for solver in adaptive
                   for rtol in ADAPTIVE_RTOL_QUICK[solver]])
    grid: list[Setting] = []
    for solver in fixed:
        for h in sorted({min(h, comm_step) for h in FIXED_STEP_H}, reverse=True):
            grid.append(Setting(solver, h, 1e-10, 1e-12))
    for solver in adaptive:
        for rtol in ADAPTIVE_RTOL[solver]:
            grid.append(Setting(solver, h_default, rtol, rtol / 100.0))
    return grid


class References:
    """simulate_reference per case, computed once on the finest grid and subsampled to coarser ones."""

    def __init__(self, comm_steps: Sequence[float]) -> None:
        self.finest = min(comm_steps)
        self.data: dict[str, tuple[float, dict]] = {}

    def compute(self, case: Case) -> tuple[float, float]:
        """Run the reference for ``case``; return (its comm step, wall time [s])."""
        from ...reference import simulate_reference

        t0 = time.perf_counter()
        ref = simulate_reference(case.start_values, case.stop_time, self.finest, **self._inputs(case, self.finest))
        wall = time.perf_counter() - t0
        self.data[case.name] = (self.finest, ref)
        return self.finest, wall

    @staticmethod
    def _inputs(case: Case, comm_step: float) -> dict:
        """The reference's inputs: fmpy holds each input over a communication step, so the reference sees the
        same staircase."""
        given = {"u": case.u} if case.omega_ref is None else {"u": case.u, "omega_ref": case.omega_ref}
        return {name: sig if len(sig.breaks) <= 1 else sig.sampled(comm_step, case.stop_time)
                for name, sig in given.items()}

    def get(self, case: Case, comm_step: float) -> dict:
        import numpy as np

        step, ref = self.data[case.name]
        ratio = comm_step / step
        if abs(ratio - round(ratio)) < 1e-9 and all(len(sig.breaks) <= 1 for sig in (case.u, case.omega_ref)
                                                    if sig is not None):   # no staircase to sample again
            k = int(round(ratio))
            return {name: values[::k] for name, values in ref.items()}
        from ...reference import simulate_reference

        return simulate_reference(case.start_values, case.stop_time, comm_step, **self._inputs(case, comm_step))
