"""Wrong answers with status OK, and valid configurations refused: one test per class found.

Against the FMI 2.0 interface only (fmpy's FMU2Slave, call by call), so they hold whatever
engine is inside cam.fmu; here the C-built one. Each compares the FMU with an independent answer:
the table itself. (The classes of the formulations and the stall are in test_fmi_formulations.py.)
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from fmi_slave import OK, Slave, extract

@pytest.fixture(scope="module")
def unzipped(engine_fmu_path, tmp_path_factory):
    return extract(engine_fmu_path, tmp_path_factory.mktemp("cam_fmu_wrong_answers"))


def _run(unzipped, params, steps, names=("theta",), inputs=None):
    """Run the steps (a list of step sizes) from t = 0; (statuses ok?, outputs at the end, errors)."""
    s = Slave(unzipped)
    try:
        if s.init(**params) != OK:
            return False, None, s.errors()
        for k, h in enumerate(steps):
            if inputs is not None:
                assert s.set(**inputs(s.time)) == OK
            if s.step(h) != OK:
                return False, None, s.errors()
        return True, s.get(*names), s.errors()
    finally:
        s.free()


TABLE_DWELL = "angle_deg,lift_mm\n0,0\n90,40\n180,0\n"


def test_a_motion_table_does_not_invent_motion(unzipped):
    """0,0 / 90,40 / 180,0: over a turn the lift stays within the table's [0, 40] mm and at 0 from
    180 to 360 deg (the voltage drive at its default 3.5 V turns the cam)."""
    s = Slave(unzipped)
    try:
        assert s.init(motion_table=TABLE_DWELL) == OK
        lifts, thetas = [], []
        while not thetas or thetas[-1] < 2 * math.pi + 0.5:
            assert s.step(1e-3) == OK
            theta, s_cam = s.get("theta", "s_cam")
            thetas.append(theta)
            lifts.append(s_cam)
            assert s.time < 10.0, "the cam should turn once within 10 s"
    finally:
        s.free()
    lifts, angles = np.array(lifts), np.degrees(np.array(thetas)) % 360.0
    assert lifts.min() >= 0.0 and lifts.max() <= 0.040
    assert np.all(lifts[(angles >= 180.0) & (angles <= 360.0)] == 0.0)
    assert lifts.max() > 0.039  # it does rise to the table's 40 mm


def test_a_table_row_that_does_not_parse_is_named_not_dropped(unzipped):
    s = Slave(unzipped)
    try:
        assert s.instantiate()
        status = s.set(motion_table="angle_deg,lift_mm\n0,O\n90,40\n180,0\n")
        if status == OK:
            status = s.init()
        assert status != OK
        assert any("'O'" in text and "row" in text for text in s.errors()), s.errors()
    finally:
        s.free()
    s = Slave(unzipped)  # a UTF-8 BOM, as Excel writes it, is not a row
    try:
        assert s.init(motion_table="\ufeff0,4\n90,40\n180,4\n") == OK
        assert s.get("s_cam")[0] == pytest.approx(0.004, rel=1e-12)
    finally:
        s.free()


def test_a_million_row_table_runs_and_restores(unzipped):
    """A table of 10^6 rows: initialisation, steps that cross thousands of knots, and state restores."""
    angles = np.arange(1_000_000) * (360.0 / 1_000_000)
    lifts = 20.0 * (1.0 - np.cos(np.radians(angles)))
    text = "\n".join(f"{float(a)!r},{float(h)!r}" for a, h in zip(angles, lifts))
    s = Slave(unzipped)
    try:
        assert s.init(motion_table=text) == OK
        state = s.fmu.getFMUstate()
        for _ in range(3):
            assert s.step(1e-3) == OK
            s.fmu.setFMUstate(state)
            s.time = 0.0
        assert s.run(0.01, 1e-3) == OK
        theta, s_cam = s.get("theta", "s_cam")
        assert s_cam == pytest.approx(0.020 * (1.0 - math.cos(theta)), rel=1e-6, abs=1e-9)
    finally:
        s.free()
