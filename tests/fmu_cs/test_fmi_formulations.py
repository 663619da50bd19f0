"""Issue 19's classes of the paper formulation, the speed drive and the stall, against the FMI interface
of cam.fmu (like tests/fmu_cs/test_fmi_boundary.py and tests/fmu_cs/test_fmi_wrong_answers.py), each compared with an
independent answer: the uniform step pattern, c = 0, the scipy reference."""
from __future__ import annotations

import math

import pytest

from fmi_slave import DISCARD, ERROR, OK, Slave, extract
from test_fmi_wrong_answers import _run

VERTICAL = {"gamma": math.pi / 2}  # gravity along the stroke (beta = 0: along X, the rise direction)


@pytest.fixture(scope="module")
def unzipped(engine_fmu_path, tmp_path_factory):
    return extract(engine_fmu_path, tmp_path_factory.mktemp("cam_fmu_formulations"))


def test_the_initial_voltage_output_is_u_in_the_paper_formulation(unzipped):
    s = Slave(unzipped)
    try:
        assert s.instantiate()
        assert s.set(formulation="paper", u=7.0) == OK
        assert s.init() == OK
        assert s.get("voltage") == [7.0]
    finally:
        s.free()


def test_the_max_steps_message_names_h_max_when_it_is_the_cause(unzipped):
    s = Slave(unzipped)
    try:
        assert s.init(h_max=1e-9, max_steps=10.0) == OK
        assert s.step(1e-3) in (DISCARD, ERROR)
        assert "h_max" in s.errors()[-1]
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




@pytest.mark.parametrize("beta", [0.0, math.pi])
@pytest.mark.parametrize("solver", ["rk45", "etdrk4", "rk4", "euler"])
def test_gravity_backlash_and_inductance_pass_a_stall(unzipped, solver, beta, reference_runs):
    """Vertical mounting, c = 0.5 mm, L = 1 mH, 3.5 V: every solver runs through the stalls the
    reference runs through, and agrees with it to its promised order."""
    params = {"c": 5e-4, "L": 1e-3, "beta": beta, "closure": "kinematic", **VERTICAL}  # the solvers on the paper's rule
    ok, out, errors = _run(unzipped, {**params, "solver": solver, "h_max": 1e-5 if solver == "euler" else 1e-4},
                           [1e-3] * 500, ("theta", "omega"))
    assert ok, errors
    ref = reference_runs.simulate(params, 0.5, 1e-3)  # the same for every solver
    tolerance = {"rk45": 1e-6, "etdrk4": 1e-3, "rk4": 1e-3, "euler": 5e-2}[solver]
    assert out[0] == pytest.approx(ref["theta"][-1], rel=tolerance, abs=tolerance)


