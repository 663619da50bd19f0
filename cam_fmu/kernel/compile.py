"""Compile the kernel's modules (``COMPILED_MODULES``) into extension modules with Cython.

    python -m cam_fmu.kernel.compile           # builds in place, prints the extension paths

Build time only (never bundled into the FMU). For each module ``name``:
Cython (pure-Python mode) turns ``name.py`` with the C types of ``name.pxd``
into C in a temporary folder, the system C compiler (``$CC``, else
``cc``/``gcc``/``clang``) turns that into ``name<EXT_SUFFIX>``
(``drive_kernel.cpython-311-x86_64-linux-gnu.so``), written beside the .py by
default. Python's import system then prefers the extension where the ABI tag
matches and falls back to the .py elsewhere.

The C is compiled with -O2 and IEEE semantics kept: no -ffast-math, and
-ffp-contract=off (no fused multiply-add), so compiled and pure-Python runs
give the same bits. A build is skipped while the extension is newer than its
.py, its .pxd and this file. Missing Cython or C compiler: ``KernelBuildError``
(no silent fallback at build time; the fallback to the .py is at import time).
"""
from __future__ import annotations

import importlib.machinery
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

from . import COMPILED_MODULES

KERNEL_DIR = Path(__file__).resolve().parent
EXT_SUFFIX = importlib.machinery.EXTENSION_SUFFIXES[0]  # '.cpython-311-x86_64-linux-gnu.so'
# -O2 and nothing that changes floating-point results (see the module doc).
CFLAGS = ("-shared", "-fPIC", "-O2", "-fwrapv", "-fno-strict-aliasing", "-ffp-contract=off", "-fno-fast-math",
          "-DNDEBUG", "-w")


class KernelBuildError(RuntimeError):
    pass


def extension_path(name: str, dest_dir: Path | None = None) -> Path:
    """Where the extension of module ``name`` goes (``dest_dir``, default the kernel package)."""
    return Path(dest_dir or KERNEL_DIR) / f"{name}{EXT_SUFFIX}"


def inputs(name: str, source_dir: Path | None = None) -> list[Path]:
    """The files the extension of ``name`` is made from: its .py, its .pxd (and this build script)."""
    source_dir = Path(source_dir or KERNEL_DIR)
    return [source_dir / f"{name}.py", source_dir / f"{name}.pxd", Path(__file__).resolve()]


def is_current(name: str, source_dir: Path | None = None, dest_dir: Path | None = None) -> bool:
    """True when the extension exists and is newer than each of its inputs."""
    ext = extension_path(name, dest_dir or source_dir)
    if not ext.is_file():
        return False
    return all(ext.stat().st_mtime >= p.stat().st_mtime for p in inputs(name, source_dir) if p.is_file())


def find_compiler() -> str:
    for candidate in filter(None, (os.environ.get("CC"), "cc", "gcc", "clang")):
        path = shutil.which(candidate.split()[0])
        if path:
            return path
    raise KernelBuildError("no C compiler found (tried $CC, cc, gcc, clang): the drive kernel is compiled from the "
                           "C that Cython generates. Install one (setup.sh does: apt-get install gcc) and build again.")


def _cython():
    try:
        import Cython  # noqa: F401
        from Cython.Compiler import Main
    except ImportError as exc:
        raise KernelBuildError(f"Cython is not installed ({exc}): the drive kernel is compiled with it. "
                               "Install it (pip install 'Cython>=3.0'; setup.sh does) and build again.") from None
    return Main


def _full_module_name(source: Path) -> str:
    """Dotted name of ``source`` from the __init__.py files above it (cam_fmu.kernel.drive_kernel)."""
    parts = [source.stem]
    folder = source.parent
    while (folder / "__init__.py").is_file():
        parts.insert(0, folder.name)
        folder = folder.parent
    return ".".join(parts)


def compile_module(name: str, source_dir: Path, dest_dir: Path, compiler: str | None = None) -> Path:
    """Cython + C compiler for one module, unconditionally; the extension replaces any old one atomically."""
    main = _cython()
    cc = compiler or find_compiler()
    source, pxd = source_dir / f"{name}.py", source_dir / f"{name}.pxd"
    for needed in (source, pxd):
        if not needed.is_file():
            raise KernelBuildError(f"{needed} does not exist: a compiled module needs its .py and its .pxd")
    include = Path(sysconfig.get_paths()["include"])
    if not (include / "Python.h").is_file():
        raise KernelBuildError(f"Python.h not found in {include}: install the Python development headers")
    dest = extension_path(name, dest_dir)
    dest.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="cam_fmu_kernel_") as tmp:
        c_file = Path(tmp) / f"{name}.c"
        # the .pxd beside the .py is found by Cython itself (pure-Python mode's augmenting .pxd)
        result = main.compile(str(source), full_module_name=_full_module_name(source), output_file=str(c_file),
                              language_level=3)
        if result.num_errors or not c_file.is_file():
            raise KernelBuildError(f"Cython could not translate {source} ({result.num_errors} error(s), see above)")
        built = Path(tmp) / dest.name
        cmd = [cc, *CFLAGS, f"-I{include}", str(c_file), "-o", str(built), "-lm"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise KernelBuildError(f"compiling the C of {source.name} failed:\n{' '.join(cmd)}\n{proc.stderr}")
        partial = dest.with_name(f".{dest.name}.{os.getpid()}.tmp")
        shutil.copyfile(built, partial)
        os.chmod(partial, 0o755)
        os.replace(partial, dest)  # a new inode: a process that has the old one loaded keeps it
    return dest


def build_extension(source_dir: Path | None = None, dest_dir: Path | None = None,
                    modules: tuple[str, ...] = COMPILED_MODULES, force: bool = False) -> list[Path]:
    """Build (or keep, when current) the extension of each module; return their paths.

    ``source_dir`` holds ``<name>.py`` and ``<name>.pxd`` (default: this kernel
    package); the extensions go to ``dest_dir`` (default: ``source_dir``).
    """
    source_dir = Path(source_dir or KERNEL_DIR).resolve()
    dest_dir = Path(dest_dir or source_dir).resolve()
    _cython()  # fails clearly even when every extension is current
    built = []
    for name in modules:
        if force or not is_current(name, source_dir, dest_dir):
            compile_module(name, source_dir, dest_dir)
        built.append(extension_path(name, dest_dir))
    return built


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="python -m cam_fmu.kernel.compile", description=__doc__.split("\n\n")[0])
    parser.add_argument("--force", action="store_true", help="rebuild even when the extensions are current")
    args = parser.parse_args(argv)
    try:
        for path in build_extension(force=args.force):
            print(path)
    except KernelBuildError as exc:
        print(f"cam_fmu.kernel.compile: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
