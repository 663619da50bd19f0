"""SSP 1.0 files (System Structure and Parameterization): write and read a system of FMUs.

A ``.ssp`` is a zip with ``SystemStructure.ssd`` and the FMUs under
``resources/``. What is written and read here is the common subset that
ecos, libcosim (OSP) and fmpy all understand:

- one ``ssd:System`` with ``ssd:Component`` elements (``source="resources/X.fmu"``),
  each with its ``ssd:Connectors`` (inputs/outputs used by the connections) and
  inline ``ssd:ParameterBindings`` (one ``ssv:ParameterSet`` of Real, Boolean and
  String values: only the values that differ from the FMU's defaults; ``write_ssp``
  reads the defaults from each FMU's modelDescription.xml and drops a binding equal to
  one. OMSimulator's importer knows no ``ssv:String`` in some versions ("Unknown
  ParameterBinding-type"): a string equal to its default, such as cam.fmu's
  ``drive = voltage``, is therefore never written; one that differs is kept, since
  dropping it would change the system);
- ``ssd:Connections`` (``startElement.startConnector -> endElement.endConnector``);
- ``ssd:DefaultExperiment`` (startTime, stopTime: the loop's own, which a run without a
  stop time of its own takes) with the OSP annotation
  ``osp:FixedStepAlgorithm baseStepSize`` (the communication step), which
  libcosim reads; ecos takes the step on its command line;
- inside ``ssd:System``, OMSimulator's vendor annotation (``org.openmodelica``:
  ``oms:FixedStepMaster stepSize`` = the same step): OMSimulator's importer learns
  the system's type only from it and aborts without it; other engines ignore it,
  as the standard lets them.

``read_ssp`` checks what the standard requires before anything runs
(``validate``): every connection names a component and a connector of it
declared with the right kind (output or input at its start, input at its end),
no input is fed by two connections, and each component's source is an FMU (a zip
with a modelDescription.xml); the error names the component or connection.

Standard library only (and the scene files' numbers, ``scene_data``).
"""
from __future__ import annotations

import os
import shutil
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence
from xml.dom.minidom import parseString
from xml.etree import ElementTree as ET

from ..engine import reproducible
from . import scene_data

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
OMS = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"
OMS_TOLERANCE = 1e-4  # OMSimulator's absolute and relative tolerance attributes (unused by a fixed-step master)
PARAMETER_SET = "initialValues"
for _prefix, _uri in (("ssd", SSD), ("ssc", SSC), ("ssv", SSV), ("osp", OSP), ("oms", OMS)):
    ET.register_namespace(_prefix, _uri)


class SspError(ValueError):
    """An SSP file that cannot be used; the message names the file and the element."""


@dataclass(frozen=True)
class Connection:
    start_element: str
    start_connector: str
    end_element: str
    end_connector: str

    def __str__(self) -> str:
        return f"{self.start_element}.{self.start_connector} -> {self.end_element}.{self.end_connector}"


@dataclass
class Component:
    name: str
    source: str  # path inside the SSP, e.g. resources/cam.fmu
    inputs: list[str] = field(default_factory=list)
    outputs: list[str] = field(default_factory=list)
    parameters: dict[str, Any] = field(default_factory=dict)  # float, bool or str


@dataclass
class System:
    name: str
    components: dict[str, Component]
    connections: list[Connection]
    start_time: float = 0.0
    stop_time: float = 1.0
    step_size: float = 1e-3
    path: Path | None = None


def _q(ns: str, tag: str) -> str:
    return f"{{{ns}}}{tag}"


def _fmt(value: float) -> str:
    return repr(float(value))


