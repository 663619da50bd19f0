"""`cam-fmu jump` for every follower type other than the translating roller (physics.kind_jump) against the closed
form evaluated by brute force here, on test_reflect_kinds' hand-written cam: a spring-closed arm at constant speed
leaves the cam at omega_jump = min over psi'' < 0 of sqrt((L (F0 + k L psi) + W cos(psi + psi_0)) / ((J_arm + m L^2)
|psi''|)) (W = 0 on a horizontal mounting); a translating flat face at the roller's, s-based,
sqrt((F0 + k s - F_gx) / (m |s''|)). The preload and the rate found for a target speed give, by the same brute force,
omega_jump = sqrt(S) target."""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cam_fmu.cli.jump import report
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.follower import jump_speed

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "physics"))
from test_reflect_kinds import BASE, BETA, G_N, H, KINDS, coordinate, lift  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SPRING = dict(closure="spring", k_spring=2000.0, F_spring0=20.0, mu=0.0)
GRID = np.linspace(0.0, 2.0 * math.pi, 400_001)  # rad: the brute force's angles, 1.6e-5 rad apart


def lift_grid() -> tuple[np.ndarray, np.ndarray]:
    """(s, s'') [m, m/rad2] over GRID: test_reflect_kinds.lift, vectorised (checked against it below)."""
    theta = GRID % (2.0 * math.pi)
    rise, fall = theta < BETA, (theta >= 2 * BETA) & (theta < 3 * BETA)
    x = np.where(rise, theta / BETA, (theta - 2 * BETA) / BETA)
    w = 2.0 * math.pi * x
    up = H * (x - np.sin(w) / (2.0 * math.pi))
    s = np.where(rise, up, np.where(fall, H - up, np.where(theta < 2 * BETA, H, 0.0)))
    s2 = np.where(rise | fall, np.where(rise, 1.0, -1.0) * 2.0 * math.pi * H / BETA ** 2 * np.sin(w), 0.0)
    return s, s2


def brute_force(kind: str, params: dict, omega: float | None = None) -> tuple[float, float]:
    """(omega_jump [rad/s], least contact force along the roller's path at omega [N]) over GRID by hand."""
    k, F0 = params["k_spring"], params["F_spring0"]
    s, s2 = lift_grid()
    if kind.startswith("oscillating"):
        p = KINDS[kind]
        L, scale = p["arm_length"], p["lift_angle"] / H
        q, q2, I_f = scale * s, scale * s2, p["J_arm"] + BASE["m"] * L * L
        gamma = params.get("gamma", math.pi)
        W = (BASE["G"] * L + p["m_arm"] * G_N * p["r_cm_arm"]) * math.sin(gamma) if gamma != math.pi else 0.0
        closing, a = L * (F0 + k * L * q) + W * np.cos(q + p["psi_0"]), L
    else:
        q, q2, I_f = s, s2, BASE["m"]
        closing, a = F0 + k * q, 1.0  # horizontal: no gravity along X
    decelerating = q2 < 0.0
    jump = math.sqrt(float(np.min(closing[decelerating] / (I_f * -q2[decelerating]))))
    margin = math.inf if omega is None else float(np.min((closing + I_f * q2 * omega * omega) / a))
    return jump, margin


def test_the_vectorised_cam_is_the_hand_written_one():
    s, s2 = lift_grid()
    for j in range(0, len(GRID), 9973):
        assert (s[j], s2[j]) == pytest.approx(lift(float(GRID[j]))[::2], rel=1e-12, abs=1e-15)


# a translating flat face's gravity is the roller's F_gx: tilted, it is checked against the roller below
@pytest.mark.parametrize("kind, gamma", [(kind, math.pi) for kind in KINDS]
                         + [("oscillating_roller", 1.2), ("oscillating_flat", 1.2)])
def test_the_jump_speed_of_every_kind_is_its_closed_form(kind, gamma):
    params = dict(BASE, **KINDS[kind], **SPRING, gamma=gamma)
    exact, _ = brute_force(kind, params)
    out = report(params, None, None, 1.5)
    assert out["omega_jump"] == pytest.approx(exact, rel=1e-8)
    q = coordinate(kind, out["theta_jump"])[0]
    assert (out["psi_jump"] == pytest.approx(q, rel=1e-12)) if kind.startswith("oscillating") \
        else out["psi_jump"] is None
    for ratio, held in ((0.98, True), (1.02, False)):
        omega = ratio * exact
        seen = report(params, omega, None, 1.5)
        assert (seen["margin_N"] > 0.0) == held
        assert seen["margin_N"] == pytest.approx(brute_force(kind, params, omega)[1], rel=1e-8, abs=1e-9)
        assert seen["speed_ratio"] == pytest.approx(1.0 / ratio, rel=1e-8)


