"""cam3.fmu, the FMI 3.0 co-simulation FMU: fmpy's validation, its CLI, bit-for-bit agreement with cam.fmu (FMI
2.0) on every shipped scene, FMU states, and the refusals an FMI 3.0 host sees (fmpy's FMU3Slave call by call).
Same engine, same instance layer and glue rules: only csrc/fmi/fmi3_cs.c and the model description differ."""
from __future__ import annotations

import os
import shutil
import re
from pathlib import Path
import subprocess
import sys
import zipfile

from ctypes import POINTER, byref, c_bool, c_double, c_int, c_void_p

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu

from cam_fmu.experiments.runner import input_table
from cam_fmu.experiments.scenes import find_scene, scene_names
from cam_fmu.physics.variables import OUTPUT_NAMES


@pytest.fixture(scope="module")
def cam3(cam3_fmu_path):
    return cam3_fmu_path  # the session's build (conftest.py)


@pytest.fixture(scope="module")
def unzipped(cam3, tmp_path_factory):
    folder = tmp_path_factory.mktemp("cam3_unzipped")
    with zipfile.ZipFile(cam3) as z:
        z.extractall(folder)
    return folder


def test_fmpy_validates_it_and_reads_an_fmi3_co_simulation_fmu(cam3):
    assert validate_fmu(str(cam3)) == []
    md = read_model_description(str(cam3))
    assert md.fmiVersion == "3.0" and md.coSimulation.modelIdentifier == "cam" and md.modelExchange is not None
    # its Model Exchange: tests/fmi3/test_fmi3_me.py
    names = {v.name: v for v in md.modelVariables}
    assert set(OUTPUT_NAMES) <= set(names) and names["time"].causality == "independent"
    assert names["omega"].unit == "rad/s" and names["omega"].displayUnit == "rpm"
    with zipfile.ZipFile(cam3) as z:
        assert {"binaries/x86_64-linux/cam.so", "binaries/x86_64-windows/cam.dll", "binaries/aarch64-linux/cam.so",
                "binaries/x86_64-darwin/cam.dylib", "binaries/aarch64-darwin/cam.dylib"} <= set(z.namelist())


