"""The residual vibration after a rise from the law's acceleration spectrum, in closed form per segment.

The train: an end mass m on a spring k with a damper d in parallel, its other end moved by the follower,
y(t) = h S(t / t_r). In the follower's frame, e = x - y (x: the end mass), time u = t / t_r and lengths in h:

    e'' + 2 zeta W e' + W^2 e = -A(u),    W = 2 pi r,  r = t_r / T_n,  T_n = 2 pi sqrt(m / k),
    zeta = d / (2 sqrt(k m)),

from rest (e = e' = 0 at u = 0). After the rise (u > 1) e rings freely; its amplitude at the start of the dwell
(the envelope, for zeta < 1), with lambda = -zeta W + i W_d and W_d = W sqrt(1 - zeta^2):

    R = |int_0^1 A(u) exp(lambda (1 - u)) du| / W_d                      (undamped: |int A e^{i W u} du| / W)

as a fraction of the lift. Each segment's integral is closed form: a constant, a quarter sine, a quarter cosine
(the harmonic-trapezoid family) or a polynomial (integration by parts); a segment whose quarter wave resonates
with W (s^2 + a^2 = 0, a removable singularity) is integrated by Gauss-Legendre quadrature instead.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ..kinematics.motion_law import SHAPE_CONST, SHAPE_SIN, MotionLaw
from ..kinematics.polynomial import PolynomialLaw

__all__ = ["residual", "check_ratios", "check_zeta"]

_GL_X, _GL_W = np.polynomial.legendre.leggauss(48)
_NEAR = 1e-6    # |s^2 + a^2| / a^2 below this: the segment is integrated by quadrature


def check_zeta(zeta: float) -> float:
    """zeta as a float in [0, 1); ValueError naming it otherwise."""
    z = float(zeta)
    if not (math.isfinite(z) and 0.0 <= z < 1.0):
        raise ValueError(f"zeta {zeta!r}: allowed the train's damping ratio in [0, 1) (underdamped)")
    return z


def check_ratios(r: Sequence[float] | float) -> np.ndarray:
    """The ratios r as an array, each finite and > 0; ValueError naming the bad ones otherwise."""
    arr = np.atleast_1d(np.asarray(r, dtype=float))
    bad = arr[~(np.isfinite(arr) & (arr > 0.0))]
    if bad.size:
        raise ValueError(f"r = rise time / natural period must be > 0 and finite, got {bad[:3].tolist()}")
    return arr


def _quadrature(law, start: float, end: float, s: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """int_start^end A(u) exp(s u + shift) du by 48-point Gauss-Legendre (one smooth piece)."""
    u = 0.5 * (end - start) * _GL_X + 0.5 * (start + end)
    _, _, A, _ = law.evaluate(u)
    # Inside the piece: an evaluation at its interior points only (no split point among the nodes).
    return 0.5 * (end - start) * (np.exp(np.outer(s, u) + shift[:, None]) @ (_GL_W * A))


def _motion_law_integral(law: MotionLaw, s: np.ndarray, shift: np.ndarray) -> np.ndarray:
    total = np.zeros(s.shape, dtype=complex)
    for end, start, F, c, kind, _, _ in law.segments():
        if c == 0.0:
            continue
        e0, e1 = np.exp(s * start + shift), np.exp(s * end + shift)
        if kind == SHAPE_CONST:
            total += c * (e1 - e0) / s
            continue
        a = 1.0 / F
        den = s * s + a * a
        near = np.abs(den) < _NEAR * a * a
        with np.errstate(divide="ignore", invalid="ignore"):
            if kind == SHAPE_SIN:       # int_0^L sin(a v) e^{s v} dv, a L = pi/2
                part = c * (s * e1 + a * e0) / den
            else:                       # int_0^L cos(a v) e^{s v} dv
                part = c * (a * e1 - s * e0) / den
        if near.any():
            part[near] = _quadrature(law, start, end, s[near], shift[near])
        total += part
    return total


def _polynomial_integral(law: PolynomialLaw, s: np.ndarray, shift: np.ndarray) -> np.ndarray:
    """int_0^1 p(u) e^{s u + shift} du = [e^{s u + shift} sum_k (-1)^k p^(k)(u) / s^(k+1)]_0^1, p = A;
    by quadrature where |s| < 4 (the sum cancels there)."""
    coef = law._d2
    total = np.zeros(s.shape, dtype=complex)
    small = np.abs(s) < 4.0
    if small.any():
        total[small] = _quadrature(law, 0.0, 1.0, s[small], shift[small])
    big = ~small
    if big.any():
        sb, hb = s[big], shift[big]
        derivs = [coef]
        while len(derivs[-1]) > 1:
            d = derivs[-1]
            derivs.append(tuple(k * d[k] for k in range(1, len(d))))
        acc = np.zeros(sb.shape, dtype=complex)
        for k, d in enumerate(derivs):
            at1, at0 = sum(d), d[0]
            acc += (-1) ** k * (at1 * np.exp(sb + hb) - at0 * np.exp(hb)) / sb ** (k + 1)
        total[big] = acc
    return total


def residual(law, r: Sequence[float] | float, zeta: float = 0.0) -> np.ndarray:
    """Residual amplitude / lift at the start of the dwell after a rise of ``law`` (a MotionLaw or a
    PolynomialLaw) for each ratio r = rise time / the train's natural period (> 0), damping ratio zeta in [0, 1).
    """
    rr = check_ratios(r)
    z = check_zeta(zeta)
    W = 2.0 * math.pi * rr
    Wd = W * math.sqrt(1.0 - z * z)
    # exp(lambda (1 - u)) = exp(s u + shift) with s = -lambda, shift = lambda: Re(s u + shift) <= 0 on [0, 1].
    lam = -z * W + 1j * Wd
    s, shift = -lam, lam
    if isinstance(law, MotionLaw):
        integral = _motion_law_integral(law, s, shift)
    elif isinstance(law, PolynomialLaw):
        integral = _polynomial_integral(law, s, shift)
    else:
        raise TypeError(f"residual: a MotionLaw or a PolynomialLaw, got {type(law).__name__}")
    return np.abs(integral) / Wd
