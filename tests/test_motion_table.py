"""Motion-table programs: periodic cubic spline against scipy's, its stated
continuity, its accuracy order on a table sampled from a CamProgram, the
CamProgram interface, math-only evaluation, the drive physics, and errors."""

import math

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from cam_fmu.physics.drive import DriveModel
from cam_fmu.kinematics import motion_table
from cam_fmu.kinematics.cam_program import CamProgram, paper_program
from cam_fmu.kinematics.motion_table import TableProgram, parse_motion_table, program_from_table_text

TWO_PI = 2 * math.pi
PROG = CamProgram("cycloidal", "modified_sine", 0.03, math.radians(100), math.radians(40),
                  math.radians(120), math.radians(100))


def _table(prog, step_deg):
    th = np.radians(np.arange(0.0, 360.0, step_deg))
    return TableProgram(th, prog.evaluate(th)[0])


def test_matches_scipy_periodic_spline_on_uneven_knots():
    rng = np.random.default_rng(7)
    deg = np.sort(rng.choice(np.arange(5.0, 355.0, 0.5), size=40, replace=False))
    lift = 10.0 + 5.0 * np.sin(np.radians(deg)) + rng.uniform(0.0, 1.0, deg.size)
    text = "angle_deg,lift_mm\n" + "\n".join(f"{a},{s}" for a, s in zip(deg, lift))
    prog = program_from_table_text(text)
    th = np.radians(deg)
    ref = CubicSpline(np.append(th, th[0] + TWO_PI), np.append(lift, lift[0]) * 1e-3, bc_type="periodic")
    x = rng.uniform(-TWO_PI, 2 * TWO_PI, 2000)
    xr = th[0] + np.mod(x - th[0], TWO_PI)
    for k, q in enumerate(prog.evaluate(x)[:3]):
        assert np.allclose(q, ref(xr, k), rtol=1e-10, atol=1e-13 * 10 ** k)
    for xi in x[:200]:            # the math-only scalar path
        d = prog.derivatives(float(xi))
        xi_r = th[0] + (xi - th[0]) % TWO_PI
        assert all(d[k] == pytest.approx(float(ref(xi_r, k)), rel=1e-9, abs=1e-12) for k in range(3))


def test_stated_continuity_s_s1_s2_continuous_s3_jumps_at_the_knots():
    prog = _table(PROG, 5.0)
    knots = np.array(prog.breakpoints())
    assert np.allclose(knots, np.radians(np.arange(0.0, 360.0, 5.0)), atol=1e-15)
    eps = 1e-9
    left = np.array([prog.derivatives(k - eps) for k in knots])
    right = np.array([prog.derivatives(k + eps) for k in knots])   # knot 0 wraps around 360 deg
    # across a knot a continuous derivative changes by at most 2 eps max|next derivative|
    bound = 2 * eps * np.abs(np.vstack([left, right])).max(axis=0) * 1.01 + 1e-16
    for k in range(3):
        assert np.abs(left[:, k] - right[:, k]).max() < bound[k + 1]
    jumps = np.abs(left[:, 3] - right[:, 3])
    assert jumps.max() > 1e-2 * np.abs(left[:, 3]).max()       # the third derivative is only piecewise constant
    # interpolates the table and repeats every 360 deg
    assert np.allclose(prog.evaluate(knots)[0], np.array(prog.lifts), atol=1e-15)
    th = np.linspace(0.0, TWO_PI, 97) + 1e-3     # off the knots
    for a, b in zip(prog.evaluate(th), prog.evaluate(th + 3 * TWO_PI)):
        assert np.allclose(a, b, atol=1e-12)


def test_accuracy_order_on_a_sampled_cam_program():
    grid = np.linspace(0.0, TWO_PI, 20001)
    exact = PROG.evaluate(grid)[:3]
    errs = []
    for step in (4.0, 2.0, 1.0, 0.5):
        approx = _table(PROG, step).evaluate(grid)[:3]
        errs.append([np.abs(a - b).max() for a, b in zip(approx, exact)])
    errs = np.array(errs)
    order = np.log2(errs[0] / errs[-1]) / 3.0          # over three halvings of the spacing
    assert order[0] > 3.7 and order[1] > 2.7 and order[2] > 1.8      # O(h^4), O(h^3), O(h^2)


def test_cam_program_interface_and_pressure_angle():
    table = _table(paper_program(), 0.5)
    a_t, at_t = table.max_pressure_angle(0.1)
    a_p, at_p = paper_program().max_pressure_angle(0.1)
    assert a_t == pytest.approx(a_p, abs=1e-6)
    # rise and return of the paper profile are mirror images: the maximum is at theta or 2 pi - theta
    assert min(abs(at_t - at_p), abs(at_t - (TWO_PI - at_p))) < 1e-3
    assert table.lift == pytest.approx(paper_program().lift, rel=1e-12)
    s, ds, d2s, d3s = table.derivatives(1.0)
    assert all(type(v) is float for v in (s, ds, d2s, d3s))


