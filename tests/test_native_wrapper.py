"""The project's Python-hosting linux64 binary (cam_fmu/fmu/native), on pi_speed.fmu, the FMU that uses it:
loading, statuses, state, leaks, isolation.

The native side is driven by tests/native_host/host.c, compiled here and run with an
empty environment (``env -i PATH=/usr/bin:/bin``): dlopen(RTLD_LOCAL), no libpython
preloaded, no PYTHONHOME/PYTHONPATH. The Python side runs fmpy in subprocesses. (cam.fmu's
binary is the C engine: tests/test_engine_fmu_c_host.py and tests/test_fmi_boundary.py.)
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from native_support import (EMPTY_ENV, ROOT, compile_host, extract, require, run_host, run_python,
                            value_references, valgrind_prefix, valgrind_summary)

FMI2_CS_FUNCTIONS = """fmi2GetTypesPlatform fmi2GetVersion fmi2SetDebugLogging fmi2Instantiate fmi2FreeInstance
fmi2SetupExperiment fmi2EnterInitializationMode fmi2ExitInitializationMode fmi2Terminate fmi2Reset fmi2GetReal
fmi2GetInteger fmi2GetBoolean fmi2GetString fmi2SetReal fmi2SetInteger fmi2SetBoolean fmi2SetString
fmi2GetFMUstate fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize fmi2SerializeFMUstate
fmi2DeSerializeFMUstate fmi2GetDirectionalDerivative fmi2SetRealInputDerivatives fmi2GetRealOutputDerivatives
fmi2DoStep fmi2CancelStep fmi2GetStatus fmi2GetRealStatus fmi2GetIntegerStatus fmi2GetBooleanStatus
fmi2GetStringStatus""".split()


@pytest.fixture(scope="module")
def fmu_dir(pi_speed_fmu_path, tmp_path_factory) -> Path:
    return extract(pi_speed_fmu_path, tmp_path_factory.mktemp("native_fmu"))


@pytest.fixture(scope="module")
def host(tmp_path_factory) -> Path:
    return compile_host(tmp_path_factory.mktemp("native_host") / "host")


@pytest.fixture(scope="module")
def vr(fmu_dir):
    return value_references(fmu_dir)


def _status(result, cmd):
    return [x["status"] for x in result["cmds"] if x["cmd"] == cmd]


# --------------------------------------------------------------------------- the binary
def test_binary_needs_no_libpython_at_link_time(fmu_dir):
    """No Py* symbol is undefined (OMSimulator's 'undefined symbol: _Py_NoneStruct' cannot happen)."""
    nm = require("nm")
    so = fmu_dir / "binaries" / "linux64" / "pi_speed.so"
    undefined = subprocess.run([nm, "-D", "--undefined-only", str(so)], capture_output=True, text=True).stdout
    assert not [line for line in undefined.split() if line.startswith(("Py", "_Py"))], undefined
    needed = subprocess.run(["readelf", "-d", str(so)], capture_output=True, text=True).stdout
    assert "libpython" not in needed
    exported = subprocess.run([nm, "-D", "--defined-only", str(so)], capture_output=True, text=True).stdout.split()
    assert set(FMI2_CS_FUNCTIONS) <= set(exported)
    # pythonfmu's win64 binary is kept as it is (it cannot be built or tested here)
    assert (fmu_dir / "binaries" / "win64" / "pi_speed.dll").is_file()


def test_resources_record_python_and_private_names(fmu_dir):
    text = (fmu_dir / "resources" / "python.txt").read_text()
    keys = dict(line.split("=", 1) for line in text.splitlines() if "=" in line and not line.startswith("#"))
    assert Path(keys["libpython"]).is_file() and Path(keys["executable"]).is_file()
    assert keys["version"] == "%d.%d" % sys.version_info[:2]
    native = dict(line.split("=", 1) for line in (fmu_dir / "resources" / "native.txt").read_text().split())
    assert (fmu_dir / "resources" / native["package"] / "_fmi_bridge.py").is_file()
    assert (fmu_dir / "resources" / native["package"] / "_pythonfmu" / "fmi2slave.py").is_file()
    assert (fmu_dir / "resources" / f"{native['slave_module']}.py").is_file()
    assert not (fmu_dir / "resources" / "pythonfmu").exists()
    slave = (fmu_dir / "resources" / f"{native['slave_module']}.py").read_text()
    assert "from cam_fmu " not in slave and "from pythonfmu" not in slave


def test_build_stops_without_a_c_compiler(tmp_path):
    empty = tmp_path / "bin"
    empty.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("CC",)}
    env["PATH"] = str(empty)
    env["PYTHONPATH"] = str(ROOT)
    for model in ("pi_speed", "cam"):  # both binaries are compiled: no silent fallback
        proc = subprocess.run([sys.executable, str(ROOT / "build_fmu.py"), "--model", model,
                               "--dest", str(tmp_path / f"{model}.fmu")], capture_output=True, text=True, env=env,
                              cwd=tmp_path)
        assert proc.returncode != 0
        assert "no C compiler" in proc.stderr, proc.stderr
        assert not (tmp_path / f"{model}.fmu").exists()


