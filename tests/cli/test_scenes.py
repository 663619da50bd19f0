"""Scenes (cam_fmu/experiments/scene_files/*.toml), the engines and `cam-fmu simulate`.

Physics of the drive itself is tested in tests/test_drive_*.py; here: every
scene loads and runs, the CLI writes what it promises, bad scene files are
rejected with the key named, and scene-level facts of the paper's figures.
"""
from __future__ import annotations

import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cam_fmu import cli
from cam_fmu.kinematics.cam_program import paper_program
from cam_fmu.experiments.runner import input_table, run_scene
from cam_fmu.physics.parameters import KGF, defaults
from cam_fmu.experiments.scenes import SCENE_DIR, SceneError, load_scene, scene_files, scene_from_dict
from cam_fmu.fmu.engine import OUTPUTS

ROOT = Path(__file__).resolve().parents[2]
MODELS = SCENE_DIR  # the shipped scenes
SCENES = {path.stem: path for path in scene_files(MODELS)}
REQUIRED = {"paper_fig4", "paper_fig5a", "paper_fig5b", "paper_fig6", "backlash", "tilted", "inductance"}
SHORT = 0.1  # s: voltage-drive scenes are shortened to this in the smoke test


@pytest.fixture(scope="module")
def full_runs(reference_runs):
    """Reference runs of the scenes whose facts need the whole duration (cheap ones only)."""
    return {name: reference_runs.scene(load_scene(SCENES[name]))
            for name in ("paper_fig4", "paper_fig5a", "paper_fig5b", "paper_fig6")}


def test_required_scenes_exist_and_document_themselves():
    assert REQUIRED <= set(SCENES), f"missing scenes: {REQUIRED - set(SCENES)}"
    for name, path in SCENES.items():
        first = path.read_text(encoding="utf-8").splitlines()[0]
        assert first.startswith("# "), f"{path.name} must start with a comment saying what it reproduces"
        assert load_scene(path).description, f"{path.name} has no description"


@pytest.mark.parametrize("name", sorted(SCENES))
def test_scene_runs_on_the_reference(name):
    scene = load_scene(SCENES[name])
    if scene.drive == "voltage":
        scene = scene.with_stop_time(SHORT)
    results = run_scene(scene, "reference")
    assert list(results) == [run.label for run in scene.runs]
    # every output interval, plus a last shorter one ending at stop_time (as fmpy does: fig. 4 lasts 2 pi s)
    n = int(np.floor(scene.stop_time / scene.output_interval * (1 + 1e-12))) + 1
    n += scene.stop_time - (n - 1) * scene.output_interval > 1e-9 * scene.stop_time
    for label, r in results.items():
        assert r["time"][0] == 0.0 and len(r["time"]) == n and r["time"][-1] == scene.stop_time, label
        for out, _unit, _desc in OUTPUTS:
            assert r[out].shape == (n,) and np.all(np.isfinite(r[out])), (label, out)


def test_runs_inherit_the_scene_and_override_it():
    scene = load_scene(SCENES["paper_fig6"])
    assert [r.label for r in scene.runs] == ["consistent", "paper"]
    assert scene.primary.params["formulation"] == "consistent"
    assert scene.runs[1].params["formulation"] == "paper"
    for run in scene.runs:  # the scene's [parameters] reach every run
        assert run.params["gamma"] == math.pi and run.params["drive"] == "voltage"
    assert scene.u.value(1.0) == 3.5
    plain = scene_from_dict({"u": 2.0, "stop_time": 1.0, "output_interval": 0.1}, name="plain")
    assert [r.label for r in plain.runs] == ["base"] and plain.primary.params == {**defaults()}
    assert plain.primary.start_values() == {"drive": "voltage"}


# ------------------------------------------------------------------- the CLI
def test_set_leaves_out_a_run_it_makes_a_copy_of(capsys):
    """backlash compares c = 0.5 mm with a run labelled c_0; ``--set c=...`` takes every run's own c, so the
    second run would repeat the first under a label that says c = 0: it is left out, with a note."""
    from cam_fmu.cli.simulate import apply_sets
    from cam_fmu.experiments.scenes import find_scene

    scene = find_scene("backlash")
    assert [run.label for run in scene.runs] == ["c_0.5mm", "c_0"]
    assert scene.runs[1].params["c"] == 0.0
    changed = apply_sets(scene, ["c=0.2mm"])
    assert [run.label for run in changed.runs] == ["c_0.5mm"]
    assert changed.primary.params["c"] == pytest.approx(2e-4, rel=1e-15)
    assert "run 'c_0' is the same as run 'c_0.5mm'" in capsys.readouterr().err
    other = apply_sets(scene, ["mu=0.1"])  # a parameter no run sets: both runs stay, each with its own c
    assert [(run.label, run.params["c"], run.params["mu"]) for run in other.runs] == [
        ("c_0.5mm", 5e-4, 0.1), ("c_0", 0.0, 0.1)]


