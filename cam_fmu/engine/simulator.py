"""The C engine's drive from Python: ``DriveSimulator`` (DriveSimulator's public API) and ``run_scene``.

The engine (``csrc/``) owns the state, the formulation, the solver and every
check; this module converts parameters and states between Python values and
the engine's, and turns the engine's errors into the exceptions of
``cam_fmu.errors`` (and ``physics.parameters.ParameterError``) with the
engine's message. Times in s, SI units throughout.
"""
from __future__ import annotations

import ctypes
import math
from array import array
from typing import Any, Mapping, Sequence

from ..errors import SimulationError, StepRejected
from ..physics.parameters import BY_NAME, ParameterError
from ..physics.variables import INPUT_STARTS, OUTPUT_NAMES
from . import contract
from .library import load

__all__ = ["DriveSimulator", "run_scene"]

N_OUTPUTS = len(OUTPUT_NAMES)
NX, NX_RIGID = contract.NX, contract.NX_RIGID  # the state slots (contract.X_SLOTS)
STATE_NAMES = tuple(name.lower() for name, _ in contract.X_SLOTS)  # theta, omega, current, twist, omega_m, ...
SLOTS = contract.state_slots()  # the saved state's entries (CAM_S_*), from the one layout
S_TIME, S_U, S_OMEGA_REF, S_OMEGA_DOT_REF = SLOTS["TIME"], SLOTS["U"], SLOTS["OMEGA_REF"], SLOTS["OMEGA_DOT_REF"]
S_H_NEXT, S_STEPS_TAKEN, S_X, S_STUCK = SLOTS["H_NEXT"], SLOTS["STEPS_TAKEN"], SLOTS["X"], SLOTS["STUCK"]
S_DIRECTION, S_CONTACT, S_S_FREE, S_SIDE = SLOTS["DIRECTION"], SLOTS["CONTACT"], SLOTS["S_FREE"], SLOTS["SIDE"]
S_FORM_U, S_HAVE_BUDGET, S_BUDGET, S_SPEED = SLOTS["FORM_U"], SLOTS["HAVE_BUDGET"], SLOTS["WORK_IN"], SLOTS["SPEED"]
N_SPEED = dict(contract.STATE_LAYOUT)["SPEED"]  # the speed drive's and a free follower's entries
BUDGET_KEYS = ("work_in", "work_abs", "theta", "i", "e_mech0", "e_mag0")  # WORK_IN .. E_MAG0
STATE_VERSION = contract.STATE_VERSION
EVENT_NAMES = contract.event_names()  # code k's name (cam_contract.h CAM_EV_*)
CamMode = contract.structure("CamMode")
CamEventRecord = contract.structure("CamEventRecord")
CamError = contract.structure("CamError")
_RAISES = {"ParameterError": ParameterError, "SimulationError": SimulationError, "StepRejected": StepRejected,
           "MemoryError": MemoryError}
EXCEPTIONS = {value: _RAISES[py] for _, value, py, _ in contract.STATUSES if py}  # status -> what Python raises


_P = ctypes.c_void_p
_D = ctypes.POINTER(ctypes.c_double)
_SIGNATURES = {
    "cam_params_sizeof": (ctypes.c_size_t, []),
    "cam_drive_sizeof": (ctypes.c_size_t, []),
    "cam_params_defaults": (None, [_P]),
    "cam_params_free": (None, [_P]),
    "cam_param_index": (ctypes.c_int, [ctypes.c_char_p]),
    "cam_params_unknown": (ctypes.c_int, [ctypes.c_char_p, _P]),
    "cam_params_set_real": (ctypes.c_int, [_P, ctypes.c_int, ctypes.c_double, _P]),
    "cam_params_set_string": (ctypes.c_int, [_P, ctypes.c_int, ctypes.c_char_p, ctypes.c_size_t, _P]),
    "cam_drive_init": (ctypes.c_int, [_P, _P, _P]),
    "cam_drive_free": (None, [_P]),
    "cam_drive_set_start_time": (ctypes.c_int, [_P, ctypes.c_double, _P]),
    "cam_drive_set_inputs": (ctypes.c_int, [_P, ctypes.c_double, ctypes.c_double, ctypes.c_double, _P]),
    "cam_drive_do_step": (ctypes.c_int, [_P, ctypes.c_double, ctypes.c_double, ctypes.c_double, ctypes.c_double,
                                         ctypes.c_double, _P]),
    "cam_drive_outputs": (_D, [_P]),
    "cam_drive_values": (_D, [_P]),
    "cam_drive_get_state": (None, [_P, _D]),
    "cam_drive_set_state": (ctypes.c_int, [_P, _D, _P]),
    "cam_drive_run": (ctypes.c_int, [_P, ctypes.c_long, _D, _D, ctypes.POINTER(ctypes.c_long), _P]),
    "cam_drive_time": (ctypes.c_double, [_P]),
    "cam_drive_steps_taken": (ctypes.c_long, [_P]),
    "cam_drive_last_steps": (ctypes.c_long, [_P]),
    "cam_drive_nx": (ctypes.c_int, [_P]),
    "cam_drive_event": (ctypes.POINTER(CamEventRecord), [_P, ctypes.c_long]),
    "cam_drive_events_logged": (ctypes.c_long, [_P]),
    "cam_event_record_sizeof": (ctypes.c_size_t, []),
    "cam_state_len": (ctypes.c_size_t, []),
}


