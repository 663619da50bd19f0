"""Blocks users write in Python, as FMUs: pythonfmu packs a slave script, ``cam-fmu cosim --controller``
runs it beside cam.fmu.

    cam-fmu python-block [SCRIPT] --dest out/python_pi.fmu

The shipped example is ``examples/python_pi_slave.py`` (a PI speed controller; its docstring says what a
machine running the FMU needs). Build time: pythonfmu only; the FMU it makes carries pythonfmu's binary,
which embeds CPython (docs/fmu.md, "Blocks written in Python").
"""
from __future__ import annotations

from pathlib import Path

EXAMPLE = Path(__file__).resolve().parent / "examples" / "python_pi_slave.py"


class PythonBlockError(RuntimeError):
    """The block could not be built; the message says why."""


def build(dest: Path, script: Path = EXAMPLE) -> Path:
    """Pack the pythonfmu slave ``script`` into the FMU ``dest`` (a path ending in .fmu) and return it."""
    script, dest = Path(script).resolve(), Path(dest).resolve()
    if not script.is_file() or script.suffix != ".py":
        raise PythonBlockError(f"script {str(script)!r}: allowed an existing .py file holding one Fmi2Slave class")
    if dest.suffix != ".fmu":
        raise PythonBlockError(f"--dest {str(dest)!r}: the FMU's path must end in .fmu")
    from pythonfmu.builder import FmuBuilder  # heavy, and only for this command

    dest.parent.mkdir(parents=True, exist_ok=True)
    return Path(FmuBuilder.build_FMU(script, dest=dest))
