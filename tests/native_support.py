"""Helpers for the tests of the Python-hosting linux64 binary (pi_speed.fmu; tests/test_native_*.py) and of
the C hosts.

Tools that CI installs (gcc, valgrind, ecos + libtbb12, libcosimpy) are required:
a missing one FAILS the test, it never skips.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path
from typing import Dict, List, Optional, Sequence
from xml.etree import ElementTree as ET

import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
HOST_C = HERE / "native_host" / "host.c"
SUPPRESSIONS = HERE / "native_host" / "valgrind.supp"
EMPTY_ENV = {"PATH": "/usr/bin:/bin"}  # what `env -i PATH=/usr/bin:/bin` leaves


def require(tool: str) -> str:
    path = shutil.which(tool)
    if not path:
        pytest.fail(f"{tool} is not installed: CI installs it (./setup.sh); the native-host tests need it")
    return path


def ecos_path() -> Path:
    try:
        import ecospy
    except ImportError:
        pytest.fail("ecospy is not installed (pip install -e '.[test]')")
    exe = Path(ecospy.__file__).parent / "binaries" / "ecos"
    if not exe.is_file():
        pytest.fail(f"no ecos binary at {exe}")
    exe.chmod(exe.stat().st_mode | 0o111)
    return exe


def extract(fmu: Path, dest: Path) -> Path:
    dest.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(dest)
    return dest


def value_references(fmu_dir: Path) -> Dict[str, int]:
    root = ET.parse(fmu_dir / "modelDescription.xml").getroot()
    return {sv.get("name"): int(sv.get("valueReference")) for sv in root.iter("ScalarVariable")}


def compile_host(dest: Path) -> Path:
    """tests/native_host/host.c compiled (gcc is required: its absence fails the test)."""
    from cam_fmu.tools import soak

    require("gcc")
    return soak.compile_host(dest)


VALGRIND_OPTIONS = ["--error-limit=no", "--num-callers=40", "--leak-check=full", "--show-leak-kinds=definite",
                    "--errors-for-leak-kinds=none", f"--suppressions={SUPPRESSIONS}"]
OWN_CODE = ("fmi2_python.c", "/pi_speed.so", "/cam.so")  # frames of the FMUs' binaries in a valgrind stack


def valgrind_prefix(log: Path, trace_children: bool = False) -> List[str]:
    cmd = [require("valgrind"), *VALGRIND_OPTIONS, f"--log-file={log}"]
    if trace_children:
        cmd.append("--trace-children=yes")
    return cmd


def valgrind_summary(log: Path) -> dict:
    """Errors (after the suppressions) and definitely lost bytes from a valgrind log (all processes)."""
    text = log.read_text(errors="replace") if log.is_file() else ""
    errors = sum(int(m) for m in re.findall(r"ERROR SUMMARY: (\d+) errors", text))
    # definitely lost blocks allocated by the FMU's binary (numpy's module init leaks a few at every exit)
    records = re.split(r"\n==\d+== \n", text)
    own_lost = [r for r in records if "definitely lost in loss record" in r and any(o in r for o in OWN_CODE)]
    lost = sum(int(re.search(r"([\d,]+) (?:\(\S+ direct, \S+ indirect\) )?bytes", r).group(1).replace(",", ""))
               for r in own_lost)
    kinds = sorted(set(re.findall(r"==\d+== (Invalid [a-z]+ of size \d+|Invalid free|Mismatched free"
                                  r"|Use of uninitialised value[^\n]*|Conditional jump[^\n]*)", text)))
    return {"errors": errors, "definitely_lost": lost, "kinds": kinds, "summaries": text.count("ERROR SUMMARY"),
            "excerpt": text[-6000:]}


def run_host(host: Path, fmu_dir: Path, *commands: str, env: Optional[dict] = None,
             prefix: Sequence[str] = (), timeout: float = 900) -> dict:
    """Run the C host on the FMU's linux64 binary (cam.so, pi_speed.so, ...); return its exit code, the JSON
    lines (commands, log messages) and stderr."""
    binary = fmu_dir / "binaries" / "linux64" / "cam.so"
    if not binary.is_file():
        binary = next((fmu_dir / "binaries" / "linux64").glob("*.so"))
    proc = subprocess.run([*prefix, str(host), str(binary),
                           str(fmu_dir / "resources"), *commands],
                          capture_output=True, text=True, env=EMPTY_ENV if env is None else env, timeout=timeout)
    lines = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    return {"rc": proc.returncode, "lines": lines, "cmds": [x for x in lines if "cmd" in x],
            "logs": [x for x in lines if "log" in x], "stderr": proc.stderr, "stdout": proc.stdout}


def run_python(code: str, *args: str, cwd: Optional[Path] = None, env: Optional[dict] = None,
               timeout: float = 900) -> dict:
    """Run ``python -c code args`` (PYTHONPATH/PYTHONHOME removed) and return its last JSON line ({...} or [...])."""
    if env is None:
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    proc = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=cwd, env=env,
                          timeout=timeout)
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    for line in reversed(proc.stdout.splitlines()):
        if line.startswith(("{", "[")):
            try:
                return json.loads(line)
            except json.JSONDecodeError:
                continue  # a host's own log line
    raise AssertionError("no JSON result\n" + proc.stdout[-3000:] + proc.stderr[-3000:])


def libcosim_script(names: Sequence[str], u: Optional[float] = None) -> str:
    """Python code that runs the FMU ``sys.argv[1]`` in libcosim (libcosimpy: a local slave, 1 ms steps to
    0.2 s, a last-value observer) and prints ``RESULT`` and the last values of ``names`` as JSON; ``u``: the
    input's start value, if given."""
    start = f'ex.real_initial_value(idx, vr["u"], {float(u)!r})\n' if u is not None else ""
    return (
        "import json, sys\n"
        "from libcosimpy.CosimExecution import CosimExecution\n"
        "from libcosimpy.CosimSlave import CosimLocalSlave\n"
        "from libcosimpy.CosimObserver import CosimObserver\n"
        "ex = CosimExecution.from_step_size(step_size=int(1e6))\n"
        "obs = CosimObserver.create_last_value()\n"
        "ex.add_observer(obs)\n"
        "idx = ex.add_local_slave(CosimLocalSlave(fmu_path=sys.argv[1], instance_name='cam'))\n"
        "vr = {v.name.decode() if isinstance(v.name, bytes) else v.name: v.reference for v in ex.slave_variables(idx)}\n"
        + start +
        "ex.simulate_until(target_time=int(0.2e9))\n"
        f"print('RESULT ' + json.dumps(obs.last_real_values(idx, [vr[n] for n in {list(names)!r}])))\n")


