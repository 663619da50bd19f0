"""cam3.fmu's modelDescription.xml (FMI 3.0 co-simulation and Model Exchange), from the same variable table as
cam.fmu's.

Build time only. One source for names, value references, units, ranges and defaults
(``model_description.variable_rows``, generated from physics/parameters.py and variables.py), the
same unit and type definitions (display units: rpm for rad/s, deg for rad, mm for m; physics/units.py), log
categories and default experiment; what FMI 3.0 adds is used where it helps a user: the instantiation token checked
by the binary; Model Exchange's continuous states, their derivatives and its event indicators (csrc/fmi/fmi3_me.c).
No co-simulation event mode, no early return, no clocks, no arrays: the drive is a fixed set of scalars stepped
synchronously (docs/fmu.md, "cam3.fmu").
"""
from __future__ import annotations

import math
from typing import Any, Dict, List
from xml.dom.minidom import parseString
from xml.etree import ElementTree as ET

from ..physics.variables import DEPENDENCIES, EVENT_INDICATORS
from .model_description import (LOG_CATEGORIES, experiment_element, type_definitions, typed_units, unit_attributes,
                                unit_definitions)

TYPES = {"Real": "Float64", "Boolean": "Boolean", "String": "String"}


def indicator_rows() -> List[Dict[str, Any]]:
    """Model Exchange's event indicators as FMI 3.0 variables (csrc/fmi/exchange.h's slots): the mode's event
    functions, then the angle to the profile's next breakpoint; each > 0 while nothing happens."""
    rows = [dict(name=f"z_event_{k + 1}", unit="", description=f"event indicator {k + 1}: the drive mode's event "
                 f"function {k + 1} (1 where the mode has fewer)") for k in range(EVENT_INDICATORS - 1)]
    rows.append(dict(name="z_breakpoint", unit="rad", description="event indicator: the cam angle to the profile's "
                     "next breakpoint ahead"))
    return rows


