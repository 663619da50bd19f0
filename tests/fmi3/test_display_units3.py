"""cam3.fmu's display units (FMI 3.0 <UnitDefinitions>/<DisplayUnit>, <Float64Type>s, the variables' declaredType,
unit and displayUnit): read back from the built FMU, checked against the closed conversions (tests/display_units.py),
the FMI 3.0 XSD and fmpy's validation; the same units as cam.fmu's."""
from __future__ import annotations

import math

from fmpy import read_model_description
from fmpy.validation import validate_fmu

from display_units import check_display_units, model_description, schema_problems


def test_cam3_fmu_shows_speeds_in_rpm_angles_in_degrees_and_lengths_in_mm(cam3_fmu_path, cam_fmu_path):
    xml = model_description(cam3_fmu_path)
    assert schema_problems(xml, "3") == []
    assert validate_fmu(str(cam3_fmu_path)) == []
    shown = check_display_units(xml, "3")
    assert {shown[n] for n in ("omega", "omega_m", "omega0", "omega_ref")} == {"rpm"}
    assert {shown[n] for n in ("theta", "theta_m", "alpha", "theta0", "gamma")} == {"deg"}
    assert {shown[n] for n in ("s", "s_cam", "c", "lift", "r_b")} == {"mm"}
    # every variable shows as in cam.fmu (Model Exchange's states too); FMI 3.0's event indicators are variables,
    # the angle to the next breakpoint in degrees
    shown2 = check_display_units(model_description(cam_fmu_path), "2")
    assert {name: unit for name, unit in shown.items() if not name.startswith("z_")} == shown2
    assert shown["z_breakpoint"] == "deg" and shown["x_omega"] == "rpm" and shown["x_gap"] == "mm"


def test_fmpy_reads_cam3s_display_units_and_their_factors(cam3_fmu_path):
    md = read_model_description(str(cam3_fmu_path), validate=True)
    factors = {(u.name, d.name): d.factor for u in md.unitDefinitions for d in u.displayUnits}
    variables = {v.name: v for v in md.modelVariables}
    for name, display, closed in (("omega", "rpm", 60.0 / (2.0 * math.pi)), ("theta", "deg", 180.0 / math.pi),
                                  ("s", "mm", 1000.0), ("c", "mm", 1000.0)):
        v = variables[name]
        assert v.displayUnit == display and v.declaredType.displayUnit == display
        assert math.isclose(factors[(v.unit, display)], closed, rel_tol=1e-15)
