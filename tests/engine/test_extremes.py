"""cam.fmu at the extremes (issue 5): each case asserts physics, not just "no crash".

cam.fmu is C (no Python inside): fmpy loads it into this process, as FMPy's own tests do, one instance
reused with reset() between the cases. Per case: the
stop time is reached or an FMI error is reported, the outputs are finite, an
energy or momentum bound holds, and where the reference can run, the FMU agrees
with it (simulate_reference, scipy, tight tolerances).
"""
from __future__ import annotations

import math
import shutil

import numpy as np
import pytest

NAMES = ("time", "omega", "theta", "s", "i", "M", "J", "v", "a", "alpha", "s_cam")
PI = math.pi

# Parameters of the paper (parameters.py defaults) used in the closed forms below.
R, C_E, C_M, J_M, M_F = 19.0, 0.146, 0.015 * 9.80665, 4.41e-5, 0.012
U_BREAK = R * M_F / C_M  # V: at theta = 0, s' = 0: only the shaft friction holds the cam

# name: start values, input u [V] (number or (times, values)), stop time [s], communication step [s]
CASES: dict[str, dict] = {
    "L_1e-6_etdrk4_10ms": dict(start={"L": 1e-6, "solver": "etdrk4"}, u=3.5, stop=2.0, step=1e-2),
    "L_1e-6_rk45_10ms": dict(start={"L": 1e-6}, u=3.5, stop=2.0, step=1e-2),
    "L_0.1": dict(start={"L": 0.1}, u=3.5, stop=2.0, step=1e-3),
    # explicit solvers asked for steps 190x beyond their stability limit (R/L = 1.9e4 1/s)
    "rk4_beyond_stability": dict(start={"L": 1e-3, "solver": "rk4", "h_max": 1e-2}, u=3.5, stop=0.5, step=1e-2),
    "euler_beyond_stability": dict(start={"L": 1e-3, "solver": "euler", "h_max": 1e-2}, u=3.5, stop=0.5, step=1e-2),
    "step_1us": dict(start={}, u=3.5, stop=2e-3, step=1e-6),
    "step_1s": dict(start={}, u=3.5, stop=4.0, step=1.0),
    "rest_u0": dict(start={}, u=0.0, stop=1.0, step=1e-2),
    "below_break_away": dict(start={}, u=0.99 * U_BREAK, stop=1.0, step=1e-2),
    "above_break_away": dict(start={}, u=1.01 * U_BREAK, stop=1.0, step=1e-2),
    "forward": dict(start={}, u=3.5, stop=2.0, step=1e-3),
    "backward": dict(start={}, u=-3.5, stop=2.0, step=1e-3),
    "u_100V": dict(start={}, u=100.0, stop=1.0, step=1e-2),
    "u_100V_coarse": dict(start={}, u=100.0, stop=1.0, step=0.1),
    "clearance_1nm": dict(start={"c": 1e-9}, u=3.5, stop=2.0, step=1e-3),
    "clearance_5mm": dict(start={"c": 5e-3}, u=3.5, stop=2.0, step=1e-3),
    "vertical_stall": dict(start={"gamma": PI / 2, "beta": PI, "guide_friction": False}, u=3.5, stop=1.0, step=1e-3),
    "vertical_driven_back": dict(start={"gamma": PI / 2, "beta": PI, "theta0": PI / 2, "guide_friction": False},
                                 u=0.5, stop=1.0, step=1e-3),
    "mass_1e-6": dict(start={"m": 1e-6, "G": 1e-5}, u=3.5, stop=1.0, step=1e-3),
    "mass_40": dict(start={"m": 40.0, "G": 392.0}, u=3.5, stop=2.0, step=1e-3),
    "J_m_small": dict(start={"J_m": J_M / 100}, u=3.5, stop=2.0, step=1e-3),
    "J_m_large": dict(start={"J_m": J_M * 100}, u=3.5, stop=2.0, step=1e-3),
    "revolutions_1e4": dict(start={"drive": "speed"}, omega_ref=200 * PI, stop=100.0, step=1e-2),
    "unbounded_jerk_laws": dict(start={"rise_law": "simple_harmonic", "return_law": "constant_acceleration"},
                                u=3.5, stop=2.0, step=1e-3),
    "zero_length_segments_and_dwells": dict(
        start={"rise_law": "custom", "rise_T1": 0.0, "rise_T2": 0.0, "rise_T3": 0.3, "rise_T4": 0.7, "rise_T5": 0.7,
               "rise_T6": 1.0, "return_law": "cycloidal", "rise_angle": 2.0, "upper_dwell": 1.0,
               "return_angle": 2.0, "lower_dwell": 2 * PI - 5.0},
        u=3.5, stop=2.0, step=1e-3),
}


