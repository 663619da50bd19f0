"""The one fmpy runner: an FMU extracted and instantiated once, reset between runs.

Used by the scene runner and the bench. fmpy's default path instantiates and
frees an instance per run; this one keeps the library loaded and the
instance alive. An instance that failed is abandoned, never freed: freeing a
pythonfmu 0.7.0 instance after an error crashes the host at exit.

Every instance gets this runner's own logger: the FMU's error and discard
messages are kept (``messages``), never printed (fmpy's default logger prints
``[ERROR] ...`` lines on stdout), and a failed run raises FmuRunError whose text
is the FMU's own message (the cause), followed by fmpy's status line.

FMI 2.0 and 3.0 co-simulation FMUs run alike (cam.fmu, cam3.fmu: fmpy's FMU2Slave or FMU3Slave); any
other FMU is refused at construction with a message naming its FMI version and interfaces (``check_runnable``).
"""
from __future__ import annotations

import math
import tempfile
from pathlib import Path
from typing import Any, Callable, Sequence


class FmuRunError(RuntimeError):
    """A run that failed or stopped early; the message is the FMU's own where it gave one."""


SUPPORTED = ("2.0", "3.0")  # FMI versions run, co-simulation only


def check_runnable(md: Any, where: str) -> None:
    """FmuRunError unless the model description ``md`` (fmpy's) is an FMI 2.0 or 3.0 co-simulation FMU."""
    version = str(md.fmiVersion)
    if version not in SUPPORTED:
        raise FmuRunError(f"{where}: an FMI {version} FMU; runnable are FMI 2.0 and 3.0 co-simulation FMUs "
                          "(cam.fmu, cam3.fmu)")
    if md.coSimulation is None:
        raise FmuRunError(f"{where}: an FMI {version} FMU without co-simulation (Model Exchange only); runnable are "
                          "co-simulation FMUs")


class FmuRunner:
    """``simulate`` runs the FMU from 0 to stop_time through fmpy.simulate_fmu."""

    def __init__(self, fmu: str | Path, workdir: str | Path | None = None, name: str = "cam") -> None:
        from fmpy import extract, read_model_description

        self.name = name
        self.fmu_path = Path(fmu)
        self.md = read_model_description(str(fmu))
        check_runnable(self.md, str(fmu))
        self.fmi3 = str(self.md.fmiVersion) == "3.0"
        self._tmp = None
        if workdir is None:
            self._tmp = tempfile.TemporaryDirectory(prefix="cam_fmu_run_")
            workdir = self._tmp.name
        self.unzipdir = extract(str(fmu), unzipdir=str(Path(workdir) / f"unzip_{name}"))
        self.count = 0
        self.fmu = None
        self.abandoned: list = []
        self.messages: list[str] = []  # the FMU's messages of status fmi2Discard and worse, this run
        self._new_instance(logger=self._collect)

    def _collect(self, _env: Any, _name: Any, status: int, _category: Any, message: Any) -> None:
        if status >= 2:  # fmi2Discard, fmi2Error, fmi2Fatal
            text = message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
            self.messages.append(" ".join(text.split()))

    def _new_instance(self, logging: bool = False, logger: Callable | None = None) -> None:
        from fmpy.fmi2 import (FMU2Slave, calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                               fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free)

        if self.fmu is not None:
            self.abandoned.append(self.fmu)
        self.count += 1
        if self.fmi3:
            from fmpy.fmi3 import FMU3Slave

            self.fmu = FMU3Slave(guid=self.md.guid, unzipDirectory=self.unzipdir,
                                 modelIdentifier=self.md.coSimulation.modelIdentifier,
                                 instanceName=f"{self.name}{self.count}")
            log3 = None
            if logger is not None:  # fmi3LogMessageCallback(env, status, category, message): the same statuses
                def log3(env: Any, status: int, category: Any, message: Any) -> None:
                    logger(env, None, status, category, message)
            self.fmu.instantiate(loggingOn=logging, logMessage=log3)
            self.fresh = True
            return
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
                from ctypes import byref

                from fmpy.logging import addLoggerProxy
                addLoggerProxy(byref(callbacks))
            except Exception:  # noqa: BLE001
                pass
            self._callbacks = callbacks  # keep the ctypes objects alive
        self.fmu.instantiate(callbacks=callbacks, loggingOn=logging)
        self.fresh = True

    def simulate(self, start_values: dict[str, Any], stop_time: float, output_interval: float, inputs: Any,
                 outputs: Sequence[str] | None = None, check_end: bool = False,
                 on_step: Callable[[float], None] | None = None) -> Any:
        """fmpy's result array; ``check_end``: raise FmuRunError when the run stopped before stop_time;
        ``on_step(time)``: called after every communication step (progress)."""
        from fmpy import simulate_fmu

        if not self.fresh:
            self.fmu.reset()
        self.fresh = False
        self.messages.clear()
        reached = [0.0]

        def step_finished(time: float, _recorder: Any) -> bool:
            reached[0] = time
            if on_step is not None:
                on_step(time)
            return True

        try:
            result = simulate_fmu(self.unzipdir, model_description=self.md, fmu_instance=self.fmu,
                                  start_values=start_values, start_time=0.0, stop_time=stop_time,
                                  output_interval=output_interval, input=inputs,
                                  output=list(outputs) if outputs is not None else None,
                                  step_finished=step_finished if check_end or on_step is not None else None)
        except Exception as exc:  # noqa: BLE001 - fmpy's FMICallException and friends: the FMU's cause first
            self._new_instance(logger=self._collect)  # the failed instance is abandoned (module docstring)
            raise FmuRunError(self._cause(str(exc))) from exc
        if check_end and not math.isclose(reached[0], stop_time, rel_tol=1e-9, abs_tol=1e-12):
            raise FmuRunError(self._cause(f"the FMU stopped at t = {reached[0]:g} s before stop_time = "
                                          f"{stop_time:g} s"))
        return result

    def _cause(self, what: str) -> str:
        """The FMU's own messages of this run (the cause), then ``what`` happened, on one line."""
        own = [m for m in dict.fromkeys(self.messages) if "PyObject_CallMethod" not in m]
        return "; ".join(own + [what]) if own else what

    def error_text(self, exc: BaseException, *args: Any, **kwargs: Any) -> str:
        """Re-run with logging on to capture the FMU's own message; leave a fresh instance behind."""
        messages: list[str] = []

        def logger(_env, _name, status, _category, message):
            text = message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
            if status >= 3:  # fmi2Error, fmi2Fatal
                messages.append(text.strip())

        try:
            self._new_instance(logging=True, logger=logger)
            self.simulate(*args, **kwargs)
        except Exception:  # noqa: BLE001
            pass
        self._new_instance(logger=self._collect)
        own = [m for m in messages if "PyObject_CallMethod" not in m and "Fatal py exception" not in m]
        return (own[0] if own else f"{type(exc).__name__}: {exc}").replace("\n", " ")
