"""The exchange of the Python-hosting linux64 binary, on pi_speed.fmu: fmi2GetReal of outputs and inputs, and
fmi2SetReal of inputs within their ranges (finite values), answered in C from a buffer the bridge keeps
current (docs/fmu.md#the-exchange).

What could go wrong, and is checked here: a value answered in C that the slave does not hold (stale
outputs after a state restore or a reset, inputs the slave never saw), a bad input accepted without its
message, a call that still crosses into Python, memory errors in the native host.
"""
from __future__ import annotations

import shutil

import pytest

from native_support import EMPTY_ENV, ROOT, compile_host, extract, run_host, run_python, value_references

PER_STEP_CALLS = r"""
import json, sys
from fmpy import read_model_description, extract
from fmpy.fmi2 import FMU2Slave
md = read_model_description(sys.argv[1])
vr = {v.name: v.valueReference for v in md.modelVariables}
outs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
ins = [v.valueReference for v in md.modelVariables if v.causality == "input"]
fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(sys.argv[1]), modelIdentifier="pi_speed", instanceName="a")
fmu.instantiate(); fmu.setupExperiment(startTime=0.0); fmu.enterInitializationMode(); fmu.exitInitializationMode()
package = dict(x.split("=", 1) for x in open(str(fmu.unzipDirectory) + "/resources/native.txt").read().split())["package"]
bridge = sys.modules[package + "._fmi_bridge"]
calls = {}
for name in [n for n, f in vars(bridge.Instance).items() if callable(f) and not n.startswith("_")]:
    def counting(self, *a, _o=getattr(bridge.Instance, name), _n=name):
        calls[_n] = calls.get(_n, 0) + 1
        return _o(self, *a)
    setattr(bridge.Instance, name, counting)
t = 0.0
for k in range(200):
    fmu.setReal([vr["omega_meas"]], [3.0 + 0.005 * k])
    fmu.setReal([vr["M_load"], vr["J_load"]], [0.01, 0.002])
    fmu.doStep(t, 1e-3); t += 1e-3
    fmu.getReal([vr["u"], vr["integral"]]); fmu.getReal(outs + ins)
per_step = dict(calls)
fmu.getReal([vr["u"], vr["kp"]])               # a parameter among the outputs: Python answers
mixed = calls.get("get_real", 0)
fmu.setReal([vr["omega_meas"], vr["M_load"]], [3.5, 1.0])
print(json.dumps({"per_step": per_step, "mixed_get": mixed, "after_set": calls.get("set_real", 0)}))
"""


def test_only_do_step_crosses_into_python_per_step(pi_speed_fmu_path, tmp_path):
    shutil.copyfile(pi_speed_fmu_path, tmp_path / "pi_speed.fmu")
    r = run_python(PER_STEP_CALLS, str(tmp_path / "pi_speed.fmu"), cwd=tmp_path)
    assert r["per_step"] == {"do_step": 200}, r  # set of inputs, get of outputs and inputs: in C
    assert r["mixed_get"] == 1 and r["after_set"] == 0, r


AGREES_WITH_SLAVE = r"""
import gc, json, math, random, sys
from fmpy import read_model_description, extract
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi1 import FMICallException
md = read_model_description(sys.argv[1])
vr = {v.name: v.valueReference for v in md.modelVariables}
outs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
inputs = ["omega_meas", "omega_setpoint", "M_load", "J_load"]
start = {v.name: float(v.start) for v in md.modelVariables if v.name in inputs}
fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(sys.argv[1]), modelIdentifier="pi_speed", instanceName="a")
fmu.instantiate(callbacks=None)
package = dict(x.split("=", 1) for x in open(str(fmu.unzipDirectory) + "/resources/native.txt").read().split())["package"]
bridge = sys.modules[package + "._fmi_bridge"]
instance = next(o for o in gc.get_objects() if isinstance(o, bridge.Instance))
fmu.setupExperiment(startTime=0.0); fmu.enterInitializationMode(); fmu.exitInitializationMode()
rng = random.Random(int(sys.argv[2]))
model = dict(start)           # the inputs the FMU must hold: the last ones accepted
saved, saved_model = None, None
t, in_error, checks, refused, kinds = 0.0, False, 0, 0, {}
for n in range(int(sys.argv[3])):
    op = rng.choice(["set", "set", "set_bad", "set_two", "step", "step", "step", "save", "restore", "reset"])
    kinds[op] = kinds.get(op, 0) + 1
    try:
        if op == "set":
            name = rng.choice(inputs); value = rng.uniform(-20.0, 20.0)
            fmu.setReal([vr[name]], [value]); model[name] = value
        elif op == "set_two":
            a, b = rng.uniform(0.0, 10.0), rng.uniform(-5.0, 5.0)
            fmu.setReal([vr["omega_meas"], vr["M_load"]], [a, b]); model["omega_meas"], model["M_load"] = a, b
        elif op == "set_bad":
            fmu.setReal([vr["omega_meas"]], [rng.choice([math.nan, math.inf, -math.inf])])
            raise AssertionError("a bad input was accepted")
        elif op == "step":
            fmu.doStep(t, 1e-3); t += 1e-3
        elif op == "save":
            saved, saved_model = fmu.getFMUstate(), dict(model)
        elif op == "restore" and saved is not None:
            fmu.setFMUstate(saved); model = dict(saved_model); in_error = False
        elif op == "reset":
            fmu.reset(); model = dict(start); in_error = False; t = 0.0; saved = None
            if rng.random() < 0.5:   # outputs not calculated yet: Python answers the next get
                fmu.setupExperiment(startTime=0.0); fmu.enterInitializationMode(); fmu.exitInitializationMode()
    except FMICallException as exc:
        if op == "set_bad" or in_error:
            assert exc.status == 3, (op, exc.status)
            refused += 1
            in_error = True
        else:
            raise
    # the fast answers against the slave's own per-variable getters (pythonfmu's path)
    fast = fmu.getReal(outs + [vr[x] for x in inputs])
    slave = instance.slave
    exchange_dirty = instance.exchange.head[bridge._DIRTY]
    held = slave.get_real(outs) if slave._initialized else None
    if held is not None:
        assert fast[:len(outs)] == held, (n, op)
    assert fast[len(outs):] == [model[x] for x in inputs], (n, op, fast[len(outs):], model)
    assert not (exchange_dirty and op in ("step", "save", "reset")), (n, op)  # Python calls take the inputs
    if not exchange_dirty:   # the slave has seen every input C took
        assert [slave._inputs[x] for x in inputs] == [model[x] for x in inputs], (n, op)
    checks += 1
print(json.dumps({"checks": checks, "refused": refused, "kinds": kinds}))
"""


