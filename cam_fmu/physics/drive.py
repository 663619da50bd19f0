"""Physics of the cam drive: follower forces, load torque, inertia, motor.

Plain functions of plain floats (``math`` only), shared by the reference
integration, the FMU and the tests. Equations and corrections: docs/model.md
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

from ..kernel.drive_kernel import DriveKernel, solve_guide_friction
from ..kinematics.cam_program import CamProgram, ProgramBase
from ..kinematics.motion_table import program_from_table_text
from .motor import Motor
from .parameters import ParameterError, law_spec, resolve


def sign(x: float) -> float:
    """+1, -1 or 0 (Coulomb friction's sgn, with sgn(0) = 0)."""
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


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
class LoadState:
    """Everything the drive equation produces at one instant (SI units)."""

    omega_dot: float  # rad/s2
    M: float  # N m, total load torque on the shaft: M_f sgn(omega) + M_l
    J: float  # kg m2, equivalent inertia
    f: float  # N, guide friction force
    v: float  # m/s, follower velocity
    a: float  # m/s2, follower acceleration
    alpha: float  # rad, pressure angle
    s_cam: float  # m, cam lift at the contact


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
        self.M_f = p["M_f"] if p["shaft_friction"] else 0.0
        self.m = p["m"] if p["follower_inertia"] else 0.0
        G = p["G"] if p["gravity"] else 0.0
        self.F_gx = G * math.sin(p["gamma"]) * math.cos(p["beta"])  # N, gravity along X
        self.G_y = G * math.sin(p["gamma"]) * math.sin(p["beta"])  # N, gravity along Y
        self.N_g = abs(G * math.cos(p["gamma"]))  # N, guide support |N_g|
        self.mu = p["mu"] if p["guide_friction"] else 0.0
        self.r_b = p["r_b"]
        self.c = p["c"] if p["backlash"] else 0.0
        self.formulation = p["formulation"]
        self.drive = p["drive"]
        # Does the follower load the shaft at all? (inertia, gravity or friction)
        self.follower = self.m != 0.0 or self.F_gx != 0.0 or self.mu != 0.0
        if self.mu > 0.0:
            check_self_locking(self.program, self.mu, self.r_b)
        # The hot path (profile, right-hand side, rk45 with events): one object per model.
        self.kernel = DriveKernel(self.program, self.J_m, self.m, self.M_f, self.F_gx, self.G_y, self.N_g,
                                  self.mu, self.r_b, self.c, self.R, self.L, self.c_e, self.c_m)

    # ----------------------------------------------------------- mechanics
    def omega_dot(self, theta: float, omega: float, torque: float, direction: float, engaged: bool = True,
                  side: float = 0.0) -> float:
        """Angular acceleration [rad/s2], consistent formulation (docs/model.md section 5).

        ``torque`` is the motor torque c_m i [N m]; ``direction`` is sgn(omega),
        or the trial direction of motion when omega = 0 (stiction); ``engaged``
        False means the follower is free in the backlash gap (J = J_m, no load).
        ``side`` +1/-1 fixes the sign of the guide's side force N_r (the friction
        branch, held between events so the right-hand side is smooth); 0 chooses it.
        The formula is the drive kernel's (kernel/drive_kernel.py), compiled where it can be.
        """
        return self.kernel.omega_dot(theta, omega, torque, direction, engaged, side)

    def side_force(self, theta: float, omega: float, torque: float, direction: float, side: float = 0.0) -> float:
        """The guide's side force N_r [N] while the follower is engaged and moving (0 without guide friction).

        |N_r| has a kink where N_r changes sign (the friction mu |N_r| does): the
        integrators locate that zero as an event instead of stepping over it.
        """
        return self.kernel.side_force(theta, omega, torque, direction, side)

    def load(self, theta: float, omega: float, omega_dot: float, direction: float, engaged: bool = True) -> LoadState:
        """Load torque, inertia and follower motion for a known omega_dot (the kernel's formula)."""
        k = self.kernel
        k.load(theta, omega, omega_dot, direction, engaged)
        return LoadState(omega_dot, k.load_M, k.load_J, k.load_f, k.load_v, k.load_a, k.load_alpha, k.load_s)

    def breakaway_direction(self, theta: float, torque: float, engaged: bool = True) -> float:
        """Direction the shaft starts to move from rest: +1, -1, or 0 (stays stuck).

        At rest, friction opposes the motion that would start: the shaft moves
        forward only if it accelerates forward with friction against it, and so
        on. With no friction and zero net torque it stays at rest.
        """
        if self.omega_dot(theta, 0.0, torque, 1.0, engaged) > 0.0:
            return 1.0
        if self.omega_dot(theta, 0.0, torque, -1.0, engaged) < 0.0:
            return -1.0
        return 0.0

    def energy(self, theta: float, omega: float, i: float, engaged: bool = True) -> float:
        """Stored energy [J]: kinetic + gravity potential (along X) + magnetic."""
        s, s1, _, _ = self.program.derivatives(theta)
        J = self.J_m + (self.m * s1 * s1 if engaged else 0.0)
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
