"""The load terms that differ between follower types, in the arc coordinate (issue 40).

An oscillating arm runs in the arc coordinate x = L psi [m] along its roller centre's path (L = arm_length):
its "mass" is m_eq = (J_arm + m L^2) / L^2 [kg], so the translating follower's terms apply unchanged to x.
What differs is written here: the arm's kinetic inertia torque, gravity about the pivot, a flat face's
friction at the contact offset s', and the jump speed of a spring-closed arm. Units: SI, angles in rad.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["arc_mass", "arm_inertia_torque", "arm_gravity_torque", "flat_face_torque", "arm_jump_speed"]


def arc_mass(m: float, J_arm: float, arm_length: float) -> float:
    """m_eq [kg] of an arm (J_arm [kg m^2] about its pivot, follower mass m [kg] at arm_length [m]) in x = L psi."""
    if not (arm_length > 0.0):
        raise ValueError(f"arm_length must be > 0 m, got {arm_length!r} m")
    return (J_arm + m * arm_length ** 2) / arm_length ** 2


def arm_inertia_torque(m: float, J_arm: float, arm_length: float, psi1, psi2, omega: float):
    """Cam torque [N m] accelerating the arm at constant cam speed omega [rad/s]: (J_arm + m L^2) psi' psi'' omega^2.

    psi1, psi2 = dpsi/dtheta [1], d2psi/dtheta2 [1/rad]."""
    return (J_arm + m * arm_length ** 2) * np.asarray(psi1) * np.asarray(psi2) * omega ** 2


def arm_gravity_torque(m: float, m_arm: float, arm_length: float, r_cm_arm: float, psi, psi1, psi_0: float,
                       g: float = 9.80665):
    """Cam torque [N m] lifting the arm against gravity: dV/dpsi * psi'.

    Convention: psi_0 [rad] is the arm's angle above the horizontal at psi = 0, so the potential is
    V = (m L + m_arm r_cm_arm) g sin(psi + psi_0) [J] (r_cm_arm [m]: pivot to the arm's own centre of mass)."""
    moment = m * arm_length + m_arm * r_cm_arm
    return moment * g * np.cos(np.asarray(psi) + psi_0) * np.asarray(psi1)


def flat_face_torque(N, s, s1, base_radius: float, mu: float, omega: float):
    """Cam torque [N m] of a contact force N [N] on a translating flat face: N s' + mu |N| (r_b + s) sgn(omega).

    The normal force acts at the offset s' [m/rad] from the cam centre; the sliding friction acts on the face at
    distance r_b + s [m] from it."""
    N = np.asarray(N, dtype=float)
    return N * np.asarray(s1) + mu * np.abs(N) * (base_radius + np.asarray(s)) * math.copysign(1.0, omega)


def arm_jump_speed(m: float, J_arm: float, arm_length: float, F_spring0: float, k_spring: float, psi, psi2) -> float:
    """omega_jump [rad/s] of a spring-closed arm at constant speed: min over psi'' < 0 of
    sqrt(L (F0 + k L psi) / ((J_arm + m L^2) |psi''|)); inf where psi'' never goes negative."""
    psi = np.asarray(psi, dtype=float)
    psi2 = np.asarray(psi2, dtype=float)
    neg = psi2 < 0.0
    if not neg.any():
        return math.inf
    L = arm_length
    torque = L * (F_spring0 + k_spring * L * psi[neg])
    return float(np.sqrt(np.min(torque / ((J_arm + m * L ** 2) * np.abs(psi2[neg])))))
