"""The 3-4-5 and 4-5-6-7 polynomial laws: their boundary conditions and derivatives against numpy's own
polynomial algebra, their place beside the presets (the C engine's table stays the harmonic-trapezoid one)."""
from __future__ import annotations

import numpy as np
import pytest
from numpy.polynomial import Polynomial

from cam_fmu.kinematics.polynomial import PolynomialLaw
from cam_fmu.kinematics.presets import LAW_NAMES, POLYNOMIALS, PRESETS, named_law
from cam_fmu.physics.parameters import LAW_CHOICES


@pytest.mark.parametrize("name", list(POLYNOMIALS))
def test_rise_conditions_and_derivatives(name):
    law = named_law(name)
    p = Polynomial(POLYNOMIALS[name])
    # S(0) = 0, S(1) = 1, V = A = 0 at both ends, from numpy's derivative, not the law's own.
    assert p(0.0) == 0.0 and p(1.0) == pytest.approx(1.0, abs=1e-14)
    for k in (1, 2):
        assert p.deriv(k)(0.0) == 0.0 and abs(p.deriv(k)(1.0)) < 1e-12
    u = np.linspace(0.0, 1.0, 101)
    S, V, A, J = law.evaluate(u)
    for k, got in enumerate((S, V, A, J)):
        np.testing.assert_allclose(got, p.deriv(k)(u) if k else p(u), atol=1e-11)
    for x in (0.0, 0.3, 1.0):
        assert law.scalar(x) == pytest.approx(tuple(float(q) for q in (p(x), *(p.deriv(k)(x) for k in (1, 2, 3)))),
                                              abs=1e-11)
    assert law.jumps() == ()


def test_the_4567_has_zero_jerk_at_the_ends_and_the_345_does_not():
    assert named_law("polynomial_4567").scalar(0.0)[3] == 0.0
    assert named_law("polynomial_345").scalar(0.0)[3] == 60.0   # 6 x 10: the T^3 term's


def test_dwells_outside_the_rise():
    law = named_law("polynomial_345")
    assert law.scalar(-0.5) == (0.0, 0.0, 0.0, 0.0) and law.scalar(1.5) == (1.0, 0.0, 0.0, 0.0)
    S, V, A, J = law.evaluate(np.array([-0.5, 1.5]))
    assert S.tolist() == [0.0, 1.0] and V.tolist() == A.tolist() == J.tolist() == [0.0, 0.0]


def test_names_and_the_engine_table():
    assert LAW_NAMES == (*PRESETS, *POLYNOMIALS)
    # The drive's choices (and the C engine's generated table, engine/test_engine_codegen.py) are PRESETS only.
    assert not set(POLYNOMIALS) & set(LAW_CHOICES)
    assert all(len(T) == 6 for T in PRESETS.values())
    with pytest.raises(ValueError, match="known laws: .*polynomial_4567"):
        named_law("nope")


def test_refused_coefficients():
    with pytest.raises(ValueError, match="S\\(0\\) = 0 and S\\(1\\) = 1"):
        PolynomialLaw((0.0, 2.0))
    with pytest.raises(ValueError, match="finite"):
        PolynomialLaw((0.0, float("nan")))
