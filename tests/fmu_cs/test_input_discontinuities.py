"""Outputs at an input's discontinuity are its left limit, in cam.fmu and in the scipy reference alike
(docs/model.md 8.1): every corner of an omega_ref table (one of them a stop, where omega reaches 0 and turns back)
and a step of the voltage u.

Against what is independent of the convention's code: the row at each discontinuity equals the row, at that time,
of a run whose input continues the interval that ends there (the same engine, to 1e-9 of the output's range: the
tables' interpolations differ by roundings; cam.fmu bit for bit where the held input is the same), and cam.fmu equals the reference at every
output, the rows at the discontinuities included.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.experiments.runner import run_scene
from cam_fmu.experiments.scenes import find_scene

VERTICAL = 'gamma = 1.5707963267948966\nbeta = 3.141592653589793'
# The follower's closures over a table with corners at 0.3, 0.8 and 1.2 s: the kinematic rule in a vertical groove
# (its play operator and its rest rule), a follower of its own in a vertical groove and on a spring.
CLOSURES = {
    "kinematic-vertical": f'closure = "kinematic"\nc = 5e-4\n{VERTICAL}',
    "groove-vertical": f'closure = "form"\nc = 5e-4\n{VERTICAL}',
    "spring": 'closure = "spring"\nk_spring = 500.0\nF_spring0 = 5.0',
}
# omega_ref [rad/s]: speeds up to 8 rad/s, holds, slows to a stop at 1.2 s and turns back (-10 rad/s2).
TIMES, VALUES = [0.0, 0.3, 0.8, 1.2, 1.5], [2.0, 8.0, 8.0, 0.0, -3.0]
CORNERS = (0.3, 0.8, 1.2)
J_0, C_M = 4.41e-5, 0.015 * 9.80665   # kg m2, N m/A: the defaults (physics/parameters.py), J_cam = 0
KEYS = ("M", "i", "voltage", "a", "N_contact", "s", "v", "omega", "theta")


def scene_file(folder, name: str, drive: str, signal: str, stop: float, interval: float, params: str):
    path = folder / f"{name}.toml"
    path.write_text(f'description = "{name}"\ndrive = "{drive}"\nstop_time = {stop!r}\noutput_interval = {interval!r}\n'
                    f'plot = "time"\n{signal}\n[parameters]\n{params}\n[[runs]]\nlabel = "a"\n')
    return find_scene(str(path))


def table(times, values) -> str:
    return f'omega_ref = {{type = "table", time = {list(times)!r}, value = {list(values)!r}}}'


def continued(corner: float) -> tuple[list[float], list[float]]:
    """The table up to ``corner`` with its piece ending there continued to 1.5 s (no discontinuity at corner)."""
    k = TIMES.index(corner)
    slope = (VALUES[k] - VALUES[k - 1]) / (TIMES[k] - TIMES[k - 1])
    return TIMES[:k] + [1.5], VALUES[:k] + [VALUES[k - 1] + slope * (1.5 - TIMES[k - 1])]


def row_at(result: dict, t: float) -> int:
    j = int(np.argmin(np.abs(result["time"] - t)))
    assert abs(result["time"][j] - t) < 1e-9
    return j


@pytest.mark.parametrize("interval", [0.01, 0.1])
@pytest.mark.parametrize("closure", CLOSURES)
def test_every_corner_of_an_omega_ref_table_is_the_left_limit(closure, interval, tmp_path, cam_fmu_path):
    """At 0.1 s steps the grid times 0.30000000000000004 and 1.2000000000000002 s are an ulp past the corners (fmpy
    steps there with the input before the corner): they count as the corners. The stop at 1.2 s: the FMU's speed is
    a rounding off 0 there (it was read as a moving cam, the reference as one at rest, 0.012-0.025 N m apart)."""
    params = CLOSURES[closure]
    scene = scene_file(tmp_path, "corners", "speed", table(TIMES, VALUES), 1.5, interval, params)
    fmu, ref = run_scene(scene, "fmu", cam_fmu_path)["a"], run_scene(scene, "reference")["a"]
    for key in KEYS:
        scale = np.max(np.abs(ref[key])) + 1e-300
        assert np.max(np.abs(fmu[key] - ref[key])) < 1e-9 * scale, key   # every row, the corners included
    jumps = 0
    for corner in CORNERS:
        times, values = continued(corner)
        left = scene_file(tmp_path, f"left_{corner}", "speed", table(times, values), 1.5, interval, params)
        fmu_left, ref_left = run_scene(left, "fmu", cam_fmu_path)["a"], run_scene(left, "reference")["a"]
        j = row_at(fmu, corner)
        assert j == row_at(fmu_left, corner)
        for key in KEYS:   # the same steps up to the corner (the tables' interpolations differ by roundings)
            scale = np.max(np.abs(ref[key])) + 1e-12
            assert abs(fmu[key][j] - fmu_left[key][j]) < 1e-9 * scale, (corner, key)
            assert abs(ref[key][j] - ref_left[key][j]) < 1e-9 * scale, (corner, key)
        # the row after the corner is the new interval's: the current steps by at least J_0 times omega_dot's step
        # over c_m (the rotor's share; the follower's m s'^2 adds to it where it is carried)
        k = TIMES.index(corner)
        step = abs((VALUES[k + 1] - VALUES[k]) / (TIMES[k + 1] - TIMES[k])
                   - (VALUES[k] - VALUES[k - 1]) / (TIMES[k] - TIMES[k - 1]))
        jumps += abs(ref["i"][j + 1] - ref_left["i"][j + 1]) > 0.9 * J_0 * step / C_M
    assert jumps == len(CORNERS)


def test_a_step_of_the_voltage_is_the_left_limit(tmp_path, cam_fmu_path):
    """u steps from 3.5 to 8 V at 0.2 s: at 0.2 s the outputs of the run that stays at 3.5 V (voltage 3.5, the current
    it drives), from the next output on those of 8 V; on the rigid drive, with an inductance (L = 1 mH: the reference
    refused the run, "Required step size is less than spacing between numbers" at 0.083 s, solve_ivp evaluating the
    piece's end with the 8 V after the step) and in a vertical groove, where the cam has stuck at 3.5 V by 0.1 s and the
    step breaks it away (the reference refused that run too: 1000 events a rounding before the step), cam.fmu against
    the reference at every output."""
    step = 'u = {type = "step", time = 0.2, before = 3.5, after = 8.0}'
    for params in ('gamma = 3.141592653589793', 'gamma = 3.141592653589793\nL = 1e-3', f'c = 5e-4\n{VERTICAL}'):
        scene = scene_file(tmp_path, "ustep", "voltage", step, 0.3, 1e-3, params)
        held = scene_file(tmp_path, "uheld", "voltage", "u = 3.5", 0.3, 1e-3, params)
        fmu, ref = run_scene(scene, "fmu", cam_fmu_path)["a"], run_scene(scene, "reference")["a"]
        fmu_held, ref_held = run_scene(held, "fmu", cam_fmu_path)["a"], run_scene(held, "reference")["a"]
        j = row_at(fmu, 0.2)
        assert fmu["voltage"][j] == ref["voltage"][j] == 3.5 and fmu["voltage"][j + 1] == ref["voltage"][j + 1] == 8.0
        for key in KEYS:
            scale = np.max(np.abs(ref[key])) + 1e-300
            assert np.max(np.abs(fmu[key] - ref[key])) < 1e-7 * scale, (params, key)
            assert np.max(np.abs(fmu[key][:j + 1] - fmu_held[key][:j + 1])) < 1e-12 * scale, (params, key)
            assert abs(ref[key][j] - ref_held[key][j]) < 1e-9 * scale, (params, key)
        assert abs(ref["i"][j + 1] - ref_held["i"][j + 1]) > 0.1   # the step's effect from the next output on
        if "c = 5e-4" in params:   # stuck at 3.5 V (from 0.1 s on), broken away by 8 V
            assert np.all(ref["omega"][j - 100:j + 1] == 0.0) and np.max(np.abs(ref["omega"][j + 1:])) > 0.0
