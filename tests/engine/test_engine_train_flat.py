"""The follower train on a translating flat follower (docs/model.md 14.6, 16; issue 41): its path is s, as the
roller's, so without friction its load on the cam, P s' with P = m a - F_gx + F_train, is the roller's (the contact's
geometry changes N, not P): the engine's flat (kind.c) against the scipy reference's roller (reference/train_voltage.py,
train_speed.py, written apart); the train's energy balance from the engine's outputs; what is still refused."""
from __future__ import annotations

import numpy as np
import pytest

from cam_fmu.engine.simulator import DriveSimulator
from cam_fmu.physics.parameters import ParameterError, defaults
from cam_fmu.physics.signals import Signal
from cam_fmu.reference.integrate import simulate_reference
from cam_fmu.experiments.engine_runs import simulate_engine
from tests.engine.test_engine_train import STEP, STOP, TRAIN, engine_run, speed_run, worst
from tests.engine.test_engine_train_own_follower import CLOSURES as OWN_CLOSURES, SCENE as OWN_SCENE
from tests.engine.test_engine_train_speed_follower import TRAIN as SPEED_TRAIN, runs as speed_runs

FLAT = dict(follower_type="translating_flat")
# N_contact is the geometry's (the flat's P, the roller's P / cos(alpha)): not compared
NAMES = ("theta", "omega", "i", "M", "s", "s_end", "v_end", "a_end", "F_train")


@pytest.mark.parametrize("extra", [dict(), dict(gamma=1.0, beta=0.3)], ids=["plain", "tilted"])
def test_the_flat_with_a_train_drives_as_the_roller_reference_without_friction(extra):
    """measured with rk45 at rtol 1e-10 (the roller's own bound in test_engine_train.py is 2e-6)."""
    params = dict(defaults(), **TRAIN, **extra)
    engine = engine_run(dict(params, **FLAT))
    reference = simulate_reference(params, STOP, STEP, u=None)
    for name in NAMES:
        assert worst(engine, reference, name) < 2e-6, (name, worst(engine, reference, name))
    assert engine["F_train"].min() < -1.0 < 1.0 < engine["F_train"].max()   # the train rings


def test_the_speed_drive_carries_the_flat_s_train_as_the_roller_reference():
    w = Signal((0.0, 0.4, 0.4, 0.7), (20.0, 35.0, 35.0, -10.0))
    params = dict(defaults(), **dict(TRAIN, drive="speed"))
    engine = speed_run(dict(params, **FLAT), w)
    reference = simulate_reference(params, STOP, STEP, omega_ref=w)
    for name in NAMES:
        assert worst(engine, reference, name) < 5e-8, (name, worst(engine, reference, name))


def test_the_flat_s_train_keeps_its_energy_balance_with_friction():
    """m_end v_e^2/2 + k (s - x_e)^2/2 - F_ex x_e + int d (v - v_e)^2 dt - (the same at 0) = int F_train v dt (14.6),
    the integrals by the trapezoid rule on a 50 us grid, with the face's friction on (the flat's own lever). The
    trapezoid's error is the gap: measured 6.4e-6 J at 0.1 ms, 1.6e-6 J (2.7e-5 of the work) at 50 us, h^2."""
    step, stop = 5e-5, 0.3
    params = dict(defaults(), **dict(TRAIN, mu=0.03, M_f=0.01, gamma=1.0), **FLAT)
    out = engine_run(params, stop=stop, step=step)
    k, d, m_end = TRAIN["k_train"], TRAIN["d_train"], TRAIN["m_end"]
    F_ex = m_end * 9.80665 * np.sin(params["gamma"]) * np.cos(params["beta"])
    stored = 0.5 * m_end * out["v_end"] ** 2 + 0.5 * k * (out["s"] - out["s_end"]) ** 2 - F_ex * out["s_end"]
    damp = d * (out["v"] - out["v_end"]) ** 2
    work = out["F_train"] * out["v"]
    integral = lambda y: np.concatenate(([0.0], np.cumsum(0.5 * step * (y[1:] + y[:-1]))))  # noqa: E731
    gap = stored - stored[0] + integral(damp) - integral(work)
    assert np.max(np.abs(work)) > 1.0
    assert np.max(np.abs(gap)) < 5e-5 * np.max(np.abs(integral(np.abs(work)))), np.max(np.abs(gap))


def test_a_train_not_run_yet_is_refused_by_name():
    """An arm's train is torsional, under parameters of its own (not built yet): k_train on an arm is refused."""
    with pytest.raises(ParameterError, match="follower_type"):
        DriveSimulator(dict(defaults(), **TRAIN, **dict(FLAT, follower_type="oscillating_roller")))


def test_the_flat_s_train_on_a_follower_of_its_own_flies_as_the_roller_reference_without_friction():
    """The voltage drive, closure 'spring', the train pulling the follower off (reference/train_flight.py's roller,
    written apart): measured theta 2.7e-12 rad, s 6.7e-13 m, s_end 5.4e-13 m, F_train 1.2e-8 N, M 2.5e-10 N m, with
    234 of 501 samples in flight and 4 touch-downs."""
    params = dict(defaults(), **OWN_SCENE, **OWN_CLOSURES["spring"], d_train=2.0)
    reference = simulate_reference(params, 0.5, 1e-3, u=None)
    engine = simulate_engine(dict(params, **FLAT), 0.5, 1e-3)
    assert np.sum(reference["contact"] == 0.0) > 100 and reference["impacts"][-1] >= 2.0   # it flies and lands
    for name, bound in (("theta", 1e-11), ("s", 5e-12), ("s_end", 5e-12), ("F_train", 1e-7), ("M", 2e-9)):
        error = np.max(np.abs(engine[name] - reference[name]))
        assert error < bound, (name, error)
    assert np.array_equal(engine["N_contact"] == 0.0, reference["contact"] == 0.0)


@pytest.mark.parametrize("scene_name, label", [("spring_jump", "above_1.02"), ("groove_crossover", "form")])
def test_the_speed_drive_s_flat_with_a_train_flies_as_the_roller_reference_without_friction(scene_name, label):
    """The speed drive's follower of its own (reference/train_flight.py's TrainSpeedFollowerRun for the roller):
    measured s within 1.9e-11 m, F_train 2.5e-7 N, M 1.8e-8 N m past the jump; 3.6e-11 m, 6.6e-7 N, 4.4e-8 N m across
    the groove (the roller's own agreement there: 3.3e-11 m, 6.2e-7 N)."""
    got, ref = speed_runs(scene_name, label, dict(SPEED_TRAIN, mu=0.0), dict(FLAT))
    assert np.any(ref["contact"] == 0.0) and ref["impacts"][-1] >= 1.0
    for name, bound in (("s", 2e-10), ("s_end", 2e-10), ("F_train", 4e-6), ("M", 3e-7), ("theta", 1e-12)):
        error = np.max(np.abs(got[name] - ref[name]))
        assert error < bound, (name, error)
