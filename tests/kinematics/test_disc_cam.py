"""Disc-cam geometry against closed forms and independent numerical computations."""

import math

import numpy as np
import pytest
import sympy as sp
from scipy.spatial import cKDTree

from cam_fmu.kinematics.cam_program import CamProgram, paper_program
from cam_fmu.kinematics.disc_cam import DiscCam


class EccentricCircle:
    """Follower lift of a circular disc (radius Rc, centre eps off the cam axis)
    under a roller r_r on the line y = -e, derived here with sympy from the
    circle's geometry alone: roller centre (X, -e) at distance Rc + r_r from
    the disc centre eps (cos psi, sin psi), psi = theta + psi0."""

    def __init__(self, Rc, eps, r_r, e):
        self.Rp = Rp = Rc + r_r
        self.r_b = Rp - eps                          # closest pitch point to the axis
        self.eps, self.e = eps, e
        self.psi0 = math.pi - math.asin(e / self.r_b)   # s(0) = 0
        th = sp.Symbol("th")
        psi = th + self.psi0
        X = eps * sp.cos(psi) + sp.sqrt(Rp ** 2 - (e + eps * sp.sin(psi)) ** 2)
        s = X - math.sqrt(self.r_b ** 2 - e ** 2)
        self._f = [sp.lambdify(th, sp.diff(s, th, k), "numpy") for k in range(4)]
        self._X = sp.lambdify(th, X, "numpy")

    def evaluate(self, theta):
        theta = np.asarray(theta, dtype=float)
        return tuple(np.broadcast_to(f(theta), theta.shape).astype(float) for f in self._f)

    def derivatives(self, theta):
        return tuple(float(f(theta)) for f in self._f)

    def breakpoints(self):
        return (0.0,)

    def centre_cam_frame(self):
        return self.eps * math.cos(self.psi0), self.eps * math.sin(self.psi0)


TH = np.linspace(0.0, 2.0 * math.pi, 721)


@pytest.mark.parametrize("e", [0.0, 0.012, -0.02])
def test_eccentric_circle_closed_forms(e):
    Rc, eps, r_r = 0.06, 0.015, 0.01
    prog = EccentricCircle(Rc, eps, r_r, e)
    s = prog.evaluate(TH)[0]
    assert s.min() > -1e-12 and s.max() > 0.02           # lift measured from the prime circle
    cam = DiscCam(prog, prog.r_b, r_r, e)
    cx, cy = prog.centre_cam_frame()
    # pitch curve, inner and outer contour are circles about the disc centre
    x, y = cam.pitch(TH)
    assert np.allclose(np.hypot(x - cx, y - cy), Rc + r_r, rtol=0, atol=1e-12)
    x, y = cam.contour(TH, "inner")
    assert np.allclose(np.hypot(x - cx, y - cy), Rc, rtol=0, atol=1e-12)
    x, y = cam.contour(TH, "outer")
    assert np.allclose(np.hypot(x - cx, y - cy), Rc + 2 * r_r, rtol=0, atol=1e-12)
    # constant radius of curvature
    assert np.allclose(cam.pitch_radius_of_curvature(TH), Rc + r_r, rtol=1e-10)
    assert np.allclose(cam.contour_radius_of_curvature(TH, "inner"), Rc, rtol=1e-10)
    assert np.allclose(cam.contour_radius_of_curvature(TH, "outer"), Rc + 2 * r_r, rtol=1e-10)
    # pressure angle: the contact normal passes through the disc centre
    psi = TH + prog.psi0
    alpha = np.arctan2(-e - eps * np.sin(psi), prog._X(TH) - eps * np.cos(psi))
    assert np.allclose(cam.pressure_angle(TH), alpha, rtol=0, atol=1e-12)


def _fd_pitch(cam, th):
    """Pitch points, first and second derivatives by central differences."""
    h = 1e-4
    pts = [np.array(cam.pitch(th + k * h)) for k in (-1, 0, 1)]
    d1 = (pts[2] - pts[0]) / (2 * h)
    d2 = (pts[2] - 2 * pts[1] + pts[0]) / h ** 2
    return pts[1], d1, d2


@pytest.mark.parametrize("e", [0.0, 0.015, -0.025])
def test_curvature_and_pressure_angle_against_finite_differences(e):
    prog = CamProgram("modified_sine", "cycloidal", 0.03, math.radians(100), math.radians(50),
                      math.radians(120), math.radians(90))
    cam = DiscCam(prog, 0.07, 0.015, e)
    bp = np.array(prog.breakpoints() + (2 * math.pi,))
    th = np.linspace(0.0, 2 * math.pi, 1999)
    th = th[np.min(np.abs(th[:, None] - bp[None, :]), axis=1) > 1e-3]   # s'' may jump at breakpoints
    _, d1, d2 = _fd_pitch(cam, th)
    cross = d1[0] * d2[1] - d1[1] * d2[0]
    kappa_fd = -cross / np.hypot(d1[0], d1[1]) ** 3       # clockwise traversal: convex > 0
    assert np.allclose(cam.pitch_curvature(th), kappa_fd, rtol=1e-5, atol=1e-4)
    # pressure angle: normal of the pitch curve, rotated into the fixed frame, against +X
    c, s = np.cos(th), np.sin(th)
    tx, ty = c * d1[0] - s * d1[1], s * d1[0] + c * d1[1]
    alpha_fd = np.arctan2(tx, -ty)                           # normal = tangent turned +90 deg
    assert np.allclose(cam.pressure_angle(th), alpha_fd, rtol=0, atol=1e-7)
    # and the closed form tan(alpha) = (s' - e) / (sqrt(r_b^2 - e^2) + s)
    sv, s1, _, _ = prog.evaluate(th)
    assert np.allclose(np.tan(cam.pressure_angle(th)), (s1 - e) / (math.sqrt(0.07 ** 2 - e ** 2) + sv),
                       rtol=1e-12, atol=1e-15)


