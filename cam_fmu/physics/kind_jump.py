"""A spring-closed follower of another kind at constant speed: where and at what cam speed it leaves the cam, and the
spring that holds it (docs/model.md 16; the translating roller's is physics/follower.py).

The follower's coordinate q = s (translating flat face) or psi (an arm), its inertia I_f = m or J_arm + m L^2
(physics.kind_drive.KindDriveModel). The return spring acts along the roller's path, at arm_length L for an arm, so
the closing force (translating) or torque about the pivot (an arm) is

    translating flat face:  C(theta) = F0 + k s - F_gx                              [N]
    arm:                    C(theta) = L (F0 + k L psi) + W cos(psi + psi_0)         [N m]

(F0 = F_spring0, k = k_spring; the arm's weight torque W cos(psi + psi_0), kind_drive's dV/dpsi). In contact at
constant speed omega the cam supplies I_f q'' omega^2 + C; contact is lost where that reaches 0 while q'' < 0:

    omega_jump = min over q'' < 0 of sqrt(C / (I_f |q''|))

A flat face's friction and an arm's pivot friction act with the contact's force (kind_drive: mu |P| lambda) and
vanish with it: they do not move the jump. C = a F0 + b k + c with a = 1 or L, b = s or L^2 psi and c = -F_gx or
W cos(psi + psi_0): the preload and the rate that hold a target speed follow from it, and every force this module
reports is C / a, the force along the roller's path (an arm's torque over L).
"""
from __future__ import annotations

import math
from typing import Any, Mapping

from .follower import Jump, minimise_over_turn
from .follower_kind import FollowerKind
from .kind_drive import KindDriveModel
from .parameters import resolve
from .rules import check_rules

__all__ = ["KindSpring"]


class KindSpring:
    """The spring-closed follower of ``params`` (follower_type other than the translating roller, closure 'spring'):
    the kind's model with the follower on the cam, and the spring (module doc)."""

    def __init__(self, params: Mapping[str, Any]) -> None:
        p = resolve(params)
        kind = FollowerKind.from_parameters(p)
        if kind.default:
            raise ValueError("the translating roller's jump is physics/follower.py's")
        check_rules(p)   # the spring's and the kind's rules: both engines fly every type (docs/model.md 16.3)
        self.k, self.F0 = float(p["k_spring"]), float(p["F_spring0"])
        self.model = KindDriveModel(dict(p, closure="kinematic", k_spring=0.0, F_spring0=0.0, restitution=0.0),
                                    kind)
        self.kind = kind
        self.a = kind.arm_length if kind.oscillating else 1.0

    @property
    def program(self):
        """The cam program (its breakpoints bound the smooth pieces searched)."""
        return self.model.program

    def parts(self, theta: float) -> tuple[float, float, float, float]:
        """(b, c, q'', s) at theta [rad]: C = a F0 + b k + c (module doc), q'' [m/rad2 or rad/rad2], s the lift [m]."""
        q, _, q2, s = self.model.coordinate(theta)
        if self.kind.oscillating:
            return self.a * self.a * q, self.model.potential_slope(q), q2, s
        return s, -self.model.F_gx, q2, s

    def closing(self, theta: float, F0: float | None = None, k: float | None = None) -> float:
        """C / a [N] at theta [rad]: the closing force along the roller's path (the spring's F0, k unless given)."""
        b, c, _, _ = self.parts(theta)
        F0 = self.F0 if F0 is None else F0
        k = self.k if k is None else k
        return (self.a * F0 + b * k + c) / self.a

    def need(self, theta: float, omega: float) -> float:
        """I_f max(-q'', 0) omega^2 / a [N] at theta [rad]: the force along the path the deceleration needs."""
        return self.model.I_f * max(-self.parts(theta)[2], 0.0) * omega * omega / self.a

    def jump(self) -> Jump:
        """omega_jump [rad/s] and where (module doc); Jump.s is the lift s [m] there, Jump.s2 the coordinate's q''."""
        breaks = self.program.breakpoints()
        weakest, theta_w = minimise_over_turn(self.closing, breaks)
        stroke = self.a * self.kind.lift_angle if self.kind.oscillating else self.program.lift  # m, the largest b / a
        scale = abs(self.F0) + abs(self.k) * stroke + abs(self.model.F_gx) + abs(self.model.W) / self.a
        if weakest < -1e-12 * scale:  # below the rounding of C / a at a stroke's end
            _, _, q2, s = self.parts(theta_w)
            return Jump(0.0, theta_w, s, q2, f"the closing force along the roller's path is {weakest:.6g} N < 0 at "
                                             f"theta = {theta_w:.6g} rad: the follower is not held even at rest")
        if self.model.I_f == 0.0:
            return Jump(math.inf, math.nan, math.nan, math.nan, "a follower without inertia needs no force: it "
                                                                "never jumps")

        def ratio(theta: float) -> float:  # (rad/s)^2 at which the contact force reaches 0 at theta
            q2 = self.parts(theta)[2]
            if q2 >= 0.0:
                return math.inf
            return self.a * self.closing(theta) / (self.model.I_f * -q2)

        value, theta = minimise_over_turn(ratio, breaks)
        if not math.isfinite(value):
            return Jump(math.inf, math.nan, math.nan, math.nan, "q'' >= 0 everywhere: the cam never has to pull")
        _, _, q2, s = self.parts(theta)
        what = "torque L (F0 + k L psi) (and the arm's weight)" if self.kind.oscillating else "force F0 + k s - F_gx"
        return Jump(math.sqrt(value), theta, s, q2, f"contact is first lost where the spring's {what} equals the "
                                                    f"inertial I_f |q''| omega^2")

    def margin(self, omega: float) -> tuple[float, float]:
        """(least contact force along the roller's path [N], theta [rad]) over a turn at omega [rad/s]:
        C / a + I_f q'' omega^2 / a; negative, the follower leaves the cam."""
        def force(theta: float) -> float:
            return self.closing(theta) + self.model.I_f * self.parts(theta)[2] * omega * omega / self.a

        return minimise_over_turn(force, self.program.breakpoints())

    def preload_for(self, omega: float, safety: float, k: float | None = None) -> tuple[float, float]:
        """(least F_spring0 [N], theta [rad] that sets it) holding omega [rad/s] with the force safety factor
        ``safety`` at the rate k [N/m] (default the spring's; C / a >= S need everywhere, physics.follower.preload_for's
        rule)."""
        value, theta = minimise_over_turn(
            lambda x: -(safety * self.need(x, omega) - self.closing(x, F0=0.0, k=k)), self.program.breakpoints())
        return -value, theta

    def rate_for(self, omega: float, safety: float) -> tuple[float, float]:
        """(least k_spring [N/m], theta [rad] that sets it) holding omega [rad/s] with the safety factor at the
        preload F0; inf where no rate can (an angle where the spring's lift term b <= 0 falls short)."""
        def need(theta: float) -> float:
            short = safety * self.need(theta, omega) - self.closing(theta, k=0.0)
            if short <= 0.0:
                return 0.0
            b = self.parts(theta)[0] / self.a
            return -short / b if b > 0.0 else -math.inf

        value, theta = minimise_over_turn(need, self.program.breakpoints())
        return -value, theta

