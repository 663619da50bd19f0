"""Soak runs of cam.fmu in several hosts: does any run abort (load, run, unload, exit)?

Developer command (the issue's counts; about 4 minutes on 2 shared cores):

    python -m cam_fmu.tools.soak models/cam.fmu --fmpy-cli 200 --scipy-script 200 --ecos 50 --c-host 50

The tests (tests/hosts/test_native_hosts.py) run the same functions with smaller counts.
A run fails on a non-zero exit status (an abort is -6, a segfault -11 / 139) or on a
glibc heap message ("corrupted double-linked list", "double free", ...) in its output; a C host
run also fails unless its own report says the model ran (the instance made, every call fmi2OK):
a host that exits cleanly because the FMU refused it proves nothing.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path
from typing import Dict, List, Optional

REPO = Path(__file__).resolve().parents[2]
HOST_C = REPO / "tests" / "native_host" / "host.c"
EMPTY_ENV = {"PATH": "/usr/bin:/bin"}
HEAP_MESSAGES = ("corrupted", "double free", "free(): invalid", "malloc(): ", "Segmentation fault", "Aborted")

SCIPY_SCRIPT = r"""
import sys
from fmpy import simulate_fmu
res = simulate_fmu(sys.argv[1], start_values={"u": 3.0}, output_interval=1e-3, stop_time=0.5)
import scipy.integrate, scipy.optimize, scipy.interpolate   # scipy-using modules after the FMU run
sol = scipy.integrate.solve_ivp(lambda t, y: -y, (0.0, 1.0), [1.0])
assert abs(res["time"][-1] - 0.5) < 1e-12 and sol.success
print("ok")
"""  # and a normal interpreter exit: no os._exit


def _fmpy_cli() -> List[str]:
    script = Path(sys.executable).with_name("fmpy")
    if script.is_file():
        return [sys.executable, str(script)]
    found = shutil.which("fmpy")
    if not found:
        raise RuntimeError("fmpy's command line tool is not installed")
    return [sys.executable, found]


def _ecos() -> Path:
    import ecospy
    exe = Path(ecospy.__file__).parent / "binaries" / "ecos"
    exe.chmod(exe.stat().st_mode | 0o111)
    return exe


def compile_host(dest: Path) -> Path:
    cc = shutil.which(os.environ.get("CC", "")) or shutil.which("cc") or shutil.which("gcc")
    if not cc:
        raise RuntimeError("no C compiler for the test host")
    from ..engine.build import fmi_headers

    subprocess.run([cc, "-std=c99", "-D_POSIX_C_SOURCE=200809L", "-O1", "-g", "-Wall", "-Wextra", "-Werror",
                    f"-I{fmi_headers()}", "-o", str(dest), str(HOST_C), "-ldl", "-lm"], check=True)
    return dest


def _failed(proc: subprocess.CompletedProcess) -> bool:
    text = (proc.stdout or "") + (proc.stderr or "")
    return proc.returncode != 0 or any(m in text for m in HEAP_MESSAGES)


def _host_ran(proc: subprocess.CompletedProcess) -> bool:
    """The C host's JSON lines say the model ran: the instance was made and every call returned fmi2OK."""
    lines = [json.loads(line) for line in (proc.stdout or "").splitlines() if line.startswith("{")]
    cmds = [x for x in lines if "cmd" in x]
    made = [x for x in cmds if x["cmd"] == "inst"]
    return bool(made) and all(x.get("ok") for x in made) and all(x.get("status", 0) == 0 for x in cmds)


def _loop(runs: int, make_cmd, cwd: Path, env: Optional[dict] = None, ran=None) -> Dict[str, object]:
    """``runs`` runs of the command; a run fails on an abort or a heap message, or when ``ran`` (the proof
    that the model did run, not only the host) says no."""
    failures, codes, start = 0, {}, time.monotonic()
    first_failure = ""
    for _ in range(runs):
        proc = subprocess.run(make_cmd(), cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True, errors="replace")
        if _failed(proc) or (ran is not None and not ran(proc)):
            failures += 1
            codes[proc.returncode] = codes.get(proc.returncode, 0) + 1
            first_failure = first_failure or (proc.stderr[-1500:] or proc.stdout[-1500:])
    return {"runs": runs, "failures": failures, "exit_codes": codes, "seconds": round(time.monotonic() - start, 1),
            "first_failure": first_failure}


def fmpy_cli(fmu: Path, runs: int, work: Path) -> Dict[str, object]:
    """`fmpy simulate cam.fmu --start-values u 3.0 solver rk4 --output-interval 1e-3`, output to a pipe."""
    cmd = [*_fmpy_cli(), "simulate", str(fmu), "--start-values", "u", "3.0", "solver", "rk4",
           "--output-interval", "1e-3"]
    return _loop(runs, lambda: cmd, work)


def scipy_script(fmu: Path, runs: int, work: Path) -> Dict[str, object]:
    """Simulate with fmpy, then import and use scipy, then exit normally."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    return _loop(runs, lambda: [sys.executable, "-c", SCIPY_SCRIPT, str(fmu)], work, env)


def ecos(fmu: Path, runs: int, work: Path) -> Dict[str, object]:
    """The ecos CLI with an empty environment (no LD_PRELOAD, PYTHONHOME, PYTHONPATH)."""
    cmd = [str(_ecos()), "simulate", "--path", str(fmu), "--stopTime", "0.2", "--stepSize", "0.001"]
    return _loop(runs, lambda: cmd, work, EMPTY_ENV)


def c_host(fmu: Path, runs: int, work: Path, host: Optional[Path] = None) -> Dict[str, object]:
    """tests/native_host/host.c: dlopen(RTLD_LOCAL), instantiate, 200 steps, free, dlclose, exit."""
    host = host or compile_host(work / "host")
    fmu_dir = work / "fmu"
    if not fmu_dir.is_dir():
        with zipfile.ZipFile(fmu) as z:
            z.extractall(fmu_dir)
    import xml.etree.ElementTree as ET

    root = ET.parse(fmu_dir / "modelDescription.xml").getroot()
    identifier = root.find("CoSimulation").get("modelIdentifier")
    first_input = next(v.get("valueReference") for v in root.iter("ScalarVariable") if v.get("causality") == "input")
    cmd = [str(host), str(fmu_dir / "binaries" / "linux64" / f"{identifier}.so"), str(fmu_dir / "resources"),
           "guid", root.get("guid"), "inst", "init", "setr", first_input, "3.0", "step", "200", "0.001", "free"]
    return _loop(runs, lambda: cmd, work, EMPTY_ENV, ran=_host_ran)


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("fmu", type=Path)
    parser.add_argument("--fmpy-cli", type=int, default=200)
    parser.add_argument("--scipy-script", type=int, default=200)
    parser.add_argument("--ecos", type=int, default=50)
    parser.add_argument("--c-host", type=int, default=50)
    args = parser.parse_args(argv)
    fmu = args.fmu.resolve()
    results = {}
    with tempfile.TemporaryDirectory(prefix="cam_fmu_soak_") as tmp:
        for name, fn, runs in (("fmpy_cli", fmpy_cli, args.fmpy_cli), ("scipy_script", scipy_script, args.scipy_script),
                               ("ecos", ecos, args.ecos), ("c_host", c_host, args.c_host)):
            if runs:
                work = Path(tmp) / name
                work.mkdir()
                results[name] = fn(fmu, runs, work)
                print(name, json.dumps({k: v for k, v in results[name].items() if k != "first_failure"}), flush=True)
    return 1 if any(r["failures"] for r in results.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
