"""cam3.fmu's display units (FMI 3.0 <UnitDefinitions>/<DisplayUnit>, <Float64Type>s, the variables' declaredType,
unit and displayUnit): read back from the built FMU, checked against the closed conversions (tests/display_units.py),
the FMI 3.0 XSD and fmpy's validation; the same units as cam.fmu's."""
from __future__ import annotations

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
