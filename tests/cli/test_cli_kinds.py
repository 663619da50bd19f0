"""`cam-fmu reflect` and `cam-fmu bode` on the shipped rocker (packaging_rocker, an oscillating roller arm): the
resonance bode locates on the engine at a frozen angle is sqrt(k_g / J) of the map reflect writes (k_g the slope of
its gravity torque column by central differences, J its inertia column): with the velocity as output the peak of
|H| of J s^2 + b s + k_g sits at sqrt(k_g / J) whatever the damping b. A spring-closed arm refused by the map with
advice that runs."""
from __future__ import annotations

import csv
import json
import math
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TILTED = ["--set", "gamma=1.2"]  # the arm's plane tilted: its weight gives the standstill a stiffness


def cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "cam_fmu.cli", *args], capture_output=True, text=True, cwd=cwd,
                          env={**os.environ, "PYTHONPATH": str(ROOT), "CAM_FMU_PROGRESS": "0"}, timeout=600)


def test_bode_locates_the_rockers_resonance_of_reflects_map(tmp_path):
    done = cli("reflect", "packaging_rocker", *TILTED, "--rpm", "1", "--points", "3600", "--no-plot", "--out",
               str(tmp_path), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    with (tmp_path / "packaging_rocker_reflect.csv").open() as f:
        rows = [[float(x) for x in row] for row in list(csv.reader(f))[1:]]
    k = 300  # theta = 30 deg, on the rise where the arm's weight holds the cam back more the further it turns
    h = rows[k + 1][0] - rows[k - 1][0]
    k_g = (rows[k + 1][4] - rows[k - 1][4]) / h  # N m/rad: d M_gravity / d theta
    J = rows[k][1]
    assert k_g > 0.0
    f_n = math.sqrt(k_g / J) / (2.0 * math.pi)
    done = cli("bode", "packaging_rocker", *TILTED, "--theta", "30", "--fmin", "1", "--fmax", "10", "--points", "15",
               "--json", "--no-plot", "--out", str(tmp_path), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    summary = json.loads(done.stdout)
    assert summary["cam_difference"] < 2e-4  # the engine against the linear model over the grid
    peaks = [e for e in summary["extrema"] if e["output"] == "cam"]
    assert [e["kind"] for e in peaks] == ["resonance"]
    assert abs(peaks[0]["f"] / f_n - 1.0) < 2e-3 and abs(peaks[0]["f_analytic"] / f_n - 1.0) < 2e-3


def test_reflect_refuses_a_spring_closed_arm_and_its_advice_runs(tmp_path):
    sets = ["--set", "closure=spring", "--set", "k_spring=2000", "--set", "F_spring0=20"]
    done = cli("reflect", "packaging_rocker", *sets, "--out", str(tmp_path), cwd=tmp_path)
    assert done.returncode == 2 and "closure 'spring'" in done.stderr, done.stderr
    advised = re.findall(r"`(cam-fmu [^`]+)`", done.stderr)
    assert len(advised) == 1 and shlex.split(advised[0])[1:3] == ["jump", "packaging_rocker"]
    ran = cli(*shlex.split(advised[0])[1:], "--no-plot", "--out", str(tmp_path), cwd=tmp_path)
    assert ran.returncode == 0 and "omega_jump:" in ran.stdout, ran.stderr


def test_a_sweep_takes_the_follower_type_as_a_categorical_parameter(tmp_path):
    """`cam-fmu sweep packaging_rocker --vary follower_type=oscillating_roller,oscillating_flat --vary mu=0.05` runs
    both arms (the scene's arm fields fit either) as two cases; each case's peak load torque is that of the scene run
    with its type in the engine directly (the type reaches the run), and they differ: with friction a roller arm
    (the pivot's) and a flat face (sliding on the cam) load it differently (without it, on the same psi law, alike)."""

    from cli_run import cli, csv_rows
    from cam_fmu.engine.simulator import DriveSimulator
    from cam_fmu.experiments.scenes import find_scene

    cli("sweep", "packaging_rocker", "--vary", "follower_type=oscillating_roller,oscillating_flat", "--vary",
        "mu=0.05", "--stop-time", "1.0", "--serial", "--no-plot", "--out", str(tmp_path), cwd=tmp_path)
    header, *rows = csv_rows(tmp_path / "packaging_rocker_sweep.csv")
    got = {row[header.index("follower_type")]: float(row[header.index("peak_M [N.m]")]) for row in rows}
    assert sorted(got) == ["oscillating_flat", "oscillating_roller"]
    assert all(row[header.index("status")] == "ok" for row in rows)
    scene = find_scene("packaging_rocker")
    for kind, peak in got.items():
        sim = DriveSimulator(dict(scene.primary.params, follower_type=kind, mu=0.05))
        sim.set_inputs(scene.u.value(0.0), 0.0, 0.0)
        torques = []
        for k in range(int(round(1.0 / scene.output_interval))):
            t = k * scene.output_interval
            sim.do_step(t, scene.output_interval, u=scene.u.value(t), omega_ref=0.0, omega_dot_ref=0.0)
            torques.append(abs(sim.outputs()["M"]))
        assert abs(peak - max(torques)) <= 1e-9 * peak
    assert abs(got["oscillating_roller"] - got["oscillating_flat"]) > 1e-3 * max(got.values())
