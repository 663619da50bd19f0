"""`cam-fmu bench`: the speed-accuracy trade of cam.fmu, measured through fmpy.

    cam-fmu bench [--quick] [--out DIR]        # or: python -m cam_fmu.bench ...

For every solver over a grid of internal settings (fixed-step solvers: h_max;
rk45: rtol with atol = rtol / 100) and communication steps, on the scenes
paper_fig6, backlash and inductance (models/*.toml; built-in copies if a file
is missing), it runs cam.fmu through ``fmpy.simulate_fmu`` (one instance,
reset between runs, best of a few repeats) and reports per run:

- ``theta_err`` [rad], ``omega_err`` [rad/s]: max |FMU - reference| over the
  communication points, the reference being ``reference.simulate_reference``
  (scipy, rtol 1e-12; its own theta accuracy is ~1e-8 rad, so smaller errors
  are not resolved);
- ``us_per_step``: wall time of the whole ``simulate_fmu`` call (set-up,
  initialisation, the step loop with input setting and output recording) per
  communication step; ``rtf``: simulated seconds per wall second;
- ``cost_ratio``: us_per_step / the floor's us_per_step at the same
  communication step. The floor is a trivial pythonfmu slave with the same
  inputs and outputs whose do_step only returns True, built into a temporary
  folder under a unique module name and timed in the same process, just before
  each FMU run (alternating, best of the repeats of each): what fmpy +
  pythonfmu cost with no model at all. Each block of runs (scene x
  communication step) also starts with a floor row of its own.

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

Timing on a shared machine is noisy: compare ratios measured in the same run,
not absolute times across runs. The FMU runs in this process, which already
imported the checkout's ``cam_fmu``: the FMU's slave script then uses these
modules rather than its bundled copies (same code when the FMU is up to date,
which ``ensure_fmu`` checks against the bundled sources' modification times).
"""
from __future__ import annotations

import argparse
import csv
import gc
import importlib.util
import math
import os
import subprocess
import sys
import tempfile
import time
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_FMU = ROOT / "models" / "cam.fmu"
DEFAULT_OUT = Path("out") / "bench"

SOLVER_KEYS = ("solver", "h_max", "rtol", "atol", "max_steps")
FIXED_STEP_H = (1e-3, 2.5e-4, 1e-4)  # s, h_max of euler, rk4, etdrk4
RK45_RTOL = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10)  # atol = rtol / 100 (1e-10 is the default)
COMM_STEPS = (1e-4, 1e-3, 1e-2)  # s
CASES = ("fig6", "backlash", "inductance")
LEVELS = (1e-3, 1e-6, 1e-8)  # rad: accuracy levels of the choice table
TARGET_ERR = 1e-6  # rad: the project's accuracy target at 1 ms on fig. 6
TARGET_RATIO = 3.0  # the cheapest setting meeting TARGET_ERR costs at most this x the floor

# scene file and the built-in fallback (overrides of the defaults, u = 3.5 V, 0-2 s)
CASE_SCENES = {"fig6": ("paper_fig6.toml", {}), "backlash": ("backlash.toml", {"c": 5e-4}),
               "inductance": ("inductance.toml", {"L": 1e-3})}

COLUMNS = ("case", "kind", "solver", "setting", "h_max", "rtol", "atol", "default", "comm_step", "n_steps",
           "status", "reached_stop", "t_end", "theta_err", "omega_err", "wall_s", "us_per_step", "rtf",
           "floor_us_per_step", "cost_ratio", "repeats", "error")


# =========================================================================== cases and settings
@dataclass
class Case:
    name: str
    start_values: dict[str, Any]  # FMU start values (no solver settings)
    u: Any  # signals.Signal
    stop_time: float
    source: str  # scene file or "built-in"


