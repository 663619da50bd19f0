"""The quick start as README.md writes it: its two commands use the virtual environment setup.sh makes
(``.venv``), .ci/run runs exactly its test command, every command line of the docs that runs the package's
Python or commands runs the environment's, and a test run finds the commands of the environment it runs in.
The fresh-machine run of setup.sh itself: tests/tools/test_setup_fresh.py."""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "tests" / "README.md",
        ROOT / "models" / "README.md"]
FENCE = re.compile(r"^```([^\n`]*)\n(.*?)^```[ \t]*$", re.M | re.S)
# a command of the package's environment at the start of a command (a line, or after && ; |)
RUNS = re.compile(r"(?:^|&&|;|\|)\s*((?:\S*/)?(?:python3?|cam-fmu|fmpy|pytest))\b")


def _quick_start() -> list[str]:
    """The bash lines of README.md's Quick start section."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = re.search(r"^## Quick start\n(.*?)^## ", text, re.M | re.S).group(1)
    return [line.strip() for lang, body in FENCE.findall(section) if lang.strip() == "bash"
            for line in body.splitlines() if line.strip()]


def test_the_quick_start_is_two_commands_on_the_virtual_environment():
    main, tests = _quick_start()
    for command in (main, tests):
        first, *rest = [part.strip() for part in command.split("&&")]
        assert first == "bash setup.sh", command
        assert rest and all(part.startswith(".venv/bin/") for part in rest), command
    assert "cam-fmu simulate" in main and "build_fmu.py" in main, main
    assert "-m pytest" in tests, tests


def test_ci_runs_exactly_the_readme_test_command():
    run = [line.strip() for line in (ROOT / ".ci" / "run").read_text().splitlines()
           if line.strip() and not line.lstrip().startswith("#")]
    assert run[-1] == _quick_start()[1], run  # the last command of .ci/run, after its set -e and cd


def test_every_command_line_of_the_docs_runs_the_environment():
    """In the docs' shell blocks, every python, cam-fmu, fmpy or pytest a line runs is .venv/bin's."""
    wrong = []
    for path in DOCS:
        for lang, body in FENCE.findall(path.read_text(encoding="utf-8")):
            if lang.strip() not in ("bash", "sh", "console", "shell"):
                continue
            for line in body.splitlines():
                code = line.split(" #", 1)[0]
                wrong += [f"{path.relative_to(ROOT)}: {line.strip()}" for command in RUNS.findall(code)
                          if not command.startswith(".venv/bin/")]
    assert not wrong, "\n".join(wrong)


def test_the_command_check_sees_a_bare_command():
    """The check above is not vacuous: it catches a bare command after && and at a line's start."""
    assert [c for c in RUNS.findall("bash setup.sh && python -m pytest -q") if not c.startswith(".venv/bin/")]
    assert RUNS.findall("cam-fmu bench --quick") == ["cam-fmu"]
    assert RUNS.findall(".venv/bin/cam-fmu bench") == [".venv/bin/cam-fmu"]


def test_a_test_run_finds_the_commands_of_its_own_environment():
    """`.venv/bin/python -m pytest` with a PATH without .venv/bin: conftest.py puts the directory of
    sys.executable (where the environment's console scripts are) first on PATH, so the tests and their
    children run this environment's cam-fmu and fmpy, not another installation's."""
    here = Path(sys.executable).parent
    for name in ("cam-fmu", "fmpy"):
        found = shutil.which(name)
        assert found and Path(found).parent == here, (name, found, here)
    child = subprocess.run(["sh", "-c", "command -v cam-fmu"], capture_output=True, text=True, timeout=60)
    assert Path(child.stdout.strip()).parent == here, child.stdout  # children inherit it
