"""The drive's hot path, one module compiled by Cython in pure-Python mode (docs/performance.md).

``drive_kernel.py`` is plain Python: the readable source and the fallback. Its
twin ``drive_kernel.pxd`` gives Cython the C types (cdef class attributes,
typed methods), and ``compile.py`` turns the pair into an extension module
placed beside the .py. Python's import system prefers the extension where its
ABI tag matches (``cpython-311-x86_64-linux-gnu``) and loads the .py
everywhere else, so one import serves both paths.
"""
from __future__ import annotations

COMPILED_MODULES: tuple[str, ...] = ("drive_kernel",)  # the modules compile.py turns into extensions


def compiled() -> bool:
    """True when the drive kernel in use is the compiled extension, False for the pure-Python fallback."""
    from . import drive_kernel

    return not str(drive_kernel.__file__).endswith(".py")
