"""Build cam.fmu from the C engine: a binary FMU that needs nothing but the C library.

Build time only. Steps:

1. The GUID: a hash of the variable table (``model_description.variable_rows``)
   and of the engine's sources (``engine.build.digest``).
2. The generated headers (``engine.codegen``: the variable and parameter tables of
   ``physics/parameters.py`` and ``physics/variables.py``) in a temporary folder.
3. The binary: every engine source (``engine/csrc/src/*.c``) and the FMI 2.0
   glue (``engine/csrc/fmi/fmi2.c`` and ``fmi2_me.c`` over ``glue.c``, ``glue_me.c``,
   ``exchange.c`` and ``instance.c``) compiled into one shared library with the
   official FMI headers (fmpy's copy), only the FMI functions exported, linked
   with libc and libm only: ``binaries/linux64/cam.so``; with the MinGW-w64 cross
   compiler also ``binaries/win64/cam.dll`` (Windows' own KERNEL32 and msvcrt only).
4. ``modelDescription.xml``: ``model_description.skeleton`` completed by
   ``model_description.postprocess`` (units, ranges, structure, the default
   experiment of the paper's fig. 6 scene).
5. The C sources under ``sources/``, with the generated table and the official
   headers: anyone can rebuild the binary for another platform
   (``cc -std=c99 -shared -fPIC -include sources/guid.h -Isources sources/*.c -lm``).
"""
from __future__ import annotations

import shutil
import tempfile
import zipfile
from pathlib import Path
from typing import Sequence

from ..engine import build as engine_build
from ..engine import codegen
from . import model_description, model_description3

MODEL_IDENTIFIER = "cam"
DESCRIPTION = ("Electromechanical cam drive: DC motor, disc cam, translating roller follower "
               "(energy-consistent hybrid model, docs/model.md); the C engine of cam_fmu")
FMI = engine_build.CSRC / "fmi"
# The FMI glue of each version: the instance layer, the Model Exchange layer, the glue both share, the
# version's own files (FMI 2.0: co-simulation and Model Exchange; FMI 3.0: co-simulation); its official
# headers; its platform folders (FMI 3.0 names them by architecture and OS).
SHARED_GLUE = (FMI / "instance.c", FMI / "exchange.c", FMI / "glue.c", FMI / "glue_me.c", FMI / "checksum.c")
GLUE = {2: (*SHARED_GLUE, FMI / "fmi2.c", FMI / "fmi2_me.c"),
        3: (*SHARED_GLUE, FMI / "fmi3_cs.c")}
