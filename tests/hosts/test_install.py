"""A non-editable `pip install .` works from any directory: the engine is compiled at install time, and the
scenes and the FMU build ship with the package."""
from __future__ import annotations

import os
import subprocess
import sys
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_installed_package_simulates_a_shipped_scene_on_the_fmu(tmp_path):
    """The build needs setuptools, wheel (setuptools < 70.1) and numpy without build isolation: they come from the
    test's own locked environment, put after the new environment's site-packages by a .pth line (its .pth files, the
    editable install's among them, are not read from there), not from whatever the system Python holds (a machine
    whose system Python had no wheel failed here, 2026-11-28)."""
    import sysconfig

    env_dir = tmp_path / "venv"
    venv.EnvBuilder(system_site_packages=True, with_pip=False).create(env_dir)
    python = env_dir / "bin" / "python"
    purelib = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                             capture_output=True, text=True, check=True).stdout.strip()
    (Path(purelib) / "locked_test_env.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
    proc = subprocess.run([str(python), "-m", "pip", "install", "--no-deps", "--no-build-isolation", "-q",
                           str(ROOT)], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    where = subprocess.run([str(python), "-c", "import cam_fmu; print(cam_fmu.__file__)"], capture_output=True,
                           text=True, env=env, cwd=elsewhere, timeout=120)
    assert where.returncode == 0 and where.stdout.strip().startswith(str(env_dir)), where.stdout + where.stderr
    # pip built the C engine into the package: loading it compiles nothing and writes no cache
    lib = subprocess.run([str(python), "-c", "from cam_fmu.engine import build; print(build.build())"],
                         capture_output=True, text=True, env=env, cwd=elsewhere, timeout=120)
    assert lib.returncode == 0, lib.stderr
    assert lib.stdout.strip().startswith(str(env_dir)) and "/engine/_lib/libcamdrive-" in lib.stdout
    assert not (tmp_path / "cache" / "cam_fmu").exists() or not list((tmp_path / "cache" / "cam_fmu").glob("libcamdrive*"))
    cam_fmu_cli = env_dir / "bin" / "cam-fmu"
    run = subprocess.run([str(cam_fmu_cli), "simulate", "paper_fig6", "--engine", "fmu", "--out", "out",
                          "--stop-time", "0.05", "--no-plot"], capture_output=True, text=True, env=env,
                         cwd=elsewhere, timeout=600)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-3000:]
    assert (elsewhere / "out" / "paper_fig6.csv").is_file()
    assert (elsewhere / "out" / "paper_fig6__paper.csv").is_file()
    built = list((tmp_path / "cache" / "cam_fmu").glob("cam-*.fmu"))
    assert len(built) == 1, "the installed package builds its FMU into the user cache"
    # the CSV holds 51 rows of 1 ms steps and the cam has started to turn
    rows = (elsewhere / "out" / "paper_fig6.csv").read_text().splitlines()
    assert len(rows) == 52 and float(rows[-1].split(",")[2]) > 0.0
