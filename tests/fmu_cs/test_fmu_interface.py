"""cam.fmu through fmpy: default experiment, state, instances, reset, inputs, errors.

cam.fmu is C (no Python inside): fmpy loads it into this process, as FMPy's own tests do. Each scenario
returns one dict (what the FMU returned and said; the binary's own stderr output is kept as ``_stderr``);
the tests below check it. Every run checks that it reached its stop time: a falsy do_step return is
fmi2Discard, which makes fmpy stop early without an exception.
"""
from __future__ import annotations

import csv
import math
import os
import shutil
import subprocess
import sys
import tempfile

import pytest

OUTPUT_NAMES = ("omega", "theta", "s", "i", "M", "J", "v", "a", "alpha", "s_cam")  # at least these; omega first
H = 1e-3  # communication step of the manual loops [s]

# Parameter sets for the state tests: internal state differs between them
# (adaptive step size, backlash memory, current, the paper scheme's history).
STATE_CASES = {
    "default": {},
    "backlash": {"c": 0.002},
    "inductance_etdrk4": {"L": 1e-3, "solver": "etdrk4"},
    "paper_rk4": {"formulation": "paper", "solver": "rk4"},
}

# name: (start values, input signal spec, variable the message must name, text the message must contain)
ERROR_CASES = {
    "R_negative": ({"R": -1.0}, None, "'R'", "[0.001, 10000]"),  # physical ranges (issue 9)
    "J_m_zero": ({"J_m": 0.0}, None, "'J_m'", "[1e-09, 100]"),
    "h_max_too_large": ({"h_max": 100.0}, None, "'h_max'", "[1e-09, 10]"),
    "mu_nan": ({"mu": float("nan")}, None, "'mu'", "[0, 0.5]"),
    "unknown_preset": ({"rise_law": "bogus"}, None, "'rise_law'", "'cycloidal'"),
    "unknown_solver": ({"solver": "bogus"}, None, "'solver'", "'rk45'"),
    "unknown_drive": ({"drive": "torque"}, None, "'drive'", "'speed'"),
    "angles_not_2pi": ({"rise_angle": 2.0}, None, "'rise_angle'", "2 pi"),
    "max_steps_exceeded": ({"solver": "rk4", "h_max": 1e-5, "max_steps": 1.0}, None, "max_steps", "max_steps = 1"),
    "u_nan": ({}, ("u", float("nan")), "'u'", "[-10000, 10000]"),  # inputs have finite ranges (issue 9)
    "u_inf": ({}, ("u", float("inf")), "'u'", "[-10000, 10000]"),
    "u_1e300": ({}, ("u", 1e300), "'u'", "[-10000, 10000]"),
    "omega_ref_nan": ({"drive": "speed"}, ("omega_ref", float("nan")), "'omega_ref'", "[-10000, 10000]"),
}


# =========================================================================== scenarios
def _md(fmu):
    from fmpy import read_model_description
    return read_model_description(fmu)


class Manual:
    """One FMU2Slave instance driven step by step."""

    def __init__(self, unzipdir, md, name="inst", logging=False):
        from fmpy.fmi2 import FMU2Slave
        self.md = md
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.types = {v.name: v.type for v in md.modelVariables}
        outputs = [v.name for v in md.modelVariables if v.causality == "output"]
        self.output_names = list(OUTPUT_NAMES) + [n for n in outputs if n not in OUTPUT_NAMES]
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(callbacks=self._callbacks(), loggingOn=logging)
        self.time = 0.0

    def _callbacks(self):
        """Callbacks with a live logger. fmpy's logging proxy keeps the last logger given to simulate_fmu in a
        static variable (fmpy/logging, s_logger) that outlives that call's ctypes thunk: an instance using
        fmpy's defaultCallbacks after simulate_fmu(logger=...) would call freed memory at its first message.
        cam.fmu reports errors through the logger even with logging off, so give every instance its own."""
        from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                               fmi2CallbackLoggerTYPE)
        from fmpy import calloc, free
        from fmpy.logging import addLoggerProxy
        from ctypes import byref
        self.messages = []

        def logger(component, instance, status, category, message):
            self.messages.append((int(status), message.decode("utf-8", "replace")))
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(callbacks))
        self._keep = (callbacks, logger)
        return callbacks

    def set(self, name, value):
        vr = [self.vr[name]]
        kind = self.types[name]
        if kind == "Real":
            self.fmu.setReal(vr, [float(value)])
        elif kind == "Boolean":
            self.fmu.setBoolean(vr, [bool(value)])
        else:
            self.fmu.setString(vr, [str(value)])

    def init(self, params=None):
        self.fmu.setupExperiment(startTime=0.0)
        for name, value in (params or {}).items():
            self.set(name, value)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        self.time = 0.0
        self.n = 0
        self.t0 = 0.0

    def outputs(self):
        return self.fmu.getReal([self.vr[n] for n in self.output_names])

    def step(self, n, u=None):
        """n steps of H; u: None or a function of the step's start time. Returns the outputs after each."""
        rows = []
        for _ in range(n):
            if u is not None:
                self.set("u", u(self.time))
            # the same time arithmetic as fmpy's simulate_fmu: t_k = t0 + k H, h = t_(k+1) - t_k
            t_next = self.t0 + (self.n + 1) * H
            self.fmu.doStep(currentCommunicationPoint=self.time, communicationStepSize=t_next - self.time)
            self.n += 1
            self.time = t_next
            rows.append(self.outputs())
        return rows


