"""`cam-fmu bench --sweep N`: the sweep's benchmark runs tiny here and reports what docs/performance.md quotes
(structure only: timings on a shared machine are not asserted)."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_sweep_benchmark_reports_engine_serial_cluster_and_memory(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "bench", "--sweep", "60", "--workers", "2", "--out",
                           str(tmp_path)], capture_output=True, text=True, cwd=tmp_path, timeout=900,
                          env={**os.environ, "PYTHONPATH": str(ROOT), "CAM_FMU_PROGRESS": "0"})
    assert proc.returncode == 0, proc.stderr[-3000:]
    result = json.loads((tmp_path / "sweep_bench.json").read_text())
    assert result["cases"] == 60 and result["workers"] == 2
    assert 0 < result["engine_s"] < result["engine_setup_s"] and result["engine_cpu_s"] > 0  # the scene's set-up costs on top of the run
    serial, cluster = result["serial"], result["cluster"]
    assert serial["cases"] == 60 and serial["case_s"] > 0
    assert serial["overhead"] == pytest.approx(serial["case_s"] / result["engine_s"])
    assert cluster["failed"] == 0 and 0 < cluster["run_s"] <= cluster["wall_s"]
    assert cluster["cases_per_s"] == pytest.approx(60 / cluster["run_s"])
    assert cluster["ratio"] == pytest.approx(cluster["cases_per_s"] * result["engine_s"] / 2)
    assert cluster["cpu_s_per_case"] > 0 and cluster["driver_rss_mib"]["peak"] > 0 and len(cluster["worker_rss_mib"]) >= 2
    lines = proc.stdout.strip().splitlines()
    assert lines[0].startswith("engine's own run of a case (fig. 6, 2 s): ") and "target <= 1.3" in lines[1]
    assert "local cluster of 2 workers: 60 cases" in lines[2] and "target >= 0.8" in lines[2] and "CPU a case" in lines[2]
    assert lines[3].startswith("Parquet: ") and "RSS [MiB] first quarter/peak: driver " in lines[3]
    assert 8 < cluster["disk_bytes_per_case"] < 10_000  # at least the case number's 8 bytes
