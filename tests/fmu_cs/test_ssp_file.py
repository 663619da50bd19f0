"""The SSP file the project writes and what read_ssp accepts.

- The SSD validates against the SSP 1.0 schema that fmpy ships, with OMSimulator's vendor annotation
  inside ssd:System carrying the loop's own step (OMSimulator aborts without it; ecos and libcosim run
  the annotated file in tests/hosts/test_speed_loop.py).
- A malformed SSP (an input fed twice, a connection to an unknown connector, a corrupt FMU inside) is
  refused by `cam-fmu cosim` before anything runs: one line naming the culprit, exit 2.
"""
from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import fmpy
import pytest
from lxml import etree

from cam_fmu.fmu.ssp import OMS, Connection, SspError, read_ssp, speed_loop_system, write_ssp

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = Path(fmpy.__file__).parent / "ssp" / "schema" / "SystemStructureDescription.xsd"
SSD = "{http://ssp-standard.org/SSP1/SystemStructureDescription}"


def fake_fmu(path: Path, description: bool = True) -> Path:
    """A zip that passes for an FMU up to loading (read_ssp does not load FMUs)."""
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("modelDescription.xml" if description else "readme.txt", "<fmiModelDescription/>")
    return path


def write(tmp_path: Path, system, cam: Path | None = None) -> Path:
    cam = cam or fake_fmu(tmp_path / "cam.fmu")
    return write_ssp(system, {"cam": cam, "controller": fake_fmu(tmp_path / "pi.fmu")}, tmp_path / "loop.ssp")


@pytest.mark.parametrize("step", [1e-3, 2.5e-4])
def test_ssd_is_valid_ssp_and_carries_omsimulators_annotation(tmp_path, step):
    ssp = write(tmp_path, speed_loop_system(stop_time=1.0, step_size=step))
    doc = etree.fromstring(zipfile.ZipFile(ssp).read("SystemStructure.ssd"))
    schema = etree.XMLSchema(etree.parse(str(SCHEMA)))
    assert schema.validate(doc), schema.error_log
    system = doc.find(f"{SSD}System")
    masters = system.findall(f"{SSD}Annotations/*[@type='org.openmodelica']/{{{OMS}}}Annotations/"
                             f"{{{OMS}}}SimulationInformation/{{{OMS}}}FixedStepMaster")
    assert len(masters) == 1 and float(masters[0].get("stepSize")) == step
    assert read_ssp(ssp).step_size == step  # the OSP step, read back, is the same step


def test_the_shipped_ssp_is_valid_and_annotated():
    from cam_fmu.fmu.build import ensure_ssp

    doc = etree.fromstring(zipfile.ZipFile(ensure_ssp()).read("SystemStructure.ssd"))
    assert etree.XMLSchema(etree.parse(str(SCHEMA))).validate(doc)
    assert doc.find(f"{SSD}System/{SSD}Annotations/*[@type='org.openmodelica']") is not None


def _twice(s):
    s.connections.append(Connection("cam", "M", "controller", "omega_meas"))


def _unknown_connector(s):
    s.connections[1] = Connection("cam", "omega_out", "controller", "omega_meas")


def _unknown_component(s):
    s.connections[0] = Connection("controler", "u", "cam", "u")


def _into_an_output(s):
    s.connections[0] = Connection("controller", "u", "cam", "omega")


MALFORMED = [
    (_twice, "input controller.omega_meas is fed by two connections"),
    (_unknown_connector, "component 'cam' has no connector 'omega_out'"),
    (_unknown_component, "no component 'controler'"),
    (_into_an_output, "cam.omega is an output"),
]


@pytest.mark.parametrize("change,message", MALFORMED, ids=[m[0].__name__ for m in MALFORMED])
def test_malformed_connections_are_refused(tmp_path, change, message):
    system = speed_loop_system()
    change(system)
    ssp = write(tmp_path, system)
    with pytest.raises(SspError, match="loop.ssp"):
        read_ssp(ssp)
    proc = cosim(ssp, tmp_path)
    assert message in proc.stderr


@pytest.mark.parametrize("description", [True, False], ids=["corrupt zip", "no modelDescription"])
def test_a_corrupt_fmu_is_named_by_its_component(tmp_path, description):
    cam = tmp_path / "cam.fmu"
    if description:
        cam.write_bytes(b"not a zip at all")
    else:
        fake_fmu(cam, description=False)
    proc = cosim(write(tmp_path, speed_loop_system(), cam), tmp_path)
    assert "component 'cam': resources/cam.fmu" in proc.stderr and "not an FMU" in proc.stderr


def cosim(ssp: Path, cwd: Path) -> subprocess.CompletedProcess:
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "cosim", str(ssp), "--no-plot", "--out", "out"],
                          capture_output=True, text=True, cwd=cwd, env={**os.environ, "PYTHONPATH": str(ROOT)},
                          timeout=300)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and lines[0].startswith("cam-fmu cosim: error: "), proc.stderr
    assert "Traceback" not in proc.stderr and not (cwd / "out").exists()
    return proc


