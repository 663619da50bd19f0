"""`cam-fmu bench`: what cam.fmu costs per communication step and how accurate each solver setting is.

Each benchmark is one module with ``run(ctx: Context) -> int`` (0, or 1 when a run went wrong without an
error) and one line in ``BENCHMARKS``. A benchmark reports ratios against a baseline measured in the same
run (the C floor FMU, the defaults, the gcc build): timings on a shared machine move, their ratios less.
"""
from __future__ import annotations

import importlib
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

# name: (module, in a plain `cam-fmu bench`, what it measures)
BENCHMARKS = {
    "grid": ("grid", True, "theta error (s error in the speed drive) and cost ratio of every solver setting x comm "
                           "step (fig6, backlash, inductance, groove_voltage, spring_voltage, spring_jump)"),
    "scenes": ("scenes", True, "us per step of cam.fmu and the C floor on every shipped scene at the defaults"),
    "effects": ("effects", True, "us per step of fig. 6 with each effect switched"),
    "loops": ("loops", True, "tight loops: a C host, fmpy's FMU2Slave, one in-process run"),
    "memory": ("memory", False, "RSS over a long run through FMU2Slave"),
    "toolchain": ("toolchain", False, "cam.fmu's binary from zig against the system gcc's"),
    "fmi3_me": ("fmi3_me", False, "FMI 3.0 Model Exchange (cam3.fmu) against FMI 2.0's (cam.fmu) in fmpy"),
    "jacobian": ("jacobian", False, "stiff runs (L = 1 mH, rigid and compliant) and a run through events (backlash, "
                                    "closure form) under scipy's BDF and Radau with cam.fmu's directional derivatives "
                                    "against differencing: right-hand sides, wall"),
    "train": ("train", False, "the follower train's cost against the rigid drive, per run and per internal step "
                              "(in-process, voltage drive under rk45, rk4, rk23; speed drive)"),
    "kinds": ("kinds", False, "each follower type's cost against the translating roller's, per run and per internal "
                              "step (in-process, voltage drive, rk45)"),
}
DEFAULT = tuple(name for name, (_m, default, _w) in BENCHMARKS.items() if default)


@dataclass
class Context:
    """What every benchmark is given: the FMU measured, the output folder, a temporary folder, the C floor."""

    fmu: Path
    out: Path
    tmp: Path
    quick: bool
    say: Callable[[str], None]
    cases: tuple[str, ...] = ()   # the grid's cases (cases.CASES); empty: all of them (fig6 with quick)
    _runners: dict = field(default_factory=dict)

    def c_floor(self) -> Path:
        """The C floor FMU (``c_floor.py``), built once per run."""
        if "c_floor_fmu" not in self._runners:
            from .c_floor import build_c_floor_fmu
            self._runners["c_floor_fmu"] = build_c_floor_fmu(self.tmp)
        return self._runners["c_floor_fmu"]

    def runner(self, name: str):
        """A TimedRunner of 'cam' (the FMU measured) or 'c_floor', one per run (its instance is reused)."""
        if name not in self._runners:
            from .timing import TimedRunner
            self._runners[name] = TimedRunner(self.fmu if name == "cam" else self.c_floor(), self.tmp, name)
        return self._runners[name]


def run(names: Sequence[str], out: Path, quick: bool = False, fmu_path: Path | None = None,
        log: Callable[[str], None] | None = None, cases: Sequence[str] = ()) -> int:
    """Run the benchmarks ``names`` (keys of BENCHMARKS, in their order) into ``out``, the grid on ``cases`` (empty:
    its default); 0, or 1 when one says so."""
    from ...experiments.fmu_file import check_cam_variables
    from ...fmu.build import ensure_fmu

    def say(text: str) -> None:
        (log or print)(text)
        sys.stdout.flush()

    fmu = check_cam_variables(ensure_fmu(fmu_path, log=say))  # another FMU: refused before any run
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    status = 0
    with tempfile.TemporaryDirectory(prefix="cam_bench_") as tmp:
        ctx = Context(fmu, out, Path(tmp), quick, say, tuple(cases))
        for name in names:
            say(f"\n# {name}: {BENCHMARKS[name][2]}")
            status |= importlib.import_module(f".{BENCHMARKS[name][0]}", __name__).run(ctx)
        ctx._runners.clear()  # the instances go before their folder
    return status
