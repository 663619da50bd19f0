"""The FMI boundary of cam.fmu: each class of defect an adversarial round found, one test each.

Written against the FMI 2.0 interface only (fmpy's FMU2Slave, call by call), so they hold
whatever engine is inside the FMU. The rule they enforce: a call ends with OK and a correct
answer, or with an FMI error whose message names its cause; a refused call changes nothing.
"""
from __future__ import annotations

import math
import struct
import zlib

import pytest

from fmi_slave import DISCARD, ERROR, OK, Slave, extract


@pytest.fixture(scope="module")
def unzipped(engine_fmu_path, tmp_path_factory):
    return extract(engine_fmu_path, tmp_path_factory.mktemp("cam_fmu_boundary"))


@pytest.fixture
def slave(unzipped):
    s = Slave(unzipped)
    yield s
    s.free()


def test_outputs_in_initialization_mode_follow_the_inputs_set_there(slave):
    """Outputs read in initialisation mode are those of the inputs set there, not of the start values."""
    assert slave.instantiate()
    assert slave.call("setupExperiment", None, 0.0) == OK
    assert slave.call("enterInitializationMode") == OK
    assert slave.set(u=7.0) == OK
    i, voltage = slave.get("i", "voltage")
    R = slave.fmu.getReal([slave.vr["R"]])[0]
    assert i == pytest.approx(7.0 / R, rel=1e-12)  # at rest, L = 0: i = u / R
    assert voltage == 7.0
    assert slave.set(u=3.0) == OK
    assert slave.get("i")[0] == pytest.approx(3.0 / R, rel=1e-12)


@pytest.mark.parametrize("formulation", ["consistent"])
def test_the_initial_voltage_output_is_the_input_in_every_formulation(slave, formulation):
    assert slave.instantiate()
    assert slave.set(formulation=formulation, u=7.0) == OK
    assert slave.init() == OK
    assert slave.get("voltage") == [7.0]


@pytest.mark.parametrize("claimed", [0.5, 0.0, -1e300, math.nan, math.inf])
def test_a_step_that_does_not_start_where_the_fmu_is_is_refused(slave, claimed):
    assert slave.init() == OK
    assert slave.run(0.01, 1e-3) == OK
    theta = slave.get("theta")[0]
    assert slave.step(1e-3, t=claimed) == ERROR
    text = " ".join(slave.errors())
    assert "currentCommunicationPoint" in text and "0.01" in text
    last = slave.fmu.getRealStatus(2)  # fmi2LastSuccessfulTime
    assert last == pytest.approx(0.01, abs=1e-15)
    assert slave.get("theta")[0] == theta  # nothing moved


def test_a_step_that_starts_where_the_fmu_is_to_rounding_is_taken(slave):
    assert slave.init() == OK
    t = 0.0
    for _ in range(10):
        assert slave.step(0.1, t=t) == OK
        t += 0.1  # summed: 0.9999999999999999 after ten steps
    assert slave.step(0.1, t=1.0) == OK


def test_a_multi_value_set_with_one_bad_value_writes_nothing(slave):
    assert slave.init() == OK
    before = slave.fmu.getReal([slave.vr["u"], slave.vr["omega_ref"]])
    status = slave.call("setReal", [slave.vr["u"], slave.vr["omega_ref"]], [7.0, math.nan])
    assert status == ERROR
    assert "omega_ref" in " ".join(slave.errors())
    assert slave.fmu.getReal([slave.vr["u"], slave.vr["omega_ref"]]) == before


def test_the_state_machine_refuses_calls_out_of_order(unzipped):
    s = Slave(unzipped)
    assert s.instantiate()
    assert s.step(1e-3) == ERROR  # before initialisation
    assert "fmi2DoStep" in " ".join(s.errors())
    s.free()
    s = Slave(unzipped)
    assert s.init() == OK
    assert s.call("enterInitializationMode") == ERROR  # in step mode
    s.free()
    s = Slave(unzipped)
    assert s.init() == OK
    assert s.call("terminate") == OK
    assert s.step(1e-3) == ERROR  # after fmi2Terminate
    s.free()


def test_instantiate_checks_the_guid(unzipped):
    s = Slave(unzipped, guid="{00000000-0000-0000-0000-000000000000}")
    assert not s.instantiate()
    assert any("GUID" in text for text in s.errors())


def _set_raw_string(slave, name: str, raw: bytes) -> int:
    import ctypes

    from fmpy.fmi1 import FMICallException

    vr = (ctypes.c_uint * 1)(slave.vr[name])
    value = (ctypes.c_char_p * 1)(raw)
    try:
        return slave.fmu.fmi2SetString(slave.fmu.component, vr, 1, value)
    except FMICallException as exc:
        return exc.status