def _read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    with path.open() as fh:
        header = [name.split(" [", 1)[0] for name in next(csv.reader(fh))]  # 'omega [rad/s]' -> 'omega'
    return header, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def test_cli_writes_csv_per_run_and_png(tmp_path, capsys):
    status = cli.main(["simulate", str(SCENES["paper_fig6"]), "--engine", "reference",
                       "--out", str(tmp_path), "--stop-time", "0.05"])
    assert status == 0, capsys.readouterr().err
    primary, other, png = (tmp_path / "paper_fig6.csv", tmp_path / "paper_fig6__paper.csv",
                           tmp_path / "paper_fig6.png")
    for path in (primary, other):
        header, data = _read_csv(path)
        assert header[:7] == ["time", "theta", "omega", "s", "i", "M", "J"]
        assert set(header) >= {name for name, _u, _d in OUTPUTS}
        assert data.shape == (51, len(header))
        assert data[-1, 0] == pytest.approx(0.05)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    # the primary CSV is the consistent run: i = (u - c_e omega) / R with L = 0
    header, data = _read_csv(primary)
    col = {name: k for k, name in enumerate(header)}
    p = defaults()
    assert np.allclose(data[:, col["i"]], (3.5 - p["c_e"] * data[:, col["omega"]]) / p["R"], rtol=1e-9, atol=1e-12)