def model_description(model_identifier: str, token: str, rows: List[Dict[str, Any]], experiment: tuple,
                      description: str) -> bytes:
    """The FMI 3.0 model description of ``rows`` (value reference = row index), pretty-printed UTF-8.

    Co-simulation, and Model Exchange where the table has continuous states (cam.fmu's state and derivative rows,
    at the table's end): 'time' takes the value reference after the table (TIME_VR in csrc/fmi/fmi3_cs.c), the
    event indicators the ones after it (fmi3_me.c)."""
    time_vr = len(rows)
    model_exchange = any(row.get("derivative") for row in rows)
    root = ET.Element("fmiModelDescription", fmiVersion="3.0", modelName=model_identifier,
                      instantiationToken=token, description=description, generationTool="cam_fmu",
                      variableNamingConvention="flat")
    if model_exchange:  # beside co-simulation, one binary (csrc/fmi/fmi3_me.c over exchange.c)
        ET.SubElement(root, "ModelExchange", modelIdentifier=model_identifier, canGetAndSetFMUState="true",
                      canSerializeFMUState="true", providesDirectionalDerivatives="true",
                      providesAdjointDerivatives="false", needsCompletedIntegratorStep="true")
    ET.SubElement(root, "CoSimulation", modelIdentifier=model_identifier,
                  canHandleVariableCommunicationStepSize="true", canGetAndSetFMUState="true",
                  canSerializeFMUState="true", providesDirectionalDerivatives="false",
                  providesAdjointDerivatives="false", hasEventMode="false",
                  canReturnEarlyAfterIntermediateUpdate="false", providesIntermediateUpdate="false",
                  needsCompletedIntegratorStep="false", maxOutputDerivativeOrder="0")
    indicators = indicator_rows() if model_exchange else []
    units = sorted({row["unit"] for row in rows + indicators if row["unit"]} | {"s"})  # 's': the variable 'time'
    root.append(unit_definitions(units))
    if typed_units(units):
        root.append(type_definitions(units, fmi3=True))
    categories = ET.SubElement(root, "LogCategories")
    for name, text in LOG_CATEGORIES:
        ET.SubElement(categories, "Category", name=name, description=text.replace("fmi2", "fmi3"))
    root.append(experiment_element(experiment))
    variables = ET.SubElement(root, "ModelVariables")
    # the independent variable FMI 3.0 asks for, after the whole table (value reference TIME_VR)
    ET.SubElement(variables, "Float64", name="time", valueReference=str(time_vr), causality="independent",
                  variability="continuous", description="simulation time", **unit_attributes("s"))
    vr_of = {row["name"]: vr for vr, row in enumerate(rows)}
    for vr, row in enumerate(rows):
        element = _variable(vr, row)
        if row.get("derivative"):  # FMI 3.0 names the state by its value reference
            element.set("derivative", str(vr_of[row["derivative"]]))
        variables.append(element)
    indicator_vrs = [time_vr + 1 + k for k in range(len(indicators))]
    for vr, row in zip(indicator_vrs, indicators):
        ET.SubElement(variables, "Float64", name=row["name"], valueReference=str(vr), causality="local",
                      variability="continuous", description=row["description"], **unit_attributes(row["unit"]))
    structure = ET.SubElement(root, "ModelStructure")
    outputs = [vr for vr, row in enumerate(rows) if row["causality"] == "output"]
    derivatives = [vr for vr, row in enumerate(rows) if row.get("derivative")]
    states = [vr_of[rows[vr]["derivative"]] for vr in derivatives]
    # Model Exchange: each output and state derivative lists the states and inputs it depends on
    # (variables.DEPENDENCIES, by value reference), as cam.fmu's FMI 2.0 <ModelStructure> does by index
    for vr in outputs:
        _unknown(structure, "Output", vr, rows, vr_of, model_exchange)
    for vr in derivatives:
        _unknown(structure, "ContinuousStateDerivative", vr, rows, vr_of, model_exchange)
    for vr in sorted(outputs + states + derivatives):
        ET.SubElement(structure, "InitialUnknown", valueReference=str(vr))
    for vr in indicator_vrs:
        ET.SubElement(structure, "EventIndicator", valueReference=str(vr))
    return parseString(ET.tostring(root, encoding="UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")


def _unknown(structure: ET.Element, kind: str, vr: int, rows: List[Dict[str, Any]], vr_of: Dict[str, int],
             model_exchange: bool) -> None:
    """An <Output> or <ContinuousStateDerivative> of ``vr``; under Model Exchange with the value references it
    depends on (variables.DEPENDENCIES) and dependenciesKind 'dependent' for each (the directional derivatives
    give the coefficients)."""
    element = ET.SubElement(structure, kind, valueReference=str(vr))
    name = rows[vr]["name"]
    if model_exchange and name in DEPENDENCIES:
        known = sorted(vr_of[k] for k in DEPENDENCIES[name])
        element.set("dependencies", " ".join(map(str, known)))
        element.set("dependenciesKind", " ".join("dependent" for _ in known))


def _variable(vr: int, row: Dict[str, Any]) -> ET.Element:
    attrs = {"name": row["name"], "valueReference": str(vr), "description": row["description"],
             "causality": row["causality"], "variability": row["variability"]}
    if row["initial"] and row["causality"] != "input":
        attrs["initial"] = row["initial"]
    kind = TYPES[row["type"]]
    if kind == "Float64":
        attrs.update(unit_attributes(row["unit"]))
        for key in ("min", "max"):
            if row[key] is not None and math.isfinite(row[key]):
                attrs[key] = repr(float(row[key]))
        if row["start"] is not None:
            attrs["start"] = repr(float(row["start"]))
        return ET.Element(kind, attrs)
    if kind == "Boolean":
        if row["start"] is not None:
            attrs["start"] = "true" if row["start"] else "false"
        return ET.Element(kind, attrs)
    element = ET.Element(kind, attrs)
    if row["start"] is not None:
        ET.SubElement(element, "Start", value=str(row["start"]))
    return element


__all__ = ["indicator_rows", "model_description"]
