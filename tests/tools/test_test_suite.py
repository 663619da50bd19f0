"""The test suite's own rules: the fast loop's budget from the recorded durations, the markers taken from them,
and the session's reference runs (tests/markers.py, tests/reference_runs.py, tests/README.md)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import markers

ROOT = Path(__file__).resolve().parents[2]


def test_the_fast_loop_fits_its_budget_by_the_recorded_durations():
    """The recorded seconds of the fast loop's tests (an upper bound: markers.fast_loop_bound) plus what the loop
    spends outside them (start-up, collection, the session's FMU builds for this machine) stay within the fast
    loop's target. A test that grows past markers.SLOW_SECONDS leaves the loop at the next record; many small
    ones that together outgrow it fail here."""
    recorded = markers.load()
    bound, count = markers.fast_loop_bound(recorded)
    assert count > 500, f"the record holds {count} fast tests: re-record it from a full run (tests/markers.py)"
    assert bound + markers.FAST_LOOP_OVERHEAD_SECONDS <= markers.FAST_LOOP_SECONDS, (
        f"the fast loop's {count} tests take {bound:.1f} s by the record, plus "
        f"{markers.FAST_LOOP_OVERHEAD_SECONDS:.0f} s outside them: over its {markers.FAST_LOOP_SECONDS:.0f} s")


def test_slow_is_a_tests_own_time_or_a_module_fixture_it_needs_over_the_threshold():
    over, under = markers.SLOW_SECONDS * 1.5, markers.SLOW_SECONDS / 2
    recorded = {"tests": {"tests/a/test_x.py::test_long": over, "tests/a/test_x.py::test_short": under},
                "fixtures": {"tests/a/test_x.py::scenes": over, "tests/a/test_x.py::table": under}, "session": {}}
    assert markers.is_slow("tests/a/test_x.py::test_long", [], recorded)
    assert not markers.is_slow("tests/a/test_x.py::test_short", ["table", "tmp_path"], recorded)
    assert markers.is_slow("tests/a/test_x.py::test_short", ["scenes"], recorded)  # its fixture is
    assert not markers.is_slow("tests/b/test_y.py::test_short", ["scenes"], recorded)  # another file's fixture
    assert not markers.is_slow("tests/a/test_x.py::test_new", [], recorded)  # not recorded yet: in the loop
    # the bound: the two fast tests' own time (test_new is not recorded) and the fixture under the threshold
    recorded["tests"]["tests/hosts/test_z.py::test_wine"] = under  # external: never in the fast loop
    assert markers.fast_loop_bound(recorded) == (pytest.approx(2 * under), 1)


def test_the_recorder_writes_own_times_apart_from_shared_fixtures(tmp_path):
    """--record-durations: a module fixture's set-up is recorded under the fixture, not under its first test."""
    (tmp_path / "conftest.py").write_text(
        f"import sys\nsys.path.insert(0, {str(ROOT / 'tests')!r})\nfrom pathlib import Path\n"
        "from markers import DurationRecorder\n\n"
        "def pytest_addoption(parser):\n    parser.addoption('--record-durations', type=Path)\n\n"
        "def pytest_configure(config):\n"
        "    config.pluginmanager.register(DurationRecorder(config.getoption('record_durations')), 'rec')\n")
    (tmp_path / "test_m.py").write_text(
        "import time, pytest\n\n@pytest.fixture(scope='module')\ndef shared():\n    time.sleep(0.6)\n\n"
        "def test_first(shared):\n    time.sleep(0.2)\n\ndef test_second(shared):\n    pass\n")
    out = tmp_path / "durations.json"
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--record-durations",
                           str(out), "test_m.py"], cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    recorded = markers.load(out)
    assert recorded["fixtures"]["test_m.py::shared"] >= 0.6
    assert 0.2 <= recorded["tests"]["test_m.py::test_first"] < 0.6  # its sleep, not the fixture's
    assert recorded["tests"]["test_m.py::test_second"] < 0.2


def test_the_sessions_reference_runs_are_the_runners_to_the_bit_and_each_callers_own(reference_runs):
    """The cache gives what run_scene(scene, 'reference') gives, computes a run once, and a caller that writes
    into its arrays does not change the next caller's."""
    from cam_fmu.experiments.runner import run_scene
    from cam_fmu.experiments.scenes import find_scene

    scene = find_scene("speed_drive").with_stop_time(0.05)
    direct = run_scene(scene, "reference")
    before = reference_runs.computed
    first = reference_runs.scene(scene)
    first[scene.primary.label]["theta"][:] = np.nan
    second = reference_runs.scene(scene)
    assert reference_runs.computed - before == len(scene.runs)
    assert list(second) == list(direct)
    for label, run in direct.items():
        assert set(second[label]) == set(run)
        assert all(np.array_equal(second[label][k], run[k]) for k in run), label


