"""The engine's cam program through ctypes: laws, motion tables, s(theta), breakpoints.

``EngineProfile.from_laws(...)`` and ``EngineProfile.from_table(text)`` build the C
engine's ``CamProfile`` (csrc/include/cam_profile.h); refusals raise ValueError with the
engine's message. The structures are engine/contract.py's, from which the header's are generated (their size is
checked against ``cam_profile_sizeof``). A test helper: tests/engine/test_engine_profile.py holds the C program against
the Python model with it.
"""
from __future__ import annotations

import ctypes
from typing import Sequence

from cam_fmu.engine.contract import SEGMENT_FIELDS, structure
from cam_fmu.engine.library import load
from cam_fmu.engine.simulator import CamError

__all__ = ["EngineProfile", "law_segments", "SEGMENT_FIELDS"]

_D = ctypes.c_double
_PD = ctypes.POINTER(_D)
_SIZE = ctypes.c_size_t


CamLaw, CamTable, CamProfile = (structure(name) for name in ("CamLaw", "CamTable", "CamProfile"))


def _lib() -> ctypes.CDLL:
    lib = load()
    if not getattr(lib, "_cam_profile_typed", False):
        lib.cam_profile_sizeof.restype = _SIZE
        lib.cam_profile_sizeof.argtypes = []
        if lib.cam_profile_sizeof() != ctypes.sizeof(CamProfile):
            raise RuntimeError("engine_profile: CamProfile differs from cam_profile.h")
        lib.cam_law_init.argtypes = [ctypes.POINTER(CamLaw), _D * 6, ctypes.c_char_p, ctypes.POINTER(CamError)]
        lib.cam_law_eval.argtypes = [ctypes.POINTER(CamLaw), _D, _D * 4]
        lib.cam_law_eval.restype = None
        lib.cam_profile_init_laws.argtypes = [ctypes.POINTER(CamProfile), _D * 6, _D * 6] + [_D] * 5 + [
            ctypes.POINTER(CamError)]
        lib.cam_profile_init_table.argtypes = [ctypes.POINTER(CamProfile), ctypes.c_char_p, _SIZE,
                                               ctypes.POINTER(CamError)]
        lib.cam_profile_free.argtypes = [ctypes.POINTER(CamProfile)]
        lib.cam_profile_free.restype = None
        lib.cam_profile_eval_counted.argtypes = [ctypes.POINTER(CamProfile), _D, _D * 4, ctypes.POINTER(_SIZE)]
        lib.cam_profile_eval_counted.restype = None
        lib.cam_first_crossed.argtypes = [_PD, _SIZE, _D, _D, ctypes.POINTER(_SIZE)]
        lib.cam_first_crossed.restype = _D
        lib._cam_profile_typed = True
    return lib


def law_segments(T: Sequence[float], name: str | None = None) -> tuple[tuple[float, ...], ...]:
    """The engine's non-empty segments of the law with split points T (7 floats each, as
    ``MotionLaw.segments()``); ValueError with the engine's message when refused."""
    lib, law, err = _lib(), CamLaw(), CamError()
    if lib.cam_law_init(ctypes.byref(law), (_D * 6)(*T), None if name is None else name.encode(), ctypes.byref(err)):
        raise ValueError(err.message.decode())
    return tuple(tuple(law.segments[SEGMENT_FIELDS * k:SEGMENT_FIELDS * (k + 1)]) for k in range(law.n_segments))


def law_eval(T: Sequence[float], t: float) -> tuple[float, float, float, float]:
    """(S, V, A, J) of the engine's law with split points T at t."""
    lib, law, err, out = _lib(), CamLaw(), CamError(), (_D * 4)()
    if lib.cam_law_init(ctypes.byref(law), (_D * 6)(*T), None, ctypes.byref(err)):
        raise ValueError(err.message.decode())
    lib.cam_law_eval(ctypes.byref(law), t, out)
    return tuple(out)


class EngineProfile:
    """A C ``CamProfile``: s(theta) and its derivatives, breakpoints, the breakpoint search."""

    def __init__(self) -> None:
        self._lib = _lib()
        self._p = CamProfile()
        self._live = False

    @classmethod
    def from_laws(cls, rise_T: Sequence[float], return_T: Sequence[float], lift: float, rise_angle: float,
                  upper_dwell: float, return_angle: float, lower_dwell: float) -> "EngineProfile":
        """Two laws with dwells (angles [rad] summing to 2 pi, lift [m])."""
        self, err = cls(), CamError()
        if self._lib.cam_profile_init_laws(ctypes.byref(self._p), (_D * 6)(*rise_T), (_D * 6)(*return_T), lift,
                                           rise_angle, upper_dwell, return_angle, lower_dwell, ctypes.byref(err)):
            raise ValueError(err.message.decode())
        self._live = True
        return self

    @classmethod
    def from_table(cls, text: str | bytes) -> "EngineProfile":
        """A motion table's CSV text (str is encoded as UTF-8)."""
        self, err = cls(), CamError()
        data = text.encode("utf-8") if isinstance(text, str) else bytes(text)
        if self._lib.cam_profile_init_table(ctypes.byref(self._p), data, len(data), ctypes.byref(err)):
            raise ValueError(err.message.decode())
        self._live = True
        return self

    def __del__(self) -> None:
        if getattr(self, "_live", False):
            self._lib.cam_profile_free(ctypes.byref(self._p))
            self._live = False

    @property
    def struct(self) -> CamProfile:
        """The C structure itself (read only by convention)."""
        return self._p

    def derivatives(self, theta: float) -> tuple[float, float, float, float]:
        """(s [m], ds/dtheta [m/rad], d2s/dtheta2, d3s/dtheta3) at theta [rad]."""
        out = (_D * 4)()
        self._lib.cam_profile_eval_counted(ctypes.byref(self._p), theta, out, None)
        return tuple(out)

    def derivatives_counted(self, theta: float) -> tuple[tuple[float, float, float, float], int]:
        """``derivatives`` and the number of knot comparisons it made (tables: the binary search)."""
        out, count = (_D * 4)(), _SIZE(0)
        self._lib.cam_profile_eval_counted(ctypes.byref(self._p), theta, out, ctypes.byref(count))
        return tuple(out), count.value

    def breakpoints(self) -> tuple[float, ...]:
        """The program's breakpoints [rad], ascending in [0, 2 pi)."""
        return tuple(self._p.points[k] for k in range(self._p.n_points))

    def feature_angle(self) -> float:
        """The program's finest angular detail [rad]."""
        return self._p.feature_angle

    @property
    def lift(self) -> float:
        """The lift h [m] (a table: its largest lift)."""
        return self._p.lift


def first_crossed(points: Sequence[float], start: float, end: float) -> tuple[float, int]:
    """The engine's first crossing of the ascending periodic points (NaN: none) and how many
    crossing angles it computed."""
    arr, count = (_D * len(points))(*points), _SIZE(0)
    found = _lib().cam_first_crossed(arr, len(points), start, end, ctypes.byref(count))
    return found, count.value
