"""The engine built with AddressSanitizer and UndefinedBehaviorSanitizer, run by a C host (no Python in
the process: ASan and CPython do not mix): scenes, state round trips and error paths run clean and give
the bits of the ordinary build; and the ordinary build under valgrind shows no error and no leak."""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from cam_fmu.engine import build, codegen
from cam_fmu.engine.simulator import DriveSimulator

HOST = build.CSRC / "hosts" / "scene_host.c"
SANITIZE = ("-fsanitize=address,undefined", "-fno-omit-frame-pointer", "-fno-sanitize-recover=all", "-g")


def _host(tmp_path: Path, flags: tuple[str, ...]) -> Path:
    """The C host linked against the engine library built with ``flags``."""
    lib = build.build(flags)
    gen = tmp_path / "gen"
    codegen.write(gen)
    exe = tmp_path / "scene_host"
    cmd = [build.find_compiler(), *build.CFLAGS, *flags, f"-I{build.INCLUDE}", f"-I{gen}", str(HOST), str(lib),
           f"-Wl,-rpath,{lib.parent}", "-o", str(exe), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return exe


def _lines(stdout: str) -> dict[str, list[str]]:
    return {line.split(" ", 1)[0]: line.split(" ")[1:] for line in stdout.splitlines()}


def _python_line(params: dict, steps: int) -> list[str]:
    sim = DriveSimulator(params)
    for k in range(steps):
        sim.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
    out = sim.outputs()
    return ["0", out["theta"].hex(), out["omega"].hex(), str(sim.steps_taken)]


def _same(c_line: list[str], python_line: list[str]) -> bool:
    """A host line and a Python line: the same status, the same bits of theta and omega, the same steps
    (C's %a and Python's float.hex spell some numbers differently: compared as numbers)."""
    return (c_line[0] == python_line[0] and c_line[3] == python_line[3]
            and all(float.fromhex(a) == float.fromhex(b) for a, b in zip(c_line[1:3], python_line[1:3])))


def _check(lines: dict[str, list[str]]) -> None:
    for name in ("fig6", "backlash", "inductance", "tilted", "table", "paper", "speed", "euler", "rk4", "etdrk4",
                 "stiff-pole", "compliant", "compliant-backlash", "stick-slip"):
        assert lines[name][0] == "0", (name, lines[name])
        assert lines[f"{name}-resumed"] == ["0", "same"], name
    assert _same(lines["fig6"], _python_line({}, 2000))
    assert _same(lines["backlash"], _python_line({"c": 5e-4}, 2000))
    assert _same(lines["paper"], _python_line({"formulation": "paper"}, 2000))
    assert _same(lines["etdrk4"], _python_line({"c": 5e-4, "solver": "etdrk4", "h_max": 1e-4, "L": 1e-3,
                                                   "closure": "kinematic"}, 1000))
    shaft = {"J_m": 3e-5, "J_cam": 1.41e-5, "k_shaft": 50.0, "d_shaft": 1e-3}
    assert _same(lines["compliant"], _python_line(shaft, 2000))
    stick_slip = {"J_m": 3e-5, "J_cam": 1.41e-5, "k_shaft": 0.5, "M_f": 0.02, "follower_inertia": False,
                  "gravity": False, "guide_friction": False}
    sim = DriveSimulator(stick_slip)
    for k in range(600):
        sim.do_step(k * 1e-3, 1e-3, 2.9, 1.0)
    assert [float.fromhex(v) for v in lines["stick-slip"][1:3]] == [sim.outputs()["theta"], sim.outputs()["omega"]]
    expected = {"no-J_cam": "1", "bad-table": "1", "bad-R": "1", "unknown": "1", "bad-solver": "1", "max-steps": "3",
                "bad-step": "2", "bad-input": "2", "bad-state": "2", "bad-contact": "2", "bad-nan": "2"}
    assert {name: lines[name][0] for name in expected} == expected
    assert " ".join(lines["bad-R"][1:]) == "parameter 'R' = 0.0 [Ohm] is outside the allowed range [0.001, 10000] Ohm"
    assert " ".join(lines["bad-nan"][1:]) == "state entry 9 = nan is not finite"


def test_address_and_undefined_behaviour_sanitizers_are_clean(tmp_path):
    proc = subprocess.run([str(_host(tmp_path, SANITIZE))], capture_output=True, text=True,
                          env={"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0",
                               "UBSAN_OPTIONS": "print_stacktrace=1"})
    assert proc.returncode == 0 and "runtime error" not in proc.stderr and "Sanitizer" not in proc.stderr, \
        proc.stderr[-3000:]
    _check(_lines(proc.stdout))


def test_valgrind_shows_no_error_and_no_leak(tmp_path):
    valgrind = shutil.which("valgrind")
    assert valgrind, "valgrind is not installed (setup.sh installs it)"
    exe = _host(tmp_path, ("-g",))
    proc = subprocess.run([valgrind, "--error-exitcode=9", "--leak-check=full", "--errors-for-leak-kinds=all",
                           str(exe)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "All heap blocks were freed" in proc.stderr and "ERROR SUMMARY: 0 errors" in proc.stderr
    _check(_lines(proc.stdout))


def test_the_check_fails_on_one_bit(tmp_path):
    """The comparison with the Python binding is exact: one output bit off fails it."""
    lines = _lines(subprocess.run([str(_host(tmp_path, ()))], capture_output=True, text=True).stdout)
    _check(lines)
    theta = float.fromhex(lines["fig6"][1])
    lines["fig6"][1] = (theta + abs(theta) * 2.0 ** -52).hex()
    with pytest.raises(AssertionError):
        _check(lines)
