"""Build cam.fmu, pi_speed.fmu (FMI 2.0 co-simulation, pythonfmu 0.7.0) and speed_loop.ssp.

    python build_fmu.py                          # -> models/cam.fmu, models/pi_speed.fmu, models/speed_loop.ssp
    python -m cam_fmu.fmu.build --dest /tmp/x/cam.fmu
    python -m cam_fmu.fmu.build --model pi_speed --dest /tmp/x/pi_speed.fmu

Every FMU in MODELS is built the same way (its own slave script and module name):

What goes into the FMU (under resources/):
- the slave script ``cam_fmu/fmu/camdrive_fmu_slave.py`` (imported by the FMU as
  the top-level module ``camdrive_fmu_slave``),
- a copy of pythonfmu (pythonfmu does that itself),
- ``cam_fmu/``: only the modules the slave needs, found by following the
  package-internal imports (``import cam_fmu.x``, ``from cam_fmu import x``,
  ``from .x import y``...) of the slave script, transitively. Modules such as
  the scipy-based reference integration or the plots are never bundled. The
  closure may import only the standard library and numpy: anything else
  (scipy above all: it crashes native hosts at Py_Finalize) fails the build.
  The bundled package gets a minimal ``__init__.py`` unless a bundled module
  needs a name from the real one.

Before zipping, the staged bundle is imported in an isolated interpreter
(``python -I``, nothing of this checkout on sys.path) to prove it is complete.
After zipping, modelDescription.xml is completed by ``model_description``
(units, initial, InitialUnknowns, DefaultExperiment...).

linux64: ``native.compile`` stages the bundle under private names
(``cam_fmu_<hash>``, ``<slave>_<hash>``), compiles the project's own FMI wrapper
with the system C compiler (no compiler: the build stops) and puts it,
``resources/python.txt`` and ``resources/native.txt`` into the FMU (docs/fmu.md).

The compiled drive kernel (``cam_fmu/kernel``, docs/architecture.md): cam.fmu
always bundles ``kernel/drive_kernel.py`` (the fallback); ``build(compiled=True)``
(the default; ``--pure-python`` turns it off) first builds its extension in
place with ``kernel.compile`` (so the checkout uses it too), then compiles the
staged copy under the private package name and ships that .so beside the
bundled .py. Where the .so's ABI tag does not match the host's Python, the
import system loads the .py.
"""
from __future__ import annotations

import argparse
import ast
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Dict, Iterable, List, Set, Tuple

from ..kernel import COMPILED_MODULES

PACKAGE = "cam_fmu"
PACKAGE_DIR = Path(__file__).resolve().parents[1]  # this cam_fmu
SLAVE_SCRIPT = Path("fmu") / "camdrive_fmu_slave.py"  # relative to the package
# Every FMU the project builds: model name -> (slave script relative to the package, slave class).
MODELS: Dict[str, Tuple[Path, str]] = {
    "cam": (SLAVE_SCRIPT, "CamDriveSlave"),
    "pi_speed": (Path("fmu") / "pi_speed_fmu_slave.py", "PiSpeedSlave"),
}
KERNEL = "kernel"  # the subpackage of the compiled modules
# Modules bundled even before the slave imports them: cam.fmu carries the drive kernel (.py and .so).
ROOTS: Dict[str, Tuple[str, ...]] = {"cam": tuple(f"{KERNEL}.{m}" for m in COMPILED_MODULES)}
SSP_NAME = "speed_loop"  # models/speed_loop.ssp: pi_speed.fmu closing a speed loop around cam.fmu
# Files that shape the FMU beside the bundled closure (their change makes a built FMU stale).
BUILD_SOURCES = (Path("fmu") / "build.py", Path("fmu") / "model_description.py",
                 Path("fmu") / "native" / "fmi2_python.c", Path("fmu") / "native" / "bridge.py",
                 Path("fmu") / "native" / "compile.py", Path(KERNEL) / "compile.py")
ALLOWED_THIRD_PARTY = {"numpy", "pythonfmu"}
FORBIDDEN = {"scipy", "matplotlib", "pandas", "fmpy"}


class BuildError(RuntimeError):
    pass


def _module_file(package_dir: Path, dotted: str) -> Path | None:
    """File of package-internal module ``dotted`` (relative to the package), or None."""
    base = package_dir.joinpath(*dotted.split(".")) if dotted else package_dir
    if base.with_suffix(".py").is_file():
        return base.with_suffix(".py")
    if (base / "__init__.py").is_file():
        return base / "__init__.py"
    return None