def test_a_flat_face_jumps_as_the_roller_on_the_same_cam():
    """A translating flat face and a translating roller have the same s(theta), mass and spring: the same jump,
    tilted (gravity along X) too; physics.follower.jump_speed computes the roller's."""
    for extra in ({}, {"gamma": 1.2, "beta": 0.3}):
        params = dict(BASE, **SPRING, **extra)
        roller = DriveModel(dict(params, drive="speed"))
        expected = jump_speed(roller.program, roller.m, roller.k_spring, roller.F_spring0, roller.F_gx, 0.0)
        flat = report(dict(params, follower_type="translating_flat"), None, None, 1.5)
        assert flat["omega_jump"] == pytest.approx(expected.omega_jump, rel=1e-12)
        assert flat["theta_jump"] == pytest.approx(expected.theta, abs=1e-9)


@pytest.mark.parametrize("kind", ["oscillating_roller", "oscillating_flat"])
def test_the_spring_sized_for_a_target_holds_it_with_its_safety(kind):
    params = dict(BASE, **KINDS[kind], **SPRING)
    target, safety = 50.0, 1.5  # beyond the scene spring's 42-46 rad/s: both answers bind at a deceleration
    out = report(params, None, target, safety)
    for sized in (dict(params, F_spring0=out["preload_N"]), dict(params, k_spring=out["k_spring_N_per_m"])):
        assert brute_force(kind, sized)[0] == pytest.approx(math.sqrt(safety) * target, rel=1e-6)


def test_an_arm_held_by_its_weight_alone_and_one_it_cannot_hold():
    """Without a spring a tilted arm is closed by its weight torque W cos(psi + psi_0): the brute force's jump while
    psi + psi_0 < pi / 2 everywhere; beyond that the arm falls off at rest (omega_jump = 0, said why)."""
    params = dict(BASE, **KINDS["oscillating_roller"], **dict(SPRING, F_spring0=0.0, k_spring=0.0), gamma=1.2)
    out = report(params, None, None, 1.5)
    assert out["omega_jump"] == pytest.approx(brute_force("oscillating_roller", params)[0], rel=1e-8)
    over = report(dict(params, psi_0=1.4), None, None, 1.5)  # psi + psi_0 reaches 1.7 rad > pi / 2
    assert over["omega_jump"] == 0.0 and "not held even at rest" in over["reason"]


def test_a_groove_and_a_spring_with_a_clearance_are_refused_with_their_reason():
    params = dict(BASE, **KINDS["oscillating_flat"], **SPRING)
    with pytest.raises(ValueError, match="closure 'kinematic'"):
        report(dict(params, closure="kinematic", k_spring=0.0, F_spring0=0.0), None, None, 1.5)
    with pytest.raises(ValueError, match="'c' = 0.001 m: closure 'spring'"):
        report(dict(params, c=1e-3), None, None, 1.5)


def test_the_command_runs_a_spring_closed_rocker(tmp_path):
    """The shipped rocker scene closed by a spring: the command's JSON is report()'s, its figure written."""
    sets = ["--set", "closure=spring", "--set", "k_spring=2000", "--set", "F_spring0=20"]
    done = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "jump", "packaging_rocker", *sets, "--rpm", "60",
                           "--json", "--out", str(tmp_path)], capture_output=True, text=True, cwd=tmp_path,
                          env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=300)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    from cam_fmu.experiments.scenes import find_scene

    params = dict(find_scene("packaging_rocker").primary.params, closure="spring", k_spring=2000.0, F_spring0=20.0)
    expected = report(params, 2.0 * math.pi, None, 1.5)
    assert out["omega_jump"] == expected["omega_jump"] and out["psi_jump"] == expected["psi_jump"]
    assert out["margin_N"] == expected["margin_N"]
    assert (tmp_path / "packaging_rocker_jump.png").stat().st_size > 10_000
