"""Reproducible builds (docs/fmu.md, "Reproducible builds"): two builds of one commit into two folders give the
same bytes for every FMU (every platform's binaries), every SSP and every wheel. The session's builds
(conftest: cam_fmu_path, cam3_fmu_path, pi_speed_fmu_path, wheels_folder; every platform in a full run) are the
first build; this module builds each artefact once more into a folder of another path length (slow: zig builds
every platform, pip builds every wheel).

Independent checks beside the byte comparison: the zip entries carry the last commit's time as git reports it
(or SOURCE_DATE_EPOCH when set), in name order, 0644; no binary names a build folder.
"""
from __future__ import annotations

import os
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest

from cam_fmu.engine import reproducible, targets
from cam_fmu.fmu import build as fmu_build

ROOT = Path(__file__).resolve().parents[2]


def _commit_time() -> int:
    return int(subprocess.run(["git", "log", "-1", "--format=%ct"], cwd=ROOT, capture_output=True, text=True,
                              check=True).stdout)


def _build_fmu(dest: Path, model: str, *extra: str, env: dict | None = None) -> Path:
    proc = subprocess.run([sys.executable, str(ROOT / "build_fmu.py"), "--model", model, "--dest", str(dest),
                           *extra], cwd=ROOT, capture_output=True, text=True, timeout=1800, env=env)
    assert proc.returncode == 0 and dest.is_file(), proc.stderr[-3000:]
    return dest


def _with_ssps(folder: Path, fmus: dict[str, Path]) -> dict[str, Path]:
    ssps = {f"{n}.ssp": fmu_build.build_ssp(folder / f"{n}.ssp", fmus["cam.fmu"], fmus["pi_speed.fmu"], n)
            for n in fmu_build.SSP_NAMES}
    return {**fmus, **ssps}


@pytest.fixture(scope="module")
def twice(tmp_path_factory, cam_fmu_path, cam3_fmu_path, pi_speed_fmu_path) -> list[dict[str, Path]]:
    """Every FMU (all platforms) and SSP twice: the session's build, and one more into a folder of another path
    length."""
    assert set(fmu_build.MODELS) == {"cam", "cam3", "pi_speed"}, fmu_build.MODELS  # the session builds these
    first = _with_ssps(tmp_path_factory.mktemp("first"),
                       {"cam.fmu": cam_fmu_path, "cam3.fmu": cam3_fmu_path, "pi_speed.fmu": pi_speed_fmu_path})
    folder = tmp_path_factory.mktemp("second_build_elsewhere") / "deeper"
    folder.mkdir(parents=True, exist_ok=True)
    second = _with_ssps(folder, {f"{m}.fmu": _build_fmu(folder / f"{m}.fmu", m) for m in fmu_build.MODELS})
    return [first, second]


@pytest.fixture(scope="module")
def wheels_twice(tmp_path_factory, wheels_folder) -> list[dict[str, Path]]:
    """Every wheel twice: the session's build and one more."""
    folder = tmp_path_factory.mktemp("wheels_again") / "elsewhere"
    folder.mkdir(parents=True)
    proc = subprocess.run([sys.executable, str(ROOT / "build_fmu.py"), "--wheels", str(folder)], cwd=ROOT,
                          capture_output=True, text=True, timeout=3600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return [{p.name: p for p in wheels_folder.glob("*.whl")}, {p.name: p for p in folder.glob("*.whl")}]


@pytest.mark.external
@pytest.mark.slow
def test_every_fmu_and_ssp_is_the_same_bytes_twice(twice):
    first, second = twice
    assert sorted(first) == sorted(["cam.fmu", "cam3.fmu", "pi_speed.fmu", "speed_loop.ssp", "compliant_loop.ssp"])
    differ = [name for name in first if first[name].read_bytes() != second[name].read_bytes()]
    assert not differ, differ
    with zipfile.ZipFile(first["cam.fmu"]) as z:  # every platform's binary is in what was compared
        folders = {n.split("/")[1] for n in z.namelist() if n.startswith("binaries/")}
    assert folders == {t.fmi2 for t in targets.TARGETS}, folders


@pytest.mark.external
@pytest.mark.slow
def test_the_entries_carry_the_commit_time_in_order_0644(twice):
    stamp = time.gmtime(_commit_time())[:6]
    stamp = (*stamp[:5], stamp[5] // 2 * 2)  # a zip stores even seconds
    for path in twice[0].values():
        with zipfile.ZipFile(path) as z:
            infos = z.infolist()
        assert [i.filename for i in infos] == sorted(i.filename for i in infos), path.name
        assert {i.date_time for i in infos} == {stamp}, (path.name, {i.date_time for i in infos})
        assert {(i.external_attr >> 16) & 0o777 for i in infos} == {0o644}, path.name


@pytest.mark.external
@pytest.mark.slow
def test_no_binary_names_a_build_folder(twice):
    """What broke it: the macOS library carried /tmp/cam_fmu_build_<random>/... as its install name."""
    for name in ("cam.fmu", "cam3.fmu", "pi_speed.fmu"):
        with zipfile.ZipFile(twice[0][name]) as z:
            for entry in (n for n in z.namelist() if n.startswith("binaries/")):
                data = z.read(entry)
                for needle in (b"cam_fmu_build_", b"cam_gen_", str(ROOT).encode(), b"/tmp/"):
                    assert needle not in data, (name, entry, needle)


@pytest.mark.external
@pytest.mark.slow
def test_every_wheel_is_the_same_bytes_twice(wheels_twice):
    first, second = wheels_twice
    assert len(first) == len(targets.TARGETS) and sorted(first) == sorted(second), (sorted(first), sorted(second))
    differ = [name for name in first if first[name].read_bytes() != second[name].read_bytes()]
    assert not differ, differ
    stamp = time.gmtime(_commit_time())[:5]
    with zipfile.ZipFile(next(iter(first.values()))) as z:
        assert {i.date_time[:5] for i in z.infolist()} == {stamp}  # SOURCE_DATE_EPOCH reached bdist_wheel


@pytest.mark.slow
def test_source_date_epoch_is_honoured_by_a_host_build(tmp_path):
    """SOURCE_DATE_EPOCH=1000000000 is 2001-09-09 01:46:40 UTC; two builds of this machine's binary (the
    system C compiler) into two folders are the same bytes too."""
    env = {**os.environ, "SOURCE_DATE_EPOCH": "1000000000"}
    a = _build_fmu(tmp_path / "a" / "cam.fmu", "cam", "--platforms", "host", env=env)
    b = _build_fmu(tmp_path / "b" / "elsewhere" / "cam.fmu", "cam", "--platforms", "host", env=env)
    assert a.read_bytes() == b.read_bytes()
    with zipfile.ZipFile(a) as z:
        assert {i.date_time for i in z.infolist()} == {(2001, 9, 9, 1, 46, 40)}


def test_the_default_epoch_outside_git_and_a_bad_value(monkeypatch, tmp_path):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    assert reproducible.source_date_epoch() == _commit_time()  # in this checkout: the last commit's time
    monkeypatch.setattr(reproducible, "ROOT", tmp_path)  # no git here
    assert reproducible.source_date_epoch() == reproducible.FIXED_EPOCH == 315532800  # 1980-01-01 00:00 UTC
    assert time.gmtime(reproducible.FIXED_EPOCH)[:6] == (1980, 1, 1, 0, 0, 0)
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "yesterday")
    with pytest.raises(ValueError, match="SOURCE_DATE_EPOCH"):
        reproducible.source_date_epoch()
