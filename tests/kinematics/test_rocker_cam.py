"""The oscillating roller follower against closed forms written here: the roller centre's path and the
pressure angle from the triangle (cam axis O, pivot P, roller centre C; law of cosines) and from the
relative instant centre of cam and arm, an eccentric circle cam whose arm motion is the intersection of
two circles, the curvature from finite differences; the refused geometries; the smallest base radius."""

import math
import re

import numpy as np
import pytest
import sympy as sp
from closed_forms import SympyProgram, to_cam_frame

from cam_fmu.kinematics.cam_program import CamProgram
from cam_fmu.kinematics.design_checks import Limits
from cam_fmu.kinematics.follower_checks import check_follower, refuse_unbuildable, smallest_base_radius_for
from cam_fmu.kinematics.follower_types import make_cam
from cam_fmu.kinematics.rocker_cam import OscillatingRollerCam

PROG = CamProgram("cycloidal", "modified_sine", 0.02, math.radians(100), math.radians(40),
                  math.radians(120), math.radians(100))
TH = np.linspace(0.0, 2 * math.pi, 1441)


def _triangle(r_b, L, d):
    """Pivot P (fixed frame) with the roller centre at (r_b, 0) and P on the +Y side; the angle at P."""
    beta = math.acos((d * d + r_b * r_b - L * L) / (2 * d * r_b))       # angle at O
    delta0 = math.acos((d * d + L * L - r_b * r_b) / (2 * d * L))       # angle at P
    return np.array([d * math.cos(beta), d * math.sin(beta)]), delta0


@pytest.mark.parametrize("r_b, L, d, lift_deg", [(0.05, 0.08, 0.1, 20.0), (0.04, 0.12, 0.1, 30.0)])
def test_roller_centre_path_and_pressure_angle_from_the_triangle(r_b, L, d, lift_deg):
    lift = math.radians(lift_deg)
    cam = OscillatingRollerCam(PROG, r_b, 0.01, L, d, lift)
    P, delta0 = _triangle(r_b, L, d)
    s, s1, _, _ = PROG.evaluate(TH)
    psi, psi1 = lift * s / PROG.lift, lift * s1 / PROG.lift
    # law of cosines: |OC|^2 = d^2 + L^2 - 2 d L cos(delta0 + psi); |PC| = L
    x, y = cam.pitch(TH)
    assert np.allclose(np.hypot(x, y), np.sqrt(d * d + L * L - 2 * d * L * np.cos(delta0 + psi)), rtol=0, atol=1e-13)
    px, py = to_cam_frame(TH, P[0], P[1])
    assert np.allclose(np.hypot(x - px, y - py), L, rtol=0, atol=1e-13)
    # the arm's angle: between PO and PC, delta0 + psi (fixed frame: C = Rot(theta) c)
    Cx, Cy = to_cam_frame(-TH, x, y)
    ang = np.arccos(((-P[0]) * (Cx - P[0]) + (-P[1]) * (Cy - P[1])) / (d * L))
    assert np.allclose(ang, delta0 + psi, rtol=0, atol=1e-7)
    # pressure angle: the contact normal passes through the instant centre of cam (about O, speed 1) and
    # arm (about P, speed psi'), I = -psi' / (1 - psi') P; alpha is between the line C-I and the path (the
    # perpendicular of P-C)
    Ix, Iy = -psi1 / (1 - psi1) * P[0], -psi1 / (1 - psi1) * P[1]
    nx, ny = Cx - Ix, Cy - Iy
    wx, wy = -(Cy - P[1]), Cx - P[0]
    alpha = np.arccos(np.abs(nx * wx + ny * wy) / (np.hypot(nx, ny) * np.hypot(wx, wy)))
    assert np.allclose(np.abs(cam.pressure_angle(TH)), alpha, rtol=0, atol=1e-7)
    # on a dwell the normal is the radius OC: |alpha| = |90 deg - gamma|, gamma the triangle's angle at C
    dwell = (TH > math.radians(100.5)) & (TH < math.radians(139.5))
    r = np.hypot(x, y)[dwell]
    gamma = np.arccos((L * L + r * r - d * d) / (2 * L * r))
    assert np.allclose(np.abs(cam.pressure_angle(TH[dwell])), np.abs(0.5 * math.pi - gamma), atol=1e-12)