# --------------------------------------------------------------------------- native host, empty environment
def test_c_host_empty_environment_matches_fmpy(fmu_dir, host, vr, pi_speed_fmu_path, tmp_path):
    outs = ["u", "error", "integral"]
    r = run_host(host, fmu_dir, "inst", "init", "setr", str(vr["omega_meas"]), "3.0", "step", "300", "0.001",
                 "getr", ",".join(str(vr[n]) for n in outs), "free")
    assert r["rc"] == 0 and r["lines"][-1] == {"exit": 0}, r
    native = next(x for x in r["cmds"] if x["cmd"] == "getr")["values"]
    shutil.copyfile(pi_speed_fmu_path, tmp_path / "pi_speed.fmu")
    ref = run_python(
        "import json, sys\nfrom fmpy import simulate_fmu\n"
        "r = simulate_fmu('pi_speed.fmu', start_values={'omega_meas': 3.0}, output_interval=1e-3, stop_time=0.3)\n"
        "print(json.dumps([float(r[n][-1]) for n in sys.argv[1:]]))", *outs, cwd=tmp_path)
    assert abs(native[2]) > 0.1  # the integrator has run: a saturated command is no proof
    # the same Python code; only the communication-point arithmetic differs (host: t += h, fmpy: t = k h)
    assert native == pytest.approx(ref, rel=1e-12, abs=1e-14)


def test_status_protocol_error_is_recoverable(fmu_dir, host, vr):
    r = run_host(host, fmu_dir, "inst", "init", "step", "20", "0.001", "save",
                 "setr", str(vr["omega_meas"]), "nan",  # bad input: fmi2Error
                 "step", "1", "0.001",               # not allowed after fmi2Error
                 "getr", str(vr["u"]),               # get* allowed
                 "restore", "step", "20", "0.001",   # fmi2SetFMUstate recovers
                 "setr", str(vr["omega_meas"]), "inf", "reset",  # fmi2Reset recovers too
                 "setr", str(vr["kp"]), "-1",        # bad parameter
                 "free", "free")                     # fmi2FreeInstance after fmi2Error, and with NULL
    assert r["rc"] == 0 and r["lines"][-1] == {"exit": 0}, r
    assert _status(r, "setr") == [3, 3, 3]
    assert _status(r, "step") == [0, 3, 0]
    assert _status(r, "restore") == [0] and _status(r, "reset") == [0]
    errors = [x for x in r["logs"] if x["log"] == 3]
    assert all(x["category"] == "logStatusError" for x in errors)
    assert any("'omega_meas'" in x["msg"] and "not finite" in x["msg"] for x in errors)  # logged, loggingOn false
    assert any("'kp'" in x["msg"] and "[0, 10000]" in x["msg"] for x in errors)  # its allowed range
    assert any("not allowed after fmi2Error" in x["msg"] for x in errors)
    assert not [x for x in r["logs"] if x["log"] == 4]                    # never fmi2Fatal


def test_state_get_set_serialise_bit_exact(fmu_dir, host, vr):
    outs = ",".join(str(vr[n]) for n in ("u", "error", "integral", "u_ff"))
    r = run_host(host, fmu_dir, "inst", "init", "setr", str(vr["omega_meas"]), "3.5", "step", "150", "0.001",
                 "save", "serial",                 # the restored state went through bytes
                 "step", "100", "0.001", "getr", outs,
                 "restore", "step", "100", "0.001", "getr", outs, "free")
    assert r["rc"] == 0, r
    first, second = [x["values"] for x in r["cmds"] if x["cmd"] == "getr"]
    assert first == second and first[2] != 0.0  # the integrator's state went through the bytes
    assert all(s == 0 for s in _status(r, "save") + _status(r, "serial") + _status(r, "restore"))


