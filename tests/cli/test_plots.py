"""Figures that read themselves (issue 12, part 3): the difference panel of scenes with
several runs, the voltage of speed-drive scenes, a readable bench.png, and progress
of `cam-fmu simulate`.

Figures are inspected as matplotlib objects (axes, labels, tick labels), not by pixels.
"""
from __future__ import annotations

import io
import os
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from cam_fmu import cli  # noqa: E402
from cam_fmu.experiments import fmpy_runner, runner  # noqa: E402
from cam_fmu.experiments.progress import ProgressBar  # noqa: E402
from cam_fmu.experiments.scenes import find_scene  # noqa: E402
from cam_fmu.physics.variables import OUTPUT_NAMES  # noqa: E402
from cam_fmu.plots.scene import PLOTS, difference, draw_scene, plot_scene  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def _fake_results(labels, n=50, stop=0.5, shift=0.0):
    """{label: outputs} with every output present; run k differs from run 0 by k*0.1 (+ shift in time)."""
    results = {}
    for k, label in enumerate(labels):
        t = np.linspace(0.0, stop, n + k * 7)  # different grids: the difference must interpolate
        r = {"time": t}
        for name in OUTPUT_NAMES:
            r[name] = np.sin(3.0 * t) + 0.1 * k
        r["theta"] = 10.0 * t
        results[label] = r
    return results


def _ylabels(fig):
    return [ax.get_ylabel() for ax in fig.axes]


@pytest.mark.parametrize("name", ["inductance", "backlash", "paper_fig6"])
def test_several_runs_get_a_difference_panel_under_every_quantity(name):
    scene = find_scene(name)
    labels = [run.label for run in scene.runs]
    assert len(labels) >= 2
    fig = draw_scene(plt, scene, _fake_results(labels))
    ylabels = _ylabels(fig)
    diffs = [y for y in ylabels if "difference" in y]
    mains = [y for y in ylabels if "difference" not in y]
    plt.close(fig)
    assert len(diffs) == len(mains) >= 1
    assert all(y.endswith("]") and "[" in y for y in diffs), diffs  # with units
    if name == "paper_fig6":
        assert diffs == ["difference [rad/s]"]


def test_one_run_has_no_difference_panel():
    scene = find_scene("tilted")  # a 'time' scene; drawn from its primary run alone
    fig = draw_scene(plt, scene, _fake_results([scene.runs[0].label]))
    ylabels = _ylabels(fig)
    plt.close(fig)
    assert len(ylabels) == 4 and not any("difference" in y for y in ylabels)


def test_difference_is_the_other_run_minus_the_primary_on_the_primary_grid():
    x0 = np.linspace(0.0, 1.0, 11)
    x = np.linspace(0.0, 1.0, 101)
    d = difference(x0, x, 2.0 * x + 1.0, 2.0 * x0)
    assert d.shape == x0.shape
    np.testing.assert_allclose(d, 1.0)
    assert np.isnan(difference(x0, x[:50], x[:50], x0)[-1])  # outside the other run: no value


def test_the_difference_panel_draws_the_difference():
    scene = find_scene("paper_fig6")
    results = _fake_results([run.label for run in scene.runs])
    fig = draw_scene(plt, scene, results)
    dax = [ax for ax in fig.axes if "difference" in ax.get_ylabel()][0]
    line = dax.get_lines()[0]
    plt.close(fig)
    np.testing.assert_allclose(line.get_xdata(), results[scene.runs[0].label]["time"])
    np.testing.assert_allclose(line.get_ydata(), 0.1, atol=2e-4)  # run 1 is run 0 + 0.1 (linear interpolation)


def test_speed_drive_scene_shows_voltage_and_current():
    scene = find_scene("speed_drive")
    assert scene.drive == "speed" and scene.plot == "time"
    fig = draw_scene(plt, scene, _fake_results([run.label for run in scene.runs]))
    ylabels = _ylabels(fig)
    plt.close(fig)
    assert "voltage [V]" in ylabels and "current i [A]" in ylabels
    assert "difference [V]" in ylabels


def test_voltage_drive_time_figure_has_no_voltage_panel():
    scene = find_scene("inductance")
    assert scene.drive == "voltage"
    fig = draw_scene(plt, scene, _fake_results([run.label for run in scene.runs]))
    ylabels = _ylabels(fig)
    plt.close(fig)
    assert "voltage [V]" not in ylabels and "current i [A]" in ylabels


def test_every_kind_is_written(tmp_path):
    for kind in PLOTS:
        scene = find_scene({"fig4": "paper_fig4", "fig5": "paper_fig5a", "fig6": "paper_fig6",
                            "time": "speed_drive", "follower": "spring_bounce", "train": "train_voltage",
                            "arm_time": "packaging_rocker"}[kind])
        assert scene.plot == kind
        path = plot_scene(scene, _fake_results([run.label for run in scene.runs]), tmp_path / f"{kind}.png")
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_speed_drive_scene_needs_voltage_on_the_reference(reference_runs):
    """The shipped scene: the required voltage is drawn and is not the trivial k omega."""
    scene = find_scene("speed_drive").with_stop_time(0.3)
    results = reference_runs.scene(scene)
    v = results["L_1mH"]["voltage"]
    assert np.all(np.isfinite(v)) and v.max() - v.min() > 10.0  # V: the cam's torque shows in the voltage
    assert np.abs(results["L_1mH"]["omega"] - 10.0).max() < 1e-9


