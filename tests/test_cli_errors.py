"""Every CLI error is one line `cam-fmu CMD: error: ...` with exit status 2, never a traceback."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = str(ROOT / "README.md")
BINARY = sys.executable  # a binary file given as a scene

CASES = [
    (["curve", "--base-radius-mm", "-5"], "curve", "--base-radius-mm -5: allowed a number > 0"),
    (["simulate", "paper_fig6", "--engine", "fmu", "--fmu", README], "simulate", "is not an FMU"),
    (["simulate", "paper_fig6", "--out", README], "simulate", "--out"),
    (["simulate", BINARY], "simulate", "not a scene file"),
    (["simulate", "paper_fig6", "--set", "m=-1"], "simulate", "'m' = -1.0 [kg] is outside the allowed range"),
    (["simulate", "paper_fig6", "--set", "mass=1"], "simulate", "unknown parameter 'mass'"),
    (["sweep", "paper_fig6", "--vary", "m=1:2"], "sweep", "NAME=START:STOP:N"),
    (["sweep", "paper_fig6", "--vary", "m=0:1:2", "--metric", "bogus", "--serial"], "sweep", "--metric bogus"),
    (["sweep", BINARY, "--vary", "m=0:1:2"], "sweep", "not a scene file"),
    (["cosim", README], "cosim", "not an SSP file"),
    (["cosim", "--set", "controller.kp=-1"], "cosim", "'kp' = -1.0"),
]


@pytest.mark.parametrize("args,command,message", CASES, ids=[" ".join(c[0][:2]) + f" #{k}" for k, c in enumerate(CASES)])
def test_one_line_error_exit_2(args, command, message, tmp_path):
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", *args], capture_output=True, text=True,
                          cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=300)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"cam-fmu {command}: error: "), proc.stderr
    assert message in lines[0] and "Traceback" not in proc.stderr
