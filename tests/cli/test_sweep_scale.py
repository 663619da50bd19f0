"""cam-fmu sweep at scale: the C engine in-process equals cam.fmu to the bit, batches survive a killed worker,
the Parquet table streams and resumes after kill -9 to the same bits, sampled designs, Sobol indices checked
against a closed form and a one-at-a-time sweep, the sizing metrics against numpy on a simulate run."""
from __future__ import annotations

import csv
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from cam_fmu.experiments.sweep import Design, SweepError, parse_sample, parse_vary
from cli_run import cli, csv_rows, env



def _parquet_rows(folder: Path) -> list[dict]:
    from cam_fmu.experiments.sweep_store import iter_rows

    return list(iter_rows(folder))


SAMPLE = ["paper_fig6", "--vary", "m=0.2:0.8", "--vary", "rise_law=paper,cycloidal,modified_sine",
          "--vary", "mu=0:0.3", "--sample", "random:8", "--seed", "3", "--stop-time", "0.4", "--no-plot",
          "--metric", "peak_i,peak_M,peak_voltage,ripple,mean_omega,final_omega,rms_M,rms_i,peak_accel,energy_per_turn"]


def test_the_engine_in_process_and_cam_fmu_give_the_same_bits(cam_fmu_path, tmp_path):
    """A random sample of 8 cases (every metric) and a failing case, on the engine and through fmpy on cam.fmu:
    every number equal; a failed case fails on both, the FMU's message carrying the engine's."""
    engine = cli("sweep", *SAMPLE, "--serial", "--out", str(tmp_path / "engine"), cwd=tmp_path)
    fmu = cli("sweep", *SAMPLE, "--serial", "--fmu", str(cam_fmu_path), "--out", str(tmp_path / "fmu"), cwd=tmp_path)
    assert "engine engine" in engine.stderr and "engine fmu" in fmu.stderr
    a, b = csv_rows(tmp_path / "engine" / "paper_fig6_sweep.csv"), csv_rows(tmp_path / "fmu" / "paper_fig6_sweep.csv")
    assert a == b and len(a) == 9 and all(r[-2] == "ok" for r in a[1:])
    failing = ["paper_fig6", "--vary", "max_steps=10000,1", "--metric", "final_omega", "--stop-time", "0.05",
               "--serial", "--no-plot"]
    cli("sweep", *failing, "--out", str(tmp_path / "fe"), cwd=tmp_path, check=1)
    cli("sweep", *failing, "--fmu", str(cam_fmu_path), "--out", str(tmp_path / "ff"), cwd=tmp_path, check=1)
    fa, fb = csv_rows(tmp_path / "fe" / "paper_fig6_sweep.csv"), csv_rows(tmp_path / "ff" / "paper_fig6_sweep.csv")
    assert [r[:4] for r in fa] == [r[:4] for r in fb] and [r[3] for r in fa[1:]] == ["ok", "failed"]
    assert "max_steps = 1 internal steps" in fa[2][4] and fa[2][4] in fb[2][4]


def test_sizing_metrics_equal_numpy_on_a_simulate_run(tmp_path):
    """rms_M, rms_i (second half), peak_accel (d omega_m/dt) and energy_per_turn (voltage x i over the second
    half per cam turn) of the scene's own run, from `simulate`'s CSV with numpy (12 digits written)."""
    cli("simulate", "paper_fig6", "--engine", "fmu", "--stop-time", "1", "--no-plot", "--out", str(tmp_path / "sim"),
         cwd=tmp_path)
    data = np.genfromtxt(tmp_path / "sim" / "paper_fig6.csv", delimiter=",", names=True)
    t, i, m_load = data["time_s"], data["i_A"], data["M_Nm"]
    half = t >= t[-1] / 2
    expected = {
        "rms_M": math.sqrt(np.mean(m_load[half] ** 2)),
        "rms_i": math.sqrt(np.mean(i[half] ** 2)),
        "peak_accel": np.max(np.abs(np.diff(data["omega_m_rads"]) / np.diff(t))),
        "energy_per_turn": np.trapezoid(data["voltage_V"][half] * i[half], t[half])
        / ((data["theta_rad"][half][-1] - data["theta_rad"][half][0]) / (2 * math.pi)),
    }
    from cam_fmu.experiments.scenes import find_scene

    mass = find_scene("paper_fig6").primary.params["m"]
    cli("sweep", "paper_fig6", "--vary", f"m={mass}:{mass}:1", "--metric", ",".join(expected), "--stop-time", "1",
         "--serial", "--no-plot", "--out", str(tmp_path / "sw"), cwd=tmp_path)
    rows = csv_rows(tmp_path / "sw" / "paper_fig6_sweep.csv")
    assert rows[0][2:6] == ["rms_M [N.m]", "rms_i [A]", "peak_accel [rad/s2]", "energy_per_turn [J]"]
    for name, value in zip(expected, rows[1][2:6]):
        assert float(value) == pytest.approx(expected[name], rel=1e-6), name
    assert expected["energy_per_turn"] > 0 and expected["peak_accel"] > 0


