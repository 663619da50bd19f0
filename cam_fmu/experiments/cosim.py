"""A fixed-step co-simulation master for SSP systems, on fmpy's FMU2Slave, and its in-process twin.

``simulate_system(ssp)`` runs every component of an SSP file (ssp.read_ssp) on
one communication grid (Jacobi: every FMU steps from the same connector values):

1. instantiate each FMU, setupExperiment, apply the SSP's parameter values
   (ParameterBindings), enter initialisation mode;
2. in initialisation mode, pass every connection (output -> input) as many
   times as there are components, so that initial outputs that depend on
   inputs (the controller's initial output on cam's initial M and J) settle on
   the consistent initial values (as libcosim and ecos do); exit
   initialisation mode;
3. read every output: the connector values at the start time (the first step
   therefore sees the controller's initial output, not 0);
3. for each step from t to t + h: set each input from its connector, doStep
   every FMU, read the outputs: they are the values *at* t + h, and the row is
   labelled t + h.

This fixes what fmpy's ``simulate_ssp`` does differently (connectors start at
0.0, parameter values of the file ignored, rows labelled with the step's start
time). The loops here have no direct feedthrough (outputs change only in
doStep), so Jacobi is exact for them; ecos and libcosim use the same scheme.

``reference_loop`` is the same speed loop stepped in-process with no FMU:
fmu.engine.DriveSimulator (cam.fmu's engine) and control.pi.PiSpeedController
(pi_speed.fmu's law), in the same order with the same numbers: an independent
check of the master, the SSP, both slaves and their bundles.

The time grid is t_k = start + k h (no accumulated rounding).
"""
from __future__ import annotations

import contextlib
import math
import tempfile
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from .limits import check_steps
from ..fmu.ssp import System, SspError, extract_ssp, read_ssp

Progress = Callable[[int, int], None]


class CosimError(RuntimeError):
    """A co-simulation that could not run; the message names the component and variable."""


class CosimInterrupted(KeyboardInterrupt):
    """An interrupt (SIGINT, Ctrl-C) during simulate_system: ``result`` holds the rows up to the last completed
    communication step (the same columns as a whole run), of ``steps`` steps."""

    def __init__(self, result: dict[str, np.ndarray], steps: int) -> None:
        super().__init__(f"interrupted at t = {result['time'][-1]:g} s")
        self.result, self.steps = result, steps


@contextlib.contextmanager
def _interrupt_flag():
    """A list that gets an entry when SIGINT arrives inside the block, instead of KeyboardInterrupt: an exception
    raised inside a Python FMU's doStep (pi_speed.fmu runs in this process) turns into its fatal status, and the
    run's rows would be lost. The master checks the flag between communication steps."""
    import signal
    import threading

    seen: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield seen
        return
    previous = signal.signal(signal.SIGINT, lambda signum, _frame: seen.append(signum))
    try:
        yield seen
    finally:
        signal.signal(signal.SIGINT, previous)


def _n_steps(start: float, stop: float, h: float) -> int:
    if not (math.isfinite(h) and h > 0):
        raise CosimError(f"step size = {h!r} s: allowed (0, inf)")
    if not stop > start:
        raise CosimError(f"stop time = {stop!r} s must exceed the start time {start!r} s")
    check_steps(stop - start, h, "stop time - start time / step size", CosimError)
    n = round((stop - start) / h)
    if abs(n * h - (stop - start)) > 1e-9 * max(1.0, stop - start):
        raise CosimError(f"stop time - start time = {stop - start!r} s is not a whole number of steps h = {h!r} s")
    return n


