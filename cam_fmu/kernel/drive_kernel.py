# cython: language_level=3, annotation_typing=False, boundscheck=False, wraparound=False, cdivision=True, cpow=True, initializedcheck=False
"""The cam drive's hot path: profile, right-hand side, Dormand-Prince steps, events and breakpoints.

Plain Python with ``math`` only: the run-time engine's own copy of the
formulas of ``physics.drive.DriveModel`` (profile, omega_dot, side force, load,
guide friction) and ``physics.energy.EnergyBudget``, in the same order of
operations, so the scipy reference (which integrates ``physics``) checks a
second implementation. It imports the event names and constants from
``physics``, never the reverse. ``compile.py`` compiles this file with
the C types of ``drive_kernel.pxd`` (Cython, pure-Python mode). Compiled and
pure-Python runs execute the same IEEE operations in the same order: they agree
to the last bit (tests/test_kernel_build.py).

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

from ..physics.energy import RELATIVE_SLACK
from ..physics.formulations.consistent import EVENT_NAMES, SIDE_HYSTERESIS
from ..physics.variables import OUTPUT_NAMES

# Constants spelled out: compiled, ``math`` here is C's libc math (the .pxd), which has no pi, inf or nan.
TWO_PI = 2.0 * 3.141592653589793  # 2 pi, math.pi being that double
SHAPE_CONST, SHAPE_SIN, SHAPE_COS = 0, 1, 2  # as kinematics.motion_law (tests/test_architecture.py checks)
INF, NAN = float("inf"), float("nan")
SEGMENT_FIELDS = 7  # end, start, F, c, kind, V0, S0 per non-empty law segment


def solve_guide_friction(n0: float, kappa: float, sigma: float, mu: float, n_support: float,
                         side: float = 0.0) -> float:
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
        self.evaluations = 0  # of the profile, counted: a switched-off follower must cost none in the dynamics
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
        self.evaluations += 1
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
        return first_angle_crossed(self.points, self.n_points, start, end)


def first_angle_crossed(points, n: int, start: float, end: float) -> float:
    """The first of the periodic angles points[:n] (each in [0, 2 pi)) strictly between start and end [rad],
    in the direction of travel, or NaN (none); its cost does not grow with |end - start|."""
    best = 0.0
    if end > start:
        best = INF
        for k in range(n):
            p = points[k]
            angle = p + math.ceil((start - p) / TWO_PI) * TWO_PI
            if angle <= start:
                angle += TWO_PI
            if angle < best:
                best = angle
        return best if best < end else NAN
    if end < start:
        best = -INF
        for k in range(n):
            p = points[k]
            angle = p + math.floor((start - p) / TWO_PI) * TWO_PI
            if angle >= start:
                angle -= TWO_PI
            if angle > best:
                best = angle
        return best if best > end else NAN
    return NAN


# Positions of the outputs in an output buffer (physics.variables.OUTPUTS order).
O_OMEGA, O_THETA, O_S, O_I, O_M, O_J, O_V, O_A, O_ALPHA, O_S_CAM, O_VOLTAGE = (
    OUTPUT_NAMES.index(name) for name in ("omega", "theta", "s", "i", "M", "J", "v", "a", "alpha", "s_cam",
                                          "voltage"))
N_OUTPUTS = len(OUTPUT_NAMES)

# Dormand-Prince 5(4) tableau (Hairer, Norsett, Wanner, Solving ODE I, table 5.2).
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = 9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0  # B2 = 0
E1, E3, E4, E5, E6, E7 = (71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0,
                          -1.0 / 40.0)  # b5 - b4 (E2 = 0)

# Event codes; EVENT_NAMES[code] is the formulation's name for it (physics.formulations.consistent).
STOP, CONTACT, ENGAGE_UP, ENGAGE_DOWN, BREAK_AWAY, SIDE = (
    EVENT_NAMES.index(name) for name in ("stop", "contact", "engage_up", "engage_down", "break_away", "side_force"))
# N [N]: the side-force event's hysteresis (physics.formulations.consistent.SIDE_HYSTERESIS says why).
_HYSTERESIS = SIDE_HYSTERESIS  # the compiled module's C copy (a cdef global is not a Python attribute)
EVENT_ITERATIONS = 60  # Illinois iterations at most per located zero


class DriveKernel(Profile):
    """The consistent drive under a voltage u: right-hand side, events, and its rk45 integration.

    Parameters are a DriveModel's (SI units, effects switched off already zero).
    The state ``y0, y1, y2`` is (theta [rad], omega [rad/s], i [A]; i unused with
    L = 0) and the mode ``stuck, direction, contact, s_free, side`` that of
    ``physics.formulations.consistent.Mode``. ``apply_event(code, u)`` and
    ``settle_python(u)`` are the formulation's transitions (rare: events and rest).
    """

    def __init__(self, program, J_m: float, m: float, M_f: float, F_gx: float, G_y: float, N_g: float,
                 mu: float, r_b: float, c: float, R: float, L: float, c_e: float, c_m: float) -> None:
        Profile.__init__(self, program)
        self.J_m, self.m, self.M_f, self.F_gx, self.G_y, self.N_g = J_m, m, M_f, F_gx, G_y, N_g
        self.mu, self.r_b, self.c, self.R, self.L, self.c_e, self.c_m = mu, r_b, c, R, L, c_e, c_m
        self.follower = m != 0.0 or F_gx != 0.0 or mu != 0.0
        self.has_current = L > 0.0
        self.backlash = c > 0.0
        self.guide_side = mu > 0.0 and self.follower
        self.size = 3 if self.has_current else 2
        self.y0 = self.y1 = self.y2 = 0.0
        self.stuck = False
        self.direction = 1.0
        self.contact = 1
        self.s_free = 0.0
        self.side = 1.0
        # load terms (set by load_terms): frictionless acceleration x0 and the guide's friction terms
        self.x0 = self.J = self.sigma = self.f = self.n0 = self.kappa = 0.0
        self.load_M = self.load_J = self.load_f = self.load_v = self.load_a = self.load_alpha = self.load_s = 0.0
        self.d0 = self.d1 = self.d2 = 0.0  # derivative written by rhs
        # integrator state
        self.h_next = self.h_max = self.rtol = self.atol = 0.0
        self.max_steps = self.steps = 0
        self.k1_valid = False
        self.k1_0 = self.k1_1 = self.k1_2 = 0.0  # f(y)
        self.z0 = self.z1 = self.z2 = 0.0  # dopri_step: y5
        self.e0 = self.e1 = self.e2 = 0.0  # dopri_step: error estimate
        self.k7_0 = self.k7_1 = self.k7_2 = 0.0  # dopri_step: f(y5)
        self.n0_ = self.n1_ = self.n2_ = 0.0  # the step's end state
        self.kn0 = self.kn1 = self.kn2 = 0.0  # f at the step's end
        self.hi0 = self.hi1 = self.hi2 = 0.0  # locate: the state just past the zero
        self.fsal_u = 0.0
        self.before = array("d", [0.0, 0.0, 0.0])
        self.after = array("d", [0.0, 0.0, 0.0])
        self.codes = array("i", [0, 0, 0])
        self.n_events = 0
        self.hit = 0  # code of the event first_event found
        self.have_before = False
        self.saved = array("d", [0.0] * 8)  # snapshot(): y, mode
        self.apply_event = None  # callable(code, u): the formulation's transition, in Python
        self.settle_python = None  # callable(u): the formulation's settle at rest, in Python
        self.fail = None  # callable(kind, time, value): raises the formulation's error

    # ------------------------------------------------------------ physics
    def load_terms(self, theta: float, omega: float, drive: float, direction: float, side: float) -> None:
        """x0 = the frictionless omega_dot [rad/s2]; with guide friction J, sigma, f, n0, kappa too."""
        self.profile(theta)
        s = self.s
        s1 = self.s1
        m = self.m
        J = self.J_m + m * s1 * s1
        inertial = m * self.s2 * omega * omega - self.F_gx  # N, axial force of the profile's curvature and gravity
        self.J = J
        self.x0 = (drive - inertial * s1) / J
        if self.mu == 0.0:
            return
        v_sign = s1 * direction
        self.sigma = 1.0 if v_sign > 0.0 else (-1.0 if v_sign < 0.0 else 0.0)
        tan_a = s1 / (self.r_b + s)
        self.n0 = (inertial + m * s1 * self.x0) * tan_a + self.G_y
        self.kappa = self.J_m / J * tan_a
        self.f = solve_guide_friction(self.n0, self.kappa, self.sigma, self.mu, self.N_g, side)

    def omega_dot(self, theta: float, omega: float, torque: float, direction: float, engaged: bool,
                  side: float) -> float:
        """Angular acceleration [rad/s2] of the consistent formulation (docs/model.md section 5).

        ``torque`` c_m i [N m]; ``direction`` sgn(omega) or the trial direction at
        rest; ``engaged`` False: the follower is free in the gap (J = J_m, no
        load); ``side`` +1/-1 holds the guide's friction branch, 0 chooses it.
        """
        drive = torque - self.M_f * direction
        if not (engaged and self.follower):
            return drive / self.J_m
        self.load_terms(theta, omega, drive, direction, side)
        if self.mu == 0.0:
            return self.x0
        return self.x0 - self.sigma * self.f * self.s1 / self.J

    def side_force(self, theta: float, omega: float, torque: float, direction: float, side: float) -> float:
        """The guide's side force N_r [N] while engaged and moving (0 without guide friction)."""
        if self.mu == 0.0 or not self.follower:
            return 0.0
        self.load_terms(theta, omega, torque - self.M_f * direction, direction, side)
        return self.n0 + self.sigma * self.kappa * self.f

    def torque(self, omega: float, i: float, u: float) -> float:
        """Motor torque [N m]: c_m i, or with L = 0 the quasi-static c_m (u - c_e omega) / R."""
        if self.has_current:
            return self.c_m * i
        return self.c_m * (u - self.c_e * omega) / self.R

    def rhs(self, theta: float, omega: float, i: float, u: float) -> None:
        """dy/dt at (theta, omega, i) under u and the mode, into d0, d1, d2."""
        if self.stuck:
            self.d0 = 0.0
            self.d1 = 0.0
        else:
            self.d0 = omega
            self.d1 = self.omega_dot(theta, omega, self.torque(omega, i, u), self.direction, self.contact != 0,
                                     self.side if self.guide_side else 0.0)
        self.d2 = (u - self.R * i - self.c_e * omega) / self.L if self.has_current else 0.0

    def choose_side(self, u: float) -> None:
        """The friction branch of the current state (where N_r = 0, the one it moves into)."""
        if self.guide_side and self.contact != 0 and not self.stuck:
            n_r = self.side_force(self.y0, self.y1, self.torque(self.y1, self.y2, u), self.direction, 0.0)
            if abs(n_r) > _HYSTERESIS:
                self.side = -1.0 if n_r < 0.0 else 1.0

    def settle(self, u: float) -> None:
        """At the start of a step: a moving shaft only re-chooses its friction branch; at rest, the formulation decides."""
        if not self.stuck and self.y1 != 0.0:
            self.choose_side(u)
        else:
            self.settle_python(u)

    def breakaway_margin(self, theta: float, i: float, u: float) -> float:
        """> 0 when the shaft would start moving from rest [rad/s2]."""
        torque = self.torque(0.0, i, u)
        engaged = self.contact != 0
        forward = self.omega_dot(theta, 0.0, torque, 1.0, engaged, 0.0)
        backward = -self.omega_dot(theta, 0.0, torque, -1.0, engaged, 0.0)
        return backward if backward > forward else forward

    def load(self, theta: float, omega: float, omega_dot: float, direction: float, engaged: bool) -> None:
        """Load torque, inertia and follower motion for a known omega_dot [rad/s2], into the
        attributes load_M [N m] (M_f sgn(omega) + M_l), load_J [kg m2], load_f [N, guide friction],
        load_v [m/s], load_a [m/s2], load_alpha [rad, pressure angle], load_s [m, cam lift]."""
        self.profile(theta)
        s = self.s
        s1 = self.s1
        tan_a = s1 / (self.r_b + s)
        shaft = self.M_f * direction
        self.load_alpha = math.atan(tan_a)
        self.load_s = s
        if not engaged:
            self.load_M, self.load_J, self.load_f, self.load_v, self.load_a = shaft, self.J_m, 0.0, 0.0, 0.0
            return
        v = s1 * omega
        a = self.s2 * omega * omega + s1 * omega_dot
        v_sign = s1 * direction
        sigma = 1.0 if v_sign > 0.0 else (-1.0 if v_sign < 0.0 else 0.0)
        push = self.m * a - self.F_gx  # N, axial force without friction
        f = solve_guide_friction(push * tan_a + self.G_y, tan_a, sigma, self.mu, self.N_g, 0.0)
        self.load_M = shaft + (push + sigma * f) * s1
        self.load_J = self.J_m + self.m * s1 * s1
        self.load_f, self.load_v, self.load_a = f, v, a

    def outputs(self, u: float, omega_dot: float, known: bool, out) -> None:
        """Every output at the state, in physics.variables.OUTPUTS order, into the buffer ``out``.

        ``known``: ``omega_dot`` [rad/s2] is the acceleration at the state already
        (rk45's last stage), else it is computed.
        """
        theta, omega = self.y0, self.y1
        i = self.y2 if self.has_current else (u - self.c_e * omega) / self.R
        engaged = self.contact != 0
        if self.stuck:
            self.load(theta, 0.0, 0.0, 0.0, engaged)
            self.load_M = self.c_m * i  # static friction takes whatever the motor applies
            self.load_v = self.load_a = 0.0
        else:
            if not known:
                self.rhs(theta, omega, self.y2, u)
                omega_dot = self.d1
            self.load(theta, omega, omega_dot, self.direction, engaged)
        out[O_OMEGA] = omega
        out[O_THETA] = theta
        out[O_S] = self.load_s - self.c * self.contact if engaged else self.s_free
        out[O_I] = i
        out[O_M] = self.load_M
        out[O_J] = self.load_J
        out[O_V] = self.load_v
        out[O_A] = self.load_a
        out[O_ALPHA] = self.load_alpha
        out[O_S_CAM] = self.load_s
        out[O_VOLTAGE] = u

    def publishable(self, out, budget, u: float, h: float) -> int:
        """Check the outputs of a step of h [s] under u [V] before they are published (the energy budget,
        if any, books the step): 0 fine, 1 an output is not finite, 2 the follower is beyond the
        clearance c from the cam (a contact event was missed), 3 the state holds more energy than the
        source delivered."""
        total = 0.0
        for k in range(N_OUTPUTS):
            total += out[k]
        if not math.isfinite(total):
            return 1
        if abs(out[O_S] - out[O_S_CAM]) > self.c * (1.0 + 1e-9) + 1e-12:
            return 2
        if budget is not None:
            budget.step(u, h, out[O_THETA], out[O_I])
            if budget.surplus(out[O_OMEGA], out[O_S], out[O_J], out[O_I]) > 0.0:
                return 3
        return 0

    # ------------------------------------------------------------ events
    def event_codes(self) -> int:
        """The active events into ``codes``; returns how many."""
        n = 0
        if self.stuck:
            if self.has_current:
                self.codes[0] = BREAK_AWAY
                n = 1
        elif self.backlash and self.contact == 0:
            self.codes[0] = STOP
            self.codes[1] = ENGAGE_UP
            self.codes[2] = ENGAGE_DOWN
            n = 3
        else:
            self.codes[0] = STOP
            n = 1
            if self.backlash:
                self.codes[n] = CONTACT
                n += 1
            if self.guide_side:
                self.codes[n] = SIDE
                n += 1
        self.n_events = n
        return n

    def event_value(self, code: int, theta: float, omega: float, i: float, u: float) -> float:
        """Value of event ``code`` at the state (> 0: nothing happens)."""
        if code == STOP:
            return omega * self.direction
        if code == SIDE:
            return self.side * self.side_force(theta, omega, self.torque(omega, i, u), self.direction,
                                               self.side) + _HYSTERESIS
        if code == BREAK_AWAY:
            return -self.breakaway_margin(theta, i, u)
        self.profile(theta)
        if code == ENGAGE_UP:
            return self.s_free - (self.s - self.c)
        if code == ENGAGE_DOWN:
            return (self.s + self.c) - self.s_free
        return self.contact * self.s1 * self.direction  # CONTACT: s1 times the direction held

    def snapshot(self) -> None:
        """Keep the state and mode, for ``rollback`` (a rejected step leaves the state as before it)."""
        saved = self.saved
        saved[0], saved[1], saved[2] = self.y0, self.y1, self.y2
        saved[3] = 1.0 if self.stuck else 0.0
        saved[4], saved[5], saved[6], saved[7] = self.direction, self.contact, self.s_free, self.side

    def rollback(self) -> None:
        """Back to the state and mode of the last ``snapshot``; rk45's stored derivative is dropped."""
        saved = self.saved
        self.y0, self.y1, self.y2 = saved[0], saved[1], saved[2]
        self.stuck = saved[3] != 0.0
        self.direction, self.contact, self.s_free, self.side = saved[4], int(saved[5]), saved[6], saved[7]
        self.k1_valid = False

    # ------------------------------------------------------------ integration
    def dopri_step(self, h: float, u: float) -> None:
        """One Dormand-Prince 5(4) step of size h [s] from y (k1 = f(y) valid): y5 into z, error into e, f(y5) into k7."""
        y0, y1, y2 = self.y0, self.y1, self.y2
        p1_0, p1_1, p1_2 = self.k1_0, self.k1_1, self.k1_2
        self.rhs(y0 + h * A21 * p1_0, y1 + h * A21 * p1_1, y2 + h * A21 * p1_2, u)
        p2_0, p2_1, p2_2 = self.d0, self.d1, self.d2
        self.rhs(y0 + h * (A31 * p1_0 + A32 * p2_0), y1 + h * (A31 * p1_1 + A32 * p2_1),
                 y2 + h * (A31 * p1_2 + A32 * p2_2), u)
        p3_0, p3_1, p3_2 = self.d0, self.d1, self.d2
        self.rhs(y0 + h * (A41 * p1_0 + A42 * p2_0 + A43 * p3_0), y1 + h * (A41 * p1_1 + A42 * p2_1 + A43 * p3_1),
                 y2 + h * (A41 * p1_2 + A42 * p2_2 + A43 * p3_2), u)
        p4_0, p4_1, p4_2 = self.d0, self.d1, self.d2
        self.rhs(y0 + h * (A51 * p1_0 + A52 * p2_0 + A53 * p3_0 + A54 * p4_0),
                 y1 + h * (A51 * p1_1 + A52 * p2_1 + A53 * p3_1 + A54 * p4_1),
                 y2 + h * (A51 * p1_2 + A52 * p2_2 + A53 * p3_2 + A54 * p4_2), u)
        p5_0, p5_1, p5_2 = self.d0, self.d1, self.d2
        self.rhs(y0 + h * (A61 * p1_0 + A62 * p2_0 + A63 * p3_0 + A64 * p4_0 + A65 * p5_0),
                 y1 + h * (A61 * p1_1 + A62 * p2_1 + A63 * p3_1 + A64 * p4_1 + A65 * p5_1),
                 y2 + h * (A61 * p1_2 + A62 * p2_2 + A63 * p3_2 + A64 * p4_2 + A65 * p5_2), u)
        p6_0, p6_1, p6_2 = self.d0, self.d1, self.d2
        # B2 is 0; the seventh stage is evaluated at y5 itself (first same as last).
        self.z0 = y0 + h * (B1 * p1_0 + B3 * p3_0 + B4 * p4_0 + B5 * p5_0 + B6 * p6_0)
        self.z1 = y1 + h * (B1 * p1_1 + B3 * p3_1 + B4 * p4_1 + B5 * p5_1 + B6 * p6_1)
        self.z2 = y2 + h * (B1 * p1_2 + B3 * p3_2 + B4 * p4_2 + B5 * p5_2 + B6 * p6_2)
        self.rhs(self.z0, self.z1, self.z2, u)
        self.k7_0, self.k7_1, self.k7_2 = self.d0, self.d1, self.d2
        self.e0 = h * (E1 * p1_0 + E3 * p3_0 + E4 * p4_0 + E5 * p5_0 + E6 * p6_0 + E7 * self.d0)
        self.e1 = h * (E1 * p1_1 + E3 * p3_1 + E4 * p4_1 + E5 * p5_1 + E6 * p6_1 + E7 * self.d1)
        self.e2 = h * (E1 * p1_2 + E3 * p3_2 + E4 * p4_2 + E5 * p5_2 + E6 * p6_2 + E7 * self.d2)

    def ensure_k1(self, u: float) -> None:
        """k1 = f(y) unless it is valid already."""
        if not self.k1_valid:
            self.rhs(self.y0, self.y1, self.y2, u)
            self.k1_0, self.k1_1, self.k1_2 = self.d0, self.d1, self.d2
            self.k1_valid = True

    def attempt(self, u: float, remaining: float, time: float, span: float) -> float:
        """One accepted rk45 step: its length dt [s]; the end state in n*, f there in kn*.

        Error control on rtol, atol; theta's error is scaled by at most 2 pi (it
        enters the physics mod 2 pi, so its accuracy does not decay over many
        turns). The smallest step is 1e-12 of ``span``, the communication step:
        below it the step is rejected (``fail``: StepRejected, fmi2Discard).
        """
        dt = self.h_next
        if remaining < dt:
            dt = remaining
        if self.h_max < dt:
            dt = self.h_max
        floor = 1e-12 * span
        atol, rtol = self.atol, self.rtol
        self.ensure_k1(u)
        while True:
            self.dopri_step(dt, u)
            scale = abs(self.z0) if abs(self.z0) > abs(self.y0) else abs(self.y0)
            if TWO_PI < scale:
                scale = TWO_PI
            total = (self.e0 / (atol + rtol * scale)) ** 2
            scale = abs(self.z1) if abs(self.z1) > abs(self.y1) else abs(self.y1)
            total += (self.e1 / (atol + rtol * scale)) ** 2
            if self.size == 3:
                scale = abs(self.z2) if abs(self.z2) > abs(self.y2) else abs(self.y2)
                total += (self.e2 / (atol + rtol * scale)) ** 2
            norm = math.sqrt(total / self.size)
            if norm <= 1.0:
                factor = 5.0 if norm == 0.0 else min(5.0, 0.9 * norm ** -0.2)
                if dt < remaining or factor < 1.0:
                    self.h_next = min(dt * factor, 1e3)
                else:
                    self.h_next = max(self.h_next, dt * min(factor, 1.0))
                self.n0_, self.n1_, self.n2_ = self.z0, self.z1, self.z2
                self.kn0, self.kn1, self.kn2 = self.k7_0, self.k7_1, self.k7_2
                return dt
            if not math.isfinite(norm):
                norm = 1e10
            dt *= max(0.1, 0.9 * norm ** -0.2)
            if dt < floor:
                self.fail(0, time, floor)
                return dt

    def trial(self, tau: float, u: float) -> None:
        """The state tau [s] into the current step, into z (moving: a dopri step; stuck: exact)."""
        if self.stuck:
            self.z0, self.z1, self.z2 = self.y0, 0.0, self.current_at_rest(tau, u)
        else:
            self.dopri_step(tau, u)

    def current_at_rest(self, dt: float, u: float) -> float:
        """i [A] after dt [s] with the shaft held: exact approach to u / R (L > 0)."""
        target = u / self.R
        return target + (self.y2 - target) * math.exp(-dt * self.R / self.L)

    def zero_value(self, code: int, target: float, theta: float, omega: float, i: float, u: float) -> float:
        """The function locate() drives to zero: event ``code``, or (code -1) the gap to the breakpoint target."""
        if code < 0:
            return self.direction * (target - theta)
        return self.event_value(code, theta, omega, i, u)

    def locate(self, code: int, target: float, g_lo: float, g_hi: float, dt: float, u: float) -> float:
        """Illinois false position for the zero in (0, dt] [s]; the state just past it (g <= 0) into hi*.

        hi* must hold the state at dt on entry.
        """
        lo, hi = 0.0, dt
        side = 0
        for _ in range(EVENT_ITERATIONS):
            if hi - lo <= 1e-13 * max(dt, 1e-300) + 1e-15:
                break
            tau = hi - g_hi * (hi - lo) / (g_hi - g_lo) if g_hi != g_lo else 0.5 * (lo + hi)
            if not lo < tau < hi:
                tau = 0.5 * (lo + hi)
            self.trial(tau, u)
            g_tau = self.zero_value(code, target, self.z0, self.z1, self.z2, u)
            if g_tau <= 0.0:
                hi, g_hi = tau, g_tau
                self.hi0, self.hi1, self.hi2 = self.z0, self.z1, self.z2
                if side == -1:
                    g_lo *= 0.5
                side = -1
            else:
                lo, g_lo = tau, g_tau
                if side == 1:
                    g_hi *= 0.5
                side = 1
        return hi

    def first_event(self, dt: float, u: float) -> float:
        """Earliest event in (0, dt] of the step from y to n*: its time from the step start [s], with its code
        in ``hit`` and the state there in hi*; or -1.0 (none).

        A function already at or below zero at the step's start is decided by where it
        goes: into the event (g1 < 0, or it started below zero) fires it at once; away
        from it (g1 > 0 from exactly 0) does not. A zero at the start is never lost.
        """
        n = self.n_events
        if not self.have_before:
            for k in range(n):
                self.before[k] = self.event_value(self.codes[k], self.y0, self.y1, self.y2, u)
        self.have_before = False
        if n == 0:
            return -1.0
        for k in range(n):
            self.after[k] = self.event_value(self.codes[k], self.n0_, self.n1_, self.n2_, u)
        for k in range(n):
            if self.before[k] < 0.0 or (self.before[k] == 0.0 and self.after[k] < 0.0):
                self.hit = self.codes[k]
                self.hi0, self.hi1, self.hi2 = self.y0, self.y1, self.y2
                return 0.0
        best = -1.0
        b0 = b1 = b2 = 0.0
        for k in range(n):
            if self.before[k] > 0.0 and self.after[k] <= 0.0:
                self.hi0, self.hi1, self.hi2 = self.n0_, self.n1_, self.n2_
                tau = self.locate(self.codes[k], 0.0, self.before[k], self.after[k], dt, u)
                if best < 0.0 or tau < best:
                    best = tau
                    self.hit = self.codes[k]
                    b0, b1, b2 = self.hi0, self.hi1, self.hi2
        if best < 0.0:
            for k in range(n):
                self.before[k] = self.after[k]
            self.have_before = True  # the next step starts where this one ended
            return -1.0
        self.hi0, self.hi1, self.hi2 = b0, b1, b2
        return best

    def advance(self, u: float, h: float, time: float) -> int:
        """Advance the state by one communication step h [s] under u [V]; returns the internal steps taken.

        Every step ends at the profile breakpoint it would cross and at the located
        zero of the first event; the event's transition is the formulation's
        (``apply_event``). More than ``max_steps`` steps is an error (``fail``).
        """
        t = 0.0
        steps = 0
        was_stuck = self.stuck
        self.have_before = False
        self.settle(u)
        if not (self.k1_valid and self.fsal_u == u and not was_stuck):
            self.k1_valid = False
        self.event_codes()
        while h - t > 1e-12 * h:
            if self.stuck and not self.has_current:
                break  # nothing evolves until the input changes
            steps += 1
            if steps > self.max_steps:
                self.fail(1, time + t, h)
            remaining = h - t
            next_valid = False  # does kn* hold f at the step's end?
            if self.stuck:
                dt = remaining
                self.n0_, self.n1_, self.n2_ = self.y0, 0.0, self.current_at_rest(dt, u)
            else:
                dt = self.attempt(u, remaining, time + t, h)
                next_valid = True
                target = self.first_breakpoint(self.y0, self.n0_)
                if target == target:  # not NaN: the step crosses a breakpoint and ends just past it
                    self.hi0, self.hi1, self.hi2 = self.n0_, self.n1_, self.n2_
                    cut = self.locate(-1, target, self.direction * (target - self.y0),
                                      self.direction * (target - self.n0_), dt, u)
                    if cut != dt:  # its first-same-as-last derivative belonged to the longer step
                        dt = cut
                        self.n0_, self.n1_, self.n2_ = self.hi0, self.hi1, self.hi2
                        next_valid = False
            tau = self.first_event(dt, u)
            if tau < 0.0:
                self.y0, self.y1, self.y2 = self.n0_, self.n1_, self.n2_
                t += dt
                self.k1_valid = next_valid
                if next_valid:
                    self.k1_0, self.k1_1, self.k1_2 = self.kn0, self.kn1, self.kn2
                continue
            self.y0, self.y1, self.y2 = self.hi0, self.hi1, self.hi2
            t += tau
            self.k1_valid = False
            self.apply_event(self.hit, u)
            self.event_codes()
            self.have_before = False
        if self.stuck:
            self.k1_valid = False
        self.fsal_u = u
        return steps

    def advance_checked(self, u: float, h: float, time: float, out, budget) -> int:
        """A whole communication step in one call: ``snapshot``, ``advance`` (its step count into
        ``steps``), the outputs into ``out`` and ``publishable``'s verdict on them (0: publish)."""
        self.snapshot()
        self.steps = self.advance(u, h, time)
        self.outputs(u, self.k1_1, self.k1_valid and not self.stuck, out)  # advance's k1 is f at its end
        return self.publishable(out, budget, u, h)


