"""Every platform of cam_fmu/engine/targets.py, in cam.fmu, cam3.fmu and the engine library: built by zig on
this machine, each binary read back here by parsers written in this file (ELF, PE, Mach-O), and run where it
can run: aarch64 Linux under qemu-user against x86_64 (1e-12 relative, the same statuses, a state round trip),
Windows under wine (test_engine_fmu_win64.py, test_fmi3.py), macOS not at all ("built, not run").

Also the FMUs' sources/: compiled as they are by a plain `cc sources/*.c` and by fmpy's CMake build from the
build descriptions (FMI 2.0: <SourceFiles>; FMI 3.0: sources/buildDescription.xml), the result run against
the shipped binary. qemu-user-static, libc6-arm64-cross, wine64 and cmake are required tools (setup.sh).
"""
from __future__ import annotations

import json
import re
import shutil
import struct
import subprocess
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest

from cam_fmu.engine import build as engine_build
from cam_fmu.engine import targets
from cam_fmu.fmu import macho
from native_support import HOST_C, PLATFORM_SCENES, compile_host, require, runner, scene_commands, zig_host

HERE = Path(__file__).resolve().parents[1]
HOST3_C = HERE / "native_host" / "host3.c"
ME_HOST_C = HERE / "engine_c" / "me_host.c"
FMI2_FOLDERS = {"linux64": "x86_64-linux", "aarch64-linux": "aarch64-linux", "win64": "x86_64-windows",
                "darwin64": "x86_64-darwin aarch64-darwin"}  # written out here, not read from the table
EM_X86_64, EM_AARCH64 = 62, 183
CPU_X86_64, CPU_ARM64 = 0x01000007, 0x0100000C
LINKER_SYMBOLS = {"_mh_dylib_header", "__dso_handle"}  # (underscore dropped) what Apple's and zig's linkers export from any dylib


@pytest.fixture(scope="module")
def cam3(cam3_fmu_path) -> Path:
    return cam3_fmu_path  # the session's build (conftest.py): every platform, as hosts/ is never in the fast loop


def _extract(fmu: Path, folder: Path) -> Path:
    with zipfile.ZipFile(fmu) as z:
        z.extractall(folder)
    return folder


@pytest.fixture(scope="module")
def unzipped(engine_fmu_path, cam3, tmp_path_factory) -> dict:
    return {2: _extract(engine_fmu_path, tmp_path_factory.mktemp("platforms_2")),
            3: _extract(cam3, tmp_path_factory.mktemp("platforms_3"))}


def _required(version: int) -> set[str]:
    header = (engine_build.fmi_headers(version) / f"fmi{version}Functions.h").read_text()
    if version == 2:
        return set(re.findall(r"^#define (fmi2\w+)\s+fmi2FullName", header, flags=re.M))
    return set(re.findall(r"^#define (fmi3\w+) ", header, flags=re.M)) - {"fmi3Version"}


def _guid(folder: Path) -> str:
    root = ET.parse(folder / "modelDescription.xml").getroot()
    return root.get("guid") or root.get("instantiationToken")


def _vr(folder: Path) -> dict[str, str]:
    root = ET.parse(folder / "modelDescription.xml").getroot()
    return {v.get("name"): v.get("valueReference") for v in root.find("ModelVariables")}


# --------------------------------------------------------------------------- the binaries' formats
def elf_machine(path: Path) -> int:
    data = path.read_bytes()[:20]
    assert data[:4] == b"\x7fELF" and data[4] == 2, f"{path}: not a 64-bit ELF file"
    return struct.unpack_from("<H", data, 18)[0]


