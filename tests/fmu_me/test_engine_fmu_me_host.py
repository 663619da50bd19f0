"""A Model Exchange host in C (tests/engine_c/me_host.c: fixed-step explicit Euler with event handling)
linked with cam.fmu's FMI 2.0 functions, built with AddressSanitizer and UBSan and run under valgrind:
no report, the same trajectory as fmpy's Euler, the refusals fmi2Error. gcc and valgrind are required."""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import fmpy
import pytest

from cam_fmu.engine import build as engine_build
from cam_fmu.engine import codegen
from cam_fmu.fmu.engine_fmu import binary_sources
from cam_fmu.fmu.model_description import variable_rows
from native_support import require, valgrind_prefix, valgrind_summary

HOST = Path(__file__).resolve().parents[1] / "engine_c" / "me_host.c"
FLAGS = ["-std=c99", "-O1", "-g", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror", "-pedantic"]
SANITIZE = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]
GUID = "me-host-test"
VR = {row["name"]: k for k, row in enumerate(variable_rows())}
# the paper's rule (closure 'kinematic'): Model Exchange has no event indicators for a free follower yet
BACKLASH = [f"{VR['backlash']}=true", f"{VR['c']}=0.0005", f"{VR['gamma']}=3.141592653589793",
            f"{VR['closure']}=s:kinematic"]
STEP, STOP = 1e-4, 0.8  # s: two impacts and a separation (backlash scene)
# the compliant shaft, well damped (damping ratio about 0.2, so that explicit Euler at 1e-5 s is stable),
# with an inductance: all five states move
COMPLIANT = [f"{VR['k_shaft']}=50", f"{VR['d_shaft']}=0.01", f"{VR['J_cam']}=1.41e-5", f"{VR['J_m']}=3e-5",
             f"{VR['inductance']}=true", f"{VR['L']}=0.001", f"{VR['gamma']}=3.141592653589793"]


def compile_host(folder: Path, extra: list[str]) -> Path:
    gcc = require("gcc")
    generated = [str(p) for p in codegen.write(folder / "gen") if p.suffix == ".c"]
    exe = folder / "me_host"
    cmd = [gcc, *FLAGS, *extra, f'-DMODEL_GUID="{GUID}"', f"-I{engine_build.INCLUDE}", f"-I{folder / 'gen'}",
           f"-I{engine_build.fmi_headers()}", *generated,
           *map(str, binary_sources("cam", 2)), str(HOST), "-o", str(exe), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return exe


def run(exe: Path, prefix: list[str] = (), params: list[str] = BACKLASH, step: float = STEP,
        stop: float = STOP) -> dict:
    env = {"PATH": "/usr/bin:/bin", "CAM_FORMULATION_VR": str(VR["formulation"]),
           "ASAN_OPTIONS": "detect_leaks=1", "UBSAN_OPTIONS": "print_stacktrace=1"}
    proc = subprocess.run([*prefix, str(exe), GUID, str(step), str(stop), *params], capture_output=True,
                          text=True, timeout=600, env=env)
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr[-3000:]
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    lines = {line.split()[0]: line.split()[1:] for line in proc.stdout.splitlines()}
    return {"events": int(lines["events"][0]), "final": [float(v) for v in lines["final"]],
            "refused": [int(v) for v in lines["refused"]], "paper": int(lines["paper"][0]), "out": proc.stdout}


@pytest.fixture(scope="module")
def sanitized(tmp_path_factory) -> dict:
    return run(compile_host(tmp_path_factory.mktemp("me_asan"), SANITIZE))


def test_euler_with_events_is_clean_under_asan_and_ubsan(sanitized):
    assert sanitized["events"] >= 3  # engage_up, contact, engage_down (and side-force flips)
    assert sanitized["refused"] == [3, 3, 3, 3]  # wrong count, NULL eventInfo, fmi2DoStep, NaN time
    assert sanitized["paper"] == 3
    assert "fmi2ExitInitializationMode: formulation 'paper'" in sanitized["out"]


def test_the_compliant_drive_with_an_inductance_is_clean_under_asan_and_ubsan(tmp_path):
    result = run(compile_host(tmp_path, SANITIZE), params=COMPLIANT, step=1e-5, stop=0.1)
    t, theta, omega, i = result["final"]
    assert t == pytest.approx(0.1, rel=1e-12) and theta > 0.1 and omega > 1.0 and i > 0.0
    assert result["refused"] == [3, 3, 3, 3] and result["paper"] == 3


def test_the_c_host_follows_fmpys_euler(sanitized, engine_fmu_path):
    """Two hosts of the same scheme: fmpy's ForwardEuler on the packed FMU, this C host on the sources."""
    result = fmpy.simulate_fmu(str(engine_fmu_path), fmi_type="ModelExchange", solver="Euler", step_size=STEP,
                               output_interval=STEP, stop_time=STOP,
                               start_values={"backlash": True, "c": 5e-4, "gamma": 3.141592653589793,
                                             "closure": "kinematic"})
    t, theta, omega, _ = sanitized["final"]
    assert t == pytest.approx(STOP, rel=1e-12)
    assert theta == pytest.approx(result["theta"][-1], rel=1e-9)
    assert omega == pytest.approx(result["omega"][-1], rel=1e-6)


def test_valgrind_finds_no_error(tmp_path):
    exe = compile_host(tmp_path, [])
    log = tmp_path / "memcheck.log"
    result = run(exe, valgrind_prefix(log))
    summary = valgrind_summary(log)
    assert summary["summaries"] >= 1
    assert summary["errors"] == 0, summary["excerpt"]
    assert "definitely lost: 0 bytes" in log.read_text() or "definitely lost" not in log.read_text()
    assert result["events"] >= 3
    assert os.path.getsize(log) > 0


def _follower_params() -> tuple[dict, list[str]]:
    """spring_voltage (the follower of its own, e = 0.5) as start values and as the C host's vr=value arguments."""
    from cam_fmu.experiments.scenes import find_scene
    scene = find_scene("spring_voltage")
    start = dict(next(r for r in scene.runs if r.label == "e_0.5").start_values(), u=scene.u.value(0.0))
    text = {True: "true", False: "false"}
    return start, [f"{VR[k]}={text[v] if isinstance(v, bool) else v}" for k, v in start.items()]


def test_the_follower_of_its_own_is_clean_under_asan_and_ubsan_and_follows_fmpys_euler(tmp_path, engine_fmu_path):
    """The C host's Euler at 2e-6 s through the lift-off and three bounces of spring_voltage (closure 'spring'), under
    ASan/UBSan, with a saved state in flight's run: the same final theta and omega as fmpy's Euler on the packed FMU."""
    start, params = _follower_params()
    step, stop = 2e-6, 0.06
    result = run(compile_host(tmp_path, SANITIZE), params=params, step=step, stop=stop)
    euler = fmpy.simulate_fmu(str(engine_fmu_path), fmi_type="ModelExchange", solver="Euler", step_size=step,
                              output_interval=step, stop_time=stop, start_values=start)
    t, theta, omega, _ = result["final"]
    assert t == pytest.approx(stop, rel=1e-12)
    assert result["events"] >= 4  # the lift-off and three touch-downs (and the profile's breakpoints)
    assert theta == pytest.approx(euler["theta"][-1], rel=1e-9)
    assert omega == pytest.approx(euler["omega"][-1], rel=1e-6)
    assert result["refused"] == [3, 3, 3, 3]