def _run_cases(fmu: str, cases: dict) -> dict:
    """Every case through fmpy on one instance (reset between them): {name: {"error", "messages", output: array}}."""
    from fmpy import extract, instantiate_fmu, read_model_description, simulate_fmu
    from fmpy.fmi1 import FMICallException

    md = read_model_description(fmu)
    unzipdir = extract(fmu)
    messages: list[str] = []

    def logger(component, instance, status, category, message):
        messages.append(message.decode("utf-8", "replace"))

    instance = instantiate_fmu(unzipdir, md, fmi_type="CoSimulation", debug_logging=True, logger=logger)
    out = {}
    for name, case in cases.items():
        messages.clear()
        instance.reset()
        inputs = [("u", case.get("u", 0.0)), ("omega_ref", case.get("omega_ref", 1.0))]
        table = np.array([(0.0, *[v for _, v in inputs]), (case["stop"], *[v for _, v in inputs])],
                         dtype=[("time", float)] + [(n, float) for n, _ in inputs])
        record: dict = {"error": None}
        try:
            res = simulate_fmu(fmu, model_description=md, fmu_instance=instance, start_values=case["start"],
                               input=table, stop_time=case["stop"], output_interval=case["step"],
                               output=list(NAMES[1:]))
            record.update({n: np.array(res[n]) for n in NAMES})
        except FMICallException as exc:
            record["error"] = f"{exc.function} returned status {int(exc.status)}"
        record["messages"] = list(messages)
        out[name] = record
    instance.freeInstance()
    _KEEP_ALIVE.append(instance)  # its logger's ctypes thunk: fmpy's logger proxy keeps a pointer to the last one
    shutil.rmtree(unzipdir, ignore_errors=True)
    return out


_KEEP_ALIVE: list = []


@pytest.fixture(scope="module")
def runs(cam_fmu_path):
    return _run_cases(str(cam_fmu_path), CASES)


def _reference(name: str):
    from cam_fmu.reference import simulate_reference
    from cam_fmu.physics.signals import constant
    case = CASES[name]
    return simulate_reference(case["start"], case["stop"], case["step"], u=constant(case.get("u", 0.0)),
                              omega_ref=constant(case.get("omega_ref", 1.0)))


def _completed(run: dict, name: str) -> None:
    """Reached the stop time with finite outputs (or the test fails with the FMU's messages)."""
    assert run["error"] is None, f"{name}: {run['error']}: {run['messages'][-3:]}"
    case = CASES[name]
    assert run["time"][-1] == pytest.approx(case["stop"], abs=1e-9 * case["stop"]), f"{name} stopped early"
    for n in NAMES:
        assert np.all(np.isfinite(run[n])), f"{name}: {n} not finite"


def _kinetic_bound(run: dict, name: str) -> None:
    """Energy: kinetic + magnetic energy never exceeds the electrical energy put in.

    E_in = int u i dt by the trapezoid rule on the output grid (a slight
    over- or under-estimate; 2 % slack); horizontal mountings only, where
    gravity does no work.
    """
    case = CASES[name]
    start = case["start"]
    u = case.get("u", 0.0)
    L = start.get("L", 0.0)
    kinetic = 0.5 * run["J"] * run["omega"] ** 2 + 0.5 * L * run["i"] ** 2
    power = u * run["i"]
    e_in = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(run["time"]))])
    assert np.all(kinetic <= 1.02 * np.maximum.accumulate(e_in) + 1e-12), f"{name}: energy created"


def _agrees(run: dict, ref: dict, name: str, theta_tol: float, omega_tol: float) -> None:
    err_theta = np.max(np.abs(run["theta"] - ref["theta"]))
    err_omega = np.max(np.abs(run["omega"] - ref["omega"]))
    assert err_theta < theta_tol, f"{name}: theta differs from the reference by {err_theta:.3g} rad"
    assert err_omega < omega_tol, f"{name}: omega differs from the reference by {err_omega:.3g} rad/s"


