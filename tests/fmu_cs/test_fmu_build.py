"""cam.fmu as built by build_fmu.py: model description, bundle, run without cam_fmu installed."""
from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from cam_fmu.physics import parameters  # the pytest process may import cam_fmu: it never loads the FMU
from cam_fmu.physics.variables import STATES

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def md_root(cam_fmu_path):
    with zipfile.ZipFile(cam_fmu_path) as z:
        return ET.fromstring(z.read("modelDescription.xml"))


def test_validate_fmu_reports_no_problem(cam_fmu_path):
    from fmpy.validation import validate_fmu  # reads the XML only; does not load the binary
    assert validate_fmu(str(cam_fmu_path)) == []


def test_default_build_target_is_models_cam_fmu():
    from cam_fmu.fmu.build import default_fmu_path
    assert default_fmu_path() == ROOT / "models" / "cam.fmu"


def test_model_description_complete(md_root):
    assert md_root.get("modelName") == "cam" and md_root.get("description")
    cs = md_root.find("CoSimulation")
    assert cs.get("modelIdentifier") == "cam"
    assert cs.get("canGetAndSetFMUstate") == "true" and cs.get("canSerializeFMUstate") == "true"
    exp = md_root.find("DefaultExperiment")
    assert (float(exp.get("startTime")), float(exp.get("stopTime")), float(exp.get("stepSize"))) == (0.0, 2.0, 1e-3)
    assert float(exp.get("tolerance")) == parameters.BY_NAME["rtol"].default  # a Model Exchange host's rtol
    units = {u.get("name") for u in md_root.find("UnitDefinitions")}
    variables = md_root.find("ModelVariables").findall("ScalarVariable")
    by_name = {v.get("name"): v for v in variables}
    for index, v in enumerate(variables, start=1):
        assert v.get("causality") and v.get("variability"), v.get("name")
        if v.get("causality") != "input":  # FMI 2.0 forbids 'initial' on inputs
            assert v.get("initial"), v.get("name")
        real = v.find("Real")
        if real is not None and real.get("unit"):
            assert real.get("unit") in units
    # every parameter under its own name, unit, start and kind
    for spec in parameters.PARAMETERS:
        v = by_name[spec.name]
        assert v.get("causality") == "parameter" and v.get("variability") == "fixed"
        kind = {"real": "Real", "boolean": "Boolean", "string": "String"}[spec.kind]
        typed = v.find(kind)
        assert typed is not None, spec.name
        if spec.kind == "real":
            assert float(typed.get("start")) == spec.default  # exact: written with repr
            if spec.unit:
                assert typed.get("unit") == spec.unit
        elif spec.kind == "boolean":
            assert typed.get("start") == ("true" if spec.default else "false")
        else:
            assert typed.get("start") == spec.default
    # inputs and outputs
    assert by_name["u"].get("causality") == "input" and float(by_name["u"].find("Real").get("start")) == 3.5
    assert by_name["u"].find("Real").get("unit") == "V"
    assert by_name["omega_ref"].get("causality") == "input"
    index_of = {v.get("name"): k for k, v in enumerate(variables, start=1)}
    outputs = {n for n, v in by_name.items() if v.get("causality") == "output"}
    assert {"omega", "theta", "s", "i", "M", "J", "v", "a", "alpha", "s_cam"} <= outputs
    structure = md_root.find("ModelStructure")
    listed = {int(u.get("index")) for u in structure.find("Outputs")}
    initial = {int(u.get("index")) for u in structure.find("InitialUnknowns")}
    assert listed == {index_of[n] for n in outputs}
    # Model Exchange: the states and their derivatives are initial unknowns too (calculated)
    states = {n for n, v in by_name.items() if v.get("causality") == "local"}
    assert initial == listed | {index_of[n] for n in states} and len(states) == 2 * len(STATES)
    assert by_name["omega"].find("Real").get("unit") == "rad/s"


@pytest.mark.parametrize("model, source", [("cam", "sources/cam_model.h"), ("pi_speed", "sources/pi_law.c")])
def test_shipped_fmus_carry_no_python(model, source, cam_fmu_path, pi_speed_fmu_path):
    """cam.fmu and pi_speed.fmu are C models on the shared glue: binaries and their C sources, no Python module,
    no pythonfmu, no python.txt, and their Linux binary links no libpython."""
    path = cam_fmu_path if model == "cam" else pi_speed_fmu_path
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
        binary = z.read(f"binaries/linux64/{model}.so")
    assert f"binaries/linux64/{model}.so" in names and source in names and "sources/model.h" in names
    assert not [n for n in names if n.endswith((".py", ".pyc")) or "python" in n.lower()], names
    assert b"libpython" not in binary and b"Py_Initialize" not in binary


ISOLATED_RUN = r"""
import json, sys
sys.path.extend(json.loads(sys.argv[1]))       # site-packages only: no .pth files, no editable cam_fmu
try:
    import cam_fmu
    importable = cam_fmu.__file__
except ImportError:
    importable = None
from fmpy import simulate_fmu
import numpy as np
path_before, modules_before = list(sys.path), set(sys.modules)
res = simulate_fmu(sys.argv[2], output_interval=1e-3)
added = sorted(m for m in set(sys.modules) - modules_before if m.startswith(("cam", "pythonfmu")))
print(json.dumps({
    "importable_before": importable,
    "stop": float(res["time"][-1]),
    "finite": bool(all(np.all(np.isfinite(res[n])) for n in res.dtype.names)),
    "end": float(res[sys.argv[3]][-1]),
    "added_modules": added, "path_unchanged": sys.path == path_before,
    "scipy_loaded": any(m.split(".")[0] == "scipy" for m in sys.modules),
}))
"""


