"""cam-fmu sweep: cases on dask.distributed equal serial runs bit for bit.

Serial and distributed sweeps run as child processes (FMUs load only there). dask
must be installed (the CI installs it): a missing dask fails these tests.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cam_fmu.experiments.sweep import SweepError, cases, parse_vary

ROOT = Path(__file__).resolve().parents[1]
SWEEP = ["sweep", "paper_fig6", "--vary", "m=0.2:0.6:3", "--vary", "rise_law=paper,cycloidal",
         "--metric", "peak_i,peak_M,ripple,final_omega", "--stop-time", "0.3", "--no-plot"]


def _env() -> dict:
    return {**os.environ, "PYTHONPATH": str(ROOT), "CAM_FMU_PROGRESS": "0"}


def _sweep(fmu: Path, out: Path, *extra: str) -> str:
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", *SWEEP, "--fmu", str(fmu), "--out", str(out), *extra],
                          capture_output=True, text=True, env=_env(), cwd=out.parent, timeout=600)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return (out / "paper_fig6_sweep.csv").read_text()


def test_parse_vary_and_cases():
    v = parse_vary("m=0.2:0.6:3")
    assert v.name == "m" and v.values == (0.2, 0.4, 0.6000000000000001) or v.values[0] == 0.2
    assert len(v.values) == 3 and v.values[-1] == pytest.approx(0.6)
    laws = parse_vary("rise_law=paper,cycloidal")
    assert laws.values == ("paper", "cycloidal")
    assert cases([v, laws])[:2] == [{"m": 0.2, "rise_law": "paper"}, {"m": 0.2, "rise_law": "cycloidal"}]
    with pytest.raises(SweepError, match=r"'m' = -1.0 .*allowed range \[0, 10000\]"):
        parse_vary("m=-1:1:3")
    with pytest.raises(SweepError, match="unknown parameter 'mass'"):
        parse_vary("mass=1:2:3")
    with pytest.raises(SweepError, match="allowed one of"):
        parse_vary("rise_law=paper,nonsense")


@pytest.fixture(scope="module")
def serial(cam_fmu_path, tmp_path_factory) -> str:
    return _sweep(cam_fmu_path, tmp_path_factory.mktemp("serial") / "out", "--serial")


def test_serial_table(serial):
    lines = serial.strip().splitlines()
    assert lines[0] == "m [kg],rise_law,peak_i [A],peak_M [N.m],ripple [rad/s],final_omega [rad/s]"
    assert len(lines) == 1 + 6
    rows = [line.split(",") for line in lines[1:]]
    # a heavier follower slows the spin-up: final omega falls with m for each law
    for law in ("paper", "cycloidal"):
        finals = [float(r[5]) for r in rows if r[1] == law]
        assert finals == sorted(finals, reverse=True) and finals[0] > finals[-1]


def test_local_cluster_equals_serial_bit_for_bit(cam_fmu_path, serial, tmp_path):
    assert _sweep(cam_fmu_path, tmp_path / "out", "--workers", "2") == serial


def test_scheduler_and_workers_as_processes_equal_serial(cam_fmu_path, serial, tmp_path):
    """A dask scheduler and 2 workers started as separate processes on loopback; always torn down."""
    sched_file = tmp_path / "scheduler.json"
    dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
    procs = [subprocess.Popen([*dask, "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(sched_file)], env=_env(), cwd=tmp_path,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        for _ in range(600):
            if sched_file.is_file() and sched_file.stat().st_size:
                break
            time.sleep(0.1)
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for _ in range(2):
            procs.append(subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file", str(sched_file),
                 "--nworkers", "1", "--nthreads", "1", "--host", "127.0.0.1", "--no-dashboard"],
                env=_env(), cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from distributed import Client
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(2, timeout=120)
            assert len(client.scheduler_info()["workers"]) == 2
        assert _sweep(cam_fmu_path, tmp_path / "out", "--scheduler", address) == serial
    finally:
        for proc in reversed(procs):
            proc.terminate()
        for proc in procs:
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
