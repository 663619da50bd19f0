"""Compile the C engine (``csrc/src/*.c``) into a plain shared library.

    python -m cam_fmu.engine.build            # builds (or finds current) and prints the library's path

Build time only. The system C compiler (``$CC``, else ``cc``/``gcc``/``clang``)
compiles every ``csrc/src/*.c`` as C99 with IEEE semantics kept (no
``-ffast-math``; ``-ffp-contract=off``: no fused multiply-add, so the results
do not depend on the compiler's choice of instructions), linked with libm only.
The library's name carries a hash of its sources and flags, so a stale build is
never loaded; it is written beside this file, or where the package folder is not
writable, into ``$XDG_CACHE_HOME/cam_fmu`` (``~/.cache/cam_fmu``).
No compiler: ``EngineBuildError`` naming what was tried.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Sequence

HERE = Path(__file__).resolve().parent
CSRC = HERE / "csrc"
INCLUDE = CSRC / "include"
SOURCES = CSRC / "src"
LIBRARY_STEM = "libcamdrive"
# C99, warnings as errors, IEEE arithmetic exactly as written (see the module doc).
CFLAGS: tuple[str, ...] = ("-std=c99", "-O2", "-fPIC", "-ffp-contract=off", "-fno-fast-math",
                           "-Wall", "-Wextra", "-Werror", "-pedantic")
LDFLAGS: tuple[str, ...] = ("-shared", "-lm")


class EngineBuildError(RuntimeError):
    """The engine could not be compiled; the message says why and what was tried."""


def source_files() -> list[Path]:
    """The engine's C sources and headers, in a stable order."""
    return sorted(SOURCES.glob("*.c")) + sorted(INCLUDE.glob("*.h"))


def fmi_headers() -> Path:
    """The folder of the official FMI 2.0/3.0 headers: the copy fmpy (a core dependency) ships."""
    import fmpy

    folder = Path(fmpy.__file__).resolve().parent / "c-code"
    if not (folder / "fmi2Functions.h").is_file():
        raise EngineBuildError(f"the FMI headers are not in {folder} (fmpy's c-code folder): reinstall fmpy")
    return folder


def find_compiler() -> str:
    """The C compiler to use: ``$CC`` or the first of cc, gcc, clang on PATH."""
    tried = []
    for name in ([os.environ["CC"]] if os.environ.get("CC") else []) + ["cc", "gcc", "clang"]:
        path = shutil.which(name)
        if path:
            return path
        tried.append(name)
    raise EngineBuildError(f"no C compiler found (tried {', '.join(tried)}): install gcc "
                           "(Debian: apt-get install gcc) or set CC")


def digest(extra_flags: Sequence[str] = ()) -> str:
    """12 hex digits of the sources, headers and flags: the library's identity."""
    h = hashlib.sha256()
    for path in source_files():
        h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    h.update(" ".join(CFLAGS + LDFLAGS + tuple(extra_flags)).encode())
    return h.hexdigest()[:12]


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def library_dir() -> Path:
    """Where built libraries go: beside this file if writable, else the user's cache."""
    if _writable(HERE / "_lib"):
        return HERE / "_lib"
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "cam_fmu"
    cache.mkdir(parents=True, exist_ok=True)
    return cache


def compile_library(dest: Path, extra_flags: Sequence[str] = (), compiler: str | None = None) -> Path:
    """Compile every engine source into the shared library ``dest``; returns ``dest``."""
    cc = compiler or find_compiler()
    sources = [str(p) for p in sorted(SOURCES.glob("*.c"))]
    if not sources:
        raise EngineBuildError(f"no C sources in {SOURCES}")
    dest.parent.mkdir(parents=True, exist_ok=True)
    tmp = dest.with_name(f".{dest.name}.{os.getpid()}.tmp")
    cmd = [cc, *CFLAGS, *extra_flags, f"-I{INCLUDE}", *sources, "-o", str(tmp), *LDFLAGS]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        tmp.unlink(missing_ok=True)
        raise EngineBuildError(f"compiling the engine failed ({' '.join(cmd)}):\n{proc.stderr.strip()}")
    os.replace(tmp, dest)  # atomic: a concurrent loader never sees half a library
    return dest


def build(extra_flags: Sequence[str] = ()) -> Path:
    """The current engine library (compiled now unless a build of these sources exists)."""
    suffix = ".dll" if sys.platform == "win32" else ".so"
    dest = library_dir() / f"{LIBRARY_STEM}-{digest(extra_flags)}{suffix}"
    if dest.is_file():
        return dest
    return compile_library(dest, extra_flags)


def main() -> int:
    try:
        print(build())
    except EngineBuildError as exc:
        print(f"cam_fmu.engine.build: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
