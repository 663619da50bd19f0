"""Design checks: undercut flagged on a known undercut design and not on a safe
one, extremes against independent dense computations, the base-radius search
against the pressure angle's closed-form bound."""

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from cam_fmu.kinematics.cam_program import CamProgram, paper_program
from cam_fmu.kinematics.design_checks import Limits, check_design, smallest_base_radius
from cam_fmu.kinematics.disc_cam import DiscCam

PROG = CamProgram("cycloidal", "cycloidal", 0.04, math.radians(60), math.radians(120),
                  math.radians(60), math.radians(120))


def _reversal(cam, th, side="inner"):
    """Where the contour runs against the pitch curve (finite differences of the points)."""
    h = 1e-6
    p1, p0 = np.array(cam.pitch(th + h)), np.array(cam.pitch(th - h))
    c1, c0 = np.array(cam.contour(th + h, side)), np.array(cam.contour(th - h, side))
    return np.sum((p1 - p0) * (c1 - c0), axis=0) < 0.0


def test_known_undercut_is_flagged_where_the_contour_reverses():
    # 40 mm in 60 deg on a 30 mm prime circle with a 25 mm roller: the rise's
    # convex top has rho_p < r_r, and the contour turns back on itself there.
    cam = DiscCam(PROG, 0.030, 0.025)
    rep = check_design(cam)
    assert rep.undercut and not rep.ok
    assert rep.min_radius_of_curvature < 0.0
    assert any(w.check == "undercut" for w in rep.warnings)
    th = np.linspace(0.0, 2 * math.pi, 36000, endpoint=False)
    rev = _reversal(cam, th)
    assert rev.any()
    inside = np.zeros_like(rev)
    for a, b in rep.undercut_ranges:
        assert 0.0 <= a < b < 2 * math.pi
        inside |= (th > a) & (th < b)
    # reversed exactly inside the reported ranges (grid points within 1e-5 rad of an end excluded)
    ends = np.array([x for ab in rep.undercut_ranges for x in ab])
    far = np.min(np.abs(th[:, None] - ends[None, :]), axis=1) > 1e-5
    assert np.array_equal(rev[far], inside[far])
    # and at the ends the pitch curve's radius equals the roller radius (finite differences)
    for t in ends:
        h = 1e-5
        (x0, y0), (x1, y1), (x2, y2) = (cam.pitch(t + k * h) for k in (-1, 0, 1))
        dx, dy = (x2 - x0) / (2 * h), (y2 - y0) / (2 * h)
        ddx, ddy = (x2 - 2 * x1 + x0) / h ** 2, (y2 - 2 * y1 + y0) / h ** 2
        rho = -(dx * dx + dy * dy) ** 1.5 / (dx * ddy - dy * ddx)
        assert rho == pytest.approx(0.025, rel=1e-4)


def test_safe_design_passes_and_its_contour_never_reverses():
    cam = DiscCam(PROG, 0.120, 0.010)
    rep = check_design(cam, Limits(groove=True))
    assert not rep.undercut and not rep.groove_undercut and rep.undercut_ranges == ()
    th = np.linspace(0.0, 2 * math.pi, 36000, endpoint=False)
    assert not _reversal(cam, th).any() and not _reversal(cam, th, "outer").any()
    assert rep.min_radius_of_curvature > 0.0


def test_groove_undercut_on_the_outer_wall():
    # concave pitch parts with |rho_p| < r_r: the groove's outer wall reverses, the plate cam does not
    cam = DiscCam(PROG, 0.030, 0.012)
    rep = check_design(cam, Limits(groove=True))
    assert rep.groove_undercut and not rep.undercut
    th = np.linspace(0.0, 2 * math.pi, 36000, endpoint=False)
    assert _reversal(cam, th, "outer").any() and not _reversal(cam, th, "inner").any()
    assert rep.min_concave_radius < 0.012
    assert not check_design(cam).groove_undercut          # not checked for a plate cam