# --------------------------------------------------------------------------- bench.png
def _bench_rows(span_decades=3.0):
    from cam_fmu.tools.bench.cases import CASES
    from cam_fmu.engine.solvers import SOLVERS
    rows = []
    for case in CASES[:2]:
        for k, solver in enumerate(list(SOLVERS)[:2]):
            for comm in (1e-3, 1e-2):
                for j in range(3):
                    rows.append(dict(case=case, kind="fmu", status="ok", solver=solver, comm_step=comm,
                                     cost_ratio=(2.0 + k) * 10.0 ** (span_decades * j / 2 / 3),
                                     theta_err=10.0 ** (-3 - 2 * j)))
    return rows


@pytest.mark.parametrize("span", [3.0, 0.4])
def test_bench_plot_has_labelled_log_ticks_and_units(tmp_path, monkeypatch, span):
    from cam_fmu.tools.bench import report
    captured = {}
    real_close = plt.close
    monkeypatch.setattr(plt, "close", lambda fig=None: captured.setdefault("fig", fig))
    path = tmp_path / "bench.png"
    report.plot(_bench_rows(span), path)
    fig = captured["fig"]
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    fig.canvas.draw()
    axes = [ax for ax in fig.axes if ax.get_xscale() == "log"]
    assert len(axes) == 2
    for ax in axes:
        assert ax.get_yscale() == "log"
        assert "[" in ax.get_xlabel() and ax.get_ylabel().endswith("[rad]")
        for axis in (ax.xaxis, ax.yaxis):
            labels = [t.get_text() for t in axis.get_ticklabels(which="both")
                      if t.get_text() and axis.get_view_interval().min() <= t.get_position()[axis is ax.yaxis]
                      <= axis.get_view_interval().max()]
            assert len(labels) >= 2, (axis, labels)  # numbers on the visible range, even under a decade
    assert fig.legends and fig.legends[0].get_texts()
    real_close(fig)


# --------------------------------------------------------------------------- progress
def test_simulate_prints_progress_per_run(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("CAM_FMU_PROGRESS", "1")
    rc = cli.main(["simulate", "inductance", "--stop-time", "0.05", "--out", str(tmp_path), "--no-plot"])
    err = capsys.readouterr().err
    assert rc == 0
    assert "simulate inductance (reference, runs)" in err
    assert "2/2" in err and err.endswith("\n")


def test_simulate_is_quiet_on_a_pipe(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    env.pop("CAM_FMU_PROGRESS", None)
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "simulate", "paper_fig6", "--stop-time", "0.05",
                           "--out", str(tmp_path), "--no-plot"], capture_output=True, text=True, env=env, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""


def test_fmu_runs_report_progress_per_communication_step(monkeypatch):
    """The FMU path counts steps over all runs (a fake runner stands in for fmpy)."""
    class FakeRunner:
        def __init__(self, fmu, name=""):
            pass

        def simulate(self, start_values, stop_time, output_interval, inputs, outputs=None, check_end=False,
                     on_step=None):
            t = np.arange(0.0, stop_time + output_interval / 2, output_interval)
            for time in t[1:]:
                on_step(time)
            return {name: t for name in ("time",) + tuple(outputs)}

    monkeypatch.setattr(fmpy_runner, "FmuRunner", FakeRunner)
    calls = []
    scene = find_scene("paper_fig6").with_stop_time(0.01)  # 2 runs x 10 steps
    runner._fmu_runs(scene, Path("unused.fmu"), progress=lambda done, total: calls.append((done, total)))
    assert {total for _, total in calls} == {20}
    dones = [done for done, _ in calls]
    assert dones == sorted(dones) and dones[0] == 0 and dones[-1] == 20 and 10 in dones


def test_progress_bar_close_ends_an_open_line():
    stream = io.StringIO()
    bar = ProgressBar("x", stream=stream)
    bar.enabled = True
    bar(1, 3)
    bar.close()
    assert stream.getvalue().endswith("\n") and stream.getvalue().count("\n") == 1
    bar.close()
    assert stream.getvalue().count("\n") == 1


def test_the_paper_figures_of_the_speed_drive_show_the_voltage_needed(reference_runs):
    """fig4 and fig5 (speed-drive scenes) carry a voltage panel over the cam angle."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cam_fmu.experiments.scenes import find_scene
    from cam_fmu.plots.scene import PLOTS

    for kind, name in (("fig4", "paper_fig4"), ("fig5", "paper_fig5a")):
        scene = find_scene(name)
        assert scene.drive == "speed"
        results = reference_runs.scene(scene.with_stop_time(1.0))
        fig, axes = PLOTS[kind](plt, results, scene.drive)
        labels = [ax.get_ylabel() for ax in axes]
        assert "voltage [V]" in labels, labels
        line = axes[labels.index("voltage [V]")].get_lines()[0]
        first = next(iter(results.values()))
        assert np.allclose(line.get_ydata(), first["voltage"])
        plt.close(fig)


def test_an_oscillating_followers_scene_shows_the_arm_angle():
    """The packaging rocker (an oscillating roller) draws psi in degrees where a translating follower shows s: its
    panel is the output psi times 180/pi (here psi = 0.2 rad everywhere: 11.459 deg)."""
    scene = find_scene("packaging_rocker")
    results = _fake_results([run.label for run in scene.runs])
    for r in results.values():
        r["psi"] = np.full_like(r["time"], 0.2)
    fig = draw_scene(plt, scene, results)
    ylabels = _ylabels(fig)
    line = fig.axes[ylabels.index("arm angle psi [deg]")].get_lines()[0]
    plt.close(fig)
    assert "follower s [mm]" not in ylabels
    assert np.allclose(line.get_ydata(), 0.2 * 180.0 / np.pi)
