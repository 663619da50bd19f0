"""cam.fmu's and pi_speed.fmu's display units (FMI 2.0 UnitDefinitions/DisplayUnit, TypeDefinitions, the variables'
declaredType/unit/displayUnit): read back from the built FMUs, checked against the closed conversions
(tests/display_units.py), the FMI 2.0 XSD and fmpy's validation, which catches a display unit that is not defined."""
from __future__ import annotations

import math
import zipfile

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from display_units import check_display_units, model_description, schema_problems


def test_cam_fmu_shows_speeds_in_rpm_angles_in_degrees_and_lengths_in_mm(cam_fmu_path):
    xml = model_description(cam_fmu_path)
    assert schema_problems(xml, "2") == []
    shown = check_display_units(xml, "2")
    # the variables people read (issue 42), and the other lengths and angles, each in its display unit
    assert {shown[n] for n in ("omega", "omega_m", "omega0", "omega_ref")} == {"rpm"}
    assert {shown[n] for n in ("theta", "theta_m", "alpha", "theta0", "gamma", "beta", "rise_angle")} == {"deg"}
    assert {shown[n] for n in ("s", "s_cam", "c", "lift", "r_b", "x_gap")} == {"mm"}
    assert "v" not in shown and "i" not in shown and "M" not in shown  # SI where SI reads well


@pytest.mark.parametrize("fmu", ["cam_fmu_path", "cam3_fmu_path"])
def test_fmpy_reads_the_display_units_and_their_factors(request, fmu):
    """cam.fmu (FMI 2.0) and cam3.fmu (FMI 3.0) alike, as fmpy reads them."""
    md = read_model_description(str(request.getfixturevalue(fmu)), validate=True)
    factors = {(u.name, d.name): d.factor for u in md.unitDefinitions for d in u.displayUnits}
    variables = {v.name: v for v in md.modelVariables}
    for name, display, closed in (("omega", "rpm", 60.0 / (2.0 * math.pi)), ("theta", "deg", 180.0 / math.pi),
                                  ("s", "mm", 1000.0), ("c", "mm", 1000.0)):
        v = variables[name]
        assert v.displayUnit == display and v.declaredType.displayUnit == display
        assert math.isclose(factors[(v.unit, display)], closed, rel_tol=1e-15)
    # 600 rpm is 62.83... rad/s: the FMU's factor turns the SI value back into the number a user reads
    assert math.isclose(factors[("rad/s", "rpm")] * (600.0 * 2.0 * math.pi / 60.0), 600.0, rel_tol=1e-15)


def test_pi_speed_fmu_shows_its_speeds_in_rpm(pi_speed_fmu_path):
    xml = model_description(pi_speed_fmu_path)
    assert schema_problems(xml, "2") == []
    shown = check_display_units(xml, "2")
    assert shown == {"omega_meas": "rpm", "omega_setpoint": "rpm", "error": "rpm", "omega_set": "rpm"}
    assert validate_fmu(str(pi_speed_fmu_path)) == []


@pytest.mark.parametrize("change, problem", [
    (lambda xml: xml.replace(b'displayUnit="rpm" min=', b'displayUnit="furlong" min=', 1), "display unit"),
    (lambda xml: xml.replace(b'<DisplayUnit name="mm" factor="1000.0"/>', b"", 1), "display unit"),
    (lambda xml: xml.replace(b'<DisplayUnit name="deg"', b'<DisplayUnit nom="deg"', 1), "nom"),
], ids=["undefined-display-unit", "display-unit-removed", "attribute-not-in-schema"])
def test_the_validation_catches_a_broken_display_unit(cam_fmu_path, tmp_path, change, problem):
    """The checks above can fail: fmpy's validation (its XSD and unit rules) reports a display unit that is not
    defined, and the schema an attribute it does not know."""
    xml = model_description(cam_fmu_path)
    broken = change(xml)
    assert broken != xml
    with zipfile.ZipFile(cam_fmu_path) as z:
        z.extractall(tmp_path)
    (tmp_path / "modelDescription.xml").write_bytes(broken)
    problems = validate_fmu(str(tmp_path))
    assert problems and any(problem in p for p in problems), problems

