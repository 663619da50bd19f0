"""cam.fmu runs anywhere, with the same outputs: fmpy on Python 3.10, 3.11, 3.12 and 3.13, ecos, libcosim and
a C host, each with an empty environment and with nothing of the building Python in reach.

"Nothing in reach": every host runs in a private mount namespace (``unshare -m``) in which an empty tmpfs
lies over the building interpreter's prefix (sys.base_prefix, and sys.prefix when that is a venv) and
over this checkout, with ``env -i PATH=/usr/bin:/bin``. fmpy runs from venvs of the other Python versions
(pyenv's, under their own prefixes, which stay visible), made once per machine under the temporary
folder. ecos runs from a copy of its binaries outside the hidden folders. libcosim runs from the
Python 3.12 venv. The reference is the C host's run of the same cases (tests/native_host/host.c); every
host must give its outputs to 1e-12 relative (ecos writes 6 decimals: to that). The linux64 binary
links libc and libm only, and its newest glibc symbol version is the floor docs/fmu.md states.
Every tool is required: a missing pyenv version, unshare or ecos fails the test.
"""
from __future__ import annotations

import csv
import json
import re
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from native_support import (EMPTY_ENV, ROOT, compile_host, ecos_path, extract, libcosim_script, require, result_line,
                            run_host)

VERSIONS = ("3.10", "3.12", "3.13")  # beside the building Python (3.11: the C host's reference runs beside it)
PYENV = Path.home() / ".pyenv" / "versions"
NAMES = ("theta", "omega", "s")
SYSTEM = {"/", "/usr", "/usr/local", "/bin", "/lib"}


def _pinned(package: str) -> str:
    for line in (ROOT / "constraints" / "test.txt").read_text().splitlines():
        if line.lower().startswith(package.lower() + "=="):
            return line.strip()
    pytest.fail(f"{package} is not pinned in constraints/test.txt")


def _hidden_folders() -> list[str]:
    """The building Python's folders and the checkout, as they are hidden (a system prefix: its lib/pythonX.Y)."""
    import cam_fmu

    folders = {sys.base_prefix, sys.prefix, str(ROOT), str(Path(cam_fmu.__file__).resolve().parents[1])}
    out = set()
    for folder in folders:
        folder = str(Path(folder).resolve())
        out.add(str(Path(folder) / "lib" / f"python{sys.version_info[0]}.{sys.version_info[1]}")
                if folder in SYSTEM else folder)
    # a folder inside another is hidden with it (a venv in the checkout, as setup.sh makes: once the checkout is
    # under a tmpfs its mount point is gone and mount failed)
    return sorted(f for f in out if not any(Path(f).is_relative_to(other) and f != other for other in out))


