"""Post-processing of cam.fmu's modelDescription.xml (build time only, not bundled).

pythonfmu 0.7.0 writes names, causality, variability, initial, start and the
Outputs list, but no units, no min/max, no InitialUnknowns and Real starts with
only 16 significant digits. ``postprocess`` adds what the Reference FMUs have:

- a model description, the DefaultExperiment of the paper's fig. 6 scene;
- ``<UnitDefinitions>`` (SI base-unit exponents and the display units of each unit, physics/units.py),
  ``<TypeDefinitions>`` (one type per quantity) and ``declaredType``/``unit``/``displayUnit``
  on every Real that has a unit (angles shown in deg, angular velocities in rpm, lengths in mm);
- explicit causality, variability and initial on every variable (FMI 2.0 forbids
  ``initial`` on inputs, so inputs carry causality, variability and start);
- ``min``/``max`` on parameters with finite bounds, exact (repr) start values;
- complete ``<Outputs>`` and ``<InitialUnknowns>`` (every output is 'calculated').

The same table (``variable_rows``) generates the variable table of docs/fmu.md
(``markdown_table``), so the documentation cannot drift from the FMU.
"""
from __future__ import annotations

import math
from typing import Any, Dict, List, Optional
from xml.dom.minidom import parseString
from xml.etree import ElementTree as ET

from ..physics import parameters
from ..physics.units import BASE_UNIT_ORDER, UNITS, display_unit
from ..physics.variables import (DEPENDENCIES, EVENT_INDICATORS, FEEDTHROUGH, FEEDTHROUGH_INPUTS, INPUT_RANGES,
                                 INPUTS, OUTPUTS, STATES)


def unit_definitions(units: List[str]) -> ET.Element:
    """<UnitDefinitions> of the SI ``units`` (physics.units.UNITS, FMI 2.0 and 3.0 alike): each with its base-unit
    exponents and, as <DisplayUnit>s, every unit a value of it may be given in (display = factor * SI + offset)."""
    element = ET.Element("UnitDefinitions")
    for unit in sorted(units):
        if unit not in UNITS:
            raise ValueError(f"unit {unit!r} has no entry in physics.units.UNITS (its SI base-unit exponents)")
        spec = UNITS[unit]
        node = ET.SubElement(element, "Unit", name=unit)
        exponents = dict(spec.base)
        if exponents:
            ET.SubElement(node, "BaseUnit", {k: str(exponents[k]) for k in BASE_UNIT_ORDER if k in exponents})
        for name, factor, offset in spec.alternatives:
            attrs = {"name": name, "factor": repr(factor)}
            if offset:
                attrs["offset"] = repr(offset)
            ET.SubElement(node, "DisplayUnit", attrs)
    return element


def typed_units(units: List[str]) -> List[str]:
    """The units that get a declared type (their quantity): every one of UNITS but the dimensionless '1'."""
    return sorted(unit for unit in units if unit in UNITS and unit != "1")


def type_definitions(units: List[str], fmi3: bool = False) -> ET.Element:
    """<TypeDefinitions>: one real type per quantity of ``units`` (typed_units) with its quantity, unit and display
    unit (FMI 2.0 <SimpleType><Real .../>, FMI 3.0 <Float64Type .../>)."""
    element = ET.Element("TypeDefinitions")
    for unit in typed_units(units):
        spec = UNITS[unit]
        attrs = {"quantity": spec.quantity, "unit": unit}
        if display_unit(unit) is not None:
            attrs["displayUnit"] = spec.display
        if fmi3:
            ET.SubElement(element, "Float64Type", {"name": spec.type_name, **attrs})
        else:
            ET.SubElement(ET.SubElement(element, "SimpleType", name=spec.type_name), "Real", attrs)
    return element


def unit_attributes(unit: str) -> Dict[str, str]:
    """A Real variable's declaredType, unit and displayUnit (FMI 2.0 and 3.0) for its SI ``unit`` ('' : none)."""
    if not unit:
        return {}
    attrs = {"unit": unit}
    if unit in UNITS and unit != "1":
        attrs["declaredType"] = UNITS[unit].type_name
    if display_unit(unit) is not None:
        attrs["displayUnit"] = UNITS[unit].display
    return attrs


def variable_rows() -> List[Dict[str, Any]]:
    """Every FMU variable in value-reference order (the slave registers inputs, outputs, parameters)."""
    rows: List[Dict[str, Any]] = []
    for name, unit, start, desc in INPUTS:
        low, high = INPUT_RANGES[name]
        rows.append(dict(name=name, type="Real", causality="input", variability="continuous", initial=None,
                         unit=unit, start=float(start), min=low, max=high, description=desc,
                         allowed=f"[{low:g}, {high:g}] {unit}"))
    for name, unit, desc in OUTPUTS:
        rows.append(dict(name=name, type="Real", causality="output", variability="continuous",
                         initial="calculated", unit=unit, start=None, min=None, max=None, description=desc,
                         allowed="(output)"))
    return rows + parameter_rows(parameters.PARAMETERS) + state_rows()