def _finite(rows):
    return all(math.isfinite(x) for row in rows for x in row)


def _unzip(fmu):
    from fmpy import extract
    return extract(fmu)


def scenario_default(fmu):
    """simulate_fmu with no option at all, and with the 1 ms communication step."""
    import numpy as np
    from fmpy import simulate_fmu
    res = simulate_fmu(fmu)
    res_1ms = simulate_fmu(fmu, output_interval=1e-3)
    return {
        "stop": float(res["time"][-1]), "n": len(res),
        "finite": bool(all(np.all(np.isfinite(res[n])) for n in res.dtype.names)),
        "outputs": list(res.dtype.names),
        "omega_end": float(res["omega"][-1]), "theta_end": float(res["theta"][-1]),
        "stop_1ms": float(res_1ms["time"][-1]), "n_1ms": len(res_1ms),
        "omega_1ms_at_2ms_grid": [float(x) for x in res_1ms["omega"][::2]],
        "omega_2ms": [float(x) for x in res["omega"]],
        "omega_max": float(np.max(res_1ms["omega"])),
    }


def scenario_omega(fmu):
    """omega(t) at every 1 ms communication point over the default experiment (for ecos)."""
    from fmpy import simulate_fmu
    res = simulate_fmu(fmu, output_interval=1e-3)
    return {"time": [float(x) for x in res["time"]], "omega": [float(x) for x in res["omega"]]}


def scenario_state(fmu):
    md = _md(fmu)
    unzipdir = _unzip(fmu)
    out = {}
    for case, params in STATE_CASES.items():
        a = Manual(unzipdir, md, "a")
        a.init(params)
        a.step(500)                       # t1 = 0.5 s
        at_t1 = a.outputs()
        state = a.fmu.getFMUstate()
        first = a.step(300)               # t2 = 0.8 s
        a.fmu.setFMUstate(state)
        restored_t1 = a.outputs()
        a.n, a.time = 500, 500 * H
        again = a.step(300)
        blob = a.fmu.serializeFMUstate(state)
        state2 = a.fmu.deSerializeFMUstate(blob)
        a.fmu.setFMUstate(state2)
        a.n, a.time = 500, 500 * H
        deserialized = a.step(300)
        # a second, fresh instance takes over the serialised state
        b = Manual(unzipdir, md, "b")
        b.init()
        state3 = b.fmu.deSerializeFMUstate(bytes(blob))
        b.fmu.setFMUstate(state3)
        b.n, b.time = 500, 500 * H
        other = b.step(300)
        for inst, states in ((a, (state, state2)), (b, (state3,))):
            for s in states:
                inst.fmu.freeFMUstate(s)
            inst.fmu.terminate()
            inst.fmu.freeInstance()
        out[case] = {
            "finite": _finite(first),
            "moved": first[-1] != at_t1,
            "restored_outputs_equal": restored_t1 == at_t1,
            "set_get_identical": again == first,
            "deserialized_identical": deserialized == first,
            "other_instance_identical": other == first,
            "serialized_bytes": len(blob),
            "end_time": a.time,
        }
    shutil.rmtree(unzipdir, ignore_errors=True)
    return out


