"""The drive with a follower of another kind: a translating flat face, or an arm with a roller or a flat face
(docs/model.md 16).

One degree of freedom, the cam angle theta, as the translating roller's (closure 'kinematic': the follower stays on
the cam). The follower's coordinate is q = s (translating) or q = psi = lift_angle s / h (an arm), its inertia
I_f = m (translating) or J_A = J_arm + m L^2 (an arm, L = arm_length), its potential V(q):

    translating:  V = -F_gx s                                    (the translating roller's gravity, 4.1)
    arm:          V = W sin(psi + psi_0),  W = (G L + m_arm g_n r_cm_arm) sin(gamma)   (gravity on, else 0)

The force (or an arm's torque about its pivot) that moves the follower, before friction, is
P = I_f (q'' omega^2 + q' omega_dot) + dV/dq, and the load torque on the cam

    M = M_f sgn(omega) + P q' + mu |P| lambda(theta) sgn(omega)

with the friction's lever lambda >= 0 where it acts (``mu`` with the guide-friction effect on):
translating flat face: the face slides on the cam at r_b + s from its axis, lambda = r_b + s (the guide is taken
frictionless: it carries the face's friction sideways and does no work); oscillating flat face: the face slides on
the cam, which lies p = d sin(delta) from the face's line, the normal force N = P / l at l = d cos(delta) / (1 - psi')
from the pivot, lambda = p / l = tan(delta) (1 - psi') (the friction along the face passes through the pivot: no
torque on the arm); oscillating roller: the roller rolls, the pivot carries a Coulomb torque mu |P| against the arm's
turn, lambda = |psi'|. The friction's power mu |P| lambda |omega| is the loss. Lagrange's equation with
J(theta) = J_0 + I_f q'^2 gives omega_dot; |P| depends on omega_dot, solved exactly on the branch sgn(P) (held between
the side events of the reference, as the guide's N_r). A translating flat carries the follower train's force F_train
(``axial`` [N], docs/model.md 14.6) along s: it adds to P, so to the friction mu |P| lambda; an arm's train is
torsional (k_train_arm, d_train_arm, J_end), carried in the law's lift units along s as the engine does (k_train =
k_train_arm scale^2, ..., its force along s over scale the torque joining the arm's P); k_train on an arm is refused
naming follower_type. Plain functions of floats, as physics/drive.py.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

from ..kinematics.follower_checks import refuse_unbuildable
from ..kinematics.follower_types import make_cam
from .drive import DriveModel, LoadState, effective_clearance, follower_mass, sign
from .follower_kind import FollowerKind
from .train import Train
from .parameters import KGF, ParameterError, mounting_component, resolve

__all__ = ["KindDriveModel", "KindLoad"]

LOCKING_GRID = 3600  # angles over a turn where the flat face's wedging is tested
G_N = KGF  # m/s2, standard gravity (the arm's own weight m_arm g_n; the follower's is the parameter G)


@dataclass
class KindLoad(LoadState):
    """LoadState with the kind's friction loss [W] and its driving force P [N, or N m about an arm's pivot]."""

    loss: float = 0.0
    P: float = 0.0
    lever: float = 0.0  # lambda [m, or 1 for an arm]
    speed: float = 0.0  # |omega| [rad/s]


class KindDriveModel(DriveModel):
    """DriveModel whose follower is ``kind`` (not the translating roller: that is DriveModel itself)."""

    def __init__(self, params: Mapping[str, Any] | None, kind: FollowerKind) -> None:
        if kind.default:
            raise ValueError("the translating roller is DriveModel itself")
        p = resolve(params)
        # The roller's self-locking test (its guide, its pressure angle) is not this follower's: built without
        # guide friction, the kind's own friction set after (its own test below).
        super().__init__({**p, "guide_friction": False})
        self.params = p
        self.mu = p["mu"] if p["guide_friction"] else 0.0
        self.kind = kind
        self._refuse(p)
        m = follower_mass(p)
        gravity = p["gravity"]
        if kind.oscillating:
            L = kind.arm_length
            self._scale = kind.lift_angle / self.program.lift  # psi^(k) = scale s^(k)
            self.I_f = (kind.J_arm if p["follower_inertia"] else 0.0) + m * L * L
            gamma = p["gamma"]
            in_plane = mounting_component(math.sin(gamma), gamma)
            self.W = ((p["G"] * L + kind.m_arm * G_N * kind.r_cm_arm) * in_plane) if gravity else 0.0
        else:
            self._scale = 1.0
            self.I_f = m
            self.W = 0.0
        if p.get("k_train_arm", 0.0) > 0.0:   # an arm's torsional train in the law's lift units along s (14.6)
            k2 = self._scale * self._scale
            self.train = Train(p["k_train_arm"] * k2, p["d_train_arm"] * k2, p["J_end"] * k2, torsional=True)
        self.follower = self.I_f != 0.0 or self.F_gx != 0.0 or self.W != 0.0 or self.mu != 0.0
        if kind.follower_type == "oscillating_flat":
            self._delta0 = math.asin(min(1.0, self.r_b / kind.pivot_distance))
        try:
            self.cam = make_cam(self.program, self.r_b, kind.follower_type,
                                r_roller=0.0 if kind.follower_type == "oscillating_roller" else None,
                                arm_length=kind.arm_length, pivot_distance=kind.pivot_distance,
                                lift_angle=kind.lift_angle)
            refuse_unbuildable(self.cam)
        except ValueError as exc:
            raise ParameterError(f"follower_type {kind.follower_type!r} with 'r_b' = {self.r_b!r} m: {exc}") from None
        self._check_locking()

    def _refuse(self, p: Mapping[str, Any]) -> None:
        kind = self.kind.follower_type
        refused = [name for name, on in (("'c' (clearance)", effective_clearance(p) != 0.0 and not self.free_follower),
                                         ("'k_shaft' (compliant shaft)", self.compliant),
                                         ) if on]
        if p.get("k_train", 0.0) > 0.0:
            self.refuse_train()
        if refused:
            raise ParameterError(f"follower_type {kind!r} runs with the follower on the cam or as a body of its own "
                                 f"(closure 'spring', or 'form' with a clearance and a mass m > 0; docs/model.md "
                                 f"16.3) and a rigid shaft so far: parameters "
                                 f"{', '.join(refused)} must be off")
        if self.kind.oscillating and p["gravity"] and p["beta"] != 0.0:
            raise ParameterError(f"parameter 'beta' = {p['beta']!r} rad is not used by follower_type {kind!r} "
                                 f"(the arm's angle to gravity is its psi_0): leave it at 0")

    def refuse_train(self) -> None:
        """Refuse the follower train along X (k_train) on an arm: an arm's is torsional (k_train_arm, ...)."""
        if self.kind.oscillating:
            raise ParameterError(f"the follower train ('k_train' > 0) does not run with follower_type "
                                 f"{self.kind.follower_type!r}: an arm's train is torsional (k_train_arm, "
                                 f"d_train_arm, J_end); allowed follower_type 'translating_roller' or "
                                 f"'translating_flat'")

    # ----------------------------------------------------------- the kind's terms
    def coordinate(self, theta: float) -> tuple[float, float, float, float]:
        """(q, q', q'', s) at theta: q = s [m] translating, psi [rad] for an arm; s the law's lift [m]."""
        s, s1, s2, _ = self.program.derivatives(theta)
        k = self._scale
        return k * s, k * s1, k * s2, s

    def potential_slope(self, q: float) -> float:
        """dV/dq [N, or N m for an arm]: -F_gx translating, W cos(psi + psi_0) for an arm."""
        if self.kind.oscillating:
            return self.W * math.cos(q + self.kind.psi_0) if self.W else 0.0
        return -self.F_gx

    def potential_curvature(self, q: float) -> float:
        """d2V/dq2 [N/m, or N m/rad for an arm]: 0 translating (V linear in s), -W sin(psi + psi_0) for an arm."""
        if self.kind.oscillating:
            return -self.W * math.sin(q + self.kind.psi_0) if self.W else 0.0
        return 0.0

    def potential(self, theta: float) -> float:
        """V [J] at theta (0 at zero lift for an arm level with psi_0 = 0)."""
        q, _, _, s = self.coordinate(theta)
        if self.kind.oscillating:
            return self.W * math.sin(q + self.kind.psi_0)
        return -self.F_gx * s

    def lever(self, q: float, q1: float, s: float) -> float:
        """lambda >= 0 [m, or 1 for an arm] at q, q', s: the friction torque on the cam per |P| (module doc)."""
        kind = self.kind.follower_type
        if kind == "translating_flat":
            return self.r_b + s
        if kind == "oscillating_flat":
            return math.tan(self._delta0 + q) * (1.0 - q1)
        return abs(q1)

    def _check_locking(self) -> None:
        """Refuse a flat face that friction would wedge: J_0 + I_f q' (q' -+ mu lambda) <= 0 somewhere."""
        if self.mu == 0.0 or self.I_f == 0.0:
            return
        worst, at = math.inf, 0.0
        for k in range(LOCKING_GRID + 1):  # every 0.1 deg
            theta = 2.0 * math.pi * k / LOCKING_GRID
            q, q1, _, s = self.coordinate(theta)
            value = self.J_0 + self.I_f * (q1 * q1 - abs(q1) * self.mu * self.lever(q, q1, s))
            if value < worst:
                worst, at = value, theta
        if worst <= 0.0:
            raise ParameterError(f"parameters 'mu' = {self.mu!r} and 'r_b' = {self.r_b!r} m wedge the "
                                 f"{self.kind.follower_type} follower by its friction at theta = "
                                 f"{math.degrees(at):.4g} deg (J_0 + I_f q' (q' - mu lambda) = {worst:.4g} kg m2 "
                                 f"<= 0): allowed where it stays > 0 (lower mu or add inertia J_cam)")

    def _terms(self, theta: float, omega: float, axial: float = 0.0) -> tuple[float, float, float]:
        """(A, q', lambda): P = A + I_f q' omega_dot; ``axial`` [N]: the train's force along q, in A."""
        q, q1, q2, s = self.coordinate(theta)
        A = self.I_f * q2 * omega * omega + self.potential_slope(q) + axial / self._scale
        return A, q1, self.lever(q, q1, s) if self.mu else 0.0

    def _branch(self, A: float, q1: float, lam: float, drive: float, direction: float,
                side: float) -> tuple[float, float]:
        """(omega_dot, P) on the branch sgn(P) = side (0: the branch that holds)."""
        I_f, J_0 = self.I_f, self.J_0
        b = side if side else (-1.0 if A * J_0 + I_f * q1 * drive < 0.0 else 1.0)
        k = q1 + self.mu * lam * direction * b
        den = J_0 + I_f * q1 * k
        if den <= 0.0:
            raise ParameterError(f"the {self.kind.follower_type} follower wedges by its friction: parameter 'mu' = "
                                 f"{self.mu!r} too large here (J_0 + I_f q' (q' + mu lambda) = {den:.4g} kg m2)")
        omega_dot = (drive - A * k) / den
        return omega_dot, A + I_f * q1 * omega_dot

    # ----------------------------------------------------------- DriveModel's mechanics, for this kind
    def omega_dot(self, theta: float, omega: float, torque: float, direction: float, engaged: bool = True,
                  side: float = 0.0, axial: float = 0.0) -> float:
        """Angular acceleration [rad/s2]: J(theta) omega_dot = c_m i - M_f d - (A + mu |P| lambda d) ... solved on
        the branch of sgn(P) (module doc); ``side`` fixes that branch (+1/-1), 0 chooses it. ``axial`` [N]: the
        follower train's force on a translating flat along s (docs/model.md 14.6), a part of P."""
        drive = torque - self.M_f * direction
        if not (self.follower or axial):
            return drive / self.J_0
        A, q1, lam = self._terms(theta, omega, axial)
        return self._branch(A, q1, lam, drive, direction, side)[0]

    def side_force(self, theta: float, omega: float, torque: float, direction: float, side: float = 0.0,
                   axial: float = 0.0) -> float:
        """P [N, or N m] on the branch ``side``: its sign change is the friction's kink (the side event);
        ``axial`` [N] the train's force in P."""
        if self.mu == 0.0 or not self.follower:
            return 0.0
        A, q1, lam = self._terms(theta, omega, axial)
        return self._branch(A, q1, lam, torque - self.M_f * direction, direction, side)[1]

    def follower_friction_power(self, theta: float, omega: float, drive: float, direction: float, side: float,
                                axial: float = 0.0) -> float:
        """The kind's friction power [W] on the branch ``side`` held, mu side P lambda d omega (= mu |P| lambda
        |omega| while side = sgn(P), d = sgn(omega); smooth through the stop), ``drive`` = T - M_f d [N m]."""
        if self.mu == 0.0 or not self.follower:
            return 0.0
        A, q1, lam = self._terms(theta, omega, axial)
        P = self._branch(A, q1, lam, drive, direction, side)[1]
        return self.mu * side * P * lam * direction * omega

    def load(self, theta: float, omega: float, omega_dot: float, direction: float, engaged: bool = True,
             axial: float = 0.0) -> KindLoad:
        """Load torque, inertia and motion for a known omega_dot (module doc). ``N`` is the contact's normal force
        [N]: along X on a translating face, P / l on an oscillating face, the pivot torque over L cos(alpha) on a
        roller arm; alpha the roller arm's pressure angle (0 for a flat face). ``axial`` [N]: the train's force
        on a translating flat along s, a part of P (so of its friction mu |P| lambda)."""
        q, q1, q2, s = self.coordinate(theta)
        s1, s2 = q1 / self._scale, q2 / self._scale
        I_f, kind = self.I_f, self.kind
        P = I_f * (q2 * omega * omega + q1 * omega_dot) + self.potential_slope(q) + axial / self._scale
        lam = self.lever(q, q1, s) if self.mu else 0.0
        friction = self.mu * abs(P) * lam  # N m on the cam, against its turn
        M = self.M_f * direction + P * q1 + friction * direction
        J = self.J_0 + I_f * q1 * q1
        alpha, N = 0.0, P
        if kind.follower_type == "oscillating_roller":
            alpha = float(self.cam.pressure_angle(theta))
            N = (P + self.mu * abs(P) * sign(q1 * direction)) / (kind.arm_length * math.cos(alpha))
        elif kind.follower_type == "oscillating_flat":
            N = P * (1.0 - q1) / (kind.pivot_distance * math.cos(self._delta0 + q))
        return KindLoad(omega_dot, M, J, self.mu * abs(N), s1 * omega, s2 * omega * omega + s1 * omega_dot, alpha,
                        s, N, loss=friction * abs(omega), P=P, lever=lam, speed=abs(omega))

    def friction_power(self, load: LoadState, side: float = 0.0) -> float:
        """The follower's friction loss mu |P| lambda |omega| [W] (module doc); with ``side`` (+1/-1, the branch the
        integrator holds between side events) mu side P lambda |omega|: the power of the friction torque the drive
        equation applies, which stays smooth through the located zero of P (|P| has a kink there that an integrator
        step would cross before the event stops it)."""
        if side:
            return self.mu * side * load.P * load.lever * load.speed
        return load.loss

    def energy(self, theta: float, omega: float, i: float, engaged: bool = True) -> float:
        """Stored energy [J]: (1/2) (J_0 + I_f q'^2) omega^2 + V + (1/2) L i^2."""
        q1 = self.coordinate(theta)[1]
        return 0.5 * (self.J_0 + self.I_f * q1 * q1) * omega * omega + self.potential(theta) + 0.5 * self.L * i * i
