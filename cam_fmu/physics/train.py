"""The follower train inside the drive: a spring-damper from the follower to an end mass (docs/model.md 14.6).

The train is its own description, not an FMU parameter (the C engine does not run it yet): the reference takes it
as an optional input. Between the follower (position s, velocity v along X) and the end mass (x_e, v_e):

    F_train = k_train (s - x_e) + d_train (v - v_e)      [N], pulling the end mass along X, the follower against it
    m_end a_e = F_train + F_ex                          F_ex = m_end g_n sin(gamma) cos(beta): its weight along X
                                                        (0 with the gravity effect off)

The end mass starts at rest relative to the follower in the spring's static deflection: x_e = s + F_ex / k_train,
v_e = v. Plain functions of floats (``math`` only), as physics/drive.py.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

from .parameters import KGF, ParameterError, mounting_component

__all__ = ["Train", "end_weight"]

G_N = KGF  # m/s2, standard gravity (the weight of the end mass; the follower's is the parameter G)


@dataclass(frozen=True)
class Train:
    """The follower train: stiffness ``k_train`` [N/m] (0: no train, the rigid drive), damping ``d_train`` [N.s/m]
    and end mass ``m_end`` [kg]. ``torsional``: an arm's train (k_train_arm, d_train_arm, J_end, checked as those
    parameters) carried in the law's lift units, its three scaled by (lift_angle / lift)^2: the ranges along X do not
    apply, and its end inertia turns about its own centre (no weight along X, end_weight)."""

    k_train: float = 0.0
    d_train: float = 0.0
    m_end: float = 0.0
    torsional: bool = False

    def __post_init__(self) -> None:
        for name, low, high in (("k_train", 0.0, 1e12), ("d_train", 0.0, 1e9), ("m_end", 0.0, 1e4)):
            value = getattr(self, name)
            high = math.inf if self.torsional else high
            if not (isinstance(value, (int, float)) and math.isfinite(value) and low <= value <= high):
                raise ParameterError(f"train parameter '{name}' = {value!r}: allowed {low:g} .. {high:g}")
        if self.k_train > 0.0 and self.m_end <= 0.0:
            raise ParameterError(f"train parameter 'm_end' = {self.m_end!r} kg with 'k_train' = {self.k_train!r} N/m:"
                                 f" allowed m_end > 0 where k_train > 0 (a massless end has no dynamics)")

    @property
    def active(self) -> bool:
        """Does the drive carry the train (k_train > 0)?"""
        return self.k_train > 0.0

    def force(self, s: float, v: float, x_e: float, v_e: float) -> float:
        """F_train [N] from the follower's s [m], v [m/s] and the end mass's x_e [m], v_e [m/s]."""
        return self.k_train * (s - x_e) + self.d_train * (v - v_e)

    def natural_frequency(self) -> float:
        """sqrt(k_train / m_end) [rad/s] (the end mass on the train, the follower held)."""
        return math.sqrt(self.k_train / self.m_end)


def end_weight(train: Train, params: Mapping[str, Any]) -> float:
    """F_ex [N]: the end mass's weight along X, m_end g_n sin(gamma) cos(beta) with gravity on, else 0 (and 0 for
    an arm's torsional train, whose end inertia turns about its own centre)."""
    if not params["gravity"] or train.torsional:
        return 0.0
    gamma, beta = params["gamma"], params["beta"]
    along = mounting_component(math.sin(gamma), gamma) * mounting_component(math.cos(beta), beta)
    return train.m_end * G_N * along
