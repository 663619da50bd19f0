"""`cam-fmu host-env`: the environment a non-Python host needs to run cam.fmu.

cam.fmu's binary (pythonfmu's ``binaries/linux64/cam.so``) embeds a Python
interpreter but does not link libpython: a Python host (fmpy) already has the
symbols, a native host (ecos, a C/C++ or Java tool) does not and crashes when it
loads the FMU. The fix is to preload this machine's libpython and tell the
embedded interpreter where its standard library and packages (numpy) are:

    LD_PRELOAD=/path/libpython3.11.so.1.0 PYTHONHOME=/prefix PYTHONPATH=/site-packages

Everything is computed with ``sysconfig`` for the interpreter that runs this
command, so run it with the Python (venv) whose numpy the FMU should use.
Only the standard library is imported here.
"""
from __future__ import annotations

import argparse
import json
import os
import shlex
import site
import sys
import sysconfig
from pathlib import Path
from typing import Dict, List


class HostEnvError(RuntimeError):
    pass


def libpython_path() -> Path:
    """The shared libpython of the running interpreter (the file to LD_PRELOAD)."""
    if sys.platform == "win32":
        raise HostEnvError("host-env computes LD_PRELOAD for Linux hosts; on Windows put the Python "
                           "directory (with python3X.dll) on PATH instead")
    libdir = sysconfig.get_config_var("LIBDIR") or ""
    candidates: List[Path] = []
    for var in ("INSTSONAME", "LDLIBRARY"):
        name = sysconfig.get_config_var(var)
        if name and ".so" in name:
            candidates.append(Path(libdir) / name)
            multiarch = sysconfig.get_config_var("MULTIARCH")
            if multiarch:
                candidates.append(Path(libdir) / multiarch / name)
    for path in candidates:
        if path.is_file():
            return path
    if not sysconfig.get_config_var("Py_ENABLE_SHARED"):
        raise HostEnvError(
            f"this Python ({sys.executable}) is built without a shared libpython (Py_ENABLE_SHARED = 0): "
            "native FMU hosts need one; use a Python built with --enable-shared "
            "(e.g. Debian's python3, or pyenv with PYTHON_CONFIGURE_OPTS=--enable-shared)")
    raise HostEnvError("shared libpython not found; looked for: " + ", ".join(map(str, candidates)))


def python_path() -> List[str]:
    """Directories with the packages the FMU imports (numpy): this environment's site-packages."""
    paths: List[str] = []
    for key in ("purelib", "platlib"):
        path = sysconfig.get_paths().get(key)
        if path and path not in paths and os.path.isdir(path):
            paths.append(path)
    try:
        import importlib.util
        spec = importlib.util.find_spec("numpy")
        if spec is not None and spec.origin:
            numpy_dir = str(Path(spec.origin).parent.parent)
            if numpy_dir not in paths:
                paths.append(numpy_dir)  # e.g. numpy in the user site
    except (ImportError, ValueError):
        pass
    if site.ENABLE_USER_SITE and os.path.isdir(site.getusersitepackages()) and site.getusersitepackages() not in paths:
        paths.append(site.getusersitepackages())
    return paths


def host_env() -> Dict[str, str]:
    """The variables a native host needs: LD_PRELOAD, PYTHONHOME, PYTHONPATH."""
    return {
        "LD_PRELOAD": str(libpython_path()),
        "PYTHONHOME": sys.base_prefix,  # the standard library's prefix (not a venv's)
        "PYTHONPATH": os.pathsep.join(python_path()),
    }


def env_line(env: Dict[str, str] | None = None, export: bool = False) -> str:
    env = host_env() if env is None else env
    parts = [f"{k}={shlex.quote(v)}" for k, v in env.items()]
    if export:
        return "\n".join(f"export {p}" for p in parts)
    return " ".join(parts)
