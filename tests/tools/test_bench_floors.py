"""The bench's C floor FMU, and its report functions (Pareto front, ratios, goal verdict) on synthetic rows.

The C floor is a plain C library (no Python inside), so unlike cam.fmu and the
pythonfmu floor it is loaded in the pytest process. No timing is asserted.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
import zipfile

import pytest

from cam_fmu.physics.parameters import EFFECTS
from cam_fmu.physics.variables import INPUT_STARTS, INPUTS, OUTPUT_NAMES
from cam_fmu.tools.bench import perstep, report


@pytest.fixture(scope="module")
def c_floor(tmp_path_factory):
    from cam_fmu.tools.bench.c_floor import build_c_floor_fmu

    # no C compiler is an error here (NativeBuildError), not a skip: CI installs gcc (setup.sh)
    return build_c_floor_fmu(tmp_path_factory.mktemp("c_floor"))


def _variables(fmu):
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    return {v.get("name"): v.get("causality") for v in root.iter("ScalarVariable")}


def test_c_floor_validates_and_has_cam_fmus_inputs_and_outputs(c_floor, cam_fmu_path):
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(c_floor)) == []
    floor = _variables(c_floor)
    cam = {name: causality for name, causality in _variables(cam_fmu_path).items()
           if causality in ("input", "output")}
    assert floor == cam
    assert [n for n, c in floor.items() if c == "input"] == [row[0] for row in INPUTS]
    assert sorted(n for n, c in floor.items() if c == "output") == sorted(OUTPUT_NAMES)


def test_c_floor_simulates_its_toy_model_and_sets_every_output(c_floor):
    from fmpy import simulate_fmu

    h, u = 1e-3, INPUT_STARTS["u"]
    result = simulate_fmu(str(c_floor), stop_time=2.0, output_interval=h)
    assert set(OUTPUT_NAMES) <= set(result.dtype.names)
    assert len(result) == 2001 and math.isclose(result["time"][-1], 2.0)
    # forward Euler of omega' = u - omega from 0: omega_n = u (1 - (1 - h)^n); theta' = omega
    n = 2000
    assert math.isclose(result["omega"][-1], u * (1.0 - (1.0 - h) ** n), rel_tol=1e-9)
    assert math.isclose(result["theta"][-1], h * float(sum(result["omega"][:-1])), rel_tol=1e-9)
    for name in OUTPUT_NAMES:  # every output moves with the states
        assert result[name][-1] != 0.0 and math.isfinite(result[name][-1]), name


def test_c_floor_follows_its_input_and_resets(c_floor, tmp_path):
    import numpy as np

    from cam_fmu.experiments.fmpy_runner import FmuRunner

    runner = FmuRunner(c_floor, tmp_path, "c_floor")
    inputs = np.array([(0.0, -2.0, 1.0, 0.0), (1.0, -2.0, 1.0, 0.0)],
                      dtype=[("time", float), ("u", float), ("omega_ref", float), ("omega_dot_ref", float)])
    first = runner.simulate({}, 1.0, 1e-3, inputs, outputs=["theta", "omega"])
    again = runner.simulate({}, 1.0, 1e-3, inputs, outputs=["theta", "omega"])  # after fmi2Reset
    assert first["omega"][-1] < 0.0
    assert np.array_equal(first["theta"], again["theta"]) and np.array_equal(first["omega"], again["omega"])


# --------------------------------------------------------------------------- report functions
def _grid_row(case, comm, solver, setting, err, ratio, status="ok", default=False):
    return report._row(case=case, kind="fmu", solver=solver, setting=setting, comm_step=comm, status=status,
                       theta_err=err, cost_ratio=ratio, us_per_step=ratio * 30.0, default=default)


def test_pareto_keeps_only_the_non_dominated_settings_per_scene_and_comm_step():
    rows = [
        _grid_row("fig6", 1e-3, "euler", "h=0.001", 5e-2, 3.0),
        _grid_row("fig6", 1e-3, "rk4", "h=0.001", 2e-4, 3.5),
        _grid_row("fig6", 1e-3, "etdrk4", "h=0.001", 2e-4, 3.6),   # as accurate as rk4, dearer: dominated
        _grid_row("fig6", 1e-3, "rk45", "rtol=1e-06", 1e-3, 4.0),  # less accurate and dearer than rk4
        _grid_row("fig6", 1e-3, "rk45", "rtol=1e-10", 3e-9, 4.5, default=True),
        _grid_row("fig6", 1e-3, "rk45", "rtol=1e-9", 3e-9, 4.5),   # a tie with the default: both stay
        _grid_row("fig6", 1e-2, "rk45", "rtol=1e-10", 1e-1, 9.0),  # another comm step: its own front
        _grid_row("fig6", 1e-3, "rk4", "h=0.0001", "", 1.0, status="error"),  # no error value: not ranked
        report._row(case="fig6", kind="floor", solver="floor", comm_step=1e-3, status="ok", cost_ratio=1.0),
    ]
    front = report.pareto(rows)
    marked = {(r["solver"], r["setting"], r["comm_step"]): r["pareto"] for r in rows}
    assert marked == {("euler", "h=0.001", 1e-3): True, ("rk4", "h=0.001", 1e-3): True,
                      ("etdrk4", "h=0.001", 1e-3): False, ("rk45", "rtol=1e-06", 1e-3): False,
                      ("rk45", "rtol=1e-10", 1e-3): True, ("rk45", "rtol=1e-9", 1e-3): True,
                      ("rk45", "rtol=1e-10", 1e-2): True, ("rk4", "h=0.0001", 1e-3): "",
                      ("floor", "", 1e-3): ""}
    assert [(r["solver"], r["comm_step"]) for r in front][:2] == [("euler", 1e-3), ("rk4", 1e-3)]
    assert len(front) == 5
    text = report.format_pareto(front)
    assert "rtol=1e-10*" in text and "etdrk4" not in text


def _scene_row(cam, py, c, scene="paper_fig6", record="theta,omega"):
    row = dict(scene=scene, drive="voltage", record=record, comm_step=1e-3, n_steps=2000, stop_time=2.0,
               cam_us=cam, py_floor_us=py, c_floor_us=c, repeats=5, error="")
    row["cam_py_ratio"] = cam / py
    row["cam_c_ratio"] = cam / c
    return row


def test_goal_verdict_states_both_ratios():
    rows = [_scene_row(130.0, 25.0, 18.0, record="all"),   # another record: not the one reported
            _scene_row(24.0, 20.0, 10.0)]
    text = report.goal_verdict(rows)
    assert "fig6" in text and "theta+omega" in text
    assert "cam.fmu 24.0 us/step (best of 5 rounds) = 1.20x the pythonfmu floor (20.0 us), 2.40x the C floor " \
        "(10.0 us)" in text
    assert "no fig6 row" in report.goal_verdict([_scene_row(1.0, 1.0, 1.0, scene="backlash")])


def test_the_targets_verdict_says_met_or_not_with_the_figures():
    from cam_fmu.tools.bench import targets

    fast = dict(c_host_us=0.4, c_host_floor_us=0.01, fmpy_us=4.5, fmpy_floor_us=4.0, fmpy_ratio=1.125,
                in_process_ms=1.5, theta_end=13.2)
    lines = targets.verdict(fast)
    assert len(lines) == 3 and all(line.endswith(": met") for line in lines), lines
    assert "0.400 us/step" in lines[0] and "1.125x" in lines[1] and "1.50 ms" in lines[2]
    slow = dict(fast, c_host_us=1.2, fmpy_ratio=1.3, in_process_ms=2.7)
    assert all(line.endswith("NOT met") for line in targets.verdict(slow))


def test_the_targets_are_measured_as_positive_finite_numbers(cam_fmu_path, tmp_path):
    """A quick measurement of every target (timing values are not asserted, only that they are measured,
    and that the C host ran the model: theta moved)."""
    from cam_fmu.tools.bench import targets

    measured = targets.measure(cam_fmu_path, tmp_path, quick=True)
    for key in ("c_host_us", "c_host_floor_us", "fmpy_us", "fmpy_floor_us", "fmpy_ratio", "in_process_ms"):
        assert math.isfinite(measured[key]) and measured[key] > 0.0, (key, measured)
    assert measured["theta_end"] > 1.0


def test_scene_and_effect_rows_print_their_ratios():
    line = report.format_scene_row(_scene_row(130.0, 25.0, 18.0))
    assert line.split()[:2] == ["paper_fig6", "theta,omega"]
    assert [float(x) for x in line.split()[2:]] == pytest.approx([130.0, 25.0, 18.0, 5.2, 7.22], abs=0.006)
    effects = [dict(config="defaults", change="fig. 6 as shipped", us_per_step=130.0, delta_us=0.0, py_ratio=5.2,
                    c_ratio=7.2, error=""),
               dict(config="all off", change="every effect false", us_per_step=100.0, delta_us=-30.0, py_ratio=4.0,
                    c_ratio=5.5, error="")]
    text = report.format_effects(effects)
    assert "-30.0" in text and "all off" in text


def test_effect_configs_switch_each_effect_once():
    configs = perstep.effect_configs()
    names = [c[0] for c in configs]
    assert names[0] == "defaults" and names[-1] == "all off" and len(set(names)) == len(names)
    for effect in EFFECTS:
        assert (f"{effect} off", f"{effect} = false", {effect: False}) in configs
    assert dict((c[0], c[2]) for c in configs)["backlash on"] == {"c": 5e-4}
    assert dict((c[0], c[2]) for c in configs)["inductance on"] == {"L": 1e-3}
    assert configs[-1][2] == {effect: False for effect in EFFECTS}


def test_every_shipped_scene_is_in_the_full_scene_table():
    from cam_fmu.experiments.scenes import scene_names

    full = perstep.scene_list(quick=False)
    assert full[0] == "paper_fig6" and sorted(full) == sorted(scene_names())
    assert perstep.scene_list(quick=True) == ["paper_fig6"]
    speed = perstep.load_scene_case("speed_drive")
    assert speed.drive == "speed" and "solver" not in speed.start_values
    assert set(speed.inputs.dtype.names) == {"time", *INPUT_STARTS}
