"""A follower of another kind (translating flat face, oscillating roller or flat face) as the motor sees it at one
cam angle: the inertia, the load's static torque and its stiffness (docs/model.md 16, docs/control.md).

The formulas are the kind's own (physics.kind_drive.KindDriveModel): the follower's coordinate q = s or psi, its
inertia I_f = m or J_arm + m L^2, its potential V(q). At an angle theta the cam side carries

    J_c(theta) = J_0 + I_f q'^2           (J_0 = J_cam with a compliant shaft, J_m + J_cam with a rigid one)
    M_g(theta) = dV/dtheta = V'(q) q'     the gravity torque that holds the cam at rest
    k_g(theta) = d2V/dtheta2 = V''(q) q'^2 + V'(q) q''   gravity's stiffness about that rest

The maps and linear models of control/ are analysis, not runs: they take a compliant shaft (k_shaft > 0) with any
follower type, the two-mass system of docs/model.md 12.3 with the kind's J_c(theta), although the engines run the
other types with a rigid shaft only so far (physics/rules.py). The kind's model is built with a rigid shaft; the
shaft's k_shaft, d_shaft, J_m and J_cam are kept beside it.

A follower train (k_train on a translating flat, k_train_arm on an arm; docs/model.md 14.6) is carried as the engine
carries it, in the law's lift units along s: its force F_train pulls the cam by F_train s' on every kind, and its end
mass m_end (J_end (lift_angle / lift)^2 for an arm) moves along s. Its weight F_ex along s (a flat's) joins gravity.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from ..physics.follower_kind import FollowerKind
from ..physics.kind_drive import KindDriveModel
from ..physics.parameters import ParameterError, resolve
from ..physics.train import Train

__all__ = ["KindView", "kind_view"]


@dataclass(frozen=True)
class KindView:
    """The kind's drive model (rigid shaft) and the shaft it sits on (SI units)."""

    model: KindDriveModel
    k_shaft: float  # N m/rad, 0: rigid
    d_shaft: float  # N m s/rad
    J_m: float  # kg m2, the rotor
    J_cam: float  # kg m2, the cam and its shaft

    @property
    def compliant(self) -> bool:
        """Is there a torsional spring between the rotor and the cam?"""
        return self.k_shaft > 0.0

    def cam_side(self, theta: float) -> float:
        """J_c [kg m2] at theta [rad]: what turns with the cam, the follower reflected (module doc)."""
        q1 = self.model.coordinate(theta)[1]
        return (self.J_cam if self.compliant else self.model.J_0) + self.model.I_f * q1 * q1

    def low_frequency_inertia(self, theta: float) -> float:
        """J_c + m_end s'^2 [kg m2] at theta [rad]: the cam side with a train's end mass carried along (its
        low-frequency limit; J_end psi'^2 for an arm's), J_c without a train."""
        train = self.train
        if train is None:
            return self.cam_side(theta)
        s1 = self.model.program.derivatives(theta)[1]
        return self.cam_side(theta) + train.m_end * s1 * s1

    def gravity_torque(self, theta: float) -> float:
        """M_g = V'(q) q' - F_ex s' [N m] at theta [rad]: the follower's weight, and a train's end mass's (held by
        the train's spring), as a torque on the cam."""
        q, q1, _, _ = self.model.coordinate(theta)
        s1 = self.model.program.derivatives(theta)[1]
        return self.model.potential_slope(q) * q1 - self.train_weight() * s1

    def gravity_stiffness(self, theta: float) -> float:
        """k_g = V''(q) q'^2 + V'(q) q'' - F_ex s'' [N m/rad] at theta [rad]: d M_g / d theta."""
        q, q1, q2, _ = self.model.coordinate(theta)
        s2 = self.model.program.derivatives(theta)[2]
        return self.model.potential_curvature(q) * q1 * q1 + self.model.potential_slope(q) * q2 \
            - self.train_weight() * s2

    @property
    def train(self) -> Train | None:
        """The follower train in the law's lift units along s (an arm's torsional one scaled by (lift_angle /
        lift)^2, physics.kind_drive), None without one: its force F pulls the cam by F s' whatever the kind."""
        return self.model.train if self.model.train.active else None

    def train_weight(self) -> float:
        """F_ex [N]: the train's end mass's weight along s (a translating flat's; 0 for an arm's torsional train and
        without a train: DriveModel.train_weight)."""
        return self.model.train_weight()


def kind_view(params: Mapping[str, Any] | None) -> KindView | None:
    """The view of ``params``' follower type; None for the translating roller (physics.drive.DriveModel's own
    formulas). A compliant shaft is taken apart from the kind's model (module doc); it needs J_cam > 0 as the
    roller's does."""
    p = resolve(params)
    kind = FollowerKind.from_parameters(p)
    if kind.default:
        return None
    k_shaft = float(p["k_shaft"])
    if k_shaft > 0.0 and not p["J_cam"] > 0.0:
        raise ParameterError(f"parameter 'J_cam' = {p['J_cam']!r} [kg.m2]: a compliant shaft (k_shaft = {k_shaft!r} "
                             f"N.m/rad) needs the inertia of its cam side; allowed with k_shaft > 0: J_cam in "
                             f"(0, 100] kg.m2")
    model = KindDriveModel(dict(p, k_shaft=0.0), kind)
    return KindView(model, k_shaft, float(p["d_shaft"]), float(p["J_m"]), float(p["J_cam"]))