def _imports(path: Path, package_dir: Path) -> Tuple[Set[str], Set[str], bool]:
    """(package-internal modules, external top-level modules, needs the real __init__) of one file."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    rel_parts = path.relative_to(package_dir).with_suffix("").parts if path.is_relative_to(package_dir) else ()
    if rel_parts and rel_parts[-1] == "__init__":
        rel_parts = rel_parts[:-1]
        current_pkg = list(rel_parts)
    else:
        current_pkg = list(rel_parts[:-1])
    internal: Set[str] = set()
    external: Set[str] = set()
    needs_init = False

    def add_internal(dotted: str, names: Iterable[str]) -> None:
        nonlocal needs_init
        for name in names:
            sub = f"{dotted}.{name}" if dotted else name
            if _module_file(package_dir, sub) is not None:
                internal.add(sub)
            elif dotted:
                internal.add(dotted)
            else:
                needs_init = True  # a name defined in the package's __init__
        if dotted and _module_file(package_dir, dotted) is not None:
            internal.add(dotted)

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                top, _, rest = alias.name.partition(".")
                if top == PACKAGE:
                    if rest:
                        internal.add(rest)
                else:
                    external.add(top)
        elif isinstance(node, ast.ImportFrom):
            names = [a.name for a in node.names]
            if node.level:
                base = current_pkg[: len(current_pkg) - (node.level - 1)] if node.level > 1 else current_pkg
                dotted = ".".join(base + ([node.module] if node.module else []))
                add_internal(dotted, names)
            else:
                top, _, rest = (node.module or "").partition(".")
                if top == PACKAGE:
                    add_internal(rest, names)
                else:
                    external.add(top)
    return internal, external, needs_init


def bundle_modules(package_dir: Path, script: Path, roots: Iterable[str] = ()) -> Tuple[List[Path], bool]:
    """Files of ``package_dir`` the slave needs (transitively) and whether the real __init__ is needed.

    ``roots``: package-internal modules (``kernel.drive_kernel``) bundled as if the slave imported them.
    """
    todo = [script]
    seen: Set[Path] = set()
    files: Set[Path] = set()
    externals: Dict[str, Set[str]] = {}
    needs_init = False
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        internal, external, init = _imports(path, package_dir)
        if path == script:
            internal |= set(roots)
        needs_init |= init
        for ext in external:
            externals.setdefault(ext, set()).add(path.name)
        for dotted in internal:
            target = _module_file(package_dir, dotted)
            if target is None:
                raise BuildError(f"{path.name} imports {PACKAGE}.{dotted}, which does not exist in {package_dir}")
            # parent packages of a sub-package module come along, and what they import
            parts = dotted.split(".")
            for k in range(1, len(parts)):
                init = package_dir.joinpath(*parts[:k], "__init__.py")
                files.add(init)
                todo.append(init)
            files.add(target)
            todo.append(target)
        if init:
            files.add(package_dir / "__init__.py")
            todo.append(package_dir / "__init__.py")
    stdlib = set(sys.stdlib_module_names) | {"__future__"}
    bad = {m: sorted(users) for m, users in externals.items()
           if m in FORBIDDEN or (m not in stdlib and m not in ALLOWED_THIRD_PARTY)}
    if bad:
        raise BuildError("the FMU's run-time modules may import only the standard library and numpy; found: "
                         + "; ".join(f"{m} (in {', '.join(u)})" for m, u in sorted(bad.items())))
    return sorted(f for f in files if f != script), needs_init


def stage(package_dir: Path, script: Path, staging: Path, roots: Iterable[str] = ()) -> List[str]:
    """Copy the slave script and the needed part of the package into ``staging``; return the bundled names.

    Each FMU bundles only its own slave's closure: ``native.privatize`` then
    renames the package and the script to names private to this build
    (``cam_fmu_<hash>``), so cam.fmu and pi_speed.fmu loaded into one host
    process never share or shadow each other's modules.
    """
    modules, needs_init = bundle_modules(package_dir, script, roots)
    target_pkg = staging / PACKAGE
    target_pkg.mkdir(parents=True)
    for path in modules:
        dest = target_pkg / path.relative_to(package_dir)
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(path, dest)
    if not needs_init or not (package_dir / "__init__.py").is_file():
        (target_pkg / "__init__.py").write_text(
            '"""The part of cam_fmu that cam.fmu needs at run time (bundled by build_fmu.py)."""\n',
            encoding="utf-8")
    shutil.copy2(script, staging / script.name)
    return sorted(str(p.relative_to(staging)) for p in staging.rglob("*.py"))


CHECK_BUNDLE = r"""
import json, sys
sys.path[:0] = [sys.argv[1]]
import {module} as slave_module
import {package} as bundled_package
assert bundled_package.__file__.startswith(sys.argv[1]), bundled_package.__file__
slave = slave_module.{cls}(instance_name="check", resources=sys.argv[1])
slave.exit_initialization_mode()
assert slave.do_step(0.0, 1e-3) is True
forbidden = sorted(m for m in sys.modules if m.split(".")[0] in {forbidden!r})
modules = sorted(m for m in sys.modules if m.startswith("cam_fmu"))
import importlib
kernel = {{m: importlib.import_module("{package}." + m).__file__ for m in {kernel!r}}}
print(json.dumps({{"forbidden": forbidden, "modules": modules, "kernel": kernel}}))
"""


def check_bundle(staging: Path, module: str, cls: str = "CamDriveSlave", package: str = PACKAGE,
                 kernel: Iterable[str] = ()) -> dict:
    """Import and step the staged slave in an isolated interpreter: proves the bundle is complete.

    Each module of ``kernel`` (``kernel.drive_kernel``) is imported too; ``info["kernel"]``
    maps it to the file Python loaded (the extension, or the .py where there is none).
    """
    code = CHECK_BUNDLE.format(module=module, cls=cls, package=package, forbidden=sorted(FORBIDDEN),
                               kernel=list(kernel))
    proc = subprocess.run([sys.executable, "-I", "-c", code, str(staging)], capture_output=True, text=True,
                          cwd=staging, timeout=120)
    if proc.returncode != 0:
        raise BuildError(f"the staged FMU resources do not import in isolation:\n{proc.stderr}")
    info = json.loads(proc.stdout.strip().splitlines()[-1])
    if info["forbidden"]:
        raise BuildError(f"the FMU's run-time path imports {info['forbidden']}: keep them out of the bundle")
    return info


def _model(model: str) -> Tuple[Path, str]:
    if model not in MODELS:
        raise BuildError(f"model {model!r}: allowed {', '.join(map(repr, MODELS))}")
    return MODELS[model]


def sources(package_dir: Path = PACKAGE_DIR, model: str = "cam") -> list[Path]:
    """Every file whose content ends up in (or shapes) the FMU of ``model``."""
    script = package_dir / _model(model)[0]
    modules = bundle_modules(package_dir, script, ROOTS.get(model, ()))[0]
    pxds = [p.with_suffix(".pxd") for p in modules if p.with_suffix(".pxd").is_file()]  # C types of a compiled one
    return [script, *modules, *pxds, *(package_dir / p for p in BUILD_SOURCES)]


def is_stale(fmu: Path, package_dir: Path = PACKAGE_DIR, model: str = "cam") -> bool:
    """True when ``fmu`` is missing or older than one of its sources."""
    fmu = Path(fmu)
    if not fmu.is_file():
        return True
    newest = max(p.stat().st_mtime for p in sources(package_dir, model) if p.is_file())
    return fmu.stat().st_mtime < newest


def compiled_in_bundle(staged_package: Path) -> Tuple[str, ...]:
    """The compiled modules whose .py is in the staged package (cam.fmu: all; pi_speed.fmu: none)."""
    return tuple(m for m in COMPILED_MODULES if (staged_package / KERNEL / f"{m}.py").is_file())


def build_kernel_in_place(package_dir: Path) -> List[Path]:
    """The kernel's extensions beside their .py (a checkout imports them too); a read-only package is left as is."""
    from ..kernel import compile as kernel_compile

    source = package_dir / KERNEL
    return kernel_compile.build_extension(source) if os.access(source, os.W_OK) else []


