"""Every C file the project ships or builds in its tests compiles warning-free under gcc and clang, C99.

The files: the FMUs' ``sources/`` folders as they ship (the engine, the FMI glue of each version, the PI
controller, their generated tables and ``guid.h``: what a user compiles with ``cc sources/*.c``), and every
other ``.c`` file of the package and of ``tests/`` (the fuzz drivers, the C hosts, the bench's C floor), each
with the include folders and macros its build gives it. Syntax only (``-fsyntax-only``): the warnings are the
front end's. A missing compiler fails: CI installs both (setup.sh).
"""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from cam_fmu.engine import build, codegen
from cam_fmu.fmu import engine_fmu, pi_codegen
from cam_fmu.tools.bench import c_floor

ROOT = Path(__file__).resolve().parents[2]
FLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-fsyntax-only")
COMPILERS = ("gcc", "clang")
# the FMUs as they ship: (C model, FMI version) of cam.fmu, cam3.fmu and pi_speed.fmu
SHIPPED = (("cam", 2), ("cam", 3), ("pi_speed", 2))


def _tree_files() -> list[Path]:
    return sorted(p for folder in ("cam_fmu", "tests") for p in (ROOT / folder).rglob("*.c")
                  if ".venv" not in p.parts)


@pytest.fixture(scope="module")
def groups(tmp_path_factory) -> dict[str, tuple[list[Path], list[str]]]:
    """{name: (C files, include and macro flags)}: the FMUs' sources/ folders, then every other file of the tree."""
    tmp = tmp_path_factory.mktemp("c_compilers")
    out: dict[str, tuple[list[Path], list[str]]] = {}
    shipped_names: set[str] = set()
    for model, version in SHIPPED:
        folder = tmp / f"{model}_fmi{version}" / "sources"
        files = engine_fmu.write_sources(folder, engine_fmu.MODELS[model], "{00000000-0000-0000-0000-000000000000}",
                                         version)
        out[f"{model} FMI {version}.0 sources/"] = ([folder / name for name in files], [f"-I{folder}"])
        shipped_names.update(files)
    generated = [*codegen.write(tmp / "gen"), *pi_codegen.write(tmp / "pi_gen")]
    include = [build.INCLUDE, build.CSRC / "fmi", build.fmi_headers(2), build.fmi_headers(3), tmp / "gen",
               engine_fmu.CONTROL_CSRC, tmp / "pi_gen"]
    common = [*(f"-I{p}" for p in include), '-DMODEL_GUID="{0}"']
    rest = [p for p in _tree_files() if not (p.name in shipped_names and p.parent in
                                             (build.SOURCES, build.CSRC / "fmi", engine_fmu.CONTROL_CSRC))]
    floor = [p for p in rest if p == c_floor.C_SOURCE]
    out["the tree's other C files"] = ([p for p in rest if p not in floor], common)
    out["the bench's C floor"] = (floor, [*common, *(f"-D{k}={v}" for k, v in c_floor.defines().items())])
    assert {p.name for p in generated if p.suffix == ".c"} <= shipped_names  # the generated tables ship
    return out


def test_every_c_file_is_in_a_group(groups):
    """Nothing escapes: every .c of the tree is compiled, from the shipped folders or as itself."""
    compiled = {p.name for files, _ in groups.values() for p in files}
    assert {p.name for p in _tree_files()} <= compiled
    assert "host.c" in compiled and "fuzz_driver.c" in compiled and "floor.c" in compiled
    assert "cam_params.c" in compiled and "pi_params.c" in compiled  # the generated tables
    assert all(files for files, _ in groups.values())


@pytest.mark.parametrize("compiler", COMPILERS)
def test_c99_warning_free(compiler, groups):
    cc = shutil.which(compiler)
    if cc is None:
        pytest.fail(f"{compiler} is not installed: CI installs it (setup.sh); every C file must compile under it")
    failures = []
    for name, (files, flags) in groups.items():
        proc = subprocess.run([cc, *FLAGS, *flags, *map(str, files)], capture_output=True, text=True)
        if proc.returncode != 0 or proc.stderr.strip():
            failures.append(f"{name} ({len(files)} files):\n{proc.stderr[-4000:]}")
    assert not failures, f"{compiler} {' '.join(FLAGS)}:\n" + "\n".join(failures)


def test_the_check_sees_an_implicit_declaration(tmp_path):
    """The flags catch what they are for: a C99 file calling strdup without POSIX fails under both."""
    src = tmp_path / "implicit.c"
    src.write_text('#include <string.h>\n#include <stdlib.h>\n'
                   'int main(void) { char *s = strdup("x"); free(s); return 0; }\n')
    for compiler in COMPILERS:
        cc = shutil.which(compiler)
        if cc is None:
            pytest.fail(f"{compiler} is not installed: CI installs it (setup.sh)")
        proc = subprocess.run([cc, *FLAGS, str(src)], capture_output=True, text=True)
        assert proc.returncode != 0 and "strdup" in proc.stderr, (compiler, proc.stderr)
