"""MotionLaw: boundary conditions, continuity, derivative consistency,
zero-length segments, the two evaluation paths, invalid input, properties."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings, strategies as st

from cam_fmu.kinematics.motion_law import MotionLaw
from cam_fmu.kinematics.presets import PRESETS

ALL_T = list(PRESETS.values()) + [
    (0.1, 0.2, 0.35, 0.5, 0.6, 0.9),          # asymmetric, Amp != Amm
    (0.0, 0.0, 0.3, 0.3, 0.3, 1.0),           # zero-length 1, 2, 4, 5, 7 (T6 = 1)
    (0.0, 0.2, 0.2, 0.7, 0.7, 1.0),           # accelerate-cruise-decelerate with jumps
    (0.05, 0.05, 0.05, 0.95, 0.95, 0.95),     # only sine ramps around long cruise
    (0.2, 0.2, 0.2, 0.2, 0.2, 1.0),           # seg 1 then seg 6 (A jumps Amp -> -Amm)
]


@pytest.mark.parametrize("T", ALL_T)
def test_boundary_conditions(T):
    m = MotionLaw(T)
    assert m.scalar(0.0)[:2] == (0.0, 0.0)
    S1, V1, _, _ = m.scalar(1.0)
    assert S1 == pytest.approx(1.0, abs=1e-14)
    assert V1 == pytest.approx(0.0, abs=1e-13)


@pytest.mark.parametrize("T", ALL_T)
def test_continuity_at_split_points(T):
    m = MotionLaw(T)
    jumps = m.jumps()
    eps = 1e-9
    for p in set(T):
        if not 0.0 < p < 1.0:
            continue
        L, R = m.scalar(p - eps), m.scalar(p + eps)
        assert R[0] == pytest.approx(L[0], abs=1e-8)      # S
        assert R[1] == pytest.approx(L[1], abs=1e-6)      # V
        if p not in jumps:
            assert R[2] == pytest.approx(L[2], abs=1e-5 * max(m.Amp, m.Amm))  # A


def test_jumps_are_detected_where_expected():
    assert MotionLaw(PRESETS["cycloidal"]).jumps() == ()
    assert MotionLaw(PRESETS["simple_harmonic"]).jumps() == (0.0, 1.0)
    assert MotionLaw(PRESETS["constant_acceleration"]).jumps() == (0.0, 0.5, 1.0)
    assert MotionLaw((0.0, 0.2, 0.2, 0.7, 0.7, 1.0)).jumps() == (0.0, 0.2, 0.7, 1.0)
    assert MotionLaw((0.2, 0.2, 0.2, 0.2, 0.2, 1.0)).jumps() == (0.2, 1.0)


@pytest.mark.parametrize("T", ALL_T)
def test_derivative_consistency(T):
    """Central differences of S, V, A against V, A, J away from split points."""
    m = MotionLaw(T)
    t = np.linspace(0.0, 1.0, 2001)[1:-1]
    h = 1e-6
    far = np.min(np.abs(t[:, None] - np.array((0.0,) + tuple(T) + (1.0,))[None, :]), axis=1) > 10 * h
    t = t[far]
    Sp, Vp, Ap, _ = m.evaluate(t + h)
    Sm, Vm, Am, _ = m.evaluate(t - h)
    _, V, A, J = m.evaluate(t)
    scale = max(m.Amp, m.Amm)
    np.testing.assert_allclose((Sp - Sm) / (2 * h), V, atol=1e-7)
    np.testing.assert_allclose((Vp - Vm) / (2 * h), A, atol=1e-6 * scale)
    np.testing.assert_allclose((Ap - Am) / (2 * h), J, atol=1e-3 * scale)


@pytest.mark.parametrize("T", ALL_T)
def test_scalar_and_vector_paths_agree_including_split_points(T):
    m = MotionLaw(T)
    t = np.concatenate([np.linspace(-0.1, 1.1, 241), np.array((0.0,) + tuple(T) + (1.0,))])
    vec = m.evaluate(t)
    for k, tk in enumerate(t):
        sc = m.scalar(float(tk))
        assert all(type(x) is float for x in sc)
        np.testing.assert_allclose(sc, [q[k] for q in vec], rtol=1e-13, atol=1e-13)


def test_split_point_convention_left_limit():
    """Documented: at a split point the segment ending there; at 0 the first one."""
    m = MotionLaw(PRESETS["constant_acceleration"])
    assert m.scalar(0.0)[2] == 4.0          # right limit at T = 0
    assert m.scalar(0.5)[2] == 4.0          # left limit at the jump
    assert m.scalar(1.0)[2] == -4.0         # left limit at the end
    assert m.scalar(-1e-12) == (0.0, 0.0, 0.0, 0.0)
    assert m.scalar(1.0 + 1e-12) == (1.0, 0.0, 0.0, 0.0)


def test_zero_length_segments_make_the_classical_closed_forms():
    # simple harmonic: S = (1 - cos pi T)/2 ; constant acceleration: 2 T^2 then 1 - 2 (1-T)^2
    t = np.linspace(0, 1, 101)
    S, V, A, _ = MotionLaw(PRESETS["simple_harmonic"]).evaluate(t)
    np.testing.assert_allclose(S, (1 - np.cos(np.pi * t)) / 2, atol=1e-14)
    np.testing.assert_allclose(V, np.pi / 2 * np.sin(np.pi * t), atol=1e-13)
    S, _, _, _ = MotionLaw(PRESETS["constant_acceleration"]).evaluate(t)
    np.testing.assert_allclose(S, np.where(t <= 0.5, 2 * t**2, 1 - 2 * (1 - t) ** 2), atol=1e-14)
    # cycloidal: S = T - sin(2 pi T) / (2 pi)
    S, _, _, _ = MotionLaw(PRESETS["cycloidal"]).evaluate(t)
    np.testing.assert_allclose(S, t - np.sin(2 * np.pi * t) / (2 * np.pi), atol=1e-14)


def test_asymmetric_law_has_different_peaks():
    m = MotionLaw((0.1, 0.2, 0.35, 0.5, 0.6, 0.9))
    assert abs(m.Amp - m.Amm) > 0.5
    # Areas balance: int A = 0 -> Amp * (F1 + L2 + F3) = Amm * (F5 + L6 + F7)
    F = lambda a, b: (b - a) / (math.pi / 2)
    assert m.Amp * (F(0, .1) + .1 + F(.2, .35)) == pytest.approx(m.Amm * (F(.5, .6) + .3 + F(.9, 1)), rel=1e-14)


@pytest.mark.parametrize("T, fragment", [
    ((0.1, 0.2, 0.3, 0.4, 0.5), "6 numbers"),
    ((0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7), "6 numbers"),
    ("abcdef", "6 numbers"),
    ((0.1, 0.2, float("nan"), 0.4, 0.5, 0.6), "T3=nan"),
    ((0.1, 0.2, 0.3, float("inf"), 0.5, 0.6), "T4=inf"),
    ((-0.1, 0.2, 0.3, 0.4, 0.5, 0.6), "T1=-0.1"),
    ((0.1, 0.2, 0.3, 0.4, 0.5, 1.5), "T6=1.5"),
    ((0.1, 0.3, 0.2, 0.4, 0.5, 0.6), "T2=0.3 > T3=0.2"),
    ((0.0, 0.0, 0.0, 0.4, 0.5, 0.6), "no acceleration"),
    ((0.1, 0.2, 0.3, 1.0, 1.0, 1.0), "no deceleration"),
    ((0.0, 0.0, 0.0, 1.0, 1.0, 1.0), "no acceleration"),
])
def test_invalid_split_points_raise_naming_values(T, fragment):
    with pytest.raises(ValueError, match=fragment.replace("(", r"\(")):
        MotionLaw(T)


def test_degenerate_but_ordered_points_either_work_or_raise_cleanly():
    with pytest.raises(ValueError, match="finite curve"):
        MotionLaw((0.0, 0.0, 5e-324, 0.5, 1.0, 1.0))


def test_immutable_and_hashable():
    m = MotionLaw(PRESETS["paper"])
    with pytest.raises(AttributeError):
        m.Amp = 1.0
    assert m == MotionLaw(list(PRESETS["paper"])) and hash(m) == hash(MotionLaw(PRESETS["paper"]))


@st.composite
def split_points(draw):
    xs = sorted(draw(st.lists(st.one_of(st.floats(0, 1), st.sampled_from([0.0, 0.25, 0.5, 1.0])),
                              min_size=6, max_size=6)))
    # Valid curves need T3 > 0 and T4 < 1; keep clear of absurdly short
    # acceleration phases (Amp ~ 1/T3^2) so absolute tolerances stay meaningful.
    assume(xs[2] >= 1e-3 and xs[3] <= 1.0 - 1e-3)
    return tuple(xs)


@settings(max_examples=150, deadline=None)
@given(split_points())
def test_properties_over_random_split_points(T):
    m = MotionLaw(T)
    t = np.linspace(0.0, 1.0, 4001)
    S, V, A, _ = m.evaluate(t)
    assert S[0] == 0.0 and V[0] == 0.0
    assert S[-1] == pytest.approx(1.0, abs=1e-12)
    assert V[-1] == pytest.approx(0.0, abs=1e-10 * max(1.0, m.Amp))
    assert m.Amp > 0 and m.Amm > 0
    # Accelerate (A >= 0) then decelerate: V >= 0, S monotone.
    assert np.all(V >= -1e-12 * max(1.0, V.max()))
    assert np.all(np.diff(S) >= -1e-12)
    assert np.abs(V).max() >= 1.0 - 1e-12
    # int_0^1 V dT = S(1) - S(0) = 1 (composite Simpson on a fine grid)
    n = 20000
    tt = np.linspace(0.0, 1.0, n + 1)
    Vt = m.evaluate(tt)[1]
    integral = (1.0 / n / 3.0) * (Vt[0] + Vt[-1] + 4 * Vt[1:-1:2].sum() + 2 * Vt[2:-1:2].sum())
    assert integral == pytest.approx(1.0, abs=1e-4)