def system_xml(system: System) -> bytes:
    """SystemStructure.ssd of ``system``."""
    root = ET.Element(_q(SSD, "SystemStructureDescription"), {"version": "1.0", "name": system.name})
    sys_el = ET.SubElement(root, _q(SSD, "System"), {"name": system.name})
    elements = ET.SubElement(sys_el, _q(SSD, "Elements"))
    for comp in system.components.values():
        c_el = ET.SubElement(elements, _q(SSD, "Component"),
                             {"name": comp.name, "source": comp.source, "type": "application/x-fmu-sharedlibrary"})
        conns = ET.SubElement(c_el, _q(SSD, "Connectors"))
        for kind, names in (("input", comp.inputs), ("output", comp.outputs)):
            for name in names:
                con = ET.SubElement(conns, _q(SSD, "Connector"), {"name": name, "kind": kind})
                ET.SubElement(con, _q(SSC, "Real"))
        if comp.parameters:
            bindings = ET.SubElement(c_el, _q(SSD, "ParameterBindings"))
            binding = ET.SubElement(bindings, _q(SSD, "ParameterBinding"))
            values = ET.SubElement(binding, _q(SSD, "ParameterValues"))
            pset = ET.SubElement(values, _q(SSV, "ParameterSet"), {"version": "1.0", "name": PARAMETER_SET})
            params = ET.SubElement(pset, _q(SSV, "Parameters"))
            for name, value in comp.parameters.items():
                p_el = ET.SubElement(params, _q(SSV, "Parameter"), {"name": name})
                if isinstance(value, bool):
                    ET.SubElement(p_el, _q(SSV, "Boolean"), {"value": "true" if value else "false"})
                elif isinstance(value, str):
                    ET.SubElement(p_el, _q(SSV, "String"), {"value": value})
                else:
                    ET.SubElement(p_el, _q(SSV, "Real"), {"value": _fmt(value)})
    connections = ET.SubElement(sys_el, _q(SSD, "Connections"))
    for c in system.connections:
        ET.SubElement(connections, _q(SSD, "Connection"), {
            "startElement": c.start_element, "startConnector": c.start_connector,
            "endElement": c.end_element, "endConnector": c.end_connector})
    oms = ET.SubElement(ET.SubElement(ET.SubElement(sys_el, _q(SSD, "Annotations")), _q(SSC, "Annotation"),
                                      {"type": "org.openmodelica"}), _q(OMS, "Annotations"))
    ET.SubElement(ET.SubElement(oms, _q(OMS, "SimulationInformation")), _q(OMS, "FixedStepMaster"),
                  {"description": "oms-ma", "stepSize": _fmt(system.step_size),
                   "absoluteTolerance": _fmt(OMS_TOLERANCE), "relativeTolerance": _fmt(OMS_TOLERANCE)})
    exp = ET.SubElement(root, _q(SSD, "DefaultExperiment"),
                        {"startTime": _fmt(system.start_time), "stopTime": _fmt(system.stop_time)})
    ann = ET.SubElement(ET.SubElement(exp, _q(SSD, "Annotations")), _q(SSC, "Annotation"),
                        {"type": "com.opensimulationplatform"})
    alg = ET.SubElement(ann, _q(OSP, "Algorithm"))
    ET.SubElement(alg, _q(OSP, "FixedStepAlgorithm"), {"baseStepSize": _fmt(system.step_size)})
    return parseString(ET.tostring(root, encoding="UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")


def fmu_defaults(fmu: str | Path) -> dict[str, Any]:
    """{name: start value} of the parameters an FMU (2.0 or 3.0) declares, typed as parse_ssd types them; {} for
    a file that is no FMU (read_ssp refuses it, naming the component)."""
    try:
        with zipfile.ZipFile(fmu) as z:
            root = ET.fromstring(z.read("modelDescription.xml"))
    except (zipfile.BadZipFile, KeyError, ET.ParseError):
        return {}
    variables = root.find("ModelVariables")
    found: dict[str, Any] = {}
    for v in (variables if variables is not None else []):
        if v.get("causality") != "parameter":
            continue
        typed = v[0] if v.tag == "ScalarVariable" and len(v) else v  # FMI 2.0: <Real start=...>; 3.0: <Float64>
        kind = typed.tag
        start = typed.get("start")
        if start is None and kind == "String":
            child = typed.find("Start")  # FMI 3.0 strings: <Start value=.../>
            start = child.get("value") if child is not None else None
        if start is None:
            continue
        if kind in ("Real", "Float64", "Float32"):
            found[v.get("name")] = float(start)
        elif kind == "Boolean":
            found[v.get("name")] = start.strip().lower() in ("true", "1")
        elif kind.startswith("Int"):
            found[v.get("name")] = int(start)
        else:
            found[v.get("name")] = start
    return found


def without_defaults(system: System, defaults: Mapping[str, Mapping[str, Any]]) -> System:
    """A copy of ``system`` whose components keep only the parameter values that differ from ``defaults``
    (component name -> {parameter: default}); a value of another type than its default is kept."""
    import copy

    pruned = copy.deepcopy(system)
    for comp in pruned.components.values():
        own = defaults.get(comp.name, {})
        comp.parameters = {name: value for name, value in comp.parameters.items()
                           if not (name in own and type(own[name]) is type(_typed(value)) and own[name] == _typed(value))}
    return pruned


def _typed(value: Any) -> Any:
    """A binding's value as parse_ssd reads it back (int and float alike are Real)."""
    return float(value) if isinstance(value, int) and not isinstance(value, bool) else value


def write_ssp(system: System, fmus: Mapping[str, str | Path], dest: str | Path) -> Path:
    """Write ``dest`` (.ssp): SystemStructure.ssd plus each component's FMU (``fmus``: name -> file). A parameter
    value equal to the FMU's own default is not written (module docstring)."""
    dest = Path(dest)
    dest.parent.mkdir(parents=True, exist_ok=True)
    tmp = dest.with_name(f"{dest.name}.{os.getpid()}.tmp")  # its own: two writers never share one
    defaults = {comp.name: fmu_defaults(fmus[comp.name]) for comp in system.components.values()}
    entries: dict[str, bytes | Path] = {"SystemStructure.ssd": system_xml(without_defaults(system, defaults))}
    for comp in system.components.values():
        entries.setdefault(comp.source, Path(fmus[comp.name]))
    reproducible.write_zip(tmp, entries)  # sorted, the build's time: two builds give the same bytes
    tmp.replace(dest)
    return dest


def _float(el: ET.Element, key: str, where: str) -> float:
    try:
        return float(el.attrib[key])
    except (KeyError, ValueError):
        raise SspError(f"{where}: <{el.tag.split('}')[-1]}> needs a numeric '{key}'") from None


def parse_ssd(xml: bytes, where: str = "SystemStructure.ssd") -> System:
    """The System of an SSD document (the subset described in the module docstring)."""
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as exc:
        raise SspError(f"{where}: not valid XML: {exc}") from None
    if root.tag != _q(SSD, "SystemStructureDescription"):
        raise SspError(f"{where}: the root element is not ssd:SystemStructureDescription (SSP 1.0)")
    sys_el = root.find(_q(SSD, "System"))
    if sys_el is None:
        raise SspError(f"{where}: no ssd:System")
    components: dict[str, Component] = {}
    for c_el in sys_el.iter(_q(SSD, "Component")):
        name, source = c_el.get("name"), c_el.get("source")
        if not name or not source:
            raise SspError(f"{where}: a ssd:Component needs 'name' and 'source'")
        comp = Component(name, source)
        for con in c_el.iter(_q(SSD, "Connector")):
            (comp.inputs if con.get("kind") == "input" else comp.outputs).append(con.get("name"))
        for p_el in c_el.iter(_q(SSV, "Parameter")):
            pname = p_el.get("name")
            for kind, conv in (("Real", float), ("Boolean", lambda v: v.strip().lower() in ("true", "1")),
                               ("String", str), ("Integer", int)):
                v_el = p_el.find(_q(SSV, kind))
                if v_el is not None:
                    try:
                        comp.parameters[pname] = conv(v_el.get("value"))
                    except (TypeError, ValueError):
                        raise SspError(f"{where}: parameter {name}.{pname}: bad {kind} value "
                                       f"{v_el.get('value')!r}") from None
        components[name] = comp
    connections = []
    for e in sys_el.iter(_q(SSD, "Connection")):
        c = Connection(e.get("startElement"), e.get("startConnector"), e.get("endElement"), e.get("endConnector"))
        for elem in (c.start_element, c.end_element):
            if elem not in components:
                raise SspError(f"{where}: connection {c}: no component {elem!r}")
        connections.append(c)
    system = System(sys_el.get("name") or root.get("name") or "system", components, connections)
    exp = root.find(_q(SSD, "DefaultExperiment"))
    if exp is not None:
        system.start_time = _float(exp, "startTime", where) if "startTime" in exp.attrib else 0.0
        if "stopTime" in exp.attrib:
            system.stop_time = _float(exp, "stopTime", where)
        alg = exp.find(f".//{_q(OSP, 'FixedStepAlgorithm')}")
        if alg is not None:
            system.step_size = _float(alg, "baseStepSize", where)
    return system


def read_ssp(path: str | Path) -> System:
    """The System of the SSP file ``path``."""
    path = Path(path)
    if not path.is_file():
        raise SspError(f"SSP file {str(path)!r} does not exist")
    try:
        with zipfile.ZipFile(path) as z:
            xml = z.read("SystemStructure.ssd")
            names = set(z.namelist())
    except zipfile.BadZipFile:
        raise SspError(f"{path}: not an SSP file (not a zip archive)") from None
    except KeyError:
        raise SspError(f"{path}: no SystemStructure.ssd inside") from None
    system = parse_ssd(xml, where=f"{path}:SystemStructure.ssd")
    for comp in system.components.values():
        if comp.source not in names:
            raise SspError(f"{path}: component {comp.name!r}: {comp.source!r} is not in the archive")
    validate(system, where=str(path))
    _check_fmus(path, system)
    system.path = path
    return system


def validate(system: System, where: str = "SystemStructure.ssd") -> None:
    """Raise SspError unless every connection joins declared connectors and each input has one source."""
    fed: dict[tuple[str, str], Connection] = {}
    for c in system.connections:
        for elem, connector, kinds in ((c.start_element, c.start_connector, ("output", "input")),
                                       (c.end_element, c.end_connector, ("input",))):
            comp = system.components.get(elem)
            if comp is None:
                raise SspError(f"{where}: connection {c}: no component {elem!r}")
            declared = {n: "input" for n in comp.inputs} | {n: "output" for n in comp.outputs}
            if connector not in declared:
                raise SspError(f"{where}: connection {c}: component {elem!r} has no connector {connector!r}; "
                               f"it declares: {', '.join(declared) or 'none'}")
            if declared[connector] not in kinds:
                raise SspError(f"{where}: connection {c}: {elem}.{connector} is an {declared[connector]}, "
                               f"a connection {'ends' if kinds == ('input',) else 'starts'} at "
                               f"{' or '.join(kinds)}s")
        key = (c.end_element, c.end_connector)
        if key in fed:
            raise SspError(f"{where}: input {c.end_element}.{c.end_connector} is fed by two connections "
                           f"({fed[key]} and {c}); an input takes one")
        fed[key] = c


def _check_fmus(path: Path, system: System) -> None:
    """Each component's source is a zip archive with a modelDescription.xml (an FMU)."""
    import io

    with zipfile.ZipFile(path) as z:
        for comp in system.components.values():
            try:
                with zipfile.ZipFile(io.BytesIO(z.read(comp.source))) as fmu:
                    if "modelDescription.xml" not in fmu.namelist():
                        raise SspError(f"{path}: component {comp.name!r}: {comp.source} has no modelDescription.xml "
                                       f"(not an FMU)")
            except zipfile.BadZipFile:
                raise SspError(f"{path}: component {comp.name!r}: {comp.source} is not an FMU "
                               f"(not a zip archive)") from None


def extract_ssp(path: str | Path, dest: str | Path) -> Path:
    """Unpack the SSP into ``dest`` (a fresh folder) and return it."""
    dest = Path(dest)
    if dest.exists():
        shutil.rmtree(dest)
    with zipfile.ZipFile(path) as z:
        z.extractall(dest)
    return dest


# -------------------------------------------------------------------- the speed loop
def speed_loop_system(cam_parameters: Mapping[str, Any] | None = None,
                      controller_parameters: Mapping[str, Any] | None = None,
                      stop_time: float = 2.0, step_size: float = 1e-3,
                      feedforward_connections: bool = True, name: str = "speed_loop",
                      measured: str = "omega") -> System:
    """models/speed_loop.ssp: pi_speed.fmu (instance 'controller') closing a speed loop around cam.fmu ('cam'),
    on the speed ``measured`` ('omega': the cam's; 'omega_m': the rotor's, beyond a compliant shaft)."""
    connections = [Connection("controller", "u", "cam", "u"), Connection("cam", measured, "controller", "omega_meas")]
    if feedforward_connections:
        connections += [Connection("cam", "M", "controller", "M_load"), Connection("cam", "J", "controller", "J_load")]
    cam_out = sorted({c.start_connector for c in connections if c.start_element == "cam"},
                     key=["omega", "omega_m", "M", "J"].index)
    ctrl_in = [c.end_connector for c in connections if c.end_element == "controller"]
    return System(name, {
        "cam": Component("cam", "resources/cam.fmu", inputs=["u"], outputs=cam_out,
                         parameters=dict(cam_parameters or {})),
        "controller": Component("controller", "resources/pi_speed.fmu", inputs=ctrl_in, outputs=["u"],
                                parameters=dict(controller_parameters or {})),
    }, connections, 0.0, stop_time, step_size)


SPEED_LOOP_CAM = {"gamma": 3.141592653589793}  # horizontal mounting, as the paper's fig. 6
SPEED_LOOP_CONTROLLER: dict[str, Any] = {}  # the controller's defaults (control.pi.PARAMETERS)


def compliant_loop_system() -> System:
    """models/compliant_loop.ssp: the PI loop on the cam's speed (an encoder on the cam shaft) around the
    compliant_shaft scene's drive (resonance 207-363 Hz), sampled at 5 kHz; its gains (kp 0.5 V/(rad/s),
    ki 5 V/rad) keep the loop's bandwidth below the anti-resonance (docs/control.md section 5)."""
    return speed_loop_system(scene_data.primary_parameters("compliant_shaft"), {"omega_set": 3.0, "kp": 0.5, "ki": 5.0},
                             stop_time=2.0, step_size=2e-4, feedforward_connections=False, name="compliant_loop", measured="omega")
