"""A follower train on the speed drive's follower of its own (docs/model.md 14.6, issue 41): the C engine against the
scipy reference (reference/train_flight.py's TrainSpeedFollowerRun, written from the model's equations apart from the
engine), the energy a flight keeps with an undamped train, and a lift-off the train alone causes."""
from __future__ import annotations

import numpy as np
import pytest

from cam_fmu.experiments.engine_runs import simulate_engine
from cam_fmu.experiments.scenes import find_scene
from cam_fmu.physics.parameters import defaults
from cam_fmu.reference import simulate_reference

TRAIN = dict(k_train=2e4, d_train=2.0, m_end=0.1)   # N/m, N.s/m, kg: 71 Hz on the held follower


def runs(scene_name: str, label: str, change: dict, engine_change: dict | None = None,
         interval: float = 1e-3) -> tuple[dict, dict]:
    """(engine, reference) outputs of a scene's run with ``change`` (the engine's with ``engine_change`` on top), on
    the same grid."""
    scene = find_scene(scene_name)
    run = next(r for r in scene.runs if r.label == label)
    params = dict(run.overrides, **change)
    ref = simulate_reference(params, scene.stop_time, interval, omega_ref=scene.omega_ref)
    got = simulate_engine(dict(params, **(engine_change or {})), scene.stop_time, interval, omega_ref=scene.omega_ref)
    return got, ref


@pytest.mark.parametrize("scene_name, label, change", [
    ("spring_jump", "above_1.02", TRAIN),                       # lifts off past the jump speed, the train ringing
    ("spring_jump", "above_1.02", dict(TRAIN, d_train=0.0)),
    ("groove_crossover", "form", TRAIN)])                       # flights across the groove's clearance
def test_the_engine_is_the_reference(scene_name, label, change):
    """Measured: s and s_end within 3.3e-11 m, v_end 1.5e-8 m/s, F_train 6.2e-7 N, M 4.3e-8 N.m on spring_jump;
    1.7e-10 m, 7.2e-8 m/s, 3.4e-6 N, 2.4e-7 N.m in the groove (the bounds are 6x those); they fly at the same
    samples."""
    got, ref = runs(scene_name, label, change)
    assert np.any(ref["contact"] == 0.0) and ref["impacts"][-1] >= 1.0   # it flies and lands
    assert np.ptp(ref["F_train"]) > 1.0                                   # and the train rings
    for name, bound in (("s", 1e-9), ("s_end", 1e-9), ("v", 5e-7), ("v_end", 5e-7), ("F_train", 2e-5), ("M", 2e-6),
                        ("theta", 1e-12)):
        error = np.max(np.abs(got[name] - ref[name]))
        assert error < bound, (name, error)
    assert np.array_equal(got["N_contact"] == 0.0, ref["N_contact"] == 0.0)


def test_an_undamped_train_keeps_the_flights_energy():
    """In flight (no friction, no damper, gravity across the stroke) the follower, the end mass, the return spring and
    the train exchange energy only among themselves: m v^2/2 + m_end v_e^2/2 + F0 s + k s^2/2 + k_train (s - x_e)^2/2
    holds between every two of the engine's flight samples with no touch-down between them (the reference's count)."""
    scene = find_scene("spring_jump")
    params = dict(defaults(), **next(r for r in scene.runs if r.label == "above_1.02").overrides)
    got, ref = runs("spring_jump", "above_1.02", dict(TRAIN, d_train=0.0, mu=0.0), interval=1e-4)
    m, k, F0 = params["m"], params["k_spring"], params["F_spring0"]
    assert abs(np.sin(params["gamma"])) < 1e-15   # no friction, no weight along the stroke
    energy = (0.5 * m * got["v"] ** 2 + 0.5 * TRAIN["m_end"] * got["v_end"] ** 2 + F0 * got["s"]
              + 0.5 * k * got["s"] ** 2 + 0.5 * TRAIN["k_train"] * (got["s"] - got["s_end"]) ** 2)
    flying = got["N_contact"] == 0.0
    pairs = [j for j in range(len(energy) - 1)
             if flying[j] and flying[j + 1] and ref["impacts"][j] == ref["impacts"][j + 1]]
    assert len(pairs) > 20
    drift = max(abs(energy[j + 1] - energy[j]) for j in pairs)
    assert drift < 1e-9 * np.max(np.abs(energy)), drift


def test_the_train_alone_pulls_the_follower_off():
    """Below the jump speed (0.98) the follower stays on the cam; a heavy, soft train (a 4 kg end mass at 16 Hz) rings
    at the end of the rise and pulls it off: the engine and the reference fly at the same samples."""
    without, _ = runs("spring_jump", "below_0.98", {})
    assert np.all(without["N_contact"] > 0.0)
    got, ref = runs("spring_jump", "below_0.98", dict(k_train=4e4, d_train=0.0, m_end=4.0))
    assert np.any(ref["contact"] == 0.0)
    assert np.array_equal(got["N_contact"] == 0.0, ref["N_contact"] == 0.0)
    assert np.max(np.abs(got["s"] - ref["s"])) < 1e-9


def test_a_tilted_groove_with_friction_starts_on_the_flank_the_weights_press_and_is_the_reference():
    """Gravity along +X (tilted, gamma 1.2, beta 0.3) presses the follower and, through the train, the end mass's
    weight onto the groove's -1 flank at the start; guide friction, a ramp of omega_ref, restitution 0.3. The
    reference first decided the start with the end mass at rest relative to the +1 flank and flew from there; the
    engine, which rests it relative to each candidate, was right. Measured: s within 1.7e-12 m, F_train 6.3e-8 N, 44
    impacts. (With restitution 1 and no damper the groove is chaotic: the reference at rtol 1e-10 leaves itself at
    1e-12 by 4e-4 m within 0.4 s, so no engine can follow it there.)"""
    from cam_fmu.physics.signals import Signal

    params = dict(drive="speed", rise_law="cycloidal", return_law="cycloidal", lift=0.02, r_b=0.08, m=0.4, G=4.0,
                  gravity=True, gamma=1.2, beta=0.3, mu=0.05, closure="form", c=5e-4, restitution=0.3, **TRAIN)
    ramp = Signal([0.0, 0.3, 0.6], [5.0, 60.0, 0.0])
    ref = simulate_reference(params, 0.6, 1e-3, omega_ref=ramp)
    got = simulate_engine(params, 0.6, 1e-3, omega_ref=ramp)
    assert ref["N_contact"][0] < 0.0 and ref["s"][0] == got["s"][0] == 5e-4   # on the -1 flank, s_cam + c
    assert ref["impacts"][-1] > 10
    assert np.max(np.abs(got["s"] - ref["s"])) < 1e-10 and np.max(np.abs(got["F_train"] - ref["F_train"])) < 1e-5
    assert np.array_equal(got["N_contact"] == 0.0, ref["N_contact"] == 0.0)