def load_cases(names: Sequence[str]) -> list[Case]:
    """The benchmark scenes, from models/*.toml if present (primary run), else built in."""
    from .signals import constant

    cases = []
    for name in names:
        filename, fallback = CASE_SCENES[name]
        path = ROOT / "models" / filename
        if path.is_file():
            from .scenes import load_scene

            scene = load_scene(path)
            values = {k: v for k, v in scene.primary.start_values().items() if k not in SOLVER_KEYS}
            if scene.drive != "voltage":
                raise ValueError(f"bench: scene {path} has drive {scene.drive!r}; the bench needs 'voltage'")
            values["drive"] = "voltage"
            cases.append(Case(name, values, scene.u or constant(3.5), scene.stop_time, str(path.relative_to(ROOT))))
        else:
            cases.append(Case(name, dict(fallback), constant(3.5), 2.0, "built-in"))
    return cases


@dataclass(frozen=True)
class Setting:
    solver: str
    h_max: float
    rtol: float
    atol: float

    @property
    def label(self) -> str:
        return f"rtol={self.rtol:g}" if self.solver == "rk45" else f"h={self.h_max:g}"

    @property
    def is_default(self) -> bool:
        from .parameters import defaults

        d = defaults()
        return (self.solver, self.h_max, self.rtol, self.atol) == (d["solver"], d["h_max"], d["rtol"], d["atol"])

    def start_values(self) -> dict[str, Any]:
        return {"solver": self.solver, "h_max": self.h_max, "rtol": self.rtol, "atol": self.atol}


def settings_grid(comm_step: float, quick: bool) -> list[Setting]:
    """Solver settings run at one communication step (fixed-step h_max capped at the step, deduplicated)."""
    from .parameters import defaults

    h_default = defaults()["h_max"]
    if quick:
        return [Setting("euler", min(1e-3, comm_step), 1e-10, 1e-12),
                Setting("rk4", min(1e-3, comm_step), 1e-10, 1e-12),
                Setting("etdrk4", min(1e-3, comm_step), 1e-10, 1e-12),
                Setting("rk45", h_default, 1e-6, 1e-8),
                Setting("rk45", h_default, 1e-10, 1e-12)]
    grid: list[Setting] = []
    for solver in ("euler", "rk4", "etdrk4"):
        for h in sorted({min(h, comm_step) for h in FIXED_STEP_H}, reverse=True):
            grid.append(Setting(solver, h, 1e-10, 1e-12))
    for rtol in RK45_RTOL:
        grid.append(Setting("rk45", h_default, rtol, rtol / 100.0))
    return grid