def engine() -> ctypes.CDLL:
    """The engine library with the signatures of the functions this binding calls."""
    lib = load()
    if not getattr(lib, "_cam_signatures", False):
        for name, (restype, argtypes) in _SIGNATURES.items():
            function = getattr(lib, name)
            function.restype, function.argtypes = restype, argtypes
        lib._cam_signatures = True
    return lib


def raise_for(error: CamError) -> None:
    """The exception of the engine's error status (contract.STATUSES), with its message."""
    raise EXCEPTIONS.get(error.status, SimulationError)(error.message.decode("utf-8", "replace"))


def _set_parameter(lib: ctypes.CDLL, params: ctypes.Array, name: str, value: Any, err: CamError) -> None:
    index = lib.cam_param_index(name.encode())
    if index < 0:
        lib.cam_params_unknown(name.encode(), ctypes.byref(err))
        raise_for(err)
    kind = BY_NAME[name].kind
    if kind == "string" and not isinstance(value, str):
        value = BY_NAME[name].check(value)  # its message shows the value as given (3, not '3')
    if kind == "string" or isinstance(value, str):
        data = str(value).encode("utf-8")
        status = lib.cam_params_set_string(params, index, data, len(data), ctypes.byref(err))
    elif kind == "boolean":
        status = lib.cam_params_set_real(params, index, 1.0 if bool(value) else 0.0, ctypes.byref(err))
    else:
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise ParameterError(f"parameter {name!r} = {value!r} is not a number: "
                                 f"allowed {BY_NAME[name].allowed()}") from None
        status = lib.cam_params_set_real(params, index, number, ctypes.byref(err))
    if status:
        raise_for(err)


