"""The frequency response (control.frequency, `cam-fmu bode`): the C engine's small-signal response against
the analytic transfer function of the linearised drive (docs/model.md 12.3), and that model against the
two-mass closed forms of section 12.3."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from cam_fmu.control.frequency import analytic_response, linear_model
from cam_fmu.experiments.frequency import measured_response
from cam_fmu.control.reflect import two_mass_frequencies
from cam_fmu.experiments.scenes import find_scene
from cam_fmu.physics.drive import DriveModel

SCENE = find_scene("compliant_shaft")
SHAFT = dict(SCENE.parameters, **SCENE.runs[0].overrides)
F = np.geomspace(3.0, 700.0, 6)  # Hz: below, around and above the resonance (207-363 Hz) and anti-resonance


def _difference(measured, exact) -> float:
    """The largest |measured - exact| relative to the peak of |exact| over the sweep."""
    return float(np.max(np.abs(measured - exact)) / np.max(np.abs(exact)))


@pytest.mark.parametrize("name, params, theta_deg, tol_motor", [
    ("compliant, constant s'", SHAFT, 60.0, 2e-3),
    ("compliant, L = 2 mH", dict(SHAFT, L=2e-3), 60.0, 2e-3),
    ("compliant, gravity's stiffness", dict(SHAFT, gamma=math.pi / 2, beta=math.pi, G=1.0), 20.0, 2e-3),
    ("rigid", dict(SHAFT, k_shaft=0.0), 60.0, 2e-3),
])
def test_the_engine_responds_as_the_linearised_drive_at_a_frozen_angle(name, params, theta_deg, tol_motor):
    theta0 = math.radians(theta_deg)
    exact = analytic_response(params, theta0, F)
    seen = measured_response(params, F, theta0=theta0)
    assert _difference(seen.motor, exact.motor) < tol_motor, name
    assert _difference(seen.cam, exact.cam) < 1e-4, name
    assert seen.u0 == exact.u0


def test_a_turning_drive_without_follower_is_the_linear_two_mass_system():
    """Without a follower the drive is linear while it turns (the shaft friction is a constant torque), so
    the response at a mean speed is the frozen one, at any angle."""
    params = dict(SHAFT, follower_inertia=False, gravity=False, guide_friction=False)
    seen = measured_response(params, F, u0=3.5)
    exact = analytic_response(params, 0.0, F)
    assert _difference(seen.motor, exact.motor) < 1e-3 and _difference(seen.cam, exact.cam) < 1e-3
    assert "turning under u0 = 3.5 V" in seen.note


def test_the_linear_model_has_the_two_mass_resonance_of_the_closed_form():
    """The oscillatory poles of the linearised drive (no back-EMF to speak of, no damping) sit at the
    resonance f_r of docs/model.md 12.3, and |H_motor| dips to nothing at the anti-resonance f_a."""
    quiet = dict(SHAFT, d_shaft=0.0, c_e=1e-6)
    for theta_deg in (0.0, 60.0, 100.0):
        theta0 = math.radians(theta_deg)
        A, _, _ = linear_model(quiet, theta0)
        pole = max(np.linalg.eigvals(A).imag) / (2.0 * math.pi)
        model = DriveModel(quiet)
        s1 = model.program.derivatives(theta0)[1]
        f_r, f_a = two_mass_frequencies(model.k_shaft, model.J_m, model.J_0 + model.m * s1 * s1)
        assert pole == pytest.approx(f_r, rel=1e-6)
        dip = analytic_response(quiet, theta0, [0.9 * f_a, f_a, 1.1 * f_a]).motor
        assert abs(dip[1]) < 1e-6 * min(abs(dip[0]), abs(dip[2]))


def test_an_unstable_standstill_and_a_cam_that_does_not_turn_are_refused():
    tilted = dict(SHAFT, gamma=math.pi / 2, beta=math.pi, G=1.0)
    with pytest.raises(ValueError, match="k_g"):
        measured_response(tilted, [10.0], theta0=math.radians(170.0))
    with pytest.raises(ValueError, match="does not turn"):
        measured_response(SHAFT, [10.0], u0=0.5)


def test_the_bode_command_writes_its_table_and_summary(tmp_path):
    done = subprocess.run([sys.executable, "-m", "cam_fmu", "bode", "compliant_shaft", "--theta", "60", "--fmin", "5",
                           "--fmax", "500", "--points", "4", "--json", "--out", str(tmp_path)],
                          capture_output=True, text=True, check=True)
    summary = json.loads(done.stdout)
    assert summary["motor_difference"] < 2e-3 and summary["cam_difference"] < 1e-4
    assert "frozen at theta0 = 1.0472 rad" in summary["operating_point"]
    lines = (tmp_path / "compliant_shaft_bode.csv").read_text().splitlines()
    assert lines[0].startswith("f [Hz],motor_gain [(rad/s)/V],motor_phase [deg]") and len(lines) == 5
    assert (tmp_path / "compliant_shaft_bode.png").stat().st_size > 10000
