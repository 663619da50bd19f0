"""The display units of an FMU's modelDescription.xml read back and checked against the closed conversions
(tests/fmu_cs/test_display_units.py for cam.fmu and pi_speed.fmu, tests/fmi3/test_display_units3.py for cam3.fmu).

CLOSED is written from the units' definitions, not from cam_fmu: display value = factor * SI value."""
from __future__ import annotations

import math
import zipfile
from pathlib import Path

from lxml import etree

import fmpy

CLOSED = {  # display unit -> (its SI unit, factor)
    "rpm": ("rad/s", 60.0 / (2.0 * math.pi)), "deg/s": ("rad/s", 180.0 / math.pi),
    "deg": ("rad", 180.0 / math.pi), "rev": ("rad", 1.0 / (2.0 * math.pi)),
    "deg/s2": ("rad/s2", 180.0 / math.pi),
    "mm": ("m", 1000.0), "cm": ("m", 100.0), "um": ("m", 1e6),
    "mm/s": ("m/s", 1000.0), "mm/s2": ("m/s2", 1000.0),
    "ms": ("s", 1000.0), "us": ("s", 1e6),
    "mV": ("V", 1000.0), "mA": ("A", 1000.0), "mH": ("H", 1000.0), "uH": ("H", 1e6),
    "mOhm": ("Ohm", 1000.0), "kOhm": ("Ohm", 1e-3),
    "V/rpm": ("V/(rad/s)", 2.0 * math.pi / 60.0),  # V per rpm = V per (rad/s) x (rad/s per rpm)
    "N.m/deg": ("N.m/rad", math.pi / 180.0),
    "mN.m": ("N.m", 1000.0), "kN": ("N", 1e-3), "N/mm": ("N/m", 1e-3),
    "g": ("kg", 1000.0), "g.cm2": ("kg.m2", 1000.0 * 100.0 ** 2),
}
# the SI base-unit exponents of the units that carry a display unit by default
BASE = {"m": {"m": "1"}, "rad": {"rad": "1"}, "rad/s": {"rad": "1", "s": "-1"}}
# what a variable shows by default: its SI unit's display unit (issue 42: rpm, deg, mm)
SHOWN = {"rad/s": "rpm", "rad": "deg", "m": "mm"}


def model_description(fmu: Path) -> bytes:
    with zipfile.ZipFile(fmu) as z:
        return z.read("modelDescription.xml")


def schema_problems(xml: bytes, version: str) -> list[str]:
    """The FMI XSD's complaints about ``xml`` (the schemas fmpy ships: fmi2/fmi2ModelDescription.xsd, fmi3/...)."""
    folder = Path(fmpy.__file__).parent / "schema" / f"fmi{version}"
    schema = etree.XMLSchema(file=str(folder / f"fmi{version}ModelDescription.xsd"))
    ok = schema.validate(etree.fromstring(xml))
    return [] if ok else [f"{e.line}: {e.message}" for e in schema.error_log]


def real_variables(root, version: str) -> dict:
    """name -> the element carrying unit/displayUnit/declaredType (FMI 2.0: <Real>, FMI 3.0: <Float64>)."""
    if version == "2":
        return {sv.get("name"): sv.find("Real") for sv in root.find("ModelVariables")
                if sv.find("Real") is not None}
    return {v.get("name"): v for v in root.find("ModelVariables") if v.tag == "Float64"}


def check_display_units(xml: bytes, version: str) -> dict[str, str]:
    """Assert every unit definition and every displayed variable against CLOSED, BASE and SHOWN; return
    {variable: display unit} of the variables shown in another unit than SI."""
    root = etree.fromstring(xml)
    units = {u.get("name"): u for u in root.find("UnitDefinitions")}
    for name, unit in units.items():
        for display in unit.findall("DisplayUnit"):
            si, factor = CLOSED[display.get("name")]
            assert si == name, (display.get("name"), name)
            assert math.isclose(float(display.get("factor")), factor, rel_tol=1e-15), display.get("name")
            assert float(display.get("offset", "0")) == 0.0
        if name in BASE:
            assert dict(unit.find("BaseUnit").attrib) == BASE[name]
    types = {}
    for t in root.find("TypeDefinitions"):
        typed = t.find("Real") if version == "2" else t
        types[t.get("name")] = typed
    shown = {}
    for name, var in real_variables(root, version).items():
        unit = var.get("unit")
        display = var.get("displayUnit")
        assert display == SHOWN.get(unit), (name, unit, display)
        if unit and unit != "1":
            declared = types[var.get("declaredType")]
            assert declared.get("unit") == unit and declared.get("displayUnit") == display, name
        if display is not None:
            assert display in {d.get("name") for d in units[unit].findall("DisplayUnit")}, name
            shown[name] = display
    return shown