class _Slave:
    """One FMU instance of the system (fmpy FMU2Slave) with its value references by name."""

    def __init__(self, name: str, unzipdir: Path) -> None:
        from fmpy import read_model_description
        from fmpy.fmi2 import FMU2Slave

        self.name = name
        self.md = read_model_description(str(unzipdir))
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=str(unzipdir),
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()

    def var(self, name: str, causality: str | None = None):
        v = self.vars.get(name)
        if v is None:
            raise CosimError(f"component {self.name!r} has no variable {name!r}; it has: "
                             + ", ".join(sorted(self.vars)))
        if causality and v.causality != causality:
            raise CosimError(f"{self.name}.{name} is a {v.causality}, not an {causality}")
        return v

    def set_parameter(self, name: str, value: Any) -> None:
        v = self.var(name)
        if v.type == "Boolean":
            self.fmu.setBoolean([v.valueReference], [bool(value)])
        elif v.type == "String":
            self.fmu.setString([v.valueReference], [str(value)])
        elif v.type == "Integer":
            self.fmu.setInteger([v.valueReference], [int(value)])
        else:
            self.fmu.setReal([v.valueReference], [float(value)])


def simulate_system(ssp: str | Path | System, stop_time: float | None = None, step_size: float | None = None,
                    record: Sequence[str] | None = None, progress: Progress | None = None,
                    workdir: str | Path | None = None) -> dict[str, np.ndarray]:
    """Run the SSP; return {'time': t, 'comp.var': values} for every connector (and ``record``: 'comp.var')."""
    system = ssp if isinstance(ssp, System) else read_ssp(ssp)
    if system.path is None:
        raise SspError("simulate_system needs a System read from a file (its FMUs)")
    start = system.start_time
    stop = system.stop_time if stop_time is None else float(stop_time)
    h = system.step_size if step_size is None else float(step_size)
    n = _n_steps(start, stop, h)
    tmp = tempfile.TemporaryDirectory(prefix="cam_fmu_cosim_") if workdir is None else None
    root = extract_ssp(system.path, Path(tmp.name if tmp else workdir) / "ssp")
    slaves: dict[str, _Slave] = {}
    for comp in system.components.values():
        slave = _Slave(comp.name, _unzip(root / comp.source, root / "fmus" / comp.name))
        slave.fmu.setupExperiment(startTime=start, stopTime=stop)
        for pname, value in comp.parameters.items():
            slave.set_parameter(pname, value)
        slaves[comp.name] = slave
    for slave in slaves.values():
        slave.fmu.enterInitializationMode()
    wires = [(slaves[c.end_element], slaves[c.end_element].var(c.end_connector, "input").valueReference,
              f"{c.start_element}.{c.start_connector}") for c in system.connections]
    names = [f"{c.start_element}.{c.start_connector}" for c in system.connections]
    names += [r for r in (record or []) if r not in names]
    readers: dict[str, list] = {}  # component -> [(column, vr)]
    for column in dict.fromkeys(names):
        comp, _, var = column.partition(".")
        if comp not in slaves:
            raise CosimError(f"{column!r}: no component {comp!r}; components: {', '.join(slaves)}")
        readers.setdefault(comp, []).append((column, slaves[comp].var(var).valueReference))
    columns = [c for pairs in readers.values() for c, _ in pairs]
    data = np.empty((n + 1, len(columns)))
    sources = {f"{c.start_element}.{c.start_connector}": (slaves[c.start_element],
               slaves[c.start_element].var(c.start_connector).valueReference) for c in system.connections}
    for _ in range(len(slaves)):  # initial values through the connections (see step 2)
        for slave, vr, src in wires:
            src_slave, src_vr = sources[src]
            slave.fmu.setReal([vr], src_slave.fmu.getReal([src_vr]))
    for slave in slaves.values():
        slave.fmu.exitInitializationMode()

    def read() -> dict[str, float]:
        values: dict[str, float] = {}
        for comp, pairs in readers.items():
            got = slaves[comp].fmu.getReal([vr for _, vr in pairs])
            values.update(zip((c for c, _ in pairs), got))
        return values

    values = read()
    data[0] = [values[c] for c in columns]
    done = n
    with _interrupt_flag() as interrupt:
        for k in range(n):
            if interrupt:
                done = k
                break
            t = start + k * h
            for slave, vr, src in wires:
                slave.fmu.setReal([vr], [values[src]])
            for slave in slaves.values():
                slave.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            values = read()
            data[k + 1] = [values[c] for c in columns]
            if progress is not None:
                progress(k + 1, n)
    for slave in slaves.values():
        slave.fmu.terminate()  # no fmi2FreeInstance: see runner._fmu_runs (pythonfmu 0.7.0 at exit)
    result = {"time": start + h * np.arange(done + 1)}
    result.update({c: data[:done + 1, j] for j, c in enumerate(columns)})
    if done < n:
        raise CosimInterrupted(result, n)
    return result