def result_line(stdout: str):
    """The JSON after ``RESULT`` in a host's output (its own log lines around it)."""
    return json.loads(next(line for line in stdout.splitlines() if line.startswith("RESULT "))[7:])


# --------------------------------------------------------------------------- other platforms (engine/targets.py)
# The scenes every platform's binary runs against x86_64 Linux's: the drive of fig. 6, with a clearance, and the
# spring-closed follower of its own bouncing (spring_voltage's parameters: lift-offs, impacts, the Zeno guard), as
# host.c commands over variable names (value references differ between FMUs).
PLATFORM_SCENES = {
    "fig6": [],
    "backlash": [("setr", "c", "0.002")],
    "spring": [("sets", "closure", "spring"), ("setr", "k_spring", "800"), ("setr", "F_spring0", "20"),
               ("setr", "restitution", "0.5"), ("setr", "omega0", "60"), ("setr", "J_cam", "0.05"),
               ("setr", "gamma", "3.141592653589793"), ("setr", "u", "11")],
    # an oscillating roller in a groove with its pivot's friction: its own flight, impacts about the pivot
    "rocker": [("sets", "follower_type", "oscillating_roller"), ("setr", "arm_length", "0.15"),
               ("setr", "pivot_distance", "0.18"), ("setr", "lift_angle", "0.3"), ("setr", "J_arm", "0.002"),
               ("sets", "closure", "form"), ("setr", "c", "0.0003"), ("setr", "restitution", "0.5"),
               ("setr", "mu", "0.05"), ("setr", "u", "6")],
}


def scene_commands(scene: str, vr: Dict[str, object]) -> List[str]:
    """host.c's commands setting a PLATFORM_SCENES scene's parameters, by the FMU's value references."""
    return [word for cmd, name, value in PLATFORM_SCENES[scene] for word in (cmd, str(vr[name]), value)]


WINE = Path("/usr/lib/wine/wine64")  # Debian's wine64 package (the `wine` wrapper is another package)
QEMU_AARCH64 = "qemu-aarch64-static"  # Debian's qemu-user-static
AARCH64_ROOT = Path("/usr/aarch64-linux-gnu")  # Debian's libc6-arm64-cross: the aarch64 loader and libc


def zig_host(target: str, dest: Path, source: Path, *flags: str) -> Path:
    """The C test host ``source`` compiled by zig for ``target`` (a name of engine/targets.py), against the
    vendored FMI headers; on Linux dynamically linked, so it can dlopen the FMU's binary of that platform."""
    from cam_fmu.engine import build, targets

    row = targets.get(target)
    libs = ["-D_POSIX_C_SOURCE=200809L", "-ldl", "-lm"] if row.system == "Linux" else []  # dlopen (POSIX)
    cmd = [*build.zig_cc(), "-target", row.zig, "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", "-Wno-strict-prototypes",
           f"-I{build.fmi_headers(2)}", f"-I{build.fmi_headers(3)}", *flags, str(source), "-o", str(dest), *libs]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=dest.parent)
    assert proc.returncode == 0, proc.stderr
    return dest


def runner(target: str) -> List[str]:
    """The command prefix that runs an executable of ``target`` on this x86_64 Linux machine (qemu, wine);
    a missing tool fails the test (setup.sh installs them)."""
    from cam_fmu.engine import targets

    runs = targets.get(target).runs
    if runs == "qemu":
        if not (AARCH64_ROOT / "lib" / "ld-linux-aarch64.so.1").exists():
            pytest.fail(f"{AARCH64_ROOT} has no aarch64 loader: setup.sh installs Debian's libc6-arm64-cross")
        return [require(QEMU_AARCH64), "-L", str(AARCH64_ROOT)]
    if runs == "wine":
        if not WINE.is_file():
            pytest.fail(f"{WINE} is missing: setup.sh installs Debian's wine64 package")
        return [str(WINE)]
    if runs == "native":
        return []
    pytest.fail(f"{target} binaries cannot run here (engine/targets.py: runs={runs!r})")