def test_no_python_found_gives_a_clear_message(fmu_dir, host):
    r = run_host(host, fmu_dir, "inst", env={**EMPTY_ENV, "CAM_FMU_PYTHON": "/nonexistent/python3"})
    assert r["rc"] == 0, r                      # the host itself survives
    assert r["cmds"][0] == {"cmd": "inst", "ok": False}
    msg = " ".join(x["msg"] for x in r["logs"])
    assert "CAM_FMU_PYTHON" in msg and "/nonexistent/python3" in msg and "python.txt" in msg


@pytest.mark.parametrize("which", ["executable", "libpython"])
def test_cam_fmu_python_overrides_python_txt(fmu_dir, host, tmp_path, which):
    """CAM_FMU_PYTHON (a python executable or a libpython) wins over resources/python.txt."""
    broken = tmp_path / "fmu"
    shutil.copytree(fmu_dir, broken)
    (broken / "resources" / "python.txt").write_text("libpython=/nonexistent/libpython3.so\n")
    bad = run_host(host, broken, "inst")
    assert bad["cmds"][0]["ok"] is False and "/nonexistent/libpython3.so" in bad["logs"][0]["msg"]
    import sysconfig
    target = sys.executable if which == "executable" else \
        os.path.join(sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("INSTSONAME"))
    good = run_host(host, broken, "inst", "init", "step", "10", "0.001", "free",
                    env={**EMPTY_ENV, "CAM_FMU_PYTHON": target})
    assert good["rc"] == 0 and good["cmds"][0]["ok"] is True, good
    assert _status(good, "step") == [0]


def test_instantiate_free_cycles_do_not_leak(fmu_dir, host):
    """1000 fmi2Instantiate/fmi2FreeInstance cycles (after 200 for warm-up) grow RSS by under 1 MB."""
    r = run_host(host, fmu_dir, "cycles", "200", "cycles", "1000")
    assert r["rc"] == 0, r
    cycles = [x for x in r["cmds"] if x["cmd"] == "cycles"][1]
    growth_kb = cycles["rss_end_kb"] - cycles["rss_after_20_kb"]
    print(f"RSS growth over cycles 21..1000 after warm-up: {growth_kb} kB")
    assert growth_kb < 1024, cycles


def test_c_host_under_valgrind(fmu_dir, host, vr, tmp_path):
    """memcheck: no invalid read/write/free and nothing definitely lost, from load to dlclose and exit."""
    log = tmp_path / "valgrind.log"
    env = {**EMPTY_ENV, "PYTHONMALLOC": "malloc"}
    watch = f"{vr['u']},{vr['integral']},{vr['omega_meas']}"  # answered from the exchange, in C
    r = run_host(host, fmu_dir, "inst", "getr", watch, "init", "setr", str(vr["omega_meas"]), "3.0", "step", "100",
                 "0.001", "getr", watch, "save", "serial", "restore", "getr", watch, "setr", str(vr["omega_meas"]), "nan",
                 "step", "1", "0.001", "reset", "init", "step", "10", "0.001", "getr", watch, "free", "cycles", "3",
                 env=env, prefix=valgrind_prefix(log))
    assert r["rc"] == 0 and r["lines"][-1] == {"exit": 0}, r
    assert [x["status"] for x in r["cmds"] if x["cmd"] == "getr"] == [0, 0, 0, 0], r
    summary = valgrind_summary(log)
    assert summary["summaries"] == 1 and summary["errors"] == 0 and summary["definitely_lost"] == 0, \
        summary["excerpt"]


