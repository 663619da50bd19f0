"""The C engine's cam program (cam_fmu/engine/csrc: cam_profile.h) against the Python one.

Laws, law programs and the breakpoint search are compared to the bit with
kinematics.motion_law.MotionLaw and kinematics.cam_program.CamProgram (derivatives and
first_angle_crossed); motion tables to the bit with the Python model
(kinematics.motion_table), on dense grids, at the breakpoints and one ulp either side.
Shape properties of random tables (hypothesis), the refusals and their messages, a
10^6-row table with its comparison count, and the C library's own messages.
"""
from __future__ import annotations

import math
import struct
from array import array

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from engine_profile import EngineProfile, first_crossed, law_eval, law_segments
from cam_fmu.kinematics.cam_program import CamProgram, first_angle_crossed
from cam_fmu.kinematics.motion_law import MotionLaw
from cam_fmu.kinematics.motion_table import parse_motion_table, program_from_table_text
from cam_fmu.kinematics.presets import PRESETS
from cam_fmu.physics.parameters import ParameterError, resolve

TWO_PI = 2.0 * math.pi


def bits(values) -> bytes:
    return struct.pack(f"{len(values)}d", *values)


def random_T(rng) -> tuple[float, ...]:
    """Valid split points, with ties (zero-length segments) and the ends 0 and 1 now and then."""
    while True:
        T = sorted(rng.uniform(0.0, 1.0, 6))
        for k in range(6):
            r = rng.random()
            if r < 0.15 and k:
                T[k] = T[k - 1]
            elif r < 0.2:
                T[k] = 0.0 if k < 3 else 1.0
        T = tuple(sorted(float(t) for t in T))
        if T[2] > 0.0 and T[3] < 1.0:
            try:
                MotionLaw(T)
            except ValueError:
                continue
            return T


def law_cases():
    rng = np.random.default_rng(18)
    return list(PRESETS.values()) + [random_T(rng) for _ in range(300)]


# -- laws ------------------------------------------------------------------------------------------

def test_law_segments_are_the_python_ones_to_the_bit():
    for T in law_cases():
        c, py = law_segments(T), MotionLaw(T).segments()
        assert len(c) == len(py)
        for a, b in zip(c, py):
            assert bits(a) == bits(tuple(float(x) for x in b)), T


def test_law_evaluation_is_motion_law_scalar_to_the_bit():
    rng = np.random.default_rng(5)
    for T in law_cases()[:60]:
        edges = (0.0, *T, 1.0)
        grid = list(rng.uniform(-0.1, 1.1, 200)) + [e for t in edges for e in
                                                     (t, math.nextafter(t, -1), math.nextafter(t, 2))]
        law = MotionLaw(T)
        for t in grid:
            assert bits(law_eval(T, t)) == bits(law.scalar(t)), (T, t)


@pytest.mark.parametrize("T", [
    (math.nan, 0.1, 0.2, 0.3, 0.4, 0.5), (0.1, 0.2, math.inf, 0.5, 0.6, 0.7), (-0.1, 0.1, 0.2, 0.3, 0.4, 1.5),
    (0.1, 0.3, 0.2, 0.5, 0.45, 0.9), (0.0, 0.0, 0.0, 0.5, 0.6, 0.7), (0.1, 0.2, 0.3, 1.0, 1.0, 1.0),
    (0.0, 0.0, 5e-324, 0.5, 0.5, 1.0),
])
def test_law_refusals_are_motion_laws_messages_and_name_the_parameters(T):
    with pytest.raises(ValueError) as py:
        MotionLaw(T)
    with pytest.raises(ValueError) as c:
        law_segments(T)
    assert str(c.value) == str(py.value)
    with pytest.raises(ValueError) as named:
        law_segments(T, "rise")
    text = str(named.value)
    assert text.startswith("rise law: ") and "rise_T" in text and " T1=" not in text


# -- law programs ------------------------------------------------------------------------------------