def test_positive_offset_lowers_the_rise_pressure_angle():
    prog = paper_program()
    rise = np.linspace(0.0, math.pi, 2001)
    ret = rise + math.pi
    a0, ap = DiscCam(prog, 0.1, 0.02, 0.0), DiscCam(prog, 0.1, 0.02, 0.02)
    assert np.abs(ap.pressure_angle(rise)).max() < np.abs(a0.pressure_angle(rise)).max() - math.radians(3)
    assert np.abs(ap.pressure_angle(ret)).max() > np.abs(a0.pressure_angle(ret)).max() + math.radians(3)
    # the in-line case equals CamProgram's own pressure angle (tan a = s' / (r_b + s))
    assert np.allclose(a0.pressure_angle(rise), prog.pressure_angle(rise, 0.1), atol=1e-15)


@pytest.mark.parametrize("e", [0.0, 0.02])
def test_every_contour_point_is_r_r_from_the_pitch_curve(e):
    prog = paper_program()
    r_r = 0.02
    cam = DiscCam(prog, 0.1, r_r, e)
    dense = np.linspace(0.0, 2 * math.pi, 400001)
    tree = cKDTree(np.column_stack(cam.pitch(dense)))
    th = np.linspace(0.0, 2 * math.pi, 3600, endpoint=False)
    for side in ("inner", "outer"):
        d, _ = tree.query(np.column_stack(cam.contour(th, side)))
        # nearest point of the whole pitch curve (not only the one it came from)
        assert np.abs(d - r_r).max() < 1e-7, side
    # the inner contour lies on the cam axis side: closer to the axis than the pitch curve
    assert np.all(np.hypot(*cam.contour(th)) < np.hypot(*cam.pitch(th)))


def test_zero_lift_is_the_prime_circle_and_the_contour_base_circle():
    prog = CamProgram("cycloidal", "cycloidal", 0.02, 1.0, 1.0, 1.0, 2 * math.pi - 3.0)
    cam = DiscCam(prog, 0.05, 0.012, 0.01)
    dwell = np.linspace(3.01, 2 * math.pi - 0.01, 50)   # lower dwell: s = 0
    assert np.allclose(np.hypot(*cam.pitch(dwell)), 0.05, atol=1e-15)
    assert np.allclose(np.hypot(*cam.contour(dwell)), 0.05 - 0.012, atol=1e-15)
    assert cam.base_circle_radius == pytest.approx(0.038)
    # at theta = 0 the roller centre is on the follower axis y = -e
    x, y = cam.pitch(0.0)
    assert y == pytest.approx(-0.01) and x == pytest.approx(math.sqrt(0.05 ** 2 - 0.01 ** 2))


@pytest.mark.parametrize("kw, fragment", [
    (dict(base_radius=0.05, roller_radius=0.05), "roller_radius r_r = 50 mm must be < r_b = 50 mm"),
    (dict(base_radius=0.05, roller_radius=-0.001), "roller_radius r_r must be a finite number >= 0"),
    (dict(base_radius=-1.0, roller_radius=0.01), "base_radius"),
    (dict(base_radius=0.05, roller_radius=0.01, offset=0.05), "|e| < r_b = 50 mm"),
    (dict(base_radius=0.05, roller_radius=0.01, offset=math.nan), "offset"),
])
def test_errors_name_the_parameter_and_the_range(kw, fragment):
    with pytest.raises(ValueError) as exc:
        DiscCam(paper_program(), **kw)
    assert fragment in str(exc.value)
    with pytest.raises(ValueError, match="side must be 'inner' or 'outer'"):
        DiscCam(paper_program(), 0.1, 0.01).contour(0.0, "left")


def test_a_knife_edge_is_a_roller_of_radius_zero():
    """r_r = 0: the contour is the pitch curve, its radius of curvature the pitch curve's, nothing undercuts."""
    from cam_fmu.kinematics.design_checks import check_design

    cam = DiscCam(paper_program(), 0.1, 0.0, 0.01)
    th = np.linspace(0.0, 2 * math.pi, 721)
    assert np.array_equal(np.array(cam.contour(th)), np.array(cam.pitch(th)))
    assert np.array_equal(cam.contour_radius_of_curvature(th), cam.pitch_radius_of_curvature(th))
    rep = check_design(cam)
    assert not rep.undercut and rep.min_radius_of_curvature == rep.min_pitch_radius > 0.0