# --------------------------------------------------------------------------- Python host (fmpy)
NO_FEEDTHROUGH = r"""
import json, sys
from fmpy import read_model_description, extract
from fmpy.fmi2 import FMU2Slave
md = read_model_description(sys.argv[1])
vr = {v.name: v.valueReference for v in md.modelVariables}
outs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(sys.argv[1]), modelIdentifier="pi_speed", instanceName="a")
fmu.instantiate(); fmu.setupExperiment(startTime=0.0); fmu.enterInitializationMode(); fmu.exitInitializationMode()
unchanged, changed_after_step, t = True, False, 0.0
for k in range(50):
    before = fmu.getReal(outs)
    fmu.setReal([vr["omega_meas"]], [3.5 if k % 2 else 3.0])
    fmu.setReal([vr["M_load"]], [0.1 * k])
    unchanged &= fmu.getReal(outs) == before     # a new input changes no output before fmi2DoStep
    fmu.doStep(t, 1e-3); t += 1e-3
    changed_after_step |= fmu.getReal(outs) != before
fmu.terminate(); fmu.freeInstance()
deps = {u.variable.name: u.dependencies for u in md.outputs}
print(json.dumps({"unchanged": unchanged, "changed_after_step": changed_after_step,
                  "deps": {k: [d.name for d in v] for k, v in deps.items()}, "n_outputs": len(outs)}))
"""


def test_outputs_have_no_direct_feedthrough(pi_speed_fmu_path, tmp_path):
    """dependencies="" on every output is the truth: a Jacobi master closing a loop needs no iteration."""
    shutil.copyfile(pi_speed_fmu_path, tmp_path / "pi_speed.fmu")
    r = run_python(NO_FEEDTHROUGH, str(tmp_path / "pi_speed.fmu"), cwd=tmp_path)
    assert r["unchanged"] and r["changed_after_step"]
    assert len(r["deps"]) == r["n_outputs"] and all(v == [] for v in r["deps"].values())
    with zipfile.ZipFile(pi_speed_fmu_path) as z:
        xml = z.read("modelDescription.xml").decode()
    assert xml.count('dependencies=""') == r["n_outputs"]


BATCHED = r"""
import json, sys
from fmpy import read_model_description, extract
from fmpy.fmi2 import FMU2Slave
md = read_model_description(sys.argv[1])
outs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
reals = [v.valueReference for v in md.modelVariables if v.causality == "parameter" and v.type == "Real"]
fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(sys.argv[1]), modelIdentifier="pi_speed", instanceName="a")
fmu.instantiate()
native = open(str(fmu.unzipDirectory) + "/resources/native.txt").read().split()
package = dict(x.split("=", 1) for x in native)["package"]
bridge = sys.modules[package + "._fmi_bridge"]
calls = {"get_real": 0, "set_real": 0, "slave_get": 0}
for name in ("get_real", "set_real"):
    original = getattr(bridge.Instance, name)
    def counting(self, *a, _o=original, _n=name):
        calls[_n] += 1
        return _o(self, *a)
    setattr(bridge.Instance, name, counting)
values = fmu.getReal(reals)
fmu.setReal(reals, values)
fmu.getReal(outs)
fmu.freeInstance()
print(json.dumps({"calls": calls, "n_get": len(reals) + len(outs), "n_set": len(reals)}))
"""


def test_get_set_real_of_n_variables_is_one_python_call(pi_speed_fmu_path, tmp_path):
    shutil.copyfile(pi_speed_fmu_path, tmp_path / "pi_speed.fmu")
    r = run_python(BATCHED, str(tmp_path / "pi_speed.fmu"), cwd=tmp_path)
    assert r["n_set"] >= 8
    assert r["calls"]["get_real"] == 2 and r["calls"]["set_real"] == 1, r


