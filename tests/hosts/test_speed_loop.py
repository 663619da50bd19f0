"""The shipped closed loop: pi_speed.fmu + cam.fmu in models/speed_loop.ssp, in four engines.

- the project's master (cam-fmu cosim / experiments.cosim) against the same loop stepped
  in-process without FMUs (fmu.engine.DriveSimulator + control.pi): the same code, so
  they must agree to rounding (1e-9);
- ecos (native C++, reading the SSP file itself) and libcosim (OSP, reading the SSP file)
  against the master, to their output precision.

Both FMUs are C: the project's master runs them in this process through fmpy; ecos, libcosim (an isolated
Python) and the CLI run in their own processes. These tests FAIL (never skip) when ecos or libcosimpy is
missing: the CI installs both.
"""
from __future__ import annotations

import csv
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cam_fmu.experiments.cosim import reference_loop
from cam_fmu.fmu.ssp import PARAMETER_SET, read_ssp, speed_loop_system, write_ssp
from cam_fmu.tools import ecos_host

ROOT = Path(__file__).resolve().parents[2]
STOP = 2.0


def _child(args: list[str], cwd: Path, isolated: bool = False, timeout: float = 300) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    if isolated:
        env.pop("PYTHONPATH", None)
    else:
        env["PYTHONPATH"] = str(ROOT)  # this checkout, not an installed cam_fmu
    proc = subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=cwd, env=env,
                          timeout=timeout)
    if proc.returncode != 0:
        pytest.fail(f"{args} exited with {proc.returncode}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return proc


@pytest.fixture(scope="module")
def ssp(cam_fmu_path, pi_speed_fmu_path, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("speed_loop")
    pi_fmu = pi_speed_fmu_path  # the session's build (conftest.py: build_fmu.py --model pi_speed)
    # a controller with feedforward, so that every connection (u, omega, M, J) carries a signal
    system = speed_loop_system({"gamma": math.pi}, {"feedforward": 1.0, "kp": 2.0, "ki": 20.0}, stop_time=STOP)
    return write_ssp(system, {"cam": cam_fmu_path, "controller": pi_fmu}, folder / "speed_loop.ssp")


@pytest.fixture(scope="module")
def master(ssp) -> dict:
    from cam_fmu.experiments.cosim import simulate_system
    return {k: np.asarray(v) for k, v in simulate_system(str(ssp), record=["cam.gamma", "controller.integral"]).items()}


@pytest.fixture(scope="module")
def reference(ssp) -> dict:
    return reference_loop(read_ssp(ssp))


def test_master_equals_the_in_process_loop(master, reference):
    assert np.array_equal(master["time"], reference["time"]) and master["time"][-1] == pytest.approx(STOP)
    for column in ("cam.omega", "controller.u", "cam.M", "cam.J"):
        diff = float(np.max(np.abs(master[column] - reference[column])))
        assert diff <= 1e-9, f"{column}: FMU loop and in-process loop differ by {diff}"


def test_master_semantics(master, ssp):
    # the SSP's parameter values reach the FMUs (cam.gamma = pi, not its default)
    assert np.all(master["cam.gamma"] == math.pi)
    # the first step sees the controller's initial output, not 0: kp * 5 + c_e * 5 + R M(0) / c_m V with
    # cam's initial M(0) = M_f = 0.012 N m passed to the controller during initialisation
    assert master["controller.u"][0] == pytest.approx(2.0 * 5.0 + 0.146 * 5.0 + 19.0 * 0.012 / 0.147099750,
                                                      abs=1e-6)
    # rows are labelled with the time their values belong to: omega at t = 0 is the initial state (rest),
    # and the first step's result (after 1 ms at about 10.7 V) is labelled 1 ms
    assert master["time"][0] == 0.0 and master["cam.omega"][0] == 0.0
    assert master["time"][1] == 1e-3 and master["cam.omega"][1] > 1.0
    assert abs(master["cam.omega"][len(master["time"]) // 2:].mean() - 5.0) < 0.1


def test_ecos_runs_the_ssp_and_agrees(ssp, master):
    """ecos reads the SSP (parameters, connections) itself. Its CSV has 6 decimals: agreement to 1e-6."""
    columns = _ecos_columns(ssp)
    assert np.all(columns["controller.feedforward"] == 1.0)  # the SSP's parameter values were applied
    assert len(columns["time"]) == len(master["time"])
    assert np.max(np.abs(columns["time"] - master["time"])) < 1e-9
    for column in ("cam.omega", "controller.u", "cam.M"):
        diff = float(np.max(np.abs(columns[column] - master[column])))
        assert diff <= 1e-6, f"ecos vs cam-fmu cosim: {column} differs by {diff}"


def _ecos_columns(ssp: Path) -> dict:
    """Run ecos in a fresh folder and read its CSV with instance names (cam.u and controller.u differ)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        # ecos applies an SSP's parameter values only when told the parameter set's name
        run = ecos_host.simulate(ssp, STOP, 1e-3, workdir=Path(tmp), extra_args=["--parameterSet", PARAMETER_SET])
        assert run.returncode == 0, run.stderr[-2000:]
        return ecos_host.read_csv(next(Path(tmp).glob("*.csv")), keep_instance=True)


def test_libcosim_runs_the_ssp_and_agrees(ssp, master):
    """libcosim (in a Python host, isolated: the FMUs run their bundled code) agrees to 1e-8.

    libcosim counts time in integer nanoseconds, so the step times it passes to doStep differ
    from k * 1e-3 in the last bits; the results differ by about 1e-11.
    """
    script = ROOT / "cam_fmu" / "tools" / "libcosim_host.py"
    out = _child(["-I", str(script), str(ssp), str(STOP), "cam.omega", "controller.u", "cam.M"],
                 cwd=ssp.parent, isolated=True).stdout
    lc = {k: np.array(v) for k, v in json.loads([l for l in out.splitlines() if l.startswith("{")][-1]).items()}
    assert len(lc["time"]) == len(master["time"]) - 1  # libcosim's rows start after the first step
    assert np.max(np.abs(lc["time"] - master["time"][1:])) < 1e-12
    for column in ("cam.omega", "controller.u", "cam.M"):
        diff = float(np.max(np.abs(lc[column] - master[column][1:])))
        assert diff <= 1e-8, f"libcosim vs cam-fmu cosim: {column} differs by {diff}"


def test_cli_cosim_writes_csv_with_units_and_figure(ssp, reference, tmp_path):
    proc = _child(["-m", "cam_fmu.cli", "cosim", str(ssp), "--out", str(tmp_path)], cwd=tmp_path)
    assert "ripple" in proc.stdout
    with open(tmp_path / "speed_loop.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    header = rows[0]
    assert header[:3] == ["time [s]", "controller.u [V]", "cam.omega [rad/s]"]
    data = np.array(rows[1:], dtype=float)
    for k, name in enumerate(header):
        column = name.split(" [")[0]
        assert np.allclose(data[:, k], reference[column], rtol=1e-11, atol=1e-12), column
    assert (tmp_path / "speed_loop.png").read_bytes()[:4] == b"\x89PNG"


def test_an_interrupted_cosim_keeps_the_finished_runs_and_the_steps_done(ssp, tmp_path):
    """Ctrl-C in the second of two runs (SIGINT to the process group; pi_speed.fmu runs Python in this process, where
    a KeyboardInterrupt inside its doStep was a fatal FMU status and the rows were lost): exit 130, one line, no
    traceback; the first run's CSV whole, the second's up to the last step, both equal to the in-process loop."""
    from conftest import interrupt_after_progress

    status, stderr = interrupt_after_progress(
        [sys.executable, "-m", "cam_fmu.cli", "cosim", str(ssp), "--gains", "1:10,2:20", "--stop-time", "60",
         "--no-plot", "--out", str(tmp_path)], 3000, tmp_path, {**os.environ, "PYTHONPATH": str(ROOT)},
        label="kp=2 ki=20")
    assert status == 130, stderr[-3000:]
    assert "Traceback" not in stderr and "fatal" not in stderr, stderr[-3000:]
    last = stderr.strip().splitlines()[-1]
    second = tmp_path / "speed_loop__kp2_ki20.csv"
    assert last.startswith("cam-fmu cosim: interrupted at t = ") and last.endswith(
        f"of 60000 steps): kept in {second}; the 1 runs before it in {tmp_path}"), last
    system = read_ssp(ssp)
    for path, gains in ((tmp_path / "speed_loop__kp1_ki10.csv", (1.0, 10.0)), (second, (2.0, 20.0))):
        with open(path, newline="") as fh:
            rows = list(csv.reader(fh))
        data = np.array(rows[1:], dtype=float)
        steps = len(data) - 1
        assert steps >= 3000 and (steps == 60000) == (path != second), path
        assert np.allclose(data[:, 0], np.arange(steps + 1) * 1e-3, rtol=1e-11, atol=1e-12)  # no row lost or doubled
        system.components["controller"].parameters.update(kp=gains[0], ki=gains[1])
        twin = reference_loop(system, stop_time=steps * 1e-3)
        for k, name in enumerate(rows[0][1:], start=1):
            assert np.allclose(data[:, k], twin[name.split(" [")[0]], rtol=1e-11, atol=1e-12), (path.name, name)
