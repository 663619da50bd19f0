"""`cam-fmu bench grid --quick --case spring_jump`: the speed drive in the error grid (issue 38).

The speed drive imposes theta and omega (the input's integral, exact), so its case is measured and ranked by the
follower's position s against the scipy reference (rtol 1e-12): its follower of its own lifts off the cam above the
jump speed (`spring_jump`, run above_1.02) and flies. No wall-clock limits: costs are only checked to be the ratios
the bench says they are.
"""
from __future__ import annotations

import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from test_bench import QUICK_FMU_ROWS

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def speed_grid(tmp_path_factory, cam_fmu_path):
    out = tmp_path_factory.mktemp("bench_speed")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["MPLBACKEND"] = "Agg"
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "bench", "grid", "--quick", "--case", "spring_jump",
                           "--out", str(out), "--fmu", str(cam_fmu_path)],
                          capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)
    if proc.returncode != 0:
        pytest.fail(f"bench grid exited with {proc.returncode}\n--- stdout\n{proc.stdout[-4000:]}\n"
                    f"--- stderr\n{proc.stderr[-4000:]}")
    tables = {}
    for name in ("bench", "choices"):
        with open(out / f"{name}.csv", newline="", encoding="utf-8") as fh:
            tables[name] = list(csv.DictReader(fh))
    return {"out": out, "stdout": proc.stdout, **tables}


def _fmu(rows, solver, setting):
    found = [r for r in rows if r["kind"] == "fmu" and r["solver"] == solver and r["setting"] == setting]
    assert len(found) == 1, (solver, setting, found)
    return found[0]


def test_every_solver_runs_the_speed_drive_and_is_measured_by_s(speed_grid):
    rows = speed_grid["bench"]
    assert {r["case"] for r in rows} == {"spring_jump"}
    assert {(r["solver"], r["setting"]) for r in rows if r["kind"] == "fmu"} == QUICK_FMU_ROWS
    for r in rows:
        assert r["status"] == "ok" and r["reached_stop"] == "True" and math.isclose(float(r["t_end"]), 0.22), r
        if r["kind"] == "fmu":
            # theta and omega are the input's: no error column claims to measure them
            assert r["theta_err"] == "" and r["omega_err"] == "", r
            assert 0.0 <= float(r["s_err"]) < 1e-5, r   # every setting: its flights resolved (below)
            assert math.isclose(float(r["cost_ratio"]), float(r["us_per_step"]) / float(r["floor_us_per_step"]),
                                rel_tol=1e-9)
    # the methods' orders at the same flight steps (0.05 rad of the spring's phase under error control, 4e-4 rad
    # with a fixed step; docs/model.md 13.4): rk45 (5th order) beats rk23 (3rd), rk4 beats euler (1st)
    rk45, rk23 = (float(_fmu(rows, s, "rtol=1e-06")["s_err"]) for s in ("rk45", "rk23"))
    rk4, euler = (float(_fmu(rows, s, "h=0.001")["s_err"]) for s in ("rk4", "euler"))
    assert rk45 < 1e-9 and rk23 > 10.0 * rk45, (rk45, rk23)
    assert euler > 100.0 * rk4, (euler, rk4)
    assert float(_fmu(rows, "rk45", "rtol=1e-10")["s_err"]) < 1e-9


def test_the_speed_case_is_ranked_by_s(speed_grid):
    from cam_fmu.tools.bench.cases import LEVELS

    choices = speed_grid["choices"]
    assert [float(c["level"]) for c in choices] == list(LEVELS["s_err"])
    runs = [r for r in speed_grid["bench"] if r["kind"] == "fmu"]
    for c in choices:
        assert c["ranked_by"] == "s_err" and c["case"] == "spring_jump"
        good = [r for r in runs if float(r["s_err"]) < float(c["level"])]
        cheapest = min(good, key=lambda r: float(r["cost_ratio"]))
        assert (c["solver"], c["setting"]) == (cheapest["solver"], cheapest["setting"]), c
        assert float(c["error"]) == float(cheapest["s_err"])
    least = min(float(r["s_err"]) for r in runs)
    assert any(r["pareto"] == "True" for r in runs if float(r["s_err"]) == least)
    assert "s_err" in speed_grid["stdout"] and (speed_grid["out"] / "bench.png").stat().st_size > 10_000


def test_a_voltage_case_stays_ranked_by_theta():
    """The choice table picks by the case's own error: theta for a voltage scene even where s is known too."""
    from cam_fmu.tools.bench.report import choose

    def row(setting, theta, s, ratio):
        return {"case": "backlash", "kind": "fmu", "comm_step": 1e-3, "status": "ok", "solver": "rk45",
                "setting": setting, "theta_err": theta, "omega_err": 0.0, "s_err": s, "us_per_step": ratio,
                "cost_ratio": ratio}

    # by s, "b" (cheaper, s within 1e-8) would be chosen at 1e-6; by theta only "a" is within 1e-6 rad
    choices = choose([row("a", 1e-7, 1e-3, 2.0), row("b", 1e-4, 1e-9, 1.0)])
    at = {c["level"]: c for c in choices}
    assert [c["ranked_by"] for c in choices] == ["theta_err"] * 3
    assert at[1e-3]["setting"] == "b" and at[1e-6]["setting"] == "a" and at[1e-8]["solver"] == "none"
