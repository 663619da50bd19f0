"""Build hook: ``pip install .`` compiles the C engine into the installed package.

The engine (cam_fmu/engine/csrc) is a plain shared library that needs no Python C
API: ``build_py`` compiles it with the system C compiler into
``cam_fmu/engine/_lib/`` of the build, under the name ``cam_fmu.engine.build``
looks for, so an installed package never compiles at run time. With
``CAM_FMU_ENGINE_TARGET`` set to a name of cam_fmu/engine/targets.py (x86_64-linux,
aarch64-linux, x86_64-windows, x86_64-darwin, aarch64-darwin) it is compiled by zig
for that platform instead (a wheel for another platform, built on Linux). The wheel is
marked platform-specific because it carries that library. Everything else is
in pyproject.toml.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent


class BuildPyWithEngine(build_py):
    """build_py, then the engine library beside the built package's engine sources."""

    def run(self) -> None:
        super().run()
        sys.path.insert(0, str(ROOT))  # this checkout's cam_fmu (the build tools only)
        from cam_fmu.engine import build

        target = os.environ.get("CAM_FMU_ENGINE_TARGET") or None
        dest = Path(self.build_lib) / "cam_fmu" / "engine" / "_lib" / build.library_name(target=target)
        build.compile_library(dest, target=target)
        print(f"cam_fmu: built the engine library {dest.name}")


class BinaryDistribution(Distribution):
    """The package carries a compiled library: its wheel is platform-specific."""

    def has_ext_modules(self) -> bool:
        return True


setup(cmdclass={"build_py": BuildPyWithEngine}, distclass=BinaryDistribution)