def program_cases():
    rng = np.random.default_rng(11)
    names = list(PRESETS)
    cases = [(PRESETS["paper"], PRESETS["paper"], 1.5 * math.pi * 0.035, math.pi, 0.0, math.pi, 0.0)]
    for k in range(24):
        a = rng.uniform(0.05, 3.0, 4)
        if k % 3 == 0:
            a[1] = 0.0
        if k % 4 == 0:
            a[3] = 0.0
        a = a * TWO_PI / a.sum()
        a[-1] = max(TWO_PI - a[0] - a[1] - a[2], 0.0)
        rise = PRESETS[names[k % len(names)]] if k % 2 else random_T(rng)
        ret = PRESETS[names[(3 * k) % len(names)]] if k % 5 else random_T(rng)
        cases.append((rise, ret, float(rng.uniform(1e-3, 0.5)), *map(float, a)))
    return cases


def test_law_program_is_the_python_cam_program_to_the_bit():
    rng = np.random.default_rng(3)
    for case in program_cases():
        program = CamProgram(*case)
        engine = EngineProfile.from_laws(*case)
        points = program.breakpoints()
        assert bits(engine.breakpoints()) == bits(points)
        assert engine.feature_angle() == program.feature_angle()
        grid = list(np.linspace(-20.0, 20.0, 4001)) + list(rng.uniform(-1e9, 1e9, 300))
        grid += [p + k * TWO_PI for p in points for k in (-2, 0, 1, 1000)]
        grid += [math.nextafter(p, d) for p in points for d in (-1.0, 7.0)]
        grid += [0.0, -0.0, -1e-300, 5e-324, -TWO_PI, TWO_PI, 1e300, -1e300, math.nan]
        for theta in grid:
            assert bits(engine.derivatives(float(theta))) == bits(program.derivatives(float(theta))), (case, theta)
        for theta in (math.inf, -math.inf):                     # no angle: the lower dwell
            assert engine.derivatives(theta) == (0.0, 0.0, 0.0, 0.0)


def test_law_program_refusals():
    base = (PRESETS["paper"], PRESETS["paper"])
    # the sum of the angles: physics/parameters.resolve's message, word for word
    angles = {"rise_angle": 3.0, "upper_dwell": 0.2, "return_angle": 3.0, "lower_dwell": 0.0}
    with pytest.raises(ParameterError) as py:
        resolve(angles)
    with pytest.raises(ValueError) as c:
        EngineProfile.from_laws(*base, 0.1, *angles.values())
    assert str(c.value) == str(py.value)
    # lift and angles: CamProgram's messages
    for args in ((0.0, math.pi, 0.0, math.pi, 0.0), (0.1, math.nan, 0.0, math.pi, 0.0),
                 (0.1, 0.0, 0.0, TWO_PI, 0.0), (0.1, math.pi, -1.0, math.pi, 1.0)):
        with pytest.raises(ValueError) as py:
            CamProgram(*base, *args)
        with pytest.raises(ValueError) as c:
            EngineProfile.from_laws(*base, *args)
        assert str(c.value) == str(py.value)
    with pytest.raises(ValueError, match=r"^return law: no deceleration segment: return_T4=1.0"):
        EngineProfile.from_laws(PRESETS["paper"], (0.1, 0.2, 0.3, 1.0, 1.0, 1.0), 0.1, math.pi, 0.0, math.pi, 0.0)


# -- the first breakpoint ---------------------------------------------------------------------------

def test_first_breakpoint_is_the_python_programs_to_the_bit():
    rng = np.random.default_rng(21)
    for trial in range(60):
        n = int(rng.integers(0, 40)) if trial % 10 else int(rng.integers(1000, 3000))
        pts = np.sort(rng.uniform(0.0, TWO_PI, n))
        if n > 3:
            pts[1] = pts[0]                                      # duplicates and 0 are allowed
            pts[0] = 0.0 if trial % 2 else pts[0]
            pts = np.sort(pts)
        points = [float(p) for p in pts]
        arr = array("d", points)
        for _ in range(300):
            scale = float(rng.choice([1.0, 10.0, 1e3, 1e9, 1e15]))
            start = float(rng.uniform(-scale, scale))
            if points and rng.random() < 0.3:                   # start on a point, or next to it
                start = points[int(rng.integers(len(points)))] + TWO_PI * float(rng.integers(-3, 4))
                start = math.nextafter(start, float(rng.choice([-1e300, 1e300]))) if rng.random() < 0.5 else start
            end = start + float(rng.choice([rng.uniform(-10, 10), rng.uniform(-1e-6, 1e-6), 0.0, 1e6, -TWO_PI]))
            expected = first_angle_crossed(points, start, end)
            found, _ = first_crossed(points, start, end)
            assert bits((found,)) == bits((expected,)), (points[:5], start, end)
        for start, end in ((math.nan, 1.0), (1.0, math.nan), (2.0, 2.0)):
            assert math.isnan(first_crossed(points, start, end)[0])