def state_rows() -> List[Dict[str, Any]]:
    """Model Exchange's continuous states, then their derivatives (appended: the co-simulation value
    references before them stay): local, calculated, read-only."""
    rows: List[Dict[str, Any]] = []
    for name, unit, _rate, desc in STATES:
        rows.append(dict(name=name, type="Real", causality="local", variability="continuous", initial="calculated",
                         unit=unit, start=None, min=None, max=None, description=desc, allowed="(state)"))
    for name, _unit, rate, _desc in STATES:
        rows.append(dict(name=f"der({name})", type="Real", causality="local", variability="continuous",
                         initial="calculated", unit=rate, start=None, min=None, max=None,
                         description=f"derivative of {name}", allowed="(derivative)", derivative=name))
    return rows


def parameter_rows(specs) -> List[Dict[str, Any]]:
    """The rows of parameters (ParameterSpec): fixed, exact start, min/max from their ranges."""
    rows: List[Dict[str, Any]] = []
    for spec in specs:
        kind = {"real": "Real", "boolean": "Boolean", "string": "String"}[spec.kind]
        row = dict(name=spec.name, type=kind, causality="parameter", variability="fixed", initial="exact",
                   unit=spec.unit if spec.kind == "real" else "", start=spec.default,
                   min=None, max=None, description=spec.description, allowed=spec.allowed())
        if spec.kind == "real":
            low = 0.0 if spec.zero_ok else spec.low
            row["min"] = low if math.isfinite(low) else None
            row["max"] = spec.high if math.isfinite(spec.high) else None
        rows.append(row)
    return rows


def controller_rows() -> List[Dict[str, Any]]:
    """Every variable of pi_speed.fmu (control.pi's tables) in value-reference order."""
    from ..control import pi

    rows: List[Dict[str, Any]] = []
    for name, unit, start, desc in pi.INPUTS:
        rows.append(dict(name=name, type="Real", causality="input", variability="continuous", initial=None,
                         unit=unit, start=float(start), min=None, max=None, description=desc,
                         allowed="any finite value"))
    for name, unit, desc in pi.OUTPUTS:
        rows.append(dict(name=name, type="Real", causality="output", variability="discrete",
                         initial="calculated", unit=unit, start=None, min=None, max=None, description=desc,
                         allowed="(output)"))
    return rows + parameter_rows(pi.PARAMETERS)


ROWS = {"cam": variable_rows, "pi_speed": controller_rows}  # model name -> its variable table


def _fmt(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)  # shortest string that round-trips exactly
    return str(value)


# The relative tolerance every FMU's DefaultExperiment declares: the engine's own co-simulation rtol. A host that
# integrates cam.fmu through Model Exchange with its own solver (OMSimulator picks Model Exchange when an FMU
# offers both, fmpy's CVode) reads it; without it each host runs at its own default (fmpy 1e-5), far looser
# than the co-simulation (docs/fmu.md, "Model Exchange"). Co-simulation ignores it (rtol is a parameter).
DEFAULT_TOLERANCE = parameters.BY_NAME["rtol"].default


def experiment_element(default_experiment: tuple) -> ET.Element:
    """<DefaultExperiment> of (start, stop, step) [s] with the tolerance DEFAULT_TOLERANCE (FMI 2.0 and 3.0)."""
    start, stop, step = default_experiment
    return ET.Element("DefaultExperiment", startTime=_fmt(float(start)), stopTime=_fmt(float(stop)),
                      tolerance=_fmt(float(DEFAULT_TOLERANCE)), stepSize=_fmt(float(step)))


