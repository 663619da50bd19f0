"""Stiction at omega = 0 and backlash impacts (docs/model.md section 6), against hand-derived values.

Stiction: at rest with L = 0 the motor torque is c_m u / R. At the break-away
threshold omega = omega_dot = 0, so a = s'' omega^2 + s' omega_dot = 0 and the
static resistance forward is

    M_f + (-F_gx + sigma f) s',   sigma = sgn(s'),
    f = mu (|(-F_gx) tan(alpha) + G_y + sigma f tan(alpha)| + |G cos(gamma)|)

so u_b = R (M_f + (-F_gx + sigma f) s') / c_m; at theta = 0 (s' = 0): u_b = R M_f / c_m.
Backward (sigma = -sgn(s')) the shaft runs back once c_m u / R < -M_f + (-F_gx + sigma f) s'.

Backlash: the follower rests inside the gap and is picked up when the cam has
moved by the clearance: a plastic impact that keeps J_m omega (the follower is at
rest before), so J_m omega_minus = (J_m + m s'^2) omega_plus, losing energy.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.physics.formulations import consistent as hybrid_module
from cam_fmu.physics.drive import DriveModel, break_away_voltage
from cam_fmu.physics.formulations.consistent import ENGAGE_DOWN, ENGAGE_UP, HybridDrive, Mode
from cam_fmu.reference import simulate_reference
from cam_fmu.physics.signals import constant
from cam_fmu.fmu.engine import DriveSimulator
from test_drive_closed_form import DEFAULTS, H, friction_fixed_point, paper_profile

R, C_M, J_M, M_F, MASS, G, MU, R_B = (DEFAULTS[k] for k in ("R", "c_m", "J_m", "M_f", "m", "G", "mu", "r_b"))


def _hand_threshold(theta: float, gamma: float, beta: float, sigma: float) -> float:
    """Motor torque [N m] at which the shaft starts in direction sigma (see module docstring)."""
    s, s1, _ = paper_profile(theta)
    F_gx = G * math.sin(gamma) * math.cos(beta)
    G_y = G * math.sin(gamma) * math.sin(beta)
    tan_a = s1 / (R_B + s)
    sig_v = math.copysign(1.0, s1 * sigma) if s1 != 0 else 0.0
    f = friction_fixed_point(-F_gx * tan_a + G_y, tan_a, sig_v, MU, G * math.cos(gamma))
    return sigma * M_F + (-F_gx + sig_v * f) * s1


def _run_sim(params, u, steps, h=1e-3, events=None):
    """The C engine's outputs at every step; ``events``: a list that receives its transitions
    (the engine's event log, read after every step: it keeps the last 256)."""
    sim = DriveSimulator(params)
    sim.set_inputs(u, 1.0)
    rows = [sim.outputs()]
    seen = -1
    for k in range(steps):
        sim.do_step(k * h, h, u, 1.0)
        rows.append(sim.outputs())
        if events is not None:
            fresh = [e for e in sim.events() if e["index"] > seen]
            assert not fresh or fresh[0]["index"] == seen + 1, "the log dropped transitions"
            seen = fresh[-1]["index"] if fresh else seen
            events += [(e["name"], e["before"], e["after"],   # the rigid drive's mode (no follower's own fields)
                        Mode(**{k: v for k, v in e["mode_before"].items() if k not in ("left", "sigma")}))
                       for e in fresh]
    return {name: np.array([r[name] for r in rows]) for name in rows[0]}


# ----------------------------------------------------------------- stiction
def test_break_away_voltage_at_zero_is_R_Mf_over_cm():
    """u_b = R M_f / c_m = 19 * 0.012 / 0.1471 = 1.54997 V (to 1e-12 relative)."""
    u_b = R * M_F / C_M
    assert u_b == pytest.approx(1.54997, abs=1e-5)
    assert break_away_voltage(DriveModel({})) == pytest.approx(u_b, rel=1e-12)


@pytest.mark.parametrize("engine", ["simulator", "reference"])
def test_below_break_away_the_cam_never_moves(engine):
    """u = 0.99 u_b for 1 s: theta stays exactly theta0, omega exactly 0 at every output."""
    u = 0.99 * R * M_F / C_M
    if engine == "simulator":
        out = _run_sim({}, u, 1000)
    else:
        out = simulate_reference({}, 1.0, 1e-3, u=constant(u))
    assert np.all(out["theta"] == 0.0)
    assert np.all(out["omega"] == 0.0)
    assert np.all(out["s"] == 0.0)
    # static friction holds what the motor applies: M = c_m i
    np.testing.assert_allclose(out["M"], C_M * u / R, rtol=1e-15)


@pytest.mark.parametrize("engine", ["simulator", "reference"])
def test_just_above_break_away_it_starts_without_chatter(engine):
    """u = 1.01 u_b: the cam turns (theta > 0.1 rad after 2 s; measured 0.185 rad),
    omega >= 0 at every output (never reverses), and it never re-sticks and restarts."""
    u = 1.01 * R * M_F / C_M
    if engine == "simulator":
        out = _run_sim({}, u, 2000)
    else:
        out = simulate_reference({}, 2.0, 1e-3, u=constant(u))
    w = out["omega"]
    assert out["theta"][-1] > 0.1
    assert np.all(w >= 0.0)
    assert np.all(np.diff(out["theta"]) >= 0.0)
    moving = w > 0.0
    first = int(np.argmax(moving))
    assert first <= 1 and np.all(moving[first:])  # started at once, no stop-and-go


def test_simulator_and_reference_agree_near_break_away():
    """Creeping just above u_b is a sensitive case: both engines agree on theta to 1e-6 rad."""
    u = 1.01 * R * M_F / C_M
    a = _run_sim({}, u, 2000)
    b = simulate_reference({}, 2.0, 1e-3, u=constant(u))
    assert np.max(np.abs(a["theta"] - b["theta"])) < 1e-6


TILT = dict(gamma=math.radians(100.0), beta=math.pi, theta0=math.pi / 2)  # gravity opposes the rise


def test_break_away_with_gravity_and_slope_by_hand():
    """theta0 = pi/2 (s' = 2A = 70 mm/rad), gravity along -X of 3.94 N: the threshold holds the
    gravity torque F_gx s' = 0.276 N m: u_b = 37.19 V (hand formula, to 1e-10 relative)."""
    model = DriveModel(TILT)
    torque_fw = _hand_threshold(math.pi / 2, TILT["gamma"], TILT["beta"], 1.0)
    u_b = R * torque_fw / C_M
    assert u_b == pytest.approx(37.19, abs=0.01)
    assert break_away_voltage(model, math.pi / 2) == pytest.approx(u_b, rel=1e-10)


@pytest.mark.parametrize("engine", ["simulator", "reference"])
def test_stiction_band_with_gravity(engine):
    """Between the backward and forward thresholds the tilted cam stays put; outside it moves
    the way the torques say: forward above u_b, backward (gravity wins) below u_back."""
    theta0 = math.pi / 2
    u_fw = R * _hand_threshold(theta0, TILT["gamma"], TILT["beta"], 1.0) / C_M
    u_bw = R * _hand_threshold(theta0, TILT["gamma"], TILT["beta"], -1.0) / C_M
    assert 30 < u_bw < u_fw

    def run(u):
        if engine == "simulator":
            return _run_sim(TILT, u, 200)
        return simulate_reference(TILT, 0.2, 1e-3, u=constant(u))

    for u in (1.001 * u_bw, 0.5 * (u_bw + u_fw), 0.999 * u_fw):
        out = run(u)
        assert np.all(out["theta"] == theta0) and np.all(out["omega"] == 0.0), u
    fw, bw = run(1.01 * u_fw), run(0.99 * u_bw)
    assert fw["theta"][-1] > theta0 and np.all(fw["omega"] >= 0.0)
    assert bw["theta"][-1] < theta0 and np.all(bw["omega"] <= 0.0)


# ------------------------------------------------------------------ backlash
@pytest.mark.parametrize("engine", ["simulator", "reference"])
def test_zero_clearance_is_exactly_the_no_backlash_run(engine):
    """c = 0 with the backlash switch on == switch off == c > 0 with the switch off, bit for bit."""
    runs = []
    for params in (dict(backlash=True, c=0.0), dict(backlash=False), dict(backlash=False, c=0.002)):
        if engine == "simulator":
            runs.append(_run_sim(params, 3.5, 500))
        else:
            runs.append(simulate_reference(params, 0.5, 1e-3))
    for other in runs[1:]:
        for name in ("theta", "omega", "s", "M", "J", "i"):
            assert np.array_equal(runs[0][name], other[name]), name


C = 0.002  # m


def test_engagement_keeps_generalised_momentum_direct():
    """HybridDrive.apply_event(ENGAGE_UP/DOWN): J_m omega- = (J_m + m s'^2) omega+ (s' by hand)."""
    drive = HybridDrive(DriveModel(dict(c=C, closure="kinematic")))
    for theta, name, omega in ((0.4, ENGAGE_UP, 7.0), (1.5, ENGAGE_UP, 3.0), (math.pi + 0.5, ENGAGE_DOWN, 5.0),
                               (0.4, ENGAGE_DOWN, -2.0)):
        s, s1, _ = paper_profile(theta)
        side = 1 if name == ENGAGE_UP else -1
        mode = Mode(stuck=False, direction=math.copysign(1.0, omega), contact=0, s_free=s - side * C)
        y = [theta, omega]
        drive.apply_event(y, 3.5, mode, name)
        assert mode.contact == side
        assert y[0] == theta
        J = J_M + MASS * s1 * s1
        assert J_M * omega == pytest.approx(J * y[1], rel=1e-14)
        assert 0.5 * J * y[1] ** 2 < 0.5 * J_M * omega ** 2  # plastic: energy lost


@pytest.fixture
def spy_events(monkeypatch):
    """Record (name, y before, y after, mode before) of every HybridDrive.apply_event call."""
    log = []
    original = HybridDrive.apply_event

    def spy(self, y, u, mode, name):
        before, mode_before = list(y), mode.copy()
        original(self, y, u, mode, name)
        log.append((name, before, list(y), mode_before))

    monkeypatch.setattr(hybrid_module.HybridDrive, "apply_event", spy)
    return log


@pytest.mark.parametrize("engine", ["simulator", "reference"])
def test_backlash_run_lag_momentum_and_energy(engine, spy_events):
    """Fig. 6 drive (u = 3.5 V, 2 s) with c = 2 mm.

    - every engagement happens where the cam has closed the gap: |s_cam - s_free| = c (1e-9 m);
    - J_m omega- = (J_m + m s'^2) omega+ at each one (1e-12 relative) and energy drops;
    - on the rise, once engaged, the follower lags by c: s = s_cam - c (1e-12 m); on the
      return it leads by c: s = s_cam + c; before the first pick-up it rests at 0.
    """
    if engine == "simulator":  # the C engine: its own event log
        events: list = []
        out = _run_sim(dict(c=C, closure="kinematic"), 3.5, 2000, events=events)
    else:  # the reference: the readable model's transitions, spied
        out = simulate_reference(dict(c=C, closure="kinematic"), 2.0, 1e-3)
        events = spy_events
    engagements = [e for e in events if e[0] in (ENGAGE_UP, ENGAGE_DOWN)]
    assert len(engagements) >= 2 * int(out["theta"][-1] / (2 * math.pi))  # two per turn
    for name, before, after, mode in engagements:
        theta, w_minus, w_plus = before[0], before[1], after[1]
        s, s1, _ = paper_profile(theta)
        side = 1 if name == ENGAGE_UP else -1
        assert mode.contact == 0
        assert s - side * C == pytest.approx(mode.s_free, abs=1e-9)
        J = J_M + MASS * s1 * s1
        assert J_M * w_minus == pytest.approx(J * w_plus, rel=1e-12)
        assert 0.5 * J * w_plus ** 2 < 0.5 * J_M * w_minus ** 2
    # the lag, from the outputs, classified by the closed-form profile only
    th = np.mod(out["theta"], 2 * math.pi)
    s_cam = np.array([paper_profile(x)[0] for x in out["theta"]])
    np.testing.assert_allclose(out["s_cam"], s_cam, atol=1e-12)
    first_turn = out["theta"] < 2 * math.pi
    rising, falling = th < math.pi, th > math.pi
    margin = 1e-6
    engaged_up = rising & (s_cam > np.where(first_turn, C, 2 * C) + margin)
    engaged_down = falling & (s_cam < H - 2 * C - margin)
    resting = first_turn & rising & (s_cam < C - margin)
    assert engaged_up.sum() > 100 and engaged_down.sum() > 100 and resting.sum() > 10
    np.testing.assert_allclose(out["s"][engaged_up], s_cam[engaged_up] - C, atol=1e-12)
    np.testing.assert_allclose(out["s"][engaged_down], s_cam[engaged_down] + C, atol=1e-12)
    assert np.all(out["s"][resting] == 0.0)


def test_backlash_energy_only_lost_at_impacts(spy_events):
    """Reference with energy=True and c = 2 mm (c_e = c_m: a lossless converter, see
    test_reference's power balance): the energy missing from the balance,
    E_in - E_copper - E_shaft - E_guide - Delta(1/2 J omega^2), never decreases, and at the
    end equals the sum of the impact losses 1/2 (J_m omega-^2 - J omega+^2) seen at the
    engagements (to 1e-9 J of a 2.9e-2 J total; measured: steps >= -4e-13 J)."""
    out = simulate_reference(dict(c=C, c_e=C_M, closure="kinematic"), 2.0, 1e-3, energy=True)
    kinetic = 0.5 * out["J"] * out["omega"] ** 2
    missing = out["E_in"] - out["E_copper"] - out["E_shaft"] - out["E_guide"] - (kinetic - kinetic[0])
    assert np.all(np.diff(missing) > -1e-9)  # energy is never gained
    impacts = 0.0
    for name, before, after, _ in spy_events:
        if name in (ENGAGE_UP, ENGAGE_DOWN):
            s1 = paper_profile(before[0])[1]
            impacts += 0.5 * (J_M * before[1] ** 2 - (J_M + MASS * s1 * s1) * after[1] ** 2)
    assert impacts > 1e-4
    assert missing[-1] == pytest.approx(impacts, abs=1e-9)
