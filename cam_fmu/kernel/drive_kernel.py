# cython: language_level=3, annotation_typing=False, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The cam drive's hot path: profile, right-hand side, Dormand-Prince steps, events and breakpoints.

Plain Python with ``math`` only, and the one source of these formulas: the
physics classes (``physics.drive.DriveModel``, ``physics.formulations.consistent``)
and the scipy reference call them, and ``compile.py`` compiles this file with
the C types of ``drive_kernel.pxd`` (Cython, pure-Python mode). Compiled and
pure-Python runs execute the same IEEE operations in the same order: they agree
to the last bit (tests/test_kernel_paths.py).

Style forced by the compilation, so that no Python object is built per
evaluation: results are written into attributes (``s, s1, s2, s3`` after
``profile``, the stage derivatives ``d_theta, d_omega, d_i``) instead of being
returned as tuples, the continuous state is the scalars ``theta, omega, i``,
and the mode is the attributes ``stuck, direction, contact, s_free, side``.

Formulas: docs/model.md sections 1-6 (profile, load, guide friction); the
integrator: docs/fmu.md (solver settings).
"""
from __future__ import annotations

import math
from array import array

TWO_PI = 2.0 * math.pi
SHAPE_CONST, SHAPE_SIN, SHAPE_COS = 0, 1, 2  # as kinematics.motion_law (tests/test_kernel_paths.py checks)
SEGMENT_FIELDS = 7  # end, start, F, c, kind, V0, S0 per non-empty law segment


def solve_guide_friction(n0: float, kappa: float, sigma: float, mu: float, n_support: float,
                         side: float) -> float:
    """Guide friction force f >= 0 [N] solving f = mu (|n0 + sigma kappa f| + n_support).

    The side force N_r = n0 + sigma kappa f depends on f itself (through the
    contact force): solved exactly on its two linear branches instead of lagging
    f by a step (docs/model.md section 5). Unique because mu |kappa| < 1.
    ``side`` +1/-1 takes the branch where N_r has that sign (held between the
    integrators' side-force events); 0 chooses the branch that holds.
    """
    if mu == 0.0:
        return 0.0
    if side != 0.0:
        return mu * (side * n0 + n_support) / (1.0 - side * mu * sigma * kappa)
    sk = sigma * kappa
    f = mu * (n0 + n_support) / (1.0 - mu * sk)
    if f >= 0.0 and n0 + sk * f >= 0.0:
        return f
    return mu * (n_support - n0) / (1.0 + mu * sk)


def law_segments(law) -> array:
    """A MotionLaw's non-empty segments, SEGMENT_FIELDS floats each, for ``Profile``."""
    return array("d", [float(x) for seg in law.segments() for x in seg])


class Profile:
    """s(theta) and its first three derivatives for a cam program, evaluated without building objects.

    A ``CamProgram`` (two laws and dwells) is evaluated here, in the kernel; any
    other program (a user's motion table) through its own ``derivatives``.
    """

    def __init__(self, program) -> None:
        self.s = self.s1 = self.s2 = self.s3 = 0.0
        self.law_S = self.law_V = self.law_A = self.law_J = 0.0
        self.points = array("d", program.breakpoints())
        self.n_points = len(self.points)
        rise = getattr(program, "rise_law", None)
        self.laws = rise is not None
        self.program_derivatives = program.derivatives
        if not self.laws:
            self.rise = self.ret = array("d")
            self.n_rise = self.n_ret = 0
            self.b1 = self.b2 = self.b3 = self.lift = 0.0
            self.kr0 = self.kr1 = self.kr2 = self.kr3 = self.kd0 = self.kd1 = self.kd2 = self.kd3 = 0.0
            return
        self.rise = law_segments(program.rise_law)
        self.ret = law_segments(program.return_law)
        self.n_rise = len(self.rise) // SEGMENT_FIELDS
        self.n_ret = len(self.ret) // SEGMENT_FIELDS
        self.lift = program.lift
        self.b1 = program.rise_angle
        self.b2 = self.b1 + program.upper_dwell
        self.b3 = self.b2 + program.return_angle
        beta, h = program.rise_angle, program.lift
        self.kr0, self.kr1, self.kr2, self.kr3 = 1.0 / beta, h / beta, h / beta ** 2, h / beta ** 3
        beta = program.return_angle
        self.kd0, self.kd1, self.kd2, self.kd3 = 1.0 / beta, h / beta, h / beta ** 2, h / beta ** 3

    def law(self, segs, n: int, T: float) -> None:
        """(S, V, A, J) of one dimensionless law at T into law_S..law_J (MotionLaw.scalar's conventions)."""
        if T < 0.0:
            self.law_S = self.law_V = self.law_A = self.law_J = 0.0
            return
        if T > 1.0:
            self.law_S = 1.0
            self.law_V = self.law_A = self.law_J = 0.0
            return
        k = 0
        while k < n - 1 and T > segs[SEGMENT_FIELDS * k]:
            k += 1
        base = SEGMENT_FIELDS * k
        t0 = segs[base + 1]
        F = segs[base + 2]
        c = segs[base + 3]
        kind = segs[base + 4]
        V0 = segs[base + 5]
        S0 = segs[base + 6]
        u = T - t0
        if kind == SHAPE_CONST:
            self.law_S = S0 + u * (V0 + 0.5 * c * u)
            self.law_V = V0 + c * u
            self.law_A = c
            self.law_J = 0.0
            return
        x = u / F
        sx = math.sin(x)
        cx = math.cos(x)
        cF = c * F
        if kind == SHAPE_SIN:
            self.law_S = S0 + V0 * u + cF * (u - F * sx)
            self.law_V = V0 + cF * (1.0 - cx)
            self.law_A = c * sx
            self.law_J = c / F * cx
            return
        self.law_S = S0 + V0 * u + cF * F * (1.0 - cx)
        self.law_V = V0 + cF * sx
        self.law_A = c * cx
        self.law_J = -c / F * sx

    def profile(self, theta: float) -> None:
        """s [m], ds/dtheta [m/rad], d2s/dtheta2, d3s/dtheta3 at theta [rad] into s, s1, s2, s3."""
        if not self.laws:
            self.s, self.s1, self.s2, self.s3 = self.program_derivatives(theta)
            return
        th = math.fmod(theta, TWO_PI)
        if th < 0.0:
            th += TWO_PI
            if th >= TWO_PI:  # -tiny + 2 pi rounds to 2 pi
                th = 0.0
        if th <= self.b1:
            self.law(self.rise, self.n_rise, th * self.kr0)
            self.s = self.lift * self.law_S
            self.s1 = self.kr1 * self.law_V
            self.s2 = self.kr2 * self.law_A
            self.s3 = self.kr3 * self.law_J
        elif th <= self.b2:
            self.s = self.lift
            self.s1 = self.s2 = self.s3 = 0.0
        elif th <= self.b3:
            self.law(self.ret, self.n_ret, (th - self.b2) * self.kd0)
            self.s = self.lift * (1.0 - self.law_S)
            self.s1 = -self.kd1 * self.law_V
            self.s2 = -self.kd2 * self.law_A
            self.s3 = -self.kd3 * self.law_J
        else:
            self.s = self.s1 = self.s2 = self.s3 = 0.0

    def derivatives(self, theta: float) -> tuple:
        """(s, ds/dtheta, d2s/dtheta2, d3s/dtheta3) at theta [rad], as a tuple (for Python callers)."""
        self.profile(theta)
        return self.s, self.s1, self.s2, self.s3

    def first_breakpoint(self, start: float, end: float) -> float:
        """The first breakpoint angle [rad] strictly between start and end, or NaN (none)."""
        best = 0.0
        if end > start:
            best = math.inf
            for k in range(self.n_points):
                p = self.points[k]
                angle = p + math.ceil((start - p) / TWO_PI) * TWO_PI
                if angle <= start:
                    angle += TWO_PI
                if angle < best:
                    best = angle
            return best if best < end else math.nan
        if end < start:
            best = -math.inf
            for k in range(self.n_points):
                p = self.points[k]
                angle = p + math.floor((start - p) / TWO_PI) * TWO_PI
                if angle >= start:
                    angle -= TWO_PI
                if angle > best:
                    best = angle
            return best if best > end else math.nan
        return math.nan