def build(dest: Path, package_dir: Path | None = None, verbose: bool = False, model: str = "cam",
          compiled: bool = True) -> Path:
    """Build the FMU of ``model`` (a key of MODELS) at ``dest`` (a path ending in .fmu) and return it.

    ``compiled``: bundle the compiled drive kernel beside its .py (built first, in
    place); False builds a pure-Python FMU (the bench compares the two).
    """
    package_dir = Path(package_dir or PACKAGE_DIR).resolve()
    dest = Path(dest).resolve()
    if dest.suffix != ".fmu":
        raise BuildError(f"--dest must end in .fmu: {dest}")
    from pythonfmu.builder import FmuBuilder  # heavy import, only when building

    import importlib

    from . import model_description
    from .native import compile as native

    rel_script, cls = _model(model)
    slave_module = importlib.import_module(f"{__package__}.{rel_script.stem}")
    DEFAULT_EXPERIMENT, DESCRIPTION = slave_module.DEFAULT_EXPERIMENT, slave_module.DESCRIPTION
    script = package_dir / rel_script
    with tempfile.TemporaryDirectory(prefix="cam_fmu_build_") as tmp:
        staging = Path(tmp) / "stage"
        staging.mkdir()
        bundled = stage(package_dir, script, staging, ROOTS.get(model, ()))
        extensions: List[Path] = []
        kernel_inputs: List[Path] = []  # hashed into the private name: a pure-Python build gets another one
        if compiled and compiled_in_bundle(staging / PACKAGE):
            build_kernel_in_place(package_dir)
            kernel_inputs = [package_dir / KERNEL / "compile.py",
                             *(package_dir / KERNEL / f"{m}.pxd" for m in compiled_in_bundle(staging / PACKAGE))]
        names = native.privatize(staging, PACKAGE, script.stem, extra=kernel_inputs)  # cam_fmu_<hash>, ...
        if kernel_inputs:  # compiled again under the private name (native.compile_kernel says why)
            extensions = native.compile_kernel(package_dir / KERNEL, staging / names.package / KERNEL,
                                               compiled_in_bundle(staging / names.package))
        binary = native.build_binary(Path(tmp) / "native" / f"{model}.so")  # fails early without a C compiler
        kernel = [f"{KERNEL}.{m}" for m in compiled_in_bundle(staging / names.package)]
        info = check_bundle(staging, names.slave_module, cls, names.package, kernel)
        loaded = {m: not f.endswith(".py") for m, f in info["kernel"].items()}
        if any(is_ext != compiled for is_ext in loaded.values()):
            raise BuildError(f"the staged kernel modules loaded {info['kernel']}, expected "
                             f"{'the extensions' if compiled else 'the .py files'}")
        if verbose:
            print("bundled:", ", ".join(bundled + [str(e.name) for e in extensions]))
            print("modules imported at run time:", ", ".join(info["modules"]))
            print("kernel:", ", ".join(f"{m} ({Path(f).name})" for m, f in info["kernel"].items()))
        out = Path(tmp) / "out" / f"{model}.fmu"
        out.parent.mkdir()
        FmuBuilder.build_FMU(
            staging / f"{names.slave_module}.py",
            dest=out,
            project_files=[staging / names.package],
            canGetAndSetFMUstate=True,   # --handle-state
            canSerializeFMUstate=True,   # --serialize-state
        )
        model_description.rewrite_fmu(
            out,
            description=DESCRIPTION,
            default_experiment=(DEFAULT_EXPERIMENT.start_time, DEFAULT_EXPERIMENT.stop_time,
                                DEFAULT_EXPERIMENT.step_size),
            rows=model_description.ROWS[model](),
        )
        native.install(out, names, binary)  # our linux64 binary, python.txt, private pythonfmu
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(out, dest)
    return dest


