"""Shared fixtures and the test layout's markers (tests/README.md).

The tests sit in folders by layer (kinematics, vibration, physics, engine, fmu_cs, fmu_me, fmi3, hosts, cli, tools);
the shared helpers (native_support.py, engine_profile.py, fmi_slave.py) and the C hosts beside this file.
Markers, set here so that a module cannot forget them (the rules: markers.py):
- ``external``: every test of ``hosts/`` and of the modules in ``markers.EXTERNAL`` (wine, qemu-user, valgrind,
  sanitizers, other CPythons, native FMU hosts, zig's other platforms, the package index);
- ``slow``: measured, not listed: a test whose recorded duration in durations.json (or a module fixture's set-up
  it needs) exceeds ``markers.SLOW_SECONDS``; ``--record-durations tests/durations.json`` on a full run
  re-records the file.
``python -m pytest -m "not external and not slow"`` is the loop a developer runs while working; it builds the
session's FMUs for this machine only (the system C compiler). CI runs everything.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
# The environment pytest runs in comes first on PATH: `.venv/bin/python -m pytest` from a shell whose PATH
# lacks .venv/bin still runs that environment's console scripts (cam-fmu, fmpy), here and in every child.
# sys.executable unresolved: a venv's python is a symlink out of its bin folder.
_ENV_BIN = Path(sys.executable).parent
if (_ENV_BIN / "cam-fmu").is_file() and os.environ.get("PATH", "").split(os.pathsep)[0] != str(_ENV_BIN):
    os.environ["PATH"] = os.pathsep.join([str(_ENV_BIN), os.environ.get("PATH", "")])
# the shared helpers, and the layers' modules that others import (a test of one layer may reuse another's
# closed forms or hosts), whichever folders a session collects
for _folder in (Path(__file__).resolve().parent, *sorted(p for p in Path(__file__).resolve().parent.iterdir()
                                                         if p.is_dir() and any(p.glob("test_*.py")))):
    sys.path.insert(0, str(_folder))

from markers import (DURATIONS, DurationRecorder, XdistDurations, is_external, is_slow, load,  # noqa: E402
                     longest_modules_first)
from session_share import once, shared_folder  # noqa: E402 - after sys.path

RECORDED = load()


def pytest_addoption(parser):
    parser.addoption("--record-durations", metavar="PATH", default=None, type=Path,
                     help="write every test's own duration and its module and session fixtures' set-ups to PATH "
                          f"(a full run, into {DURATIONS.relative_to(ROOT)}: tests/markers.py)")


def pytest_configure(config):
    path = config.getoption("record_durations")
    if path is not None:
        recorder = DurationRecorder(path, config)
        config.pluginmanager.register(recorder, "cam_fmu_durations")
        if config.pluginmanager.hasplugin("xdist") and not hasattr(config, "workerinput"):
            config.pluginmanager.register(XdistDurations(recorder), "cam_fmu_durations_xdist")


def pytest_collection_modifyitems(config, items):
    if hasattr(config, "workerinput"):  # a pytest-xdist worker: the longest modules are handed out first
        items[:] = longest_modules_first(items, RECORDED)
    for item in items:
        if is_external(item.nodeid):
            item.add_marker(pytest.mark.external)
        if is_slow(item.nodeid, item.fixturenames, RECORDED):
            item.add_marker(pytest.mark.slow)


def _fast_loop(config) -> bool:
    """The session leaves out the external tests: no test needs another platform's binaries."""
    return "not external" in (config.getoption("markexpr", "") or "")