def postprocess(xml_bytes: bytes, default_experiment: tuple, description: Optional[str] = None,
                rows: Optional[List[Dict[str, Any]]] = None) -> bytes:
    """Return the completed modelDescription.xml (``rows``: the model's variable table, default cam.fmu's)."""
    root = ET.fromstring(xml_bytes)
    for element in root.iter():  # drop pythonfmu's pretty-printing whitespace before re-indenting
        if element.text is not None and not element.text.strip():
            element.text = None
        if element.tail is not None and not element.tail.strip():
            element.tail = None
    if description:
        root.set("description", description)
    rows = {row["name"]: row for row in (variable_rows() if rows is None else rows)}

    # UnitDefinitions and TypeDefinitions right after CoSimulation (schema order).
    for old in root.findall("UnitDefinitions") + root.findall("TypeDefinitions"):
        root.remove(old)
    units = sorted({row["unit"] for row in rows.values() if row["type"] == "Real" and row["unit"]})
    children = list(root)
    cosim_index = next(i for i, c in enumerate(children) if c.tag == "CoSimulation")
    root.insert(cosim_index + 1, unit_definitions(units))
    if typed_units(units):
        root.insert(cosim_index + 2, type_definitions(units))

    # DefaultExperiment before ModelVariables.
    for old in root.findall("DefaultExperiment"):
        root.remove(old)
    root.insert(list(root).index(root.find("ModelVariables")), experiment_element(default_experiment))

    # Variables.
    variables = root.find("ModelVariables")
    index_of: Dict[str, int] = {}
    for index, sv in enumerate(variables.findall("ScalarVariable"), start=1):
        name = sv.get("name")
        if name not in rows:
            raise ValueError(f"FMU variable {name!r} is not in the variable table")
        row = rows[name]
        index_of[name] = index
        for key in ("causality", "variability"):
            sv.set(key, row[key])
        if row["initial"] is None:
            sv.attrib.pop("initial", None)
        else:
            sv.set("initial", row["initial"])
        if row["description"]:
            sv.set("description", row["description"])
        typed = sv.find(row["type"])
        if typed is None:
            raise ValueError(f"FMU variable {name!r} is not of type {row['type']}")
        typed.attrib.clear()
        if row["type"] == "Real":
            for key, value in unit_attributes(row["unit"]).items():
                typed.set(key, value)
        if row["min"] is not None:
            typed.set("min", _fmt(float(row["min"])))
        if row["max"] is not None:
            typed.set("max", _fmt(float(row["max"])))
        if row["start"] is not None:
            typed.set("start", _fmt(float(row["start"]) if row["type"] == "Real" else row["start"]))
        if row.get("derivative"):  # a state derivative names its state by index (states come first)
            typed.set("derivative", str(index_of[row["derivative"]]))
    missing = set(rows) - set(index_of)
    if missing:
        raise ValueError(f"variables missing from the FMU: {sorted(missing)}")

    # ModelStructure: every output in Outputs and InitialUnknowns (all are 'calculated').
    # Outputs: in co-simulation a new input (u, omega_ref) changes no output before the next fmi2DoStep;
    # in Model Exchange the outputs follow the host's state and inputs at once, and those of
    # variables.FEEDTHROUGH (i, M, a, voltage, N_contact) depend on u directly. One model description serves both:
    # they list u (Model Exchange's truth, and safe for a co-simulation master), the others list nothing,
    # so a master need not iterate a loop closed around cam.fmu through omega, theta or s.
    # InitialUnknowns: no dependencies attribute (= may depend on every input and parameter), which
    # is the truth: the initial i and voltage follow the inputs set before initialisation.
    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    # Derivatives (Model Exchange): every state's derivative, no dependencies attribute (= on all).
    # InitialUnknowns also hold the states and derivatives, computed from the parameters and inputs.
    outputs = [name for name, row in rows.items() if row["causality"] == "output"]
    derivatives = [name for name, row in rows.items() if row.get("derivative")]
    states = [row["derivative"] for row in rows.values() if row.get("derivative")]
    out_node = ET.SubElement(structure, "Outputs")
    feedthrough = " ".join(str(index_of[name]) for name in FEEDTHROUGH_INPUTS if name in index_of)
    for name in sorted(outputs, key=index_of.get):
        if derivatives:   # Model Exchange: the states and the input each output follows (variables.DEPENDENCIES)
            _depends(out_node, name, index_of)
        else:
            ET.SubElement(out_node, "Unknown", index=str(index_of[name]),
                          dependencies=feedthrough if name in FEEDTHROUGH and derivatives else "")
    if derivatives:
        der_node = ET.SubElement(structure, "Derivatives")
        for name in sorted(derivatives, key=index_of.get):
            _depends(der_node, name, index_of)
    init_node = ET.SubElement(structure, "InitialUnknowns")
    for name in sorted(outputs + states + derivatives, key=index_of.get):
        ET.SubElement(init_node, "Unknown", index=str(index_of[name]))

    text = ET.tostring(root, encoding="UTF-8")
    return parseString(text).toprettyxml(indent="  ", encoding="UTF-8")


def _depends(parent: ET.Element, name: str, index_of: Dict[str, int]) -> None:
    """An <Unknown> for ``name`` with its dependencies (variables.DEPENDENCIES: states and inputs, by index) and
    dependenciesKind 'dependent' for each (the directional derivatives give the coefficients)."""
    known = sorted(index_of[k] for k in DEPENDENCIES[name])
    ET.SubElement(parent, "Unknown", index=str(index_of[name]), dependencies=" ".join(map(str, known)),
                  dependenciesKind=" ".join("dependent" for _ in known))


