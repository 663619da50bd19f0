"""The shipped closed loops (models/speed_loop.ssp, models/compliant_loop.ssp) run where there is no Python:
a co-simulation master written in C (tests/native_host/loop_host.c) loads cam's and pi_speed's binaries from
the SSP, with an empty environment: on x86_64 Linux, on aarch64 Linux under qemu-user and as a Windows
program under wine.

- x86_64 Linux: the C master gives the project's master (experiments.cosim, fmpy) to the bit: the same
  binaries, the same calls in the same order.
- aarch64 Linux and x86_64 Windows (other C libraries, another libm) agree to 1e-12 of each signal's range.
Every tool (gcc, zig, qemu-user-static with libc6-arm64-cross, wine) is required: a missing one fails.
"""
from __future__ import annotations

import os
import subprocess
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest

from cam_fmu.engine import targets
from cam_fmu.engine.build import fmi_headers
from cam_fmu.experiments.cosim import simulate_system
from cam_fmu.fmu.build import ensure_ssp
from cam_fmu.fmu.ssp import read_ssp
from native_support import require, runner, zig_host

HERE = Path(__file__).resolve().parents[1]
LOOP_HOST = HERE / "native_host" / "loop_host.c"
OTHERS = ("aarch64-linux", "x86_64-windows")  # the targets run here besides this machine's


@pytest.fixture(scope="module")
def hosts(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("loop_host")
    linux = folder / "loop_host"
    proc = subprocess.run([require("gcc"), "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", f"-I{fmi_headers()}",
                           str(LOOP_HOST), "-o", str(linux), "-ldl"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    built = {"x86_64-linux": linux}
    for name in OTHERS:
        runner(name)  # the tool that runs it is there, else the test fails
        built[name] = zig_host(name, folder / f"loop_host_{name}{'.exe' if 'windows' in name else ''}", LOOP_HOST)
    return built


def _loop(name: str, folder: Path):
    """The SSP's system, its FMUs unpacked, and the C master's arguments: guids, parameters, connections."""
    ssp = ensure_ssp(name)
    system = read_ssp(ssp)
    with zipfile.ZipFile(ssp) as z:
        z.extractall(folder / "ssp")
    components = list(system.components)
    assert components == ["cam", "controller"]
    info = {}
    for comp in components:
        unpacked = folder / comp
        with zipfile.ZipFile(folder / "ssp" / system.components[comp].source) as z:
            z.extractall(unpacked)
        root = ET.parse(unpacked / "modelDescription.xml").getroot()
        variables = {sv.get("name"): sv for sv in root.iter("ScalarVariable")}
        info[comp] = (unpacked, root.get("guid"), variables, root.find("CoSimulation").get("modelIdentifier"))
    items = []
    for letter, comp in zip("AB", components):
        variables = info[comp][2]
        for pname, value in system.components[comp].parameters.items():
            sv = variables[pname]
            if sv.find("Real") is None:  # the C master sets Reals only: any other value must be the default
                start = next(iter(sv)).get("start")
                assert str(value).lower() == str(start).lower(), (comp, pname, value, start)
                continue
            items.append(f"p{letter}:{sv.get('valueReference')}={float(value)!r}")
    letter = dict(zip(components, "AB"))
    for c in system.connections:
        out = info[c.start_element][2][c.start_connector].get("valueReference")
        into = info[c.end_element][2][c.end_connector].get("valueReference")
        items.append(f"w{letter[c.start_element]}:{out}>{letter[c.end_element]}:{into}")
    return system, info, items


def _run_loop(host: Path, system, info, items, target: str) -> np.ndarray:
    row = targets.get(target)
    args = []
    for comp in ("cam", "controller"):
        folder, guid, _vars, identifier = info[comp]
        args += [str(folder / "binaries" / row.fmi2 / f"{identifier}{row.suffix}"), guid]
    cmd = [*runner(target), str(host), *args, repr(system.stop_time), repr(system.step_size), *items]
    env = {"PATH": "/usr/bin:/bin"}
    if row.runs == "wine":
        env = {**env, "WINEDEBUG": "-all", "HOME": os.environ.get("HOME", "/root")}
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=900)
    lines = proc.stdout.splitlines()
    assert proc.returncode == 0 and lines and lines[-1] == "status OK", proc.stdout[-1500:] + proc.stderr[-1500:]
    return np.array([[float(x) for x in line.split()] for line in lines[:-1]])


@pytest.mark.parametrize("name", ["speed_loop", "compliant_loop"])
def test_the_loop_runs_with_no_python_as_the_project_master_does(hosts, name, tmp_path):
    system, info, items = _loop(name, tmp_path)
    master = simulate_system(system)
    columns = [f"{c.start_element}.{c.start_connector}" for c in system.connections]
    expected = np.column_stack([master["time"], *(master[c] for c in columns)])
    linux = _run_loop(hosts["x86_64-linux"], system, info, items, "x86_64-linux")
    assert linux.shape == expected.shape
    assert np.array_equal(linux, expected), float(np.max(np.abs(linux - expected)))
    span = np.ptp(expected[:, 1:], axis=0) + 1e-300
    for name in OTHERS:
        other = _run_loop(hosts[name], system, info, items, name)
        assert other.shape == expected.shape and np.array_equal(other[:, 0], expected[:, 0])
        worst = float(np.max(np.abs(other[:, 1:] - expected[:, 1:]) / span))
        assert worst <= 1e-12, f"{name} differs from x86_64-linux by {worst:.3g} of a signal's range"
    # the loop did its job: the cam's speed settles near the setpoint in the second half
    omega = expected[len(expected) // 2:, 1 + columns.index("cam.omega")]
    setpoint = float(system.components["controller"].parameters.get("omega_set", 5.0))
    assert abs(omega.mean() - setpoint) < 0.1 * abs(setpoint)
