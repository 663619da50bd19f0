"""Flat-faced followers against closed forms written here: the translating face's contour from the envelope
(the contact s' along the face, rho = r_b + s + s''), the face touching the cam at every angle, eccentric
circles under a translating and an oscillating face, the face width, the refused geometries and the smallest
base radius against its closed form max(-(s + s''))."""

import math
import re

import numpy as np
import pytest
import sympy as sp
from closed_forms import SympyProgram, to_cam_frame
from scipy.optimize import minimize_scalar

from cam_fmu.kinematics.cam_program import CamProgram
from cam_fmu.kinematics.design_checks import Limits
from cam_fmu.kinematics.flat_cam import OscillatingFlatCam, TranslatingFlatCam
from cam_fmu.kinematics.follower_checks import check_flat, refuse_unbuildable, smallest_base_radius_for
from cam_fmu.kinematics.follower_types import make_cam

PROG = CamProgram("cycloidal", "modified_sine", 0.02, math.radians(100), math.radians(40),
                  math.radians(120), math.radians(100))
TH = np.linspace(0.0, 2 * math.pi, 1441)


def test_translating_face_contour_from_the_envelope():
    r_b = 0.05
    cam = TranslatingFlatCam(PROG, r_b)
    refuse_unbuildable(cam)
    s, s1, s2, _ = PROG.evaluate(TH)
    # the contact is s' from the axis along the face: (r_b + s, -s') in the fixed frame
    x, y = cam.contour(TH)
    ex, ey = to_cam_frame(TH, r_b + s, -s1)
    assert np.allclose(x, ex, rtol=0, atol=1e-15) and np.allclose(y, ey, rtol=0, atol=1e-15)
    assert np.allclose(cam.radius_of_curvature(TH), r_b + s + s2, rtol=0, atol=1e-15)
    assert np.allclose(cam.face_position(TH), -s1, rtol=0, atol=0)
    # the face touches the cam at every angle: no contour point lies beyond the face x = r_b + s
    dense = np.array(cam.contour(np.linspace(0, 2 * math.pi, 20000, endpoint=False)))
    for t, lift in zip(TH[::8], s[::8]):
        n = np.array([math.cos(t), -math.sin(t)])           # the face's normal in the cam frame
        assert (n @ dense).max() <= r_b + lift + 1e-9
    # and rho from finite differences of the contour points
    th = TH[(np.abs(TH - math.radians(50)) < 0.6)]
    h = 1e-4
    p = [np.array(cam.contour(th + k * h)) for k in (-1, 0, 1)]
    d1, d2 = (p[2] - p[0]) / (2 * h), (p[2] - 2 * p[1] + p[0]) / h ** 2
    rho_fd = -np.hypot(d1[0], d1[1]) ** 3 / (d1[0] * d2[1] - d1[1] * d2[0])
    assert np.allclose(cam.radius_of_curvature(th), rho_fd, rtol=1e-5)


def test_translating_face_on_an_eccentric_circle():
    # a disc of radius Rc, centre eps from the axis: the face at x = Rc + eps cos(theta + pi) + ..., i.e.
    # s = eps (1 - cos theta) over r_b = Rc - eps; the contour is the disc, rho = Rc, the face width 2 eps
    Rc, eps = 0.04, 0.01

    class Eccentric:
        lift = 2 * eps

        def evaluate(self, th):
            th = np.asarray(th, dtype=float)
            return eps * (1 - np.cos(th)), eps * np.sin(th), eps * np.cos(th), -eps * np.sin(th)

        def derivatives(self, th):
            return tuple(float(v) for v in self.evaluate(th))

        def breakpoints(self):
            return (0.0,)

    cam = TranslatingFlatCam(Eccentric(), Rc - eps)
    x, y = cam.contour(TH)
    assert np.allclose(np.hypot(x + eps, y), Rc, rtol=0, atol=1e-15)
    assert np.allclose(cam.radius_of_curvature(TH), Rc, rtol=0, atol=1e-15)
    rep = check_flat(cam)
    assert rep.face_width == pytest.approx(2 * eps, rel=1e-12) and rep.ok


def test_face_width_is_max_minus_min_of_s_prime():
    rep = check_flat(TranslatingFlatCam(PROG, 0.05))
    # cycloidal rise: s'max = 2 h / b; modified sine return: s'max = 1.76 h / b (Vm of the law)
    b_rise, b_ret = math.radians(100), math.radians(120)
    from cam_fmu.kinematics.characteristics import characteristics
    from cam_fmu.kinematics.presets import law
    vm_ret = characteristics(law("modified_sine")).Vm
    assert rep.face_max == pytest.approx(0.02 * vm_ret / b_ret, rel=1e-9)       # the return: -s' > 0
    assert rep.face_min == pytest.approx(-2 * 0.02 / b_rise, rel=1e-9)
    assert rep.face_width == pytest.approx(2 * 0.02 / b_rise + 0.02 * vm_ret / b_ret, rel=1e-9)


