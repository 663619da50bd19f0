"""The follower train on a follower of its own of every other kind, the C engine against the scipy reference
(physics/kind_train_follower.py: the kind's body of its own carrying the train's end mass in the law's lift units,
written apart from the engine): a translating flat's train along s, an arm's torsional one, on a return spring and
in a groove, both drives, with the kind's friction and tilted gravity (docs/model.md 14.6, 16.3)."""
from __future__ import annotations

import numpy as np
import pytest

from cam_fmu.physics.parameters import defaults
from cam_fmu.reference.integrate import simulate_reference
from test_engine_follower_kinds import KINDS, NAMES, OWN, SCENE, SPEED, STEP, STOP, VOLTS, engine_run, worst

# About 36 Hz on its own, damped lightly, on every kind: along s on the flat, about the pivot on an arm.
TRAINS = {"translating_flat": dict(k_train=5e3, d_train=0.5, m_end=0.1),
          "oscillating_roller": dict(k_train_arm=60.0, d_train_arm=0.005, J_end=1e-3),
          "oscillating_flat": dict(k_train_arm=60.0, d_train_arm=0.005, J_end=1e-3)}
TRAIN_NAMES = NAMES + ("s_end", "v_end", "a_end", "F_train", "psi_end", "psi_dot_end", "M_train")
# Every output's largest difference relative to its largest value, measured: the voltage drive 2.1e-9 .. 4.1e-7 (the
# oscillating face's psi_dot the largest, as without a train), the speed drive 2.7e-10 .. 2.0e-8.
BOUNDS = {"voltage": 1e-6, "speed": 5e-8}


@pytest.mark.parametrize("drive", list(BOUNDS))
@pytest.mark.parametrize("closure", [pytest.param("spring"), pytest.param("groove", marks=pytest.mark.slow)])
@pytest.mark.parametrize("kind", list(KINDS))
def test_the_engine_flies_every_kind_with_its_train_as_the_reference_does(kind, closure, drive):
    """Lift-offs, flights and impacts with the train ringing (F_train swinging over 12 to 212 N along s): every
    output within BOUNDS of its largest, the flights on the same rows; the same run without the train is far off
    (the train matters here)."""
    params = {**defaults(), **SCENE, **KINDS[kind], **OWN[closure], **TRAINS[kind], "mu": 0.05, "drive": drive}
    engine = engine_run(params)
    reference = simulate_reference(params, STOP, STEP, u=VOLTS, omega_ref=SPEED)
    for name in TRAIN_NAMES:
        assert worst(engine, reference, name) < BOUNDS[drive], (name, worst(engine, reference, name))
    flying = engine["N_contact"] == 0.0
    assert np.sum(flying) >= 10 and reference["impacts"][-1] >= 3 and np.ptp(engine["F_train"]) > 10.0
    assert np.array_equal(flying, reference["contact"] == 0.0)
    bare = {name: value for name, value in params.items() if name not in TRAINS[kind]}
    assert worst(engine_run(bare), reference, "s") > 1e-3
