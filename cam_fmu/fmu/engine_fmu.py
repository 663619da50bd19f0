"""Build cam.fmu and cam3.fmu from the C engine: binary FMUs that need nothing but the C library.

Build time only. Steps:

1. The GUID: a hash of the variable table (``model_description.variable_rows``)
   and of the engine's sources (``engine.build.digest``).
2. ``sources/``: every engine source (``engine/csrc/src/*.c`` and ``include/*.h``), the generated
   variable and parameter tables (``engine.codegen``), the FMI glue of the version (FMI 2.0: ``fmi2.c``
   and ``fmi2_me.c``; FMI 3.0: ``fmi3_cs.c``; both over ``glue.c``, ``glue_me.c``, ``exchange.c`` and
   ``instance.c``), the official headers of the version (vendored, ``csrc/fmi/headers``) and ``guid.h``.
   They compile as they are (``cc -shared -fPIC sources/*.c -lm``); FMI 2.0 lists them in the model
   description's ``<SourceFiles>``, FMI 3.0 in ``sources/buildDescription.xml``.
3. The binaries: exactly those ``sources/*.c``, compiled for every platform of ``engine.targets`` by zig
   (``binaries.compile_sources``), only the FMI functions exported, linked with the C library and libm only;
   placed in the version's platform folders (``binaries.place``; FMI 2.0's darwin64 is one universal binary).
4. ``modelDescription.xml``: ``model_description.skeleton`` completed by ``model_description.postprocess``
   (units, ranges, structure, the default experiment of the paper's fig. 6 scene), or FMI 3.0's
   ``model_description3``.
"""
from __future__ import annotations

import shutil
import tempfile
import zipfile
from pathlib import Path
from typing import Sequence

from ..engine import build as engine_build
from ..engine import codegen, targets
from . import binaries, macho, model_description, model_description3

MODEL_IDENTIFIER = "cam"
DESCRIPTION = ("Electromechanical cam drive: DC motor, disc cam, translating roller follower "
               "(energy-consistent hybrid model, docs/model.md); the C engine of cam_fmu")
FMI = engine_build.CSRC / "fmi"
# The FMI glue of each version: the instance layer, the Model Exchange layer, the glue both share, the
# version's own files (FMI 2.0: co-simulation and Model Exchange; FMI 3.0: co-simulation); its official
# headers (vendored: engine_build.fmi_headers).
SHARED_GLUE = (FMI / "instance.c", FMI / "exchange.c", FMI / "glue.c", FMI / "glue_me.c")
GLUE = {2: (*SHARED_GLUE, FMI / "fmi2.c", FMI / "fmi2_me.c"),
        3: (*SHARED_GLUE, FMI / "fmi3_cs.c")}
