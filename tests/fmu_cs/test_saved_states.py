"""Saved states are checked as a whole: a CRC-32 over the serialised blob (csrc/fmi/checksum.c) refuses every
changed bit, and the engine's restore (csrc/src/state.c) checks the entries against each other and against the
drive, each rule with a message naming what is inconsistent, and puts nothing back on a refusal (docs/fmu.md,
"Saved states"). Through FMI 2.0 and 3.0 (fmpy, call by call) and the Python DriveSimulator."""
from __future__ import annotations

import math
import struct
import zlib

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cam_fmu.engine import simulator as S
from cam_fmu.engine.simulator import DriveSimulator
from cam_fmu.errors import SimulationError
from fmi_slave import ERROR, OK, Slave, extract

STATE_LEN = S.engine().cam_state_len()  # the drive's doubles, last in the serialised blob before the 4-byte CRC (no motion table)


def _reseal(blob: bytearray) -> bytes:
    """The blob with its CRC-32 recomputed (zlib's CRC-32 is checksum.c's): an edit the checksum cannot see."""
    struct.pack_into("<I", blob, len(blob) - 4, zlib.crc32(bytes(blob[:-4])))
    return bytes(blob)


def _edit_slot(blob: bytes, slot: int, value: float) -> bytes:
    """The serialised state with the drive's state slot ``slot`` (cam_drive.h CAM_S_*) set to ``value``, resealed."""
    edited = bytearray(blob)
    struct.pack_into("<d", edited, len(blob) - 4 - 8 * STATE_LEN + 8 * slot, value)
    return _reseal(edited)


@pytest.fixture(scope="module")
def unzipped(engine_fmu_path, tmp_path_factory):
    return extract(engine_fmu_path, tmp_path_factory.mktemp("states2"))


@pytest.fixture(scope="module")
def unzipped3(cam3_fmu_path, tmp_path_factory):
    return extract(cam3_fmu_path, tmp_path_factory.mktemp("states3"))


def _slave(unzipped) -> tuple[Slave, bytes]:
    """A cam.fmu slave 50 steps into a run with backlash (mid-stroke, moving) and its serialised state."""
    slave = Slave(unzipped)
    assert slave.init(c=5e-4) == OK and slave.run(0.05, 1e-3) == OK
    return slave, bytes(slave.fmu.serializeFMUstate(slave.fmu.getFMUstate()))