def hidden(cmd: list[str], cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess:
    """``cmd`` in a private mount namespace with an empty tmpfs over the building Python's folders and
    the checkout, in an empty environment."""
    unshare = require("unshare")
    mounts = " && ".join(f"mount -t tmpfs none '{folder}'" for folder in _hidden_folders())
    script = f"{mounts} && exec env -i PATH={EMPTY_ENV['PATH']} \"$@\""
    return subprocess.run([unshare, "-m", "--propagation", "private", "sh", "-c", script, "sh", *cmd],
                          cwd=cwd, capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def place(cam_fmu_path, tmp_path_factory) -> dict:
    """The FMU (zipped and unzipped), the fmpy driver and the C host, all outside the hidden folders."""
    folder = tmp_path_factory.mktemp("fmu_hosts")
    shutil.copyfile(cam_fmu_path, folder / "cam.fmu")
    shutil.copyfile(ROOT / "tests" / "hosts" / "fmpy_driver.py", folder / "fmpy_driver.py")
    return {"folder": folder, "fmu": folder / "cam.fmu", "unzipped": extract(cam_fmu_path, folder / "unzipped"),
            "host": compile_host(folder / "host")}


def test_hiding_works(place):
    """Inside, the building interpreter and the checkout are gone; outside, they are there."""
    probe = hidden(["sh", "-c", f"test -e '{sys.executable}' || test -e '{ROOT / 'cam_fmu'}' && echo seen || "
                                "echo hidden"], place["folder"])
    assert probe.returncode == 0 and probe.stdout.strip() == "hidden", probe
    assert Path(sys.executable).exists()


def _c_host(place, *commands, hide=True):
    vr = {sv.get("name"): sv.get("valueReference")
          for sv in ET.parse(place["unzipped"] / "modelDescription.xml").getroot().iter("ScalarVariable")}
    guid = ET.parse(place["unzipped"] / "modelDescription.xml").getroot().get("guid")
    names = ",".join(vr[n] for n in NAMES)
    expanded = [names if c == "NAMES" else (vr[c[1:]] if c.startswith("@") else c) for c in commands]
    if not hide:
        return run_host(place["host"], place["unzipped"], "guid", guid, *expanded)
    binary = place["unzipped"] / "binaries" / "linux64" / "cam.so"
    proc = hidden([str(place["host"]), str(binary), str(place["unzipped"] / "resources"), "guid", guid, *expanded],
                  place["folder"])
    lines = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    assert proc.returncode == 0 and lines and lines[-1] == {"exit": 0}, proc.stdout[-2000:] + proc.stderr[-2000:]
    return {"cmds": [x for x in lines if "cmd" in x]}


@pytest.fixture(scope="module")
def reference(place) -> dict:
    """The C host's runs, nothing of the building Python in reach: fig. 6 (2 s), backlash (1 s), state."""
    def values(result):
        return [x["values"] for x in result["cmds"] if x["cmd"] == "getr"]

    fig6 = values(_c_host(place, "inst", "init", "step", "2000", "0.001", "getr", "NAMES", "free"))[0]
    backlash = values(_c_host(place, "inst", "setr", "@c", "5e-4", "init", "step", "1000", "0.001", "getr",
                              "NAMES", "free"))[0]
    first, second = values(_c_host(place, "inst", "init", "step", "500", "0.001", "save", "serial", "step", "500",
                                   "0.001", "getr", "NAMES", "restore", "step", "500", "0.001", "getr", "NAMES",
                                   "free"))
    assert first == second  # the state restored in the C host continues to the bit
    short = values(_c_host(place, "inst", "init", "step", "200", "0.001", "getr", "NAMES", "free"))[0]
    return {"fig6": fig6, "backlash": backlash, "state": first, "at_0.2": short}


def _venv(version: str) -> Path:
    """A venv of pyenv's Python ``version`` with the pinned fmpy (and libcosimpy for 3.12), made once."""
    base = sorted(PYENV.glob(f"{version}.*"))
    if not base:
        pytest.fail(f"pyenv has no Python {version} ({PYENV}); the machine image provides 3.10, 3.12, 3.13")
    folder = Path(tempfile.gettempdir()) / "cam_fmu_host_venvs" / base[-1].name
    python = folder / "bin" / "python"
    packages = [_pinned("fmpy")] + ([_pinned("libcosimpy")] if version == "3.12" else [])
    marker = folder / "installed.txt"
    if not (python.is_file() and marker.is_file() and marker.read_text() == " ".join(packages)):
        shutil.rmtree(folder, ignore_errors=True)
        subprocess.run([str(base[-1] / "bin" / "python"), "-m", "venv", str(folder)], check=True, timeout=300)
        proc = subprocess.run([str(python), "-m", "pip", "install", "-q", *packages], capture_output=True, text=True,
                              timeout=900)
        assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
        marker.write_text(" ".join(packages))
    return python


@pytest.mark.parametrize("version", VERSIONS)
def test_fmpy_on_another_python_gives_the_same_outputs(version, place, reference):
    python = _venv(version)
    proc = hidden([str(python), str(place["folder"] / "fmpy_driver.py"), str(place["unzipped"])], place["folder"])
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    got = json.loads(proc.stdout.strip().splitlines()[-1])
    assert got["python"] == version
    for case in ("fig6", "backlash", "state"):
        assert got[case]["values"] == pytest.approx(reference[case], rel=1e-12, abs=1e-15), case
    assert got["state"]["restored_run"] == got["state"]["values"]


def test_ecos_gives_the_same_outputs(place, reference):
    binaries = place["folder"] / "ecos"
    shutil.copytree(ecos_path().parent, binaries, dirs_exist_ok=True)
    out = place["folder"] / "ecos_run"
    out.mkdir(exist_ok=True)
    proc = hidden([str(binaries / "ecos"), "simulate", "--path", str(place["fmu"]), "--stopTime", "0.2",
                   "--stepSize", "0.001"], out)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    rows = list(csv.reader(open(next(out.glob("*.csv")))))
    header = [h.strip() for h in rows[0]]
    last = rows[-1]
    n = round(float(last[header.index("time")]) / 1e-3)  # ecos's last row (0.199 s: it writes before a step)
    assert n >= 190
    c_host = _c_host(place, "inst", "init", "step", str(n), "0.001", "getr", "NAMES", "free")
    expected = [x["values"] for x in c_host["cmds"] if x["cmd"] == "getr"][0]
    for k, name in enumerate(NAMES):
        col = next(j for j, h in enumerate(header) if h.endswith(f"::{name}[REAL]"))
        assert float(last[col]) == pytest.approx(expected[k], abs=1e-6), name  # 6 decimals written




def test_libcosim_gives_the_same_outputs(place, reference):
    python = _venv("3.12")
    script = place["folder"] / "libcosim_driver.py"
    script.write_text(libcosim_script(NAMES))
    proc = hidden([str(python), str(script), str(place["fmu"])], place["folder"])
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    values = result_line(proc.stdout)
    assert values == pytest.approx(reference["at_0.2"], rel=1e-12, abs=1e-15)


def test_the_c_host_hidden_and_not_agree(place, reference):
    """Hiding changes nothing: the C host beside the building Python gives the same bits."""
    result = _c_host(place, "inst", "init", "step", "2000", "0.001", "getr", "NAMES", "free", hide=False)
    assert [x["values"] for x in result["cmds"] if x["cmd"] == "getr"][0] == reference["fig6"]


def test_the_binary_needs_libc_and_libm_only_and_the_documented_glibc(place):
    binary = place["unzipped"] / "binaries" / "linux64" / "cam.so"
    needed = subprocess.run([require("readelf"), "-d", str(binary)], capture_output=True, text=True).stdout
    libraries = set(re.findall(r"Shared library: \[([^\]]+)\]", needed))
    assert libraries <= {"libc.so.6", "libm.so.6"} and "libc.so.6" in libraries, libraries
    symbols = subprocess.run([require("objdump"), "-T", str(binary)], capture_output=True, text=True).stdout
    versions = {tuple(int(x) for x in v.split(".")) for v in re.findall(r"GLIBC_(\d+\.\d+(?:\.\d+)?)", symbols)}
    newest = ".".join(map(str, max(versions)))
    doc = (ROOT / "docs" / "fmu.md").read_text(encoding="utf-8")
    stated = re.search(r"glibc >= (\d+\.\d+)", doc).group(1)
    assert newest == stated, f"the binary needs glibc {newest}, docs/fmu.md says {stated}"