HEADERS = {2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
           3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
PLATFORM_DIRS = {2: {"linux64": "linux64", "win64": "win64"}, 3: {"linux64": "x86_64-linux", "win64": "x86_64-windows"}}
FMU_NAMES = {2: "cam.fmu", 3: "cam3.fmu"}
# Only the FMI functions are exported (FMI2_Export in the official header sets their visibility).
BINARY_FLAGS: tuple[str, ...] = ("-fvisibility=hidden",)
# win64: Debian's MinGW-w64 cross compiler; libgcc linked in, so the DLL needs only Windows' own
# KERNEL32.dll and msvcrt.dll.
WIN64_COMPILER = "x86_64-w64-mingw32-gcc"
WIN64_FLAGS: tuple[str, ...] = ("-static-libgcc",)
PLATFORMS = ("linux64", "win64")


class FmuBuildError(RuntimeError):
    """The FMU could not be built; the message says why."""


def sources() -> list[Path]:
    """Every file whose content shapes cam.fmu: the engine's C, the FMI glue, the generators and the tables."""
    package = engine_build.HERE.parent
    return [*engine_build.source_files(), *sorted(FMI.glob("*.[ch]")), Path(__file__), Path(model_description.__file__),
            Path(model_description3.__file__), Path(codegen.__file__), Path(engine_build.__file__),
            package / "physics" / "parameters.py",
            package / "physics" / "variables.py"]


def default_experiment() -> tuple[float, float, float]:
    """(start, stop, step) [s] of the paper's fig. 6 scene: the FMU's default experiment."""
    from ..experiments.scenes import find_scene

    scene = find_scene("paper_fig6")
    return 0.0, float(scene.stop_time), float(scene.output_interval)


def engine_guid() -> str:
    """The GUID of a cam.fmu built from this checkout."""
    return model_description.guid(model_description.variable_rows(), engine_build.digest())


def compile_binary(dest: Path, guid: str, compiler: str | None = None, extra_flags: Sequence[str] = (),
                   fmi_version: int = 2) -> Path:
    """Compile the engine, the instance layer and the FMI glue of ``fmi_version`` into the shared library ``dest``."""
    try:
        return engine_build.compile_library(dest, (*BINARY_FLAGS, f'-DCAM_GUID="{guid}"', *extra_flags), compiler,
                                            extra_sources=GLUE[fmi_version], include=(engine_build.fmi_headers(),))
    except engine_build.EngineBuildError as exc:
        raise FmuBuildError(f"cam.fmu's binary: {exc}") from None


def win64_compiler() -> str | None:
    """The MinGW-w64 cross compiler on PATH, or None."""
    return shutil.which(WIN64_COMPILER)


def build(dest: Path, win64: bool | None = None, fmi_version: int = 2) -> Path:
    """Build cam.fmu (``fmi_version`` 2) or cam3.fmu (3) at ``dest`` (a path ending in .fmu) and return it.

    ``win64``: True requires the win64 binary (FmuBuildError without the cross compiler), False
    leaves it out, None (the default) adds it when the cross compiler is installed."""
    if fmi_version not in GLUE:
        raise FmuBuildError(f"fmi_version {fmi_version!r}: allowed 2 or 3")
    dest = Path(dest).resolve()
    if dest.suffix != ".fmu":
        raise FmuBuildError(f"the FMU's path must end in .fmu: {dest}")
    cross = win64_compiler() if win64 is not False else None
    if win64 and not cross:
        raise FmuBuildError(f"the win64 binary needs the MinGW-w64 cross compiler {WIN64_COMPILER} "
                            "(Debian: apt-get install gcc-mingw-w64-x86-64; setup.sh installs it)")
    rows = model_description.variable_rows()
    guid = engine_guid()
    with tempfile.TemporaryDirectory(prefix="cam_fmu_build_") as tmp:
        root = Path(tmp)
        folders = PLATFORM_DIRS[fmi_version]
        compile_binary(root / "fmu" / "binaries" / folders["linux64"] / f"{MODEL_IDENTIFIER}.so", guid,
                       fmi_version=fmi_version)
        if cross:
            compile_binary(root / "fmu" / "binaries" / folders["win64"] / f"{MODEL_IDENTIFIER}.dll", guid, cross,
                           WIN64_FLAGS, fmi_version)
        if fmi_version == 2:
            xml = model_description.postprocess(model_description.skeleton(MODEL_IDENTIFIER, guid, rows),
                                                default_experiment(), DESCRIPTION, rows)
        else:
            xml = model_description3.model_description(MODEL_IDENTIFIER, guid, rows, default_experiment(),
                                                       DESCRIPTION)
        (root / "fmu" / "modelDescription.xml").write_bytes(xml)
        sources = root / "fmu" / "sources"
        generated = codegen.write(sources)  # the generated table, beside the hand-written sources
        for path in [*engine_build.SOURCES.glob("*.c"), *engine_build.INCLUDE.glob("*.h"), *GLUE[fmi_version],
                     *FMI.glob("*.h"), *(engine_build.fmi_headers() / name for name in HEADERS[fmi_version])]:
            shutil.copyfile(path, sources / path.name)
        (sources / "guid.h").write_text(f'#define CAM_GUID "{guid}"\n')
        del generated
        out = root / f"{MODEL_IDENTIFIER}.fmu"
        with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED) as z:
            for path in sorted((root / "fmu").rglob("*")):
                if path.is_file():
                    z.write(path, path.relative_to(root / "fmu").as_posix())
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(out, dest)
    return dest
