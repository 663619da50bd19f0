"""Wrong answers with status OK, and valid configurations refused: one test per class found.

Against the FMI 2.0 interface only (fmpy's FMU2Slave, call by call), so they hold whatever
engine is inside cam.fmu. Each compares the FMU with an independent answer: the same run at
another communication-step pattern, the limit c -> 0, the scipy reference, the table itself.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from fmi_slave import OK, Slave, extract

VERTICAL = {"gamma": math.pi / 2}  # gravity along the stroke (beta = 0: along X, the rise direction)


@pytest.fixture(scope="module")
def unzipped(cam_fmu_path, tmp_path_factory):
    return extract(cam_fmu_path, tmp_path_factory.mktemp("cam_fmu_wrong_answers"))


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


def test_the_paper_formulation_does_not_follow_the_host_step_pattern(unzipped):
    """theta(0.5 s) of the paper's algorithm: uniform 0.1 ms steps against steps alternating 0.07/0.03 ms
    (both on the calculation grid of h_max = 0.01 ms); a pattern off that grid is refused, never answered."""
    params = {"formulation": "paper", "h_max": 1e-5}
    ok, uniform, errors = _run(unzipped, params, [1e-4] * 5000)
    assert ok, errors
    ok, alternating, errors = _run(unzipped, params, [7e-5, 3e-5] * 5000)
    assert ok, errors
    assert alternating[0] == pytest.approx(uniform[0], rel=1e-9)
    ok, off_grid, errors = _run(unzipped, {"formulation": "paper", "h_max": 1e-4}, [7e-5, 3e-5] * 50)
    if ok:  # answered: then the answer must be the uniform pattern's on the same grid
        ok_u, on_grid, _ = _run(unzipped, {"formulation": "paper", "h_max": 1e-4}, [1e-4] * 50)
        assert ok_u and off_grid[0] == pytest.approx(on_grid[0], rel=1e-9)
    else:
        assert any("h_max" in text for text in errors), errors


def test_the_speed_drive_with_backlash_keeps_the_holding_torque(unzipped):
    """Vertical mounting, 5 rad/s for 0.1 s, then omega_ref = 0: the follower rests on the cam and the
    motor holds its weight; with a clearance c the answer converges to c = 0's as c -> 0."""
    names = ("M", "i", "voltage", "theta")

    def inputs(t):
        return {"omega_ref": 5.0 if t < 0.1 - 1e-12 else 0.0}

    results = {}
    for c in (0.0, 1e-9, 1e-3):
        ok, out, errors = _run(unzipped, {"drive": "speed", "c": c, **VERTICAL}, [1e-3] * 200, names, inputs)
        assert ok, errors
        results[c] = out
    M0, i0, v0, theta0 = results[0.0]
    assert abs(M0) > 1e-3  # the weight needs a holding torque at this angle
    for c in (1e-9, 1e-3):
        M, i, v, theta = results[c]
        assert theta == pytest.approx(theta0, rel=1e-12)
        assert M == pytest.approx(M0, rel=1e-6), c
        assert i == pytest.approx(i0, rel=1e-6), c
        assert v == pytest.approx(v0, rel=1e-6), c


_REFERENCES: dict = {}  # beta -> the reference run (the same for every solver)


@pytest.mark.parametrize("beta", [0.0, math.pi])
@pytest.mark.parametrize("solver", ["rk45", "etdrk4", "rk4", "euler"])
def test_gravity_backlash_and_inductance_pass_a_stall(unzipped, solver, beta):
    """Vertical mounting, c = 0.5 mm, L = 1 mH, 3.5 V: every solver runs through the stalls the
    reference runs through, and agrees with it to its promised order."""
    from cam_fmu.reference.integrate import simulate_reference

    params = {"c": 5e-4, "L": 1e-3, "beta": beta, **VERTICAL}
    ok, out, errors = _run(unzipped, {**params, "solver": solver, "h_max": 1e-5 if solver == "euler" else 1e-4},
                           [1e-3] * 500, ("theta", "omega"))
    assert ok, errors
    key = beta
    if key not in _REFERENCES:
        _REFERENCES[key] = simulate_reference(params, 0.5, 1e-3)
    ref = _REFERENCES[key]
    tolerance = {"rk45": 1e-6, "etdrk4": 1e-3, "rk4": 1e-3, "euler": 5e-2}[solver]
    assert out[0] == pytest.approx(ref["theta"][-1], rel=tolerance, abs=tolerance)


TABLE_DWELL = "angle_deg,lift_mm\n0,0\n90,40\n180,0\n"


def test_a_motion_table_does_not_invent_motion(unzipped):
    """0,0 / 90,40 / 180,0: the lift stays within the table's [0, 40] mm and at 0 from 180 to 360 deg."""
    s = Slave(unzipped)
    try:
        assert s.init(motion_table=TABLE_DWELL, drive="speed", omega_ref=10.0) == OK
        lifts, thetas = [], []
        for _ in range(700):
            assert s.step(1e-3) == OK
            theta, s_cam = s.get("theta", "s_cam")
            thetas.append(theta)
            lifts.append(s_cam)
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
        assert s.init(motion_table=text, drive="speed", omega_ref=10.0) == OK
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
