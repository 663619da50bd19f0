"""A value with its unit: `--set NAME=VALUE[UNIT]` in every command that takes it (simulate, bode, reflect, jump,
cosim), `--vary` in sweep, and a scene file's `name = "VALUE UNIT"`: one parser (physics/units.py through
ParameterSpec.check) converts to the parameter's SI unit and refuses a unit of another quantity, naming the
parameter's unit and the units it accepts. Values are compared with the closed conversions
(rpm = rad/s * 60 / (2 pi), deg = rad * 180 / pi, mm = m * 1000)."""
from __future__ import annotations

import csv
import math
import subprocess

import pytest

from cam_fmu.experiments.scenes import SceneError, find_scene, load_scene

RPM_600 = 600.0 * 2.0 * math.pi / 60.0  # rad/s
C_REFUSED = "c is a length in m; give m, mm, cm, um (not 'rpm')"


@pytest.mark.parametrize("args, command", [
    (["simulate", "paper_fig6", "--set", "c=3rpm"], "simulate"),
    (["bode", "paper_fig6", "--set", "c=3rpm"], "bode"),
    (["reflect", "paper_fig6", "--set", "c=3rpm"], "reflect"),
    (["jump", "spring_jump", "--set", "c=3rpm"], "jump"),
    (["cosim", "--set", "cam.c=3rpm", "--no-plot"], "cosim"),
    (["sweep", "paper_fig6", "--vary", "c=0:3rpm:3"], "sweep"),
], ids=["simulate", "bode", "reflect", "jump", "cosim", "sweep"])
def test_every_command_refuses_a_unit_of_another_quantity_naming_the_parameters_unit(args, command, tmp_path):
    proc = subprocess.run(["cam-fmu", *args, "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"cam-fmu {command}: error: ") and C_REFUSED in lines[0], lines


def test_cosim_converts_the_controllers_setpoint_and_refuses_a_length(tmp_path):
    from cam_fmu.control import pi

    assert math.isclose(pi.BY_NAME["omega_set"].check("600rpm"), RPM_600, rel_tol=1e-15)
    proc = subprocess.run(["cam-fmu", "cosim", "--set", "controller.omega_set=3mm", "--no-plot", "--out",
                           str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2
    assert "omega_set is an angular velocity in rad/s; give rad/s, rpm, deg/s (not 'mm')" in proc.stderr


def test_simulate_starts_from_values_given_in_rpm_and_degrees(tmp_path):
    """End to end: the first CSV row (t = 0) holds the initial speed and angle set in rpm and deg, in SI."""
    proc = subprocess.run(["cam-fmu", "simulate", "paper_fig6", "--stop-time", "0.01", "--no-plot", "--out",
                           str(tmp_path), "--set", "omega0=600rpm", "--set", "theta0=90deg", "--set", "c=0.5mm",
                           "--set", "closure=kinematic"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    with open(tmp_path / "paper_fig6.csv", newline="") as fh:
        first = next(csv.DictReader(fh))
    assert math.isclose(float(first["omega [rad/s]"]), RPM_600, rel_tol=1e-11)  # %.12g in the CSV
    assert math.isclose(float(first["theta [rad]"]), math.pi / 2.0, rel_tol=1e-11)


def test_set_converts_to_the_parameters_unit_as_a_plain_number_would_be_taken():
    from cam_fmu.cli.simulate import apply_sets

    scene = apply_sets(find_scene("paper_fig6"), ["omega0=600rpm", "c=0.5 mm", "gamma=90deg", "r_b=12cm",
                                                  "L=2mH", "J_m=441g.cm2", "k_spring=3N/mm"])
    params = scene.primary.params
    closed = {"omega0": RPM_600, "c": 0.5 / 1000.0, "gamma": 90.0 * math.pi / 180.0, "r_b": 0.12, "L": 2e-3,
              "J_m": 441.0 / 1e7, "k_spring": 3000.0}
    for name, value in closed.items():
        assert math.isclose(params[name], value, rel_tol=1e-15), name
    plain = apply_sets(find_scene("paper_fig6"), [f"{name}={value!r}" for name, value in params.items()
                                                  if name in closed])
    assert {n: plain.primary.params[n] for n in closed} == {n: params[n] for n in closed}


@pytest.mark.parametrize("text, message", [
    ("mu=3mm", "mu is dimensionless: give a plain number, not 'mm'"),
    ("omega0=5furlong", "omega0 is an angular velocity in rad/s; give rad/s, rpm, deg/s (not 'furlong')"),
    ("gamma=1rpm", "gamma is an angle in rad; give rad, deg, rev (not 'rpm')"),
    ("c=500mm", "'c' = 0.5 [m] (given '500mm') is outside the allowed range [0, 0.1] m"),
    ("c=mm", "'c' = 'mm' is not a number"),
    ("rise_law=3mm", "allowed one of"),
], ids=["dimensionless", "unknown-unit", "angle-in-rpm", "out-of-range", "no-number", "text-parameter"])
def test_set_refuses_with_the_reason(text, message):
    from cam_fmu.cli.simulate import apply_sets

    with pytest.raises(ValueError) as info:
        apply_sets(find_scene("paper_fig6"), [text])
    assert message in str(info.value)


def test_sweep_takes_values_and_bounds_with_units():
    from cam_fmu.experiments.sweep_cases import parse_vary

    grid = parse_vary("c=0mm:0.5mm:3")
    assert grid.values == (0.0, 0.25e-3, 0.5e-3)
    assert math.isclose(parse_vary("omega0=0:600rpm").high, RPM_600, rel_tol=1e-15)
    assert parse_vary("c=0.1mm,0.2mm").values == (0.1e-3, 0.2e-3)


SCENE = """description = "units"
u = 3.5
stop_time = 0.01
output_interval = 1e-3

[parameters]
"""


def test_a_scene_file_takes_a_value_with_its_unit_as_text(tmp_path):
    path = tmp_path / "units.toml"
    path.write_text(SCENE + 'omega0 = "600 rpm"\nc = "0.5mm"\nclosure = "kinematic"\n'
                    '\n[[runs]]\nlabel = "tilted"\ngamma = "90 deg"\n')
    run = load_scene(path).primary
    assert math.isclose(run.params["omega0"], RPM_600, rel_tol=1e-15) and run.params["c"] == 0.5e-3
    assert math.isclose(run.params["gamma"], math.pi / 2.0, rel_tol=1e-15)
    assert run.overrides["omega0"] == run.params["omega0"]  # what every engine reads: the SI number
    path.write_text(SCENE + 'c = "3rpm"\n')
    with pytest.raises(SceneError, match="c is a length in m; give m, mm, cm, um"):
        load_scene(path)