# ------------------------------------------------------------------ corruption: every single-bit flip
def test_every_single_bit_flip_of_a_cam_fmu_state_is_refused_with_a_message(unzipped):
    """About 40 single-bit flips of a saved state used to restore with OK and another trajectory."""
    slave, blob = _slave(unzipped)
    before = slave.get("theta", "omega", "s")
    for bit in range(8 * len(blob)):
        bad = bytearray(blob)
        bad[bit // 8] ^= 1 << (bit % 8)
        seen = len(slave.messages)
        assert slave.call("deSerializeFMUstate", bytes(bad)) == ERROR, bit
        texts = [text for status, _c, text in slave.messages[seen:] if status == ERROR]
        assert texts and texts[-1].startswith("fmi2DeSerializeFMUstate: "), (bit, texts)
        assert "corrupt" in texts[-1] or "not a serialised cam state" in texts[-1], texts
    assert slave.get("theta", "omega", "s") == before  # nothing was restored
    slave.fmu.setFMUstate(slave.fmu.deSerializeFMUstate(blob))  # the true blob still restores
    assert slave.step(1e-3) == OK
    slave.free()


def test_every_single_bit_flip_of_a_cam3_fmu_state_is_refused_with_a_message(unzipped3):
    from fmpy import read_model_description
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi3 import FMU3Slave

    md = read_model_description(str(unzipped3))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    log: list[tuple[int, str]] = []
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=str(unzipped3), modelIdentifier="cam", instanceName="flips")
    fmu.instantiate(logMessage=lambda env, status, category, message: log.append((status, message.decode())))
    fmu.setFloat64([vr["c"]], [5e-4])
    fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()
    for k in range(50):
        fmu.doStep(k * 1e-3, 1e-3)
    blob = bytes(fmu.serializeFMUState(fmu.getFMUState()))
    for bit in range(8 * len(blob)):
        bad = bytearray(blob)
        bad[bit // 8] ^= 1 << (bit % 8)
        seen = len(log)
        with pytest.raises(FMICallException) as refused:
            fmu.deserializeFMUState(bytes(bad))
        assert refused.value.status == 3, bit  # fmi3Error
        texts = [text for status, text in log[seen:] if status == 3]
        assert texts and texts[-1].startswith("fmi3DeserializeFMUState: "), (bit, texts)
        assert "corrupt" in texts[-1] or "not a serialised cam state" in texts[-1], texts
    fmu.setFMUState(fmu.deserializeFMUState(blob))
    fmu.doStep(0.05, 1e-3)
    fmu.terminate()
    fmu.freeInstance()


# ------------------------------------------------------------------ consistency through FMI
def test_a_resealed_state_whose_direction_contradicts_omega_is_refused_by_name(unzipped):
    """direction -1 while omega = +3.19 restored with OK (50 steps later omega 0.93 instead of 2.72)."""
    slave, blob = _slave(unzipped)
    omega = slave.get("omega")[0]
    assert omega > 0.5
    state = slave.fmu.deSerializeFMUstate(_edit_slot(blob, S.S_DIRECTION, -1.0))  # the checksum holds: resealed
    seen = len(slave.messages)
    assert slave.call("setFMUstate", state) == ERROR
    text = slave.messages[seen:][-1][2]
    assert text.startswith("fmi2SetFMUstate: ") and "direction -1" in text and "sign of omega" in text
    assert slave.get("omega") == [omega]
    slave.free()


def test_a_resealed_state_before_the_start_time_is_refused_by_name(unzipped):
    slave, blob = _slave(unzipped)
    state = slave.fmu.deSerializeFMUstate(_edit_slot(blob, S.S_TIME, -0.5))
    seen = len(slave.messages)
    assert slave.call("setFMUstate", state) == ERROR
    assert "state time -0.5 s is before the drive's start time 0" in slave.messages[seen:][-1][2]
    slave.free()


# ------------------------------------------------------------------ consistency: the Python DriveSimulator
def _moving(params=None) -> DriveSimulator:
    sim = DriveSimulator(params or {})
    for k in range(60):
        sim.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
    return sim


INCONSISTENT = [  # (parameters, slot, value, words of the message)
    ({}, S.S_DIRECTION, -1.0, "sign of omega"),
    ({}, S.S_STUCK, 1.0, "a held shaft has omega = 0"),
    ({}, S.S_CONTACT, 0.0, "no backlash"),
    ({}, S.S_TIME, -1e-3, "before the drive's start time"),
    ({}, S.S_X + 2, 0.5, "no inductance"),
    ({}, S.S_X + 3, 0.1, "shaft is rigid"),
    ({"c": 5e-4, "closure": "kinematic"}, S.S_S_FREE, 1.0, "beyond the clearance"),
    ({"c": 5e-4}, S.S_X + 7, 0.01, "follower gap 0.01 m"),   # its own follower's gap x[CAM_GAP]: off the groove
    ({"drive": "speed"}, S.S_HAVE_BUDGET, 1.0, "keeps none"),
    ({}, S.S_BUDGET, -1.0, "more energy than its account"),  # work_in: the source delivered -1 J
    ({}, S.S_X + 1, 1e150, "more energy than its account"),  # finite outputs, 1/2 J omega^2 far past the books
    ({}, S.S_X + 1, 1e200, "none the drive can reach"),
]


@pytest.mark.parametrize("params,slot,value,words", INCONSISTENT, ids=[w for *_, w in INCONSISTENT])
def test_an_inconsistent_state_is_refused_naming_the_rule_and_changes_nothing(params, slot, value, words):
    sim = _moving(params)
    if params.get("c"):  # free in the gap, at the cam: the follower's position is an entry
        state = sim.state_array()
        state[S.S_CONTACT], state[S.S_S_FREE] = 0.0, sim.outputs()["s_cam"]
        sim.set_state_array(state)
    saved, out = sim.state_array(), sim.outputs()
    state = sim.state_array()
    state[slot] = value
    with pytest.raises(SimulationError, match=words):
        sim.set_state_array(state)
    assert sim.state_array() == saved and sim.outputs() == out


def test_a_drive_started_late_refuses_a_state_from_before_its_start():
    sim = DriveSimulator({}, start_time=1.0)
    sim.do_step(1.0, 1e-3, 3.5, 1.0)
    state = sim.get_state()
    sim.set_state(state)  # its own state restores
    with pytest.raises(SimulationError, match=r"state time 0.5 s is before the drive's start time 1(\.0)? s"):
        sim.set_state(dict(state, time=0.5))


# A value for a slot: the rule-relevant specials and random numbers.
VALUES = st.one_of(st.sampled_from([0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 1e-300, 1e300, -1e300]),
                   st.floats(-1e3, 1e3, allow_nan=False))
SLOTS = [S.S_TIME, S.S_X, S.S_X + 1, S.S_X + 2, S.S_STUCK, S.S_DIRECTION, S.S_CONTACT, S.S_S_FREE, S.S_SIDE,
         S.S_HAVE_BUDGET, S.S_BUDGET, S.S_BUDGET + 4]


@settings(max_examples=150, deadline=None)
@given(params=st.sampled_from([{}, {"c": 5e-4}, {"L": 1e-3}, {"drive": "speed"}]),
       edits=st.lists(st.tuples(st.sampled_from(SLOTS), VALUES), min_size=1, max_size=3))
def test_property_a_restored_state_is_one_the_drive_can_be_in_and_a_refused_one_changes_nothing(params, edits):
    """Any edit of up to three entries: the restore refuses it and the drive is as before, or the restored state
    keeps the rules (a moving shaft's direction is the sign of omega, a held shaft has omega = 0, a free follower
    lies in the gap, no time before the start beyond rounding) and its outputs are finite."""
    sim = _moving(params)
    saved = sim.state_array()
    state = sim.state_array()
    for slot, value in edits:
        state[slot] = value
    try:
        sim.set_state_array(state)
    except SimulationError as exc:
        assert str(exc) and sim.state_array() == saved
        return
    s = sim.state_array()
    omega = s[S.S_X + 1]
    if params.get("drive") != "speed":
        assert (s[S.S_STUCK] == 1.0 and omega == 0.0) or (s[S.S_STUCK] == 0.0 and s[S.S_DIRECTION] * omega >= 0.0)
    assert s[S.S_TIME] >= -1e-9  # the start (0) less the rounding slack the step's time check allows, docs/fmu.md
    out = sim.outputs()
    assert all(math.isfinite(v) for v in out.values())
    assert abs(out["s"] - out["s_cam"]) <= params.get("c", 0.0) * (1 + 1e-9) + 1e-12


@pytest.mark.parametrize("params", [{}, {"k_shaft": 40.0, "J_cam": 2e-5}, {"c": 5e-4}],
                         ids=["rigid", "compliant", "own follower"])
def test_a_state_of_the_wrong_length_is_refused_naming_the_slots(params):
    """A saved 'y' one slot short: the error names both lengths and this drive's slots (a drive with all nine slots
    raised KeyError here before)."""
    sim = _moving(params)
    state = sim.get_state()
    n = len(state["y"])
    state["y"] = state["y"][:-1]
    with pytest.raises(SimulationError, match=rf"length {n - 1}, this drive's state has {n} \(theta, omega"):
        sim.set_state(state)