def test_a_driver_killed_by_sigkill_resumes_to_the_same_table(tmp_path):
    """A serial sweep in batches of 3 killed (SIGKILL) once some batches are on disk; --resume runs the rest:
    the table equals an uninterrupted run's bit for bit, and the Parquet dataset holds every case once."""
    args = ["sweep", "paper_fig6", "--vary", "m=0.2:0.8:30", "--metric", "peak_M,final_omega,rms_i",
            "--stop-time", "3", "--serial", "--batch-size", "3", "--no-plot"]
    whole = cli(*args, "--out", str(tmp_path / "whole"), cwd=tmp_path)
    assert whole.returncode == 0
    out = tmp_path / "cut"
    folder = out / "paper_fig6_sweep.parquet"
    proc = subprocess.Popen([sys.executable, "-m", "cam_fmu.cli", *args, "--out", str(out)], env=env(), cwd=tmp_path,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        while proc.poll() is None and len(list(folder.glob("part-*.parquet"))) < 2:
            time.sleep(0.005)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    kept = len(list(folder.glob("part-*.parquet")))
    assert 2 <= kept < 10 and not (out / "paper_fig6_sweep.csv").exists()
    lock = out / "paper_fig6_sweep.lock"  # left behind by the killed driver, naming it: no longer held
    assert json.loads(lock.read_text())["pid"] == proc.pid
    again = cli(*args, "--out", str(out), "--resume", cwd=tmp_path)
    assert not lock.exists()
    assert f"({30 - 3 * kept} to run)" in again.stderr or f"({30 - 3 * kept - 3} to run)" in again.stderr
    assert (out / "paper_fig6_sweep.csv").read_text() == (tmp_path / "whole" / "paper_fig6_sweep.csv").read_text()
    rows = _parquet_rows(folder)
    assert [r["case"] for r in rows] == list(range(1, 31))
    assert rows == _parquet_rows(tmp_path / "whole" / "paper_fig6_sweep.parquet")


def test_resume_refuses_another_sweep_and_a_fresh_run_keeps_an_earlier_one(tmp_path):
    args = ["sweep", "paper_fig6", "--vary", "m=0.2:0.8:2", "--metric", "peak_M", "--stop-time", "0.05",
            "--serial", "--no-plot", "--out", str(tmp_path / "out")]
    cli(*args, cwd=tmp_path)
    folder = tmp_path / "out" / "paper_fig6_sweep.parquet"
    other = cli(*args[:3], "m=0.2:0.8:3", *args[4:], "--resume", cwd=tmp_path, check=2)
    assert "--resume" in other.stderr and "vary" in other.stderr and len(other.stderr.strip().splitlines()) == 1
    metric = cli(*args[:5], "peak_i", *args[6:], "--resume", cwd=tmp_path, check=2)
    assert "metrics" in metric.stderr
    fresh = cli(*args, cwd=tmp_path, check=2)
    assert "--resume continues it, --overwrite starts again" in fresh.stderr
    cli(*args, "--overwrite", cwd=tmp_path)
    spec_file = tmp_path / "out" / "paper_fig6_sweep.json"  # beside the dataset, which holds part files only
    assert all(p.name.startswith("part-") and p.suffix == ".parquet" for p in folder.iterdir())
    spec = json.loads(spec_file.read_text())
    spec["command"] = "cosim"
    spec_file.write_text(json.dumps(spec))
    command = cli(*args, "--resume", cwd=tmp_path, check=2)
    assert "made by the command 'cosim'" in command.stderr
    nothing = cli(*args[:-1], str(tmp_path / "empty"), "--resume", cwd=tmp_path, check=2)
    assert "nothing to continue" in nothing.stderr


@pytest.mark.parametrize("args, words", [
    (["--vary", "m=0.8:0.2", "--sample", "lhs:10"], "--vary 'm=0.8:0.2': range LOW = 0.8 is not below HIGH = 0.2"),
    (["--vary", "m=0.2:0.8", "--sample", "lhs:0"], "--sample 'lhs:0': N = 0: allowed 1 <= N <= 10000000"),
    (["--vary", "m=0.2:0.8", "--sensitivity", "0"], "--sensitivity 0: allowed N >= 1"),
    (["--vary", "m=0.2:0.8", "--vary", "rise_law=paper,cycloidal", "--sensitivity"],
     "--sensitivity with --vary 'rise_law=paper,cycloidal': Sobol indices need ranges"),
    (["--vary", "m=0.2:0.8"], "a range LOW:HIGH needs --sample or --sensitivity"),
    (["--vary", "m=0.2:0.8:3", "--sample", "sobol:8"], "--sample samples ranges NAME=LOW:HIGH"),
    (["--vary", "m=0.2:0.8", "--sample", "grid:8"], "--sample 'grid:8': expected KIND:N"),
    (["--vary", "m=0.2:0.8:3", "--batch-size", "0"], "--batch-size 0: allowed >= 1"),
])
def test_bad_input_is_refused_before_any_case_runs(tmp_path, args, words):
    proc = cli("sweep", "paper_fig6", *args, "--serial", "--out", str(tmp_path / "out"), cwd=tmp_path, check=2)
    assert words in proc.stderr and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert not (tmp_path / "out").exists()


def test_sampled_designs_are_reproducible_stratified_and_independent_of_batches():
    m, law = parse_vary("m=0.2:0.8"), parse_vary("rise_law=paper,cycloidal")
    for kind in ("lhs", "sobol", "random"):
        design = Design((m, law), parse_sample(f"{kind}:64"), seed=5)
        whole = design.values(0, 64)
        assert whole == Design((m, law), (kind, 64), seed=5).values(0, 64)  # --seed: the same cases
        assert whole != Design((m, law), (kind, 64), seed=6).values(0, 64)
        pieces = [design.values(a, b) for a, b in ((0, 7), (7, 40), (40, 64))]
        assert whole == {k: sum((p[k] for p in pieces), []) for k in whole}  # case k from k alone
        assert all(0.2 <= x < 0.8 for x in whole["m"]) and set(whole["rise_law"]) == {"paper", "cycloidal"}
    lhs = Design((m,), ("lhs", 50), seed=1).values(0, 50)["m"]
    assert sorted(int((x - 0.2) / 0.6 * 50) for x in lhs) == list(range(50))  # one case per stratum
    grid = Design((parse_vary("m=0.2:0.6:3"), law)).values(0, 6)
    assert list(zip(*grid.values())) == [(0.2, "paper"), (0.2, "cycloidal"), (0.4, "paper"), (0.4, "cycloidal"),
                                          (0.6, "paper"), (0.6, "cycloidal")]
    with pytest.raises(SweepError, match="at most 10000000"):
        len(Design((parse_vary("m=0:1:4000"), parse_vary("mu=0:0.1:4000"))))


def test_sobol_indices_of_an_additive_function_match_the_closed_form(tmp_path):
    """f = sum a_i x_i with x_i uniform on [l_i, h_i]: S1_i = ST_i = a_i^2 var_i / sum a_j^2 var_j,
    var_i = (h_i - l_i)^2 / 12; estimated through the code that analyses a sweep's Parquet table."""
    from cam_fmu.experiments import sensitivity
    from cam_fmu.experiments.scenes import find_scene
    from cam_fmu.experiments.sweep_run import Plan, _schema
    from cam_fmu.experiments.sweep_store import write_part

    varies = (parse_vary("m=0.2:0.8"), parse_vary("mu=0:0.3"), parse_vary("lift=0.01:0.02"))
    design = Design(varies, ("saltelli", 4096), seed=2)
    plan = Plan("paper_fig6", find_scene("paper_fig6"), design, ["peak_M"])
    a = np.array([1.0, 4.0, 10.0])
    spans = np.array([0.6, 0.3, 0.01])
    share = a ** 2 * spans ** 2 / 12
    share /= share.sum()
    folder = tmp_path / "additive"
    folder.mkdir()
    schema = _schema(plan, {})
    n = len(design)
    for start in range(0, n, 5000):
        values = design.values(start, min(n, start + 5000))
        x = np.column_stack([values[v.name] for v in varies])
        write_part(folder, schema, {"case": list(range(start + 1, start + len(x) + 1)), **values,
                                     "peak_M": list(x @ a), "status": ["ok"] * len(x), "message": [""] * len(x)})
    rows = sensitivity.indices(plan, folder)
    assert [r["parameter"] for r in rows] == ["m", "mu", "lift"] and rows == sensitivity.indices(plan, folder)
    for r, expected in zip(rows, share):
        assert r["S1"] == pytest.approx(expected, abs=max(0.02, 2 * r["S1_conf"]))
        assert r["ST"] == pytest.approx(expected, abs=max(0.02, 2 * r["ST_conf"]))
        assert 0 < r["S1_conf"] < 0.1 and 0 < r["ST_conf"] < 0.1
    assert np.isnan(sensitivity.sobol_indices(design.problem(), np.full(n, math.nan))["ST"]).all()  # a failed case


def test_sensitivity_on_the_drive_ranks_as_a_one_at_a_time_sweep(tmp_path):
    """Sobol ST of peak_M over m, mu and J_m ranges on fig. 6 rank the parameters as the spread of peak_M does
    when each moves alone over its range (the others mid-range); the CSV, table and chart are written."""
    ranges = {"m": (0.2, 0.8), "mu": (0.0, 0.3), "J_m": (1e-5, 2e-5)}
    vary = [x for name, (lo, hi) in ranges.items() for x in ("--vary", f"{name}={lo}:{hi}")]
    proc = cli("sweep", "paper_fig6", *vary, "--sensitivity", "32", "--metric", "peak_M", "--stop-time", "0.5",
                "--serial", "--out", str(tmp_path / "s"), cwd=tmp_path)
    with open(tmp_path / "s" / "paper_fig6_sensitivity.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert list(table[0]) == ["metric", "parameter", "S1", "S1_conf", "ST", "ST_conf"] and len(table) == 3
    assert (tmp_path / "s" / "paper_fig6_sensitivity.png").stat().st_size > 0
    assert "peak_M" in proc.stdout and "S1" in proc.stdout
    by_st = [r["parameter"] for r in sorted(table, key=lambda r: -float(r["ST"]))]
    spread = {}
    for name, (lo, hi) in ranges.items():
        others = [x for o, (l2, h2) in ranges.items() if o != name for x in ("--vary", f"{o}={(l2 + h2) / 2}:{(l2 + h2) / 2}:1")]
        cli("sweep", "paper_fig6", "--vary", f"{name}={lo}:{hi}:5", *others, "--metric", "peak_M", "--stop-time",
             "0.5", "--serial", "--no-plot", "--out", str(tmp_path / name), cwd=tmp_path)
        values = [float(r[4]) for r in csv_rows(tmp_path / name / "paper_fig6_sweep.csv")[1:]]
        spread[name] = max(values) - min(values)
    assert by_st == sorted(ranges, key=lambda n: -spread[n]), (table, spread)


def test_progress_names_rate_and_failures_and_a_summary_line_ends_the_sweep(tmp_path):
    proc = cli("sweep", "paper_fig6", "--vary", "max_steps=10000,1,5000", "--metric", "final_omega",
                "--stop-time", "0.05", "--serial", "--no-plot", "--out", str(tmp_path / "out"), cwd=tmp_path, check=1,
                CAM_FMU_PROGRESS="1")
    assert "3/3" in proc.stderr and "/s, 1 failed" in proc.stderr
    summary = [line for line in proc.stderr.splitlines() if line.startswith("# paper_fig6: 3 cases in ")]
    assert len(summary) == 1 and "1 failed; 3 of 3 on disk" in summary[0]


def test_a_worker_killed_mid_sweep_loses_no_case(tmp_path):
    """A scheduler and 2 workers (with nannies) as processes; once 3 batches are on disk one worker process is
    killed (SIGKILL): its batch runs again elsewhere, and the table equals a serial run's."""
    from distributed import Client
    from test_sweep import dask_processes

    args = ["sweep", "paper_fig6", "--vary", "m=0.2:0.8:40", "--metric", "peak_M,final_omega", "--stop-time", "4",
            "--batch-size", "1", "--no-plot"]
    serial = cli(*args, "--serial", "--out", str(tmp_path / "serial"), cwd=tmp_path)
    assert serial.returncode == 0
    out = tmp_path / "dist"
    folder = out / "paper_fig6_sweep.parquet"
    with dask_processes(tmp_path) as address, Client(address, timeout="60s") as client:
        pids = client.run(os.getpid)
        assert len(pids) == 2
        sweep = subprocess.Popen([sys.executable, "-m", "cam_fmu.cli", *args, "--scheduler", address, "--out",
                                  str(out)], env=env(), cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True)
        while sweep.poll() is None and len(list(folder.glob("part-*.parquet"))) < 3:
            time.sleep(0.005)
        os.kill(next(iter(pids.values())), signal.SIGKILL)
        done_at_kill = len(list(folder.glob("part-*.parquet")))
        _, stderr = sweep.communicate(timeout=600)
    assert sweep.returncode == 0, stderr[-3000:]
    assert done_at_kill < 40
    assert (out / "paper_fig6_sweep.csv").read_text() == (tmp_path / "serial" / "paper_fig6_sweep.csv").read_text()
    assert [r["case"] for r in _parquet_rows(folder)] == list(range(1, 41))


def test_an_interrupted_serial_sweep_keeps_its_partial_batch_and_resumes_to_the_same_table(tmp_path):
    """Ctrl-C in the middle of a batch of 50: the finished cases of that batch are written too; --resume runs
    the rest of that batch and the batches after it: the table equals an uninterrupted run's."""
    from conftest import interrupt_after_progress

    args = ["sweep", "paper_fig6", "--vary", "m=0.2:0.8:120", "--metric", "peak_M,rms_M", "--stop-time", "2",
            "--serial", "--batch-size", "50", "--no-plot"]
    cli(*args, "--out", str(tmp_path / "whole"), cwd=tmp_path)
    out = tmp_path / "cut"
    status, stderr = interrupt_after_progress([sys.executable, "-m", "cam_fmu.cli", *args, "--out", str(out)], 10,
                                              tmp_path, env())
    assert status == 130, stderr[-3000:]
    kept = int(stderr.strip().splitlines()[-1].split("interrupted: ")[1].split(" of ")[0])
    assert 10 <= kept < 120
    assert [r["case"] for r in _parquet_rows(out / "paper_fig6_sweep.parquet")] == list(range(1, kept + 1))
    again = cli(*args, "--out", str(out), "--resume", cwd=tmp_path)
    assert f"({120 - kept} to run)" in again.stderr
    assert (out / "paper_fig6_sweep.csv").read_text() == (tmp_path / "whole" / "paper_fig6_sweep.csv").read_text()


def test_the_driver_holds_a_bounded_number_of_batches_however_many_run(tmp_path):
    """120 batches on a local cluster (scheduler in this process): the batches' jobs (their values) alive in
    this process stay a few times the window (2 x workers + 1), not one per batch; dask's message logs, which
    kept the last 1000 messages of every stream with the jobs in them, hold at most LOG_LENGTH each."""
    import gc

    from distributed.batched import BatchedSend

    from cam_fmu.experiments.scenes import find_scene
    from cam_fmu.experiments.sweep_run import LOG_LENGTH, Plan, run_sweep

    plan = Plan("paper_fig6", find_scene("paper_fig6"), Design((parse_vary("m=0.2:0.8"),), ("random", 600)),
                ("peak_i",), stop_time=0.01)
    seen: list[tuple[int, int, list[int]]] = []

    def progress(done: int, total: int, failed: int) -> None:
        if done in (300, total):
            gc.collect()
            jobs = sum(1 for o in gc.get_objects() if type(o) is dict and "values" in o and "start" in o)
            logs = [len(o.recent_message_log) for o in gc.get_objects() if isinstance(o, BatchedSend)]
            seen.append((done, jobs, logs))

    summary = run_sweep(plan, tmp_path, workers=2, batch_size=5, progress=progress)
    assert summary.done == 600 and summary.failed == 0
    assert [d for d, _, _ in seen] == [300, 600]
    for done, jobs, logs in seen:
        assert jobs <= 3 * (2 * 2 + 1), (done, jobs)  # 60 and 120 batches submitted by then
        assert logs and max(logs) <= LOG_LENGTH, (done, logs)
