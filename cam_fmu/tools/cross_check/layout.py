"""Which cross-check folders an FMU gets: one per FMI interface it offers and platform it carries.

The FMI Cross-Check rules' layout for an exported FMU is
``fmus/{FMI version}/{cs|me}/{platform}/{tool}/{tool version}/{model}/``. The FMI
version and the interfaces are read from the FMU's modelDescription.xml, the
platforms from its ``binaries/`` folders (``linux64``, ``win64`` for FMI 1.0 and
2.0; ``x86_64-linux``, ``x86_64-windows`` for FMI 3.0): nothing is assumed about a
particular FMU, so an FMU that adds model exchange or another FMI version is picked
up as it is.
"""
from __future__ import annotations

import re
import zipfile
from dataclasses import dataclass
from pathlib import Path

from ... import __version__

TOOL = "cam_fmu"  # {tool}: the exporting tool is this package
INTERFACES = {"cs": "CoSimulation", "me": "ModelExchange"}  # {FMI type}: fmpy's name of the interface
_LIBRARY = re.compile(r"^binaries/([^/]+)/[^/]+\.(so|dll|dylib)$")
_MODEL_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


class CrossCheckError(ValueError):
    """An FMU that cannot be packaged; the message names the file and the reason."""


@dataclass(frozen=True)
class Entry:
    """One cross-check folder: an FMU under one FMI version, interface and platform."""

    fmu: Path
    model: str  # {model}: the FMU's file name without .fmu
    fmi_version: str  # '1.0', '2.0', '3.0'
    fmi_type: str  # 'cs' or 'me'
    platform: str  # the binaries/ folder: linux64, win64, x86_64-linux, ...

    @property
    def interface(self) -> str:
        """fmpy's name of the interface: 'CoSimulation' or 'ModelExchange'."""
        return INTERFACES[self.fmi_type]

    @property
    def runs_here(self) -> bool:
        """True when this machine can load the entry's binary (fmpy's platform name for its FMI version)."""
        return self.platform == host_platform(self.fmi_version)

    def folder(self, root: str | Path) -> Path:
        """``root/fmus/{version}/{type}/{platform}/cam_fmu/{package version}/{model}``."""
        return Path(root, "fmus", self.fmi_version, self.fmi_type, self.platform, TOOL, __version__, self.model)

    def file(self, root: str | Path, suffix: str) -> Path:
        """``{model}{suffix}`` in the entry's folder (suffix '.fmu', '_ref.csv', ...)."""
        return self.folder(root) / f"{self.model}{suffix}"


def host_platform(fmi_version: str) -> str:
    """This machine's binaries/ folder name for an FMU of ``fmi_version`` (fmpy's names)."""
    import fmpy

    return fmpy.platform_tuple if fmi_version.startswith("3") else fmpy.platform


def binary_platforms(fmu: str | Path) -> list[str]:
    """The binaries/ folders of ``fmu`` that hold a shared library, sorted."""
    with zipfile.ZipFile(fmu) as z:
        found = {m.group(1) for name in z.namelist() if (m := _LIBRARY.match(name))}
    return sorted(found)


def entries(fmu: str | Path) -> list[Entry]:
    """Every cross-check folder of ``fmu``: its FMI version x the interfaces it offers x its platforms.

    CrossCheckError when the model description cannot be read, the FMU offers no
    interface, carries no binary or its name cannot be a model name.
    """
    from fmpy import read_model_description

    fmu = Path(fmu)
    if not _MODEL_NAME.match(fmu.stem):
        raise CrossCheckError(f"--fmu {str(fmu)!r}: the file name is the model name of the cross-check "
                              f"folder: letters, digits and '_', starting with a letter (got {fmu.stem!r})")
    try:
        md = read_model_description(str(fmu))
    except Exception as exc:  # noqa: BLE001 - fmpy raises several kinds for a file that is not an FMU
        raise CrossCheckError(f"--fmu {str(fmu)!r}: no readable modelDescription.xml: "
                              f"{' '.join(str(exc).split())}") from None
    types = [t for t, attr in (("cs", "coSimulation"), ("me", "modelExchange")) if getattr(md, attr) is not None]
    if not types:
        raise CrossCheckError(f"--fmu {str(fmu)!r}: offers neither co-simulation nor model exchange")
    platforms = binary_platforms(fmu)
    if not platforms:
        raise CrossCheckError(f"--fmu {str(fmu)!r}: carries no binary (binaries/<platform>/*.so|dll|dylib)")
    return [Entry(fmu, fmu.stem, md.fmiVersion, t, p) for t in types for p in platforms]


def shipped_fmus() -> list[Path]:
    """The project's FMUs of the drive (every model fmu.build builds on the drive's C model: cam.fmu,
    cam3.fmu), each built first when missing or stale. The experiment every folder records is the drive's
    (fig. 6 after a step of u); pi_speed.fmu, the controller, has no input u and is left out."""
    from ...fmu.build import ENGINE_MODELS, ensure_fmu

    return [ensure_fmu(None, model=name) for name, (c_model, _v) in ENGINE_MODELS.items() if c_model == "cam"]