def test_first_breakpoint_costs_log_n():
    n = 100_000
    points = [float(p) for p in np.sort(np.random.default_rng(2).uniform(0.0, TWO_PI, n))]
    bound = 3 * (2 * math.ceil(math.log2(n + 1)) + 5)          # at most 3 groups of equal turn count
    for start, end in ((0.1, 0.2), (-5.0, 40.0), (1e9, 1e9 - 3.0), (3.0, -1e12)):
        found, evaluations = first_crossed(points, start, end)
        assert evaluations <= bound
        assert bits((found,)) == bits((first_angle_crossed(points, start, end),))


# -- motion tables ----------------------------------------------------------------------------------

def table_text(deg, mm, header=True) -> str:
    rows = "\n".join(f"{float(a)!r},{float(s)!r}" for a, s in zip(deg, mm))
    return ("angle_deg,lift_mm\n" if header else "") + rows


def random_table(rng, n):
    deg = np.sort(rng.choice(np.arange(0.0, 360.0, 0.125), n, replace=False))
    mm = rng.uniform(0.0, 50.0, n)
    for _ in range(n // 8):                                       # dwells: runs of equal lifts
        k = int(rng.integers(n))
        mm[k:k + int(rng.integers(2, 6))] = mm[k]
    return deg, mm


def test_table_is_the_python_model_to_the_bit():
    rng = np.random.default_rng(9)
    for n in (2, 3, 5, 40, 300):
        deg, mm = random_table(rng, n)
        text = table_text(deg, mm)
        engine, model = EngineProfile.from_table(text), program_from_table_text(text)
        t = engine.struct.table
        assert t.n == n and engine.lift == model.lift
        for name, values in (("angle", model.angles), ("lift", model.lifts), ("slope", model.slopes),
                             ("width", model.widths), ("c2", [c[2] for c in model.coefficients]),
                             ("e2", [c[2] for c in model.end_coefficients]), ("c3", [c[3] for c in model.coefficients])):
            assert bits([getattr(t, name)[k] for k in range(n)]) == bits(values), name
        assert bits(engine.breakpoints()) == bits(model.breakpoints())
        assert engine.feature_angle() == model.feature_angle()
        knots = np.array(model.angles)
        grid = np.concatenate([np.linspace(-15.0, 15.0, 6001), knots, np.nextafter(knots, -9), np.nextafter(knots, 9),
                               knots + TWO_PI, knots - 5 * TWO_PI, [1e9, -1e9, 1e300, -0.0, -1e-300]])
        vectorised = np.array(model.evaluate(grid)).T
        for theta, vec in zip(grid, vectorised):
            c, py = engine.derivatives(float(theta)), model.derivatives(float(theta))
            assert bits(c) == bits(py) == bits(vec), (n, theta)
        for theta in (math.nan, math.inf, -math.inf):
            assert all(math.isnan(v) for v in engine.derivatives(theta) + model.derivatives(theta))


@st.composite
def tables(draw):
    n = draw(st.integers(2, 30))
    deg = draw(st.lists(st.integers(0, 359 * 8), min_size=n, max_size=n, unique=True))
    deg = sorted(d / 8.0 for d in deg)
    levels = draw(st.lists(st.sampled_from([0.0, 0.0, 5.0, 12.5, 40.0, 10000.0]) | st.floats(0.0, 100.0),
                           min_size=n, max_size=n))
    return deg, levels


@settings(max_examples=150, deadline=None)
@given(tables())
def test_random_tables_keep_their_shape(table):
    deg, mm = table
    engine = EngineProfile.from_table(table_text(deg, mm, header=False))
    t = engine.struct.table
    n = t.n
    angles = [t.angle[k] for k in range(n)]
    lifts = [t.lift[k] for k in range(n)]
    for k in range(n):
        assert engine.derivatives(angles[k])[0] == lifts[k]               # the rows, exactly
        a, b = lifts[k], lifts[(k + 1) % n]
        start, width = angles[k], t.width[k]
        for f in (1e-12, 0.01, 0.1, 0.25, 0.37, 0.5, 0.5 + 1e-12, 0.63, 0.75, 0.9, 0.99, 1.0 - 1e-12):
            s, s1, s2, s3 = engine.derivatives(start + f * width)
            assert min(a, b) <= s <= max(a, b)                            # never outside its two rows
            if a == b:                                                    # a dwell: exactly flat
                assert (s, s1, s2, s3) == (a, 0.0, 0.0, 0.0)
            else:                                                         # monotone: s' never against the rows
                assert s1 * (b - a) >= -1e-9 * abs(b - a) / width


def test_the_issue_table_stays_at_zero_from_180_to_360_deg():
    engine = EngineProfile.from_table("0,0\n90,40\n180,0\n")
    for theta in np.radians(np.linspace(180.0, 360.0, 721)):
        s, s1, s2, s3 = engine.derivatives(float(theta))
        assert s == 0.0 and s1 == 0.0
        if theta > math.pi:
            assert s2 == 0.0 and s3 == 0.0
    assert max(engine.derivatives(float(t))[0] for t in np.linspace(0.0, TWO_PI, 3601)) == 0.040


def test_bom_header_and_line_ends_are_the_models():
    rows = "0,1\r\n90,2 # peak\r180;1\n\n# note\n270\t0.5\n"
    for text in (rows, "\ufeff" + rows, "angle_deg,lift_mm\n" + rows, "\ufeffangle;lift\r\n" + rows):
        engine = EngineProfile.from_table(text.encode("utf-8"))
        t = engine.struct.table
        deg, mm = parse_motion_table(text)
        assert [t.angle[k] for k in range(t.n)] == [a * (math.pi / 180.0) for a in deg]
        assert [t.lift[k] for k in range(t.n)] == [s * 1e-3 for s in mm]


BAD_TABLES = [
    "0,O\n90,1\n180,0\n", "angle,lift\n0,0\n90,x\n", "a,b\n0,0\n90,1\n90,2\n", "a,b\n0,0\n90,1\n80,2\n",
    "a,b\n0,0\n90,1\n180,2\n360,1\n", "a,b\n5,0\n90,1\n360,0\n", "a,b\n0,0\n90,1\n360,0\n100,1\n",
    "a,b\n0,0\n90,-1\n", "a,b\n0,0\n90,10000.5\n", "a,b\n0,0\n400,1\n", "a,b\n0,0\nnan,1\n", "a,b\n0,0\n10,-inf\n",
    "a,b\n0;0,5\n", "a,b\n0,0\n1_0,1\n", "a,b\n0,0\n10," + "1" * 101 + "\n", "a,b\n0,0\n", "", "\ufeff",
    "# only a comment\n", "a,b\n0,0\n10,1\n10.0000001,2\n", "a,b\n0,0\n359.9999999,1\n", "\ufeffé,ü\n0,0\n90,x" + "é" * 50,
    "0,0\n1e,1\n", "0,0\n.,1\n", "0,0\n+,1\n", "0,0\n1..2,1\n", "0,0\n90,1\n\tx\t\n",
]


@pytest.mark.parametrize("text", BAD_TABLES)
def test_bad_tables_are_refused_with_the_models_message(text):
    with pytest.raises(ValueError) as py:
        program_from_table_text(text)
    with pytest.raises(ValueError) as c:
        EngineProfile.from_table(text)
    assert str(c.value) == str(py.value)
    assert str(c.value).startswith("motion table")


def test_refusals_name_the_row_the_field_and_the_text():
    with pytest.raises(ValueError, match=r"^motion table line 1 \(row 1\): the lift_mm field is not a number: 'O'$"):
        EngineProfile.from_table("0,O\n90,1\n180,0\n")
    with pytest.raises(ValueError, match=r"line 4 \(row 3\): angle '90' deg repeats '90' deg of row 2 \(line 3\)"):
        EngineProfile.from_table("a,b\n0,0\n90,1\n90,2\n")
    long = "x" * 10_000_000                                      # a huge bad value is cut, not echoed
    with pytest.raises(ValueError) as exc:
        EngineProfile.from_table("0,0\n90," + long)
    assert str(exc.value).endswith("'" + "x" * 40 + "...'")


def test_random_texts_get_the_models_answer():
    """Differential: tables written with random separators, line ends, headers and comments, then
    mutated by random fragments; both parsers give the same table or the same message."""
    rng = np.random.default_rng(4)
    pieces = ["0", "1", "90", "180", "359.9", "360", "40", "0.5", "1e-3", "-1", "1e400", "nan", "inf", ".5", "5.",
              "1e", "x", "O", "angle,lift", ",", ";", " ", "\t", "\n", "\r\n", "\r", "#c", "\ufeff", "é", "9", "270"]
    accepted = refused = 0
    for _ in range(3000):
        n = int(rng.integers(0, 8))
        angles = np.sort(rng.choice(np.arange(0, 361, 15), n, replace=False))
        parts = [str(rng.choice(["", "angle,lift\n", "\ufeff", "# c\n"]))]
        for a in angles:
            sep = str(rng.choice([",", ";", " ", "\t", " , "]))
            end = str(rng.choice(["\n", "\r\n", "\r", " # note\n"]))
            parts.append(f"{a}{sep}{int(rng.integers(0, 50))}{end}")
        text = "".join(parts)
        for _ in range(int(rng.integers(0, 3))):                  # mutations
            k = int(rng.integers(0, len(text) + 1))
            text = text[:k] + str(rng.choice(pieces)) + text[k + int(rng.integers(0, 2)):]
        try:
            model = program_from_table_text(text)
        except ValueError as exc:
            with pytest.raises(ValueError) as c:
                EngineProfile.from_table(text)
            assert str(c.value) == str(exc), repr(text)
            refused += 1
            continue
        engine = EngineProfile.from_table(text)
        accepted += 1
        assert bits(engine.breakpoints()) == bits(model.angles)
        assert bits(engine.derivatives(1.0)) == bits(model.derivatives(1.0))
    assert accepted > 300 and refused > 300                       # both paths were exercised


def test_a_million_rows_parse_and_evaluate_in_log_n_comparisons():
    n = 1_000_000
    deg = np.arange(n) * (360.0 / n)
    mm = 10.0 + 5.0 * np.sin(np.radians(deg) * 3.0)
    text = "angle_deg,lift_mm\n" + "\n".join(f"{a!r},{s!r}" for a, s in zip(deg.tolist(), mm.tolist()))
    engine = EngineProfile.from_table(text)
    t = engine.struct.table
    assert t.n == n and engine.struct.n_points == n
    assert t.lift[n // 2] == mm[n // 2] * 1e-3 and t.angle[n - 1] == deg[-1] * (math.pi / 180.0)
    limit = math.ceil(math.log2(n + 1))
    for theta in np.random.default_rng(1).uniform(-10.0, 10.0, 200):
        (s, s1, _, _), comparisons = engine.derivatives_counted(float(theta))
        assert comparisons <= limit
        exact = 1e-2 + 5e-3 * math.sin(3.0 * theta)
        assert s == pytest.approx(exact, abs=1e-12)               # O(h^3) with h = 6e-6 rad
        assert s1 == pytest.approx(1.5e-2 * math.cos(3.0 * theta), abs=1e-8)
    _, evaluations = first_crossed([t.angle[k] for k in range(0, n, 1)], 0.3, 0.4)
    assert evaluations <= 3 * (2 * limit + 5)


def test_the_angle_reduction_is_fmod_to_the_bit():
    """cam_angle_mod skips fmod where exact subtractions give its result (docs: cam_profile.h); libm's fmod,
    through Python's math.fmod, is the oracle: random angles, the multiples of 2 pi and their neighbours."""
    import ctypes

    from cam_fmu.engine.library import load

    reduce = load().cam_angle_mod
    reduce.restype, reduce.argtypes = ctypes.c_double, [ctypes.c_double]
    rng = np.random.default_rng(11)
    angles = list(rng.uniform(-40.0, 40.0, 100_000)) + list(rng.uniform(-1e6, 1e6, 1000))
    for k in range(-6, 7):
        edge = k * TWO_PI
        angles += [edge, math.nextafter(edge, -math.inf), math.nextafter(edge, math.inf), edge + 5e-324, -0.0, 0.0]
    for theta in angles:
        assert bits((reduce(float(theta)),)) == bits((math.fmod(float(theta), TWO_PI),)), theta
    assert math.isnan(reduce(math.nan)) and math.isnan(reduce(math.inf))
