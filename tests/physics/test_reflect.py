"""The reflected-load map (control.reflect, `cam-fmu reflect`) against closed forms.

The paper's cam (docs/model.md section 2) in closed form (tests/test_drive_closed_form.paper_profile):
J(theta) = J_m + m s'^2 with peak J_m + m (2 A)^2 where s' = 2 A; the inertial torque m s'' omega^2 s';
gravity -F_gx s'; the guide friction from a fixed-point iteration, a method independent of the
two-branch solve; the parts add up to the load torque of the drive model.
"""
from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from cam_fmu.control.reflect import PARTS, RESONANCE_KEYS, reflected_map, summary
from cam_fmu.physics.drive import DriveModel
from test_drive_closed_form import A, DEFAULTS, friction_fixed_point, paper_profile

TILTED = {"gamma": math.radians(100.0), "beta": math.radians(30.0), "mu": 0.05}


@pytest.mark.parametrize("params", [{}, TILTED], ids=["horizontal", "tilted"])
@pytest.mark.parametrize("rpm", [60.0, -300.0])
def test_the_map_is_the_closed_form(params, rpm):
    result = reflected_map(params, rpm, points=720)
    model = DriveModel(params)
    omega = rpm * 2.0 * math.pi / 60.0
    d = 1.0 if omega > 0 else -1.0
    for k, theta in enumerate(result["theta"]):
        s, s1, s2 = paper_profile(float(theta))
        assert result["J"][k] == pytest.approx(DEFAULTS["J_m"] + DEFAULTS["m"] * s1 * s1, rel=1e-12)
        assert result["M_inertial"][k] == pytest.approx(DEFAULTS["m"] * s2 * omega ** 2 * s1, rel=1e-9, abs=1e-15)
        assert result["M_gravity"][k] == pytest.approx(-model.F_gx * s1, rel=1e-9, abs=1e-15)
        tan_a = s1 / (model.r_b + s)
        sigma = math.copysign(1.0, s1 * d) if s1 != 0.0 else 0.0
        push = DEFAULTS["m"] * s2 * omega ** 2 - model.F_gx
        f = friction_fixed_point(push * tan_a + model.G_y, tan_a, sigma, model.mu, model.N_g)
        assert result["M_guide"][k] == pytest.approx(sigma * f * s1, rel=1e-9, abs=1e-15)
        assert result["M_shaft"][k] == DEFAULTS["M_f"] * d
        total = sum(result[part][k] for part in PARTS)
        assert result["M"][k] == pytest.approx(total, rel=1e-12, abs=1e-15)


def test_the_extremes_and_where_they_are():
    result = reflected_map({}, 60.0, points=3600)
    found = summary(result, 60.0)
    assert found["J_max"] == pytest.approx(DEFAULTS["J_m"] + DEFAULTS["m"] * (2 * A) ** 2, rel=1e-9)
    assert found["J_min"] == pytest.approx(DEFAULTS["J_m"], rel=1e-12)
    for key in ("J", "M"):  # each extreme is the value at its angle
        for end in ("min", "max"):
            k = int(np.argmin(np.abs(result["theta"] - found[f"theta_{key}_{end}"])))
            assert result[key][k] == found[f"{key}_{end}"]
    assert found["M_max"] > found["M_min"]
    assert all(found[key] is None for key in RESONANCE_KEYS)  # the drive-train is rigid


@pytest.mark.parametrize("rpm", [0.0, math.nan, 1e9])
def test_a_bad_speed_names_the_option(rpm):
    with pytest.raises(ValueError, match="--rpm"):
        reflected_map({}, rpm)


