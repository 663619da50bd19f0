"""The FMUs' own linux64 binaries with hosts that are careless or strict.

- No shipped FMU (cam.fmu, pi_speed.fmu) logs a warning when it starts: fmpy with debug logging and
  the C host (tests/native_host) both see none: both log only what goes wrong.
- A call the wrapper refuses (a NULL or bogus component, an unknown value reference) still writes safe
  values (0, false, "") into every output array: a host that ignores the status reads no garbage.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from native_support import ROOT, compile_host, extract, run_host, run_python, value_references

FMPY_START = """
import json, os, sys
from fmpy import simulate_fmu
logs = []
def logger(env, name, status, category, message):
    logs.append([int(status), category.decode(errors="replace"), message.decode(errors="replace")])
simulate_fmu(sys.argv[1], stop_time=0.01, output_interval=1e-3, debug_logging=True, logger=logger)
print(json.dumps(logs))
sys.stdout.flush(); os._exit(0)  # pythonfmu 0.7.0 may abort at interpreter teardown
"""


@pytest.fixture(scope="module")
def host(tmp_path_factory) -> Path:
    return compile_host(tmp_path_factory.mktemp("robust_host") / "host")


@pytest.fixture(params=["cam", "pi_speed"])
def shipped(request, cam_fmu_path, pi_speed_fmu_path) -> Path:
    return cam_fmu_path if request.param == "cam" else pi_speed_fmu_path


def _guid(fmu_dir: Path) -> str:
    import xml.etree.ElementTree as ET

    return ET.parse(fmu_dir / "modelDescription.xml").getroot().get("guid")


def test_no_warning_at_start_in_fmpy(shipped, tmp_path):
    logs = run_python(FMPY_START, str(shipped), cwd=tmp_path)
    assert [x for x in logs if x[0] >= 1] == [], f"{shipped.name} warns or fails at start"


def test_no_warning_at_start_in_the_c_host(shipped, host, tmp_path):
    fmu_dir = extract(shipped, tmp_path / "fmu")
    r = run_host(host, fmu_dir, "guid", _guid(fmu_dir), "inst", "init", "step", "10", "0.001", "free")
    assert r["rc"] == 0 and r["lines"][-1] == {"exit": 0}, r
    assert [x["status"] for x in r["cmds"] if "status" in x] == [0, 0, 0]
    assert r["logs"] == [] and r["stderr"] == "", f"{shipped.name}: {r['logs']} {r['stderr']}"


def test_null_and_bogus_components_get_safe_outputs(host, shipped, tmp_path):
    r = run_host(host, extract(shipped, tmp_path / "fmu"), "nullcalls")
    assert r["rc"] == 0 and r["lines"][-1] == {"exit": 0}, r
    calls = [x for x in r["cmds"] if x["cmd"] == "nullcalls"]
    assert [x["component"] for x in calls] == ["null", "bogus"]
    for x in calls:
        assert all(s >= 3 for s in x["statuses"]), x  # every call refused (fmi2Error or worse)
        assert x["real"] == [0, 0, 0] and x["integer"] == [0, 0, 0] and x["boolean"] == [0, 0, 0], x
        assert x["string"] == ["", "", ""] and x["string_status"] == [""], x
        assert x["status"] == 0 and x["real_status"] == 0 and x["integer_status"] == 0, x
        assert x["boolean_status"] == 0, x
        assert x["directional"] == [0, 0] and x["output_derivatives"] == [0, 0], x
    assert r["stderr"] == ""  # a component that is no instance has no logger: nothing is printed either


def test_unknown_value_reference_leaves_safe_outputs(host, shipped, tmp_path):
    fmu_dir = extract(shipped, tmp_path / "fmu")
    vr = value_references(fmu_dir)
    unknown = str(max(vr.values()) + 1000)
    real, string = ("omega", "rise_law") if shipped.name == "cam.fmu" else ("u", "external_setpoint")
    r = run_host(host, fmu_dir, "guid", _guid(fmu_dir), "inst", "init", "getr", f"{vr[real]},{unknown}", "gets",
                 f"{vr[string]},{unknown}", "free")
    getr = next(x for x in r["cmds"] if x["cmd"] == "getr")
    gets = next(x for x in r["cmds"] if x["cmd"] == "gets")
    assert getr["status"] == 3 and getr["values"] == [0, 0], getr
    assert gets["status"] == 3 and gets["values"] == ["", ""], gets
