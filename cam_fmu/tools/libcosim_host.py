"""Run an SSP file in libcosim (the Open Simulation Platform's C++ engine, through libcosimpy).

libcosim loads the FMUs into the calling process: a Python process already
holds the interpreter the pythonfmu binaries need, so no environment is
required; but the process then holds pythonfmu FMUs (see cli.exit_after_fmu):
call this in a subprocess (``python -m cam_fmu.tools.libcosim_host SSP STOP``
prints the result as JSON) or leave the process with os._exit.

This module imports nothing from cam_fmu (standard library, numpy and
libcosimpy only), so that ``python -I .../libcosim_host.py`` runs the FMUs on
their bundled code, not on a checkout's.

Notes: libcosimpy's step size is an integer number of nanoseconds (a float
1e-3 is truncated to 0); without one, libcosim takes the SSP's
``osp:FixedStepAlgorithm baseStepSize``. Values are read with a last-value
observer after each step, so row k holds the values at start + k h.
"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Dict, List, Sequence

import numpy as np


class LibcosimError(RuntimeError):
    pass


def simulate_ssp(ssp: str | Path, stop_time: float, variables: Sequence[str]) -> Dict[str, np.ndarray]:
    """Run ``ssp`` (its own step size) to ``stop_time``; return {'time', 'comp.var': array} for ``variables``."""
    try:
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimObserver import CosimObserver
        from libcosimpy._internal import get_last_error_message
        from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    except ImportError as exc:
        raise LibcosimError(f"libcosimpy is not installed (pip install libcosimpy): {exc}") from None
    start_time, step_size = _experiment(ssp)
    log_output_level(CosimLogLevel.ERROR)  # its default writes debug lines to stdout
    try:
        execution = CosimExecution.from_ssp_file(str(Path(ssp).resolve()))
    except AssertionError:
        raise LibcosimError(f"libcosim could not load {ssp}: {get_last_error_message()}") from None
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    index = {_text(info.name): info.index for info in execution.slave_infos()}
    refs: Dict[str, tuple[int, int]] = {}
    for column in variables:
        comp, _, var = column.partition(".")
        if comp not in index:
            raise LibcosimError(f"{column!r}: no instance {comp!r} in {ssp}")
        by_name = {_text(v.name): v.reference for v in execution.slave_variables(index[comp])}
        if var not in by_name:
            raise LibcosimError(f"{column!r}: {comp} has no variable {var!r}")
        refs[column] = (index[comp], by_name[var])
    h = step_size
    n = round((stop_time - start_time) / h)
    rows: List[List[float]] = []

    def read() -> List[float]:
        return [observer.last_real_values(slave, [vr])[0] for slave, vr in refs.values()]

    execution.step(1)  # libcosim initialises the system in its first call, then takes one step
    # The values at the start time are not observable after initialisation through libcosimpy:
    # rows start at start + h.
    rows.append(read())
    for _ in range(n - 1):
        if not execution.step(1):
            raise LibcosimError(f"libcosim step failed: {get_last_error_message()}")
        rows.append(read())
    data = np.array(rows)
    result = {"time": start_time + h * np.arange(1, n + 1)}
    result.update({c: data[:, j] for j, c in enumerate(refs)})
    return result


def _experiment(ssp: str | Path) -> tuple[float, float]:
    """(startTime, baseStepSize) of the SSP's DefaultExperiment (OSP annotation)."""
    import zipfile
    from xml.etree import ElementTree as ET

    with zipfile.ZipFile(ssp) as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
    start, step = 0.0, None
    for el in root.iter():
        if el.tag.endswith("}DefaultExperiment"):
            start = float(el.get("startTime", 0.0))
        if el.tag.endswith("}FixedStepAlgorithm"):
            step = float(el.get("baseStepSize"))
    if step is None:
        raise LibcosimError(f"{ssp}: no osp:FixedStepAlgorithm baseStepSize in its DefaultExperiment")
    return start, step


def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    ssp, stop, variables = args[0], float(args[1]), args[2:]
    result = simulate_ssp(ssp, stop, variables)
    print(json.dumps({k: v.tolist() for k, v in result.items()}))
    sys.stdout.flush()
    os._exit(0)  # pythonfmu 0.7.0 can abort at interpreter teardown (cli.exit_after_fmu)


if __name__ == "__main__":
    main()
