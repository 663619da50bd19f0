"""A block written in Python (the shipped pythonfmu example) closing the speed loop around cam.fmu in
`cam-fmu cosim --controller`: built with `cam-fmu python-block`, run in child processes (a pythonfmu FMU is
never loaded into pytest). The example is the same PI law as pi_speed.fmu without feedforward, so the loop
must give the C controller's loop to the bit.
"""
from __future__ import annotations

import csv
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "cam_fmu.cli", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=600)


def _columns(path: Path) -> dict[str, np.ndarray]:
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    data = np.array(rows[1:], dtype=float)
    return {name.split(" [")[0]: data[:, k] for k, name in enumerate(rows[0])}


@pytest.fixture(scope="module")
def block(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("python_block")
    proc = _cli("python-block", "--dest", str(folder / "python_pi.fmu"), cwd=folder)
    assert proc.returncode == 0, proc.stderr
    return folder / "python_pi.fmu"


def test_the_example_is_a_pythonfmu_fmu(block):
    with zipfile.ZipFile(block) as z:
        names = z.namelist()
    assert "resources/python_pi_slave.py" in names and "binaries/linux64/PythonPi.so" in names
    from fmpy import read_model_description

    md = read_model_description(str(block))
    causality = {v.name: v.causality for v in md.modelVariables}
    assert causality["omega_meas"] == "input" and causality["u"] == "output" and causality["kp"] == "parameter"


def test_the_python_block_closes_the_loop_as_the_c_controller_does(block, cam_fmu_path, tmp_path):
    python_run = _cli("cosim", "--controller", str(block), "--out", str(tmp_path / "py"), "--no-plot", cwd=tmp_path)
    assert python_run.returncode == 0, python_run.stderr
    c_run = _cli("cosim", "--out", str(tmp_path / "c"), "--no-plot", cwd=ROOT)
    assert c_run.returncode == 0, c_run.stderr
    py = _columns(tmp_path / "py" / f"speed_loop_{block.stem}.csv")
    c = _columns(tmp_path / "c" / "speed_loop.csv")
    assert np.array_equal(py["time"], c["time"]) and py["time"][-1] == pytest.approx(2.0)
    # the same law, the same operations: the same bits (C's u_ff + kp e adds an exact 0.0)
    assert np.array_equal(py["cam.omega"], c["cam.omega"]) and np.array_equal(py["controller.u"], c["controller.u"])
    assert abs(py["cam.omega"][len(py["time"]) // 2:].mean() - 5.0) < 0.2  # it tracks the 5 rad/s setpoint


def test_a_controller_without_the_connectors_is_refused(cam_fmu_path, tmp_path):
    proc = _cli("cosim", "--controller", str(cam_fmu_path), "--out", str(tmp_path), cwd=tmp_path)
    assert proc.returncode == 2
    assert "needs an input 'omega_meas' and an output 'u'" in proc.stderr and "Traceback" not in proc.stderr
