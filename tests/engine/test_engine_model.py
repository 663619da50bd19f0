"""The C model contract (cam_model.h) function by function against the Python model it was ported from
(physics/formulations/consistent.py HybridDrive, physics/drive.py DriveModel), on random states and
modes of several drives: the same bits from derivatives, event indicators, transitions, outputs and the
rates that bound explicit methods' steps."""
from __future__ import annotations

import ctypes
import random

import pytest

from cam_fmu.engine.simulator import NX, CamError, CamMode, _set_parameter, engine, raise_for
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.formulations.consistent import HybridDrive, Mode
from cam_fmu.physics.variables import OUTPUT_NAMES

D3 = ctypes.c_double * NX  # CAM_NX: the rigid slots and a compliant shaft's two
NO = len(OUTPUT_NAMES)
# The rigid drive's contract functions: a clearance under closure 'kinematic' (the backlash of docs/model.md 6; with
# 'form' the follower is a body of its own, whose functions voltage_follower.c provides and tests/fmu_me checks)
DRIVES = [{}, {"c": 5e-4, "closure": "kinematic"}, {"L": 1e-3}, {"gamma": 1.5707963267948966, "beta": 3.141592653589793, "mu": 0.05},
          {"c": 1e-3, "closure": "kinematic", "L": 1e-4, "mu": 0.1, "gamma": 2.0, "beta": 1.0, "M_f": 0.0},
          {"k_shaft": 40.0, "d_shaft": 0.01, "J_cam": 2e-5},
          {"k_shaft": 5e3, "J_cam": 1e-4, "L": 1e-3, "c": 5e-4, "closure": "kinematic", "mu": 0.1, "gamma": 2.0,
           "beta": 1.0}]
EVENTS = ("stop", "contact", "engage_up", "engage_down", "break_away", "side_force")


class CModel:
    """A CamModel in opaque memory, built from parameters through the binding's checks."""

    def __init__(self, params: dict) -> None:
        lib = self.lib = engine()
        sig = {"cam_model_sizeof": (ctypes.c_size_t, []), "cam_model_init": (ctypes.c_int, [ctypes.c_void_p] * 3),
               "cam_model_free": (None, [ctypes.c_void_p]),
               "cam_rhs": (None, [ctypes.c_void_p, ctypes.c_void_p, D3, ctypes.c_double, D3]),
               "cam_event_value": (ctypes.c_double, [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int, D3,
                                                     ctypes.c_double]),
               "cam_apply_event": (None, [ctypes.c_void_p, ctypes.c_void_p, D3, ctypes.c_int, ctypes.c_double]),
               "cam_settle": (None, [ctypes.c_void_p, ctypes.c_void_p, D3, ctypes.c_double, ctypes.c_int]),
               "cam_stiffness_rate": (ctypes.c_double, [ctypes.c_void_p, ctypes.c_void_p, D3, ctypes.c_int]),
               "cam_profile_rate": (ctypes.c_double, [ctypes.c_void_p, D3]),
               "cam_torque_gain": (ctypes.c_double, [ctypes.c_void_p, ctypes.c_void_p, D3]),
               "cam_outputs": (None, [ctypes.c_void_p, ctypes.c_void_p, D3, ctypes.c_double, ctypes.c_double,
                                      ctypes.c_int, ctypes.c_double * NO])}
        for name, (restype, argtypes) in sig.items():
            getattr(lib, name).restype, getattr(lib, name).argtypes = restype, argtypes
        err = CamError()
        raw = ctypes.create_string_buffer(lib.cam_params_sizeof())
        lib.cam_params_defaults(raw)
        for name, value in params.items():
            _set_parameter(lib, raw, name, value, err)
        self.buf = ctypes.create_string_buffer(lib.cam_model_sizeof())
        status = lib.cam_model_init(self.buf, raw, ctypes.byref(err))
        lib.cam_params_free(raw)
        if status:
            raise_for(err)

    def __del__(self) -> None:
        self.lib.cam_model_free(self.buf)


