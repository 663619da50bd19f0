"""The general harmonic-trapezoid cam curve (7 segments), dimensionless.

T in [0, 1] is the normalised cam angle, S(T) in [0, 1] the normalised lift.
Split points 0 <= T1 <= ... <= T6 <= 1 (T0 = 0, T7 = 1) cut [0, 1] into seven
segments; with F_i = (T_i - T_{i-1}) / (pi/2) and x = (T - T_{i-1}) / F_i the
acceleration A = d2S/dT2 is (docs/model.md section 1; the blog post's *code*, not its
printed table, which has sign errors on segments 3, 5 and 7):

    1 [0, T1]    +Amp sin x        5 (T4, T5]  -Amm sin x
    2 (T1, T2]   +Amp              6 (T5, T6]  -Amm
    3 (T2, T3]   +Amp cos x        7 (T6, 1]   -Amm cos x
    4 (T3, T4]   0

V and S are integrated in *local* form on each segment, u = T - T_{i-1}:

    V = V0_i + int_0^u A,   S = S0_i + V0_i u + int_0^u int_0^v A,

so the 14 integration constants are (V0_i, S0_i), the values of V and S at the
start of each segment.  Continuity of V and S at T1..T6 together with
S(0) = V(0) = 0 fixes them by forward propagation; everything is linear in
(Amp, Amm), and V(1) = 0, S(1) = 1 is a 2x2 system solved in closed form.
Zero-length segments contribute nothing and are never divided by.

Convention at split points: segment 1 is [0, T1], every other segment is
(T_{i-1}, T_i] and zero-length segments own no point.  Exactly at a split point
both evaluation paths therefore return the values of the segment *ending* there
(the left limit), and at T = 0 the start of the first non-empty segment (the
right limit).  Only A and J can differ between the two sides.  Outside [0, 1]
the law continues as dwells: (0, 0, 0, 0) for T < 0 and (1, 0, 0, 0) for T > 1.

This module imports only math and numpy; the C engine's laws (``csrc/src/motion_law.c``) are held to it
(tests/engine/test_engine_profile.py).
"""

from __future__ import annotations

import math
from typing import NamedTuple, Sequence

import numpy as np

__all__ = ["MotionLaw", "Segment", "SHAPE_CONST", "SHAPE_SIN", "SHAPE_COS", "golden_max"]

_HALF_PI = 0.5 * math.pi

# Segment shapes: A = c * shape(x).
SHAPE_CONST, SHAPE_SIN, SHAPE_COS = 0, 1, 2
_CONST, _SIN, _COS = SHAPE_CONST, SHAPE_SIN, SHAPE_COS
_KINDS = (_SIN, _CONST, _COS, _CONST, _SIN, _CONST, _COS)


class Segment(NamedTuple):
    """One non-empty segment of a law: A = c * shape((T - start) / F) on (start, end]."""

    end: float
    start: float
    F: float  # (end - start) / (pi/2); 1 for constant segments (unused there)
    c: float  # coefficient: +Amp, -Amm or 0
    kind: int  # SHAPE_CONST, SHAPE_SIN or SHAPE_COS
    V0: float  # V at the segment start
    S0: float  # S at the segment start
# Which coefficient each segment uses: +1 -> +Amp, -1 -> -Amm, 0 -> A = 0.
_SIDE = (1, 1, 1, 0, -1, -1, -1)


def _validate(T: Sequence[float]) -> tuple[float, ...]:
    try:
        values = tuple(float(t) for t in T)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"split points must be 6 numbers T1..T6, got {T!r}") from exc
    if len(values) != 6:
        raise ValueError(f"split points must be 6 numbers T1..T6, got {len(values)}: {values!r}")
    names = [f"T{i}={v!r}" for i, v in enumerate(values, 1)]
    bad = [n for n, v in zip(names, values) if not math.isfinite(v)]
    if bad:
        raise ValueError(f"split points must be finite numbers: {', '.join(bad)}")
    bad = [n for n, v in zip(names, values) if not 0.0 <= v <= 1.0]
    if bad:
        raise ValueError(f"split points must lie in [0, 1]: {', '.join(bad)}")
    bad = [f"{names[i]} > {names[i + 1]}" for i in range(5) if values[i] > values[i + 1]]
    if bad:
        raise ValueError(f"split points must be ordered T1 <= T2 <= ... <= T6: {', '.join(bad)}")
    if values[2] == 0.0:
        raise ValueError(
            f"no acceleration segment: {', '.join(names[:3])} (need T3 > 0 to leave the lower dwell)")
    if values[3] == 1.0:
        raise ValueError(
            f"no deceleration segment: {', '.join(names[3:])} (need T4 < 1 to reach the upper dwell)")
    return values


_INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0


def golden_max(f, a: float, b: float, tol: float = 1e-13) -> tuple[float, float]:
    """Maximum of a unimodal f on [a, b] by golden-section search: (x, f(x))."""
    c = b - _INV_PHI * (b - a)
    d = a + _INV_PHI * (b - a)
    fc, fd = f(c), f(d)
    while b - a > tol:
        if fc >= fd:
            b, d, fd = d, c, fc
            c = b - _INV_PHI * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + _INV_PHI * (b - a)
            fd = f(d)
    x = 0.5 * (a + b)
    return x, f(x)


def _segment_increments(kind: int, L: float, F: float) -> tuple[float, float]:
    """(int_0^L shape, int_0^L int_0^v shape) for a unit coefficient."""
    if L == 0.0:
        return 0.0, 0.0
    if kind == _CONST:
        return L, 0.5 * L * L
    if kind == _SIN:  # V: F (1 - cos x) -> F;  S: F (u - F sin x) -> F (L - F)
        return F, F * (L - F)
    return F, F * F  # _COS: V: F sin x -> F;  S: F^2 (1 - cos x) -> F^2


class MotionLaw:
    """One member of the general harmonic-trapezoid family; immutable.

    ``MotionLaw((T1, ..., T6))`` raises ValueError naming the offending values
    when the split points cannot make a curve (wrong count, NaN/inf, outside
    [0, 1], unordered, no acceleration or no deceleration segment).
    """

    __slots__ = ("T", "Amp", "Amm", "_edges", "_segs", "_V0", "_S0", "_arr")

    T: tuple[float, ...]
    Amp: float
    Amm: float

    def __init__(self, T: Sequence[float]) -> None:
        values = _validate(T)
        edges = (0.0,) + values + (1.0,)
        L = [edges[i + 1] - edges[i] for i in range(7)]
        F = [l / _HALF_PI for l in L]

        # Propagate V and S for unit Amp (side +1) and unit Amm (side -1)
        # separately: V(1) and S(1) are linear in (Amp, Amm).
        def propagate(side: int) -> tuple[list[float], list[float], float, float]:
            V0, S0 = [], []
            v = s = 0.0
            for i in range(7):
                V0.append(v)
                S0.append(s)
                c = 1.0 if _SIDE[i] == side else 0.0
                dv, ds = _segment_increments(_KINDS[i], L[i], F[i])
                s += v * L[i] + c * ds
                v += c * dv
            return V0, S0, v, s

        Vp, Sp, vp, sp = propagate(1)    # contributions of +Amp
        Vm, Sm, vm, sm = propagate(-1)   # contributions of -Amm (sign applied below)
        # vp*Amp - vm*Amm = 0 and sp*Amp - sm*Amm = 1.  vp, vm > 0 after
        # validation and det > 0 (the deceleration's centroid lies right of the
        # acceleration's), so this never divides by zero.
        det = sp * vm - sm * vp
        Amp = vm / det if det > 0.0 else math.inf
        Amm = vp / det if det > 0.0 else math.inf
        if not (math.isfinite(Amp) and math.isfinite(Amm)):
            raise ValueError(
                f"split points {values!r} are too close to make a finite curve "
                f"(acceleration or deceleration phase of length ~0)")
        V0 = tuple(Amp * a - Amm * b for a, b in zip(Vp, Vm))
        S0 = tuple(Amp * a - Amm * b for a, b in zip(Sp, Sm))
        coef = [Amp if s > 0 else (-Amm if s < 0 else 0.0) for s in _SIDE]

        # Non-empty segments only, as plain-float tuples for the scalar path:
        # (end, start, F, c, kind, V0, S0).  Const segments get F = 1 (unused).
        segs = tuple(
            Segment(edges[i + 1], edges[i], F[i] if _KINDS[i] != _CONST else 1.0,
                    coef[i], _KINDS[i], V0[i], S0[i])
            for i in range(7) if L[i] > 0.0)
        arr = {k: np.array([s[j] for s in segs], dtype=float)
               for j, k in enumerate(("end", "start", "F", "c", "kind", "V0", "S0"))}

        set_ = object.__setattr__
        set_(self, "T", values)
        set_(self, "Amp", float(Amp))
        set_(self, "Amm", float(Amm))
        set_(self, "_edges", edges)
        set_(self, "_segs", segs)
        set_(self, "_V0", V0)
        set_(self, "_S0", S0)
        set_(self, "_arr", arr)

    # -- immutability and identity ------------------------------------------
    def __setattr__(self, name, value):
        raise AttributeError(f"MotionLaw is immutable (tried to set {name!r})")

    def __delattr__(self, name):
        raise AttributeError(f"MotionLaw is immutable (tried to delete {name!r})")

    def __eq__(self, other):
        return isinstance(other, MotionLaw) and other.T == self.T

    def __hash__(self):
        return hash(("MotionLaw", self.T))

    def __repr__(self):
        return f"MotionLaw(T={self.T!r})"

    def __reduce__(self):
        return (MotionLaw, (self.T,))

    # -- evaluation ------------------------------------------------------------
    def scalar(self, T: float) -> tuple[float, float, float, float]:
        """(S, V, A, J) at one T, plain floats, math only (FMU hot path).

        At a split point: the segment ending there (left limit); at T = 0 the
        first non-empty segment (right limit); T < 0 -> (0, 0, 0, 0);
        T > 1 -> (1, 0, 0, 0).  NaN propagates.
        """
        if T < 0.0:
            return 0.0, 0.0, 0.0, 0.0
        if T > 1.0:
            return 1.0, 0.0, 0.0, 0.0
        for seg in self._segs:
            if T <= seg[0]:
                break
        _, t0, F, c, kind, V0, S0 = seg
        u = T - t0
        if kind == _CONST:
            return S0 + u * (V0 + 0.5 * c * u), V0 + c * u, c, 0.0
        x = u / F
        sx = math.sin(x)
        cx = math.cos(x)
        cF = c * F
        if kind == _SIN:
            return S0 + V0 * u + cF * (u - F * sx), V0 + cF * (1.0 - cx), c * sx, c / F * cx
        return S0 + V0 * u + cF * F * (1.0 - cx), V0 + cF * sx, c * cx, -c / F * sx

    def evaluate(self, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(S, V, A, J) over an array of T; same conventions as :meth:`scalar`."""
        T = np.asarray(T, dtype=float)
        a = self._arr
        idx = np.searchsorted(a["end"], T, side="left")
        idx = np.minimum(idx, len(self._segs) - 1)
        t0, F, c, kind, V0, S0 = (a[k][idx] for k in ("start", "F", "c", "kind", "V0", "S0"))
        u = T - t0
        # np.where evaluates every branch: a linear segment's F (or an empty one's)
        # makes u / F and c / F meaningless there, and they are discarded.
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            x = u / F
            sx, cx = np.sin(x), np.cos(x)
            cF = c * F
            is_sin, is_cos = kind == _SIN, kind == _COS
            S = np.where(is_sin, S0 + V0 * u + cF * (u - F * sx),
                         np.where(is_cos, S0 + V0 * u + cF * F * (1.0 - cx),
                                  S0 + u * (V0 + 0.5 * c * u)))
            V = np.where(is_sin, V0 + cF * (1.0 - cx), np.where(is_cos, V0 + cF * sx, V0 + c * u))
            A = np.where(is_sin, c * sx, np.where(is_cos, c * cx, c))
            J = np.where(is_sin, c / F * cx, np.where(is_cos, -c / F * sx, 0.0))
        before, after = T < 0.0, T > 1.0
        S = np.where(before, 0.0, np.where(after, 1.0, S))
        outside = before | after
        V = np.where(outside, 0.0, V)
        A = np.where(outside, 0.0, A)
        J = np.where(outside, 0.0, J)
        return S, V, A, J

    # -- structure ---------------------------------------------------------------
    def segments(self) -> tuple[Segment, ...]:
        """The non-empty segments in order (zero-length ones own no point)."""
        return self._segs

    def constants(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The 14 integration constants in local form: (V0_1..V0_7, S0_1..S0_7),
        V and S at the start T_{i-1} of each segment (zero-length ones included)."""
        return self._V0, self._S0

    def limits(self, t: float) -> tuple[float, float]:
        """(A(t-), A(t+)): one-sided limits of the acceleration, with the
        dwells outside [0, 1] (A = 0) on either side."""
        left = right = 0.0
        for end, start, F, c, kind, _, _ in self._segs:
            if end == t and 0.0 < end:
                left = 0.0 if kind == _COS else c          # value at x = pi/2 or const
            if start == t and start < 1.0:
                right = 0.0 if kind == _SIN else c         # value at x = 0 or const
        return left, right

    def jumps(self) -> tuple[float, ...]:
        """T values in [0, 1] (ends included) where A jumps, i.e. J is unbounded."""
        scale = max(self.Amp, self.Amm)
        out = []
        for t in sorted(set(self._edges)):
            left, right = self.limits(t)
            if abs(left - right) > 1e-12 * scale:
                out.append(t)
        return tuple(out)