def _unzip(fmu: Path, dest: Path) -> Path:
    from fmpy import extract

    return Path(extract(str(fmu), unzipdir=str(dest)))


# ------------------------------------------------------------------ in-process twin
def reference_loop(system: System, stop_time: float | None = None, step_size: float | None = None,
                   progress: Progress | None = None) -> dict[str, np.ndarray]:
    """The speed loop of ``system`` (components 'cam' and 'controller') without FMUs, same scheme and columns."""
    from ..control.pi import INPUTS as CTRL_INPUTS, PiSpeedController
    from ..fmu.engine import DriveSimulator
    from ..physics.parameters import resolve
    from ..physics.variables import INPUT_STARTS

    if set(system.components) != {"cam", "controller"}:
        raise CosimError(f"reference_loop knows the components 'cam' and 'controller', got {sorted(system.components)}")
    start = system.start_time
    stop = system.stop_time if stop_time is None else float(stop_time)
    h = system.step_size if step_size is None else float(step_size)
    n = _n_steps(start, stop, h)
    cam = DriveSimulator(resolve(system.components["cam"].parameters), start_time=start)
    cam_inputs = dict(INPUT_STARTS)
    cam.set_inputs(**cam_inputs)
    ctrl = PiSpeedController(system.components["controller"].parameters)
    ctrl_inputs = {name: start_value for name, _u, start_value, _d in CTRL_INPUTS}
    ctrl.initialize(**ctrl_inputs)

    def read() -> dict[str, float]:
        out = {f"cam.{k}": v for k, v in cam.outputs().items()}
        out.update({f"controller.{k}": v for k, v in ctrl.outputs().items()})
        return out

    for _ in range(2):  # initialisation: connections passed once per component, as the master does
        for c in system.connections:
            src = read()[f"{c.start_element}.{c.start_connector}"]
            if c.end_element == "cam":
                cam_inputs[c.end_connector] = src
                cam.set_inputs(**cam_inputs)
            else:
                ctrl_inputs[c.end_connector] = src
                ctrl.initialize(**ctrl_inputs)

    columns = list(dict.fromkeys(f"{c.start_element}.{c.start_connector}" for c in system.connections))
    values = read()
    data = np.empty((n + 1, len(columns)))
    data[0] = [values[c] for c in columns]
    for k in range(n):
        t = start + k * h
        for c in system.connections:
            target = cam_inputs if c.end_element == "cam" else ctrl_inputs
            target[c.end_connector] = values[f"{c.start_element}.{c.start_connector}"]
        cam.do_step(t, h, **cam_inputs)
        ctrl.sample(h, **ctrl_inputs)
        values = read()
        data[k + 1] = [values[c] for c in columns]
        if progress is not None:
            progress(k + 1, n)
    result = {"time": start + h * np.arange(n + 1)}
    result.update({c: data[:, j] for j, c in enumerate(columns)})
    return result


def ripple(time: np.ndarray, omega: np.ndarray, t_from: float | None = None) -> float:
    """Peak-to-peak speed ripple [rad/s] over t >= t_from (default: the second half of the run)."""
    time = np.asarray(time)
    if t_from is None:
        t_from = time[0] + 0.5 * (time[-1] - time[0])
    window = np.asarray(omega)[time >= t_from - 1e-12]
    return float(window.max() - window.min())