# --------------------------------------------------------------------------- cam.fmu
def _build_fmu(dest: Path, model: str = "cam", host_only: bool = False) -> Path:
    """Build an FMU with build_fmu.py in a subprocess: the command users run, from this checkout (every
    platform; ``host_only``: this machine's binary, the system C compiler)."""
    cmd = [sys.executable, str(ROOT / "build_fmu.py"), "--model", model, "--dest", str(dest),
           *(["--platforms", "host"] if host_only else [])]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=300)
    if proc.returncode != 0 or not dest.is_file():
        pytest.fail(f"build_fmu.py --model {model} failed (exit {proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    return dest


@pytest.fixture(scope="session")
def cam_fmu_path(tmp_path_factory, request) -> Path:
    """cam.fmu built once per test session from this checkout (into a temporary folder). It is C: loading it
    into the pytest process is safe."""
    return once(tmp_path_factory, "cam_fmu_build",
                lambda folder: _build_fmu(folder / "cam.fmu", host_only=_fast_loop(request.config)))


@pytest.fixture(scope="session")
def pi_speed_fmu_path(tmp_path_factory, request) -> Path:
    """pi_speed.fmu built once per test session (build_fmu.py --model pi_speed): the PI controller in C."""
    return once(tmp_path_factory, "pi_speed_build",
                lambda folder: _build_fmu(folder / "pi_speed.fmu", "pi_speed", host_only=_fast_loop(request.config)))


@pytest.fixture(scope="session")
def cam3_fmu_path(tmp_path_factory, request) -> Path:
    """cam3.fmu (the drive as FMI 3.0 co-simulation) built once per test session (build_fmu.py --model cam3):
    every test of it reads this one build (six modules built their own, 8-9 minutes of zig in a full run)."""
    return once(tmp_path_factory, "cam3_build",
                lambda folder: _build_fmu(folder / "cam3.fmu", "cam3", host_only=_fast_loop(request.config)))


@pytest.fixture(scope="session")
def wheels_folder(tmp_path_factory) -> Path:
    """Every platform's wheel built once per test session (build_fmu.py --wheels): the wheel tests install them,
    the reproducibility test builds them once more and compares the bytes."""
    def build(folder: Path) -> Path:
        proc = subprocess.run([sys.executable, str(ROOT / "build_fmu.py"), "--wheels", str(folder)],
                              capture_output=True, text=True, cwd=ROOT, timeout=3600)
        if proc.returncode != 0:
            pytest.fail(f"build_fmu.py --wheels failed (exit {proc.returncode}):\n{proc.stderr[-3000:]}")
        return folder

    return once(tmp_path_factory, "wheels", build)


@pytest.fixture(scope="session")
def engine_fmu_path(cam_fmu_path) -> Path:
    """cam.fmu as ``cam_fmu_path`` (built from the C engine). It hosts no Python: loading it into the
    pytest process is safe."""
    return cam_fmu_path


@pytest.fixture(scope="session")
def reference_runs(tmp_path_factory):
    """The scipy reference's runs, each integrated once per session (reference_runs.py): the modules that compare
    against the same scene share its runs, across pytest-xdist's workers too (kept in the session's shared
    folder)."""
    from reference_runs import ReferenceRuns

    return ReferenceRuns(shared_folder(tmp_path_factory) / "reference_runs")


@pytest.fixture(autouse=True)
def _no_python_fmu_in_pytest():
    """A test that loads a pythonfmu FMU (a block written in Python) or pythonfmu itself into this process fails
    here, loudly: the CLI's exit_after_fmu would otherwise end the whole pytest run at the next in-process
    `cam-fmu` call with status 0 and the rest of the tests unrun (found when a run stopped silently at 92 %)."""
    import sys as _sys

    yield
    loaded = [m for m in list(_sys.modules) if m.startswith("pythonfmu")]
    assert not loaded, f"a pythonfmu FMU was loaded into the pytest process ({loaded}): run it in a child process"


def interrupt_after_progress(cmd: list[str], done: int, cwd: Path, env: dict, label: str = "") -> tuple[int, str]:
    """Run ``cmd`` (a `cam-fmu` command drawing its progress bar: CAM_FMU_PROGRESS=1) in its own process group,
    read its progress on stderr until the bar whose label ends with ``label`` reports ``done`` units finished,
    then send SIGINT to the whole group, as
    Ctrl-C in a terminal does. Returns (exit status, stderr). A run that ends before that is returned as it ended
    (the caller's assertions on the status then fail)."""
    import os
    import re
    import signal

    proc = subprocess.Popen(cmd, cwd=cwd, env={**env, "CAM_FMU_PROGRESS": "1"}, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, start_new_session=True)
    seen = b""
    while proc.poll() is None:
        chunk = os.read(proc.stderr.fileno(), 4096)
        if not chunk:
            break
        seen += chunk
        counts = [int(m) for m in re.findall(re.escape(label.encode()) + rb" \[[#.]*\] (\d+)/\d+ ", seen)]
        if counts and counts[-1] >= done:
            os.killpg(proc.pid, signal.SIGINT)
            break
    rest = proc.stderr.read()
    proc.wait(timeout=600)
    return proc.returncode, (seen + rest).decode("utf-8", "replace")
