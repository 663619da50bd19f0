"""The FMI Cross-Check package of the project's FMUs (`cam-fmu cross-check DIR`).

For every shipped FMU, every interface it offers (co-simulation, model exchange)
and every platform it carries a binary for, the folder the FMI Cross-Check rules
ask of an exporting tool (``layout``), with its files (``package``) and fmpy's
validation of them (``validate``). docs/fmu.md#cross-check-package.
"""
from __future__ import annotations

from .layout import TOOL, Entry, entries, host_platform
from .package import write_entry, write_package
from .validate import validate_entry

__all__ = ["TOOL", "Entry", "entries", "host_platform", "write_entry", "write_package", "validate_entry"]