class DriveSimulator:
    """One cam drive in the C engine, advanced by ``do_step`` (DriveSimulator's API)."""

    def __init__(self, params: Mapping[str, Any] | None = None, start_time: float = 0.0) -> None:
        """A drive from ``params`` whose clock starts at ``start_time`` [s]: the first ``do_step`` is from there."""
        self._lib = lib = engine()
        self._err = CamError()
        self._params = dict(params or {})
        self._start_time = start_time
        self._drive = None
        raw = ctypes.create_string_buffer(lib.cam_params_sizeof())
        lib.cam_params_defaults(raw)
        try:
            for name, value in self._params.items():
                _set_parameter(lib, raw, name, value, self._err)
            drive = ctypes.create_string_buffer(lib.cam_drive_sizeof())
            if lib.cam_drive_init(drive, raw, ctypes.byref(self._err)):
                raise_for(self._err)
        finally:
            lib.cam_params_free(raw)
        self._drive = drive
        if start_time != 0.0 and lib.cam_drive_set_start_time(drive, float(start_time), ctypes.byref(self._err)):
            raise_for(self._err)
        self.values = (ctypes.c_double * N_OUTPUTS).from_address(
            ctypes.addressof(lib.cam_drive_values(drive).contents))

    def __del__(self) -> None:
        if getattr(self, "_drive", None) is not None:
            self._lib.cam_drive_free(self._drive)
            self._drive = None

    # ------------------------------------------------------------ public
    @property
    def time(self) -> float:
        """s: the time reached."""
        return self._lib.cam_drive_time(self._drive)

    @property
    def steps_taken(self) -> int:
        """Internal steps taken so far (benchmarks)."""
        return self._lib.cam_drive_steps_taken(self._drive)

    def set_inputs(self, u: float, omega_ref: float, omega_dot_ref: float = 0.0) -> None:
        """Inputs used by ``outputs`` before the first step [V, rad/s, rad/s2]."""
        if self._lib.cam_drive_set_inputs(self._drive, u, omega_ref, omega_dot_ref, ctypes.byref(self._err)):
            raise_for(self._err)

    def do_step(self, t: float, h: float, u: float = INPUT_STARTS["u"],
                omega_ref: float = INPUT_STARTS["omega_ref"], omega_dot_ref: float = 0.0) -> None:
        """Advance from t to t + h [s] with the inputs held over the step (FMI co-simulation). t must be where the
        drive is (``time``, to 1e-9 max(1, |time|): fmi2DoStep's rule), else SimulationError names both."""
        if self._lib.cam_drive_do_step(self._drive, t, h, u, omega_ref, omega_dot_ref, ctypes.byref(self._err)):
            raise_for(self._err)

    def outputs(self) -> dict[str, float]:
        """Current value of every output in OUTPUTS (computed once per state)."""
        values = self._lib.cam_drive_outputs(self._drive)
        return dict(zip(OUTPUT_NAMES, values[:N_OUTPUTS]))

    def reset(self) -> None:
        """Back to the start: a new drive from the same parameters."""
        self.__del__()
        self.__init__(self._params, self._start_time)

    def state_array(self) -> array:
        """The engine's whole state as its flat array of doubles (cam_drive.h, CAM_S_*)."""
        raw = (ctypes.c_double * self._lib.cam_state_len())()
        self._lib.cam_drive_get_state(self._drive, raw)
        return array("d", raw)

    def set_state_array(self, state: Sequence[float]) -> None:
        """Restore a state_array(); the engine checks every entry first (SimulationError naming it)."""
        length = self._lib.cam_state_len()
        if len(state) != length:
            raise SimulationError(f"engine state has {len(state)} entries, expected {length}")
        raw = (ctypes.c_double * length)(*state)
        if self._lib.cam_drive_set_state(self._drive, raw, ctypes.byref(self._err)):
            raise_for(self._err)

    def _state_slots(self) -> int:
        """The slots of x that hold this drive's state: theta, omega (2), i (3), a compliant shaft's twist and
        omega_m (5, i then 0 with L = 0)."""
        nx = self._lib.cam_drive_nx(self._drive)
        return NX if nx > NX_RIGID else nx

    def get_state(self) -> dict[str, Any]:
        """Complete internal state, JSON-serialisable (DriveSimulator's keys for the consistent formulation)."""
        s = self.state_array()
        nx = self._state_slots()
        state: dict[str, Any] = {
            "time": s[S_TIME], "u": s[S_U], "omega_ref": s[S_OMEGA_REF], "omega_dot_ref": s[S_OMEGA_DOT_REF],
            "h_next": s[S_H_NEXT], "steps_taken": int(s[S_STEPS_TAKEN]),
            "y": list(s[S_X:S_X + nx]),
            "mode": {"stuck": bool(s[S_STUCK]), "direction": s[S_DIRECTION], "contact": int(s[S_CONTACT]),
                     "s_free": s[S_S_FREE], "side": s[S_SIDE]},
            "engine": list(s),
        }
        state["energy"] = dict(zip(BUDGET_KEYS, s[S_BUDGET:S_BUDGET + 6])) if s[S_HAVE_BUDGET] else None
        return state

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state from get_state; SimulationError names what is wrong (checked before use)."""
        for key in ("time", "u", "omega_ref", "omega_dot_ref", "h_next"):
            if not math.isfinite(float(state[key])):
                raise SimulationError(f"state entry {key!r} = {state[key]!r} is not finite")
        s = self.state_array()
        nx = self._state_slots()
        y = [float(v) for v in state["y"]]
        if len(y) != nx:
            raise SimulationError(f"state 'y' has length {len(y)}, this drive's state has {nx} "
                                  f"({', '.join(STATE_NAMES[:nx])})")
        mode = state["mode"]
        s[S_TIME], s[S_U], s[S_OMEGA_REF] = float(state["time"]), float(state["u"]), float(state["omega_ref"])
        s[S_OMEGA_DOT_REF], s[S_H_NEXT] = float(state["omega_dot_ref"]), float(state["h_next"])
        s[S_STEPS_TAKEN] = float(int(state["steps_taken"]))
        s[S_X:S_X + NX] = array("d", y + [0.0] * (NX - nx))
        s[S_STUCK] = 1.0 if mode["stuck"] else 0.0
        s[S_DIRECTION], s[S_CONTACT] = float(mode["direction"]), float(mode["contact"])
        s[S_S_FREE], s[S_SIDE], s[S_FORM_U] = float(mode["s_free"]), float(mode["side"]), float(state["u"])
        energy = state.get("energy")
        s[S_HAVE_BUDGET] = 0.0 if energy is None else 1.0
        if energy is not None:
            s[S_BUDGET:S_BUDGET + 6] = array("d", [float(energy[key]) for key in BUDGET_KEYS])
        if "engine" in state:  # a follower of its own (closure 'spring'): its s, v, contact, touch-downs, guard
            speed = state["engine"][S_SPEED:S_SPEED + N_SPEED]
            s[S_SPEED:S_SPEED + N_SPEED] = array("d", [float(x) for x in speed])
        self.set_state_array(s)

    def events(self) -> list[dict[str, Any]]:
        """The transitions of the consistent formulation kept by the engine's log (the last 256), oldest
        first: its index (counted from the drive's first transition), name, time [s], the state x before and
        after (theta, omega, i; all NX slots with a compliant shaft, a train or a follower of its own, whose gap
        and rate are the last two), the mode before (a follower of its own: its contact, flank left, sigma)."""
        lib = self._lib
        if lib.cam_event_record_sizeof() != ctypes.sizeof(CamEventRecord):
            raise RuntimeError("the engine's CamEventRecord differs from the binding's")
        total = lib.cam_drive_events_logged(self._drive)
        slots = NX if lib.cam_drive_nx(self._drive) > NX_RIGID else NX_RIGID  # a compliant shaft's two slots
        out = []
        for k in range(max(0, total - 256), total):
            pointer = lib.cam_drive_event(self._drive, k)
            if not pointer:
                continue
            r = pointer.contents
            mode = r.mode_before
            out.append({"index": k, "name": EVENT_NAMES[r.code], "time": r.time,
                        "before": list(r.x_before)[:slots], "after": list(r.x_after)[:slots],
                        "mode_before": {"stuck": bool(mode.stuck), "direction": mode.direction,
                                        "contact": mode.contact, "s_free": mode.s_free, "side": mode.side,
                                        "left": mode.left, "sigma": mode.sigma}})
        return out

    def run(self, table: Any) -> Any:
        """Many communication steps in one engine call: ``table`` has one row (t, h, u, omega_ref,
        omega_dot_ref) per step (a sequence of rows or an (n, 5) array); returns the outputs after each
        step as an (n, len(OUTPUTS)) numpy array (OUTPUTS order). On an error the exception names it;
        the steps before it are done (their outputs are lost with the exception)."""
        import numpy as np

        rows = np.ascontiguousarray(table, dtype=np.float64)
        if rows.ndim != 2 or rows.shape[1] != 5:
            raise ValueError("every row of the input table has 5 entries: t, h, u, omega_ref, omega_dot_ref")
        n = rows.shape[0]
        out = np.empty((n, N_OUTPUTS), dtype=np.float64)
        done = ctypes.c_long(0)
        status = self._lib.cam_drive_run(self._drive, n, rows.ctypes.data_as(_D), out.ctypes.data_as(_D),
                                         ctypes.byref(done), ctypes.byref(self._err))
        if status:
            raise_for(self._err)
        return out


def run_scene(params: Mapping[str, Any] | None, table: Any) -> Any:
    """A whole scene in one engine call: a new drive from params, then the rows (t, h, u, omega_ref,
    omega_dot_ref) of ``table``; the outputs after each step, an (n, len(OUTPUTS)) numpy array."""
    return DriveSimulator(params).run(table)
