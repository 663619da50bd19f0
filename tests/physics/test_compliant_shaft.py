"""The compliant drive-train (docs/model.md section 12) against independent oracles: the closed form of
a torque step on the free two-mass system, energy conservation without losses, the rigid limit, the
scipy reference on the shipped scene (stick-slip included), and the refusals where it is not modelled."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.engine.simulator import DriveSimulator
from cam_fmu.errors import StepRejected
from cam_fmu.physics.parameters import ParameterError
from cam_fmu.experiments.scenes import find_scene
from cam_fmu.physics.signals import constant
from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.variables import OUTPUT_NAMES
from cam_fmu.reference import simulate_reference

COL = {name: k for k, name in enumerate(OUTPUT_NAMES)}
# No follower, no friction, a back-EMF too small to matter (c_e c_m / R = 1.5e-11 N m s): the free two-mass system.
FREE = dict(follower_inertia=False, gravity=False, guide_friction=False, shaft_friction=False, c_e=1e-6, R=1e3,
            J_m=3e-5, J_cam=1.5e-5)


def _run(params: dict, stop: float, h: float, u: float) -> np.ndarray:
    n = round(stop / h)
    table = np.column_stack([np.arange(n) * h, np.full(n, h), np.full(n, u), np.ones(n), np.zeros(n)])
    return DriveSimulator(params).run(table)


def _step_twist(t: np.ndarray, torque: float, J_m: float, J_0: float, k: float, d: float) -> tuple:
    """docs/model.md 12.4: the twist and its rate after a torque step on the rotor, from rest."""
    J_star = 1.0 / (1.0 / J_m + 1.0 / J_0)
    w_n = math.sqrt(k / J_star)
    zeta = d / (2.0 * math.sqrt(k * J_star))
    w_d = w_n * math.sqrt(1.0 - zeta * zeta)
    phi_inf = torque * J_0 / (k * (J_m + J_0))
    decay = np.exp(-zeta * w_n * t)
    phi = phi_inf * (1.0 - decay * (np.cos(w_d * t) + zeta / math.sqrt(1.0 - zeta * zeta) * np.sin(w_d * t)))
    rate = phi_inf * decay * (w_n / math.sqrt(1.0 - zeta * zeta)) * np.sin(w_d * t)
    return phi, rate


@pytest.mark.parametrize("k, d", [(50.0, 0.0), (50.0, 2e-3), (2e3, 5e-3)])
def test_a_torque_step_twists_the_free_shaft_as_the_closed_form_says(k, d):
    u, h = 100.0, 1e-4
    params = dict(FREE, k_shaft=k, d_shaft=d)
    out = _run(params, 0.05, h, u)
    t = (np.arange(len(out)) + 1) * h
    torque = FREE["c_e"] * 0.0 + (0.015 * 9.80665) * u / FREE["R"]  # c_m u / R (the back-EMF term is < 1e-8 of it)
    phi, rate = _step_twist(t, torque, FREE["J_m"], FREE["J_cam"], k, d)
    twist = out[:, COL["theta_m"]] - out[:, COL["theta"]]
    shaft = k * phi + d * rate
    assert np.max(np.abs(twist - phi)) <= 2e-6 * np.max(np.abs(phi))
    assert np.max(np.abs(out[:, COL["M_shaft"]] - shaft)) <= 2e-6 * np.max(np.abs(shaft))
    # the rotor and the cam together follow the rigid body's speed, torque t / (J_m + J_cam)
    momentum = FREE["J_m"] * out[:, COL["omega_m"]] + FREE["J_cam"] * out[:, COL["omega"]]
    assert np.max(np.abs(momentum - torque * t)) <= 1e-6 * torque * t[-1]


def test_without_losses_the_two_mass_drive_keeps_its_energy():
    """A cam turning at 20 rad/s with a follower under a conservative tilted gravity, a rotor on an undamped
    shaft, no friction and a motor too weak to matter: kinetic + elastic + potential energy is constant while
    the follower's changing inertia makes the shaft swing."""
    params = dict(c_e=1e-6, c_m=1e-6, R=1e3, shaft_friction=False, guide_friction=False, gamma=1.5707963267948966,
                  beta=0.0, G=1.0, omega0=20.0, k_shaft=30.0, d_shaft=0.0, J_m=3e-5, J_cam=1.41e-5, rtol=1e-11,
                  atol=1e-13)
    out = _run(params, 1.0, 1e-3, 0.0)
    model = DriveModel(params)
    J_c = out[:, COL["J"]] - model.J_m
    twist = out[:, COL["theta_m"]] - out[:, COL["theta"]]
    energy = (0.5 * J_c * out[:, COL["omega"]] ** 2 + 0.5 * model.J_m * out[:, COL["omega_m"]] ** 2
              + 0.5 * model.k_shaft * twist ** 2 - model.F_gx * out[:, COL["s"]])
    swing = np.max(np.abs(out[:, COL["M_shaft"]]))
    assert swing > 0.05  # the shaft does swing: 0.5 J omega^2 moves between the masses through it
    assert np.max(np.abs(energy / energy[0] - 1.0)) < 1e-8