# =========================================================================== FMUs
def _load_build_module():
    spec = importlib.util.spec_from_file_location("_cam_fmu_build_for_bench", ROOT / "build_fmu.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def ensure_fmu(path: Path = DEFAULT_FMU, log: Callable[[str], None] = print) -> Path:
    """cam.fmu at ``path``, rebuilt (build_fmu.py in a subprocess) if missing or older than its sources."""
    path = Path(path)
    if path.resolve() == DEFAULT_FMU.resolve():
        build = _load_build_module()
        package_dir = ROOT / "cam_fmu"
        script = package_dir / build.SLAVE_SCRIPT
        sources = [script, ROOT / "build_fmu.py", package_dir / "fmu_xml.py"]
        sources += build.bundle_modules(package_dir, script)[0]
        newest = max(p.stat().st_mtime for p in sources if p.is_file())
        if path.is_file() and path.stat().st_mtime >= newest:
            return path
        log(f"# building {path} (missing or older than its sources)")
        with tempfile.TemporaryDirectory(prefix="cam_bench_build_", dir=path.parent) as tmp:
            dest = Path(tmp) / "cam.fmu"
            proc = subprocess.run([sys.executable, str(ROOT / "build_fmu.py"), "--dest", str(dest)],
                                  capture_output=True, text=True, cwd=ROOT, timeout=600)
            if proc.returncode != 0 or not dest.is_file():
                raise RuntimeError(f"build_fmu.py failed (exit {proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
            os.replace(dest, path)  # atomic: another process reading the old file keeps it
        return path
    if not path.is_file():
        raise FileNotFoundError(f"FMU {path} does not exist")
    return path


FLOOR_TEMPLATE = '''"""Trivial slave for the cam.fmu benchmark: same variables, do_step does nothing."""
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real


class {cls}(Fmi2Slave):
    description = "cost floor of fmpy + pythonfmu (cam_fmu bench)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for name, start in {inputs!r}:
            setattr(self, name, start)
            self.register_variable(Real(name, causality=Fmi2Causality.input,
                                        variability=Fmi2Variability.continuous))
        for name in {outputs!r}:
            setattr(self, name, 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.output,
                                        variability=Fmi2Variability.continuous, initial=Fmi2Initial.exact))

    def do_step(self, current_time, step_size):
        return True
'''


def build_floor_fmu(folder: Path) -> Path:
    """Build the trivial slave (unique module and class name) into ``folder``; return the .fmu."""
    from .simulator import INPUTS, OUTPUTS

    tag = f"{os.getpid()}_{uuid.uuid4().hex[:8]}"
    cls = f"BenchFloor_{tag}"
    script = folder / f"bench_floor_{tag}.py"
    script.write_text(FLOOR_TEMPLATE.format(cls=cls, inputs=[(n, s) for n, _u, s, _d in INPUTS],
                                            outputs=[n for n, _u, _d in OUTPUTS]), encoding="utf-8")
    proc = subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(script), "-d", str(folder)],
                          capture_output=True, text=True, cwd=folder, timeout=300)
    fmu = folder / f"{cls}.fmu"
    if proc.returncode != 0 or not fmu.is_file():
        raise RuntimeError(f"pythonfmu build of the floor slave failed:\n{proc.stdout}\n{proc.stderr}")
    return fmu


class Runner:
    """One FMU extracted and instantiated once; ``run`` resets it between runs."""

    def __init__(self, fmu: Path, workdir: Path, name: str) -> None:
        from fmpy import extract, read_model_description

        self.name = name
        self.md = read_model_description(str(fmu))
        self.unzipdir = extract(str(fmu), unzipdir=str(workdir / f"unzip_{name}"))
        self.count = 0
        self.fmu = None
        self.abandoned: list = []
        self._new_instance()

    def _new_instance(self, logging: bool = False, logger=None) -> None:
        from fmpy.fmi2 import (FMU2Slave, calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                               fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free)

        if self.fmu is not None:
            # Abandoned, never freed: after fmi2Fatal nothing may be called, and freeing a
            # pythonfmu 0.7.0 instance after an error crashes the host at exit (README, Errors).
            self.abandoned.append(self.fmu)
        self.count += 1
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier,
                             instanceName=f"{self.name}{self.count}")
        callbacks = None
        if logger is not None:
            callbacks = fmi2CallbackFunctions()
            callbacks.logger = fmi2CallbackLoggerTYPE(logger)
            callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
            callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
            try:  # fmpy's proxy formats the variadic message
                from fmpy.logging import addLoggerProxy
                from ctypes import byref
                addLoggerProxy(byref(callbacks))
            except Exception:  # noqa: BLE001
                pass
            self._callbacks = callbacks  # keep the ctypes objects alive
        self.fmu.instantiate(callbacks=callbacks, loggingOn=logging)
        self.fresh = True

    def _simulate(self, start_values, stop_time, comm_step, input_array):
        from fmpy import simulate_fmu

        if not self.fresh:
            self.fmu.reset()
        self.fresh = False
        return simulate_fmu(self.unzipdir, model_description=self.md, fmu_instance=self.fmu,
                            start_values=start_values, start_time=0.0, stop_time=stop_time,
                            output_interval=comm_step, input=input_array)

    def run(self, start_values, stop_time, comm_step, input_array, repeats: int, min_time: float):
        """(result, best wall time [s], repeats done) or raise RunError with the FMU's message."""
        best, result, done = math.inf, None, 0
        total = 0.0
        while done < repeats and (done == 0 or total < min_time):
            gc.collect()
            gc.disable()
            try:
                t0 = time.perf_counter()
                result = self._simulate(start_values, stop_time, comm_step, input_array)
                wall = time.perf_counter() - t0
            except Exception as exc:  # noqa: BLE001  (an FMI error is a result, not a crash)
                gc.enable()
                raise RunError(self._error_text(exc, start_values, stop_time, comm_step, input_array)) from None
            finally:
                gc.enable()
            best = min(best, wall)
            total += wall
            done += 1
        return result, best, done

    def _error_text(self, exc, start_values, stop_time, comm_step, input_array) -> str:
        """Re-run with logging on to capture the FMU's own message; leave a fresh instance behind."""
        messages: list[str] = []

        def logger(_env, _name, status, _category, message):
            text = message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
            if status >= 3:  # fmi2Error, fmi2Fatal
                messages.append(text.strip())

        try:
            self._new_instance(logging=True, logger=logger)
            self._simulate(start_values, stop_time, comm_step, input_array)
        except Exception:  # noqa: BLE001
            pass
        self._new_instance()
        own = [m for m in messages if "PyObject_CallMethod" not in m and "Fatal py exception" not in m]
        return (own[0] if own else f"{type(exc).__name__}: {exc}").replace("\n", " ")


