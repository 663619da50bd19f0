"""The follower as a body of its own (docs/model.md section 13), against closed forms and invariants.

Jump speed: a simple-harmonic rise of lift h over the angle b has s = h/2 (1 - cos(pi phi/b)) and
s'' = h/2 (pi/b)^2 cos(pi phi/b); with x = -cos(pi phi/b) in (0, 1] on the decelerating half,
(F0 + k s) / (m |s''|) = (F0 + k h/2 (1 + x)) / (m h/2 (pi/b)^2 x) falls with x, so the jump speed is at
the top of the stroke: omega_jump^2 = (F0 + k h) / (m h/2 (pi/b)^2). A cycloidal rise decelerates at most
by s'' = -2 pi h / b^2 (at 3/4 of the rise): with k = 0, omega_jump^2 = F0 b^2 / (2 pi m h).
Free flight is checked against scipy's integration of m s'' = -(F0 + k s) + F_gx - sgn(v) f, and impacts
against momentum and kinetic energy computed from the velocities before and after.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cam_fmu.experiments.signals import constant
from cam_fmu.kinematics.cam_program import CamProgram
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.follower import Flight, contact_margin, impact, jump_speed, preload_for, rate_for
from cam_fmu.physics.parameters import ParameterError

H, B, M = 0.05, math.pi, 0.4


def shm_program() -> CamProgram:
    return CamProgram("simple_harmonic", "simple_harmonic", H, B, 0.0, B, 0.0)


@pytest.mark.parametrize("k, F0", [(2000.0, 20.0), (0.0, 30.0), (5e4, 0.0)])
def test_jump_speed_of_a_simple_harmonic_rise_is_the_closed_form(k, F0):
    jump = jump_speed(shm_program(), M, k, F0)
    expected = math.sqrt((F0 + k * H) / (M * H / 2 * (math.pi / B) ** 2))
    assert jump.omega_jump == pytest.approx(expected, rel=1e-9)
    assert math.fmod(jump.theta, 2 * math.pi) == pytest.approx(B, abs=1e-5)  # the top of the stroke


def test_jump_speed_of_a_cycloidal_rise_with_a_constant_force():
    program = CamProgram("cycloidal", "cycloidal", H, B, 0.0, B, 0.0)
    jump = jump_speed(program, M, 0.0, 30.0)
    assert jump.omega_jump == pytest.approx(math.sqrt(30.0 * B * B / (2 * math.pi * M * H)), rel=1e-9)
    assert jump.theta == pytest.approx(0.75 * B, abs=1e-5)


def test_gravity_along_the_stroke_adds_to_the_spring():
    """A vertical cam lifting against gravity (gamma = 90 deg, beta = 180 deg): F_gx = -G holds it down too."""
    G = 4.0
    model = DriveModel(dict(gamma=math.pi / 2, beta=math.pi, G=G, lift=H, rise_law="simple_harmonic",
                            return_law="simple_harmonic"))
    assert model.F_gx == pytest.approx(-G)
    jump = jump_speed(model.program, M, 2000.0, 20.0, model.F_gx)
    assert jump.omega_jump == pytest.approx(math.sqrt((20.0 + G + 2000.0 * H) / (M * H / 2 * (math.pi / B) ** 2)),
                                            rel=1e-9)


def test_a_spring_that_does_not_hold_at_rest_jumps_at_once():
    """Gravity pulling along the rise harder than the preload: no speed keeps the follower on (omega_jump = 0)."""
    jump = jump_speed(shm_program(), M, 0.0, 1.0, F_gx=2.0)
    assert jump.omega_jump == 0.0 and "not held even at rest" in jump.reason


def test_margin_changes_sign_at_the_jump_speed():
    program = shm_program()
    jump = jump_speed(program, M, 2000.0, 20.0)
    below, _ = contact_margin(program, 0.98 * jump.omega_jump, M, 2000.0, 20.0)
    above, _ = contact_margin(program, 1.02 * jump.omega_jump, M, 2000.0, 20.0)
    held = 20.0 + 2000.0 * H  # N, the closing force at the top, where the margin is least
    assert below == pytest.approx(held * (1 - 0.98 ** 2), rel=1e-6)
    assert above == pytest.approx(held * (1 - 1.02 ** 2), rel=1e-6)


@pytest.mark.parametrize("safety", [1.0, 1.5])
def test_preload_and_rate_for_a_target_speed(safety):
    """The preload (rate) found for a target speed with a safety factor S on force gives omega_jump = sqrt(S) target,
    by the closed form of the simple-harmonic rise."""
    target, k, F0 = 150.0, 2000.0, 20.0
    inertial = safety * M * H / 2 * (math.pi / B) ** 2 * target ** 2  # N, at the top of the stroke
    preload, _ = preload_for(shm_program(), target, safety, M, k)
    assert preload == pytest.approx(inertial - k * H, rel=1e-9)
    rate, _ = rate_for(shm_program(), target, safety, M, F0)
    assert rate == pytest.approx((inertial - F0) / H, rel=1e-9)
    assert jump_speed(shm_program(), M, rate, F0).omega_jump == pytest.approx(math.sqrt(safety) * target, rel=1e-9)


def _integrated(flight: Flight, s0: float, v0: float, times: np.ndarray) -> np.ndarray:
    """scipy's DOP853 on m s'' = -(F0 + k s) + F_gx - sgn(v) f, stopped where v changes sign."""
    out, t, y = {}, 0.0, [s0, v0]
    while t < times[-1]:
        sigma = math.copysign(1.0, y[1]) if y[1] != 0.0 else math.copysign(1.0, -flight.F0 - flight.k * y[0] + flight.F_gx)

        def rhs(_t, z, sigma=sigma):
            return [z[1], (-flight.F0 - flight.k * z[0] + flight.F_gx - sigma * flight.f) / flight.m]

        def halt(_t, z, sigma=sigma):
            return sigma * z[1]
        halt.terminal, halt.direction = True, -1
        sol = solve_ivp(rhs, (t, times[-1]), y, method="DOP853", rtol=1e-12, atol=1e-14, events=halt, dense_output=True)
        inside = times[(times >= t) & (times <= sol.t[-1])]
        out.update({float(x): sol.sol(x) for x in inside if float(x) not in out})  # a halt's time: its first piece
        t, y = sol.t[-1], [sol.y[0, -1], 0.0]
    return np.array([out[float(x)] for x in times])


