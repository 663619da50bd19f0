"""Load the C engine's shared library with ctypes (built on first use by ``build.py``).

ctypes rather than cffi: it is in the standard library (no dependency, no
build step of its own), the engine's interface is a handful of plain C
functions over doubles, ints and opaque pointers, and the library needs no
Python C API, so one binary serves every Python version.
"""
from __future__ import annotations

import ctypes
from functools import lru_cache

from .build import build


@lru_cache(maxsize=None)
def load() -> ctypes.CDLL:
    """The engine library, built if needed; one handle per process."""
    return ctypes.CDLL(str(build()))