@pytest.mark.parametrize("model, output", [("cam", "omega"), ("pi_speed", "u")])
def test_fmu_runs_where_cam_fmu_is_not_importable(model, output, cam_fmu_path, pi_speed_fmu_path, tmp_path):
    fmu = f"{model}.fmu"
    shutil.copyfile(cam_fmu_path if model == "cam" else pi_speed_fmu_path, tmp_path / fmu)
    site_dirs = [p for p in {sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]}]
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    # -I: no PYTHONPATH, no cwd/script dir, no user site; -S: no site-packages .pth (the editable install)
    proc = subprocess.run([sys.executable, "-I", "-S", "-c", ISOLATED_RUN, json.dumps(site_dirs), fmu, output],
                          cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    r = json.loads(proc.stdout.strip().splitlines()[-1])
    assert r["importable_before"] is None, f"cam_fmu importable in the isolated process: {r['importable_before']}"
    assert r["stop"] == pytest.approx(2.0, abs=1e-12), "the run stopped before its stop time"
    assert r["finite"] and abs(r["end"]) > 0.5
    # a C FMU adds no module and changes no path
    assert r["added_modules"] == [] and r["path_unchanged"], r
    assert not r["scipy_loaded"]


def test_docs_variable_table_is_the_generated_one():
    """docs/fmu.md's FMU variable table is `python -m cam_fmu.fmu.model_description`'s output: it cannot drift from the code."""
    from pathlib import Path

    from cam_fmu.fmu.model_description import markdown_table
    doc = (Path(__file__).resolve().parents[2] / "docs" / "fmu.md").read_text(encoding="utf-8")
    assert markdown_table().strip() in doc


def test_every_fmu_the_project_builds_declares_the_engines_tolerance(cam_fmu_path, pi_speed_fmu_path, cam3_fmu_path):
    """A host that integrates with its own solver reads the DefaultExperiment's tolerance and otherwise runs at
    its own default (fmpy 1e-5, OMSimulator's own): every FMU declares the engine's rtol (docs/fmu.md)."""
    for fmu in (cam_fmu_path, pi_speed_fmu_path, cam3_fmu_path):
        with zipfile.ZipFile(fmu) as z:
            exp = ET.fromstring(z.read("modelDescription.xml")).find("DefaultExperiment")
        assert exp is not None and float(exp.get("tolerance")) == parameters.BY_NAME["rtol"].default, fmu.name


HOLDER = r"""
import sys, time
from pathlib import Path
from cam_fmu.fmu.build_lock import building
folder, log = Path(sys.argv[1]), Path(sys.argv[2])
with building(folder):
    log.write_text("first in\n")
    print("holding", flush=True)
    time.sleep(0.5)
    with open(log, "a") as fh:
        fh.write("first out\n")
"""


def test_a_second_builder_waits_for_the_first(tmp_path):
    """ensure_fmu and ensure_ssp build under their folder's lock (fmu/build_lock.py): a process that asks while
    another builds enters only once the first has let go (then finds the file up to date: ensure_fmu)."""
    from cam_fmu.fmu.build_lock import LOCK_NAME, building

    log = tmp_path / "log.txt"
    holder = subprocess.Popen([sys.executable, "-c", HOLDER, str(tmp_path), str(log)], stdout=subprocess.PIPE,
                              text=True, cwd=ROOT)
    try:
        assert holder.stdout.readline().strip() == "holding"
        with building(tmp_path):
            with open(log, "a") as fh:
                fh.write("second in\n")
    finally:
        holder.wait(timeout=60)
    assert holder.returncode == 0
    assert log.read_text().splitlines() == ["first in", "first out", "second in"]
    assert (tmp_path / LOCK_NAME).is_file() and (tmp_path / LOCK_NAME).stat().st_size == 0


def test_two_writers_of_one_ssp_use_temporary_files_of_their_own(tmp_path, monkeypatch):
    """write_ssp wrote every SSP through `<name>.ssp.tmp`: two processes writing one SSP at once (two commands in
    a fresh checkout) shared that file. Its temporary file now carries the writer's pid."""
    from cam_fmu.engine import reproducible
    from cam_fmu.fmu import ssp

    seen = []
    real = reproducible.write_zip
    monkeypatch.setattr(reproducible, "write_zip", lambda path, entries: (seen.append(Path(path)), real(path, entries)))
    for name in ("cam.fmu", "pi.fmu"):
        with zipfile.ZipFile(tmp_path / name, "w") as z:
            z.writestr("modelDescription.xml", "<fmiModelDescription/>")
    dest = ssp.write_ssp(ssp.speed_loop_system(), {"cam": tmp_path / "cam.fmu", "controller": tmp_path / "pi.fmu"},
                         tmp_path / "loop.ssp")
    assert seen == [tmp_path / f"loop.ssp.{os.getpid()}.tmp"]
    assert dest.is_file() and not seen[0].exists()
