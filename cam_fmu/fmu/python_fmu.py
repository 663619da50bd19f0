"""FMUs whose model is Python by nature (pi_speed.fmu: a controller written in Python), with pythonfmu 0.7.0.

cam.fmu is not built here: its model is the C engine (``engine_fmu``). What goes
into a Python FMU (under resources/):
- the slave script (``cam_fmu/fmu/pi_speed_fmu_slave.py``, imported by the FMU
  as a top-level module),
- a copy of pythonfmu (pythonfmu does that itself),
- ``cam_fmu/``: only the modules the slave needs, found by following the
  package-internal imports (``import cam_fmu.x``, ``from cam_fmu import x``,
  ``from .x import y``...) of the slave script, transitively. The closure may
  import only the standard library and numpy: anything else (scipy above all:
  it crashes native hosts at Py_Finalize) fails the build. The bundled package
  gets a minimal ``__init__.py`` unless a bundled module needs a name from the
  real one.

Before zipping, the staged bundle is imported in an isolated interpreter
(``python -I``, nothing of this checkout on sys.path) to prove it is complete.
After zipping, modelDescription.xml is completed by ``model_description``
(units, initial, InitialUnknowns, DefaultExperiment...).

linux64: ``native.compile`` stages the bundle under private names
(``cam_fmu_<hash>``, ``<slave>_<hash>``), compiles the project's own FMI wrapper
with the system C compiler (no compiler: the build stops) and puts it,
``resources/python.txt`` and ``resources/native.txt`` into the FMU (docs/fmu.md).
"""
from __future__ import annotations

import ast
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Dict, Iterable, List, Set, Tuple

PACKAGE = "cam_fmu"
PACKAGE_DIR = Path(__file__).resolve().parents[1]  # this cam_fmu
# Every FMU built here: model name -> (slave script relative to the package, slave class).
MODELS: Dict[str, Tuple[Path, str]] = {
    "pi_speed": (Path("fmu") / "pi_speed_fmu_slave.py", "PiSpeedSlave"),
}
# Files that shape a Python FMU beside the bundled closure (their change makes a built FMU stale).
BUILD_SOURCES = (Path("fmu") / "python_fmu.py", Path("fmu") / "model_description.py",
                 Path("fmu") / "native" / "fmi2_python.c", Path("fmu") / "native" / "bridge.py",
                 Path("fmu") / "native" / "compile.py")
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


def bundle_modules(package_dir: Path, script: Path) -> Tuple[List[Path], bool]:
    """Files of ``package_dir`` the slave needs (transitively) and whether the real __init__ is needed."""
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


def stage(package_dir: Path, script: Path, staging: Path) -> List[str]:
    """Copy the slave script and the needed part of the package into ``staging``; return the bundled names.

    Each FMU bundles only its own slave's closure: ``native.privatize`` then
    renames the package and the script to names private to this build
    (``cam_fmu_<hash>``), so two Python FMUs loaded into one host process
    never share or shadow each other's modules.
    """
    modules, needs_init = bundle_modules(package_dir, script)
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
print(json.dumps({{"forbidden": forbidden, "modules": modules}}))
"""


def check_bundle(staging: Path, module: str, cls: str, package: str = PACKAGE) -> dict:
    """Import and step the staged slave in an isolated interpreter: proves the bundle is complete."""
    code = CHECK_BUNDLE.format(module=module, cls=cls, package=package, forbidden=sorted(FORBIDDEN))
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


def sources(package_dir: Path = PACKAGE_DIR, model: str = "pi_speed") -> list[Path]:
    """Every file whose content ends up in (or shapes) the Python FMU of ``model``."""
    script = package_dir / _model(model)[0]
    modules = bundle_modules(package_dir, script)[0]
    return [script, *modules, *(package_dir / p for p in BUILD_SOURCES)]


def build(dest: Path, model: str = "pi_speed", package_dir: Path | None = None, verbose: bool = False) -> Path:
    """Build the Python FMU of ``model`` (a key of MODELS) at ``dest`` (a path ending in .fmu) and return it."""
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
        bundled = stage(package_dir, script, staging)
        names = native.privatize(staging, PACKAGE, script.stem)  # cam_fmu_<hash>, ...
        binary = native.build_binary(Path(tmp) / "native" / f"{model}.so")  # fails early without a C compiler
        info = check_bundle(staging, names.slave_module, cls, names.package)
        if verbose:
            print("bundled:", ", ".join(bundled))
            print("modules imported at run time:", ", ".join(info["modules"]))
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