def scenario_instances(fmu):
    md = _md(fmu)
    unzipdir = _unzip(fmu)
    a, b = Manual(unzipdir, md, "a"), Manual(unzipdir, md, "b")
    a.init()
    b.init({"R": 25.0})
    ra, rb = [], []
    for _ in range(400):  # interleaved, different parameters and inputs
        ra += a.step(1, u=lambda t: 3.5)
        rb += b.step(1, u=lambda t: 2.0)
    c = Manual(unzipdir, md, "c")
    c.init()
    rc = c.step(400, u=lambda t: 3.5)
    d = Manual(unzipdir, md, "d")
    d.init({"R": 25.0})
    rd = d.step(400, u=lambda t: 2.0)
    # two instances with the same settings, interleaved
    e, f = Manual(unzipdir, md, "e"), Manual(unzipdir, md, "f")
    e.init()
    f.init()
    re_, rf = [], []
    for _ in range(400):
        re_ += e.step(1)
        rf += f.step(1)
    for inst in (a, b, c, d, e, f):
        inst.fmu.terminate()
        inst.fmu.freeInstance()
    shutil.rmtree(unzipdir, ignore_errors=True)
    return {"a_equals_alone": ra == rc, "b_equals_alone": rb == rd, "a_differs_b": ra != rb,
            "same_settings_identical": re_ == rf and re_ == rc, "finite": _finite(ra + rb),
            "end_time": a.time}


def scenario_reset(fmu):
    md = _md(fmu)
    unzipdir = _unzip(fmu)
    a = Manual(unzipdir, md, "a")
    a.init()
    first = a.step(600)
    a.fmu.reset()
    a.init()
    second = a.step(600)
    a.fmu.reset()
    a.init({"R": 30.0})
    changed = a.step(600)
    a.fmu.reset()
    a.init()  # reset must bring back the defaults, not keep R = 30
    third = a.step(600)
    a.fmu.terminate()
    a.fmu.freeInstance()
    shutil.rmtree(unzipdir, ignore_errors=True)
    return {"identical": first == second, "defaults_after_reset": third == first,
            "parameter_honoured": changed != first, "finite": _finite(first), "end_time": a.time}


def scenario_inputs(fmu):
    import numpy as np
    from fmpy import simulate_fmu
    md = _md(fmu)
    unzipdir = _unzip(fmu)
    stop, t_step = 1.0, 0.5
    step_sig = np.array([(0.0, 0.0), (t_step, 0.0), (t_step, 3.5), (stop, 3.5)], dtype=[("time", float), ("u", float)])
    ramp_sig = np.array([(0.0, 0.0), (stop, 3.5)], dtype=[("time", float), ("u", float)])
    res_step = simulate_fmu(fmu, input=step_sig, output_interval=H, stop_time=stop)
    res_ramp = simulate_fmu(fmu, input=ramp_sig, output_interval=H, stop_time=stop)
    res_const = simulate_fmu(fmu, output_interval=H, stop_time=stop)
    out = {"stop_step": float(res_step["time"][-1]), "stop_ramp": float(res_ramp["time"][-1]),
           "stop_const": float(res_const["time"][-1])}
    n = int(round(stop / H))
    from fmpy.simulation import Input

    def ramp(t):  # fmpy's own interpolation, so both paths see bit-identical u values
        v, _ = Input.interpolate(time=t, t=ramp_sig["time"], table=ramp_sig["u"].reshape(1, -1))
        return float(v[0])

    assert abs(ramp(0.3) - 3.5 * 0.3) < 1e-12
    for label, res, u in (("step", res_step, lambda t: 3.5 if t >= t_step - 1e-12 else 0.0),
                          ("ramp", res_ramp, ramp)):
        m = Manual(unzipdir, md, label)
        m.init()
        rows = m.step(n, u=u)
        manual = np.array([r[0] for r in rows])
        fmpy_omega = np.asarray(res["omega"][1:])
        out[f"{label}_max_diff_to_manual"] = float(np.max(np.abs(fmpy_omega - manual)))
        out[f"{label}_max_diff_to_const"] = float(np.max(np.abs(fmpy_omega - res_const["omega"][1:])))
        m.fmu.terminate()
        m.fmu.freeInstance()
    t = res_step["time"]
    out["step_omega_before"] = float(np.max(np.abs(res_step["omega"][t <= t_step])))
    out["step_omega_end"] = float(res_step["omega"][-1])
    out["const_omega_end"] = float(res_const["omega"][-1])
    out["ramp_omega_end"] = float(res_ramp["omega"][-1])
    shutil.rmtree(unzipdir, ignore_errors=True)
    return out


