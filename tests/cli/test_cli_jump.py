"""`cam-fmu jump` against the closed form, the scenes of the follower as a body of its own, and the commands that
refuse a follower that can leave the cam (docs/model.md section 13).

With k_spring = 0 and no guide friction on a horizontal mounting the closing force is the preload F0 alone, and the
paper's cam decelerates at most by s'' = -4 A (docs/model.md section 2: s'' = 4 A sin 4 theta on its transition
pieces), so omega_jump = sqrt(F0 / (4 A m)), the least contact force at omega is F0 - 4 A m omega^2, and the preload
that holds omega_t with the force safety factor S is S 4 A m omega_t^2.
"""
from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cam_fmu.experiments.scenes import find_scene
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.follower import jump_speed

ROOT = Path(__file__).resolve().parents[2]
A, MASS, F0 = 0.035, 0.4, 20.0
PRELOAD_ONLY = ["--set", "k_spring=0", "--set", "mu=0"]


def cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "cam_fmu.cli", *args], capture_output=True, text=True, cwd=cwd,
                          env={**os.environ, "PYTHONPATH": str(ROOT), "CAM_FMU_PROGRESS": "0"}, timeout=300)


def test_jump_is_the_closed_form(tmp_path):
    omega_jump = math.sqrt(F0 / (4 * A * MASS))
    rpm = 0.98 * omega_jump * 60 / (2 * math.pi)
    done = cli("jump", "spring_jump", *PRELOAD_ONLY, "--rpm", repr(rpm), "--target-rpm", "300", "--safety", "1.2",
               "--json", "--out", str(tmp_path), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert out["omega_jump"] == pytest.approx(omega_jump, rel=1e-3)  # the bound; it agrees to 1e-9
    assert out["omega_jump"] == pytest.approx(omega_jump, rel=1e-9)
    assert out["rpm_jump"] == pytest.approx(omega_jump * 60 / (2 * math.pi), rel=1e-9)
    assert out["margin_N"] == pytest.approx(F0 * (1 - 0.98 ** 2), rel=1e-9)
    assert out["speed_ratio"] == pytest.approx(1 / 0.98, rel=1e-9)
    target = 300 * 2 * math.pi / 60
    assert out["preload_N"] == pytest.approx(1.2 * 4 * A * MASS * target ** 2, rel=1e-9)
    assert (tmp_path / "spring_jump_jump.png").stat().st_size > 10000


def test_jump_prints_its_results(tmp_path):
    done = cli("jump", "spring_jump", "--rpm", "600", "--target-rpm", "500", "--no-plot", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "omega_jump: 61.22" in done.stdout and "the follower leaves the cam" in done.stdout
    assert "to hold 500 1/min with safety 1.5" in done.stdout


@pytest.mark.parametrize("args, message", [
    (["jump", "groove_crossover"], "it does not jump"),
    (["jump", "spring_jump", "--safety", "0.5"], "--safety 0.5"),
    (["jump", "spring_jump", "--rpm", "-3"], "--rpm -3"),
    (["reflect", "spring_jump"], "`cam-fmu jump spring_jump`"),
    (["bode", "paper_fig6", "--set", "closure=spring"], "no small-signal model"),
    # a groove with a clearance (closure 'form', the default): the follower can fly; the paper's rule on request
    (["reflect", "backlash"], "closure 'form'"), (["reflect", "backlash"], "--set closure=kinematic"),
    (["bode", "backlash"], "closure 'form'"), (["bode", "backlash"], "--set closure=kinematic"),
])
def test_refusals_say_why(args, message, tmp_path):
    done = cli(*args, "--out", str(tmp_path), cwd=tmp_path)
    assert done.returncode == 2 and message in done.stderr and "Traceback" not in done.stderr, done.stderr


@pytest.mark.parametrize("scene, sets", [
    ("backlash", []),  # closure 'form' with a clearance: `jump` refuses a groove, so reflect must not advise it
    ("backlash", ["--set", "c=1e-3", "--set", "m=0.5"]),
    ("spring_jump", []),
    ("paper_fig6", ["--set", "closure=spring", "--set", "F_spring0=30"]),
])
def test_reflect_advises_only_commands_that_run_on_the_scene(scene, sets, tmp_path):
    """Every command the refusal advises is run as written (with --out and --no-plot added) and succeeds; for a
    groove (closure 'form') that is not `cam-fmu jump`, which refuses it."""
    import shlex

    done = cli("reflect", scene, *sets, "--out", str(tmp_path / "refused"), cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    advised = re.findall(r"`(cam-fmu [^`]+)`", done.stderr)
    closure = "spring" if "closure=spring" in sets or scene == "spring_jump" else "form"
    assert [shlex.split(c)[1] for c in advised] == (["jump"] if closure == "spring" else ["reflect", "simulate"])
    for k, command in enumerate(advised):
        words = shlex.split(command)
        assert words[2] == scene and " ".join(sets) in command
        ran = cli(*words[1:], "--out", str(tmp_path / str(k)), "--no-plot", cwd=tmp_path)
        assert ran.returncode == 0, (command, ran.stderr)
        assert ran.stdout.strip()


def test_a_spring_beyond_the_parameters_ranges_is_refused_naming_them(tmp_path):
    """1e6 1/min with safety 100 needs a preload S 4 A m omega^2 (k_spring = 0) far beyond F_spring0's range and a
    rate beyond k_spring's (the answers were 6.1e10 N and 3.8e11 N/m with exit 0): exit 2, each parameter named with
    the value needed and its range from the parameter table; even the stiffest spring in range leaves the follower at
    sqrt(S) times the target (the contact margin, computed apart from the sizing, is < 0)."""
    from cam_fmu.physics.follower import contact_margin
    from cam_fmu.physics.parameters import BY_NAME

    done = cli("jump", "spring_jump", *PRELOAD_ONLY, "--target-rpm", "1e6", "--safety", "100", "--no-plot",
               cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    omega = 1e6 * 2 * math.pi / 60
    preload = 100 * 4 * A * MASS * omega ** 2
    assert preload > 10 * BY_NAME["F_spring0"].high
    assert f"F_spring0 would have to be {preload:.6g} N at k_spring = 0 N/m, allowed {BY_NAME['F_spring0'].allowed()}" \
        in done.stderr, done.stderr
    assert f"k_spring would have to be" in done.stderr and BY_NAME["k_spring"].allowed() in done.stderr
    assert "no spring in range does it" in done.stderr
    model = DriveModel(dict(find_scene("spring_jump").primary.params, mu=0.0))
    stiffest = contact_margin(model.program, 10.0 * omega, model.m, BY_NAME["k_spring"].high,
                              BY_NAME["F_spring0"].high, model.F_gx)[0]
    assert stiffest < 0.0


def test_an_answer_beyond_its_range_is_withheld_and_the_other_kept(tmp_path):
    """At 40000 1/min (safety 1.5, k_spring = 0) the preload S 4 A m omega^2 = 1.47e6 N is beyond F_spring0's range:
    null with the reason; the rate at the scene's preload is in range and holds (margin >= 0 at sqrt(S) omega)."""
    from cam_fmu.physics.follower import contact_margin
    from cam_fmu.physics.parameters import BY_NAME

    done = cli("jump", "spring_jump", *PRELOAD_ONLY, "--target-rpm", "40000", "--json", "--no-plot", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    omega = 40000 * 2 * math.pi / 60
    preload = 1.5 * 4 * A * MASS * omega ** 2
    assert BY_NAME["F_spring0"].high < preload < 2 * BY_NAME["F_spring0"].high
    assert out["preload_N"] is None and f"F_spring0 would have to be {preload:.6g} N" in out["beyond_range"]
    assert BY_NAME["F_spring0"].allowed() in out["beyond_range"] and "k_spring would" not in out["beyond_range"]
    k = out["k_spring_N_per_m"]
    assert 0.0 < k <= BY_NAME["k_spring"].high
    model = DriveModel(dict(find_scene("spring_jump").primary.params, mu=0.0))
    margin = contact_margin(model.program, math.sqrt(1.5) * omega, model.m, k, F0, model.F_gx)[0]
    assert abs(margin) < 1e-9 * k * model.program.derivatives(math.pi)[0]   # just held: the least rate (of k h)


def test_reflect_says_what_it_assumes(tmp_path):
    done = cli("reflect", "backlash", "--set", "closure=kinematic", "--json", "--no-plot", "--out", str(tmp_path),
               cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "a clearance c is ignored" in json.loads(done.stdout)["assumes"]


def test_spring_jump_runs_just_below_and_above_the_jump_speed(reference_runs):
    """The scene's speed is 0.98 and 1.02 times its runs' jump speeds; the reference keeps the follower on the cam in
    the first and lets it fly in the second."""
    scene = find_scene("spring_jump")
    results = reference_runs.scene(scene)
    omega = scene.omega_ref.value(0.0)
    for run, ratio in zip(scene.runs, (0.98, 1.02)):
        model = DriveModel(run.params)
        jump = jump_speed(model.program, model.m, model.k_spring, model.F_spring0, model.F_gx,
                          model.mu * (abs(model.G_y) + model.N_g))
        assert omega / jump.omega_jump == pytest.approx(ratio, abs=1e-4)
        r = results[run.label]
        lost = np.any(r["contact"] == 0.0)
        assert lost == (ratio > 1.0) and np.all(r["s"] >= r["s_cam"] - 1e-12)


def test_bounce_and_crossover_scenes_show_their_effect(reference_runs):
    bounce = reference_runs.scene(find_scene("spring_bounce"))
    assert bounce["e_0.5"]["impacts"][-1] > 2 * bounce["e_0"]["impacts"][-1] > 0  # e = 0.5 bounces, e = 0 lands
    assert bounce["e_0.5"]["contact"][-1] == 1.0  # and settles
    groove = reference_runs.scene(find_scene("groove_crossover"))
    form, kinematic = groove["form"], groove["kinematic"]
    assert -1.0 in form["contact"] and form["impacts"][-1] >= 1  # it crossed the clearance and struck
    # the crossover shock: on the rise's deceleration (pi/2 < theta < pi) the follower's velocity jumps by 0.13 m/s at
    # the upper flank; the kinematic rule has the lower flank pull it smoothly to the stroke's end
    decelerating = (form["theta"][1:] > math.pi / 2) & (form["theta"][1:] < math.pi)
    smooth = np.max(np.abs(np.diff(kinematic["v"]))[decelerating])
    assert np.max(np.abs(np.diff(form["v"]))[decelerating]) > 0.1 > 50 * smooth > 0.0


def test_the_reference_columns_have_units():
    from cam_fmu.experiments.columns import header

    assert header("N_contact") == "N_contact [N]" and header("impacts") == "impacts [1]"