def test_cli_error_names_the_key(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('u = 3.5\nstop_time = 1.0\noutput_interval = 0.1\n[parameters]\nmass = 1.0\n')
    assert cli.main(["simulate", str(bad), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "cam-fmu simulate: error:" in err and "'mass'" in err and "bad.toml" in err
    assert not list(tmp_path.glob("*.csv"))


@pytest.mark.parametrize("text, named", [
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\nduration = 3\n', "'duration'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\n[parameters]\ngama = 1.0\n', "'gama'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\n[parameters]\nR = -1\n', "'R'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\n[parameters]\nbacklash = "maybe"\n', "'backlash'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\n[[runs]]\nlabel = "a"\nbeta_deg = 90\n', "'beta_deg'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\n[[runs]]\nlabel = "a"\nc = 0.5\n', "'c'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\n[[runs]]\nformulation = "paper"\n', "'label'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\n[[runs]]\nlabel = "a"\n[[runs]]\nlabel = "a"\n', "'a'"),
    ('drive = "speed"\nu = 3.5\nstop_time = 1\noutput_interval = 0.1\n', "'omega_ref'"),
    ('drive = "torque"\nu = 3.5\nstop_time = 1\noutput_interval = 0.1\n', "'drive'"),
    ('stop_time = 1\noutput_interval = 0.1\n[u]\ntype = "step"\ntime = 0.5\nbefore = 0\nafter = 3.5\nvalue = 1\n', "'value'"),
    ('stop_time = 1\noutput_interval = 0.1\n[u]\ntype = "step"\ntime = 0.5\nafter = 3.5\n', "'before'"),
    ('stop_time = 1\noutput_interval = 0.1\n[u]\ntype = "sine"\n', "'sine'"),
    ('u = 3.5\noutput_interval = 0.1\n', "'stop_time'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0\n', "'output_interval'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\nplot = "fig9"\n', "'plot'"),
    ('u = 3.5\nstop_time = 1\noutput_interval = 0.1\n[parameters]\nrise_angle = 1.0\n', "'rise_angle'"),
    ('u = 3.5\nstop_time = = 1\n', "not valid TOML"),
])
def test_bad_scene_is_rejected_naming_the_key(tmp_path, text, named):
    path = tmp_path / "broken.toml"
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert named in str(info.value) and "broken.toml" in str(info.value)


def test_missing_scene_file(tmp_path):
    with pytest.raises(SceneError, match="does not exist"):
        load_scene(tmp_path / "nope.toml")


def test_input_table_has_jumps_as_repeated_times():
    scene = scene_from_dict({"u": {"type": "step", "time": 0.5, "before": 0.0, "after": 3.5},
                             "stop_time": 1.0, "output_interval": 0.1}, name="step")
    table = input_table(scene)
    assert table.dtype.names == ("time", "u", "omega_ref", "omega_dot_ref")
    assert [tuple(row) for row in table] == [
        (0.0, 0.0, 1.0, 0.0), (0.5, 0.0, 1.0, 0.0), (0.5, 3.5, 1.0, 0.0), (1.0, 3.5, 1.0, 0.0)]


def test_input_table_gives_the_slope_of_a_speed_ramp():
    scene = scene_from_dict({"drive": "speed", "omega_ref": {"type": "ramp", "start": 0.2, "stop": 1.0, "from": 0.0, "to": 8.0},
                             "stop_time": 1.5, "output_interval": 0.1}, name="ramp")
    table = input_table(scene)
    for row in table:
        t = row["time"]
        if 0.2 < t < 1.0:
            assert row["omega_dot_ref"] == 10.0  # 8 rad/s over 0.8 s
            assert abs(row["omega_ref"] - 10.0 * (t - 0.2)) < 1e-12
        elif t < 0.2 or t > 1.0:
            assert row["omega_dot_ref"] == 0.0


# ----------------------------------------------------- facts of the paper's figures
def test_fig4_inertia_is_the_cam_programs(full_runs):
    r = full_runs["paper_fig4"]["base"]
    p = defaults()
    _s, ds, _d2s, _d3s = paper_program().evaluate(r["theta"])  # independent of the drive model
    assert np.allclose(r["J"], p["J_m"] + p["m"] * ds ** 2, rtol=1e-12, atol=1e-15)
    assert np.allclose(r["theta"], r["time"] * 1.0, atol=1e-12)  # omega = 1 rad/s from theta0 = 0
    assert r["theta"][-1] > 2 * math.pi - 0.01  # one revolution
    # horizontal: the load torque stays within M_f plus a small inertia/friction part
    assert np.all(r["M"] > 0.0) and r["M"].max() < 2 * p["M_f"]
    assert r["J"].max() == pytest.approx(p["J_m"] + p["m"] * (p["lift"] * 4 / 3 / math.pi) ** 2, rel=1e-3)


def _spread(result):
    return float(result["M"].max() - result["M"].min())


def test_fig5a_torque_spread_grows_as_gamma_leaves_180_deg(full_runs):
    runs = full_runs["paper_fig5a"]
    spreads = [_spread(runs[label]) for label in ("gamma_180", "gamma_150", "gamma_120", "gamma_90")]
    assert all(b > a * 1.1 for a, b in zip(spreads, spreads[1:])), spreads  # sin 120 / sin 90 = 1.15
    # gravity's torque amplitude scales with sin(gamma): spread(90)/spread(150) ~ 1/sin(150 deg) = 2
    assert spreads[3] / spreads[1] == pytest.approx(2.0, rel=0.1)


def test_fig5b_beta_mirrors_gravity_along_the_rise(full_runs):
    runs = full_runs["paper_fig5b"]
    spread = {label: _spread(r) for label, r in runs.items()}
    assert spread["beta_0"] == pytest.approx(spread["beta_180"], rel=0.05)
    assert spread["beta_45"] == pytest.approx(spread["beta_135"], rel=0.05)
    assert spread["beta_0"] > spread["beta_45"] > 3 * spread["beta_90"]
    # beta = 0 pulls the follower along the rise, beta = 180 deg against it: on the rise
    # (theta in (0, pi), ds/dtheta > 0) the torque is lower at beta = 0 than at 180 deg
    rise = (runs["beta_0"]["theta"] > 0.3) & (runs["beta_0"]["theta"] < math.pi - 0.3)
    assert np.all(runs["beta_0"]["M"][rise] < runs["beta_180"]["M"][rise])


def test_fig6_formulations_differ(full_runs):
    consistent, paper = full_runs["paper_fig6"]["consistent"], full_runs["paper_fig6"]["paper"]
    assert consistent["omega"].max() > 1.5 * paper["omega"].max()
    assert abs(consistent["theta"][-1] - paper["theta"][-1]) > 0.5  # rad
    # both start from rest and both turn forward all the time
    assert consistent["omega"][0] == paper["omega"][0] == 0.0
    assert consistent["omega"][1:].min() > 0.0 and paper["omega"][1:].min() > 0.0


def test_tilted_opposing_gravity_stalls_on_the_rise(reference_runs):
    scene = load_scene(SCENES["tilted"]).with_stop_time(0.3)
    r = reference_runs.scene(scene)["opposing"]
    p = scene.primary.params
    assert p["beta"] == pytest.approx(math.pi)  # F_gx = -G: gravity opposes the rise
    assert r["omega"][-1] == 0.0 and 0.0 < r["theta"][-1] < math.pi / 2
    # at rest: motor torque c_m u / R balances G ds/dtheta within +-M_f (guide friction mu = 0.001)
    torque = p["c_m"] * 3.5 / p["R"]
    ds = paper_program().derivatives(float(r["theta"][-1]))[1]
    assert torque - p["M_f"] - 1e-3 <= p["G"] * ds <= torque + p["M_f"] + 1e-3
    assert p["c_m"] == pytest.approx(0.015 * KGF)


def test_backlash_follower_lags_by_the_clearance(reference_runs):
    scene = load_scene(SCENES["backlash"]).with_stop_time(0.8)
    r = reference_runs.scene(scene)
    c = scene.primary.params["c"]
    gap = np.abs(r["c_0.5mm"]["s_cam"] - r["c_0.5mm"]["s"])
    assert c == 5e-4 and gap.max() <= c * (1 + 1e-6) and gap.max() > 0.9 * c
    assert np.array_equal(r["c_0"]["s"], r["c_0"]["s_cam"])


# ------------------------------------------------------------------ the FMU engine
def test_cli_fmu_engine_matches_reference(tmp_path, cam_fmu_path):
    """The FMU runs in a child process (an FMU must not be loaded into pytest: conftest)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    outs = {}
    for engine in ("fmu", "reference"):
        out = tmp_path / engine
        cmd = [sys.executable, "-m", "cam_fmu.cli", "simulate", str(SCENES["paper_fig6"]), "--engine", engine,
               "--fmu", str(cam_fmu_path), "--out", str(out), "--stop-time", "0.3", "--no-plot"]
        proc = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, env=env, timeout=300)
        assert proc.returncode == 0, (engine, proc.stderr[-3000:])
        outs[engine] = {name: _read_csv(out / name) for name in ("paper_fig6.csv", "paper_fig6__paper.csv")}
    for name in ("paper_fig6.csv", "paper_fig6__paper.csv"):
        (h_fmu, fmu), (h_ref, ref) = outs["fmu"][name], outs["reference"][name]
        assert h_fmu == h_ref and fmu.shape == ref.shape
        omega = h_ref.index("omega")
        assert np.allclose(fmu[:, 0], ref[:, 0], atol=1e-12)
        assert np.max(np.abs(fmu[:, omega] - ref[:, omega])) < 1e-4 * np.max(np.abs(ref[:, omega])), name


def test_docs_document_every_parameter_and_scene():
    """docs/scenes.md holds the parameter table and the scene table (moved there from the README)."""
    text = (ROOT / "docs" / "scenes.md").read_text(encoding="utf-8")
    section = text.split("\n## Parameters", 1)[1].split("\n## ", 1)[0]
    from cam_fmu.physics.parameters import PARAMETERS
    for p in PARAMETERS:
        unit = p.unit if p.unit else "-"
        assert f"| `{p.name}` | {unit} |" in section, f"docs/scenes.md parameter table lacks {p.name} [{unit}]"
    scenes = text.split("\n## The shipped scenes", 1)[1].split("\n## ", 1)[0]
    for name in SCENES:
        assert f"| `{name}` |" in scenes, f"docs/scenes.md scene table lacks {name}"


def test_docs_parameter_table_is_the_generated_one():
    """docs/scenes.md's parameter table is physics.parameters.markdown_table(): it cannot drift from the table."""
    from cam_fmu.physics.parameters import markdown_table
    assert markdown_table() in (ROOT / "docs" / "scenes.md").read_text(encoding="utf-8")


def test_every_parameter_states_what_it_allows():
    """No 'one of ' with nothing after it (motion_table, a free string, once said that in both tables)."""
    from cam_fmu.physics.parameters import PARAMETERS

    for p in PARAMETERS:
        text = p.allowed()
        assert text.strip() and not text.rstrip().endswith("one of"), (p.name, text)
        if p.kind == "string" and not p.choices:
            assert text.startswith("any text") and p.check("angle_deg,lift_mm\n0,0\n") == "angle_deg,lift_mm\n0,0\n"
    for doc in ("scenes.md", "fmu.md"):
        assert "| one of  |" not in (ROOT / "docs" / doc).read_text(encoding="utf-8"), doc