# The tolerances: rk45 (default rtol 1e-10) keeps theta within 2.8e-9 rad of the
# reference on fig. 6 at 1 ms and within 2.4e-7 rad for the laws with jumps in
# the acceleration (measured); 1e-6 rad is the project's target.
# omega errors are ~100x larger where omega spikes (J drops 45x at the stroke
# ends, d omega/dt reaches 5e3 rad/s2), so omega gets 1e-4 rad/s. Fixed-step
# etdrk4 at h_max = 1 ms is RK4-class: 7e-4 rad measured, 2e-3 allowed.
@pytest.mark.parametrize("name, theta_tol, omega_tol", [
    ("L_0.1", 1e-6, 1e-4),
    ("step_1us", 1e-9, 1e-6),
    ("step_1s", 1e-6, 1e-4),
    ("forward", 1e-6, 1e-4),
    # 100 V: ~100 turns in 1 s, omega peaks at 1296 rad/s at each stroke end; the
    # global error of rk45 at rtol 1e-10 measured 1e-5..5e-5 rad (0.07..0.6 rad/s)
    # depending on the step sequence, the reference's own ~1e-6 rad (5e-3 rad/s).
    ("u_100V", 1e-3, 2.0),
    ("u_100V_coarse", 1e-3, 2.0),
    ("clearance_1nm", 1e-6, 1e-4),
    ("clearance_5mm", 1e-6, 1e-4),
    ("mass_40", 1e-6, 1e-4),
    ("J_m_small", 1e-6, 1e-3),
    ("J_m_large", 1e-6, 1e-4),
    ("unbounded_jerk_laws", 1e-6, 1e-4),
    ("zero_length_segments_and_dwells", 1e-6, 1e-4),
    ("L_1e-6_etdrk4_10ms", 2e-3, 0.3),
    # sub-stepped to the stability limit: rk4 measured 5e-9 rad, euler 1.4e-4 rad
    ("rk4_beyond_stability", 1e-7, 1e-4),
    ("euler_beyond_stability", 1e-3, 0.05),
])
def test_agrees_with_reference_and_creates_no_energy(runs, name, theta_tol, omega_tol):
    run = runs[name]
    _completed(run, name)
    _agrees(run, _reference(name), name, theta_tol, omega_tol)
    if CASES[name]["step"] < 1e-2:  # 10 ms output grids are too coarse for the trapezoid rule near the spikes
        _kinetic_bound(run, name)


def test_u_100V_many_revolutions_per_step(runs):
    """At 100 V the cam turns more than 4 revolutions in one 0.1 s step, and still agrees."""
    run = runs["u_100V_coarse"]
    _completed(run, "u_100V_coarse")
    assert np.max(np.diff(run["theta"])) > 4 * 2 * PI


def test_rk45_takes_a_stiff_pole_at_10_ms_steps(runs):
    """L = 1e-6 H: R/L = 1.9e7 1/s held rk45's step near 1.7e-7 s, ~6e4 steps per 10 ms step, and it was
    refused. Now rk45 takes steps longer than 3 L/R as the exponential pair (docs/model.md section 6.4):
    it completes, and agrees with etdrk4, exact on the pole, at every communication point (etdrk4's own
    promise, 1e-2 relative, is the looser; measured against each other: below 1e-5 rad)."""
    run, exact = runs["L_1e-6_rk45_10ms"], runs["L_1e-6_etdrk4_10ms"]
    _completed(run, "L_1e-6_rk45_10ms")
    assert np.allclose(run["theta"], exact["theta"], rtol=1e-4, atol=1e-6)


def test_at_rest_nothing_moves(runs):
    for name in ("rest_u0", "below_break_away"):
        run = runs[name]
        _completed(run, name)
        assert np.all(run["theta"] == 0.0) and np.all(run["omega"] == 0.0), f"{name}: the cam moved (or chattered)"
        assert np.allclose(run["i"], CASES[name]["u"] / R, rtol=1e-12, atol=0.0)  # i = u / R at rest, L = 0
        assert np.all(run["s"] == 0.0)


def test_just_above_break_away_it_starts(runs):
    run = runs["above_break_away"]
    _completed(run, "above_break_away")
    assert run["theta"][-1] > 0.01 and np.all(np.diff(run["theta"]) >= 0.0)
    assert np.all(run["omega"][1:] > 0.0)  # never stalls again: just above, it keeps going forward
    _agrees(run, _reference("above_break_away"), "above_break_away", 1e-6, 1e-4)


def test_negative_voltage_runs_backwards_as_a_mirror_image(runs):
    """The paper's profile is symmetric (s(-theta) = s(theta)) and the mounting horizontal: theta(-u) = -theta(u)."""
    fwd, back = runs["forward"], runs["backward"]
    _completed(fwd, "forward")
    _completed(back, "backward")
    assert back["theta"][-1] < -10.0
    assert np.max(np.abs(back["theta"] + fwd["theta"])) < 1e-6
    assert np.max(np.abs(back["omega"] + fwd["omega"])) < 1e-4
    assert np.max(np.abs(back["s"] - fwd["s"])) < 1e-7


