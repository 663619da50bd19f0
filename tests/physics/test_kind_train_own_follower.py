"""The follower train on a follower of its own of another kind in the reference (physics/kind_train_follower.py,
docs/model.md 14.6 and 16.3), against an invariant written here: the energy balance of docs/model.md 9 with the
train's stored energy in each kind's own terms (a flat's end mass on its spring along s, an arm's end inertia on its
torsion spring), through lift-offs, flights and impacts. (Against the C engine:
tests/engine/test_engine_train_kind_own_reference.py.)"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.physics.parameters import resolve
from cam_fmu.physics.signals import Signal
from cam_fmu.reference import simulate_reference
from test_kind_own_follower import BALANCE, G_N, H, KINDS, SCENE, stored

TRAINS = {"translating_flat": dict(k_train=5e3, d_train=0.5, m_end=0.1),
          "oscillating_roller": dict(k_train_arm=60.0, d_train_arm=0.005, J_end=1e-3),
          "oscillating_flat": dict(k_train_arm=60.0, d_train_arm=0.005, J_end=1e-3)}


def train_energy(name: str, out: dict, p: dict) -> np.ndarray:
    """J: the end's kinetic energy and the train's spring, and a flat's end mass lifted against gravity (the cam
    plane vertical, the face lifting upward: its weight m_end g_n against s); an arm's in its angles psi, psi_e =
    s_end lift_angle / h."""
    if name == "translating_flat":
        x, x_e, v_e = out["s"], out["s_end"], out["v_end"]
        return 0.5 * p["m_end"] * v_e ** 2 + 0.5 * p["k_train"] * (x - x_e) ** 2 + p["m_end"] * G_N * x_e
    per = KINDS[name].lift_angle / H
    psi, psi_e, rate_e = out["psi"], out["s_end"] * per, out["v_end"] * per
    return 0.5 * p["J_end"] * rate_e ** 2 + 0.5 * p["k_train_arm"] * (psi - psi_e) ** 2


@pytest.mark.slow
@pytest.mark.parametrize("closure", list(BALANCE))
@pytest.mark.parametrize("name", list(KINDS))
def test_energy_balance_with_the_train_through_flights_and_impacts(name, closure):
    """The stored energy's change (the drive's and the train's) is E_in - E_copper - E_shaft - E_guide - E_impact -
    E_damp (the train's damper), the cam driven forward at 40 V, back at -12 V, then 1 V, mu = 0.05, gravity on.
    Measured: at most 1.3e-10 of E_in (the flat in the groove, 1.2e-9 J of 9.6 J, the same at rtol 1e-10 .. 1e-12):
    each of its 73 impacts sets the follower onto the flank where the touch-down was located, up to 1e-12 m away,
    against the train's pull of up to 200 N; the sum of those F ds is 1.1e-9 J. Without a train the same run keeps
    4.4e-11 J (the pull there is the weight's 4 N)."""
    kind = KINDS[name]
    params = dict(SCENE, **BALANCE[closure], **TRAINS[name], follower_type=name, drive="voltage", gravity=True,
                  gamma=math.pi / 2, beta=0.0 if kind.oscillating else math.pi, mu=0.05, guide_friction=True,
                  shaft_friction=True, M_f=0.012, L=1e-3, restitution=0.5, J_cam=2e-4)
    if kind.oscillating:
        params.update(lift_angle=kind.lift_angle, arm_length=kind.arm_length, pivot_distance=kind.pivot_distance,
                      J_arm=kind.J_arm, m_arm=kind.m_arm, r_cm_arm=kind.r_cm_arm, psi_0=kind.psi_0)
    params["c_e"] = resolve(params)["c_m"]  # the motor's power balance: back-EMF constant = torque constant
    p = resolve(params)
    u = Signal((0.0, 0.12, 0.2), (40.0, -12.0, 1.0), hold=True)
    out = simulate_reference(params, 0.3, 5e-4, u=u, energy=True)
    assert out["impacts"][-1] >= 2 and np.any(out["contact"] == 0.0)
    assert out["E_damp"][-1] > 1e-5 and np.ptp(out["F_train"]) > 1.0
    E = stored(kind, out, p) + train_energy(name, out, p)
    books = out["E_in"] - out["E_copper"] - out["E_shaft"] - out["E_guide"] - out["E_impact"] - out["E_damp"]
    error = np.max(np.abs((E - E[0]) - books))
    assert error < 3e-10 * out["E_in"].max(), (error, out["E_in"].max())
