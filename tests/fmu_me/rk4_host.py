"""A fixed-step Model Exchange host written here: the classical Runge-Kutta method (rk4) on cam.fmu's FMI 2.0
functions through fmpy's FMU2Model, with event handling at the completed steps (no root finding: an event the FMU
asks for is handled at the step's end). A host of another kind than fmpy's drivers: its stages set the time h / 2
apart, and it takes every status the FMU returns, warnings among them (logged with their message)."""
from __future__ import annotations

import ctypes
import tempfile
import zipfile
from pathlib import Path

import numpy as np

WARNING = 1


def run_rk4(fmu: Path, start: dict, step: float, stop: float, outputs: tuple[str, ...]) -> dict:
    """rk4 at ``step`` [s] to ``stop`` [s] from ``start``'s values; the outputs at every step, 'statuses' the
    completed steps' FMI statuses, 'log' (status, message) of every message, 'failed' the time of an error (or
    None)."""
    from fmpy import read_model_description
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import (FMU2Model, fmi2Boolean, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                           fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, fmi2StepFinishedTYPE, fmi2True)

    folder = Path(tempfile.mkdtemp(prefix="rk4_host_"))
    with zipfile.ZipFile(fmu) as archive:
        archive.extractall(folder)
    md = read_model_description(str(folder))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    log: list[tuple[int, str]] = []

    def logger(_env, _name, status, _category, message):
        log.append((status, message.decode(errors="replace") if message else ""))

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    libc = ctypes.CDLL(None)
    libc.calloc.restype, libc.calloc.argtypes = ctypes.c_void_p, (ctypes.c_size_t, ctypes.c_size_t)
    libc.free.argtypes = (ctypes.c_void_p,)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(lambda n, size: libc.calloc(n, size))
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(lambda p: libc.free(p))
    callbacks.stepFinished = fmi2StepFinishedTYPE()
    model = FMU2Model(guid=md.guid, unzipDirectory=str(folder), modelIdentifier=md.modelExchange.modelIdentifier,
                      instanceName="rk4")
    model.instantiate(callbacks=callbacks, loggingOn=True)
    n = md.numberOfContinuousStates
    buffer = (ctypes.c_double * n)()

    def states() -> np.ndarray:
        model.fmi2GetContinuousStates(model.component, buffer, n)
        return np.array(buffer)

    def rates(t: float, x: np.ndarray) -> np.ndarray:
        model.setTime(t)
        model.setContinuousStates((ctypes.c_double * n)(*x), n)
        model.fmi2GetDerivatives(model.component, buffer, n)
        return np.array(buffer)

    def settle() -> None:
        while model.newDiscreteStates()[0]:
            pass

    model.setupExperiment(startTime=0.0)
    model.enterInitializationMode()
    for name, value in start.items():
        model.setReal([vr[name]], [value])
    model.exitInitializationMode()
    settle()
    model.enterContinuousTimeMode()
    x, t, rows, statuses, failed = states(), 0.0, [], [], None
    for k in range(int(round(stop / step))):
        k1 = rates(t, x)
        k2 = rates(t + step / 2, x + step / 2 * k1)
        k3 = rates(t + step / 2, x + step / 2 * k2)
        k4 = rates(t + step, x + step * k3)
        x, t = x + step / 6 * (k1 + 2 * k2 + 2 * k3 + k4), (k + 1) * step
        model.setTime(t)
        model.setContinuousStates((ctypes.c_double * n)(*x), n)
        enter, terminate = fmi2Boolean(), fmi2Boolean()
        try:
            statuses.append(model.fmi2CompletedIntegratorStep(model.component, fmi2True, ctypes.byref(enter),
                                                              ctypes.byref(terminate)))
        except FMICallException:
            failed = t
            break
        if enter.value:
            model.enterEventMode()
            settle()
            model.enterContinuousTimeMode()
            x = states()
        rows.append((t, *model.getReal([vr[name] for name in outputs])))
    model.terminate()
    model.freeInstance()
    table = np.array(rows)
    result = {name: table[:, k + 1] for k, name in enumerate(outputs)}
    result.update(time=table[:, 0], statuses=statuses, log=log, failed=failed)
    return result
