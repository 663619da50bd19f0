"""Build a binary FMU from a C model on the shared FMI glue: cam.fmu and cam3.fmu (the drive), pi_speed.fmu
(the PI speed controller). Each needs nothing but the C library.

Build time only. A model (``CModel``) is its hand-written C (the model table of ``csrc/fmi/model.h`` and
what it calls), a generator of its variable table in C, its variable rows (``model_description``) and its
default experiment; the FMI glue (``csrc/fmi``: glue.c and the version's files) is the same for
every model. Steps:

1. The GUID: a hash of the variable rows and of every source and generated file (``digest``).
2. ``sources/``: the model's C, its generated tables, the FMI glue of the version (FMI 2.0: ``fmi2.c`` and
   ``fmi2_me.c``, Model Exchange whole; FMI 3.0: ``fmi3_cs.c`` and ``fmi3_me.c``; both over ``glue.c``), the official headers of
   the version (vendored, ``csrc/fmi/headers``) and ``guid.h``. They compile as they are
   (``cc -shared -fPIC sources/*.c -lm``); FMI 2.0 lists them in the model description's
   ``<SourceFiles>``, FMI 3.0 in ``sources/buildDescription.xml``.
3. The binaries: exactly those ``sources/*.c``, compiled for every platform of ``engine.targets`` by zig
   (``binaries.compile_sources``), only the FMI functions exported, linked with the C library and libm only;
   placed in the version's platform folders (``binaries.place``; FMI 2.0's darwin64 is one universal binary).
4. ``modelDescription.xml``: ``model_description.skeleton`` completed by ``model_description.postprocess``,
   or FMI 3.0's ``model_description3``.
"""
from __future__ import annotations

import hashlib
import shutil
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Dict, List, Sequence

from ..engine import build as engine_build
from ..engine import codegen, reproducible, targets
from . import binaries, macho, model_description, model_description3, pi_codegen, scene_data

PACKAGE_DIR = engine_build.HERE.parent  # cam_fmu/
FMI = engine_build.CSRC / "fmi"
CONTROL_CSRC = PACKAGE_DIR / "control" / "csrc"
# The FMI glue of each version, for every model: the glue both versions share (with the saved states'
# checksum) and the version's own files (FMI 2.0: common and co-simulation, Model Exchange; FMI 3.0:
# co-simulation); its official headers (vendored: engine_build.fmi_headers).
SHARED_GLUE = (FMI / "glue.c", FMI / "checksum.c")
GLUE = {2: (*SHARED_GLUE, FMI / "fmi2.c", FMI / "fmi2_me.c"),
        3: (*SHARED_GLUE, FMI / "fmi3_cs.c", FMI / "fmi3_me.c")}