class RunError(RuntimeError):
    pass


def input_array(u, stop_time: float):
    """fmpy input table for a voltage-drive signal (omega_ref, omega_dot_ref held at their start values)."""
    from .engines import signals_table

    return signals_table({"u": u}, stop_time)


# =========================================================================== reference
class References:
    """simulate_reference per case, computed once on the finest grid and subsampled to coarser ones."""

    def __init__(self, comm_steps: Sequence[float]) -> None:
        self.finest = min(comm_steps)
        self.data: dict[str, tuple[float, dict]] = {}

    def compute(self, case: Case) -> tuple[float, float]:
        """Run the reference for ``case``; return (its comm step, wall time [s])."""
        from .reference import simulate_reference

        t0 = time.perf_counter()
        ref = simulate_reference(case.start_values, case.stop_time, self.finest, u=self._u(case, self.finest))
        wall = time.perf_counter() - t0
        self.data[case.name] = (self.finest, ref)
        return self.finest, wall

    @staticmethod
    def _u(case: Case, comm_step: float):
        # fmpy holds each input over a communication step: the reference sees the same staircase
        return case.u if len(case.u.breaks) <= 1 else case.u.sampled(comm_step, case.stop_time)

    def get(self, case: Case, comm_step: float) -> dict:
        import numpy as np

        step, ref = self.data[case.name]
        ratio = comm_step / step
        if abs(ratio - round(ratio)) < 1e-9 and len(case.u.breaks) <= 1:
            k = int(round(ratio))
            return {name: values[::k] for name, values in ref.items()}
        from .reference import simulate_reference

        return simulate_reference(case.start_values, case.stop_time, comm_step, u=self._u(case, comm_step))


# =========================================================================== the bench
def _fmt(value, spec: str, width: int) -> str:
    if value is None or value == "" or (isinstance(value, float) and math.isnan(value)):
        return f"{'-':>{width}}"
    return f"{value:>{width}{spec}}"


HEADER = (f"{'case':<11}{'kind':<6}{'solver':<7}{'setting':<12}{'comm[s]':>8}{'theta_err':>11}{'omega_err':>11}"
          f"{'us/step':>10}{'RTF':>9}{'ratio':>8}  status")


def format_row(row: dict) -> str:
    setting = row["setting"] + ("*" if row["default"] else "")
    return (f"{row['case']:<11}{row['kind']:<6}{row['solver']:<7}{setting:<12}{row['comm_step']:>8g}"
            f"{_fmt(row['theta_err'], '.2e', 11)}{_fmt(row['omega_err'], '.2e', 11)}"
            f"{_fmt(row['us_per_step'], '.1f', 10)}{_fmt(row['rtf'], '.3g', 9)}{_fmt(row['cost_ratio'], '.2f', 8)}"
            f"  {row['status']}" + (f": {row['error']}" if row["error"] else ""))