@pytest.mark.parametrize("k, F0, F_gx, f", [(2000.0, 20.0, 0.0, 0.0), (0.0, 5.0, 0.0, 0.0), (2000.0, 20.0, -3.0, 0.5),
                                           (0.0, 5.0, 1.0, 0.5)])
def test_free_flight_is_the_integrated_equation(k, F0, F_gx, f):
    flight = Flight(M, k, F0, F_gx, f)
    times = np.linspace(0.0, 0.2, 201)
    closed = np.array([flight.state(t, 0.1, 1.5)[:2] for t in times])
    numeric = _integrated(flight, 0.1, 1.5, times)
    assert np.max(np.abs(closed - numeric)) < 1e-9


def test_free_flight_keeps_its_energy_without_friction():
    flight = Flight(M, 2000.0, 20.0, -3.0)
    start = flight.energy(0.1, 1.5)
    for t in np.linspace(0.0, 1.0, 50):
        s, v, _ = flight.state(t, 0.1, 1.5)
        assert flight.energy(s, v) == pytest.approx(start, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_impact_conserves_momentum_and_loses_the_restitution_share(e):
    J0, s1, omega, v = 4.41e-5, 0.07, 20.0, -0.3
    hit = impact(J0, M, s1, omega, v, e)
    w_before, w_after = v - s1 * omega, hit.v - s1 * hit.omega
    assert w_after == pytest.approx(-e * w_before, rel=1e-12, abs=1e-15)
    assert J0 * hit.omega + M * s1 * hit.v == pytest.approx(J0 * omega + M * s1 * v, rel=1e-12)
    kinetic = lambda w, u: 0.5 * J0 * w * w + 0.5 * M * u * u  # noqa: E731
    m_eff = M * J0 / (J0 + M * s1 * s1)
    lost = kinetic(omega, v) - kinetic(hit.omega, hit.v)
    assert lost == pytest.approx(0.5 * (1 - e * e) * m_eff * w_before ** 2, rel=1e-9, abs=1e-15)
    assert hit.loss == pytest.approx(lost, rel=1e-9, abs=1e-15)


def test_plastic_impact_on_a_resting_follower_is_the_backlash_rule():
    """docs/model.md 6.2: J_m omega- = (J_m + m s'^2) omega+."""
    J0, s1, omega = 4.41e-5, 0.07, 20.0
    assert impact(J0, M, s1, omega, 0.0, 0.0).omega == pytest.approx(J0 * omega / (J0 + M * s1 * s1), rel=1e-13)


# ----------------------------------------------------------------------------- the reference in the speed drive
SPRING = dict(drive="speed", closure="spring", k_spring=2000.0, F_spring0=20.0, mu=0.0, M_f=0.0)


def _run(params, omega, turns=1.0, points=400):
    from cam_fmu.reference.flight import FollowerRun
    from cam_fmu.reference.integrate import output_grid

    model = DriveModel(params)
    run = FollowerRun(model, constant(omega), 1e-12, 1e-13)
    stop = turns * 2 * math.pi / omega
    return model, run, run.run(output_grid(stop, stop / points), 0.0)


def test_no_lift_off_below_the_jump_speed_and_lift_off_above():
    model = DriveModel(SPRING)
    jump = jump_speed(model.program, model.m, model.k_spring, model.F_spring0)
    _, run, below = _run(SPRING, 0.98 * jump.omega_jump)
    assert np.all(below["contact"] == 1.0) and not run.impacts and below["N_contact"].min() > 0.0
    _, run, above = _run(SPRING, 1.02 * jump.omega_jump)
    assert np.any(above["contact"] == 0.0) and run.impacts
    assert np.all(above["s"] >= above["s_cam"] - 1e-12)  # the follower never enters the cam


def test_reference_flight_is_the_closed_form_until_touch_down():
    """After lift-off the reference's (s, v) is Flight.state from the lift-off state, to 1e-9."""
    params = dict(SPRING, gamma=math.pi / 2, beta=math.pi, mu=0.01)  # gravity along the stroke and guide friction
    model = DriveModel(params)
    jump = jump_speed(model.program, model.m, model.k_spring, model.F_spring0, model.F_gx,
                      model.mu * (abs(model.G_y) + model.N_g))
    omega = 1.1 * jump.omega_jump
    _, run, result = _run(params, omega, points=4000)
    flying = np.flatnonzero(result["contact"] == 0.0)
    assert len(flying) > 20
    first = flying[0] - 1  # the last row in contact; lift-off lies between it and the first flying row
    flight = Flight(model.m, model.k_spring, model.F_spring0, model.F_gx, model.mu * (abs(model.G_y) + model.N_g))
    # the lift-off instant: where the flank's force reaches 0 (root by bisection on the contact rows' physics)
    from cam_fmu.physics.speed_follower import SpeedFollower
    body = SpeedFollower(model)
    lo, hi = result["time"][first], result["time"][first + 1]
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if body.held(omega * mid, omega, 0.0, 1.0) > 0.0 else (lo, mid)
    s0, s1, _, _ = model.program.derivatives(omega * hi)
    run_end = flying[np.argmax(np.diff(flying) > 1)] if np.any(np.diff(flying) > 1) else flying[-1]
    for k in range(flying[0], run_end):  # the first flight, before its touch-down
        s, v, _ = flight.state(result["time"][k] - hi, s0, s1 * omega)
        assert s == pytest.approx(result["s"][k], abs=1e-9) and v == pytest.approx(result["v"][k], abs=1e-7)


@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_reference_impacts_keep_the_restitution_law(e):
    params = dict(SPRING, restitution=e)
    model = DriveModel(params)
    omega = 1.2 * jump_speed(model.program, model.m, model.k_spring, model.F_spring0).omega_jump
    _, run, result = _run(params, omega, turns=2.0)
    assert run.impacts
    for _, before, after in run.impacts:
        assert before < 0.0  # approaching the flank
        if after != 0.0:  # a rebound (not the Zeno guard's plastic end)
            assert after == pytest.approx(-e * before, rel=1e-12)
    if e < 1.0:  # the bouncing settles: a finite sequence ended by the Zeno guard, the follower back on the cam
        assert result["contact"][-1] == 1.0 and len(run.impacts) < 200


def test_energy_of_the_flying_follower_is_kept_without_friction():
    model, run, result = _run(dict(SPRING, restitution=1.0), 1.3 * 77.85, turns=1.0, points=4000)
    flight = Flight(model.m, model.k_spring, model.F_spring0)
    flying = np.flatnonzero(result["contact"] == 0.0)
    energies = [flight.energy(result["s"][k], result["v"][k]) for k in flying]
    # between impacts the energy is constant; e = 1 impacts on a cam at imposed speed change it by the cam's work
    impact_times = [t for t, _, _ in run.impacts]
    pieces = np.searchsorted(impact_times, result["time"][flying])
    for piece in set(pieces):
        values = np.array(energies)[pieces == piece]
        assert np.ptp(values) <= 1e-9 * max(1.0, np.max(np.abs(values)))


def test_groove_with_clearance_crosses_the_gap():
    """Closure 'form' with c = 1 mm: the follower leaves the lower flank where the rise decelerates, flies across the
    gap and strikes the upper flank (the crossover shock); the kinematic rule keeps it on the lower flank."""
    params = dict(drive="speed", closure="form", c=1e-3, restitution=0.0)
    _, run, result = _run(params, 10.0, points=2000)
    assert set(np.unique(result["contact"])) >= {1.0, 0.0, -1.0}
    strikes = [before for _, before, _ in run.impacts]
    assert any(b > 0.0 for b in strikes)  # on the upper flank: approaching along +X
    assert np.all(result["s"] >= result["s_cam"] - 1e-3 - 1e-12) and np.all(result["s"] <= result["s_cam"] + 1e-3 + 1e-12)


@pytest.mark.parametrize("c, e, omega", [(1e-4, 0.9, 10.0), (1e-3, 0.9, 100.0), (1e-5, 1.0, 30.0)])
def test_a_bouncing_follower_never_leaves_the_groove(c, e, omega):
    """Many crossings of a vertical groove (gravity along the stroke, no spring): a flight is then a polynomial in
    time, which the integrator would take in one long step across a flank and back, missing the touch-down; with
    the steps bounded (flight.FLIGHT_ANGLE) every output row lies within the clearance."""
    params = dict(drive="speed", closure="form", c=c, restitution=e, gamma=math.pi / 2, mu=0.0, M_f=0.0)
    _, run, result = _run(params, omega, turns=2.0, points=20000)
    assert len(run.impacts) > 30
    assert np.max(np.abs(result["s"] - result["s_cam"])) <= c + 1e-12


@pytest.mark.parametrize("params, words", [
    (dict(drive="speed", closure="spring", c=1e-3), "'c'"),
    (dict(drive="voltage", closure="spring", formulation="paper"), "formulation 'consistent'"),  # the voltage drive's
    # refusals: tests/physics/test_voltage_follower.py
    (dict(closure="kinematic", restitution=0.5), "plastic impacts only"),
    (dict(k_spring=100.0), "closure 'spring'"),
    (dict(drive="speed", closure="spring", m=0.0), "^parameter 'm' = 0.0 kg: .* allowed with it: m > 0$"),
    (dict(closure="spring", follower_inertia=False), "^parameter 'follower_inertia' = false: .* allowed with it: "
     "follower_inertia true"),
    (dict(closure="form", c=1e-3, formulation="paper", restitution=0.5), "paper's formulation"),
])
def test_contradicting_closure_parameters_are_refused_with_the_reason(params, words):
    with pytest.raises(ParameterError, match=words):
        DriveModel(params)


def test_the_engine_refuses_what_the_model_refuses_with_the_same_words():
    """The C engine's checks of the closure are physics/drive.py's, message for message."""
    from cam_fmu.fmu.engine import DriveSimulator

    for params in (dict(drive="speed", closure="spring", c=1e-3), dict(closure="spring", formulation="paper"),
                   dict(closure="kinematic", restitution=0.5), dict(k_spring=100.0),
                   dict(drive="speed", closure="spring", m=0.0), dict(closure="spring", follower_inertia=False),
                   dict(drive="speed", closure="spring", follower_inertia=False, m=0.0),
                   dict(closure="form", c=1e-3, formulation="paper", restitution=0.5)):
        with pytest.raises(ParameterError) as python:
            DriveModel(params)
        with pytest.raises(ParameterError) as engine:
            DriveSimulator(params)
        assert str(engine.value) == str(python.value)
    for params in (dict(c=1e-3, solver="rk4"), dict(closure="spring", solver="euler")):   # refused before issue 38
        DriveModel(params)
        DriveSimulator(params)


@pytest.mark.parametrize("params", [
    dict(closure="form", m=0.0, restitution=0.5),                    # no clearance: nothing to fly across
    dict(closure="form", c=5e-4, formulation="paper", omega0=0.0),  # the paper's formulation: its eqs. 6-8
    dict(drive="speed", closure="form", c=0.0, m=0.0),
    dict(c=5e-4, m=0.0, omega0=0.0),                                 # no mass: nothing carries it across
    dict(c=5e-4, follower_inertia=False, omega0=3.0, solver="euler"),
    dict(drive="speed", c=5e-4, follower_inertia=False),
])
def test_a_groove_without_a_flight_is_the_kinematic_rule_to_the_bit(params):
    """Closure 'form' where the follower cannot fly (c = 0; no mass, m = 0 or follower_inertia false, so no
    momentum carries it across and no force moves it: gravity and friction scale with m; or the paper's voltage
    formulation, which models the clearance by its eqs. 6-8) runs the kinematic rule: the same outputs, bit for bit,
    as closure 'kinematic', in the C engine and in physics/drive.py (own_follower, model.c's free_follower)."""
    from cam_fmu.fmu.engine import DriveSimulator

    kinematic = dict(params, closure="kinematic", restitution=0.0)
    assert not DriveModel(params).free_follower and not DriveModel(kinematic).free_follower
    rows = []
    for p in (params, kinematic):
        sim = DriveSimulator(p)
        sim.set_inputs(u=6.0, omega_ref=20.0, omega_dot_ref=0.0)
        run = []
        for k in range(200):
            sim.do_step(k * 1e-3, 1e-3, u=6.0, omega_ref=20.0)
            run.append(tuple(sim.outputs().values()))
        rows.append(run)
    assert rows[0] == rows[1]
