"""Build hook: the wheel carries the C engine's library, and a distribution wheel the shipped FMUs too.

The engine (cam_fmu/engine/csrc) is a plain shared library loaded with ctypes: no Python C API, so one
wheel serves every Python >= the minimum, tagged ``py3-none-<platform>``.

- ``pip install .`` (a source build): ``build_py`` compiles the library with this machine's C compiler into
  ``cam_fmu/engine/_lib/`` under the name ``cam_fmu.engine.build`` looks for; the FMUs are built at first use
  (into the user cache, for this machine). The wheel is tagged for this machine (``py3-none-linux_x86_64``).
- ``CAM_FMU_ENGINE_TARGET=<name>`` (a row of cam_fmu/engine/targets.py; ``python build_fmu.py --wheels DIR``
  sets it for each): zig compiles the library for that platform, the wheel carries the FMUs and SSPs of
  ``models/`` (every platform's binaries; built first when missing or stale) in ``cam_fmu/shipped/``, and it
  is tagged with the row's platform (``manylinux_2_17_x86_64``, ``win_amd64``, ``macosx_11_0_arm64`` ...).
  Such an installation needs no compiler and builds nothing.
Everything else is in pyproject.toml.
"""
from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

try:  # setuptools >= 70.1 carries bdist_wheel; before, the wheel package does
    from setuptools.command.bdist_wheel import bdist_wheel
except ImportError:  # pragma: no cover - depends on the build environment
    from wheel.bdist_wheel import bdist_wheel

ROOT = Path(__file__).resolve().parent
TARGET = os.environ.get("CAM_FMU_ENGINE_TARGET") or None


class BuildPyWithEngine(build_py):
    """build_py, then the engine library beside the built package's engine sources (and, for a target, the
    shipped FMUs and SSPs)."""

    def run(self) -> None:
        super().run()
        sys.path.insert(0, str(ROOT))  # this checkout's cam_fmu (the build tools only)
        from cam_fmu.engine import build

        lib = Path(self.build_lib) / "cam_fmu" / "engine" / "_lib"
        shutil.rmtree(lib, ignore_errors=True)  # a former build's library for another platform stays out
        dest = lib / build.library_name(target=TARGET)
        build.compile_library(dest, target=TARGET)
        print(f"cam_fmu: built the engine library {dest.name}")
        shipped = Path(self.build_lib) / "cam_fmu" / "shipped"
        shutil.rmtree(shipped, ignore_errors=True)
        if TARGET:
            from cam_fmu.fmu.build import shipped_files

            shipped.mkdir(parents=True)
            for path in shipped_files():
                shutil.copyfile(path, shipped / path.name)
                print(f"cam_fmu: ships {path.name}")


class PlatformWheel(bdist_wheel):
    """py3-none-<platform>: the library needs no Python C API, so any CPython >= the minimum loads it."""

    def get_tag(self) -> tuple[str, str, str]:
        platform = super().get_tag()[2]
        if TARGET:
            sys.path.insert(0, str(ROOT))
            from cam_fmu.engine import targets

            platform = targets.get(TARGET).wheel
        return "py3", "none", platform


class BinaryDistribution(Distribution):
    """The package carries a compiled library: its wheel is platform-specific."""

    def has_ext_modules(self) -> bool:
        return True


setup(cmdclass={"build_py": BuildPyWithEngine, "bdist_wheel": PlatformWheel}, distclass=BinaryDistribution)
