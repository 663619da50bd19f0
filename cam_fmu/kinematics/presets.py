"""Named split points (T1..T6) of the general harmonic-trapezoid curve.

    name                    T1     T2     T3    T4    T5      T6
    cycloidal               1/4    1/4    1/2   1/2   3/4     3/4
    modified_sine           1/8    1/8    1/2   1/2   7/8     7/8
    modified_trapezoid      1/8    3/8    1/2   1/2   5/8     7/8
    simple_harmonic         0      0      1/2   1/2   1       1
    constant_acceleration   0      1/2    1/2   1/2   1/2     1
    mcv50                   1/16   1/16   1/4   3/4   15/16   15/16
    paper                   1/8    1/8    1/4   3/4   7/8     7/8

Sources: docs/model.md section 1 for the five classical members.  `mcv50` is the
modified constant-velocity curve with a 50 % constant-velocity part (T4 - T3
= 1/2) whose ramps are modified-sine shaped (quarter sine over 1/16, quarter
cosine over 3/16, the 1:3 ratio of the modified sine), the "MCV50" of Makino's
universal cam curve tables (H. Makino, cam-mechanism handbooks; the same table
is reproduced in index-drive makers' catalogues); these T reproduce its
tabulated Vm = 1.28, Am = 8.01, Jm = 201.4, (AV)m = 5.73 (checked in
tests/kinematics/test_characteristics.py).  `paper` is the law of the paper's profile
(the paper's section 2.1; docs/model.md section 2).

The polynomial laws, by their coefficients c_0..c_n of S(T) = sum c_k T^k (kinematics/polynomial.py):

    polynomial_345    S = 10 T^3 - 15 T^4 + 6 T^5
    polynomial_4567   S = 35 T^4 - 84 T^5 + 70 T^6 - 20 T^7

This is the one table of named laws: the parameter choices of the FMU
(``rise_law``/``return_law``), the CLI's ``--preset`` and the docs derive
from ``PRESETS``, and ``engine/codegen.py`` generates the C engine's presets from it (``math`` only).
``POLYNOMIALS`` are laws of another family, which the C engine does not evaluate (yet): ``named_law()`` and
the vibration commands (``cam-fmu residual --laws``) take them, the drive's ``rise_law`` does not.
``LAW_NAMES`` lists both tables.
"""

from __future__ import annotations

from .motion_law import MotionLaw
from .polynomial import PolynomialLaw

__all__ = ["PRESETS", "POLYNOMIALS", "LAW_NAMES", "law", "named_law"]

PRESETS: dict[str, tuple[float, ...]] = {
    "cycloidal": (1 / 4, 1 / 4, 1 / 2, 1 / 2, 3 / 4, 3 / 4),
    "modified_sine": (1 / 8, 1 / 8, 1 / 2, 1 / 2, 7 / 8, 7 / 8),
    "modified_trapezoid": (1 / 8, 3 / 8, 1 / 2, 1 / 2, 5 / 8, 7 / 8),
    "simple_harmonic": (0.0, 0.0, 1 / 2, 1 / 2, 1.0, 1.0),
    "constant_acceleration": (0.0, 1 / 2, 1 / 2, 1 / 2, 1 / 2, 1.0),
    "mcv50": (1 / 16, 1 / 16, 1 / 4, 3 / 4, 15 / 16, 15 / 16),
    "paper": (1 / 8, 1 / 8, 1 / 4, 3 / 4, 7 / 8, 7 / 8),
}

POLYNOMIALS: dict[str, tuple[float, ...]] = {
    "polynomial_345": (0.0, 0.0, 0.0, 10.0, -15.0, 6.0),
    "polynomial_4567": (0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0),
}

LAW_NAMES: tuple[str, ...] = (*PRESETS, *POLYNOMIALS)


def law(name_or_T) -> MotionLaw:
    """A MotionLaw from a preset name, 6 split points, or a MotionLaw (returned as is).

    Unknown names raise ValueError listing the known ones.
    """
    if isinstance(name_or_T, MotionLaw):
        return name_or_T
    if isinstance(name_or_T, str):
        try:
            T = PRESETS[name_or_T]
        except KeyError:
            raise ValueError(
                f"unknown motion law {name_or_T!r}; known presets: {', '.join(PRESETS)}") from None
        return MotionLaw(T)
    return MotionLaw(name_or_T)


def named_law(name_or_T) -> MotionLaw | PolynomialLaw:
    """``law()`` that also knows the polynomial laws (``POLYNOMIALS``) by name.

    Unknown names raise ValueError listing every name of both tables.
    """
    if isinstance(name_or_T, PolynomialLaw):
        return name_or_T
    if isinstance(name_or_T, str):
        if name_or_T in POLYNOMIALS:
            return PolynomialLaw(POLYNOMIALS[name_or_T])
        if name_or_T not in PRESETS:
            raise ValueError(f"unknown motion law {name_or_T!r}; known laws: {', '.join(LAW_NAMES)}")
    return law(name_or_T)
