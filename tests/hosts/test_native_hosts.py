"""cam.fmu in the hosts CI installs: fmpy (CLI and library), ecos (empty environment), libcosimpy, our C host.

Counts are small (the old binary failed 11 of 40 fmpy CLI runs, 10 of 332 scipy scripts and
20 of 20 C-host runs; the CI counts below catch the first and the last with near certainty).
The issue's full counts run with the developer command
``python -m cam_fmu.tools.soak models/cam.fmu`` (about 4 minutes).
Every tool is required: a missing one fails the test.
"""
from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from cam_fmu.tools import soak
from native_support import (EMPTY_ENV, compile_host, ecos_path, extract, libcosim_script, require, result_line,
                            run_python, valgrind_prefix, valgrind_summary)


@pytest.fixture(scope="module")
def fmu(cam_fmu_path, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("hosts") / "cam.fmu"
    shutil.copyfile(cam_fmu_path, path)
    return path


@pytest.fixture(scope="module")
def fmpy_reference(fmu):
    """omega and i at t = 0.2 s with u = 3.0 from fmpy's simulate_fmu."""
    return run_python("import json, sys\nfrom fmpy import simulate_fmu\n"
                      "r = simulate_fmu(sys.argv[1], start_values={'u': 3.0}, output_interval=1e-3, stop_time=0.2)\n"
                      "print(json.dumps({'omega': float(r['omega'][-1]), 'i': float(r['i'][-1])}))", str(fmu))


def _assert_clean(result, name):
    assert result["failures"] == 0, f"{name}: {result}"


# --------------------------------------------------------------------------- abort counts (small)
def test_fmpy_cli_never_aborts(fmu, tmp_path):
    _assert_clean(soak.fmpy_cli(fmu, 20, tmp_path), "fmpy simulate")


def test_simulate_then_scipy_never_aborts(fmu, tmp_path):
    _assert_clean(soak.scipy_script(fmu, 10, tmp_path), "simulate + scipy")


def test_ecos_empty_environment_never_aborts(fmu, tmp_path):
    ecos_path()
    require("gcc")
    _assert_clean(soak.ecos(fmu, 10, tmp_path), "ecos")


def test_c_host_never_aborts(fmu, tmp_path):
    require("gcc")
    _assert_clean(soak.c_host(fmu, 10, tmp_path), "C host")


# --------------------------------------------------------------------------- results agree
def test_ecos_empty_environment_matches_fmpy(fmu, tmp_path):
    """ecos (no LD_PRELOAD/PYTHONHOME/PYTHONPATH) and fmpy agree at ecos's last row (default u = 3.5 V)."""
    proc = subprocess.run([str(ecos_path()), "simulate", "--path", str(fmu), "--stopTime", "0.2", "--stepSize",
                           "0.001"], cwd=tmp_path, env=EMPTY_ENV, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    rows = list(csv.reader(open(next(tmp_path.glob("*.csv")))))
    header = [h.strip() for h in rows[0]]
    last = rows[-1]
    col = {name: next(k for k, h in enumerate(header) if h.endswith(f"::{name}[REAL]")) for name in ("omega", "i")}
    t_last = float(last[header.index("time")])
    assert t_last > 0.19
    ref = run_python("import json, sys\nfrom fmpy import simulate_fmu\n"
                     "r = simulate_fmu(sys.argv[1], output_interval=1e-3, stop_time=float(sys.argv[2]))\n"
                     "print(json.dumps({'t': float(r['time'][-1]), 'omega': float(r['omega'][-1]),"
                     " 'i': float(r['i'][-1])}))", str(fmu), repr(t_last))
    assert ref["t"] == pytest.approx(t_last, abs=1e-12)
    # ecos writes 6 decimals
    assert float(last[col["omega"]]) == pytest.approx(ref["omega"], abs=2e-6)
    assert float(last[col["i"]]) == pytest.approx(ref["i"], abs=2e-6)




def test_libcosimpy_matches_fmpy(fmu, fmpy_reference, tmp_path):
    try:
        import libcosimpy  # noqa: F401
    except ImportError:
        pytest.fail("libcosimpy is not installed (pip install -e '.[test]')")
    proc = subprocess.run([sys.executable, "-c", libcosim_script(("omega", "i"), u=3.0), str(fmu)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    omega, i = result_line(proc.stdout)
    assert omega == pytest.approx(fmpy_reference["omega"], rel=1e-9)
    assert i == pytest.approx(fmpy_reference["i"], rel=1e-9, abs=1e-12)


# --------------------------------------------------------------------------- valgrind
def test_fmpy_cli_under_valgrind(fmu, tmp_path):
    log = tmp_path / "valgrind.log"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PYTHONMALLOC"] = "malloc"
    cmd = [*valgrind_prefix(log), *soak._fmpy_cli(), "simulate", str(fmu), "--start-values", "u", "3.0", "solver",
           "rk4", "--output-interval", "1e-3", "--stop-time", "0.2"]
    proc = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-3000:]
    s = valgrind_summary(log)
    assert s["summaries"] >= 1 and s["errors"] == 0 and s["definitely_lost"] == 0, s["excerpt"]


def test_ecos_under_valgrind(fmu, tmp_path):
    log = tmp_path / "valgrind.log"
    cmd = [*valgrind_prefix(log), str(ecos_path()), "simulate", "--path", str(fmu), "--stopTime", "0.05",
           "--stepSize", "0.001"]
    proc = subprocess.run(cmd, cwd=tmp_path, env={**EMPTY_ENV, "PYTHONMALLOC": "malloc"}, capture_output=True,
                          text=True)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    s = valgrind_summary(log)
    assert s["summaries"] >= 1 and s["errors"] == 0 and s["definitely_lost"] == 0, s["excerpt"]