def _row(**values) -> dict:
    row = {name: "" for name in COLUMNS}
    row.update(values)
    return row


def run_bench(out: Path, quick: bool = False, fmu_path: Path | None = None,
              log: Callable[[str], None] | None = None) -> list[dict]:
    """Run the benchmark; write OUT/bench.csv, OUT/choices.csv and OUT/bench.png; return the rows."""
    import numpy as np

    def say(text: str) -> None:
        (log or print)(text)
        sys.stdout.flush()

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    fmu_path = ensure_fmu(Path(fmu_path) if fmu_path else DEFAULT_FMU, log=say)
    comm_steps = (1e-3,) if quick else COMM_STEPS
    cases = load_cases(("fig6",) if quick else CASES)
    repeats, floor_repeats, min_time = 3, 5, 1.0
    rows: list[dict] = []

    with tempfile.TemporaryDirectory(prefix="cam_bench_") as tmp:
        tmp = Path(tmp)
        floor_fmu = build_floor_fmu(tmp)
        floor = Runner(floor_fmu, tmp, "floor")
        cam = Runner(fmu_path, tmp, "cam")
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

        del floor, cam

    write_csv(rows, out / "bench.csv")
    choices = choose(rows)
    write_csv(choices, out / "choices.csv", columns=CHOICE_COLUMNS)
    say("")
    say(format_choices(choices))
    say("")
    say(target_verdict(rows))
    try:
        plot(rows, out / "bench.png")
        say(f"# wrote {out / 'bench.csv'}, {out / 'choices.csv'}, {out / 'bench.png'} "
            f"in {time.perf_counter() - started:.0f} s")
    except ImportError as exc:  # matplotlib is optional
        say(f"# wrote {out / 'bench.csv'}, {out / 'choices.csv'}; no plot ({exc})")
    return rows


def paired(floor: Runner, cam: Runner, values, stop_time, comm, inputs, repeats, min_time):
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


def write_csv(rows: list[dict], path: Path, columns: Sequence[str] = COLUMNS) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(columns))
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items() if k in columns})


# =========================================================================== summaries
CHOICE_COLUMNS = ("case", "comm_step", "level", "solver", "setting", "theta_err", "us_per_step", "cost_ratio")


def choose(rows: list[dict]) -> list[dict]:
    """Per case, comm step and accuracy level: the FMU run of lowest cost ratio whose theta error is below it."""
    choices = []
    keys = sorted({(r["case"], r["comm_step"]) for r in rows if r["kind"] == "fmu"},
                  key=lambda k: (CASES.index(k[0]) if k[0] in CASES else 99, k[1]))
    for case, comm in keys:
        runs = [r for r in rows if r["kind"] == "fmu" and r["case"] == case and r["comm_step"] == comm
                and r["status"] == "ok" and r["theta_err"] != ""]
        for level in LEVELS:
            good = [r for r in runs if r["theta_err"] < level]
            best = min(good, key=lambda r: r["cost_ratio"]) if good else None
            choices.append({"case": case, "comm_step": comm, "level": level,
                            "solver": best["solver"] if best else "none",
                            "setting": best["setting"] if best else "",
                            "theta_err": best["theta_err"] if best else "",
                            "us_per_step": best["us_per_step"] if best else "",
                            "cost_ratio": best["cost_ratio"] if best else ""})
    return choices


def format_choices(choices: list[dict]) -> str:
    lines = ["# cheapest setting per accuracy level (theta error < level)",
             f"{'case':<11}{'comm[s]':>8}{'level':>8}  {'solver':<7}{'setting':<12}{'theta_err':>11}"
             f"{'us/step':>10}{'ratio':>8}"]
    for c in choices:
        lines.append(f"{c['case']:<11}{c['comm_step']:>8g}{c['level']:>8g}  {c['solver']:<7}{c['setting']:<12}"
                     f"{_fmt(c['theta_err'], '.2e', 11)}{_fmt(c['us_per_step'], '.1f', 10)}"
                     f"{_fmt(c['cost_ratio'], '.2f', 8)}")
    return "\n".join(lines)