def test_the_fmpy_command_line_simulates_it(cam3, tmp_path):
    out = tmp_path / "cam3.csv"
    done = subprocess.run([sys.executable, "-m", "fmpy.command_line", "simulate", str(cam3), "--output-file",
                           str(out), "--output-variables", "theta", "omega"], capture_output=True, text=True)
    if done.returncode != 0:  # fmpy's console entry point, where the module has no __main__
        done = subprocess.run([shutil.which("fmpy"), "simulate", str(cam3), "--output-file", str(out),
                               "--output-variables", "theta", "omega"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    rows = np.genfromtxt(out, delimiter=",", names=True)
    assert rows["time"][-1] == pytest.approx(2.0) and 13.0 < rows["theta"][-1] < 13.5  # fig. 6: 2.1 turns


@pytest.mark.parametrize("name", scene_names())
def test_it_agrees_with_cam_fmu_bit_for_bit_on_every_shipped_scene(cam3, engine_fmu_path, name):
    scene = find_scene(name)
    for run in scene.runs:
        start = run.start_values()
        kwargs = dict(stop_time=min(scene.stop_time, 0.5), output_interval=scene.output_interval,
                      start_values=start, input=input_table(scene), output=list(OUTPUT_NAMES))
        three = simulate_fmu(str(cam3), **kwargs)
        two = simulate_fmu(str(engine_fmu_path), **kwargs)
        assert len(three) == len(two) > 10
        for column in OUTPUT_NAMES:
            assert np.array_equal(three[column], two[column]), (name, run.label, column)


class Host:
    """An FMI 3.0 host call by call (fmpy's FMU3Slave), collecting the log."""

    def __init__(self, unzipped, token=None, logging=False):
        self.md = read_model_description(str(unzipped))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.log = []
        self.fmu = FMU3Slave(guid=token or self.md.guid, unzipDirectory=str(unzipped),
                             modelIdentifier="cam", instanceName="cam3")
        self.fmu.instantiate(loggingOn=logging, logMessage=self._log)

    def _log(self, env, status, category, message):
        self.log.append((status, message.decode()))

    def start(self, **floats):
        if floats:
            self.fmu.setFloat64([self.vr[k] for k in floats], list(floats.values()))
        self.fmu.enterInitializationMode(startTime=0.0)
        self.fmu.exitInitializationMode()

    def get(self, *names):
        return self.fmu.getFloat64([self.vr[n] for n in names])


def test_a_state_saved_restored_and_serialised_continues_to_the_bit(unzipped):
    host = Host(unzipped)
    host.start(c=5e-4)
    t = 0.0
    for _ in range(300):
        host.fmu.doStep(t, 1e-3)
        t += 1e-3
    saved = host.fmu.getFMUState()
    blob = host.fmu.serializeFMUState(saved)
    for _ in range(300):
        host.fmu.doStep(t + _ * 1e-3, 1e-3)
    first = host.get("theta", "omega", "s")
    for state in (saved, host.fmu.deserializeFMUState(blob)):
        host.fmu.setFMUState(state)
        for k in range(300):
            host.fmu.doStep(t + k * 1e-3, 1e-3)
        assert host.get("theta", "omega", "s") == first
    assert host.get("time") == [pytest.approx(0.6)]
    host.fmu.freeFMUState(saved)
    host.fmu.terminate()
    host.fmu.freeInstance()


def test_lift_off_and_touch_down_are_log_lines_not_a_status(unzipped):
    """A spring-closed follower above its jump speed (docs/model.md section 13): each lift-off and touch-down is a
    logEvents line with status OK, the touch-down's relative speeds halved by restitution 0.5."""
    host = Host(unzipped, logging=True)
    host.fmu.setString([host.vr["drive"], host.vr["closure"]], ["speed", "spring"])
    host.fmu.setFloat64([host.vr[k] for k in ("k_spring", "F_spring0", "restitution", "omega_ref")],
                        [800.0, 20.0, 0.5, 60.0])
    host.start()
    for k in range(1100):
        host.fmu.doStep(k * 1e-4, 1e-4)
    lines = [m for status, m in host.log if "follower:" in m]
    assert all(status == 0 for status, m in host.log)  # fmi3OK: a log line, not a status change
    assert any("lift-off from flank +1" in m for m in lines) and sum(m.count("touch-down") for m in lines) >= 10
    first = next(m for m in lines if "touch-down" in m)
    before, after = map(float, re.search(r"relative speed (\S+) m/s, after (\S+) m/s", first).groups())
    assert before < 0.0 and after == pytest.approx(-0.5 * before, rel=1e-5)  # printed to 6 digits
    host.fmu.terminate()
    host.fmu.freeInstance()


def test_refusals_are_fmi3_errors_that_name_their_cause_and_change_nothing(unzipped):
    host = Host(unzipped)
    with pytest.raises(FMICallException):
        host.fmu.setFloat64([host.vr["R"]], [0.0])
    assert any("parameter 'R' = 0.0 [Ohm] is outside the allowed range" in m for _, m in host.log)
    with pytest.raises(FMICallException):
        host.fmu.doStep(0.0, 1e-3)  # before initialisation
    assert any("fmi3DoStep: not allowed in state 'instantiated'" in m for _, m in host.log)
    host.start()
    assert host.get("R") == [19.0]
    with pytest.raises(FMICallException):
        host.fmu.enterEventMode()
    assert any("without event mode" in m for _, m in host.log)
    host.fmu.freeInstance()


def test_a_wrong_instantiation_token_is_refused(unzipped):
    log = []
    fmu = FMU3Slave(guid="{00000000-0000-0000-0000-000000000000}", unzipDirectory=str(unzipped),
                    modelIdentifier="cam", instanceName="cam3")
    with pytest.raises(Exception, match="instantiate"):
        fmu.instantiate(logMessage=lambda env, status, category, message: log.append(message.decode()))
    assert any("instantiationToken '{00000000-0000-0000-0000-000000000000}' is not this binary's" in m for m in log)


def test_a_step_the_solver_cannot_complete_is_discarded_with_the_last_successful_time(unzipped):
    host = Host(unzipped)
    host.start(h_max=1e-6, max_steps=10.0)
    event, terminate, early, last = c_bool(), c_bool(), c_bool(), c_double(-1.0)
    do_step = host.fmu.dll.fmi3DoStep  # the bare function: fmpy's wrapper raises on Discard and drops the out-arguments
    do_step.argtypes = [c_void_p, c_double, c_double, c_bool, POINTER(c_bool), POINTER(c_bool), POINTER(c_bool),
                        POINTER(c_double)]
    do_step.restype = c_int
    status = do_step(host.fmu.component, 0.0, 1e-3, True, byref(event), byref(terminate), byref(early), byref(last))
    assert status == 2 and last.value == 0.0 and not terminate.value and not early.value  # fmi3Discard
    assert any("max_steps" in m and "h_max" in m for _, m in host.log)
    assert host.get("theta") == [0.0]
    host.fmu.freeInstance()


def test_a_c_host_runs_it_clean_under_valgrind(cam3, unzipped, tmp_path):
    """tests/native_host/host3.c (gcc and valgrind are required tools): instance cycles with a parameter, steps,
    FMU states serialised and restored to the bit, refused calls; memcheck finds no error and no leak."""
    from cam_fmu.engine.build import fmi_headers
    from native_support import require, valgrind_prefix, valgrind_summary

    host = tmp_path / "host3"
    source = Path(__file__).resolve().parents[1] / "native_host" / "host3.c"
    done = subprocess.run([require("gcc"), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic",
                           f"-I{fmi_headers(3)}", str(source), "-o", str(host), "-ldl"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    md = read_model_description(str(cam3))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    log = tmp_path / "memcheck.log"
    run = subprocess.run([*valgrind_prefix(log), str(host), str(unzipped / "binaries" / "x86_64-linux" / "cam.so"),
                          md.guid, str(vr["theta"]), str(vr["u"]), str(vr["c"]), "3"],
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    lines = [line for line in run.stdout.splitlines() if not line.startswith("log ")]
    assert lines.count("set-c 0") == lines.count("init 0") == 3
    assert lines.count("serialize 0") == lines.count("deserialize 0") == 3
    assert sum(line.startswith("restored same ") for line in lines) == 3
    assert lines.count("nan-input 3") == lines.count("wrong-time 3") == lines.count("null-get 3") == 3
    assert lines.count("terminate 0 reset 0") == 3
    assert "input 'u' = nan [V] is outside the allowed range" in run.stdout
    summary = valgrind_summary(log)
    assert summary["summaries"] >= 1 and summary["errors"] == 0, summary["excerpt"]
    assert "definitely lost" not in log.read_text() or "definitely lost: 0 bytes" in log.read_text()


def test_the_windows_binary_runs_under_wine_as_the_linux_one_does(cam3, unzipped, tmp_path):
    """host3.c cross-compiled by zig loads binaries/x86_64-windows/cam.dll under wine (both required
    tools): the same statuses as on linux, a state restored to the bit, and theta after 0.2 s with backlash equal
    to the linux binary's to 1e-12 relative (measured: equal to the bit)."""
    from cam_fmu.engine.build import fmi_headers
    from native_support import require, runner, zig_host

    wine = runner("x86_64-windows")[0]
    source = Path(__file__).resolve().parents[1] / "native_host" / "host3.c"
    exe, host = zig_host("x86_64-windows", tmp_path / "host3.exe", source), tmp_path / "host3"
    done = subprocess.run([require("gcc"), "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", f"-I{fmi_headers(3)}",
                           str(source), "-o", str(host), "-ldl"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    md = read_model_description(str(cam3))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    args = [md.guid, str(vr["theta"]), str(vr["u"]), str(vr["c"]), "1"]
    runs = {}
    for platform, cmd in (("windows", [str(wine), str(exe), str(unzipped / "binaries" / "x86_64-windows" / "cam.dll")]),
                          ("linux", [str(host), str(unzipped / "binaries" / "x86_64-linux" / "cam.so")])):
        run = subprocess.run([*cmd, *args], capture_output=True, text=True, timeout=600,
                             env={**os.environ, "WINEDEBUG": "-all"})
        assert run.returncode == 0, (platform, run.stderr[-2000:])
        runs[platform] = [line for line in run.stdout.splitlines() if not line.startswith("log ")]
    assert [line.split()[0] for line in runs["windows"]] == [line.split()[0] for line in runs["linux"]]
    restored = {p: next(line for line in lines if line.startswith("restored ")).split() for p, lines in runs.items()}
    assert restored["windows"][1] == restored["linux"][1] == "same"
    theta_w, theta_l = float.fromhex(restored["windows"][2]), float.fromhex(restored["linux"][2])
    assert theta_l > 0.5 and abs(theta_w - theta_l) <= 1e-12 * theta_l
    for status in ("set-c 0", "init 0", "nan-input 3", "wrong-time 3", "null-get 3", "terminate 0 reset 0"):
        assert status in runs["windows"], status


def test_the_binary_exports_exactly_the_functions_of_fmi3(unzipped):
    """Every function fmi3Functions.h names (an importer may look up any of them), and nothing else."""
    import re

    from cam_fmu.engine.build import fmi_headers

    header = (fmi_headers(3) / "fmi3Functions.h").read_text()
    required = set(re.findall(r"^#define (fmi3\w+) ", header, flags=re.M)) - {"fmi3Version"}
    nm = subprocess.run(["nm", "-D", "--defined-only", str(unzipped / "binaries" / "x86_64-linux" / "cam.so")],
                        capture_output=True, text=True)
    assert nm.returncode == 0, nm.stderr
    exported = {line.split()[-1] for line in nm.stdout.splitlines() if line.strip()}
    assert len(required) == 75 and exported == required


def test_a_sanitized_build_runs_the_c_host_clean(cam3, tmp_path):
    """cam3.fmu's binary and the FMI 3.0 C host built with -fsanitize=address,undefined (gcc required): the same
    instance cycles, states and refusals as under valgrind, with no sanitizer report."""
    from cam_fmu.engine.build import fmi_headers
    from cam_fmu.fmu import engine_fmu
    from native_support import require

    sanitize = ["-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer", "-g"]
    md = read_model_description(str(cam3))
    library = engine_fmu.compile_binary(tmp_path / "cam.so", md.guid, extra_flags=sanitize, fmi_version=3)
    host = tmp_path / "host3"
    source = Path(__file__).resolve().parents[1] / "native_host" / "host3.c"
    done = subprocess.run([require("gcc"), "-std=c99", "-Wall", "-Wextra", "-Werror", *sanitize,
                           f"-I{fmi_headers(3)}", str(source), "-o", str(host), "-ldl"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    vr = {v.name: v.valueReference for v in md.modelVariables}
    run = subprocess.run([str(host), str(library), md.guid, str(vr["theta"]), str(vr["u"]), str(vr["c"]), "3"],
                         capture_output=True, text=True, timeout=600,
                         env={"PATH": "/usr/bin:/bin", "ASAN_OPTIONS": "detect_leaks=1"})
    assert run.returncode == 0, run.stderr[-3000:]
    assert "ERROR: AddressSanitizer" not in run.stderr and "runtime error" not in run.stderr, run.stderr[-3000:]
    assert run.stdout.count("restored same ") == 3 and run.stdout.count("nan-input 3") == 3
