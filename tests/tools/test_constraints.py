"""The test environment is locked: setup.sh installs the test extra with constraints/test.txt, which pins
every dependency of the package and of its test extra to one version inside pyproject.toml's ranges."""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[2]
LOCK = ROOT / "constraints" / "test.txt"


def pins() -> dict[str, str]:
    out = {}
    for line in LOCK.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            name, sep, version = line.partition("==")
            assert sep and version, f"constraints/test.txt: {line!r} is not NAME==VERSION"
            out[canonicalize_name(name)] = version
    return out


def test_setup_installs_the_tests_with_the_lock():
    setup = (ROOT / "setup.sh").read_text()
    installs = [line for line in setup.splitlines() if re.search(r"pip install .*-e", line)]
    assert installs and all("-c constraints/test.txt" in line for line in installs), installs
    assert (ROOT / "constraints" / "refresh.sh").is_file()


def test_every_dependency_is_pinned_inside_its_range():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    required = [Requirement(r) for r in project["dependencies"] + project["optional-dependencies"]["test"]]
    locked = pins()
    assert "cam-fmu" not in locked, "the lock pins the project's dependencies, not the project"
    for req in required:
        if req.marker is not None and not req.marker.evaluate():
            continue  # a dependency of other Pythons only (tomli before 3.11): the lock is this Python's
        name = canonicalize_name(req.name)
        assert name in locked, f"{req.name} is not pinned in constraints/test.txt"
        assert req.specifier.contains(locked[name], prereleases=True), (req, locked[name])
    # extras' own dependencies are pinned too (dask[distributed] -> distributed)
    assert "distributed" in locked
    # pyproject keeps ranges: only the pins that docs/fmu.md explains are exact there
    exact = sorted(canonicalize_name(r.name) for r in required if any(s.operator == "==" for s in r.specifier))
    assert exact == ["ecospy", "fmpy", "libcosimpy", "pythonfmu"], exact