def build_ssp(dest: Path, cam: Path, pi_speed: Path) -> Path:
    """models/speed_loop.ssp from the two built FMUs (experiments.ssp.speed_loop_system)."""
    from ..experiments.ssp import SPEED_LOOP_CAM, SPEED_LOOP_CONTROLLER, speed_loop_system, write_ssp

    system = speed_loop_system(SPEED_LOOP_CAM, SPEED_LOOP_CONTROLLER)
    return write_ssp(system, {"cam": cam, "controller": pi_speed}, dest)


def main(argv: List[str] | None = None) -> int:
    from ..experiments.fmu_file import default_model_path

    parser = argparse.ArgumentParser(prog="build_fmu.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--dest", type=Path, default=None,
                        help="build one FMU (--model, default cam) into this file; without --dest: "
                             "cam.fmu, pi_speed.fmu and speed_loop.ssp into models/ in a source checkout "
                             "(else a user cache)")
    parser.add_argument("--model", choices=sorted(MODELS), default="cam", help="the FMU --dest builds")
    parser.add_argument("--package-dir", type=Path, default=None, help=argparse.SUPPRESS)
    parser.add_argument("-v", "--verbose", action="store_true", help="list the bundled modules")
    parser.add_argument("--pure-python", action="store_true",
                        help="bundle the drive kernel as Python only (no compiled extension; for the bench)")
    args = parser.parse_args(argv)
    compiled = not args.pure_python
    try:
        if args.dest is not None:
            print(build(args.dest, args.package_dir, args.verbose, args.model, compiled))
            return 0
        built = {name: build(default_model_path(name), args.package_dir, args.verbose, name, compiled)
                 for name in MODELS}
        for path in built.values():
            print(path)
        print(build_ssp(default_model_path(SSP_NAME, ".ssp"), built["cam"], built["pi_speed"]))
    except (BuildError, RuntimeError) as exc:  # RuntimeError: native.NativeBuildError (no C compiler ...)
        print(f"build_fmu: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