def _mode(py: Mode) -> CamMode:
    return CamMode(int(py.stuck), py.direction, py.contact, py.s_free, py.side)


def _states(model: DriveModel, seed: int, n: int = 60):
    rng = random.Random(seed)
    for _ in range(n):
        theta = rng.uniform(-20.0, 20.0)
        y = [theta, rng.choice([0.0, rng.uniform(-300.0, 300.0)]), rng.uniform(-3.0, 3.0), rng.uniform(-0.01, 0.01),
             rng.uniform(-300.0, 300.0)]
        s = model.program.derivatives(theta)[0]
        contact = rng.choice([-1, 0, 1]) if model.c > 0.0 else 1
        mode = Mode(stuck=rng.random() < 0.2, direction=rng.choice([1.0, -1.0]), contact=contact,
                    s_free=s + rng.uniform(-model.c, model.c), side=rng.choice([1.0, -1.0]))
        yield y, mode, rng.uniform(-50.0, 50.0)


@pytest.mark.parametrize("params", DRIVES, ids=[",".join(p) or "defaults" for p in DRIVES])
def test_the_contract_functions_give_the_python_models_bits(params):
    model, c = DriveModel(params), CModel(params)
    hybrid, lib = HybridDrive(model), c.lib
    for k, (y, mode, u) in enumerate(_states(model, seed=len(params))):
        if not hybrid.has_current:
            y[2] = 0.0
        if mode.stuck and hybrid.compliant:  # a held cam's speed is 0 (a stop event sets it)
            y[1] = 0.0
        x = D3(*y) if hybrid.compliant else D3(*y[:3], 0.0, 0.0)
        yy = y[:hybrid.size]
        m = _mode(mode)
        dx = D3()
        lib.cam_rhs(c.buf, ctypes.byref(m), x, u, dx)
        assert list(dx)[:hybrid.size] == list(hybrid.derivative(yy, u, mode)), (k, y, mode)
        names, values = hybrid.event_names(mode), hybrid.event_values(yy, u, mode)
        assert [lib.cam_event_value(c.buf, ctypes.byref(m), EVENTS.index(name), x, u) for name in names] \
            == list(values)
        for electrical in (0, 1):
            assert lib.cam_stiffness_rate(c.buf, ctypes.byref(m), x, electrical) \
                == hybrid.stiffness_rate(yy, mode, bool(electrical))
        assert lib.cam_profile_rate(c.buf, x) == hybrid.profile_rate(yy)
        assert lib.cam_torque_gain(c.buf, ctypes.byref(m), x) == hybrid.torque_gain(yy, mode)
        out = (ctypes.c_double * NO)()
        lib.cam_outputs(c.buf, ctypes.byref(m), x, u, 0.0, 0, out)
        assert list(out) == list(hybrid.outputs(yy, u, mode).values())
        for name in names + ("stop",):  # the transitions, in place on copies of the same state and mode
            py_y, py_mode, cx, cm = list(yy), mode.copy(), D3(*x), _mode(mode)
            hybrid.apply_event(py_y, u, py_mode, name)
            lib.cam_apply_event(c.buf, ctypes.byref(cm), cx, EVENTS.index(name), u)
            assert list(cx)[:hybrid.size] == py_y, (k, name)
            assert (cm.stuck, cm.direction, cm.contact, cm.s_free, cm.side) == \
                (int(py_mode.stuck), py_mode.direction, py_mode.contact, py_mode.s_free, py_mode.side)
        py_y, py_mode, cx, cm = list(yy), mode.copy(), D3(*x), _mode(mode)
        hybrid.settle(py_y, u, py_mode)
        lib.cam_settle(c.buf, ctypes.byref(cm), cx, u, 0)
        assert (cm.stuck, cm.direction, cm.contact, cm.s_free, cm.side) == \
            (int(py_mode.stuck), py_mode.direction, py_mode.contact, py_mode.s_free, py_mode.side)