HEADERS = {2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
           3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
FMU_NAMES = {2: "cam.fmu", 3: "cam3.fmu"}
# Only the FMI functions are exported (FMI2_Export in the official header sets their visibility).
BINARY_FLAGS: tuple[str, ...] = ("-fvisibility=hidden",)


class FmuBuildError(RuntimeError):
    """The FMU could not be built; the message says why."""


def sources() -> list[Path]:
    """Every file whose content shapes cam.fmu: the engine's C, the FMI glue and headers, the generators, the
    target table and the parameter tables."""
    package = engine_build.HERE.parent
    return [*engine_build.source_files(), *sorted(FMI.glob("*.[ch]")), *sorted(engine_build.FMI_HEADERS.rglob("*.h")),
            Path(__file__), Path(model_description.__file__), Path(model_description3.__file__),
            Path(codegen.__file__), Path(engine_build.__file__), Path(targets.__file__), Path(binaries.__file__),
            Path(macho.__file__), package / "physics" / "parameters.py", package / "physics" / "variables.py"]


def default_experiment() -> tuple[float, float, float]:
    """(start, stop, step) [s] of the paper's fig. 6 scene: the FMU's default experiment."""
    from ..experiments.scenes import find_scene

    scene = find_scene("paper_fig6")
    return 0.0, float(scene.stop_time), float(scene.output_interval)


def engine_guid() -> str:
    """The GUID of a cam.fmu built from this checkout."""
    return model_description.guid(model_description.variable_rows(), engine_build.digest())


def compile_binary(dest: Path, guid: str, compiler: str | None = None, extra_flags: Sequence[str] = (),
                   fmi_version: int = 2, target: targets.Target | str | None = None) -> Path:
    """Compile the engine, the instance layer and the FMI glue of ``fmi_version`` into the shared library ``dest``
    for ``target`` (None: this machine with ``compiler``, default the system C compiler; tests add sanitizers)."""
    try:
        return engine_build.compile_library(dest, (*BINARY_FLAGS, *extra_flags), compiler, GLUE[fmi_version],
                                            (engine_build.fmi_headers(fmi_version),), {"CAM_GUID": f'"{guid}"'},
                                            target)
    except engine_build.EngineBuildError as exc:
        raise FmuBuildError(f"cam.fmu's binary: {exc}") from None


def write_sources(folder: Path, guid: str, fmi_version: int) -> list[str]:
    """The FMU's ``sources/`` in ``folder``: engine, generated tables, glue, official headers and ``guid.h``;
    returns the names of its C files (what a build compiles), sorted."""
    folder.mkdir(parents=True, exist_ok=True)
    codegen.write(folder)  # the generated table, beside the hand-written sources
    headers = engine_build.fmi_headers(fmi_version)
    for path in [*engine_build.SOURCES.glob("*.c"), *engine_build.INCLUDE.glob("*.h"), *GLUE[fmi_version],
                 *FMI.glob("*.h"), *(headers / name for name in HEADERS[fmi_version])]:
        shutil.copyfile(path, folder / path.name)
    shutil.copyfile(engine_build.FMI_HEADERS / "LICENSE.txt", folder / "FMI_HEADERS_LICENSE.txt")
    (folder / "guid.h").write_text(f'/* the model description\'s {"guid" if fmi_version == 2 else "instantiationToken"} */\n'
                                   f'#define CAM_GUID "{guid}"\n')
    return sorted(p.name for p in folder.glob("*.c"))


def build(dest: Path, fmi_version: int = 2, platforms: Sequence[str] | None = None) -> Path:
    """Build cam.fmu (``fmi_version`` 2) or cam3.fmu (3) at ``dest`` (a path ending in .fmu) and return it.

    ``platforms``: target names of ``engine.targets`` (default: all, with zig), or ``["host"]``: this machine
    only, with the system C compiler."""
    if fmi_version not in GLUE:
        raise FmuBuildError(f"fmi_version {fmi_version!r}: allowed 2 or 3")
    dest = Path(dest).resolve()
    if dest.suffix != ".fmu":
        raise FmuBuildError(f"the FMU's path must end in .fmu: {dest}")
    rows = model_description.variable_rows()
    guid = engine_guid()
    with tempfile.TemporaryDirectory(prefix="cam_fmu_build_") as tmp:
        root = Path(tmp)
        sources = root / "fmu" / "sources"
        files = write_sources(sources, guid, fmi_version)
        try:
            built = binaries.compile_sources(root / "built", MODEL_IDENTIFIER, [sources / f for f in files],
                                             (sources,), names=platforms, extra_flags=BINARY_FLAGS)
        except (engine_build.EngineBuildError, binaries.BinaryBuildError, targets.TargetError) as exc:
            raise FmuBuildError(f"{FMU_NAMES[fmi_version]}'s binaries: {exc}") from None
        binaries.place(root / "fmu", MODEL_IDENTIFIER, fmi_version, built)
        if fmi_version == 2:
            xml = model_description.postprocess(model_description.skeleton(MODEL_IDENTIFIER, guid, rows, files),
                                                default_experiment(), DESCRIPTION, rows)
        else:
            xml = model_description3.model_description(MODEL_IDENTIFIER, guid, rows, default_experiment(),
                                                       DESCRIPTION)
            (sources / "buildDescription.xml").write_bytes(binaries.build_description(MODEL_IDENTIFIER, files))
        (root / "fmu" / "modelDescription.xml").write_bytes(xml)
        out = root / f"{MODEL_IDENTIFIER}.fmu"
        with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED) as z:
            for path in sorted((root / "fmu").rglob("*")):
                if path.is_file():
                    z.write(path, path.relative_to(root / "fmu").as_posix())
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(out, dest)
    return dest