ISOLATION = r"""
import json, os, sys
sys.path.insert(0, sys.argv[3])                      # a host 'cam_fmu' that must never be used by the FMU
import cam_fmu                                       # (importing it is fine; the FMU must not run it)
from fmpy import simulate_fmu, read_model_description, extract
from fmpy.fmi2 import FMU2Slave
path0, modules0 = list(sys.path), set(sys.modules)
a = simulate_fmu(sys.argv[1], output_interval=1e-3, stop_time=0.05)
# two different builds alive at once, both with private names
fmus = []
for k, f in enumerate(sys.argv[1:3]):
    md = read_model_description(f)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(f), modelIdentifier="pi_speed", instanceName=f"i{k}")
    fmu.instantiate(); fmu.setupExperiment(startTime=0.0); fmu.enterInitializationMode(); fmu.exitInitializationMode()
    fmus.append((fmu, md))
private = sorted(m for m in sys.modules if m.startswith(("cam_fmu_", "pi_speed_fmu_slave_")) and "." not in m)
omegas = []
for fmu, md in fmus:
    vr = {v.name: v.valueReference for v in md.modelVariables}
    for k in range(20):
        fmu.doStep(k * 1e-3, 1e-3)
    omegas.append(fmu.getReal([vr["integral"]])[0])
for fmu, md in fmus:
    fmu.terminate(); fmu.freeInstance()
added = sorted(set(sys.modules) - modules0)
print(json.dumps({"private_while_alive": private, "omegas": omegas, "host_cam_fmu_used": cam_fmu.USED,
                  "added_after_free": [m for m in added if m.startswith(("cam", "pythonfmu"))],
                  "path_unchanged": sys.path == path0, "a_end": float(a["time"][-1])}))
"""


def test_isolated_from_host_cam_fmu_and_other_builds(pi_speed_fmu_path, tmp_path):
    """The FMU runs its own bundle under private names; sys.path/sys.modules are restored after the last free."""
    # a second, different build (one bundled file differs -> different hash -> different private names)
    pkg = tmp_path / "src" / "cam_fmu"
    shutil.copytree(ROOT / "cam_fmu", pkg, ignore=shutil.ignore_patterns("__pycache__"))
    sim = pkg / "control" / "pi.py"
    sim.write_text(sim.read_text(encoding="utf-8") + "\n# second build\n", encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, str(ROOT / "build_fmu.py"), "--model", "pi_speed", "--package-dir",
                           str(pkg), "--dest", str(tmp_path / "b" / "pi_speed.fmu")], capture_output=True, text=True,
                          env=env)
    assert proc.returncode == 0, proc.stderr
    (tmp_path / "a").mkdir()
    shutil.copyfile(pi_speed_fmu_path, tmp_path / "a" / "pi_speed.fmu")
    fake = tmp_path / "hostsite" / "cam_fmu"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("USED = False\n")
    for sub in ("control", "physics"):  # the host's own cam_fmu, which the FMU must never import
        (fake / sub).mkdir()
        (fake / sub / "__init__.py").write_text("raise RuntimeError('the host cam_fmu was imported by the FMU')\n")
    r = run_python(ISOLATION, str(tmp_path / "a" / "pi_speed.fmu"), str(tmp_path / "b" / "pi_speed.fmu"),
                   str(fake.parent), cwd=tmp_path)
    assert r["a_end"] == pytest.approx(0.05, abs=1e-12)
    assert len(r["private_while_alive"]) == 4, r        # 2 packages + 2 slave modules, all distinct
    assert r["omegas"][0] == r["omegas"][1] and r["omegas"][0] != 0  # the integrator of each ran
    assert r["added_after_free"] == [] and r["path_unchanged"], r


FATAL = r"""
import json, sys
from fmpy import read_model_description, extract
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
md = read_model_description(sys.argv[1])
fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(sys.argv[1]), modelIdentifier="pi_speed", instanceName="a")
fmu.instantiate(); fmu.setupExperiment(startTime=0.0); fmu.enterInitializationMode(); fmu.exitInitializationMode()
package = dict(x.split("=", 1) for x in open(str(fmu.unzipDirectory) + "/resources/native.txt").read().split())["package"]
bridge = sys.modules[package + "._fmi_bridge"]
bridge.Instance.do_step = lambda self, t, h: None          # the bridge itself broken: not (status, payload, messages)
statuses = []
for call in (lambda: fmu.doStep(0.0, 1e-3), lambda: fmu.getReal([3]), lambda: fmu.reset()):
    try:
        call(); statuses.append(0)
    except FMICallException as exc:
        statuses.append(int(exc.status))
fmu.freeInstance()                                          # never crashes, whatever came before
print(json.dumps({"statuses": statuses}))
"""


def test_fatal_only_when_the_bridge_breaks_and_free_survives(pi_speed_fmu_path, tmp_path):
    shutil.copyfile(pi_speed_fmu_path, tmp_path / "pi_speed.fmu")
    r = run_python(FATAL, str(tmp_path / "pi_speed.fmu"), cwd=tmp_path)
    assert r["statuses"] == [4, 4, 4]