def test_smallest_base_radius_of_a_translating_face_is_the_closed_form():
    def need(th):
        s, _, s2, _ = PROG.derivatives(th)
        return s + s2

    grid = np.linspace(0, 2 * math.pi, 20001)
    k = int(np.argmin([need(t) for t in grid]))
    res = minimize_scalar(need, bounds=(grid[k - 1], grid[k + 1]), method="bounded", options={"xatol": 1e-12})
    bound = -res.fun                                          # rho = r_b + s + s'' > 0 <=> r_b > bound
    r = smallest_base_radius_for(TranslatingFlatCam(PROG, 0.05), tol=1e-9)
    assert r == pytest.approx(bound, abs=2e-9)
    refuse_unbuildable(TranslatingFlatCam(PROG, r))           # holds at r_b_min
    with pytest.raises(ValueError) as exc:                    # a little below it is refused
        refuse_unbuildable(TranslatingFlatCam(PROG, r - 1e-6))
    msg = str(exc.value)
    assert "radius of curvature r_b + s + s''" in msg and "<= 0" in msg and "base_radius r_b" in msg
    told = re.search(r"base_radius must be > ([0-9.]+) mm \(to 1e-3 mm\)", msg)
    assert told and float(told.group(1)) == pytest.approx(bound * 1e3, abs=1.5e-3)
    # with a limit on rho the bound moves by the limit
    r5 = smallest_base_radius_for(TranslatingFlatCam(PROG, 0.05), Limits(min_radius_of_curvature=0.005), tol=1e-9)
    assert r5 == pytest.approx(bound + 0.005, abs=2e-9)


def eccentric_under_face(Rc, eps, d):
    """A disc (radius Rc, centre (-eps, 0) in the cam frame) under a flat face through the pivot P =
    (r_b, sqrt(d^2 - r_b^2)), r_b = Rc - eps: the face's normal (cos psi, sin psi) with the disc tangent to
    it, (cos psi, sin psi) . (Q(theta) - P) = -Rc, solved for psi by sympy.  Returns (program with
    S = psi / lift_angle, lift_angle, P)."""
    r_b = Rc - eps
    P = (r_b, math.sqrt(d * d - r_b * r_b))
    th = sp.Symbol("th")
    Dx, Dy = -eps * sp.cos(th) - P[0], -eps * sp.sin(th) - P[1]
    D = sp.sqrt(Dx ** 2 + Dy ** 2)
    eta = sp.atan2(Dy, Dx)
    cands = [eta + sgn * sp.acos(-Rc / D) for sgn in (1, -1)]
    k0 = [float(c.subs(th, 0)) for c in cands]
    best = min(range(2), key=lambda i: abs((k0[i] + math.pi) % (2 * math.pi) - math.pi))
    psi = cands[best] - round(k0[best] / (2 * math.pi)) * 2 * sp.pi
    lift_angle = SympyProgram(psi, th).largest()
    return SympyProgram(psi, th, lift_angle), lift_angle, P


def test_oscillating_face_on_an_eccentric_circle():
    Rc, eps, d, L = 0.05, 0.008, 0.12, 0.1
    prog, lift_angle, P = eccentric_under_face(Rc, eps, d)
    assert prog.values(np.linspace(0, 2 * math.pi, 2001)).min() > -1e-12
    cam = OscillatingFlatCam(prog, Rc - eps, L, d, lift_angle)
    refuse_unbuildable(cam)
    x, y = cam.contour(TH)
    assert np.allclose(np.hypot(x + eps, y), Rc, rtol=0, atol=1e-11)              # the disc
    assert np.allclose(cam.radius_of_curvature(TH), Rc, rtol=1e-9)
    # the contact is the foot of the disc centre on the face: Q + Rc n; its distance from P along the face
    psi = prog.values(TH)
    qx, qy = to_cam_frame(-TH, -eps, 0.0)
    fx, fy = qx + Rc * np.cos(psi), qy + Rc * np.sin(psi)
    ell = (fx - P[0]) * np.sin(psi) - (fy - P[1]) * np.cos(psi)          # along (sin psi, -cos psi)
    assert np.allclose(cam.face_position(TH), ell, rtol=0, atol=1e-11)
    # at zero lift the contact is the foot of the axis on the face, sqrt(d^2 - r_b^2) from the pivot
    assert cam.face_position(0.0) == pytest.approx(math.sqrt(d * d - (Rc - eps) ** 2), rel=1e-12)
    assert np.allclose(cam.pressure_angle(TH), 0.0)


