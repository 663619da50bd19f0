"""The engine's drive kernel against the readable model in physics: two implementations, bit for bit.

The scipy reference integrates ``physics`` (DriveModel, EnergyBudget, the
breakpoint search of kinematics); the kernel (cam_fmu/kernel/drive_kernel.py,
compiled) keeps its own copy of the same formulas in the same order of
operations. Here every formula is evaluated by both at the same inputs and
the results must have the same bits. (Goes with the kernel, issue 18.)
"""
from __future__ import annotations

import math
import random

import pytest

from cam_fmu import kernel
from cam_fmu.fmu.engine import DriveSimulator
from cam_fmu.kernel import drive_kernel
from cam_fmu.kinematics.cam_program import first_angle_crossed
from cam_fmu.physics import drive, energy
from cam_fmu.physics.formulations import consistent

TWO_PI = 2.0 * math.pi
# guide friction with sideways and axial gravity (both branches of the side force), dwells, a user table
CASES = {
    "defaults": {},
    "tilted": {"gamma": math.radians(90.0), "beta": math.radians(135.0), "mu": 0.2, "G": 40.0},
    "dwells": {"rise_law": "cycloidal", "return_law": "modified_trapezoid", "rise_angle": 2.0,
               "upper_dwell": 1.0, "return_angle": 2.0, "lower_dwell": TWO_PI - 5.0, "mu": 0.1,
               "gamma": math.radians(60.0), "beta": math.radians(20.0)},
    "table": {"motion_table": "0 0\n90 0.01\n180 0.02\n270 0.01", "mu": 0.05},
    "no_follower": {"follower_inertia": False, "gravity": False, "guide_friction": False},
}


def _bits(*values: float) -> list[str]:
    return [float(v).hex() for v in values]


@pytest.fixture(params=sorted(CASES))
def pair(request):
    assert kernel.compiled(), f"the compiled kernel is not in use ({drive_kernel.__file__}): run setup.sh"
    sim = DriveSimulator(CASES[request.param])
    return sim.model, sim.kernel


def _states(seed: int, n: int = 400):
    rng = random.Random(seed)
    for _ in range(n):
        yield (rng.uniform(-TWO_PI, 3.0 * TWO_PI), rng.choice([0.0, rng.uniform(-300.0, 300.0)]),
               rng.uniform(-0.5, 0.5), rng.choice([1.0, -1.0]), rng.random() < 0.8, rng.choice([0.0, 1.0, -1.0]))


def test_omega_dot_side_force_and_load_agree_bit_for_bit(pair):
    model, k = pair
    differ = []
    for theta, omega, torque, direction, engaged, side in _states(1):
        ours = model.omega_dot(theta, omega, torque, direction, engaged, side)
        theirs = k.omega_dot(theta, omega, torque, direction, engaged, side)
        forces = (model.side_force(theta, omega, torque, direction, side),
                  k.side_force(theta, omega, torque, direction, side))
        load = model.load(theta, omega, ours, direction, engaged)
        k.load(theta, omega, ours, direction, engaged)
        kload = (k.load_M, k.load_J, k.load_f, k.load_v, k.load_a, k.load_alpha, k.load_s)
        if _bits(ours, forces[0], load.M, load.J, load.f, load.v, load.a, load.alpha, load.s_cam) \
                != _bits(theirs, forces[1], *kload):
            differ.append((theta, omega, torque, direction, engaged, side))
    assert differ == [], differ[:3]
    if model.mu > 0.0:  # the cases reach both friction branches: the check sees the branch choice
        signs = {math.copysign(1.0, model.side_force(t, w, q, d)) for t, w, q, d, _, _ in _states(2)}
        assert signs == {1.0, -1.0}


def test_guide_friction_solve_agrees_bit_for_bit():
    rng = random.Random(3)
    rows = [(rng.uniform(-50, 50), rng.uniform(-2, 2), rng.choice([1.0, -1.0, 0.0]), rng.choice([0.0, 0.3, 1e-3]),
             rng.uniform(0, 20), rng.choice([0.0, 1.0, -1.0])) for _ in range(2000)]
    ours = [drive.solve_guide_friction(*r) for r in rows]
    assert [_bits(f) for f in ours] == [_bits(drive_kernel.solve_guide_friction(*r)) for r in rows]
    assert 0.0 in ours and max(ours) > 0.0  # mu = 0, and real friction, among the cases


def test_breakpoint_search_agrees_bit_for_bit():
    from array import array

    model = drive.DriveModel(CASES["dwells"])
    points = model.program.breakpoints()
    rng = random.Random(4)
    spans = [(a, a + d) for a in (rng.uniform(-1e3, 1e3) for _ in range(300))
             for d in (0.3, -0.3, 7.0, -7.0, 0.0, 1e-9)] + [(p, p + 1.0) for p in points]
    ours = [first_angle_crossed(points, *s) for s in spans]
    theirs = [drive_kernel.first_angle_crossed(array("d", points), len(points), *s) for s in spans]
    assert [_bits(x) for x in ours] == [_bits(x) for x in theirs]
    assert sum(not math.isnan(x) for x in ours) > len(spans) // 2


def test_energy_budget_agrees_bit_for_bit():
    sim = DriveSimulator({"L": 1e-3, "inductance": True})
    out = sim.outputs()
    start = (out["theta"], out["omega"], out["i"], out["s"], out["J"])
    ours, theirs = energy.EnergyBudget(sim.model, *start), drive_kernel.EnergyBudget(sim.model, *start)
    for k in range(200):
        sim.do_step(k * 1e-3, 1e-3, 3.0 + 2.0 * math.sin(k / 7.0), 0.0)
        out = sim.outputs()
        for budget in (ours, theirs):
            budget.step(sim.u, 1e-3, out["theta"], out["i"])
        state = (out["omega"], out["s"], out["J"], out["i"])
        assert _bits(*ours.excess(*state)) == _bits(*theirs.excess(*state)), k
    assert ours.to_dict() == theirs.to_dict() and ours.work_in > 0.0


def test_the_kernel_takes_the_models_event_names_and_constants():
    assert drive_kernel.EVENT_NAMES is consistent.EVENT_NAMES
    assert drive_kernel.SIDE_HYSTERESIS is consistent.SIDE_HYSTERESIS
    assert drive_kernel.RELATIVE_SLACK is energy.RELATIVE_SLACK
