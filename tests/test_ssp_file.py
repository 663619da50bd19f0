"""The SSP file the project writes and what read_ssp accepts.

- The SSD validates against the SSP 1.0 schema that fmpy ships, with OMSimulator's vendor annotation
  inside ssd:System carrying the loop's own step (OMSimulator aborts without it; ecos and libcosim run
  the annotated file in tests/test_speed_loop.py).
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

from cam_fmu.experiments.ssp import OMS, Connection, SspError, read_ssp, speed_loop_system, write_ssp

ROOT = Path(__file__).resolve().parents[1]
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
    from cam_fmu.experiments.fmu_file import ensure_ssp

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
