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
from tests.engine.test_engine_train import STEP, STOP, TRAIN, engine_run, speed_run, worst

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


@pytest.mark.parametrize("extra", [dict(closure="spring", m=1.0, k_spring=1e3, F_spring0=20.0),
                                   dict(follower_type="oscillating_roller")], ids=["own-follower", "arm"])
def test_a_train_not_run_yet_is_refused_by_name(extra):
    with pytest.raises(ParameterError, match="follower_type"):
        DriveSimulator(dict(defaults(), **TRAIN, **dict(FLAT, **extra)))