LOG_CATEGORIES = (
    ("logEvents", "hybrid events and mode changes of the drive (stop, break-away, contact, a free follower's "
                  "lift-offs and touch-downs, ...)"),
    ("logStatusWarning", "messages with status fmi2Warning"),
    ("logStatusDiscard", "messages with status fmi2Discard: a step the solver cannot complete at this size"),
    ("logStatusError", "messages with status fmi2Error: a refused value or call, naming it"),
    ("logStatusFatal", "messages with status fmi2Fatal"),
)


def guid(rows: List[Dict[str, Any]], engine_digest: str) -> str:
    """The FMU's GUID [text]: a hash of the variable table and the engine's sources, so a binary and a
    model description of different builds never pass fmi2Instantiate's check."""
    import hashlib

    text = repr([(r["name"], r["type"], r["causality"], r["start"]) for r in rows]) + engine_digest
    h = hashlib.sha256(text.encode()).hexdigest()
    return "{%s-%s-%s-%s-%s}" % (h[:8], h[8:12], h[12:16], h[16:20], h[20:32])


def skeleton(model_identifier: str, model_guid: str, rows: List[Dict[str, Any]],
             source_files: Optional[List[str]] = None, model_exchange: bool = True) -> bytes:
    """A modelDescription.xml (co-simulation, and Model Exchange unless ``model_exchange`` is False) with every
    variable of ``rows`` (value reference = row index) and the capabilities of the C binary; ``source_files``:
    the C files of ``sources/`` a build compiles (``<SourceFiles>`` of each interface); ``postprocess``
    completes it."""
    root = ET.Element("fmiModelDescription", fmiVersion="2.0", modelName=model_identifier, guid=model_guid,
                      generationTool="cam_fmu", variableNamingConvention="flat",
                      numberOfEventIndicators=str(EVENT_INDICATORS if model_exchange else 0))
    # Model Exchange beside co-simulation, one binary (csrc/fmi/fmi2.c over exchange.c): the host's
    # solver integrates the consistent formulation's states (docs/fmu.md, "Model Exchange").
    if model_exchange:
        ET.SubElement(root, "ModelExchange", modelIdentifier=model_identifier, needsExecutionTool="false",
                      completedIntegratorStepNotNeeded="false", canBeInstantiatedOnlyOncePerProcess="false",
                      canNotUseMemoryManagementFunctions="true", canGetAndSetFMUstate="true",
                      canSerializeFMUstate="true", providesDirectionalDerivative="true")
    ET.SubElement(root, "CoSimulation", modelIdentifier=model_identifier, needsExecutionTool="false",
                  canHandleVariableCommunicationStepSize="true", canInterpolateInputs="false",
                  canBeInstantiatedOnlyOncePerProcess="false", canNotUseMemoryManagementFunctions="true",
                  canGetAndSetFMUstate="true", canSerializeFMUstate="true",
                  providesDirectionalDerivative="false")
    for interface in root:  # FMI 2.0's build description: the files to compile, in each interface
        if source_files:
            files = ET.SubElement(interface, "SourceFiles")
            for name in source_files:
                ET.SubElement(files, "File", name=name)
    categories = ET.SubElement(root, "LogCategories")
    for name, description in LOG_CATEGORIES:
        ET.SubElement(categories, "Category", name=name, description=description)
    variables = ET.SubElement(root, "ModelVariables")
    for vr, row in enumerate(rows):
        sv = ET.SubElement(variables, "ScalarVariable", name=row["name"], valueReference=str(vr))
        ET.SubElement(sv, row["type"])
    ET.SubElement(root, "ModelStructure")
    return ET.tostring(root, encoding="UTF-8")


def markdown_table() -> str:
    """The table of every FMU variable in docs/fmu.md: name, causality, type, unit, display unit, default, allowed
    range."""
    lines = ["| name | causality | type | unit | shown in | default | allowed | description |",
             "|---|---|---|---|---|---|---|---|"]
    for row in variable_rows():
        default = "" if row["start"] is None else _fmt(row["start"] if row["type"] != "Real" else float(row["start"]))
        if row["type"] == "Real" and row["start"] is not None:
            default = f"{float(row['start']):.6g}"
        shown = display_unit(row["unit"]) if row["type"] == "Real" else None
        lines.append("| `{name}` | {causality} | {type} | {unit} | {shown} | {default} | {allowed} | {description} |".format(
            name=row["name"], causality=row["causality"], type=row["type"], unit=row["unit"] or "",
            shown=shown[0] if shown else "", default=default, allowed=row["allowed"].replace("|", "\\|"),
            description=row["description"].replace("|", "\\|")))
    return "\n".join(lines)


if __name__ == "__main__":  # python -m cam_fmu.fmu.model_description: print the variable table
    print(markdown_table())
