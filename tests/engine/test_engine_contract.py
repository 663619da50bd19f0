"""The engine's contract (engine/contract.py, generated into cam_contract.h by engine/codegen.py) as the compiled
library has it: the structures' sizes, the event names, the saved state's length, version and slots, read
against what the drive publishes (its outputs), not against the table itself."""
from __future__ import annotations

import ctypes

import pytest

from cam_fmu.engine import contract
from cam_fmu.engine.simulator import CamError, CamEventRecord, CamMode, DriveSimulator, engine
from cam_fmu.physics.formulations.consistent import EVENT_NAMES
from cam_fmu.physics.variables import STATES


def test_the_structures_have_the_libraries_sizes():
    lib = engine()
    assert lib.cam_event_record_sizeof() == ctypes.sizeof(CamEventRecord)
    assert ctypes.sizeof(CamError) == 4 + contract.MESSAGE_LEN  # an int status, then the message's bytes
    assert CamEventRecord.mode_before.offset + ctypes.sizeof(CamMode) <= ctypes.sizeof(CamEventRecord)
    sizeof = lib.cam_profile_sizeof
    sizeof.restype, sizeof.argtypes = ctypes.c_size_t, []
    assert sizeof() == ctypes.sizeof(contract.structure("CamProfile"))


def test_event_names_are_the_hybrid_systems():
    lib = engine()
    name = lib.cam_event_name
    name.restype, name.argtypes = ctypes.c_char_p, [ctypes.c_int]
    assert [name(k).decode() for k in range(len(EVENT_NAMES))] == list(EVENT_NAMES)
    assert name(len(EVENT_NAMES)) is None and name(-1) is None


def test_state_slots_are_model_exchanges_first_states():
    assert [row[0] for row in STATES[:contract.NX]] == [state for _, state in contract.X_SLOTS]


@pytest.mark.parametrize("params", [{"L": 1e-3, "c": 5e-4}, {"k_shaft": 40.0, "J_cam": 2e-5, "L": 1e-3}])
def test_saved_state_slots_hold_what_the_drive_publishes(params):
    """After a few steps the saved state's version, time, inputs and x slots hold the drive's time, the inputs
    given and the published theta, omega, i (and a compliant shaft's twist theta_m - theta)."""
    lib = engine()
    sim = DriveSimulator(params)
    for k in range(20):
        sim.do_step(k * 1e-3, 1e-3, u=3.5)
    s, out, slots = sim.state_array(), sim.outputs(), contract.state_slots()
    assert len(s) == lib.cam_state_len() == contract.STATE_LEN >= slots["END"]
    assert s[slots["VERSION"]] == contract.STATE_VERSION
    assert s[slots["TIME"]] == sim.time and s[slots["U"]] == 3.5
    x = s[slots["X"]:slots["X"] + contract.NX]
    assert (x[0], x[1], x[2]) == (out["theta"], out["omega"], out["i"])
    if "k_shaft" in params:
        assert x[3] == pytest.approx(out["theta_m"] - out["theta"], rel=1e-12, abs=1e-15)
