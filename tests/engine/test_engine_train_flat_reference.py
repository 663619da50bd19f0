"""The follower train on a translating flat follower WITH its friction (docs/model.md 14.6, 16.3): the engine's
flat (kind.c, the train's force F_train along s in P, so in the face's friction mu |P| (r_b + s)) against the scipy
reference's flat (physics/kind_drive.py's KindDriveModel with ``axial`` through reference/train_voltage.py and
train_speed.py, written apart from the C); a train along X on an arm is refused by the reference naming follower_type
(an arm's is torsional: tests/engine/test_engine_train_arm.py)."""
from __future__ import annotations

import pytest

from cam_fmu.physics.parameters import ParameterError, defaults
from cam_fmu.physics.signals import Signal
from cam_fmu.physics.train import Train
from cam_fmu.reference.integrate import simulate_reference
from tests.engine.test_engine_train import REVERSING, STEP, STOP, TRAIN, speed_run, voltage_run, worst

# the face's and the shaft's friction, gravity tilted out of the plane and along the path
FLAT = dict(TRAIN, mu=0.03, M_f=0.01, gamma=1.0, beta=0.3, follower_type="translating_flat")
NAMES = ("theta", "omega", "i", "M", "N_contact", "s", "s_end", "v_end", "a_end", "F_train")


def test_the_flat_s_train_with_friction_runs_as_the_flat_reference_in_the_voltage_drive():
    """12 V, -6 V, then 0 V: the cam runs, reverses, and is stopped and broken away again by the ringing train (45
    break-aways, 46 stops, 47 sign changes of P); measured 1.7e-10 (theta) .. 1.2e-8 (a_end) of each output's largest
    value (rk45 at the engine's default rtol 1e-10 against the reference at rtol 1e-12, which lies within 1.2e-10 of
    itself at 1e-13; at 1e-10 the reference is 1.1e-2 off itself, a stop decided the other way)."""
    params = dict(defaults(), **FLAT)
    sim, engine = voltage_run(params, REVERSING)
    reference = simulate_reference(params, STOP, STEP, u=REVERSING)
    for name in NAMES:
        assert worst(engine, reference, name) < 1e-7, (name, worst(engine, reference, name))
    names = [e["name"] for e in sim.events()]
    assert "stop" in names and "break_away" in names and "side_force" in names
    assert engine["F_train"].min() < -1.0 < 1.0 < engine["F_train"].max()   # the train rings
    assert engine["omega"].min() < 0.0 < engine["omega"].max()


def test_the_flat_s_train_with_friction_runs_as_the_flat_reference_in_the_speed_drive():
    """A ramp, a jump and a reversal of omega_ref; measured 1e-15 (theta) .. 5.0e-9 (a_end, F_train) of each output's
    largest value, the voltage 2.7e-9."""
    w = Signal((0.0, 0.4, 0.4, 0.7), (20.0, 35.0, 35.0, -10.0))
    params = dict(defaults(), **dict(FLAT, drive="speed"))
    engine = speed_run(params, w)
    reference = simulate_reference(params, STOP, STEP, omega_ref=w)
    for name in NAMES + ("voltage",):
        assert worst(engine, reference, name) < 5e-8, (name, worst(engine, reference, name))
    assert engine["F_train"].min() < -1.0 < 1.0 < engine["F_train"].max()


def test_the_train_s_force_enters_the_flat_s_friction_in_the_reference():
    """The reference's load: M = M_f d + P s' + mu |P| (r_b + s) d with P = m a - F_gx + F_train (docs/model.md
    16.3), written out here from the parameters and the law's s, s', s''."""
    from cam_fmu.physics.kind_drive import KindDriveModel
    from cam_fmu.physics.follower_kind import FollowerKind

    params = dict(defaults(), **FLAT)
    model = KindDriveModel(params, FollowerKind.from_parameters(params))
    theta, omega, omega_dot, F = 0.9, 30.0, 50.0, -40.0
    s, s1, s2, _ = model.program.derivatives(theta)
    F_gx = model.F_gx
    P = params["m"] * (s2 * omega ** 2 + s1 * omega_dot) - F_gx + F
    expected = params["M_f"] + P * s1 + params["mu"] * abs(P) * (params["r_b"] + s)
    assert model.load(theta, omega, omega_dot, 1.0, True, F).M == pytest.approx(expected, rel=1e-12)


ARM = dict(arm_length=0.15, pivot_distance=0.18, J_arm=2e-3, m_arm=0.2, r_cm_arm=0.07, psi_0=0.3)


@pytest.mark.parametrize("kind, lift_angle", [("oscillating_roller", 0.3), ("oscillating_flat", 0.15)])
def test_an_arm_s_train_is_refused_by_the_reference_naming_follower_type(kind, lift_angle):
    arm = dict(ARM, follower_type=kind, lift_angle=lift_angle)
    with pytest.raises(ParameterError, match="follower_type") as info:
        simulate_reference(dict(defaults(), **dict(FLAT, beta=0.0, **arm)), 0.1, 0.01)
    assert repr(kind) in str(info.value) and "train" in str(info.value)
    given = Train(TRAIN["k_train"], TRAIN["d_train"], TRAIN["m_end"])   # a train given beside the parameters
    with pytest.raises(ParameterError, match="follower_type") as info:
        simulate_reference(dict(defaults(), **arm), 0.1, 0.01, train=given)
    assert repr(kind) in str(info.value) and "train" in str(info.value)