def test_a_stiffer_shaft_converges_to_the_rigid_drive():
    rigid = _run(dict(J_m=3e-5, J_cam=1.41e-5), 0.5, 1e-3, 3.5)
    errors = []
    for k in (1e2, 1e3, 1e4):
        J_star = 1.0 / (1.0 / 3e-5 + 1.0 / 1.41e-5)
        d = 2.0 * 0.5 * math.sqrt(k * J_star)  # damping ratio 0.5: the start's ringing dies out
        out = _run(dict(J_m=3e-5, J_cam=1.41e-5, k_shaft=k, d_shaft=d), 0.5, 1e-3, 3.5)
        errors.append(np.max(np.abs(out[:, COL["theta"]] - rigid[:, COL["theta"]])))
    # The distance to the rigid drive falls as k^(-1/2) (measured 8.3e-4, 2.9e-4, 9.5e-5 rad: ratios 0.35, 0.33 per
    # decade): the stiction start holds the cam until the twist reaches M_f / k, which the rotor spinning up alone
    # reaches after a time proportional to k^(-1/2) (docs/model.md 12.4; without shaft friction it falls as 1/k).
    for coarse, fine in zip(errors, errors[1:]):
        assert 0.25 < fine / coarse < 0.4
    assert errors[2] < 2e-4  # rad, at a shaft 200 times stiffer than the scene's


def test_a_rigid_shaft_with_J_cam_is_the_paper_drive_with_that_inertia_added_to_the_rotor():
    split = _run(dict(J_m=3e-5, J_cam=1.41e-5), 0.3, 1e-3, 3.5)
    whole = _run(dict(J_m=4.41e-5), 0.3, 1e-3, 3.5)
    assert np.max(np.abs(split[:, :11] - whole[:, :11]) / (np.abs(whole[:, :11]) + 1e-12)) < 1e-13


@pytest.fixture(scope="module")
def scene_against_reference():
    scene = find_scene("compliant_shaft")
    run = scene.runs[0]
    params = dict(scene.parameters, **run.overrides)
    stop = 0.5
    ref = simulate_reference(params, stop, scene.output_interval, u=scene.u, rtol=1e-12, atol=1e-13)
    out = _run(params, stop, scene.output_interval, scene.u.value(0.0))
    return ref, out


@pytest.mark.parametrize("name, tol", [("theta", 1e-7), ("theta_m", 1e-7), ("omega", 2e-6), ("omega_m", 2e-6),
                                        ("M_shaft", 1e-7), ("i", 1e-8)])
def test_the_engine_agrees_with_the_reference_on_the_compliant_scene(scene_against_reference, name, tol):
    ref, out = scene_against_reference
    assert np.max(np.abs(out[:, COL[name]] - ref[name][1:])) <= tol


