"""The long commands show their progress as `simulate` and `sweep` do: `python build_fmu.py` (minutes on a first
build, every platform's zig cache cold) names the FMU and the platform it is building, `cam-fmu bode` (minutes on
a turning drive) draws a bar over its frequencies, then over the extrema it locates. The bar is on stderr, drawn
with CAM_FMU_PROGRESS=1 (or on a terminal), never with 0; stdout is the same either way."""
from __future__ import annotations

import io
import os
import re
import subprocess
import sys
from pathlib import Path

from cam_fmu.engine import targets
from cam_fmu.experiments.progress import ProgressBar
from cam_fmu.fmu import binaries

ROOT = Path(__file__).resolve().parents[2]


def _run(cmd: list[str], progress: str, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "CAM_FMU_PROGRESS": progress}
    return subprocess.run(cmd, capture_output=True, text=True, cwd=cwd, env=env, timeout=600)


def _counts(stderr: str, label: str) -> list[tuple[int, int]]:
    """(done, total) of every drawing of the bar ``label`` on stderr."""
    return [(int(a), int(b)) for a, b in re.findall(re.escape(label) + r" \[[#.]*\] (\d+)/(\d+) ", stderr)]


def test_build_fmu_names_the_fmu_and_the_platform_it_builds(tmp_path):
    shown = _run([sys.executable, str(ROOT / "build_fmu.py"), "--platforms", "host", "--dest",
                  str(tmp_path / "a" / "cam.fmu")], "1", tmp_path)
    quiet = _run([sys.executable, str(ROOT / "build_fmu.py"), "--platforms", "host", "--dest",
                  str(tmp_path / "b" / "cam.fmu")], "0", tmp_path)
    assert shown.returncode == 0 and quiet.returncode == 0, shown.stderr + quiet.stderr
    assert quiet.stderr == ""
    assert shown.stdout.replace("/a/", "/b/") == quiet.stdout == f"{tmp_path / 'b' / 'cam.fmu'}\n"
    label = "build cam.fmu (FMI 2.0)"
    assert _counts(shown.stderr, label)[0] == (0, 1) and _counts(shown.stderr, label)[-1] == (1, 1), shown.stderr
    assert f"{label} [" in shown.stderr and "0/1 building host, " in shown.stderr
    assert shown.stderr.endswith("\n")


def test_every_platform_is_named_before_it_is_built():
    """compile_all tells the bar each target before compiling it (a fake compiler stands in for zig)."""
    stream = io.StringIO()
    bar = ProgressBar("build cam.fmu (FMI 2.0)", stream=stream)
    bar.enabled = True
    order = []

    def compile_one(dest: Path, row):
        order.append((row.name, stream.getvalue().count(f"building {row.name},")))
        return dest

    binaries.compile_all(Path("unused"), "cam", list(targets.NAMES), compile_one, progress=bar)
    assert [name for name, _ in order] == list(targets.NAMES)
    assert all(seen == 1 for _, seen in order), order  # drawn once, before its compilation
    n = len(targets.NAMES)
    assert _counts(stream.getvalue(), "build cam.fmu (FMI 2.0)") == [(k, n) for k in range(n + 1)]
    assert stream.getvalue().endswith("\n")


def test_bode_draws_a_bar_over_its_frequencies_and_its_extrema(tmp_path):
    args = ["bode", "compliant_shaft", "--theta", "60", "--fmin", "150", "--fmax", "260", "--points", "4",
            "--no-plot", "--out", str(tmp_path)]
    shown = _run([sys.executable, "-m", "cam_fmu.cli", *args], "1", tmp_path)
    quiet = _run([sys.executable, "-m", "cam_fmu.cli", *args], "0", tmp_path)
    assert shown.returncode == 0 and quiet.returncode == 0, shown.stderr + quiet.stderr
    assert quiet.stderr == "" and shown.stdout == quiet.stdout
    grid = _counts(shown.stderr, "bode compliant_shaft (frequencies)")
    assert grid[0] == (0, 4) and grid[-1] == (4, 4), shown.stderr
    located = _counts(shown.stderr, "bode compliant_shaft (extrema located)")
    extrema = sum(1 for line in quiet.stdout.splitlines() if " at " in line and " Hz, |H| = " in line)
    assert extrema >= 1 and located[0] == (0, extrema) and located[-1] == (extrema, extrema), shown.stderr
    assert shown.stderr.endswith("\n")
