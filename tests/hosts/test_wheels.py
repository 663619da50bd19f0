"""The package's wheels: one per platform of engine/targets.py, py3-none-<platform>, each with its engine
library (zig) and the shipped FMUs and SSPs; installed from the x86_64 Linux wheel into fresh venvs of the
machine's other CPythons with every C compiler hidden, the package runs its commands and gets the source
build's numbers. Needs the other CPythons (pyenv's 3.10, 3.12, 3.13 here) and the package index: a missing
Python fails the test.
"""
from __future__ import annotations

import csv
import re
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from cam_fmu.engine import targets

pytestmark = pytest.mark.external  # (hosts/ is external by itself; slow by its recorded durations)

ROOT = Path(__file__).resolve().parents[2]
PYENV = Path("/root/.pyenv/versions")
OTHER_PYTHONS = ("3.10", "3.12", "3.13")
SHIPPED = {"cam.fmu", "cam3.fmu", "pi_speed.fmu", "speed_loop.ssp", "compliant_loop.ssp"}


@pytest.fixture(scope="module")
def wheels(wheels_folder) -> dict[str, Path]:
    folder = wheels_folder
    made = {row.name: folder / f"cam_fmu-0.1.0-py3-none-{row.wheel}.whl" for row in targets.TARGETS}
    assert all(path.is_file() for path in made.values()), sorted(p.name for p in folder.iterdir())
    return made


def _library(wheel: Path) -> tuple[str, bytes]:
    with zipfile.ZipFile(wheel) as z:
        names = [n for n in z.namelist() if n.startswith("cam_fmu/engine/_lib/")]
        assert len(names) == 1, names  # one library, the platform's: none left over from another build
        return names[0], z.read(names[0])


def _architecture(binary: bytes) -> str:
    """The machine a shared library is for, read from its header (ELF, PE or Mach-O)."""
    if binary[:4] == b"\x7fELF":
        machine = struct.unpack_from("<H", binary, 18)[0]
        return {62: "x86_64-linux", 183: "aarch64-linux"}[machine]
    if binary[:2] == b"MZ":
        pe = struct.unpack_from("<I", binary, 0x3C)[0]
        assert binary[pe:pe + 4] == b"PE\0\0"
        return {0x8664: "x86_64-windows"}[struct.unpack_from("<H", binary, pe + 4)[0]]
    magic, cputype = struct.unpack_from("<II", binary, 0)
    assert magic == 0xFEEDFACF, hex(magic)
    return {0x01000007: "x86_64-darwin", 0x0100000C: "aarch64-darwin"}[cputype]


def test_one_wheel_per_platform_with_its_library_and_the_shipped_files(wheels):
    from cam_fmu.engine.build import library_name

    for name, wheel in wheels.items():
        row = targets.get(name)
        member, binary = _library(wheel)
        assert member.endswith(library_name(target=name)), member  # the name the loader of that platform seeks
        assert _architecture(binary) == name
        with zipfile.ZipFile(wheel) as z:
            shipped = {Path(n).name for n in z.namelist() if n.startswith("cam_fmu/shipped/")}
            tag = re.search(r"^Tag: (.*)$", z.read("cam_fmu-0.1.0.dist-info/WHEEL").decode(), re.M).group(1)
            assert z.read("cam_fmu/shipped/cam.fmu") == (ROOT / "models" / "cam.fmu").read_bytes()
        assert shipped == SHIPPED
        assert tag.startswith("py3-none-") and tag.split("-")[2] in row.wheel.split(".")


def test_auditwheel_accepts_the_linux_wheels(wheels):
    for name in ("x86_64-linux", "aarch64-linux"):
        proc = subprocess.run([sys.executable, "-m", "auditwheel", "show", str(wheels[name])], capture_output=True,
                              text=True, timeout=300)
        assert proc.returncode == 0, proc.stderr
        arch = name.split("-")[0]
        assert f'is consistent with the following platform tag:\n"manylinux_2_17_{arch}"' in proc.stdout, proc.stdout


README_BLOCK = re.search(r"## From Python.*?```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S).group(1)


@pytest.fixture(scope="module")
def source_build(tmp_path_factory) -> dict[str, object]:
    """The source build's numbers: this checkout's package (models/cam.fmu) run the same way; once for the
    three Pythons' wheels (each compared with it), not once each."""
    out = tmp_path_factory.mktemp("source")
    for args in (["simulate", "paper_fig6", "--engine", "fmu", "--no-plot"], ["cosim", "speed_loop", "--no-plot"]):
        proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", *args, "--out", str(out)], capture_output=True,
                              text=True, cwd=ROOT, timeout=600)
        assert proc.returncode == 0, proc.stderr
    readme = subprocess.run([sys.executable, "-c", README_BLOCK], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert readme.returncode == 0, readme.stderr
    return {"csv": out, "readme": readme.stdout}


def _columns(path: Path) -> dict[str, np.ndarray]:
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    data = np.array(rows[1:], dtype=float)
    return {name: data[:, k] for k, name in enumerate(rows[0])}


@pytest.mark.parametrize("version", OTHER_PYTHONS)
def test_the_wheel_runs_on_another_python_without_a_compiler(wheels, source_build, version, tmp_path):
    pythons = sorted(PYENV.glob(f"{version}.*/bin/python{version}"))
    if not pythons:
        pytest.fail(f"no CPython {version} under {PYENV} (the machine's pyenv versions)")
    venv = tmp_path / "venv"
    subprocess.run([str(pythons[-1]), "-m", "venv", str(venv)], check=True, timeout=300)
    # as a user installs it: the dependencies' newest versions for that Python (the lock is 3.11's)
    install = subprocess.run([str(venv / "bin" / "pip"), "install", "-q", str(wheels["x86_64-linux"])],
                             capture_output=True, text=True, timeout=1800)
    assert install.returncode == 0, install.stderr[-3000:]
    # nothing but the venv on PATH: no cc, gcc, clang or zig; no CC; an empty cache that must stay so
    empty = tmp_path / "empty"
    empty.mkdir()
    env = {"HOME": str(tmp_path), "XDG_CACHE_HOME": str(tmp_path / "cache"), "PATH": f"{venv / 'bin'}:{empty}",
           "CAM_FMU_PROGRESS": "0"}
    work = tmp_path / "work"
    work.mkdir()
    for args in (["simulate", "paper_fig6", "--engine", "fmu", "--no-plot", "--out", "out"],
                 ["cosim", "speed_loop", "--no-plot", "--out", "out"], ["cross-check", "xc"]):
        proc = subprocess.run([str(venv / "bin" / "cam-fmu"), *args], capture_output=True, text=True,
                              cwd=work, env=env, timeout=900)
        assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-3000:]
    logs = list((work / "xc").rglob("*_fmpy.log"))  # cross-check's folders of the shipped FMUs, validated
    assert logs and not [log for log in logs if log.read_text().rstrip().endswith("FAILED")], logs
    readme = subprocess.run([str(venv / "bin" / "python"), "-c", README_BLOCK], capture_output=True, text=True,
                            cwd=work, env=env, timeout=600)
    assert readme.returncode == 0, readme.stderr[-3000:]
    assert not (tmp_path / "cache" / "cam_fmu").exists(), "the installed wheel built something at run time"
    source = source_build
    assert readme.stdout == source["readme"]
    for name in ("paper_fig6.csv", "paper_fig6__paper.csv", "speed_loop.csv"):
        ours, theirs = _columns(work / "out" / name), _columns(source["csv"] / name)
        assert ours.keys() == theirs.keys()
        for column in ours:
            assert np.array_equal(ours[column], theirs[column]), (name, column)