def test_stick_slip_on_a_compliant_shaft_matches_the_reference():
    """The cam held by shaft friction while the rotor winds the shaft up: break-away when the shaft's torque
    beats the friction, a stop, and a second break-away (stick-slip; the motor's back-EMF damps it out after
    that), in the engine and in the reference."""
    params = dict(J_m=3e-5, J_cam=1.41e-5, k_shaft=0.5, d_shaft=0.0, M_f=0.02, follower_inertia=False,
                  gravity=False, guide_friction=False)
    ref = simulate_reference(params, 0.6, 1e-3, u=constant(2.9), rtol=1e-12, atol=1e-13)
    sim = DriveSimulator(params)
    n = 600
    table = np.column_stack([np.arange(n) * 1e-3, np.full(n, 1e-3), np.full(n, 2.9), np.ones(n), np.zeros(n)])
    out = sim.run(table)
    names = [e["name"] for e in sim.events()]
    assert names.count("break_away") == 2 and names.count("stop") == 1  # it slips, sticks and slips again
    assert np.max(np.abs(out[:, COL["theta"]] - ref["theta"][1:])) < 1e-7
    held = out[:, COL["omega"]] == 0.0
    assert held.any() and (~held).any()
    assert np.all(np.abs(out[held, COL["M_shaft"]]) <= 0.02 * (1 + 1e-9))  # static friction holds what it can


@pytest.mark.parametrize("override, words", [
    (dict(k_shaft=10.0), ["'J_cam' = 0.0", "k_shaft > 0", "(0, 100]"]),
    (dict(k_shaft=10.0, J_cam=1e-5, formulation="paper"), ["'k_shaft' = 10.0", "formulation 'paper'"]),
    (dict(k_shaft=10.0, J_cam=1e-5, drive="speed"), ["'k_shaft' = 10.0", "drive 'speed'"]),
    (dict(k_shaft=10.0, J_cam=1e-5, solver="etdrk4"), ["'k_shaft' = 10.0", "solver 'etdrk4'", "'rk45'"]),
    (dict(k_shaft=-1.0, J_cam=1e-5), ["'k_shaft' = -1.0", "0 or [1e-06, 1e+09]"]),
])
def test_what_a_compliant_shaft_cannot_do_is_refused_with_the_same_words_in_both_models(override, words):
    with pytest.raises(ParameterError) as py_error:
        DriveModel(override)
    with pytest.raises(ParameterError) as c_error:
        DriveSimulator(override)
    assert str(py_error.value) == str(c_error.value)
    for word in words:
        assert word in str(c_error.value)


def test_the_energy_guard_counts_the_shaft_and_stops_a_solver_that_makes_energy():
    """Explicit Euler grows every undamped oscillation, the shaft's too: the guard, whose account holds the rotor's
    kinetic and the shaft's elastic energy (docs/model.md 12.2), stops the run with its message; rk4 at the same
    step stays within the bound and near rk45's answer."""
    scene = find_scene("compliant_shaft")
    params = dict(scene.parameters, **scene.runs[0].overrides)
    with pytest.raises(Exception, match="energy was created") as error:
        _run(dict(params, solver="euler", h_max=1e-4), 0.5, 1e-3, 3.5)
    assert type(error.value).__name__ == "SimulationError" and "solver 'euler'" in str(error.value)
    rk4 = _run(dict(params, solver="rk4", h_max=1e-4), 0.5, 1e-3, 3.5)
    rk45 = _run(params, 0.5, 1e-3, 3.5)
    assert np.max(np.abs(rk4[:, COL["theta"]] - rk45[:, COL["theta"]])) < 1e-4


@pytest.mark.parametrize("override, cause", [
    (dict(k_shaft=1e9, J_cam=1e-9), "the compliant shaft's rate"),
    (dict(k_shaft=1.0, d_shaft=1e6, J_cam=1e-5), "the compliant shaft's rate"),
    (dict(k_shaft=1.0, J_cam=1e-5, L=1e-7), "the electrical pole R/L = 1.9e+08 1/s is integrated explicitly"),
])
def test_a_shaft_too_stiff_for_the_steps_is_refused_naming_the_cause(override, cause):
    """rk45 on an extreme shaft (or, with a shaft, a tiny L) cannot finish a step within max_steps: the step is
    refused (fmi2Discard, the state as before) with the cause and what to change, never an answer."""
    sim = DriveSimulator(override)
    with pytest.raises(StepRejected) as error:
        for k in range(10):
            sim.do_step(k * 1e-3, 1e-3, u=3.5)
    assert "max_steps" in str(error.value) and cause in str(error.value)
    assert "k_shaft = 0" in str(error.value) or "L = 0" in str(error.value)
