"""The compiled drive kernel: its build, its place in cam.fmu, and the pure-Python fallback.

Cython and a C compiler are required (setup.sh installs both): their absence
fails these tests, it never skips them.
"""
from __future__ import annotations

import importlib.util
import json
import math
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from cam_fmu.kernel import COMPILED_MODULES
from cam_fmu.kernel import compile as kernel_compile
from cam_fmu.kernel.compile import EXT_SUFFIX, KernelBuildError, build_extension

ROOT = Path(__file__).resolve().parents[1]
KERNEL_DIR = ROOT / "cam_fmu" / "kernel"
WRONG_ABI = ".cpython-399-x86_64-linux-gnu.so"  # an extension of another Python: never imported by this one


def _env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PYTHONPATH"] = str(ROOT)  # this checkout, whatever is installed
    return env


def _run(code: str, *args: str, cwd: Path = ROOT, isolated: bool = False) -> dict:
    """Run ``code`` in a fresh interpreter and return the JSON it prints last."""
    cmd = [sys.executable, *(["-I"] if isolated else []), "-c", code, *args]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd, env=_env(), timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


# --------------------------------------------------------------------------- the build
@pytest.fixture(scope="module")
def extensions() -> list[Path]:
    return build_extension()  # in place, as setup.sh does; cheap when current


def test_extension_builds_beside_the_py_and_a_fresh_process_uses_it(extensions):
    assert extensions == [KERNEL_DIR / f"{m}{EXT_SUFFIX}" for m in COMPILED_MODULES]
    assert all(p.is_file() for p in extensions)
    r = _run("import json, cam_fmu.kernel as k\nfrom cam_fmu.kernel import drive_kernel as d\n"
             "print(json.dumps({'compiled': k.compiled(), 'file': d.__file__}))")
    assert r["compiled"] is True and r["file"] == str(extensions[0])


def test_a_current_extension_is_not_rebuilt_and_a_newer_pxd_makes_it_stale(extensions, tmp_path):
    before = [p.stat().st_mtime_ns for p in extensions]
    assert build_extension() == extensions
    assert [p.stat().st_mtime_ns for p in extensions] == before
    # a copy with the mtimes kept: current; a .pxd edited later: stale (the .py alike)
    for name in COMPILED_MODULES:
        for suffix in (".py", ".pxd", EXT_SUFFIX):
            shutil.copy2(KERNEL_DIR / f"{name}{suffix}", tmp_path / f"{name}{suffix}")
        assert kernel_compile.is_current(name, tmp_path)
        ext = tmp_path / f"{name}{EXT_SUFFIX}"
        for suffix in (".pxd", ".py"):
            later = ext.stat().st_mtime + 10
            os.utime(tmp_path / f"{name}{suffix}", (later, later))
            assert not kernel_compile.is_current(name, tmp_path), suffix
            os.utime(ext, (later + 1, later + 1))


def test_missing_tools_are_clear_errors(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "Cython", None)  # import Cython -> ImportError
    with pytest.raises(KernelBuildError, match="Cython is not installed"):
        build_extension()  # even with a current extension: the build never falls back silently
    monkeypatch.delitem(sys.modules, "Cython")
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))  # no cc, gcc or clang
    with pytest.raises(KernelBuildError, match="no C compiler"):
        kernel_compile.find_compiler()
    (tmp_path / "k").mkdir()
    (tmp_path / "k" / "lonely.py").write_text("X = 1\n")
    monkeypatch.undo()
    with pytest.raises(KernelBuildError, match=r"lonely\.pxd does not exist"):
        build_extension(tmp_path / "k", modules=("lonely",))


