"""A follower train on the follower of its own in the voltage drive (docs/model.md 14.6, 13.6).

``voltage_follower.VoltageFollower`` with the train's end mass (``physics.train.Train``) as two more states after the
drive's, y = (theta, omega, i, s, v, [phi, omega_m,] x_e, v_e). The train's force F_train = k_train (s - x_e) +
d_train (v - v_e) acts between the follower (its own s, v) and the end mass, m_end dv_e/dt = F_train + F_ex (F_ex
the end mass's weight along X, train.end_weight), so the follower's closing force is F_close(s) + F_train: on its
flank (s the flank's, v = s' omega, 0 on a stuck cam) in the drive equation, the contact force P, the guide's side
force and the break-away rule, and in flight (m s_dd = -F_close(s) - F_train - sgn(v) f0). ``math`` only, written
independently of the C engine.

The base class's equations that take no state (``on_flank``, ``static_force``, ``free_acceleration``, ``direction``)
read the end mass's state bound by the last call that took one (``bind``): every method given y binds it first.
"""
from __future__ import annotations

from .train import Train, end_weight
from .voltage_follower import VoltageFollower

__all__ = ["TrainVoltageFollower"]


class TrainVoltageFollower(VoltageFollower):
    """The follower of its own on a voltage-driven cam carrying the train (``model.train``, k_train > 0)."""

    def __init__(self, model, train: Train | None = None) -> None:
        super().__init__(model)
        self.train = model.train if train is None else train
        self.F_ex = end_weight(self.train, model.params)   # N, the end mass's weight along X
        self.X_E = self.size          # index of x_e in y, v_e after it
        self.size += 2
        self._end = (0.0, 0.0)        # (x_e [m], v_e [m/s]) bound by ``bind``
        self._v = 0.0                 # m/s, the flying follower's velocity bound with it

    def bind(self, y) -> None:
        """Take the end mass's state (and the follower's v) from y for the equations that take no state."""
        self._end = (y[self.X_E], y[self.X_E + 1])
        self._v = y[4]

    def pull(self, s: float, v: float) -> float:
        """N, F_train with the follower at s [m] moving at v [m/s] and the bound end mass."""
        return self.train.force(s, v, *self._end)

    def rest(self, s: float, v: float) -> tuple[float, float]:
        """(x_e [m], v_e [m/s]): the end mass at rest relative to the follower at s [m], v [m/s], its weight on the
        train's spring."""
        return s + self.F_ex / self.train.k_train, v

    # ------------------------------------------------------------- the closing force with the train's
    def flank_closing(self, s: float, v: float) -> float:
        return self.closing(s) + self.pull(s, v)

    def free_acceleration(self, s: float, sigma: float) -> float:
        """m/s2, the flying follower's acceleration with the train's force (the bound v in its damper)."""
        net = -self.closing(s) - self.pull(s, self._v)
        if sigma == 0.0:
            if abs(net) <= self.f0:
                return 0.0
            sigma = 1.0 if net > 0.0 else -1.0
        return (net - sigma * self.f0) / self.m

    def net_at_rest(self, s: float) -> float:
        """N, the force on the flying follower at rest at s [m] (the train's included), against F_close."""
        return -self.closing(s) - self.pull(s, 0.0)

    def direction(self, s: float, v: float) -> float:
        if v != 0.0:
            return 1.0 if v > 0.0 else -1.0
        net = self.net_at_rest(s)
        return (1.0 if net > 0.0 else -1.0) if abs(net) > self.f0 else 0.0

    # ------------------------------------------------------------- the follower's motion and the end mass's rates
    def motion(self, y, contact: float) -> tuple[float, float]:
        """(s [m], v [m/s]) of the follower the train hangs on: on a flank the flank's (v 0 on a stuck cam), in flight
        its own state."""
        if contact:
            s, s1, _, _ = self.flank(y[0], contact)
            return s, (0.0 if self.heading == 0.0 else s1 * y[1])
        return y[3], y[4]

    def train_force(self, y, contact: float) -> float:
        """N, F_train at y with the follower on the flank ``contact`` (0: in flight)."""
        self.bind(y)
        return self.pull(*self.motion(y, contact))

    def train_damping(self, y, contact: float) -> float:
        """W, the train damper's loss d_train (v - v_e)^2."""
        slip = self.motion(y, contact)[1] - y[self.X_E + 1]
        return self.train.d_train * slip * slip

    # ------------------------------------------------------------- the base class's entries, bound first
    def start(self, y, u: float, contact: float) -> tuple[float, float]:
        self.bind(y)
        return super().start(y, u, contact)

    def rates(self, y, u: float, contact: float, sigma: float = 0.0) -> list[float]:
        self.bind(y)
        dy = super().rates(y, u, contact, sigma)
        F = self.train_force(y, contact)
        return dy + [y[self.X_E + 1], (F + self.F_ex) / self.train.m_end]

    def friction_power(self, y, u: float, contact: float, sigma: float) -> float:
        self.bind(y)
        return super().friction_power(y, u, contact, sigma)

    def side_force(self, y, u: float, contact: float) -> float:
        self.bind(y)
        return super().side_force(y, u, contact)

    def contact_force(self, y, u: float, contact: float = 1.0) -> float:
        self.bind(y)
        return super().contact_force(y, u, contact)

    def acceleration_scale(self, y, u: float) -> float:
        self.bind(y)
        return super().acceleration_scale(y, u)

    def land(self, y, u: float, contact: float = 1.0):
        self.bind(y)
        return super().land(y, u, contact)

    def stored_energy(self, y) -> float:
        """J, the drive's stored energy with the end mass's m_end v_e^2 / 2, the train's k_train (s - x_e)^2 / 2 and
        the end mass's weight -F_ex x_e."""
        x_e, v_e = y[self.X_E], y[self.X_E + 1]
        stretch = y[3] - x_e
        return (super().stored_energy(y) + 0.5 * self.train.m_end * v_e * v_e
                + 0.5 * self.train.k_train * stretch * stretch - self.F_ex * x_e)

    def outputs(self, y, u: float, contact: float) -> dict[str, float]:
        """The follower's outputs with the train's s_end, v_end [m, m/s], a_end [m/s2] and F_train [N]."""
        self.bind(y)
        record = super().outputs(y, u, contact)
        F = self.train_force(y, contact)
        record.update(s_end=float(y[self.X_E]), v_end=float(y[self.X_E + 1]),
                      a_end=(F + self.F_ex) / self.train.m_end, F_train=F)
        return record