GLUE_HEADERS = (FMI / "glue.h", FMI / "model.h", FMI / "fmi2_glue.h", FMI / "fmi3_glue.h", FMI / "checksum.h")
HEADERS = {2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
           3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
# Only the FMI functions are exported (FMI2_Export in the official header sets their visibility).
BINARY_FLAGS: tuple[str, ...] = ("-fvisibility=hidden",)


class FmuBuildError(RuntimeError):
    """The FMU could not be built; the message says why."""


@dataclass(frozen=True)
class CModel:
    """A C model on the shared FMI glue: what its binary, model description and sources/ are made of."""

    identifier: str                                  # the model identifier: the binary's name
    description: str                                 # the model description's description
    sources: Callable[[], List[Path]]                # its hand-written C (.c and .h), the model table's file included
    generate: Callable[[Path], List[Path]]           # writes its generated C into a folder
    rows: Callable[[], List[Dict[str, Any]]]         # its variables in value-reference order
    experiment: Callable[[], tuple]                  # (start, stop, step) [s] of its default experiment
    model_exchange: bool                             # it offers Model Exchange (FMI 2.0) beside co-simulation
    shaping: Callable[[], List[Path]]                # the Python files that shape its FMU (staleness)


def default_experiment() -> tuple[float, float, float]:
    """(start, stop, step) [s] of the paper's fig. 6 scene: cam.fmu's default experiment."""
    return scene_data.experiment("paper_fig6")


def controller_experiment() -> tuple[float, float, float]:
    """(start, stop, step) [s] of pi_speed.fmu's default experiment: 2 s sampled every millisecond."""
    return 0.0, 2.0, 1e-3


def _cam_sources() -> List[Path]:
    return [*engine_build.source_files(), FMI / "instance.c", FMI / "exchange.c", FMI / "exchange.h",
            FMI / "directional.c", FMI / "directional.h", FMI / "model_cam.c"]


def _pi_sources() -> List[Path]:
    return sorted(CONTROL_CSRC.glob("*.[ch]"))


CAM = CModel(
    identifier="cam",
    description=("Electromechanical cam drive: DC motor, disc cam, translating roller follower "
                 "(energy-consistent hybrid model, docs/model.md); the C engine of cam_fmu"),
    sources=_cam_sources, generate=codegen.write, rows=model_description.variable_rows,
    experiment=default_experiment, model_exchange=True,
    shaping=lambda: [Path(codegen.__file__), Path(engine_build.__file__), PACKAGE_DIR / "physics" / "parameters.py",
                     PACKAGE_DIR / "physics" / "variables.py"],
)
PI_SPEED = CModel(
    identifier="pi_speed",
    description=("Sampled PI speed controller (one sample per communication step) with conditional-integration "
                 "anti-windup, output clamp [u_min, u_max] and optional load-torque feedforward from cam.fmu's "
                 "M and J (control/pi.py; C in control/csrc)"),
    sources=_pi_sources, generate=pi_codegen.write, rows=model_description.controller_rows,
    experiment=controller_experiment, model_exchange=False,
    shaping=lambda: [Path(pi_codegen.__file__), PACKAGE_DIR / "control" / "pi.py",
                     PACKAGE_DIR / "physics" / "parameters.py"],
)
MODELS: Dict[str, CModel] = {"cam": CAM, "pi_speed": PI_SPEED}


def _model(model: str | CModel) -> CModel:
    if isinstance(model, CModel):
        return model
    if model not in MODELS:
        raise FmuBuildError(f"C model {model!r}: allowed {', '.join(map(repr, MODELS))}")
    return MODELS[model]


def glue_sources() -> List[Path]:
    """The glue's files, every version's (C and headers)."""
    return sorted({*GLUE[2], *GLUE[3], *GLUE_HEADERS})


def sources(model: str | CModel = "cam") -> List[Path]:
    """Every file whose content shapes the model's FMUs: its C, the glue and the official headers, the
    generators, the target table and the tables."""
    m = _model(model)
    return [*m.sources(), *glue_sources(), *sorted(engine_build.FMI_HEADERS.rglob("*.h")), Path(__file__),
            Path(model_description.__file__), Path(model_description3.__file__), Path(targets.__file__),
            Path(binaries.__file__), Path(macho.__file__), *m.shaping()]


def binary_sources(model: str | CModel = "cam", fmi_version: int = 2) -> List[Path]:
    """The C files of the model's binary for ``fmi_version``, the generated table aside."""
    m = _model(model)
    return [p for p in m.sources() if p.suffix == ".c"] + list(GLUE[fmi_version])


def digest(model: str | CModel = "cam") -> str:
    """12 hex digits of everything that shapes the model's FMUs (``sources``: its C, the glue, the headers, the
    build's Python) and of its generated table: the FMU's identity, in its GUID."""
    m = _model(model)
    h = hashlib.sha256()
    for path in sources(m):
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    with tempfile.TemporaryDirectory(prefix="cam_gen_") as gen:
        for path in m.generate(Path(gen)):
            h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    h.update(" ".join(engine_build.CFLAGS + engine_build.LDFLAGS + BINARY_FLAGS).encode())
    return h.hexdigest()[:12]


def model_guid(model: str | CModel = "cam") -> str:
    """The GUID of the model's FMU built from this checkout."""
    m = _model(model)
    return model_description.guid(m.rows(), digest(m))


def compile_binary(dest: Path, guid: str, compiler: str | None = None, extra_flags: Sequence[str] = (),
                   fmi_version: int = 2, target: targets.Target | str | None = None,
                   model: str | CModel = "cam") -> Path:
    """Compile the model, its generated table and the FMI glue of ``fmi_version`` into the shared library ``dest``
    for ``target`` (None: this machine with ``compiler``, default the system C compiler; tests add sanitizers)."""
    m = _model(model)
    with tempfile.TemporaryDirectory(prefix="cam_gen_") as gen:
        generated = [p for p in m.generate(Path(gen)) if p.suffix == ".c"]
        include = sorted({p.parent for p in m.sources()} | {Path(gen), FMI, engine_build.fmi_headers(fmi_version)})
        try:
            return engine_build.compile_shared(dest, [*binary_sources(m, fmi_version), *generated], include,
                                               {"MODEL_GUID": f'"{guid}"'}, target, (*BINARY_FLAGS, *extra_flags),
                                               compiler)
        except engine_build.EngineBuildError as exc:
            raise FmuBuildError(f"{m.identifier}'s binary: {exc}") from None


def write_sources(folder: Path, m: CModel, guid: str, fmi_version: int) -> list[str]:
    """The FMU's ``sources/`` in ``folder``: the model's C, its generated tables, the glue, the official headers
    and ``guid.h``; returns the names of its C files (what a build compiles), sorted."""
    folder.mkdir(parents=True, exist_ok=True)
    m.generate(folder)  # the generated table, beside the hand-written sources
    headers = engine_build.fmi_headers(fmi_version)
    for path in [*m.sources(), *GLUE[fmi_version], *GLUE_HEADERS, *(headers / name for name in HEADERS[fmi_version])]:
        shutil.copyfile(path, folder / path.name)
    shutil.copyfile(engine_build.FMI_HEADERS / "LICENSE.txt", folder / "FMI_HEADERS_LICENSE.txt")
    (folder / "guid.h").write_text(f'/* the model description\'s {"guid" if fmi_version == 2 else "instantiationToken"} */\n'
                                   f'#define MODEL_GUID "{guid}"\n')
    return sorted(p.name for p in folder.glob("*.c"))


def model_description_xml(m: CModel, guid: str, fmi_version: int, files: Sequence[str]) -> bytes:
    """The model description of ``m`` for ``fmi_version`` (``files``: FMI 2.0's SourceFiles)."""
    rows = m.rows()
    if fmi_version == 2:
        return model_description.postprocess(
            model_description.skeleton(m.identifier, guid, rows, list(files), m.model_exchange),
            m.experiment(), m.description, rows)
    return model_description3.model_description(m.identifier, guid, rows, m.experiment(), m.description)


def build(dest: Path, fmi_version: int = 2, platforms: Sequence[str] | None = None,
          model: str | CModel = "cam", progress: binaries.Progress | None = None) -> Path:
    """Build the FMU of ``model`` for ``fmi_version`` (2 or 3) at ``dest`` (a path ending in .fmu) and return it.

    ``platforms``: target names of ``engine.targets`` (default: all, with zig), or ``["host"]``: this machine
    only, with the system C compiler. ``progress(done, total, note=...)``: told which platform is being built
    (binaries.Progress)."""
    if fmi_version not in GLUE:
        raise FmuBuildError(f"fmi_version {fmi_version!r}: allowed 2 or 3")
    m = _model(model)
    dest = Path(dest).resolve()
    if dest.suffix != ".fmu":
        raise FmuBuildError(f"the FMU's path must end in .fmu: {dest}")
    guid = model_guid(m)
    with tempfile.TemporaryDirectory(prefix="cam_fmu_build_") as tmp:
        root = Path(tmp)
        folder = root / "fmu" / "sources"
        files = write_sources(folder, m, guid, fmi_version)
        try:
            built = binaries.compile_sources(root / "built", m.identifier, [folder / f for f in files], (folder,),
                                             names=platforms, extra_flags=BINARY_FLAGS, progress=progress)
        except (engine_build.EngineBuildError, binaries.BinaryBuildError, targets.TargetError) as exc:
            raise FmuBuildError(f"{m.identifier} (FMI {fmi_version}.0)'s binaries: {exc}") from None
        binaries.place(root / "fmu", m.identifier, fmi_version, built)
        if fmi_version == 3:
            (folder / "buildDescription.xml").write_bytes(binaries.build_description(m.identifier, files))
        (root / "fmu" / "modelDescription.xml").write_bytes(model_description_xml(m, guid, fmi_version, files))
        out = reproducible.write_zip(root / f"{m.identifier}.fmu", reproducible.tree_entries(root / "fmu"))
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(out, dest)
    return dest