def glibc_versions(path: Path) -> set[tuple[int, ...]]:
    """The GLIBC_x.y versions the ELF file needs (its .gnu.version_r, read by binutils' readelf)."""
    proc = subprocess.run([require("readelf"), "-V", "-W", str(path)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    found = {tuple(map(int, v.split("."))) for v in re.findall(r"Name: GLIBC_([\d.]+)", proc.stdout)}
    assert found, f"{path}: no versioned glibc symbol read (not dynamically linked against glibc?)"
    return found


def pe_machine_and_exports(path: Path) -> tuple[int, set[str], set[str]]:
    """(COFF machine, exported names, imported DLLs) of a PE file (machine from the header, the tables from
    binutils' objdump -p)."""
    data = path.read_bytes()
    assert data[:2] == b"MZ"
    offset = struct.unpack_from("<I", data, 0x3C)[0]
    assert data[offset:offset + 4] == b"PE\0\0"
    table = subprocess.run([require("objdump"), "-p", str(path)], capture_output=True, text=True).stdout
    rows = table[table.index("[Ordinal/Name Pointer] Table"):].splitlines()[1:]
    exports = set()
    for row in rows:  # the table's rows, up to the first line that is not one
        match = re.fullmatch(r"\s*\[\s*\d+\]\s+(\w+)", row)
        if not match:
            break
        exports.add(match.group(1))
    dlls = set(re.findall(r"DLL Name: (\S+)", table))
    return struct.unpack_from("<H", data, offset + 4)[0], exports, dlls


def macho_thin(data: bytes, base: int = 0) -> tuple[int, int, set[str], tuple[int, int]]:
    """(cputype, filetype, exported names without the leading underscore, minimum macOS (major, minor)) of the
    thin 64-bit Mach-O at ``base``: the external, defined, non-private symbols of its LC_SYMTAB; the minimum
    from LC_BUILD_VERSION or LC_VERSION_MIN_MACOSX."""
    magic, cputype, _sub, filetype, ncmds, _size = struct.unpack_from("<IiiIII", data, base)
    assert magic == 0xFEEDFACF, hex(magic)
    names, offset, minos = set(), base + 32, None
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<II", data, offset)
        if cmd in (0x32, 0x24):  # LC_BUILD_VERSION (platform, minos), LC_VERSION_MIN_MACOSX (version): xxxx.yy.zz
            version = struct.unpack_from("<I", data, offset + (12 if cmd == 0x32 else 8))[0]
            minos = (version >> 16, (version >> 8) & 0xFF)
        if cmd == 0x2:  # LC_SYMTAB
            symoff, nsyms, stroff, _strsize = struct.unpack_from("<IIII", data, offset + 8)
            for k in range(nsyms):
                strx, ntype = struct.unpack_from("<IB", data, base + symoff + 16 * k)
                if not ntype & 0xE0 and ntype & 0x0E == 0x0E and ntype & 0x01 and not ntype & 0x10:
                    start = base + stroff + strx
                    names.add(data[start:data.index(b"\0", start)].decode()[1:])
        offset += size
    return cputype, filetype, names, minos


def macho_fat(data: bytes) -> list[tuple[int, int, int, int]]:
    """(cputype, offset, size, align) of each slice of a universal Mach-O file (big-endian fat header)."""
    magic, count = struct.unpack_from(">II", data)
    assert magic == 0xCAFEBABE
    return [struct.unpack_from(">iiIII", data, 8 + 20 * k)[0:1] + struct.unpack_from(">iiIII", data, 8 + 20 * k)[2:]
            for k in range(count)]


def test_each_fmu_carries_a_binary_for_every_platform(unzipped):
    fmi2 = {p.parent.name: p.name for p in (unzipped[2] / "binaries").glob("*/*")}
    fmi3 = {p.parent.name: p.name for p in (unzipped[3] / "binaries").glob("*/*")}
    assert fmi2 == {"linux64": "cam.so", "aarch64-linux": "cam.so", "win64": "cam.dll", "darwin64": "cam.dylib"}
    assert fmi3 == {"x86_64-linux": "cam.so", "aarch64-linux": "cam.so", "x86_64-windows": "cam.dll",
                    "x86_64-darwin": "cam.dylib", "aarch64-darwin": "cam.dylib"}
    assert {t.fmi2 for t in targets.TARGETS} == set(FMI2_FOLDERS) and {t.fmi3 for t in targets.TARGETS} == set(fmi3)


@pytest.fixture(scope="module")
def engine_libraries(tmp_path_factory) -> dict[str, Path]:
    """libcamdrive built for every target (the wheels' platforms), with zig."""
    folder = tmp_path_factory.mktemp("libcamdrive")
    return {name: engine_build.build_for(name, folder / name) for name in targets.NAMES}


def _linux_binaries(unzipped, engine_libraries) -> list[tuple[Path, int]]:
    machine = {"x86_64-linux": EM_X86_64, "aarch64-linux": EM_AARCH64, "linux64": EM_X86_64}
    found = [(p, machine[p.parent.name]) for v in (2, 3) for p in (unzipped[v] / "binaries").glob("*linux*/*.so")]
    return found + [(engine_libraries[n], machine[n]) for n in ("x86_64-linux", "aarch64-linux")]


def test_every_linux_binary_is_for_its_architecture_and_needs_glibc_2_17_at_most(unzipped, engine_libraries):
    """cam.so in linux64/x86_64-linux and aarch64-linux of both FMUs, and the engine library of both: the ELF
    machine of the folder, no GLIBC_ version above 2.17 (the manylinux2014 floor)."""
    binaries = _linux_binaries(unzipped, engine_libraries)
    assert len(binaries) == 6
    for path, machine in binaries:
        assert elf_machine(path) == machine, path
        newest = max(glibc_versions(path))
        assert newest <= (2, 17), f"{path} needs GLIBC_{'.'.join(map(str, newest))}"


def test_the_windows_binaries_are_x86_64_and_export_exactly_the_fmi_functions(unzipped, engine_libraries):
    for version, folder in ((2, "win64"), (3, "x86_64-windows")):
        machine, exports, dlls = pe_machine_and_exports(unzipped[version] / "binaries" / folder / "cam.dll")
        assert machine == 0x8664 and exports == _required(version), version
        # Windows' own DLLs only: KERNEL32 and the Universal C Runtime (part of Windows 10 and later)
        assert all(d == "KERNEL32.dll" or d.startswith("api-ms-win-crt-") for d in dlls), dlls
    machine, exports, _ = pe_machine_and_exports(engine_libraries["x86_64-windows"])
    assert machine == 0x8664 and "cam_law_eval" in exports


def test_the_macos_binaries_are_dylibs_of_their_architecture_exporting_the_fmi_functions(unzipped, engine_libraries):
    """FMI 3.0: one thin dylib per tuple. FMI 2.0's darwin64: one universal file, an x86_64 and an arm64 slice at
    16 KiB-aligned offsets, inside the file and not overlapping, each exporting exactly the FMI 2.0 functions.
    Each loads on macOS 10.13 (Intel) or 11.0 (Apple silicon, its first) and later."""
    minimum = {CPU_X86_64: (10, 13), CPU_ARM64: (11, 0)}
    for folder, cputype in (("x86_64-darwin", CPU_X86_64), ("aarch64-darwin", CPU_ARM64)):
        found, filetype, names, minos = macho_thin((unzipped[3] / "binaries" / folder / "cam.dylib").read_bytes())
        assert (found, filetype, minos) == (cputype, 6, minimum[cputype])  # MH_DYLIB
        assert names - LINKER_SYMBOLS == _required(3)
    data = (unzipped[2] / "binaries" / "darwin64" / "cam.dylib").read_bytes()
    slices = macho_fat(data)
    assert sorted(s[0] for s in slices) == [CPU_X86_64, CPU_ARM64]
    end = 8 + 20 * len(slices)
    for cputype, offset, size, align in sorted(slices, key=lambda s: s[1]):
        assert offset % (1 << align) == 0 and align >= 12 and offset >= end and offset + size <= len(data)
        end = offset + size
        found, filetype, names, minos = macho_thin(data, offset)
        assert (found, filetype, minos) == (cputype, 6, minimum[cputype]) and names - LINKER_SYMBOLS == _required(2)
    for name, cputype in (("x86_64-darwin", CPU_X86_64), ("aarch64-darwin", CPU_ARM64)):
        found, _, names, minos = macho_thin(engine_libraries[name].read_bytes())
        assert found == cputype and minos == minimum[cputype] and "cam_law_eval" in names


def test_the_fat_merger_refuses_what_is_not_two_thin_architectures(unzipped, tmp_path):
    thin = unzipped[3] / "binaries" / "x86_64-darwin" / "cam.dylib"
    with pytest.raises(macho.MachOError, match="one architecture"):
        macho.merge([thin, thin], tmp_path / "twice.dylib")
    with pytest.raises(macho.MachOError, match="not a thin 64-bit Mach-O"):
        macho.merge([thin, unzipped[3] / "binaries" / "x86_64-linux" / "cam.so"], tmp_path / "elf.dylib")


def test_the_engine_library_gets_the_name_its_platform_loads():
    """build_for writes libcamdrive-<digest><suffix of the row>; this machine's loader looks for its own suffix."""
    digest = engine_build.digest()
    assert {n: engine_build.library_name(target=n) for n in targets.NAMES} == {
        "x86_64-linux": f"libcamdrive-{digest}.so", "aarch64-linux": f"libcamdrive-{digest}.so",
        "x86_64-windows": f"libcamdrive-{digest}.dll", "x86_64-darwin": f"libcamdrive-{digest}.dylib",
        "aarch64-darwin": f"libcamdrive-{digest}.dylib"}
    assert engine_build.library_name() == f"libcamdrive-{digest}.so" and targets.host().name == "x86_64-linux"


# --------------------------------------------------------------------------- aarch64 under qemu-user
def _host_run(cmd: list[str]) -> list[dict]:
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900, env={"PATH": "/usr/bin:/bin"})
    lines = [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
    assert proc.returncode == 0 and lines and lines[-1] == {"exit": 0}, proc.stdout[-2000:] + proc.stderr[-2000:]
    return lines


@pytest.fixture(scope="module")
def aarch64_hosts(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("aarch64_hosts")
    return {"host": zig_host("aarch64-linux", folder / "host", HOST_C),
            "host3": zig_host("aarch64-linux", folder / "host3", HOST3_C),
            "me_host": zig_host("aarch64-linux", folder / "me_host", ME_HOST_C, "-DME_HOST_DYNAMIC"),
            "x86_64": compile_host(folder / "host_x86_64")}


@pytest.mark.parametrize("scene", sorted(PLATFORM_SCENES))
def test_the_aarch64_binary_agrees_with_x86_64_under_qemu(unzipped, aarch64_hosts, scene):
    """The C host (tests/native_host/host.c) built for aarch64 by zig dlopens binaries/aarch64-linux/cam.so under
    qemu-aarch64: the same statuses as x86_64's linux64/cam.so, outputs to 1e-12 relative, and a state saved,
    serialised and restored gives the same bits as the run it was saved from."""
    fmu, vr = unzipped[2], _vr(unzipped[2])
    outputs = ",".join(vr[n] for n in ("omega", "theta", "s", "v", "i", "M", "J", "N_contact"))
    commands = ["guid", _guid(fmu), "inst", *scene_commands(scene, vr), "init", "step", "500", "0.001", "save", "serial", "getr", outputs,
                "step", "1500", "0.001", "getr", outputs, "restore", "step", "1500", "0.001", "getr", outputs, "free"]
    runs = {}
    for name, cmd in (("x86_64", [str(aarch64_hosts["x86_64"]), str(fmu / "binaries" / "linux64" / "cam.so")]),
                      ("aarch64", [*runner("aarch64-linux"), str(aarch64_hosts["host"]),
                                   str(fmu / "binaries" / "aarch64-linux" / "cam.so")])):
        runs[name] = _host_run([*cmd, str(fmu / "resources"), *commands])
    x86, arm = runs["x86_64"], runs["aarch64"]
    assert [(c.get("cmd"), c.get("status")) for c in arm] == [(c.get("cmd"), c.get("status")) for c in x86]
    assert all(c.get("status", 0) == 0 for c in arm)
    values = {name: [c["values"] for c in lines if c.get("cmd") == "getr"] for name, lines in runs.items()}
    assert len(values["aarch64"]) == 3 and values["aarch64"][2] == values["aarch64"][1]  # restored: the same bits
    for row_a, row_x in zip(values["aarch64"], values["x86_64"]):
        for a, x in zip(row_a, row_x):
            assert a == pytest.approx(x, rel=1e-12, abs=1e-15)
    assert values["x86_64"][1][1] > 5.0  # theta(2 s) [rad]: the cam turned


def test_the_aarch64_model_exchange_and_fmi3_binaries_agree_under_qemu(unzipped, aarch64_hosts, tmp_path):
    """tests/engine_c/me_host.c (explicit Euler with events, a saved state, refusals) and tests/native_host/host3.c
    (FMI 3.0: instance cycles, states, refusals) built for aarch64 and run under qemu on the aarch64 binaries of
    cam.fmu and cam3.fmu: the same events, statuses and restored states as on x86_64; final values to 1e-12."""
    from test_engine_fmu_me_host import BACKLASH, STEP, STOP, VR

    me = {}
    for name, lib, cmd in (("x86_64", "linux64", [str(compile_me_host(tmp_path))]),
                           ("aarch64", "aarch64-linux", [*runner("aarch64-linux"), str(aarch64_hosts["me_host"])])):
        env = {"PATH": "/usr/bin:/bin", "CAM_FMU_LIBRARY": str(unzipped[2] / "binaries" / lib / "cam.so"),
               "CAM_FORMULATION_VR": str(VR["formulation"])}
        proc = subprocess.run([*cmd, _guid(unzipped[2]), str(STEP), str(STOP), *BACKLASH], capture_output=True,
                              text=True, env=env, timeout=900)
        assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
        me[name] = {line.split()[0]: line.split()[1:] for line in proc.stdout.splitlines()}
    assert int(me["x86_64"]["events"][0]) >= 3 and me["aarch64"]["events"] == me["x86_64"]["events"]
    assert me["aarch64"]["refused"] == me["x86_64"]["refused"] == ["3", "3", "3", "3"]
    for a, x in zip(map(float, me["aarch64"]["final"]), map(float, me["x86_64"]["final"])):
        assert a == pytest.approx(x, rel=1e-12, abs=1e-300)

    fmu3, vr = unzipped[3], _vr(unzipped[3])
    x86_host3 = tmp_path / "host3"
    done = subprocess.run([require("gcc"), "-std=c99", "-O1", f"-I{engine_build.fmi_headers(3)}", str(HOST3_C), "-o",
                           str(x86_host3), "-ldl"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    args = [_guid(fmu3), vr["theta"], vr["u"], vr["c"], "2"]
    runs = {}
    for name, cmd in (("x86_64", [str(x86_host3), str(fmu3 / "binaries" / "x86_64-linux" / "cam.so")]),
                      ("aarch64", [*runner("aarch64-linux"), str(aarch64_hosts["host3"]),
                                   str(fmu3 / "binaries" / "aarch64-linux" / "cam.so")])):
        proc = subprocess.run([*cmd, *args], capture_output=True, text=True, timeout=900, env={"PATH": "/usr/bin:/bin"})
        assert proc.returncode == 0, (name, proc.stderr[-2000:])
        runs[name] = [line for line in proc.stdout.splitlines() if not line.startswith("log ")]
    assert [line.split()[0] for line in runs["aarch64"]] == [line.split()[0] for line in runs["x86_64"]]
    restored = {name: [line.split() for line in lines if line.startswith("restored ")] for name, lines in runs.items()}
    assert len(restored["aarch64"]) == 2 and all(r[1] == "same" for r in restored["aarch64"] + restored["x86_64"])
    for a, x in zip(restored["aarch64"], restored["x86_64"]):
        theta_a, theta_x = float.fromhex(a[2]), float.fromhex(x[2])
        assert theta_x > 0.5 and abs(theta_a - theta_x) <= 1e-12 * theta_x
    for status in ("set-c 0", "init 0", "nan-input 3", "wrong-time 3", "null-get 3", "terminate 0 reset 0"):
        assert runs["aarch64"].count(status) == runs["x86_64"].count(status) == 2, status


def compile_me_host(folder: Path) -> Path:
    """me_host.c for x86_64 with gcc, loading the FMI functions from CAM_FMU_LIBRARY."""
    exe = folder / "me_host"
    proc = subprocess.run([require("gcc"), "-std=c99", "-O1", "-DME_HOST_DYNAMIC", f"-I{engine_build.fmi_headers(2)}",
                           "-o", str(exe), str(ME_HOST_C), "-ldl", "-lm"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return exe


# --------------------------------------------------------------------------- the sources, for every other platform
def _steps(host: Path, fmu: Path, library: Path) -> list[list[float]]:
    vr = _vr(fmu)
    outputs = ",".join(vr[n] for n in ("omega", "theta", "i"))
    lines = _host_run([str(host), str(library), str(fmu / "resources"), "guid", _guid(fmu), "inst", "setr", vr["c"],
                       "0.002", "init", "step", "300", "0.001", "getr", outputs, "free"])
    return [c["values"] for c in lines if c.get("cmd") == "getr"]


def test_the_sources_compile_with_a_plain_cc_and_run_as_the_shipped_binary(unzipped, tmp_path):
    """`cc -shared -fPIC sources/*.c -lm` with no flag or define (guid.h carries the GUID), loaded by the C host:
    300 steps with backlash equal to the shipped linux64 binary's to 1e-12 relative."""
    fmu = unzipped[2]
    library = tmp_path / "cam.so"
    proc = subprocess.run([require("cc"), "-shared", "-fPIC", *map(str, sorted((fmu / "sources").glob("*.c"))), "-o",
                           str(library), "-lm"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    host = compile_host(tmp_path / "host")
    rebuilt, shipped = _steps(host, fmu, library), _steps(host, fmu, fmu / "binaries" / "linux64" / "cam.so")
    assert len(rebuilt) == 1 and rebuilt[0][1] > 0.05
    assert rebuilt[0] == pytest.approx(shipped[0], rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("version", [2, 3])
def test_fmpy_builds_the_binary_from_the_build_description(unzipped, tmp_path, version):
    """fmpy.build.build_platform_binary (CMake) reads the files to compile from <SourceFiles> (FMI 2.0) or
    sources/buildDescription.xml (FMI 3.0), with the shipped binaries removed; fmpy then simulates the rebuilt
    FMU as it does the shipped one: theta, omega, i after 0.3 s with backlash to 1e-12 relative."""
    from fmpy import read_model_description, simulate_fmu
    from fmpy.build import build_platform_binary

    require("cmake")
    folder = tmp_path / "fmu"
    shutil.copytree(unzipped[version], folder)
    shutil.rmtree(folder / "binaries")
    md = read_model_description(str(folder))
    files = md.buildConfigurations[0].sourceFileSets[0].sourceFiles
    assert files == sorted(p.name for p in (folder / "sources").glob("*.c")) and "binding.c" in files
    (tmp_path / "build").mkdir()
    build_platform_binary(folder, build_dir=tmp_path / "build")
    built = list((folder / "binaries").glob("*/cam.so"))
    assert [p.parent.name for p in built] == ["linux64" if version == 2 else "x86_64-linux"]
    kwargs = dict(stop_time=0.3, output_interval=1e-3, start_values={"c": 0.002}, output=["theta", "omega", "i"])
    rebuilt, shipped = simulate_fmu(str(folder), **kwargs), simulate_fmu(str(unzipped[version]), **kwargs)
    assert rebuilt["theta"][-1] > 0.05
    for name in ("theta", "omega", "i"):
        assert rebuilt[name] == pytest.approx(shipped[name], rel=1e-12, abs=1e-15), name


def test_an_unknown_platform_is_refused_naming_the_allowed_ones(tmp_path):
    import sys

    proc = subprocess.run([sys.executable, str(HERE.parent / "build_fmu.py"), "--platforms", "riscv64-linux", "--dest",
                           str(tmp_path / "cam.fmu")], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 1 and not (tmp_path / "cam.fmu").exists()
    assert "'riscv64-linux'" in proc.stderr and all(name in proc.stderr for name in targets.NAMES), proc.stderr