def scenario_errors(fmu):
    import numpy as np
    from fmpy import simulate_fmu
    from fmpy.fmi1 import FMICallException
    out = {}
    for case, (params, signal, _var, _text) in ERROR_CASES.items():
        messages = []

        def logger(component, instance, status, category, message):
            messages.append([int(status), message.decode("utf-8", "replace")])

        kwargs = {}
        if signal is not None:
            name, bad = signal
            kwargs["input"] = np.array([(0.0, 1.0), (0.05, 1.0), (0.05, bad), (0.1, bad)],
                                       dtype=[("time", float), (name, float)])
        record = {"raised": False, "status": None, "function": None, "stop": None}
        try:
            # a NaN input signal on purpose: fmpy's interpolation subtracts NaN (numpy's warning is expected)
            with np.errstate(invalid="ignore"):
                res = simulate_fmu(fmu, start_values=params, output_interval=0.01, stop_time=0.1,
                                   debug_logging=True, logger=logger, **kwargs)
            record["stop"] = float(res["time"][-1])
            record["finite"] = bool(all(np.all(np.isfinite(res[n])) for n in res.dtype.names))
        except FMICallException as exc:
            record.update(raised=True, status=int(exc.status), function=exc.function, text=str(exc))
        record["messages"] = messages
        out[case] = record

    # Outputs stay finite after a rejected input, and after a failed step.
    md = _md(fmu)
    unzipdir = _unzip(fmu)
    m = Manual(unzipdir, md, "nan")
    m.init()
    m.step(100)
    before = m.outputs()
    try:
        m.set("u", float("nan"))
        out["manual_nan_raised"] = False
    except FMICallException as exc:
        out["manual_nan_raised"] = int(exc.status)
    after = m.outputs()
    out["manual_outputs_unchanged"] = before == after
    out["manual_outputs_finite"] = all(math.isfinite(x) for x in after)
    out["manual_nan_logged"] = [m for m in m.messages if m[0] == 3]
    # fmi2Error leaves the instance recoverable: fmi2Reset, run again, fmi2FreeInstance.
    m.fmu.reset()
    m.init()
    m.step(10)
    out["manual_after_reset_finite"] = all(math.isfinite(x) for x in m.outputs())
    m.fmu.freeInstance()
    shutil.rmtree(unzipdir, ignore_errors=True)
    return out


SCENARIOS = {name[len("scenario_"):]: f for name, f in list(globals().items()) if name.startswith("scenario_")}


# =========================================================================== tests (pytest side)
def run_scenario(name, fmu):
    """The scenario's dict, with what the FMU's binary wrote to this process's stderr (file descriptor 2)."""
    with tempfile.TemporaryFile() as err:
        sys.stderr.flush()
        saved = os.dup(2)
        os.dup2(err.fileno(), 2)
        try:
            result = SCENARIOS[name](str(fmu))
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        err.seek(0)
        result["_stderr"] = err.read().decode("utf-8", "replace")
    return result


@pytest.fixture(scope="module")
def fmu_copy(cam_fmu_path, tmp_path_factory):
    folder = tmp_path_factory.mktemp("fmu_interface")
    path = folder / "cam.fmu"
    shutil.copyfile(cam_fmu_path, path)
    return path


def test_default_experiment_simulate_fmu(fmu_copy):
    r = run_scenario("default", fmu_copy)
    assert r["stop"] == pytest.approx(2.0, abs=1e-12), "simulate_fmu stopped before the default stop time"
    assert r["stop_1ms"] == pytest.approx(2.0, abs=1e-12)
    assert r["n_1ms"] == 2001
    assert r["finite"]
    assert set(OUTPUT_NAMES) <= set(r["outputs"])
    # fig. 6: from rest, 3.5 V spins the cam up; it has turned a good part of a revolution by 2 s
    assert r["omega_end"] > 0.5 and r["theta_end"] > 1.0
    # without output_interval fmpy doubles 1 ms to 2 ms (at most 1000 steps); same curve at the shared points
    a, b = r["omega_2ms"], r["omega_1ms_at_2ms_grid"]
    assert len(a) == len(b) == 1001
    assert max(abs(x - y) for x, y in zip(a, b)) <= 1e-3 * max(1.0, r["omega_max"])