def test_under_two_workers_every_worker_records_and_a_shared_build_runs_once(tmp_path):
    """`pytest -n 2 --record-durations`: each xdist worker sends the durations of the tests it ran to the
    controller, which writes them all (a worker's tests are not lost); a session fixture built with
    session_share.once runs its build once for both workers, and both read its result."""
    (tmp_path / "conftest.py").write_text(
        f"import os, sys, time\nsys.path.insert(0, {str(ROOT / 'tests')!r})\nfrom pathlib import Path\nimport pytest\n"
        "from markers import DurationRecorder, XdistDurations\nfrom session_share import once\n\n"
        "def pytest_addoption(parser):\n    parser.addoption('--record-durations', type=Path)\n\n"
        "def pytest_configure(config):\n"
        "    rec = DurationRecorder(config.getoption('record_durations'), config)\n"
        "    config.pluginmanager.register(rec, 'rec')\n"
        "    if not hasattr(config, 'workerinput'):\n"
        "        config.pluginmanager.register(XdistDurations(rec), 'rec_xdist')\n\n"
        "@pytest.fixture(scope='session')\ndef built(tmp_path_factory):\n"
        "    def build(folder):\n"
        "        with open(Path(os.environ['BUILD_LOG']), 'a') as fh:\n"
        "            fh.write(os.environ['PYTEST_XDIST_WORKER'] + '\\n')\n"
        "        time.sleep(1.0)\n"
        "        (folder / 'out.txt').write_text('built')\n"
        "        return folder / 'out.txt'\n"
        "    return once(tmp_path_factory, 'built', build)\n")
    for module, sleep in (("a", 0.3), ("b", 0.0)):
        (tmp_path / f"test_{module}.py").write_text(
            "import os, time\nfrom pathlib import Path\n\n"
            f"def test_{module}_first(built):\n    time.sleep({sleep})\n    assert built.read_text() == 'built'\n"
            "    with open(Path(os.environ['WORKER_LOG']), 'a') as fh:\n"
            "        fh.write(os.environ['PYTEST_XDIST_WORKER'] + '\\n')\n\n"
            f"def test_{module}_second():\n    pass\n")
    out, builds, workers = tmp_path / "durations.json", tmp_path / "builds.txt", tmp_path / "workers.txt"
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-n", "2", "--dist",
                           "loadscope", "--record-durations", str(out), "test_a.py", "test_b.py"], cwd=tmp_path,
                          capture_output=True, text=True,
                          env={**os.environ, "BUILD_LOG": str(builds), "WORKER_LOG": str(workers)})
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert sorted(workers.read_text().split()) == ["gw0", "gw1"]  # one module on each worker
    assert len(builds.read_text().split()) == 1  # built once for the two
    recorded = markers.load(out)
    assert set(recorded["tests"]) == {f"test_{m}.py::test_{m}_{k}" for m in "ab" for k in ("first", "second")}
    assert 0.3 <= recorded["tests"]["test_a.py::test_a_first"] < 1.0  # its sleep, not the build's 1 s
    assert recorded["session"]["built"] >= 1.0  # the builder's set-up (the other waited as long or longer)


def test_a_worker_runs_the_longest_modules_first():
    """markers.longest_modules_first: modules by recorded seconds, longest first, unrecorded ones last, each
    module's tests in their order."""
    class Item:
        def __init__(self, nodeid):
            self.nodeid = nodeid

    recorded = {"tests": {"tests/a/test_x.py::t1": 1.0, "tests/a/test_x.py::t2": 1.0, "tests/b/test_y.py::t1": 0.5},
                "fixtures": {"tests/b/test_y.py::big": 5.0}, "session": {}}
    items = [Item(n) for n in ("tests/a/test_new.py::t", "tests/a/test_x.py::t1", "tests/a/test_x.py::t2",
                               "tests/b/test_y.py::t1", "tests/b/test_y.py::t2")]
    assert [i.nodeid for i in markers.longest_modules_first(items, recorded)] == [
        "tests/b/test_y.py::t1", "tests/b/test_y.py::t2", "tests/a/test_x.py::t1", "tests/a/test_x.py::t2",
        "tests/a/test_new.py::t"]
