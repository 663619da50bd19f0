"""The platforms every C build of the project covers: one table, read by the engine library's build, the FMUs'
binaries and the tests.

Build time only. Every row is compiled on one Linux machine by zig's C compiler (the ``ziglang`` wheel:
``python -m ziglang cc -target TRIPLE``), with no cross compiler installed: Linux against glibc 2.17 (the
manylinux2014 floor), Windows against the mingw-w64 headers and the Universal C Runtime, macOS against zig's
own SDK stubs. ``runs`` says how the tests run a binary of the row on the build machine (x86_64 Debian):
``native``, ``qemu`` (qemu-aarch64-static with Debian's libc6-arm64-cross), ``wine`` (wine64), or ``none``
(macOS: built and inspected, not run).
"""
from __future__ import annotations

import platform
import sys
from dataclasses import dataclass


@dataclass(frozen=True)
class Target:
    """One platform: its name (the FMI 3.0 platform tuple), zig's target triple, the FMUs' binary folders,
    the shared library's suffix, extra compiler flags and how the tests run it here."""

    name: str
    zig: str
    fmi2: str  # FMI 2.0's binaries/ folder (darwin64: one universal binary for both macOS rows)
    fmi3: str  # FMI 3.0's binaries/ folder: the platform tuple
    suffix: str
    flags: tuple[str, ...]
    runs: str  # native | qemu | wine | none
    system: str  # platform.system() of a machine that loads it
    machines: tuple[str, ...]  # platform.machine() spellings of that architecture
    wheel: str  # the platform tag of the package's wheel for it (py3-none-<wheel>)


GLIBC_FLOOR = (2, 17)  # the Linux rows link against glibc 2.17: no versioned symbol above it
TARGETS: tuple[Target, ...] = (
    Target("x86_64-linux", "x86_64-linux-gnu.2.17", "linux64", "x86_64-linux", ".so", (), "native",
           "Linux", ("x86_64", "amd64"), "manylinux_2_17_x86_64.manylinux2014_x86_64"),
    # FMI 2.0 names no folder for aarch64 Linux: the FMI 3.0 tuple (docs/fmu.md, "What a target machine needs")
    Target("aarch64-linux", "aarch64-linux-gnu.2.17", "aarch64-linux", "aarch64-linux", ".so", (), "qemu",
           "Linux", ("aarch64", "arm64"), "manylinux_2_17_aarch64.manylinux2014_aarch64"),
    Target("x86_64-windows", "x86_64-windows-gnu", "win64", "x86_64-windows", ".dll", (), "wine",
           "Windows", ("amd64", "x86_64"), "win_amd64"),
    # macOS: the oldest release as the minimum (zig's default is its newest SDK's, 15.0): 10.13 on Intel, 11.0 (the
    # first) on Apple silicon
    Target("x86_64-darwin", "x86_64-macos.10.13", "darwin64", "x86_64-darwin", ".dylib", (), "none",
           "Darwin", ("x86_64",), "macosx_10_13_x86_64"),
    Target("aarch64-darwin", "aarch64-macos.11.0", "darwin64", "aarch64-darwin", ".dylib", (), "none",
           "Darwin", ("arm64", "aarch64"), "macosx_11_0_arm64"),
)
NAMES = tuple(t.name for t in TARGETS)


class TargetError(ValueError):
    """A target name that is not in the table."""


def get(name: str) -> Target:
    """The row called ``name`` (one of NAMES)."""
    for target in TARGETS:
        if target.name == name:
            return target
    raise TargetError(f"target {name!r}: allowed {', '.join(NAMES)}")


def host() -> Target | None:
    """The row of this machine, or None (a platform the table does not cover: build from the FMU's sources)."""
    system, machine = platform.system(), platform.machine().lower()
    if sys.maxsize <= 2 ** 32:
        return None
    return next((t for t in TARGETS if t.system == system and machine in t.machines), None)


def host_suffix() -> str:
    """The shared-library suffix of this machine: .dll, .dylib or .so."""
    return ".dll" if sys.platform == "win32" else ".dylib" if sys.platform == "darwin" else ".so"


__all__ = ["GLIBC_FLOOR", "NAMES", "TARGETS", "Target", "TargetError", "get", "host", "host_suffix"]