def test_an_extension_compiled_as_cam_fmu_loads_under_a_private_name_but_leaks_its_public_one(tmp_path):
    """Why the FMU compiles its own copy of the kernel under the private name.

    An extension compiled as ``cam_fmu.kernel.probe`` loads as ``cam_fmu_<hash>.kernel.probe``
    (PyInit_probe depends on the last name component only) and its relative imports resolve
    under the private name; but Cython's module init also enters it into sys.modules as
    ``cam_fmu.kernel.probe``, a public name that would shadow a host's own cam_fmu.
    """
    src = tmp_path / "src" / "cam_fmu"
    (src / "kernel").mkdir(parents=True)
    for name in ("__init__.py", "errors.py", "kernel/__init__.py"):
        shutil.copy2(ROOT / "cam_fmu" / name, src / name)
    (src / "kernel" / "probe.py").write_text(
        "from ..errors import SimulationError\nfrom . import COMPILED_MODULES\n\n\n"
        "def where():\n    return [SimulationError.__module__, __name__, __package__, list(COMPILED_MODULES)]\n")
    (src / "kernel" / "probe.pxd").write_text("cpdef list where()\n")
    [ext] = build_extension(src / "kernel", modules=("probe",))
    private = tmp_path / "fmu" / "cam_fmu_deadbeef"
    shutil.copytree(src, private)
    (private / "kernel" / "probe.py").unlink()  # only the extension can answer
    r = _run("import json, sys\nsys.path.insert(0, sys.argv[1])\nimport cam_fmu_deadbeef.kernel.probe as p\n"
             "print(json.dumps({'file': p.__file__, 'where': p.where(), 'cam_fmu': 'cam_fmu' in sys.modules,\n"
             "                  'leaked': sys.modules.get('cam_fmu.kernel.probe') is p}))",
             str(tmp_path / "fmu"), cwd=tmp_path, isolated=True)
    assert r["file"].endswith(ext.name)
    assert r["where"] == ["cam_fmu_deadbeef.errors", "cam_fmu_deadbeef.kernel.probe", "cam_fmu_deadbeef.kernel",
                          list(COMPILED_MODULES)]
    assert r["cam_fmu"] is False
    assert r["leaked"] is True  # the reason for compile_kernel in fmu/native/compile.py


# --------------------------------------------------------------------------- cam.fmu
def _private_package(fmu: Path) -> str:
    with zipfile.ZipFile(fmu) as z:
        return dict(line.split("=", 1) for line in z.read("resources/native.txt").decode().split())["package"]


def _kernel_entries(fmu: Path) -> set[str]:
    pkg = _private_package(fmu)
    with zipfile.ZipFile(fmu) as z:
        return {n[len(f"resources/{pkg}/"):] for n in z.namelist()
                if n.startswith(f"resources/{pkg}/kernel/")}


def _rewrite(fmu: Path, dest: Path, rename: dict[str, str | None]) -> Path:
    """A copy of ``fmu`` with entries renamed (None: removed)."""
    with zipfile.ZipFile(fmu) as zin, zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in zin.infolist():
            name = rename.get(info.filename, info.filename)
            if name is not None:
                data = zin.read(info)
                info.filename = name
                zout.writestr(info, data)
    return dest


