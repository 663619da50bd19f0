"""One cam.fmu instance driven call by call through fmpy's FMU2Slave, with every log message kept.

For tests written against the FMI interface only (whatever engine is inside the FMU):
each call returns its FMI status instead of raising, so a test can assert the status
and the message the FMU logged with it.
"""
from __future__ import annotations

import ctypes
import zipfile
from pathlib import Path
from typing import Any

OK, WARNING, DISCARD, ERROR, FATAL = range(5)


def extract(fmu: Path, dest: Path) -> Path:
    """Unzip ``fmu`` into ``dest`` (created) and return it."""
    dest.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(dest)
    return dest


class Slave:
    """cam.fmu as an FMI 2.0 co-simulation slave. ``messages`` holds (status, category, text) of every log."""

    def __init__(self, unzipdir: Path, name: str = "probe", guid: str | None = None) -> None:
        from fmpy import read_model_description
        from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                               fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, fmi2StepFinishedTYPE)

        self.md = read_model_description(str(unzipdir))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.type = {v.name: v.type for v in self.md.modelVariables}
        self.outputs = [v.name for v in self.md.modelVariables if v.causality == "output"]
        self.messages: list[tuple[int, str, str]] = []
        self.fmu = FMU2Slave(guid=guid or self.md.guid, unzipDirectory=str(unzipdir),
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)

        def log(_env, _name, status, category, message):
            self.messages.append((status, category.decode(errors="replace") if category else "",
                                  message.decode(errors="replace") if message else ""))

        # kept on self: ctypes callbacks must outlive the instance
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = fmi2CallbackLoggerTYPE(log)
        libc = ctypes.CDLL(None)
        libc.calloc.restype = ctypes.c_void_p
        libc.calloc.argtypes = (ctypes.c_size_t, ctypes.c_size_t)
        libc.free.argtypes = (ctypes.c_void_p,)
        self._callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(lambda n, size: libc.calloc(n, size))
        self._callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(lambda p: libc.free(p))
        self._callbacks.stepFinished = fmi2StepFinishedTYPE()
        self._callbacks.componentEnvironment = None
        self.time = 0.0

    # ---------------------------------------------------------------- calls returning a status
    def call(self, function: str, *args: Any) -> int:
        """fmpy's wrapper of ``function``; its FMI status (fmpy raises from discard on)."""
        from fmpy.fmi1 import FMICallException

        try:
            getattr(self.fmu, function)(*args)
        except FMICallException as exc:
            return exc.status
        return OK

    def instantiate(self, logging: bool = False) -> bool:
        try:
            self.fmu.instantiate(callbacks=self._callbacks, loggingOn=logging)
        except Exception:  # fmpy raises when fmi2Instantiate returns NULL
            return False
        return True

    def init(self, **values: Any) -> int:
        """Instantiate (if needed), set values, setup, enter and exit initialisation."""
        if getattr(self.fmu, "component", None) is None and not self.instantiate():
            return ERROR
        status = self.set(**values)
        for function, args in (("setupExperiment", (None, 0.0)), ("enterInitializationMode", ()),
                               ("exitInitializationMode", ())):
            if status != OK:
                return status
            status = self.call(function, *args)
        self.time = 0.0
        return status

    def set(self, **values: Any) -> int:
        """Set variables by name, one call per variable, in the order given; the first non-OK status."""
        for name, value in values.items():
            kind = self.type[name]
            function = {"Real": "setReal", "Boolean": "setBoolean", "String": "setString"}[kind]
            status = self.call(function, [self.vr[name]], [value])
            if status != OK:
                return status
        return OK

    def get(self, *names: str) -> list[float]:
        return list(self.fmu.getReal([self.vr[n] for n in names]))

    def step(self, h: float, t: float | None = None) -> int:
        """fmi2DoStep from the slave's time (or ``t``) by h; the time advances on OK only."""
        start = self.time if t is None else t
        status = self.call("doStep", start, h)
        if status == OK:
            self.time = start + h
        return status

    def run(self, stop: float, h: float) -> int:
        """Steps of h until stop; the first non-OK status."""
        n = int(round((stop - self.time) / h))
        for _ in range(n):
            status = self.step(h)
            if status != OK:
                return status
        return OK

    def errors(self) -> list[str]:
        """Texts of the messages logged with status discard or worse."""
        return [text for status, _category, text in self.messages if status >= DISCARD]

    def free(self) -> None:
        if getattr(self.fmu, "component", None) is not None:
            self.fmu.freeInstance()
            self.fmu.component = None
