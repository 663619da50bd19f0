"""setup.sh as a new user runs it on a fresh Debian: in a git clone of this repository, with a PATH that holds
only the system's directories (so the only python3 is the system's, /usr/bin/python3: Debian's, which refuses
`pip install`), it makes .venv from that python3, installs the package into it, and the environment's
Python imports cam_fmu and loads the engine library; a second run changes nothing; an older python3 is
refused with a clear message. Slow (a full pip install into a fresh environment) and needs the package index.
The clone is of the last commit: uncommitted changes are not in it.
"""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

pytestmark = [pytest.mark.external, pytest.mark.slow]

ROOT = Path(__file__).resolve().parents[2]
SYSTEM_PATH = "/usr/sbin:/usr/bin:/sbin:/bin"  # a fresh Debian's root shell (the report)
SYSTEM_PYTHON = Path("/usr/bin/python3")
OLD_PYTHON = Path("/root/.pyenv/versions/3.9.18/bin/python3")  # an older CPython of this machine (pyenv)
# what pip and git need from this environment (the index's address, proxies, certificates); nothing else
PASSED = ("HOME", "LANG", "http_proxy", "https_proxy", "no_proxy", "HTTP_PROXY", "HTTPS_PROXY", "NO_PROXY",
          "SSL_CERT_FILE", "REQUESTS_CA_BUNDLE")


def _env(path: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k in PASSED or k.startswith("PIP_")}
    return {**env, "PATH": path}


def _clone(folder: Path) -> Path:
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(folder)], check=True, timeout=600)
    return folder


def _setup(checkout: Path, path: str = SYSTEM_PATH) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", "setup.sh"], cwd=checkout, env=_env(path), capture_output=True, text=True,
                          timeout=3600)


def _snapshot(checkout: Path) -> dict[str, tuple[int, int]]:
    """(size, mtime in ns) of every file and folder of the checkout but .git."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(checkout):
        dirnames[:] = [d for d in dirnames if not (Path(dirpath) == checkout and d == ".git")]
        for name in [*dirnames, *filenames]:
            st = os.lstat(os.path.join(dirpath, name))
            out[os.path.relpath(os.path.join(dirpath, name), checkout)] = (st.st_size, st.st_mtime_ns)
    return out


@pytest.fixture(scope="module")
def fresh(tmp_path_factory) -> tuple[Path, subprocess.CompletedProcess]:
    """A clone set up once by setup.sh with the system's PATH: (the clone, the run)."""
    # the premise: the system's python3 is there, and it is what the system's PATH finds
    if not SYSTEM_PYTHON.is_file():
        pytest.fail(f"{SYSTEM_PYTHON} is missing: this test needs the system's python3 (Debian's python3 package)")
    found = subprocess.run(["sh", "-c", "command -v python3"], env=_env(SYSTEM_PATH), capture_output=True,
                           text=True).stdout.strip()
    assert Path(found).resolve() == SYSTEM_PYTHON.resolve(), found
    checkout = _clone(tmp_path_factory.mktemp("fresh") / "cam_fmu")
    return checkout, _setup(checkout)


def test_setup_makes_the_environment_from_the_system_python(fresh):
    checkout, run = fresh
    assert run.returncode == 0, f"{run.stdout[-3000:]}\n{run.stderr[-3000:]}"
    config = dict(line.split(" = ", 1) for line in (checkout / ".venv" / "pyvenv.cfg").read_text().splitlines()
                  if " = " in line)
    assert Path(config["home"]) == SYSTEM_PYTHON.parent, config  # made by the system's python3, not pyenv's
    assert config["include-system-site-packages"] == "false", config


def test_the_environment_imports_the_package_and_loads_the_engine(fresh, tmp_path):
    checkout, run = fresh
    assert run.returncode == 0, run.stderr[-3000:]
    code = ("import ctypes, cam_fmu; from cam_fmu.engine import library; lib = library.load(); "
            "print(cam_fmu.__file__); print(isinstance(lib, ctypes.CDLL), lib._name)")
    # from another folder, isolated (-I): the package comes from the environment, not from the working folder
    proc = subprocess.run([str(checkout / ".venv" / "bin" / "python"), "-I", "-c", code], cwd=tmp_path,
                          env=_env(SYSTEM_PATH), capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    package, loaded = proc.stdout.splitlines()[-2:]
    assert Path(package).is_relative_to(checkout), package  # this clone's package (editable install)
    ok, name = loaded.split(" ", 1)
    assert ok == "True" and Path(name).is_file() and Path(name).is_relative_to(checkout), loaded
    cli = subprocess.run([str(checkout / ".venv" / "bin" / "cam-fmu"), "--help"], cwd=tmp_path,
                         env=_env(SYSTEM_PATH), capture_output=True, text=True, timeout=600)
    assert cli.returncode == 0 and "simulate" in cli.stdout, cli.stderr[-2000:]


def test_a_second_run_changes_nothing(fresh):
    checkout, run = fresh
    assert run.returncode == 0, run.stderr[-3000:]
    before = _snapshot(checkout)
    again = _setup(checkout)
    assert again.returncode == 0, again.stderr[-3000:]
    after = _snapshot(checkout)
    changed = sorted(k for k in before.keys() | after.keys() if before.get(k) != after.get(k))
    assert not changed, changed[:20]
    assert "made the virtual environment" in run.stdout and "made the virtual environment" not in again.stdout


def test_an_older_python3_is_refused(tmp_path):
    if not OLD_PYTHON.is_file():
        pytest.fail(f"{OLD_PYTHON} is missing: this test needs a CPython older than 3.10 (pyenv's 3.9 here)")
    shim = tmp_path / "bin"
    shim.mkdir()
    (shim / "python3").symlink_to(OLD_PYTHON)
    checkout = _clone(tmp_path / "cam_fmu")
    run = _setup(checkout, f"{shim}:{SYSTEM_PATH}")
    assert run.returncode != 0, run.stdout[-2000:]
    assert "Python 3.9" in run.stderr and "3.10 or newer" in run.stderr, run.stderr
    assert not (checkout / ".venv").exists()


def test_a_python3_without_venv_gets_python3_venv_from_apt(tmp_path):
    """Debian's python3 without python3-venv: `python3 -m venv` fails, setup.sh installs python3-venv with apt
    and tries again. Here both are stand-ins (first on PATH): a python3 whose venv always fails and an apt-get
    that records its arguments, so setup.sh ends with its error after the one apt call and leaves no .venv."""
    if not SYSTEM_PYTHON.is_file():
        pytest.fail(f"{SYSTEM_PYTHON} is missing: this test needs the system's python3")
    shim, log = tmp_path / "bin", tmp_path / "apt.log"
    shim.mkdir()
    (shim / "python3").write_text('#!/bin/sh\nif [ "$1" = -m ] && [ "$2" = venv ]; then\n'
                                  '  echo "ensurepip is not available" >&2; exit 1\nfi\n'
                                  f'exec {SYSTEM_PYTHON} "$@"\n')
    (shim / "apt-get").write_text(f'#!/bin/sh\necho "$@" >> {log}\n')
    for tool in ("python3", "apt-get"):
        (shim / tool).chmod(0o755)
    checkout = _clone(tmp_path / "cam_fmu")
    run = _setup(checkout, f"{shim}:{SYSTEM_PATH}")
    assert run.returncode != 0, run.stdout[-2000:]
    assert log.read_text().splitlines() == ["update", "install -y python3-venv"], log.read_text()
    assert "failed even with python3-venv installed" in run.stderr, run.stderr
    assert not (checkout / ".venv").exists()