def target_verdict(rows: list[dict]) -> str:
    """The project's target at 1 ms on fig. 6, in words and numbers."""
    runs = [r for r in rows if r["kind"] == "fmu" and r["case"] == "fig6" and math.isclose(r["comm_step"], 1e-3)]
    if not runs:
        return "# target: no fig6 runs at 1 ms"
    default = [r for r in runs if r["default"]]
    parts = []
    if default and default[0]["status"] == "ok":
        d = default[0]
        parts.append(f"default ({d['solver']} {d['setting']}) theta error {d['theta_err']:.2e} rad "
                     f"{'<' if d['theta_err'] < TARGET_ERR else '>='} {TARGET_ERR:g}: "
                     f"{'met' if d['theta_err'] < TARGET_ERR else 'NOT met'}, {d['us_per_step']:.1f} us/step, "
                     f"ratio {d['cost_ratio']:.2f}")
    else:
        parts.append("default settings: no successful run")
    good = [r for r in runs if r["status"] == "ok" and r["theta_err"] != "" and r["theta_err"] < TARGET_ERR]
    if good:
        best = min(good, key=lambda r: r["cost_ratio"])
        ok = best["cost_ratio"] <= TARGET_RATIO
        parts.append(f"cheapest setting with theta error < {TARGET_ERR:g} rad: {best['solver']} {best['setting']} "
                     f"({best['theta_err']:.2e} rad), {best['us_per_step']:.1f} us/step = {best['cost_ratio']:.2f}x "
                     f"the floor ({best['floor_us_per_step']:.1f} us/step): "
                     f"{'met' if ok else 'NOT met'} (target <= {TARGET_RATIO:g}x)")
    else:
        parts.append(f"no setting reaches theta error < {TARGET_ERR:g} rad")
    return "# target (fig6, 1 ms): " + "; ".join(parts)


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    cases = [c for c in CASES if any(r["case"] == c for r in rows)]
    colors = {"euler": "tab:red", "rk4": "tab:blue", "etdrk4": "tab:green", "rk45": "tab:purple"}
    markers = {1e-4: "o", 1e-3: "s", 1e-2: "^"}
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 4.6), squeeze=False)
    for ax, case in zip(axes[0], cases):
        runs = [r for r in rows if r["case"] == case and r["kind"] == "fmu" and r["status"] == "ok"
                and r["theta_err"] != ""]
        for solver, color in colors.items():
            for comm in sorted({r["comm_step"] for r in runs}):
                # in grid order (coarse to fine setting), not sorted by cost
                pts = [(r["cost_ratio"], max(r["theta_err"], 1e-10)) for r in runs
                       if r["solver"] == solver and r["comm_step"] == comm]
                if pts:
                    ax.loglog(*zip(*pts), color=color, marker=markers.get(comm, "x"), linewidth=1.2,
                              label=f"{solver}, comm {comm:g} s")
        ax.axhline(TARGET_ERR, color="k", linestyle="--", linewidth=0.8)
        ax.axhspan(1e-10, 1e-8, color="0.9", zorder=0)
        ax.set_ylim(1e-10, None)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.text(0.02, 0.02, "below the reference's own accuracy (~1e-8 rad)", transform=ax.transAxes,
                fontsize=7, color="0.4")
        ax.set_title(f"{case}")
        ax.set_xlabel("cost ratio (us per comm step / trivial slave's)")
        ax.set_ylabel("max |theta - theta_ref| [rad]")
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=7, frameon=False)
    fig.suptitle("cam.fmu through fmpy: theta error against cost (dashed: 1e-6 rad target)")
    fig.tight_layout(rect=(0, 0.12, 1, 0.95))
    fig.savefig(path, dpi=110)
    plt.close(fig)