@pytest.mark.parametrize("seed", [1, 2])
def test_fast_answers_agree_with_the_slave_through_random_calls(pi_speed_fmu_path, tmp_path, seed):
    """A random sequence of sets (good and bad), steps, state saves and restores, resets: after each call,
    fmi2GetReal answered in C equals the slave's own getters (outputs) and the inputs last accepted."""
    shutil.copyfile(pi_speed_fmu_path, tmp_path / "pi_speed.fmu")
    r = run_python(AGREES_WITH_SLAVE, str(tmp_path / "pi_speed.fmu"), str(seed), "400", cwd=tmp_path)
    assert r["checks"] == 400 and r["refused"] >= r["kinds"]["set_bad"] > 10, r
    assert min(r["kinds"].get(k, 0) for k in ("restore", "reset", "step", "set_two")) > 10, r


@pytest.fixture(scope="module")
def fmu_dir(pi_speed_fmu_path, tmp_path_factory):
    return extract(pi_speed_fmu_path, tmp_path_factory.mktemp("exchange_fmu"))


def test_native_host_bad_input_still_named_and_state_restores_inputs(fmu_dir, tmp_path):
    """In a native host: an input out of range is refused with its message although good ones never reach
    Python; a restored state brings back the inputs and outputs it was taken with."""
    host = compile_host(tmp_path / "host")
    vr = value_references(fmu_dir)
    watch = f"{vr['integral']},{vr['error']},{vr['omega_meas']},{vr['M_load']}"
    r = run_host(host, fmu_dir, "inst", "init", "setr", str(vr["omega_meas"]), "5", "setr", str(vr["M_load"]), "2",
                 "step", "20", "0.001", "getr", watch, "save",
                 "setr", str(vr["omega_meas"]), "1", "step", "20", "0.001", "getr", watch,
                 "restore", "getr", watch,
                 "setr", str(vr["omega_meas"]), "nan", "getr", watch, "reset", "getr", watch, env=EMPTY_ENV)
    assert r["rc"] == 0 and r["lines"][-1] == {"exit": 0}, r
    assert [x["status"] for x in r["cmds"] if x["cmd"] == "setr"] == [0, 0, 0, 3]
    gets = [x["values"] for x in r["cmds"] if x["cmd"] == "getr"]
    assert gets[0][2:] == [5.0, 2.0] and gets[1][2:] == [1.0, 2.0]
    assert gets[1][0] != gets[0][0]                       # the integrator moved on with omega_meas = 1
    assert gets[2] == gets[0]                             # restored: outputs and inputs as saved
    assert gets[3] == gets[2]                             # the refused value changed nothing
    assert gets[4][2:] == [0.0, 0.0] and gets[4][0] == 0.0  # reset: start inputs, an empty integrator
    assert any(x["log"] == 3 and "'omega_meas'" in x["msg"] and "not finite" in x["msg"] for x in r["logs"]), \
        r["logs"]


def test_the_header_layout_is_the_same_on_both_sides():
    """The bridge's header names (bridge._HEAD) and the C side's enum list the same fields in the same order."""
    import re

    from cam_fmu.fmu.native import bridge

    source = (ROOT / "cam_fmu" / "fmu" / "native" / "fmi2_python.c").read_text()
    enum = re.search(r"enum \{ (X_MAGIC[^}]*) \};", source).group(1)
    names = [name.strip()[2:].lower() for name in enum.split(",")]
    assert names[-1] == "head" and names[:-1] == list(bridge._HEAD)
    magic = int(re.search(r"#define EXCHANGE_MAGIC (0x[0-9A-Fa-f]+)", source).group(1), 16)
    assert magic == bridge._EXCHANGE_MAGIC
