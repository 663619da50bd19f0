"""A follower train on the follower of its own, in both drives (docs/model.md 14.6, 13.6, 13).

The train's end mass (``physics.train.Train``) is two more states after the drive's: y = (theta, omega, i, s, v,
[phi, omega_m,] x_e, v_e) in the voltage drive (``TrainVoltageFollower``), y = (theta, s, v, x_e, v_e) at imposed
speed (``TrainSpeedFollower``). The train's force F_train = k_train (s - x_e) + d_train (v - v_e) acts between the
follower (its own s, v) and the end mass, m_end dv_e/dt = F_train + F_ex (F_ex the end mass's weight along X,
train.end_weight), so the follower's closing force is F_close(s) + F_train: on its flank (s the flank's, v = s' omega,
0 on a stuck cam) in the drive equation, the contact force P, the guide's side force and the break-away rule, and in
flight (m s_dd = -F_close(s) - F_train - sgn(v) f0). ``math`` only, written independently of the C engine.

The base classes' equations that take no state (``on_flank``, ``static_force``, ``free_acceleration``, ``direction``)
read the end mass's state bound by the last call that took one (``bind``): every method given y binds it first.
"""
from __future__ import annotations

from .follower import contact_sign
from .speed_follower import SpeedFollower
from .train import Train, end_weight
from .voltage_follower import VoltageFollower

__all__ = ["TrainSpeedFollower", "TrainVoltageFollower"]


class TrainCarrier:
    """What a follower of its own carrying the train adds to its drive's follower, whichever the drive: the bound end
    mass and the train's force in the closing force. ``V``: the follower's v in y; ``X_E``: x_e's, v_e after it."""

    V = 4
    lift_per_q = 1.0   # the law's lift units (the train's) per unit of the body's coordinate: 1 / scale on an arm

    def _carry(self, model, train: Train | None) -> None:
        self.train = model.train if train is None else train
        self.F_ex = end_weight(self.train, model.params)   # N, the end mass's weight along X
        self._end = (0.0, 0.0)        # (x_e [m], v_e [m/s]) bound by ``bind``
        self._v = 0.0                 # m/s, the flying follower's velocity bound with it

    def bind(self, y) -> None:
        """Take the end mass's state (and the follower's v) from y for the equations that take no state."""
        self._end = (y[self.X_E], y[self.X_E + 1])
        self._v = y[self.V]

    def pull(self, s: float, v: float) -> float:
        """N, F_train with the follower at s [m] moving at v [m/s] and the bound end mass."""
        return self.train.force(s, v, *self._end)

    def along(self, s: float, v: float) -> float:
        """The train's force along the body's coordinate at s, v in it (the bound end mass): F_train itself on a
        translating follower, F_train / scale about an arm's pivot (its torque, N m)."""
        k = self.lift_per_q
        return self.pull(s * k, v * k) * k

    def rest(self, s: float, v: float) -> tuple[float, float]:
        """(x_e [m], v_e [m/s]): the end mass at rest relative to the follower at s, v (the body's coordinate and
        rate), its weight on the train's spring."""
        k = self.lift_per_q
        return s * k + self.F_ex / self.train.k_train, v * k

    def flight_stiffness(self) -> float:
        """The flying follower's stiffness along its coordinate [N/m]: the return spring's and the train's."""
        return max(self.k, 0.0) + self.train.k_train

    def end_rates(self, F: float, y) -> list[float]:
        """(x_e', v_e') under the train's force F [N] and the end mass's weight."""
        return [y[self.X_E + 1], (F + self.F_ex) / self.train.m_end]

    def end_outputs(self, y, F: float) -> dict[str, float]:
        """The train's outputs s_end, v_end [m, m/s], a_end [m/s2] and F_train [N] at y under the force F [N]."""
        return dict(s_end=float(y[self.X_E]), v_end=float(y[self.X_E + 1]), a_end=(F + self.F_ex) / self.train.m_end,
                    F_train=F)

    # ------------------------------------------------------------- the closing force with the train's
    def flank_closing(self, s: float, v: float) -> float:
        return self.closing(s) + self.along(s, v)

    def free_acceleration(self, s: float, sigma: float) -> float:
        """m/s2, the flying follower's acceleration with the train's force (the bound v in its damper)."""
        net = -self.closing(s) - self.along(s, self._v)
        if sigma == 0.0:
            if abs(net) <= self.f0:
                return 0.0
            sigma = 1.0 if net > 0.0 else -1.0
        return (net - sigma * self.f0) / self.m

    def net_at_rest(self, s: float) -> float:
        """N, the force on the flying follower at rest at s [m] (the train's included), against F_close."""
        return -self.closing(s) - self.along(s, 0.0)

    def direction(self, s: float, v: float) -> float:
        if v != 0.0:
            return 1.0 if v > 0.0 else -1.0
        net = self.net_at_rest(s)
        return (1.0 if net > 0.0 else -1.0) if abs(net) > self.f0 else 0.0


