"""cam-fmu sweep: cases on dask.distributed equal serial runs bit for bit.

Serial and distributed sweeps run as child processes (FMUs load only there). dask
must be installed (the CI installs it): a missing dask fails these tests.
"""
from __future__ import annotations

import contextlib
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cam_fmu.experiments.sweep import SweepError, cases, parse_vary

ROOT = Path(__file__).resolve().parents[2]
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
    assert lines[0] == ("case,m [kg],rise_law,peak_i [A],peak_M [N.m],ripple [rad/s],final_omega [rad/s],status,"
                        "message")
    assert len(lines) == 1 + 6
    rows = [line.split(",")[1:] for line in lines[1:]]
    assert [line.split(",")[0] for line in lines[1:]] == ["1", "2", "3", "4", "5", "6"]
    # a heavier follower slows the spin-up: final omega falls with m for each law
    for law in ("paper", "cycloidal"):
        finals = [float(r[5]) for r in rows if r[1] == law]
        assert finals == sorted(finals, reverse=True) and finals[0] > finals[-1]
    assert all(r[6:] == ["ok", ""] for r in rows)


FAILING = ["sweep", "paper_fig6", "--vary", "max_steps=10000,1,5000", "--metric", "final_omega",
           "--stop-time", "0.05", "--no-plot"]


@pytest.mark.parametrize("where", [["--serial"], ["--workers", "2"]], ids=["serial", "workers"])
def test_a_failing_case_keeps_every_row_and_is_named(cam_fmu_path, tmp_path, where):
    """max_steps = 1 cannot complete a step: that case fails, the other two run; exit 1 at the end."""
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", *FAILING, "--fmu", str(cam_fmu_path),
                           "--out", str(out), *where], capture_output=True, text=True, env=_env(),
                          cwd=tmp_path, timeout=600)
    assert proc.returncode == 1, proc.stderr[-3000:]
    with open(out / "paper_fig6_sweep.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["case", "max_steps [1]", "final_omega [rad/s]", "status", "message"]
    assert [r[0] for r in rows[1:]] == ["1", "2", "3"]  # the case numbers
    rows = [r[1:] for r in rows]
    assert [float(r[0]) for r in rows[1:]] == [10000, 1, 5000]
    assert [r[2] for r in rows[1:]] == ["ok", "failed", "ok"]
    assert "max_steps = 1 internal steps" in rows[2][3] and rows[2][1] == "nan"
    assert float(rows[1][1]) > 0 and rows[1][1] == rows[3][1]  # both complete the same steps
    lines = proc.stderr.strip().splitlines()
    assert lines[-2].startswith("# case 2 (max_steps=1.0) failed: ") and "max_steps = 1" in lines[-2]
    assert lines[-1] == "cam-fmu sweep: 1 of 3 cases failed (rows kept, status 'failed')"
    assert "Traceback" not in proc.stderr and "distributed" not in proc.stderr, proc.stderr


def test_the_fmi3_fmu_sweeps_as_cam_fmu(serial, tmp_path, cam3_fmu_path):
    """`sweep --fmu models/cam3.fmu` failed every case ("Cannot find shared library .../linux64/cam.so": an FMI 3.0
    FMU run as 2.0). The same engine behind FMI 3.0: the same table to the bit; a failing case through it keeps
    the FMU's own message (fmi3 logMessage), as through cam.fmu."""
    cam3 = cam3_fmu_path
    assert _sweep(cam3, tmp_path / "out", "--serial") == serial
    out = tmp_path / "failing"
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", *FAILING, "--fmu", str(cam3), "--out", str(out),
                           "--serial"], capture_output=True, text=True, env=_env(), cwd=tmp_path, timeout=600)
    assert proc.returncode == 1, proc.stderr[-3000:]
    with open(out / "paper_fig6_sweep.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert [r[3] for r in rows[1:]] == ["ok", "failed", "ok"] and "max_steps = 1 internal steps" in rows[2][4]


def _rewritten(fmu: Path, dest: Path, change) -> Path:
    """A copy of ``fmu`` whose modelDescription.xml is ``change(text)``."""
    import zipfile

    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(dest, "w") as out:
        for item in src.infolist():
            data = src.read(item.filename)
            out.writestr(item, change(data.decode()) if item.filename == "modelDescription.xml" else data)
    return dest


@pytest.mark.parametrize("kind, words", [
    ("fmi1", "an FMI 1.0 FMU; runnable are FMI 2.0 and 3.0 co-simulation FMUs"),
    ("model exchange only", "an FMI 2.0 FMU without co-simulation (Model Exchange only)"),
])
def test_an_fmu_that_cannot_run_is_refused_before_any_case_naming_its_version(cam_fmu_path, tmp_path, kind, words):
    import re

    if kind == "fmi1":
        fmu = _rewritten(cam_fmu_path, tmp_path / "v1.fmu", lambda t: t.replace('fmiVersion="2.0"', 'fmiVersion="1.0"'))
    else:
        fmu = _rewritten(cam_fmu_path, tmp_path / "me.fmu",
                         lambda t: re.sub(r"<CoSimulation\b[^>]*?(/>|>.*?</CoSimulation>)", "", t, flags=re.S))
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", *FAILING, "--fmu", str(fmu), "--out", str(out),
                           "--serial"], capture_output=True, text=True, env=_env(), cwd=tmp_path, timeout=300)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert words in proc.stderr and not out.exists()