def test_the_command_writes_the_map_and_its_json(tmp_path):
    cmd = [sys.executable, "-m", "cam_fmu.cli", "reflect", "paper_fig6", "--rpm", "120", "--json", "--out",
           str(tmp_path), "--set", "m=0.8"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    found = json.loads(proc.stdout.strip().splitlines()[-1])
    for key in ("J_min", "J_max", "M_min", "M_max", *RESONANCE_KEYS):
        assert key in found and f"theta_{key}" in found
    assert found["J_max"] == pytest.approx(DEFAULTS["J_m"] + 0.8 * (2 * A) ** 2, rel=1e-9)  # --set m=0.8 applied
    header = (tmp_path / "paper_fig6_reflect.csv").read_text().splitlines()[0]
    assert header.startswith("theta [rad],J [kg.m2],M [N.m]")
    assert (tmp_path / "paper_fig6_reflect.png").stat().st_size > 10_000
    bad = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "reflect", "paper_fig6", "--rpm", "0", "--out",
                          str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "--rpm" in bad.stderr


SHAFT = {"k_shaft": 50.0, "d_shaft": 1e-3, "J_m": 3e-5, "J_cam": 1.41e-5}


def _modal_frequencies(k: float, J_m: float, J_c: float) -> tuple[float, float]:
    """The undamped frequencies [Hz] from the two-mass eigenproblem (numpy), not from the closed form: the
    nonzero eigenvalue of M^-1 K is the resonance; clamping the rotor leaves k / J_c, the anti-resonance."""
    stiffness = np.array([[k, -k], [-k, k]])
    inverse_mass = np.diag([1.0 / J_m, 1.0 / J_c])
    resonance = max(np.linalg.eigvals(inverse_mass @ stiffness).real)
    return math.sqrt(resonance) / (2.0 * math.pi), math.sqrt(k / J_c) / (2.0 * math.pi)


def test_a_compliant_shaft_maps_the_two_mass_frequencies_over_the_turn():
    result = reflected_map(SHAFT, 60.0, points=720)
    for k in range(0, 720, 37):
        s1 = paper_profile(float(result["theta"][k]))[1]
        J_c = SHAFT["J_cam"] + DEFAULTS["m"] * s1 * s1
        assert result["J"][k] == pytest.approx(SHAFT["J_m"] + J_c, rel=1e-12)
        f_r, f_a = _modal_frequencies(SHAFT["k_shaft"], SHAFT["J_m"], J_c)
        assert result["f_r"][k] == pytest.approx(f_r, rel=1e-9)
        assert result["f_a"][k] == pytest.approx(f_a, rel=1e-12)
    found = summary(reflected_map(SHAFT, 60.0, points=3600), 60.0)
    J_peak = SHAFT["J_cam"] + DEFAULTS["m"] * (2 * A) ** 2  # where s' = 2 A the follower weighs most
    assert found["f_a_min"] == pytest.approx(math.sqrt(SHAFT["k_shaft"] / J_peak) / (2 * math.pi), rel=1e-9)
    assert found["f_a_max"] == pytest.approx(math.sqrt(SHAFT["k_shaft"] / SHAFT["J_cam"]) / (2 * math.pi), rel=1e-12)
    assert found["theta_f_a_min"] == found["theta_J_max"] and found["theta_f_r_max"] == found["theta_J_min"]
    assert found["f_r_min"] == pytest.approx(_modal_frequencies(SHAFT["k_shaft"], SHAFT["J_m"], J_peak)[0], rel=1e-9)
    # f_r / f_a = sqrt(1 + J_c / J_m) everywhere
    assert np.allclose(result["f_r"] / result["f_a"], np.sqrt(1.0 + (result["J"] - SHAFT["J_m"]) / SHAFT["J_m"]),
                       rtol=1e-12)


def test_the_cli_reports_the_resonance_of_the_shipped_compliant_scene(tmp_path):
    done = subprocess.run([sys.executable, "-m", "cam_fmu", "reflect", "compliant_shaft", "--json", "--no-plot",
                           "--out", str(tmp_path)], capture_output=True, text=True, check=True)
    found = json.loads(done.stdout)
    assert 200.0 < found["f_r_min"] < found["f_r_max"] < 370.0 and 25.0 < found["f_a_min"] < 26.0
    header = (tmp_path / "compliant_shaft_reflect.csv").read_text().splitlines()[0]
    assert header.endswith("f_r [Hz],f_a [Hz]")


def test_a_train_is_its_low_frequency_limit_and_its_two_frequencies():
    """With a follower train the map is the end mass carried by the follower: J, M and its parts those of the drive
    with m + m_end and the end mass's weight (G + m_end g_n, mounted vertically) without a train, to rounding; f_a_train is
    sqrt(k_train / m_end) / (2 pi) and f_r_train(theta) the undamped pole of the linearised drive with the train
    (control.frequency.linear_model's eigenvalues, back-EMF and gravity off)."""
    from cam_fmu.control.frequency import linear_model
    from cam_fmu.physics.train import G_N

    # vertical: the end mass's weight acts along X only (its own guide carries nothing across; physics/train.py)
    train = {"k_train": 2e4, "m_end": 0.2, "gamma": math.pi / 2, "mu": 0.05}
    model = DriveModel(train)
    carried = {"m": model.m + 0.2, "G": model.params["G"] + 0.2 * G_N, "gamma": math.pi / 2, "mu": 0.05}
    got, rigid = reflected_map(train, 300.0, points=72), reflected_map(carried, 300.0, points=72)
    for name in ("J", "M", *PARTS):
        assert np.allclose(got[name], rigid[name], rtol=1e-12, atol=1e-15), name
    assert np.all(got["f_a_train"] == math.sqrt(2e4 / 0.2) / (2.0 * math.pi))
    quiet = {"k_train": 2e4, "m_end": 0.2, "c_e": 1e-6, "gravity": False}
    ring = reflected_map(quiet, 300.0, points=8)
    for theta, f_r in zip(ring["theta"][1:4], ring["f_r_train"][1:4]):
        A, _, _ = linear_model(quiet, float(theta))
        assert max(np.linalg.eigvals(A).imag) / (2.0 * math.pi) == pytest.approx(f_r, rel=1e-6)
    keys = summary(got, 300.0)
    assert keys["f_r_train_max"] == pytest.approx(got["f_r_train"].max()) and keys["f_r_min"] is None
