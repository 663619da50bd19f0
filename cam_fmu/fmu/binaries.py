"""An FMU's binaries for every platform of the target table, and the build descriptions of its sources.

Build time only, for any C model on the FMI glue (the cam drive's FMUs, engine_fmu.py, and the next ones):

- ``compile_all`` compiles a model's C sources for each target of ``engine.targets`` (zig), or with the
  name ``host`` for this machine with the system C compiler; one target after the other: zig compiles one
  target's files on every core already, and two targets at a time were slower on the 2-core build machine
  (cam.fmu with every cache warm: 11.8 s one at a time, 13.5 s two at a time);
- ``place`` puts them where FMI ``version`` wants them: ``binaries/<fmi2 folder>`` (the two macOS rows merged
  into one universal ``darwin64`` binary, ``macho.merge``) or ``binaries/<fmi3 tuple>``;
- ``build_description`` writes FMI 3.0's ``sources/buildDescription.xml``; FMI 2.0 lists the same files in
  ``<SourceFiles>`` of its model description (``model_description.skeleton``).
"""
from __future__ import annotations

import shutil
from pathlib import Path
from typing import Callable, Mapping, Sequence
from xml.dom.minidom import parseString
from xml.etree import ElementTree as ET

from ..engine import build as engine_build
from ..engine import targets
from . import macho

HOST = "host"  # this machine with the system C compiler, not zig (an installed package without the build extra)
# progress(done, total, note): called before each target (note: "building <target>") and once all are built (note
# ""), e.g. experiments.progress.ProgressBar (build_fmu.py passes one: a first build takes minutes)
Progress = Callable[..., None]


class BinaryBuildError(RuntimeError):
    """A binary could not be built; the message says why."""


def resolve(names: Sequence[str] | None) -> list[str]:
    """The target names to build: every row of the table when ``names`` is None; ``host``: this machine."""
    names = list(targets.NAMES if names is None else names)
    for name in names:
        if name != HOST:
            targets.get(name)  # TargetError naming the allowed ones
    if HOST in names and targets.host() is None:
        raise BinaryBuildError("this machine is not in the target table (engine/targets.py): compile the "
                               "FMU's sources/ (docs/fmu.md, 'What a target machine needs')")
    return names


def compile_all(folder: Path, identifier: str, names: Sequence[str], compile_one,
                progress: Progress | None = None) -> dict[str, Path]:
    """``compile_one(dest, target)`` for each of ``names`` (``target``: a row of the table, or None for ``host``),
    ``dest`` = ``folder/<name>/<identifier><suffix>``; returns {name: library}. ``progress``: see Progress."""
    def one(name: str) -> Path:
        row = targets.host() if name == HOST else targets.get(name)
        return compile_one(folder / name / f"{identifier}{row.suffix}", None if name == HOST else row)

    built = {}
    for k, name in enumerate(names):
        if progress is not None:
            progress(k, len(names), note=f"building {name}")
        built[name] = one(name)
    if progress is not None:
        progress(len(names), len(names), note="")
    return built


def compile_sources(folder: Path, identifier: str, sources: Sequence[Path], include: Sequence[Path] = (),
                    defines: Mapping[str, str] | None = None, names: Sequence[str] | None = None,
                    extra_flags: Sequence[str] = (), progress: Progress | None = None) -> dict[str, Path]:
    """The C ``sources`` (with ``include``, ``defines``, ``extra_flags``) compiled for ``names`` (default: every
    target) into ``folder``; returns {name: library}. ``progress``: see Progress."""
    def one(dest: Path, row):
        return engine_build.compile_shared(dest, sources, include, defines, row, extra_flags)

    return compile_all(folder, identifier, resolve(names), one, progress)


def place(root: Path, identifier: str, fmi_version: int, built: Mapping[str, Path]) -> list[Path]:
    """Copy the libraries ``built`` ({target name: library}) into ``root/binaries/<platform folder>/`` of FMI
    ``fmi_version``; rows sharing a folder (FMI 2.0's darwin64) become one universal binary. Returns the files."""
    folders: dict[str, list[Path]] = {}
    for name, path in built.items():
        row = targets.host() if name == HOST else targets.get(name)
        folders.setdefault(row.fmi2 if fmi_version == 2 else row.fmi3, []).append(path)
    out = []
    for folder, paths in sorted(folders.items()):
        dest = root / "binaries" / folder / f"{identifier}{paths[0].suffix}"
        dest.parent.mkdir(parents=True, exist_ok=True)
        if len(paths) == 1:
            shutil.copyfile(paths[0], dest)
        else:
            macho.merge(paths, dest)
        out.append(dest)
    return out


def build_description(identifier: str, files: Sequence[str], language: str = "C99") -> bytes:
    """FMI 3.0's ``sources/buildDescription.xml``: one configuration compiling ``files`` (names in sources/)."""
    root = ET.Element("fmiBuildDescription", fmiVersion="3.0")
    config = ET.SubElement(root, "BuildConfiguration", modelIdentifier=identifier)
    fileset = ET.SubElement(config, "SourceFileSet", language=language)
    for name in files:
        ET.SubElement(fileset, "SourceFile", name=name)
    ET.SubElement(config, "Library", name="m", description="the C math library (libm; part of the C library "
                                                           "on Windows and macOS)")
    return parseString(ET.tostring(root, encoding="UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")


__all__ = ["HOST", "BinaryBuildError", "Progress", "build_description", "compile_all", "compile_sources", "place", "resolve"]
