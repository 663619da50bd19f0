"""The follower-type load terms (physics/follower_load.py) against energy, geometry and finite differences."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.kinematics.arm_motion import ArmMotion
from cam_fmu.kinematics.cam_program import CamProgram
from cam_fmu.physics.follower_load import (arc_mass, arm_gravity_torque, arm_inertia_torque, arm_jump_speed,
                                           flat_face_torque)

PROG = CamProgram("cycloidal", "modified_sine", 0.02, math.radians(100), math.radians(40),
                  math.radians(120), math.radians(100))
ARM = ArmMotion(PROG, math.radians(25))
M, J_ARM, L = 0.4, 3e-3, 0.12
TH = np.linspace(0.05, 2 * math.pi - 0.05, 721)
H = 1e-5


def _psi(theta):
    return np.asarray(ARM.derivatives(theta)[0])


def test_arm_inertia_torque_is_the_rate_of_kinetic_energy():
    # M omega = dT/dt at constant omega, T = 1/2 (J_arm + m L^2) (psi' omega)^2: M = dT/dtheta (central differences)
    omega = 30.0
    def kinetic(theta):
        psi1 = (_psi(theta + H) - _psi(theta - H)) / (2 * H)
        return 0.5 * (J_ARM + M * L ** 2) * (psi1 * omega) ** 2
    fd = (kinetic(TH + 1e-4) - kinetic(TH - 1e-4)) / 2e-4
    _, psi1, psi2, _ = ARM.derivatives(TH)
    torque = arm_inertia_torque(M, J_ARM, L, psi1, psi2, omega)
    scale = np.max(np.abs(torque))
    assert scale > 0.1
    assert np.max(np.abs(torque - fd)) < 1e-4 * scale


def test_arc_coordinate_gives_the_arm_torque_with_the_translating_formula():
    # x = L psi with m_eq = (J_arm + m L^2)/L^2: m_eq x' x'' omega^2 is the arm's torque
    omega = 12.0
    _, psi1, psi2, _ = ARM.derivatives(TH)
    m_eq = arc_mass(M, J_ARM, L)
    assert m_eq == pytest.approx(M + J_ARM / L ** 2, rel=1e-15)
    np.testing.assert_allclose(m_eq * (L * psi1) * (L * psi2) * omega ** 2,
                               arm_inertia_torque(M, J_ARM, L, psi1, psi2, omega), rtol=1e-12, atol=1e-14)
    with pytest.raises(ValueError, match="arm_length"):
        arc_mass(M, J_ARM, 0.0)


def test_arm_gravity_torque_is_the_rate_of_potential_energy():
    m_arm, r_cm, psi_0, g = 0.3, 0.05, math.radians(-10), 9.80665
    def potential(theta):
        return (M * L + m_arm * r_cm) * g * np.sin(_psi(theta) + psi_0)
    fd = (potential(TH + H) - potential(TH - H)) / (2 * H)
    psi, psi1, _, _ = ARM.derivatives(TH)
    torque = arm_gravity_torque(M, m_arm, L, r_cm, psi, psi1, psi_0, g)
    assert np.max(np.abs(torque)) > 0.05
    assert np.max(np.abs(torque - fd)) < 1e-6


@pytest.mark.parametrize("omega", [40.0, -40.0])
def test_flat_face_torque_is_the_moment_of_the_contact_forces(omega):
    # cam frame: follower axis y, face at y = r_b + s, contact at x = s'; the cam turning at omega slides under the
    # face, friction on the cam opposes its surface speed there. Torque on the cam's drive = -(r x F_on_cam)_z.
    r_b, mu = 0.03, 0.08
    s, s1 = PROG.evaluate(TH)[:2]
    N = 200.0 + 50.0 * np.sin(TH)
    torque = flat_face_torque(N, s, s1, r_b, mu, omega)
    for i in range(0, TH.size, 37):
        r = np.array([s1[i], r_b + s[i], 0.0])
        surface_velocity = np.cross([0.0, 0.0, omega], r)  # the cam point under the contact
        f_on_cam = np.array([0.0, -N[i], 0.0]) - mu * N[i] * np.sign(surface_velocity[0]) * np.array([1.0, 0, 0])
        load = -np.cross(r, f_on_cam)[2]
        assert torque[i] == pytest.approx(load, rel=1e-12, abs=1e-12)


def test_arm_jump_speed_holds_contact_below_and_loses_it_above():
    F0, k = 40.0, 2000.0
    psi, _, psi2, _ = ARM.derivatives(TH)
    w_jump = arm_jump_speed(M, J_ARM, L, F0, k, psi, psi2)
    assert 10.0 < w_jump < 1000.0
    # contact torque about the pivot = spring torque - the arm's inertial demand, psi''(t) by finite differences
    for factor, held in [(0.98, True), (1.02, False)]:
        omega = factor * w_jump
        t = TH / omega
        dt = 1e-4 / omega
        psi_tt = (_psi((t + dt) * omega) - 2 * _psi(t * omega) + _psi((t - dt) * omega)) / dt ** 2
        contact = L * (F0 + k * L * _psi(TH)) + (J_ARM + M * L ** 2) * psi_tt
        assert (contact.min() > 0.0) == held
    assert arm_jump_speed(M, J_ARM, L, F0, k, np.zeros(3), np.ones(3)) == math.inf