def test_runtime_evaluation_uses_no_numpy(monkeypatch):
    table = _table(PROG, 2.0)
    expected = [table.derivatives(t) for t in (0.0, 0.3, 2.0, 6.2, -1.0, 100.0)]

    class NoNumpy:
        def __getattr__(self, name):
            raise AssertionError(f"numpy used at run time: np.{name}")

    monkeypatch.setattr(motion_table, "np", NoNumpy())
    assert [table.derivatives(t) for t in (0.0, 0.3, 2.0, 6.2, -1.0, 100.0)] == expected


def test_drive_physics_with_a_table_program():
    """The drive equations of DriveModel run unchanged on a table sampled every
    0.25 deg from its own (paper) program, and agree to the spline's accuracy."""
    ref = DriveModel()
    model = DriveModel()
    table = _table(ref.program, 0.25)
    model.program = table
    model._profile = table.derivatives     # the hot path binds the profile once at construction
    for theta in np.linspace(0.1, 6.2, 13):
        for omega in (-8.0, 3.0, 12.0):
            a, b = model.omega_dot(theta, omega, 0.3, math.copysign(1.0, omega)), \
                ref.omega_dot(theta, omega, 0.3, math.copysign(1.0, omega))
            assert a == pytest.approx(b, rel=2e-4, abs=1e-3)
            la, lb = model.load(theta, omega, 1.0, 1.0), ref.load(theta, omega, 1.0, 1.0)
            assert la.M == pytest.approx(lb.M, rel=2e-4, abs=1e-5)
            assert la.v == pytest.approx(lb.v, rel=1e-6, abs=1e-9)
            assert la.s_cam == pytest.approx(lb.s_cam, abs=1e-10)


def test_parse_format():
    text = "# lift table\nangle_deg; lift_mm\n0; 0\n90\t5\n180   10\n270,5\n360,0\n"
    angles, lifts = parse_motion_table(text)
    assert angles == [0.0, 90.0, 180.0, 270.0] and lifts == [0.0, 5.0, 10.0, 5.0]   # 360 row closes
    prog = program_from_table_text(text)
    assert prog.derivatives(math.pi)[0] == pytest.approx(0.010, abs=1e-15)
    assert prog.lift == pytest.approx(0.010)


@pytest.mark.parametrize("text, fragment", [
    ("a,b\n0,0\n90,1\n", "at least 3 rows"),
    ("a,b\n0,0\n90,1\n90,2\n", "increase strictly, row 3 (90 deg) follows 90 deg"),
    ("a,b\n0,0\n90,1\n180,2\n360,1\n", "must repeat the lift at 0 deg (0 mm), got 1 mm"),
    ("a,b\n0,0\n90,-1\n180,2\n", "line 3: lift must be a finite number >= 0 mm"),
    ("a,b\n0,0\n400,1\n180,2\n", "line 3: angle must lie in [0, 360] deg"),
    ("a,b\n0,0\n90,x\n180,2\n", "line 3: expected two numbers"),
])
def test_table_errors(text, fragment):
    with pytest.raises(ValueError) as exc:
        program_from_table_text(text)
    assert fragment in str(exc.value)


@pytest.mark.parametrize("angles, lifts, fragment", [
    ([0.0, 1.0, TWO_PI], [0.0, 1.0, 0.0], "span less than 360 deg"),
    ([0.0, 1.0], [0.0, 1.0], "at least 3 points"),
    ([0.0, 2.0, 1.0], [0.0, 1.0, 0.0], "increase strictly: point 3"),
    ([0.0, 1.0, 2.0], [0.0, -1.0, 0.0], "lift must be >= 0"),
])
def test_program_errors(angles, lifts, fragment):
    with pytest.raises(ValueError) as exc:
        TableProgram(angles, lifts)
    assert fragment in str(exc.value)


def _table_text(prog, step_deg):
    th = np.arange(0.0, 360.0, step_deg)
    lift = prog.evaluate(np.radians(th))[0]
    return "angle_deg,lift_mm\n" + "\n".join(f"{float(a)!r},{float(s) * 1e3!r}" for a, s in zip(th, lift))


def test_the_fmu_engine_runs_a_motion_table_parameter():
    """The String parameter motion_table drives the FMU's engine: the paper profile given as a
    table converges to the run on the law itself as the table gets finer (fig. 6, 1 s)."""
    from cam_fmu.fmu.engine import DriveSimulator

    def theta_after_1s(params):
        sim = DriveSimulator(params)
        sim.set_inputs(3.5, 1.0, 0.0)
        for k in range(1000):
            sim.do_step(k * 1e-3, 1e-3, 3.5, 1.0, 0.0)
        return sim.outputs()["theta"]

    law = theta_after_1s({})
    errors = [abs(theta_after_1s({"motion_table": _table_text(paper_program(), step)}) - law) for step in (1.0, 0.25)]
    assert law > 4.0  # the cam turned
    assert errors[0] < 1e-6 and errors[1] < errors[0] / 4


def test_a_bad_motion_table_is_a_parameter_error():
    from cam_fmu.physics.drive import DriveModel
    from cam_fmu.physics.parameters import ParameterError

    with pytest.raises(ParameterError, match="motion_table"):
        DriveModel({"motion_table": "angle_deg,lift_mm\n0,1\nfoo,bar\n"})