def test_default_experiment_fmpy_cli(fmu_copy, tmp_path):
    """`fmpy simulate cam.fmu` with no other option runs to the stop time (2 s)."""
    exe = shutil.which("fmpy")
    cmd = [exe] if exe else [sys.executable, "-m", "fmpy.command_line"]
    out = tmp_path / "cli.csv"
    proc = subprocess.run([*cmd, "simulate", str(fmu_copy), "--output-file", str(out)],
                          capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    with open(out, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert float(rows[-1]["time"]) == pytest.approx(2.0, abs=1e-12)
    assert all(math.isfinite(float(row["omega"])) for row in rows)
    assert float(rows[-1]["omega"]) > 0.5


@pytest.fixture(scope="module")
def state_result(fmu_copy):
    return run_scenario("state", fmu_copy)


@pytest.mark.parametrize("case", sorted(STATE_CASES))
def test_state_get_set_serialize_bit_identical(state_result, case):
    r = state_result[case]
    assert r["end_time"] == pytest.approx(0.8, abs=1e-12)
    assert r["finite"] and r["moved"]
    assert r["restored_outputs_equal"], "fmi2SetFMUstate did not restore the outputs at t1"
    assert r["set_get_identical"], "get state at t1, step to t2, set it back, step again: not bit-identical"
    assert r["deserialized_identical"], "serialise/deserialise changed the continuation"
    assert r["other_instance_identical"], "a second instance given the serialised state continues differently"


def test_two_instances_independent(fmu_copy):
    r = run_scenario("instances", fmu_copy)
    assert r["end_time"] == pytest.approx(0.4, abs=1e-12)
    assert r["finite"]
    assert r["a_differs_b"]
    assert r["a_equals_alone"] and r["b_equals_alone"], "interleaved instances influence each other"
    assert r["same_settings_identical"]


def test_reset_rerun_identical(fmu_copy):
    r = run_scenario("reset", fmu_copy)
    assert r["end_time"] == pytest.approx(0.6, abs=1e-12)
    assert r["finite"]
    assert r["identical"], "reset and re-run gave a different result"
    assert r["parameter_honoured"]
    assert r["defaults_after_reset"], "fmi2Reset kept a parameter value of the previous run"


def test_time_varying_u_honoured(fmu_copy):
    r = run_scenario("inputs", fmu_copy)
    for key in ("stop_step", "stop_ramp", "stop_const"):
        assert r[key] == pytest.approx(1.0, abs=1e-12), key
    # fmpy's input signal gives the same run as setting u by hand before every step
    assert r["step_max_diff_to_manual"] <= 1e-12
    assert r["ramp_max_diff_to_manual"] <= 1e-12
    # and it matters: u = 0 keeps the drive at rest (Coulomb friction), the step starts it
    assert r["step_omega_before"] <= 1e-9
    assert r["step_omega_end"] > 0.1
    assert r["step_max_diff_to_const"] > 0.1
    assert r["ramp_max_diff_to_const"] > 0.1


@pytest.fixture(scope="module")
def error_result(fmu_copy):
    return run_scenario("errors", fmu_copy)


@pytest.mark.parametrize("case", sorted(ERROR_CASES))
def test_error_reported_with_fmi_status_and_message(error_result, case):
    _params, _signal, variable, text = ERROR_CASES[case]
    r = error_result[case]
    if case == "max_steps_exceeded":
        # the step cannot be completed at this size: fmi2Discard (logStatusDiscard). fmpy asks
        # fmi2GetBooleanStatus(fmi2Terminated), gets true and ends the run early WITHOUT raising.
        assert not r["raised"] and r["stop"] == 0.0, r
        assert any(status == 2 and variable in msg and text in msg for status, msg in r["messages"]), r["messages"]
        return
    assert r["raised"], f"no FMI error: the run went on to t = {r['stop']}"
    # cam.fmu's own binary: a slave exception is fmi2Error (recoverable), never fmi2Fatal
    assert r["status"] == 3
    errors = [msg for status, msg in r["messages"] if status >= 3]
    assert any(variable in msg and text in msg for msg in errors), \
        f"no log message naming {variable} with {text!r}: {r['messages']}"
    # only there: the project's binary logs errors with logging off too, so the slave prints no second copy on
    # stderr (a CLI error stays one line; a host without a logger gets the binary's own stderr line)
    assert "[cam.fmu" not in error_result["_stderr"], error_result["_stderr"]


def test_outputs_never_nan_after_rejected_input(error_result):
    assert error_result["manual_nan_raised"] == 3
    assert any("'u'" in msg for _s, msg in error_result["manual_nan_logged"])  # logged with logging off
    assert error_result["manual_after_reset_finite"]
    assert error_result["manual_outputs_unchanged"] and error_result["manual_outputs_finite"]