def eccentric_rocker(r_b, L, d, Rp):
    """An eccentric circle (pitch circle radius Rp, centre Q0 in the cam frame) under an arm of length L about
    P: the roller centre is where the circle about P (radius L) meets the circle about Q(theta) = Rot(theta) Q0
    (radius Rp), psi(theta) by sympy from that intersection alone.  At theta = 0 the arm is at its lowest,
    with the roller centre at (r_b, 0): the pitch circle's point nearest the cam axis, Q0 = (r_b - Rp, 0).
    Returns (program with S = psi / lift_angle, lift_angle, Q0)."""
    P, _ = _triangle(r_b, L, d)
    u0 = (np.array([r_b, 0.0]) - P) / L                  # arm direction at zero lift
    Q0 = np.array([r_b - Rp, 0.0])
    th = sp.Symbol("th")
    Qx, Qy = Q0[0] * sp.cos(th), Q0[0] * sp.sin(th)
    Dx, Dy = P[0] - Qx, P[1] - Qy
    D = sp.sqrt(Dx ** 2 + Dy ** 2)
    phi0 = math.atan2(u0[1], u0[0])
    # |P + L u(phi) - Q| = Rp  <=>  cos(phi - eta) = (Rp^2 - D^2 - L^2) / (2 L D), eta = atan2(Dy, Dx)
    eta = sp.atan2(Dy, Dx)
    k = (Rp ** 2 - D ** 2 - L ** 2) / (2 * L * D)
    eta0 = float(eta.subs(th, 0))
    sign = 1.0 if (phi0 - eta0 + math.pi) % (2 * math.pi) - math.pi >= 0 else -1.0
    psi = eta + sign * sp.acos(k) - (eta0 + sign * math.acos(float(k.subs(th, 0))))
    prog = SympyProgram(psi, th)
    lift_angle = prog.largest()
    return SympyProgram(psi, th, lift_angle), lift_angle, Q0


def test_eccentric_circle_under_a_rocker():
    r_b, L, d, Rp, r_r = 0.05, 0.09, 0.11, 0.06, 0.012
    prog, lift_angle, (qx, qy) = eccentric_rocker(r_b, L, d, Rp)
    assert prog.values(TH).min() > -1e-12 and lift_angle > math.radians(5)      # the arm lowest at theta = 0
    cam = OscillatingRollerCam(prog, r_b, r_r, L, d, lift_angle)
    refuse_unbuildable(cam)
    x, y = cam.pitch(TH)
    assert np.allclose(np.hypot(x - qx, y - qy), Rp, rtol=0, atol=1e-11)          # the pitch circle
    x, y = cam.contour(TH)
    assert np.allclose(np.hypot(x - qx, y - qy), Rp - r_r, rtol=0, atol=1e-11)    # the disc
    assert np.allclose(cam.pitch_radius_of_curvature(TH), Rp, rtol=1e-9)
    assert np.allclose(cam.contour_radius_of_curvature(TH), Rp - r_r, rtol=1e-9)
    # the contact normal passes through the disc centre: alpha between C - Q and the path
    P, _ = _triangle(r_b, L, d)
    Cx, Cy = cam.roller_centre(TH)
    Qx, Qy = to_cam_frame(-TH, qx, qy)
    nx, ny = Cx - Qx, Cy - Qy
    wx, wy = -(Cy - P[1]), Cx - P[0]
    alpha = np.arccos(np.abs(nx * wx + ny * wy) / (np.hypot(nx, ny) * np.hypot(wx, wy)))
    assert np.allclose(np.abs(cam.pressure_angle(TH)), alpha, rtol=0, atol=1e-9)


def test_curvature_against_finite_differences_and_the_contour_offset():
    cam = OscillatingRollerCam(PROG, 0.05, 0.01, 0.08, 0.1, math.radians(20))
    bp = np.array(PROG.breakpoints() + (2 * math.pi,))
    th = np.linspace(0.0, 2 * math.pi, 1999)
    th = th[np.min(np.abs(th[:, None] - bp[None, :]), axis=1) > 1e-3]
    h = 1e-4
    p = [np.array(cam.pitch(th + k * h)) for k in (-1, 0, 1)]
    d1, d2 = (p[2] - p[0]) / (2 * h), (p[2] - 2 * p[1] + p[0]) / h ** 2
    kappa = -(d1[0] * d2[1] - d1[1] * d2[0]) / np.hypot(d1[0], d1[1]) ** 3
    assert np.allclose(cam.pitch_curvature(th), kappa, rtol=1e-5, atol=1e-4)
    # the normal is perpendicular to the pitch curve's tangent and points away from the cam
    nx, ny = cam.normal(th)
    assert np.allclose(nx * d1[0] + ny * d1[1], 0.0, atol=1e-6 * np.hypot(d1[0], d1[1]).max())
    cx, cy = cam.contour(th)
    assert np.allclose(np.hypot(cx - p[1][0], cy - p[1][1]), 0.01, atol=1e-14)
    assert np.all(np.hypot(cx, cy) < np.hypot(p[1][0], p[1][1]))
    # a knife edge: the contour is the pitch curve
    knife = OscillatingRollerCam(PROG, 0.05, 0.0, 0.08, 0.1, math.radians(20))
    assert np.array_equal(np.array(knife.contour(th)), np.array(knife.pitch(th)))
    assert not check_follower(knife).undercut