def test_backlash_follower_stays_in_the_gap(runs):
    for name, c in (("clearance_1nm", 1e-9), ("clearance_5mm", 5e-3)):
        run = runs[name]
        gap = run["s_cam"] - run["s"]
        assert np.all(np.abs(gap) <= c * (1 + 1e-9) + 1e-15), f"{name}: follower outside the clearance"
    tiny, none = runs["clearance_1nm"], runs["forward"]
    assert np.max(np.abs(tiny["theta"] - none["theta"])) < 1e-5  # 1 nm of play changes almost nothing


def _static_limits(run: dict, k: int) -> tuple[float, float]:
    """Motor torque and gravity torque at output k (guide friction off): c_m i and G s'(theta)."""
    from cam_fmu.kinematics.cam_program import paper_program
    s1 = paper_program().derivatives(float(run["theta"][k]))[1]
    return C_M * run["i"][k], 4.0 * s1  # F_gx = G sin(90 deg) cos(180 deg) = -G: gravity opposes the rise


def test_vertical_mounting_stalls_without_chatter(runs):
    """Gravity (G = 4 N against the rise) beats the motor: the cam stops, stays stopped, and is in static balance."""
    run = runs["vertical_stall"]
    _completed(run, "vertical_stall")
    moving = np.flatnonzero(run["omega"] != 0.0)
    assert moving.size and moving[0] == 1  # it starts (3.5 V > break-away at theta = 0, where s' = 0)
    stopped = np.flatnonzero((run["omega"] == 0.0) & (np.arange(run["omega"].size) > moving[0]))
    assert stopped.size, "the cam never stalled"
    first = stopped[0]
    assert np.all(run["omega"][first:] == 0.0) and np.all(run["theta"][first:] == run["theta"][first])
    motor, gravity = _static_limits(run, -1)
    assert abs(motor - gravity) <= M_F * (1 + 1e-9)  # static friction can hold the difference
    _agrees(run, _reference("vertical_stall"), "vertical_stall", 1e-6, 1e-4)


def test_vertical_mounting_driven_back(runs):
    """Mid-rise at 0.5 V, gravity wins and turns the cam back toward the bottom, where it comes to rest.

    It may swing past theta = 0 (the return flank then pushes it back): it ends
    at rest, in static balance, without chatter (at rest over the last 20 %).
    """
    run = runs["vertical_driven_back"]
    _completed(run, "vertical_driven_back")
    assert run["omega"][1] < 0.0 and abs(run["theta"][-1]) < PI / 4
    tail = run["omega"].size // 5
    assert np.all(run["omega"][-tail:] == 0.0) and np.all(run["theta"][-tail:] == run["theta"][-1])
    motor, gravity = _static_limits(run, -1)
    assert abs(motor - gravity) <= M_F * (1 + 1e-9)
    _agrees(run, _reference("vertical_driven_back"), "vertical_driven_back", 1e-6, 1e-4)


def test_negligible_follower_gives_the_bare_motor(runs):
    """m = 1e-6 kg: omega(t) = w_inf (1 - exp(-t / tau)), the first-order DC motor with J_m and M_f."""
    run = runs["mass_1e-6"]
    _completed(run, "mass_1e-6")
    u = CASES["mass_1e-6"]["u"]
    w_inf = (C_M * u / R - M_F) * R / (C_E * C_M)
    tau = R * J_M / (C_E * C_M)
    exact = w_inf * (1.0 - np.exp(-run["time"] / tau))
    # m s'^2 / J_m <= 1e-6 * 0.07^2 / 4.41e-5 = 1.1e-4: the follower's share of the inertia
    assert np.max(np.abs(run["omega"] - exact)) < 2e-4 * w_inf


def test_ten_thousand_revolutions_keep_theta_exact(runs):
    """Speed drive at 100 rev/s for 100 s: theta = omega t exactly, and the profile repeats every turn."""
    run = runs["revolutions_1e4"]
    _completed(run, "revolutions_1e4")
    omega = CASES["revolutions_1e4"]["omega_ref"]
    assert run["theta"][-1] / (2 * PI) == pytest.approx(1e4, rel=1e-12)
    assert np.max(np.abs(run["theta"] - omega * run["time"])) < 1e-9 * run["theta"][-1]
    # every output lands on a whole number of revolutions: the follower is back at s(0) = 0
    assert np.max(np.abs(run["s"])) < 1e-9