@pytest.mark.parametrize("e", [0.0, 0.015])
def test_extremes_match_a_dense_independent_search(e):
    prog = paper_program()
    cam = DiscCam(prog, 0.1, 0.02, e)
    rep = check_design(cam)
    th = np.linspace(0.0, 2 * math.pi, 200000, endpoint=False)
    s, s1, s2, _ = prog.evaluate(th)
    alpha = np.abs(np.arctan2(s1 - e, math.sqrt(0.1 ** 2 - e ** 2) + s))
    k = int(np.argmax(alpha))
    assert rep.max_pressure_angle == pytest.approx(alpha[k], abs=1e-8)
    # where: any angle at which the dense search reaches the maximum (with offset 0 the cam is
    # symmetric and two angles tie to the last bit, so which one argmax returns is rounding's choice)
    maximisers = th[alpha >= alpha[k] - 1e-9]
    gap = np.abs((maximisers - rep.max_pressure_angle_at + math.pi) % (2 * math.pi) - math.pi)
    assert gap.min() < 1e-3
    # radius of curvature from the pitch points by periodic central differences
    x, y = cam.pitch(th)
    d = th[1] - th[0]
    dx, dy = (np.roll(x, -1) - np.roll(x, 1)) / (2 * d), (np.roll(y, -1) - np.roll(y, 1)) / (2 * d)
    ddx = (np.roll(x, -1) - 2 * x + np.roll(x, 1)) / d ** 2
    ddy = (np.roll(y, -1) - 2 * y + np.roll(y, 1)) / d ** 2
    kappa = -(dx * ddy - dy * ddx) / (dx * dx + dy * dy) ** 1.5
    # s''' jumps at theta = 0, where the maximum sits: the differences are good to ~1e-4 there
    assert rep.min_pitch_radius == pytest.approx(1.0 / kappa.max(), rel=1e-4)
    # closed form there: s = s' = s'' = 0 at theta = 0 gives rho_p = (e^2 + s0^2)^(1/2) = r_b
    assert rep.min_pitch_radius == pytest.approx(0.1, rel=1e-12) and rep.min_radius_at == 0.0
    assert rep.min_radius_of_curvature == pytest.approx(rep.min_pitch_radius - 0.02, abs=1e-15)
    concave = -kappa
    assert rep.min_concave_radius == pytest.approx(1.0 / concave.max(), rel=1e-4)


def test_pressure_angle_warning_says_where():
    rep = check_design(DiscCam(paper_program(), 0.06, 0.01))
    w = [w for w in rep.warnings if w.check == "pressure_angle"]
    assert len(w) == 1 and w[0].at == (rep.max_pressure_angle_at,)
    assert math.degrees(rep.max_pressure_angle) > 30.0
    assert f"{math.degrees(rep.max_pressure_angle_at):.5g} deg" in w[0].message
    assert check_design(DiscCam(paper_program(), 0.06, 0.01), Limits(math.radians(45))).ok


@pytest.mark.parametrize("limit_deg", [30.0, 40.0])
def test_smallest_base_radius_matches_the_pressure_angle_bound(limit_deg):
    # In-line follower, pressure angle the binding check: tan(alpha) = s'/(r_b + s) <= tan(limit)
    # for all theta  <=>  r_b >= max(s'/tan(limit) - s).
    prog = paper_program()
    t = math.tan(math.radians(limit_deg))

    def need(th):
        s, s1, _, _ = prog.derivatives(th)
        return -(s1 / t - s)

    grid = np.linspace(0.0, math.pi, 2001)
    k = int(np.argmin([need(x) for x in grid]))
    res = minimize_scalar(need, bounds=(grid[k - 1], grid[k + 1]), method="bounded",
                          options={"xatol": 1e-12})
    bound = -res.fun
    limits = Limits(math.radians(limit_deg), min_radius_of_curvature=0.0)
    r, rep = smallest_base_radius(prog, 0.01, 0.0, limits, tol=1e-7)
    assert rep.ok and rep.base_radius == r
    assert r == pytest.approx(bound, abs=2e-7)


def test_smallest_base_radius_meets_the_curvature_limit():
    limits = Limits(math.radians(89), min_radius_of_curvature=0.005)
    r, rep = smallest_base_radius(PROG, 0.01, 0.0, limits, tol=1e-7)
    assert rep.ok and rep.min_radius_of_curvature >= 0.005
    worse = check_design(DiscCam(PROG, r - 1e-6, 0.01), limits)
    assert not worse.ok and any(w.check == "radius_of_curvature" for w in worse.warnings)


def test_limits_are_validated():
    with pytest.raises(ValueError, match=r"max_pressure_angle must lie in \(0, 90\) deg"):
        Limits(math.radians(95))
    with pytest.raises(ValueError, match="min_radius_of_curvature must be a finite number >= 0"):
        Limits(min_radius_of_curvature=-0.001)