@pytest.mark.parametrize("kw, fragment", [
    (dict(base_radius=0.05, arm_length=0.02, pivot_distance=0.1), "the arm cannot reach the cam"),
    (dict(base_radius=0.05, arm_length=0.2, pivot_distance=0.1), "|d - L| < r_b < d + L"),
    (dict(base_radius=0.05, arm_length=0.05, pivot_distance=0.03), "puts the pivot inside the cam's base circle"),
    (dict(base_radius=0.05, arm_length=0.08, pivot_distance=0.1, lift_angle=math.radians(200)),
     "lift_angle must lie in (0, 180) deg"),
])
def test_refused_at_construction(kw, fragment):
    args = dict(r_roller=0.01, lift_angle=math.radians(20)) | kw
    with pytest.raises(ValueError) as exc:
        make_cam(PROG, args.pop("base_radius"), "oscillating_roller", **args)
    assert fragment in str(exc.value)


def test_pressure_angle_at_90_degrees_is_refused():
    # d = 0.1, L = 0.08, r_b = 0.05: delta0 = 29.7 deg; a swing to 180 deg at the pivot is refused
    cam = OscillatingRollerCam(PROG, 0.05, 0.01, 0.08, 0.1, math.radians(155))
    _, delta0 = _triangle(0.05, 0.08, 0.1)
    with pytest.raises(ValueError) as exc:
        refuse_unbuildable(cam)
    assert "pressure angle reaches 90 deg" in str(exc.value)
    assert f"{math.degrees(math.pi - delta0):.6g} deg" in str(exc.value)
    just_below = OscillatingRollerCam(PROG, 0.05, 0.01, 0.08, 0.1, math.pi - delta0 - 1e-3)
    assert np.abs(just_below.pressure_angle(TH)).max() < 0.5 * math.pi
    # an arm turned that far puts the roller beyond the pivot (r -> d + L): the cam sweeps over the pivot,
    # the next refusal
    with pytest.raises(ValueError, match="would sweep over the pivot"):
        refuse_unbuildable(just_below)


def _max_alpha_triangle(r_b, L, d, lift):
    """max |alpha| [rad] on a dense grid from the instant-centre construction (no code under test)."""
    th = np.linspace(0.0, 2 * math.pi, 400001)
    s, s1, _, _ = PROG.evaluate(th)
    psi, psi1 = lift * s / PROG.lift, lift * s1 / PROG.lift
    P, delta0 = _triangle(r_b, L, d)
    phi = math.atan2(-P[1], -P[0]) + delta0 + psi
    Cx, Cy = P[0] + L * np.cos(phi), P[1] + L * np.sin(phi)
    Ix, Iy = -psi1 / (1 - psi1) * P[0], -psi1 / (1 - psi1) * P[1]
    nx, ny, wx, wy = Cx - Ix, Cy - Iy, -np.sin(phi), np.cos(phi)
    return float(np.arccos(np.abs(nx * wx + ny * wy) / np.hypot(nx, ny)).max())


@pytest.mark.parametrize("L, d", [(0.1, 0.12), (0.15, 0.18)])
def test_smallest_base_radius_is_tight(L, d):
    limit = math.radians(40)
    lift = math.radians(20)
    cam = make_cam(PROG, 0.05, "oscillating_roller", r_roller=0.008, arm_length=L, pivot_distance=d, lift_angle=lift)
    r = smallest_base_radius_for(cam, Limits(limit), tol=1e-7)
    assert _max_alpha_triangle(r, L, d, lift) <= limit + 1e-7
    assert _max_alpha_triangle(r - 2e-5, L, d, lift) > limit
    assert check_follower(make_cam(PROG, r, "oscillating_roller", r_roller=0.008, arm_length=L, pivot_distance=d,
                                   lift_angle=lift), Limits(limit)).ok


def test_a_cam_that_sweeps_over_the_pivot_is_refused():
    # L = 30 mm, d = 60 mm, r_b = 40 mm: the roller stays clear, but the contour's top (the prime circle plus
    # the lift, less the roller) comes past 60 mm from the axis
    cam = OscillatingRollerCam(PROG, 0.04, 0.005, 0.03, 0.06, math.radians(60))
    th = np.linspace(0.0, 2 * math.pi, 200001)
    reach = np.hypot(*cam.contour(th)).max()
    assert reach > 0.06
    with pytest.raises(ValueError) as exc:
        refuse_unbuildable(cam)
    assert "would sweep over the pivot" in str(exc.value)
    told = re.search(r"d must be > ([0-9.]+) mm", str(exc.value))
    assert told and float(told.group(1)) == pytest.approx(reach * 1e3, abs=1e-3)
    # the roller centre's own path reaches further still: the check is on the contour, not the pitch curve
    assert np.hypot(*cam.pitch(th)).max() == pytest.approx(reach + 0.005, abs=1e-9)
