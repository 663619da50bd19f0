"""cam.fmu in a native co-simulation host: ecos (C++).

These tests FAIL (never skip) when ecos or libtbb12 is missing:
importing the FMU into non-Python tools is part of the product.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cam_fmu.tools import ecos_host

RUNS = 4
STOP, STEP = 2.0, 1e-3  # the default experiment (fig. 6)
# ecos writes its CSV with 6 decimals: |omega| < 100 rad/s gives at most 5e-7 rad/s of rounding.
# Everything else is the same FMU code stepped on the same grid, so the runs must agree to that.
OMEGA_TOL = 2e-6


def test_host_env_is_a_deprecation_line():
    """`cam-fmu host-env` no longer prints an environment (no shipped FMU needs Python): it says so and exits 0."""
    exe = Path(sys.executable).parent / "cam-fmu"
    cmd = [str(exe)] if exe.is_file() else [sys.executable, "-m", "cam_fmu.cli"]
    proc = subprocess.run([*cmd, "host-env"], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0 and proc.stdout == ""
    assert "deprecated" in proc.stderr and "need no Python" in proc.stderr


def test_ecos_and_libtbb_available():
    binary = ecos_host.ecos_binary()  # raises EcosError (test failure) when missing or unusable
    assert os.access(binary, os.X_OK)
    assert ecos_host.missing_libraries(binary) == []


@pytest.fixture(scope="module")
def fmpy_omega(cam_fmu_path):
    from test_fmu_interface import scenario_omega  # fmpy in this process (cam.fmu is C)
    r = scenario_omega(str(cam_fmu_path))
    return np.array(r["time"]), np.array(r["omega"])


@pytest.fixture(scope="module")
def ecos_runs(cam_fmu_path):
    return [ecos_host.simulate(cam_fmu_path, STOP, STEP) for _ in range(RUNS)]


def test_ecos_runs_repeatedly_without_crash(ecos_runs):
    for k, run in enumerate(ecos_runs):
        # exit status 0 every time: a crash at teardown (Py_Finalize) is a failure
        assert run.returncode == 0, f"run {k}: exit {run.returncode}\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}"
        assert run.stop_time == pytest.approx(STOP, abs=1e-9), f"run {k} stopped at {run.stop_time}"
        assert len(run.columns["time"]) == round(STOP / STEP) + 1
        assert np.all(np.isfinite(run.columns["omega"]))


def test_ecos_omega_matches_fmpy(ecos_runs, fmpy_omega):
    t_fmpy, omega_fmpy = fmpy_omega
    assert t_fmpy[-1] == pytest.approx(STOP, abs=1e-12)
    for run in ecos_runs:
        t, omega = run.columns["time"], run.columns["omega"]
        assert len(t) == len(t_fmpy)
        assert np.max(np.abs(t - t_fmpy)) < 1e-9
        diff = float(np.max(np.abs(omega - omega_fmpy)))
        assert diff <= OMEGA_TOL, f"ecos vs fmpy omega differ by {diff} rad/s"
    # fig. 6: the drive has spun up
    assert omega_fmpy[-1] > 0.5
    # the runs are deterministic
    assert all(np.array_equal(r.columns["omega"], ecos_runs[0].columns["omega"]) for r in ecos_runs)


if __name__ == "__main__":  # print the ecos vs fmpy comparison for the README/report
    fmu = Path(sys.argv[1])
    diffs = []
    for k in range(int(sys.argv[2]) if len(sys.argv) > 2 else RUNS):
        r = ecos_host.simulate(fmu, STOP, STEP)
        diffs.append(r.returncode)
    print(json.dumps({"exit_codes": diffs}))