@pytest.fixture(scope="module")
def pure_fmu(tmp_path_factory) -> Path:
    dest = tmp_path_factory.mktemp("pure_fmu") / "cam.fmu"
    proc = subprocess.run([sys.executable, str(ROOT / "build_fmu.py"), "--pure-python", "--dest", str(dest)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert proc.returncode == 0 and dest.is_file(), proc.stdout + proc.stderr
    return dest


@pytest.fixture(scope="module")
def fallback_fmus(cam_fmu_path, tmp_path_factory) -> dict[str, Path]:
    """cam.fmu with its extension deleted, and renamed to another Python's ABI tag."""
    pkg = _private_package(cam_fmu_path)
    names = {f"resources/{pkg}/kernel/{m}{EXT_SUFFIX}": f"resources/{pkg}/kernel/{m}{WRONG_ABI}"
             for m in COMPILED_MODULES}
    folder = tmp_path_factory.mktemp("fallback_fmus")
    return {"deleted": _rewrite(cam_fmu_path, folder / "deleted.fmu", dict.fromkeys(names)),
            "wrong_abi": _rewrite(cam_fmu_path, folder / "wrong_abi.fmu", names)}


def test_cam_fmu_bundles_the_extension_beside_the_py(cam_fmu_path):
    entries = _kernel_entries(cam_fmu_path)
    for name in COMPILED_MODULES:
        assert {f"kernel/{name}.py", f"kernel/{name}{EXT_SUFFIX}"} <= entries, entries
    assert "kernel/__init__.py" in entries


def test_pure_python_fmu_has_no_extension_and_its_own_package_name(pure_fmu, cam_fmu_path):
    entries = _kernel_entries(pure_fmu)
    assert {f"kernel/{m}.py" for m in COMPILED_MODULES} <= entries
    with zipfile.ZipFile(pure_fmu) as z:
        assert not [n for n in z.namelist() if n.startswith("resources/") and n.endswith((".so", ".pyd"))]
    # the private name hashes the extension: both FMUs can share one host process
    assert _private_package(pure_fmu) != _private_package(cam_fmu_path)


KERNEL_FILE = r"""
import json, sys, zipfile, importlib
before = set(sys.modules)
with zipfile.ZipFile(sys.argv[1]) as z:
    z.extractall("x")
    pkg = dict(l.split("=", 1) for l in z.read("resources/native.txt").decode().split())["package"]
sys.path.insert(0, "x/resources")
kernel = importlib.import_module(pkg + ".kernel")
files = {m: importlib.import_module(pkg + ".kernel." + m).__file__ for m in kernel.COMPILED_MODULES}
print(json.dumps({"compiled": kernel.compiled(), "files": files,
                  "public": sorted(m for m in set(sys.modules) - before
                                   if m.startswith("cam") and m != pkg and not m.startswith(pkg + "."))}))
"""


def test_the_bundled_kernel_loads_compiled_under_the_private_name_else_the_py(cam_fmu_path, fallback_fmus,
                                                                                 tmp_path):
    """Python prefers the extension to the .py beside it, and ignores an extension of another ABI."""
    for label, fmu, compiled, suffix in (("compiled", cam_fmu_path, True, EXT_SUFFIX),
                                         ("wrong_abi", fallback_fmus["wrong_abi"], False, ".py"),
                                         ("deleted", fallback_fmus["deleted"], False, ".py")):
        (tmp_path / label).mkdir()
        r = _run(KERNEL_FILE, str(fmu), cwd=tmp_path / label, isolated=True)
        assert r["compiled"] is compiled, (label, r)
        assert all(f.endswith(suffix) for f in r["files"].values()), (label, r)
        assert r["public"] == [], (label, r)  # only private names: nothing shadows a host's own cam_fmu


SIMULATE = r"""
import json, sys
from fmpy import simulate_fmu
res = simulate_fmu(sys.argv[1], stop_time=0.2, output=["theta", "omega"])
print(json.dumps({n: [float(x) for x in res[n]] for n in ("time", "theta", "omega")}))
"""


def test_fmus_without_a_loadable_extension_simulate_the_same(cam_fmu_path, pure_fmu, fallback_fmus, tmp_path):
    runs = {}
    for label, fmu in {"compiled": cam_fmu_path, "pure": pure_fmu, **fallback_fmus}.items():
        (tmp_path / label).mkdir()
        copy = shutil.copyfile(fmu, tmp_path / label / "cam.fmu")
        runs[label] = _run(SIMULATE, str(copy), cwd=tmp_path / label)
    ref = runs.pop("compiled")
    assert ref["time"][-1] == pytest.approx(0.2) and ref["omega"][-1] > 0.0
    for label, run in runs.items():
        assert run["time"] == ref["time"], label
        for name in ("theta", "omega"):
            assert run[name] == pytest.approx(ref[name], rel=1e-12, abs=0.0), (label, name)


# --------------------------------------------------------------------------- compiled == pure, in process
@pytest.fixture(scope="module")
def kernels(extensions):
    from cam_fmu import kernel
    from cam_fmu.kernel import drive_kernel

    assert kernel.compiled(), f"the compiled kernel is not in use ({drive_kernel.__file__}): run setup.sh"
    name = "cam_fmu.kernel._drive_kernel_pure"  # inside the package: relative imports resolve
    spec = importlib.util.spec_from_file_location(name, KERNEL_DIR / "drive_kernel.py")
    pure = importlib.util.module_from_spec(spec)
    sys.modules[name] = pure
    try:
        spec.loader.exec_module(pure)
    finally:
        del sys.modules[name]
    assert pure.__file__.endswith(".py") and not drive_kernel.__file__.endswith(".py")
    return drive_kernel, pure


def _programs():
    from cam_fmu.kinematics.cam_program import CamProgram, paper_program

    two_pi = 2.0 * math.pi
    dwells = CamProgram("modified_trapezoid", "cycloidal", 0.02, rise_angle=two_pi * 100 / 360,
                        upper_dwell=two_pi * 60 / 360, return_angle=two_pi * 120 / 360,
                        lower_dwell=two_pi * 80 / 360)
    return {"paper": paper_program(), "dwells": dwells}


def _angles(program) -> list[float]:
    two_pi = 2.0 * math.pi
    angles = [-two_pi + k * 3.0 * two_pi / 397 for k in range(398)]  # over [-2 pi, 4 pi]
    for p in program.breakpoints():  # the breakpoints and their neighbours, one turn either side
        for turn in (-1, 0, 1):
            a = p + turn * two_pi
            angles += [a, math.nextafter(a, -math.inf), math.nextafter(a, math.inf)]
    return angles + [0.0, -0.0, -1e-300, two_pi, -two_pi, 1e6]


def _bits(values) -> list[str]:
    return [float(v).hex() for v in values]


@pytest.mark.parametrize("label", ["paper", "dwells"])
def test_compiled_and_pure_python_profiles_agree_bit_for_bit(kernels, label):
    compiled, pure = kernels
    program = _programs()[label]
    fast, slow = compiled.Profile(program), pure.Profile(program)
    angles = _angles(program)
    assert len(angles) >= 300
    differ = [(a, fast.derivatives(a), slow.derivatives(a)) for a in angles
              if _bits(fast.derivatives(a)) != _bits(slow.derivatives(a))]
    assert differ == [], differ[:5]
    spans = [(a, a + d) for a in angles[::7] for d in (0.3, -0.3, 7.0, -7.0, 0.0)]
    assert [_bits([fast.first_breakpoint(*s)]) for s in spans] == [_bits([slow.first_breakpoint(*s)]) for s in spans]


# --------------------------------------------------------------------------- both paths, every scene
EVERY_SCENE = r"""
import json, sys
from cam_fmu.experiments.runner import run_scene
from cam_fmu.experiments.scenes import SCENE_DIR, load_scene
out = {}
for path in sorted(SCENE_DIR.glob("*.toml")):
    scene = load_scene(path)
    for label, result in run_scene(scene, "fmu", sys.argv[1]).items():
        out[scene.name + "/" + label] = {name: [float(x) for x in values] for name, values in result.items()}
print(json.dumps(out))
"""


def test_compiled_and_pure_python_fmus_agree_on_every_scene(cam_fmu_path, pure_fmu, tmp_path):
    """Every output of every run of every shipped scene, cam.fmu (compiled kernel) against the
    pure-Python build: equal to 1e-12 relative (they run the same IEEE operations; measured: equal
    to the bit)."""
    runs = {}
    for label, fmu in (("compiled", cam_fmu_path), ("pure", pure_fmu)):
        (tmp_path / label).mkdir()
        runs[label] = _run(EVERY_SCENE, str(fmu), cwd=tmp_path / label)
    compiled, pure = runs["compiled"], runs["pure"]
    assert sorted(compiled) == sorted(pure) and len(compiled) >= 14
    for key, outputs in compiled.items():
        assert outputs["time"] == pure[key]["time"], key
        for name, values in outputs.items():
            assert values == pytest.approx(pure[key][name], rel=1e-12, abs=1e-300), (key, name)
