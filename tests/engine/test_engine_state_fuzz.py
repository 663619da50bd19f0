"""Saved states are untrusted bytes: the instance layer's restore under AddressSanitizer and UBSan.

tests/engine_c/state_driver.c runs the libFuzzer entry cam_fmu/engine/csrc/fuzz/fuzz_state.c
(its promises: a refused state has a message and changes nothing; a restored state steps to
finite outputs or is refused with a message) on the saved states of three drives and on a
fixed-seed run of their mutations (bit flips, random bytes, special doubles, truncation,
extension). Any sanitizer report or broken promise fails the test; gcc is a required tool.
"""
from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from cam_fmu.engine import codegen
from cam_fmu.engine.build import CSRC, INCLUDE, SOURCES
from native_support import require

DRIVER = Path(__file__).resolve().parents[1] / "engine_c" / "state_driver.c"
FLAGS = ["-std=c99", "-O1", "-g", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror", "-pedantic",
         "-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]


def _build(dest: Path, instance: Path = CSRC / "fmi" / "instance.c") -> Path:
    """The driver with the engine, the generated table and ``instance`` (the instance layer's source)."""
    gcc = require("gcc")
    generated = codegen.write(dest.parent / "generated")
    cmd = [gcc, *FLAGS, f"-I{INCLUDE}", f"-I{dest.parent / 'generated'}",
           *sorted(str(p) for p in SOURCES.glob("*.c")), *(str(p) for p in generated if p.suffix == ".c"),
           str(instance), str(CSRC / "fuzz" / "fuzz_state.c"), str(DRIVER), "-o", str(dest), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return dest


@pytest.fixture(scope="module")
def driver(tmp_path_factory):
    return _build(tmp_path_factory.mktemp("state_fuzz") / "state_driver")


def _run(exe: Path, *args) -> subprocess.CompletedProcess:
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=600,
                          env={"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0", "UBSAN_OPTIONS": "print_stacktrace=1"})


def test_mutated_saved_states_are_refused_or_restored_cleanly(driver):
    proc = _run(driver, "-n", 3000, "-s", 7)
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr[-3000:]
    assert proc.returncode == 0 and proc.stdout.strip() == "ok 3000", proc.stderr[-3000:]


def test_the_driver_catches_a_restore_that_trusts_its_bytes(tmp_path):
    """The same run against an instance layer whose restore skips its size check must fail: the
    driver reaches the checks it is there to test."""
    source = (CSRC / "fmi" / "instance.c").read_text()
    check = "if (initialized > 1 || n != size - HEADER_BYTES - 8 * FIXED_DOUBLES)"
    assert check in source
    broken = tmp_path / "fmi"
    broken.mkdir()
    (broken / "instance.c").write_text(source.replace(check, "if (initialized > 1)"))
    proc = _run(_build(tmp_path / "broken_driver", broken / "instance.c"), "-n", 3000, "-s", 7)
    assert proc.returncode != 0 and ("Sanitizer" in proc.stderr or "runtime error" in proc.stderr)