def test_a_string_that_is_not_utf8_is_an_error_naming_the_parameter(slave):
    assert slave.instantiate()
    status = _set_raw_string(slave, "rise_law", b"\xff\xfe\xfa")
    assert status == ERROR
    assert any("rise_law" in text and "UTF-8" in text for text in slave.errors())
    assert slave.call("reset") == OK  # the instance is not bricked
    assert slave.init() == OK
    assert slave.run(0.01, 1e-3) == OK


def test_messages_name_the_variable_or_setting_at_fault(slave):
    assert slave.instantiate()
    assert slave.call("setupExperiment", None, 0.0) == OK
    assert slave.call("enterInitializationMode") == OK
    assert slave.call("getReal", [99999]) == ERROR
    assert any("99999" in text and "value reference" in text for text in slave.errors())
    assert slave.call("setString", [slave.vr["u"]], ["x"]) == ERROR
    assert any("'u'" in text for text in slave.errors())
    assert slave.call("reset") == OK
    huge = "x" * 20_000_000
    assert slave.set(rise_law=huge) == ERROR
    assert all(len(text) < 4096 for text in slave.errors())  # the bad value is cut, not echoed whole


def test_a_step_count_that_h_max_makes_impossible_names_h_max(slave):
    assert slave.init(h_max=1e-9, max_steps=10.0) == OK
    assert slave.step(1e-3) == DISCARD
    text = slave.errors()[-1]
    assert "h_max = 1e-09 s caps every internal step" in text and "1e+06" in text


def test_loose_rk45_tolerances_are_named_in_the_advice(slave):
    """rk45 with rtol = 0.1, atol = 1 and h_max = 0.1 s at 0.1 s steps breaks the energy bound: the
    refusal names rtol and atol and does not advise the solver in use."""
    assert slave.init(rtol=0.1, atol=1.0, h_max=0.1) == OK
    statuses = [slave.step(0.1) for _ in range(3)]
    assert statuses[0] == ERROR
    text = slave.errors()[0]
    assert "energy was created" in text and "rtol = 0.1" in text and "atol = 1" in text
    assert "use solver 'rk45'" not in text


def test_a_restored_state_publishes_outputs_computed_from_it(slave):
    """Every number of a saved state edited by +0.5: the restore is refused, or the positions it
    publishes are those the restored state evolves from (positions are continuous: no jump over a
    1e-9 s step, impacts included)."""
    assert slave.init(c=0.002) == OK
    assert slave.run(0.05, 1e-3) == OK
    blob = bytes(slave.fmu.serializeFMUstate(slave.fmu.getFMUstate()))
    names = ["theta", "s", "s_cam"]
    edited_published = 0
    for edited in _edits(blob):
        try:
            state = slave.fmu.deSerializeFMUstate(edited)
            slave.fmu.setFMUstate(state)
        except Exception:
            slave.messages.clear()
            continue
        before = slave.get(*names)
        if slave.step(1e-9, t=slave.fmu.getRealStatus(2)) != OK:
            slave.messages.clear()
            continue
        after = slave.get(*names)
        for name, b, a in zip(names, before, after):
            assert abs(a - b) <= 1e-6 * max(1.0, abs(b)), (name, b, a)
        edited_published += 1
    assert edited_published > 0  # some edits are valid states (theta + 0.5 is one)


def _edits(blob: bytes):
    """The blob with one number changed by +0.5, for every number in it: little-endian doubles of a
    binary state, or the numerals of a text (JSON) state."""
    import re

    if blob[:1] in (b"{", b"["):
        for match in re.finditer(rb"-?\d+\.\d+(?:e[-+]?\d+)?", blob):
            value = float(match.group())
            if 1e-3 < abs(value) < 1e3:
                yield blob[:match.start()] + repr(value + 0.5).encode() + blob[match.end():]
        return
    for offset in range(0, len(blob) - 7):
        (value,) = struct.unpack_from("<d", blob, offset)
        if math.isfinite(value) and 1e-3 < abs(value) < 1e3:
            edited = bytearray(blob)
            struct.pack_into("<d", edited, offset, value + 0.5)
            if blob[:4] == b"SMAC":  # cam.fmu's serialised state: resealed with its CRC-32 (csrc/fmi/checksum.h)
                struct.pack_into("<I", edited, len(edited) - 4, zlib.crc32(bytes(edited[:-4])))
            yield bytes(edited)