LONG = ["sweep", "paper_fig6", "--vary", "m=0.2:0.6:400", "--metric", "final_omega", "--stop-time", "10",
        "--no-plot"]


@pytest.mark.parametrize("where", [["--serial"], ["--workers", "2"]], ids=["serial", "workers"])
def test_an_interrupt_keeps_the_finished_cases_and_says_so_on_one_line(cam_fmu_path, tmp_path, where):
    """Ctrl-C (SIGINT to the process group, the dask workers included) once a few cases have finished: exit 130,
    no traceback (KeyboardInterrupt, dask's CancelledError), one line naming what was kept, and the table holds
    exactly the finished cases, each with the numbers a run of that case alone gives."""
    from conftest import interrupt_after_progress

    out = tmp_path / "out"
    status, stderr = interrupt_after_progress([sys.executable, "-m", "cam_fmu.cli", *LONG, "--fmu",
                                               str(cam_fmu_path), "--out", str(out), *where], 3, tmp_path, _env())
    assert status == 130, stderr[-3000:]
    assert "Traceback" not in stderr and "Error" not in stderr and "WARNING" not in stderr, stderr[-3000:]
    last = stderr.strip().splitlines()[-1]
    kept = int(last.split("interrupted: ")[1].split(" of ")[0])
    assert last == f"cam-fmu sweep: interrupted: {kept} of 400 cases finished, kept in {out / 'paper_fig6_sweep.csv'}"
    assert 3 <= kept < 400
    with open(out / "paper_fig6_sweep.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["case", "m [kg]", "final_omega [rad/s]", "status", "message"] and len(rows) == 1 + kept
    masses = [float(r[1]) for r in rows[1:]]
    assert masses == sorted(masses) and all(r[3] == "ok" for r in rows[1:])
    cases = [int(r[0]) for r in rows[1:]]
    assert cases == sorted(set(cases)) and all(1 <= c <= 400 for c in cases)  # each case once
    if where == ["--serial"]:  # serial: the first cases, in order
        assert masses == [float(v) for v in parse_vary("m=0.2:0.6:400").values[:kept]]
    again = tmp_path / "again"  # two of the kept cases, run on their own
    picked = f"m={rows[1][1]},{rows[-1][1]}"
    subprocess.run([sys.executable, "-m", "cam_fmu.cli", *LONG[:2], "--vary", picked, *LONG[4:], "--fmu",
                    str(cam_fmu_path), "--out", str(again), "--serial"], check=True, capture_output=True,
                   env=_env(), cwd=tmp_path, timeout=600)
    with open(again / "paper_fig6_sweep.csv", newline="") as fh:
        alone = list(csv.reader(fh))[1:]
    assert alone == [["1", *rows[1][1:]], ["2", *rows[-1][1:]]]  # cases 1 and 2 of that sweep


def test_a_local_cluster_says_nothing_when_the_dashboard_port_is_taken(cam_fmu_path, tmp_path):
    """Another dask cluster on the machine holds 8787 (distributed's default port for the scheduler's HTTP server):
    the sweep's stderr carries only its own lines, no UserWarning about the port (seen while tests ran in parallel)."""
    import socket

    holder = socket.socket()
    try:
        holder.bind(("127.0.0.1", 8787))
        holder.listen()
    except OSError:  # already taken by another process: the very condition of this test
        pass
    try:
        proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", *FAILING, "--fmu", str(cam_fmu_path), "--out",
                               str(tmp_path / "out"), "--workers", "2"], capture_output=True, text=True, env=_env(),
                              cwd=tmp_path, timeout=600)
    finally:
        holder.close()
    assert proc.returncode == 1
    assert all(line.startswith(("# ", "cam-fmu sweep: ")) for line in proc.stderr.strip().splitlines()), proc.stderr