# Relative slack of the bound (physics.energy.RELATIVE_SLACK says why).
_SLACK = RELATIVE_SLACK  # the compiled module's C copy


class EnergyBudget:
    """Tracks W_in and the bound for one drive (SI units): the engine's copy of physics.energy.EnergyBudget."""

    def __init__(self, model, theta: float, omega: float, i: float, s: float, J: float) -> None:
        self.c_e, self.L, self.R, self.F_gx = model.c_e, model.L, model.R, model.F_gx
        self.ratio = model.c_m / model.c_e
        self.work_in = 0.0  # J, electrical work delivered by the source
        self.work_abs = 0.0  # J, sum of |u int i dt|: the scale of the bookkeeping
        self.theta, self.i = theta, i
        self.e_mech0 = self._mech(omega, s, J)
        self.e_mag0 = 0.5 * self.L * i * i

    def _mech(self, omega: float, s: float, J: float) -> float:
        return 0.5 * J * omega * omega - self.F_gx * s

    def step(self, u: float, h: float, theta: float, i: float) -> None:
        """Account for one communication step of length h [s] under u [V] ending at theta, i."""
        w = u * (u * h - self.c_e * (theta - self.theta) - self.L * (i - self.i)) / self.R
        self.work_in += w
        self.work_abs += abs(w)
        self.theta, self.i = theta, i

    def to_dict(self) -> dict:
        return {"work_in": self.work_in, "work_abs": self.work_abs, "theta": self.theta, "i": self.i,
                "e_mech0": self.e_mech0, "e_mag0": self.e_mag0}

    def restore(self, state: dict) -> None:
        for key in ("work_in", "work_abs", "theta", "i", "e_mech0", "e_mag0"):
            setattr(self, key, float(state[key]))

    def surplus(self, omega: float, s: float, J: float, i: float) -> float:
        """Energy above the bound, less the tolerance [J]: > 0 means energy was created."""
        excess, tolerance = self.excess(omega, s, J, i)
        return excess - tolerance

    def excess(self, omega: float, s: float, J: float, i: float) -> tuple:
        """(energy above the bound [J], the tolerance [J]) at the current state."""
        e_mech = self._mech(omega, s, J)
        e_mag = 0.5 * self.L * i * i
        lhs = (e_mech - self.e_mech0) + self.ratio * (e_mag - self.e_mag0)
        rhs = self.ratio * self.work_in
        scale = abs(self.e_mech0) + abs(e_mech) + self.ratio * (self.work_abs + self.e_mag0 + e_mag) + 1e-12
        return lhs - rhs, _SLACK * scale