def fmu_with_defaults(path: Path, fmi3: bool = False) -> Path:
    """A zip that passes for an FMU whose model description declares the defaults drive = 'voltage' (a string),
    J_m = 1e-5, backlash = false and kp = 1.0 (FMI 2.0 or 3.0 layout)."""
    if fmi3:
        variables = ('<String name="drive" causality="parameter"><Start value="voltage"/></String>'
                     '<Float64 name="J_m" causality="parameter" start="1e-05"/>'
                     '<Boolean name="backlash" causality="parameter" start="false"/>'
                     '<Float64 name="kp" causality="parameter" start="1.0"/>')
    else:
        variables = ''.join(f'<ScalarVariable name="{n}" causality="parameter"><{k} start="{v}"/></ScalarVariable>'
                            for n, k, v in (("drive", "String", "voltage"), ("J_m", "Real", "1e-05"),
                                            ("backlash", "Boolean", "false"), ("kp", "Real", "1.0")))
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("modelDescription.xml", f'<fmiModelDescription fmiVersion="{"3.0" if fmi3 else "2.0"}">'
                                           f'<ModelVariables>{variables}</ModelVariables></fmiModelDescription>')
    return path


def _bindings(ssp: Path) -> dict[str, dict[str, tuple[str, str]]]:
    """{component: {parameter: (ssv type, value)}} as written in the SSD."""
    doc = etree.fromstring(zipfile.ZipFile(ssp).read("SystemStructure.ssd"))
    ssv = "{http://ssp-standard.org/SSP1/SystemStructureParameterValues}"
    return {c.get("name"): {p.get("name"): (p[0].tag.replace(ssv, ""), p[0].get("value"))
                            for p in c.iter(f"{ssv}Parameter")}
            for c in doc.iter(f"{SSD}Component")}


@pytest.mark.parametrize("fmi3", [False, True], ids=["FMI 2.0", "FMI 3.0"])
def test_a_binding_equal_to_the_fmus_default_is_not_written(tmp_path, fmi3):
    """OMSimulator's importer refuses ssv:String in some versions ("Unknown ParameterBinding-type"): a value equal
    to the FMU's own default is left out, whatever its type; a value that differs stays (it changes the system)."""
    cam = fmu_with_defaults(tmp_path / "cam.fmu", fmi3)
    pi = fmu_with_defaults(tmp_path / "pi.fmu", fmi3)
    system = speed_loop_system({"drive": "voltage", "J_m": 1e-5, "backlash": False, "k_shaft": 50.0},
                               {"kp": 1, "ki": 5.0})
    written = _bindings(write_ssp(system, {"cam": cam, "controller": pi}, tmp_path / "loop.ssp"))
    assert written["cam"] == {"k_shaft": ("Real", "50.0")}
    assert written["controller"] == {"ki": ("Real", "5.0")}
    changed = speed_loop_system({"drive": "speed", "J_m": 2e-5, "backlash": True})
    written = _bindings(write_ssp(changed, {"cam": cam, "controller": pi}, tmp_path / "changed.ssp"))
    assert written["cam"] == {"drive": ("String", "speed"), "J_m": ("Real", "2e-05"), "backlash": ("Boolean", "true")}


@pytest.mark.parametrize("name, stop", [("compliant_loop", 2.0), ("speed_loop", 2.0)])
def test_the_shipped_loops_bind_no_default_and_carry_their_own_experiment(name, stop):
    """compliant_loop.ssp bound cam.fmu's drive = 'voltage' (its default) as an ssv:String, which OMSimulator could
    not import; the SSD's ssd:DefaultExperiment holds the loop's start and stop time (a run given none takes them)."""
    from cam_fmu.fmu.build import ensure_fmu, ensure_ssp
    from cam_fmu.fmu.ssp import fmu_defaults

    ssp = ensure_ssp(name)
    written = _bindings(ssp)
    defaults = {"cam": fmu_defaults(ensure_fmu(None, None, "cam")),
                "controller": fmu_defaults(ensure_fmu(None, None, "pi_speed"))}
    for comp, bound in written.items():
        for pname, (kind, value) in bound.items():
            assert kind != "String", (comp, pname)
            assert float(value) != defaults[comp][pname], (comp, pname)
    doc = etree.fromstring(zipfile.ZipFile(ssp).read("SystemStructure.ssd"))
    experiment = doc.find(f"{SSD}DefaultExperiment")
    assert (float(experiment.get("startTime")), float(experiment.get("stopTime"))) == (0.0, stop)
    assert read_ssp(ssp).stop_time == stop


def test_the_numbers_the_fmus_read_from_scene_files_are_the_scenes():
    """fmu.scene_data reads two shipped scene files as plain TOML (the fmu layer imports no experiments):
    cam.fmu's default experiment and compliant_loop.ssp's drive equal what the scene parser makes of them."""
    from cam_fmu.experiments.scenes import find_scene
    from cam_fmu.fmu import engine_fmu, ssp

    fig6 = find_scene("paper_fig6")
    assert engine_fmu.default_experiment() == (0.0, fig6.stop_time, fig6.output_interval)
    shaft = find_scene("compliant_shaft")
    assert ssp.compliant_loop_system().components["cam"].parameters == {**shaft.parameters, **shaft.runs[0].overrides}
