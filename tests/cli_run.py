"""Running `cam-fmu` as a user does, for the command-line tests (cli/test_sweep_folder.py, cli/test_sweep_scale.py):
``python -m cam_fmu.cli`` in a child process on this checkout, without the progress bar, and reading its CSV."""
from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def env(**extra: str) -> dict:
    """The child's environment: this one, the checkout first on PYTHONPATH, no progress bar, plus ``extra``."""
    return {**os.environ, "PYTHONPATH": str(ROOT), "CAM_FMU_PROGRESS": "0", **extra}


def cli(*args: str, cwd: Path, check: int | None = 0, **extra: str) -> subprocess.CompletedProcess:
    """`cam-fmu ARGS` in ``cwd``; its exit status must be ``check`` (None: any), else the assertion shows its
    output's end."""
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", *args], capture_output=True, text=True,
                          env=env(**extra), cwd=cwd, timeout=900)
    if check is not None:
        assert proc.returncode == check, proc.stdout[-3000:] + proc.stderr[-3000:]
    return proc


def csv_rows(path: Path) -> list[list[str]]:
    """A CSV file's rows, the header first."""
    with open(path, newline="") as fh:
        return list(csv.reader(fh))
