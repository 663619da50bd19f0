"""The follower train on a follower of its own of another kind, in both drives (docs/model.md 14.6, 16.3).

The kind's body (physics.kind_follower: the state's slots hold its coordinate q_f = scale s and rate) with the
train's end mass after the drive's states (physics.train_follower). The train stays in the law's lift units along s,
as the C engine carries it: F_train = k_train (q_f / scale - x_e) + d_train (q_f' / scale - v_e), and its force along
q is F_train / scale (1 on a translating flat; an arm's torsional train, k_train = k_train_arm scale^2, gives the
torque k_train_arm (psi - psi_e) + d_train_arm (psi' - psi_e')). It joins the closing force Q_close on a flank (so
the contact's P and its friction) and in flight. ``math`` only, written from docs/model.md (not from the C engine).
"""
from __future__ import annotations

from .kind_follower import KindSpeedFollower, KindVoltageFollower
from .train import Train
from .train_follower import TrainSpeedFollower, TrainVoltageFollower

__all__ = ["KindTrainSpeedFollower", "KindTrainVoltageFollower"]


class KindTrainBody:
    """What the kind changes in the train's carriage: the lift units per q and the flying stiffness along q."""

    def _per_q(self) -> None:
        self.lift_per_q = 1.0 / self.scale

    def flight_stiffness(self) -> float:
        """The flying follower's stiffness along q [N/m, or N m/rad]: the spring at l (k_spring l^2) and the train's
        k_train / scale^2."""
        return max(self.k, 0.0) * self.l * self.l + self.train.k_train * self.lift_per_q * self.lift_per_q


class KindTrainVoltageFollower(KindTrainBody, TrainVoltageFollower, KindVoltageFollower):
    """The voltage drive's follower of its own of another kind carrying the train: y = (theta, omega, i, q_f,
    q_f', x_e, v_e)."""

    def __init__(self, model, train: Train | None = None) -> None:
        super().__init__(model, train)
        self._per_q()


class KindTrainSpeedFollower(KindTrainBody, TrainSpeedFollower, KindSpeedFollower):
    """The speed drive's follower of its own of another kind carrying the train: y = (theta, q_f, q_f', x_e, v_e)."""

    held = KindSpeedFollower.held   # the kind's P on the flank (the train's pull in its flank_closing)

    def __init__(self, model, train: Train | None = None) -> None:
        super().__init__(model, train)
        self._per_q()
