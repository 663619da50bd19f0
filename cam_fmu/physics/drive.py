"""Physics of the cam drive: follower forces, load torque, inertia, motor.

Plain functions of plain floats (``math`` only): the readable model that the
scipy reference integrates, independent of the run-time engine's code (which
keeps its own copy of these formulas). Equations and corrections: docs/model.md
sections 3-6. Sign conventions: X is the rise direction, theta and omega are
positive in the cam's forward sense, v = ds/dt and a = d2s/dt2 are signed.

Switching an effect off sets its coefficients to zero once, at construction:
the hot path then carries no test for it (``follower`` False skips all
follower terms).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

from ..kinematics.cam_program import CamProgram, ProgramBase
from ..kinematics.motion_table import program_from_table_text
from .motor import Motor
from .parameters import ParameterError, law_spec, mounting_component, resolve
from .rules import OWN_FOLLOWER, check_rules
from .train import Train, end_weight


def sign(x: float) -> float:
    """+1, -1 or 0 (Coulomb friction's sgn, with sgn(0) = 0)."""
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


def solve_guide_friction(n0: float, kappa: float, sigma: float, mu: float, n_support: float,
                         side: float = 0.0) -> float:
    """Guide friction force f >= 0 [N] solving f = mu (|n0 + sigma kappa f| + n_support) (docs/model.md 4.2).

    The side force N_r = n0 + sigma kappa f [N] depends on f itself (through the
    contact force): solved exactly on its two linear branches instead of lagging
    f by a step. Unique because mu |kappa| < 1. ``side`` +1/-1 takes the branch
    where N_r has that sign (held between the integrators' side-force events);
    0 chooses the branch that holds: N_r >= 0 if its f is >= 0 and keeps N_r >= 0.
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


def check_self_locking(program: ProgramBase, mu: float, r_b: float) -> None:
    """Raise ParameterError when the follower would jam in its guide somewhere on the cam.

    The cam pushes the follower through a contact force inclined by the pressure
    angle alpha; the guide's friction grows with the side component N tan(alpha).
    Where mu |tan(alpha)| >= 1, no contact force can move the follower (the
    friction equation has no solution with a non-negative force): the drive
    self-locks there (docs/model.md section 4).
    """
    alpha, theta = program.max_pressure_angle(r_b)
    locking = mu * math.tan(alpha)
    if locking >= 1.0 - 1e-12:
        raise ParameterError(
            f"parameters 'mu' = {mu!r} and 'r_b' = {r_b!r} m make the follower self-lock in its guide: "
            f"mu tan(alpha) = {locking:.4g} >= 1 at theta = {math.degrees(theta):.4g} deg "
            f"(pressure angle alpha = {math.degrees(alpha):.4g} deg); allowed: mu tan(max alpha) < 1 "
            f"(lower mu below {1.0 / math.tan(alpha):.4g} or raise r_b)")


def effective_clearance(p: Mapping[str, Any]) -> float:
    """The clearance c [m] the model uses: c where the backlash effect is on, else 0 (docs/model.md 6.2)."""
    return p["c"] if p["backlash"] else 0.0


def follower_mass(p: Mapping[str, Any]) -> float:
    """The follower's mass m [kg] the model uses: m where the follower's inertia is on, else 0."""
    return p["m"] if p["follower_inertia"] else 0.0


def own_follower(p: Mapping[str, Any]) -> bool:
    """Does the follower move as a body of its own (docs/model.md 13)? Closure 'spring' always; 'form' where the
    groove has a clearance c > 0 to fly across, the follower a mass m > 0 to carry its momentum across it (without
    one no force moves it: gravity and friction scale with m), and the formulation has the follower's momentum (the
    paper's voltage-drive formulation models the clearance by its eqs. 6-8). Else 'form' is the rule of closure
    'kinematic', bit for bit. The rule is rules.OWN_FOLLOWER, from which model.c's free_follower is generated."""
    return bool(OWN_FOLLOWER.value(p))


def build_program(p: Mapping[str, Any]) -> ProgramBase:
    """The cam program the parameters describe: the user's motion table, else laws and angles.

    Raises ParameterError naming the parameters when they make no program.
    """
    if p["motion_table"].strip():
        try:
            return program_from_table_text(p["motion_table"])
        except ValueError as exc:
            raise ParameterError(f"parameter 'motion_table': {exc}") from None
    try:
        return CamProgram(law_spec(p, "rise"), law_spec(p, "return"), p["lift"],
                          p["rise_angle"], p["upper_dwell"], p["return_angle"], p["lower_dwell"])
    except ValueError as exc:
        raise ParameterError(f"parameters 'rise_law'/'rise_T1'..'rise_T6', 'return_law'/'return_T1'..'return_T6': "
                             f"{exc}") from None


@dataclass
class GuideTerms:
    """The coupled friction problem of docs/model.md 4.4 at one instant (SI units)."""

    J: float  # kg m2, equivalent inertia J_0 + m s'^2 (J_0: what turns with the cam)
    s1: float  # m/rad, ds/dtheta
    x0: float  # rad/s2, omega_dot without guide friction
    sigma: float  # sgn(v): the direction the friction opposes
    f: float  # N, guide friction force (0 without guide friction)
    n0: float  # N, side force N_r without friction: N_r = n0 + sigma kappa f
    kappa: float  # (J_0 / J) tan(alpha)


@dataclass
class LoadState:
    """Everything the drive equation produces at one instant (SI units)."""

    omega_dot: float  # rad/s2
    M: float  # N m, total load torque on the shaft: M_f sgn(omega) + M_l
    J: float  # kg m2, equivalent inertia of what turns with the cam: J_0 + m s'^2
    f: float  # N, guide friction force
    v: float  # m/s, follower velocity
    a: float  # m/s2, follower acceleration
    alpha: float  # rad, pressure angle
    s_cam: float  # m, cam lift at the contact
    N: float = 0.0  # N, the cam's normal force on the roller along the contact normal, signed along X (4.2)


class DriveModel:
    """The cam drive with one parameter set (see parameters.PARAMETERS)."""

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        p = resolve(params)
        self.params = p
        self.program = build_program(p)
        self.R = p["R"]
        self.L = p["L"] if p["inductance"] else 0.0
        self.c_e = p["c_e"]
        self.c_m = p["c_m"]
        self.motor = Motor(self.R, self.L, self.c_e, self.c_m)
        self.J_m = p["J_m"]
        # The drive-train (docs/model.md section 12): k_shaft = 0 is rigid, J_cam then adds to the rotor's
        # J_m; k_shaft > 0 puts a torsional spring-damper between the rotor J_m and the cam side J_cam.
        self.k_shaft = p["k_shaft"]
        self.d_shaft = p["d_shaft"]
        self.compliant = self.k_shaft > 0.0
        self.J_0 = p["J_cam"] if self.compliant else self.J_m + p["J_cam"]  # kg m2, turning with the cam
        self.M_f = p["M_f"] if p["shaft_friction"] else 0.0
        self.m = follower_mass(p)
        G = p["G"] if p["gravity"] else 0.0
        # Each sine and cosine of the mounting is exactly 0 where the angle makes it 0 (docs/model.md 4.1).
        gamma, beta = p["gamma"], p["beta"]
        sin_g, cos_g = mounting_component(math.sin(gamma), gamma), mounting_component(math.cos(gamma), gamma)
        sin_b, cos_b = mounting_component(math.sin(beta), beta), mounting_component(math.cos(beta), beta)
        self.F_gx = G * sin_g * cos_b  # N, gravity along X
        self.G_y = G * sin_g * sin_b  # N, gravity along Y
        self.N_g = abs(G * cos_g)  # N, guide support |N_g|
        self.mu = p["mu"] if p["guide_friction"] else 0.0
        self.r_b = p["r_b"]
        self.c = effective_clearance(p)
        self.formulation = p["formulation"]
        self.drive = p["drive"]
        # Does the follower load the shaft at all? (inertia, gravity or friction)
        self.follower = self.m != 0.0 or self.F_gx != 0.0 or self.mu != 0.0
        # The follower as a body of its own (docs/model.md section 13): 'kinematic' is the paper's rule.
        self.closure = p["closure"]
        self.k_spring, self.F_spring0, self.restitution = p["k_spring"], p["F_spring0"], p["restitution"]
        check_rules(p)  # the cross-parameter rules (rules.RULES; C's are generated from the same table)
        self.train = Train(p["k_train"], p["d_train"], p["m_end"])  # the follower train (14.6; k_train = 0: none)
        self.follower_type = p["follower_type"]  # this class computes the translating roller (others: kind_drive.py)
        self.free_follower = own_follower(p)
        if self.mu > 0.0:
            check_self_locking(self.program, self.mu, self.r_b)

    def train_weight(self) -> float:
        """F_ex [N]: the follower train's end mass's weight along X (physics.train.end_weight; 0 without a train,
        and for an arm's torsional train)."""
        return end_weight(self.train, self.params) if self.train.active else 0.0

    # ----------------------------------------------------------- mechanics
    def guide_terms(self, theta: float, omega: float, drive: float, direction: float, side: float,
                    axial: float = 0.0) -> GuideTerms:
        """The consistent equation's terms at theta [rad], omega [rad/s] (docs/model.md 4.4 and 5.1).

        ``drive`` is the shaft's torque c_m i - M_f d [N m]. Without guide friction
        the terms after x0 are 0; with it, f solves the coupling of f and omega_dot
        exactly (``solve_guide_friction`` with kappa' = (J_m / J) tan(alpha)). ``axial`` [N]: a further force on
        the follower against X that does not depend on omega_dot (the follower train's F_train, docs/model.md 14.6).
        """
        s, s1, s2, _ = self.program.derivatives(theta)
        m = self.m
        J = self.J_0 + m * s1 * s1
        inertial = m * s2 * omega * omega - self.F_gx  # N, axial force of the profile's curvature and gravity
        if axial:
            inertial += axial
        x0 = (drive - inertial * s1) / J
        if self.mu == 0.0:
            return GuideTerms(J, s1, x0, 0.0, 0.0, 0.0, 0.0)
        sigma = sign(s1 * direction)
        tan_a = s1 / (self.r_b + s)
        n0 = (inertial + m * s1 * x0) * tan_a + self.G_y
        kappa = self.J_0 / J * tan_a
        f = solve_guide_friction(n0, kappa, sigma, self.mu, self.N_g, side)
        return GuideTerms(J, s1, x0, sigma, f, n0, kappa)

    def omega_dot(self, theta: float, omega: float, torque: float, direction: float, engaged: bool = True,
                  side: float = 0.0, axial: float = 0.0) -> float:
        """Angular acceleration [rad/s2], consistent formulation (docs/model.md section 5.1).

        omega_dot = (c_m i - M_f d - (m s'' omega^2 - F_gx) s' - sigma f s') / (J_m + m s'^2).
        ``torque`` is the torque that drives the cam [N m]: the motor's c_m i, or a compliant shaft's;
        J_m reads J_0 (the inertia turning with the cam); ``direction`` is sgn(omega),
        or the trial direction of motion when omega = 0 (stiction); ``engaged``
        False means the follower is free in the backlash gap (J = J_m, no load).
        ``side`` +1/-1 fixes the sign of the guide's side force N_r (the friction
        branch, held between events so the right-hand side is smooth); 0 chooses it. ``axial`` [N]: the follower
        train's force on the follower, against X (docs/model.md 14.6).
        """
        drive = torque - self.M_f * direction
        if not (engaged and (self.follower or axial)):
            return drive / self.J_0
        g = self.guide_terms(theta, omega, drive, direction, side, axial)
        if self.mu == 0.0:
            return g.x0
        return g.x0 - g.sigma * g.f * g.s1 / g.J

    def side_force(self, theta: float, omega: float, torque: float, direction: float, side: float = 0.0,
                   axial: float = 0.0) -> float:
        """The guide's side force N_r [N] while the follower is engaged and moving (0 without guide friction);
        ``axial`` [N]: the follower train's force on the follower (docs/model.md 14.6).

        |N_r| has a kink where N_r changes sign (the friction mu |N_r| does): the
        integrators locate that zero as an event instead of stepping over it
        (docs/model.md sections 4.2 and 10).
        """
        if self.mu == 0.0 or not self.follower:
            return 0.0
        g = self.guide_terms(theta, omega, torque - self.M_f * direction, direction, side, axial)
        return g.n0 + g.sigma * g.kappa * g.f

    def follower_friction_power(self, theta: float, omega: float, drive: float, direction: float, side: float,
                                axial: float = 0.0) -> float:
        """The guide's friction power [W] on the branch ``side`` held, sigma f v (= f |v| while d = sgn(omega):
        smooth through the stop), ``drive`` = T - M_f d [N m], ``axial`` [N] the train's force."""
        g = self.guide_terms(theta, omega, drive, direction, side, axial)
        return g.sigma * g.f * (g.s1 * omega)

    def load(self, theta: float, omega: float, omega_dot: float, direction: float, engaged: bool = True,
             axial: float = 0.0) -> LoadState:
        """Load torque, inertia and follower motion for a known omega_dot [rad/s2] (docs/model.md 4.1-4.3).

        v = s' omega, a = s'' omega^2 + s' omega_dot; the guide friction with
        kappa = tan(alpha) (omega_dot given, no coupling left); M = M_f d +
        (m a - F_gx + sigma f) s' and the normal force N = (m a - F_gx + sigma f) / cos(alpha).
        Free in the gap (``engaged`` False): only M_f d and J_m, N = 0. ``axial`` [N] is a further force on the
        follower against X (the follower train's F_train, docs/model.md 14.6), added to m a - F_gx.
        """
        s, s1, s2, _ = self.program.derivatives(theta)
        tan_a = s1 / (self.r_b + s)
        shaft = self.M_f * direction
        alpha = math.atan(tan_a)
        if not engaged:
            return LoadState(omega_dot, shaft, self.J_0, 0.0, 0.0, 0.0, alpha, s)
        v = s1 * omega
        a = s2 * omega * omega + s1 * omega_dot
        sigma = sign(s1 * direction)
        push = self.m * a - self.F_gx  # N, axial force without friction
        if axial:
            push += axial
        f = solve_guide_friction(push * tan_a + self.G_y, tan_a, sigma, self.mu, self.N_g, 0.0)
        M = shaft + (push + sigma * f) * s1
        J = self.J_0 + self.m * s1 * s1
        N = (push + sigma * f) * math.sqrt(1.0 + tan_a * tan_a)  # X: N cos(alpha) = m a - F_gx + sigma f (the C bits)
        return LoadState(omega_dot, M, J, f, v, a, alpha, s, N)

    def friction_power(self, load: LoadState, side: float = 0.0) -> float:
        """The follower's friction loss [W] at ``load``: the guide's f |v| (docs/model.md 9); ``side``, the branch
        the integrator holds, is for another follower kind's (physics/kind_drive.py)."""
        return load.f * abs(load.v)

    def breakaway_direction(self, theta: float, torque: float, engaged: bool = True,
                            engaged_backward: bool | None = None) -> float:
        """Direction the shaft starts to move from rest: +1, -1, or 0 (stays stuck).

        At rest, friction opposes the motion that would start: the shaft moves
        forward only if it accelerates forward with friction against it, and so
        on. With no friction and zero net torque it stays at rest. ``engaged``:
        the follower loads the shaft going forward (and backward, unless
        ``engaged_backward`` says otherwise: with backlash the cam may move away
        from the follower in one direction only).
        """
        backward = engaged if engaged_backward is None else engaged_backward
        if self.omega_dot(theta, 0.0, torque, 1.0, engaged) > 0.0:
            return 1.0
        if self.omega_dot(theta, 0.0, torque, -1.0, backward) < 0.0:
            return -1.0
        return 0.0

    def energy(self, theta: float, omega: float, i: float, engaged: bool = True) -> float:
        """Stored energy [J] of a rigid drive: kinetic + gravity potential (along X) + magnetic."""
        s, s1, _, _ = self.program.derivatives(theta)
        J = self.J_0 + (self.m * s1 * s1 if engaged else 0.0)
        return 0.5 * J * omega * omega - self.F_gx * s + 0.5 * self.L * i * i


def break_away_voltage(model: DriveModel, theta: float = 0.0) -> float:
    """Smallest constant voltage [V] that starts the shaft from rest at ``theta``.

    With L = 0 the motor torque at rest is c_m u / R; the shaft starts once it
    beats the static resistance, found by bisection on the stiction test.
    """
    hi = 1.0
    while model.breakaway_direction(theta, model.c_m * hi / model.R) <= 0.0:
        hi *= 2.0
        if hi > 1e9:
            raise ValueError("the shaft does not start for any voltage up to 1e9 V")
    lo = 0.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if model.breakaway_direction(theta, model.c_m * mid / model.R) > 0.0:
            hi = mid
        else:
            lo = mid
    return hi