def test_oscillating_face_closed_forms_on_a_program():
    r_b, d, L, lift = 0.05, 0.12, 0.1, math.radians(10)
    cam = OscillatingFlatCam(PROG, r_b, L, d, lift)
    refuse_unbuildable(cam)
    s, s1, s2, _ = PROG.evaluate(TH)
    psi, psi1 = lift * s / PROG.lift, lift * s1 / PROG.lift
    delta = math.asin(r_b / d) + psi
    # the face is at d sin(delta) from the axis: every contour point within, the contact on it
    x, y = cam.contour(TH)
    X, Y = to_cam_frame(-TH, x, y)                                     # the contact in the fixed frame
    P = np.array([r_b, math.sqrt(d * d - r_b * r_b)])
    assert np.allclose((X - P[0]) * np.cos(psi) + (Y - P[1]) * np.sin(psi), 0.0, atol=1e-15)   # on the face
    assert np.allclose(cam.face_position(TH), d * np.cos(delta) / (1 - psi1), rtol=1e-12)
    assert np.allclose(np.hypot(X - P[0], Y - P[1]), d * np.cos(delta) / (1 - psi1), rtol=1e-12)
    # the reference point at L along the face traces the pitch curve
    px, py = cam.pitch(TH)
    RX, RY = to_cam_frame(-TH, px, py)
    assert np.allclose(np.hypot(RX - P[0], RY - P[1]), L, atol=1e-15)
    dense = np.array(cam.contour(np.linspace(0, 2 * math.pi, 20000, endpoint=False)))
    for t, a, dl in zip(TH[::8], psi[::8], delta[::8]):
        n = np.array([math.cos(a - t), math.sin(a - t)])       # the face's normal in the cam frame
        assert (n @ dense).max() <= d * math.sin(dl) + 1e-9
    h = 1e-4
    th = TH[(np.abs(TH - math.radians(50)) < 0.6)]
    p = [np.array(cam.contour(th + k * h)) for k in (-1, 0, 1)]
    d1, d2 = (p[2] - p[0]) / (2 * h), (p[2] - 2 * p[1] + p[0]) / h ** 2
    rho_fd = -np.hypot(d1[0], d1[1]) ** 3 / (d1[0] * d2[1] - d1[1] * d2[0])
    assert np.allclose(cam.radius_of_curvature(th), rho_fd, rtol=1e-5)


@pytest.mark.parametrize("kw, fragment", [
    (dict(base_radius=0.05, pivot_distance=0.04, lift_angle=math.radians(10)),
     "puts the pivot inside the base circle"),
    (dict(base_radius=0.05, pivot_distance=0.06, lift_angle=math.radians(40)),
     "turns the face past the perpendicular"),
    (dict(base_radius=0.05, pivot_distance=0.12, lift_angle=math.radians(60)), "psi' = "),
    (dict(base_radius=0.02, pivot_distance=0.12, lift_angle=math.radians(10)), "<= 0 at theta"),
])
def test_oscillating_face_refusals(kw, fragment):
    with pytest.raises(ValueError) as exc:
        refuse_unbuildable(make_cam(PROG, kw.pop("base_radius"), "oscillating_flat", arm_length=0.1, **kw))
    assert fragment in str(exc.value)


def test_oscillating_face_psi_prime_limit_is_the_one_named():
    # psi' = lift * s' / h; its max on the cycloidal rise is lift * 2 / b: psi' < 1 <=> lift < b / 2
    b = math.radians(100)
    cam = make_cam(PROG, 0.1, "oscillating_flat", arm_length=0.1, pivot_distance=1.0, lift_angle=0.51 * b)
    with pytest.raises(ValueError, match=rf"lift_angle must be < {math.degrees(0.5 * b):.6g} deg"):
        refuse_unbuildable(cam)


@pytest.mark.parametrize("kind, kw, fragment", [
    ("translating_flat", dict(r_roller=0.01), "r_roller is not used by follower_type 'translating_flat'"),
    ("translating_flat", dict(offset=0.01), "offset is not used by follower_type 'translating_flat'"),
    ("oscillating_flat", dict(arm_length=0.1, pivot_distance=0.2, lift_angle=0.2, r_roller=0.0),
     "r_roller is not used by follower_type 'oscillating_flat'"),
    ("translating_roller", dict(r_roller=0.01, lift_angle=0.2), "lift_angle is not used by follower_type"),
    ("oscillating_roller", dict(r_roller=0.01, arm_length=0.1, lift_angle=0.2), "needs pivot_distance [m]"),
    ("rocker", {}, "follower_type must be one of translating_roller, translating_flat"),
])
def test_parameters_a_type_does_not_use_are_refused(kind, kw, fragment):
    with pytest.raises(ValueError) as exc:
        make_cam(PROG, 0.05, kind, **kw)
    assert fragment in str(exc.value)
