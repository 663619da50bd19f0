"""The C-built cam.fmu in the C test host (tests/native_host/host.c): an empty environment,
valgrind memcheck, refusals that leave safe values. gcc and valgrind are required tools."""
from __future__ import annotations

import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest

from native_support import compile_host, run_host, valgrind_prefix, valgrind_summary


@pytest.fixture(scope="module")
def fmu_dir(engine_fmu_path, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("engine_fmu_c_host")
    with zipfile.ZipFile(engine_fmu_path) as z:
        z.extractall(folder)
    return folder


@pytest.fixture(scope="module")
def host(tmp_path_factory) -> Path:
    return compile_host(tmp_path_factory.mktemp("host") / "host")


def _md(fmu_dir: Path) -> tuple[str, dict[str, str]]:
    root = ET.parse(fmu_dir / "modelDescription.xml").getroot()
    return root.get("guid"), {sv.get("name"): sv.get("valueReference") for sv in root.iter("ScalarVariable")}


def test_runs_in_an_empty_environment_and_restores_its_state_exactly(host, fmu_dir):
    guid, vr = _md(fmu_dir)
    outputs = ",".join(vr[n] for n in ("omega", "theta", "i"))
    result = run_host(host, fmu_dir, "guid", guid, "inst", "init", "step", "200", "0.001", "save", "serial",
                      "step", "100", "0.001", "getr", outputs, "restore", "stepat", "0.2", "0.1", "getr", outputs,
                      "free")  # run_host: env -i PATH=/usr/bin:/bin
    assert result["rc"] == 0, result["stderr"]
    statuses = {c["cmd"]: c.get("status") for c in result["cmds"]}
    assert statuses["init"] == statuses["save"] == statuses["serial"] == statuses["restore"] == 0
    first, again = [c["values"] for c in result["cmds"] if c["cmd"] == "getr"]
    assert first[1] > 0.1  # theta(0.3 s) [rad]: the cam turned
    # one 0.1 s step from the restored state lands where 100 steps of 1 ms did, to rk45's tolerance
    assert again[1] == pytest.approx(first[1], rel=1e-8)


def test_valgrind_finds_no_error_and_no_leak_over_instance_cycles(host, fmu_dir, tmp_path):
    guid, vr = _md(fmu_dir)
    log = tmp_path / "memcheck.log"
    commands = ["guid", guid]
    for _ in range(3):
        commands += ["inst", "setr", vr["c"], "0.002", "init", "step", "50", "0.001", "save", "serial", "restore",
                     "setr", vr["u"], "nan", "stepat", "5", "0.001", "reset", "init", "step", "5", "0.001", "free"]
    commands += ["cycles", "50", "nullcalls"]
    result = run_host(host, fmu_dir, *commands, prefix=valgrind_prefix(log))
    assert result["rc"] == 0, result["stderr"][-2000:]
    summary = valgrind_summary(log)
    assert summary["summaries"] >= 1
    assert summary["errors"] == 0, summary["excerpt"]
    assert "definitely lost" not in log.read_text() or "definitely lost: 0 bytes" in log.read_text()
    statuses = [c["status"] for c in result["cmds"] if c["cmd"] in ("setr", "stepat")]
    assert statuses == [0, 3, 3] * 3  # c accepted; a NaN input and a step at the wrong time: fmi2Error
    nulls = [c for c in result["cmds"] if c["cmd"] == "nullcalls"]
    assert len(nulls) == 2 and all(set(c["statuses"]) == {3} and c["real"] == [0, 0, 0] for c in nulls)