class TrainSpeedFollower(TrainCarrier, SpeedFollower):
    """The follower of its own on a cam at imposed speed carrying the train: y = (theta, s, v, x_e, v_e)."""

    V, X_E = 2, 3

    def __init__(self, model, train: Train | None = None) -> None:
        super().__init__(model)
        self._carry(model, train)

    def held(self, theta: float, omega: float, omega_dot: float, contact: float) -> float:
        """N, > 0 while the flank ``contact`` holds the follower, the bound end mass's pull in its closing force."""
        s, s1, s2, _ = self.flank(theta, contact)
        return contact * contact_sign(self.m, s, s1, s2, omega, self.k, self.F0 + self.pull(s, s1 * omega), self.F_gx,
                                      self.f0, omega_dot)

    def train_force(self, y, omega: float, contact: float) -> float:
        """N, F_train at y with the follower on the flank ``contact`` (its s, s' omega; 0: in flight, its own)."""
        self.bind(y)
        k = self.lift_per_q
        if contact:
            s, s1, _, _ = self.flank(y[0], contact)
            return self.pull(s * k, s1 * omega * k)
        return self.pull(y[1] * k, y[2] * k)

    def outputs_at(self, y, omega: float, omega_dot: float, contact: float, direction: float | None = None) -> dict:
        """Every output at y with the train's (``SpeedFollower.outputs`` with the end mass bound)."""
        self.bind(y)
        record = self.outputs(float(y[0]), omega, omega_dot, float(y[1]), float(y[2]), contact, direction)
        record.update(self.end_outputs(y, self.train_force(y, omega, contact)))
        return record


class TrainVoltageFollower(TrainCarrier, VoltageFollower):
    """The follower of its own on a voltage-driven cam carrying the train (``model.train``, k_train > 0)."""

    def __init__(self, model, train: Train | None = None) -> None:
        super().__init__(model)
        self._carry(model, train)
        self.X_E = self.size          # index of x_e in y, v_e after it
        self.size += 2

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
        s, v = self.motion(y, contact)
        return self.pull(s * self.lift_per_q, v * self.lift_per_q)

    def train_damping(self, y, contact: float) -> float:
        """W, the train damper's loss d_train (v - v_e)^2."""
        slip = self.motion(y, contact)[1] * self.lift_per_q - y[self.X_E + 1]
        return self.train.d_train * slip * slip

    # ------------------------------------------------------------- the base class's entries, bound first
    def start(self, y, u: float, contact: float) -> tuple[float, float]:
        self.bind(y)
        return super().start(y, u, contact)

    def rates(self, y, u: float, contact: float, sigma: float = 0.0) -> list[float]:
        self.bind(y)
        dy = super().rates(y, u, contact, sigma)
        return dy + self.end_rates(self.train_force(y, contact), y)

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
        stretch = y[3] * self.lift_per_q - x_e
        return (super().stored_energy(y) + 0.5 * self.train.m_end * v_e * v_e
                + 0.5 * self.train.k_train * stretch * stretch - self.F_ex * x_e)

    def outputs(self, y, u: float, contact: float) -> dict[str, float]:
        """The follower's outputs with the train's s_end, v_end [m, m/s], a_end [m/s2] and F_train [N]."""
        self.bind(y)
        record = super().outputs(y, u, contact)
        record.update(self.end_outputs(y, self.train_force(y, contact)))
        return record
