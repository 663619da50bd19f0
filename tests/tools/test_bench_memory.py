"""The memory tool: RSS stays flat over a run of cam.fmu (no Python object leaked per step).

Runs ``python -m cam_fmu.tools.bench.memory`` in a child process (the pytest
process never loads cam.fmu) with a small step count. The bound is on bytes
per communication step, not on time: a leak of one small Python object per
step (a float is 24 bytes, with its list slot 32) crosses it, and the second
test shows that the tool sees such a leak.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STEPS = 20_000
BOUND = 50.0  # bytes per communication step

LEAKY = r"""
import json, sys
from pathlib import Path
from cam_fmu.tools.bench.memory import run_memory
kept = []
result = run_memory(Path(sys.argv[1]), int(sys.argv[2]), on_step=lambda out: kept.append(bytes(40)))
print(json.dumps(result))
"""


def _run(args, cam_fmu_path):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    proc = subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-4000:]
    return proc.stdout, json.loads(proc.stdout.strip().splitlines()[-1])


def test_rss_stays_flat_over_a_run(cam_fmu_path):
    out, result = _run(["-m", "cam_fmu.tools.bench.memory", "--steps", str(STEPS), "--fmu", str(cam_fmu_path),
                        "--json"], cam_fmu_path)
    assert len(result["samples"]) == 10 and result["samples"][-1]["step"] == STEPS
    assert abs(result["t_end"] - (STEPS + result["warmup"]) * 1e-3) < 1e-9  # every step was taken
    assert result["omega"] > 0.0
    assert result["bytes_per_step"] < BOUND, out
    assert "bytes per step" in out


def test_the_tool_sees_a_leak_of_one_object_per_step(cam_fmu_path):
    _out, result = _run(["-c", LEAKY, str(cam_fmu_path), str(STEPS)], cam_fmu_path)
    assert result["bytes_per_step"] > BOUND, result