def test_vary_drive_is_checked_as_simulate_checks_it(tmp_path):
    """--vary drive=speed on a voltage scene: refused up front, with simulate's own message."""
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "sweep", "paper_fig6", "--vary",
                           "drive=voltage,speed", "--serial", "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, env=_env(), cwd=tmp_path, timeout=300)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "drive = 'speed' needs the input signal 'omega_ref'" in proc.stderr
    # the same sentence simulate gives for a speed scene without omega_ref
    scene = tmp_path / "speed.toml"
    scene.write_text('drive = "speed"\nu = 1.0\nstop_time = 0.1\noutput_interval = 1e-3\n')
    sim = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "simulate", str(scene), "--no-plot"],
                         capture_output=True, text=True, env=_env(), cwd=tmp_path, timeout=300)
    assert sim.returncode == 2 and "drive = 'speed' needs the input signal 'omega_ref'" in sim.stderr


def test_local_cluster_equals_serial_bit_for_bit(cam_fmu_path, serial, tmp_path):
    assert _sweep(cam_fmu_path, tmp_path / "out", "--workers", "2") == serial


@contextlib.contextmanager
def dask_processes(tmp_path: Path, workers: int = 2):
    """A dask scheduler and ``workers`` workers (one process each, with its nanny) started as separate processes
    on loopback; yields the scheduler's address once the workers are up; always torn down."""
    from distributed import Client

    sched_file = tmp_path / "scheduler.json"
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
                               "--port", "0", "--no-dashboard", "--scheduler-file", str(sched_file)], env=_env(),
                              cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        for _ in range(600):
            if sched_file.is_file() and sched_file.stat().st_size:
                break
            time.sleep(0.1)
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for _ in range(workers):
            procs.append(subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file", str(sched_file),
                 "--nworkers", "1", "--nthreads", "1", "--host", "127.0.0.1", "--no-dashboard"],
                env=_env(), cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(workers, timeout=120)
            assert len(client.scheduler_info()["workers"]) == workers
        yield address
    finally:
        for proc in reversed(procs):
            proc.terminate()
        for proc in procs:
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()


def test_scheduler_and_workers_as_processes_equal_serial(cam_fmu_path, serial, tmp_path):
    """A dask scheduler and 2 workers started as separate processes on loopback; always torn down."""
    with dask_processes(tmp_path) as address:
        assert _sweep(cam_fmu_path, tmp_path / "out", "--scheduler", address) == serial
