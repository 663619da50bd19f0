"""The PI speed controller (control.pi) without an FMU, the SSP writer/reader, and the in-process loop."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from cam_fmu.control.pi import PiSpeedController, resolve
from cam_fmu.experiments.cosim import reference_loop, ripple
from cam_fmu.fmu.ssp import Connection, parse_ssd, speed_loop_system, system_xml
from cam_fmu.physics.parameters import ParameterError


def test_pi_law_by_hand():
    """u = kp e + I with I += ki h e, checked against the sums written out by hand."""
    c = PiSpeedController({"omega_set": 5.0, "kp": 2.0, "ki": 20.0, "u_min": -100.0, "u_max": 100.0})
    assert c.initialize(omega_meas=1.0) == 2.0 * 4.0  # no integration at initialisation
    h, meas = 1e-3, [1.0, 2.0, 4.5]
    integral = 0.0
    for w in meas:
        expected = 2.0 * (5.0 - w) + integral  # the sample uses the integral before this step
        assert c.sample(h, omega_meas=w) == pytest.approx(expected, abs=1e-15)
        integral += 20.0 * h * (5.0 - w)
    assert c.integral == pytest.approx(integral, abs=1e-15)


def test_clamp_and_anti_windup():
    c = PiSpeedController({"omega_set": 100.0, "kp": 1.0, "ki": 50.0, "u_min": -10.0, "u_max": 10.0})
    for _ in range(1000):  # saturated high with a positive error: the integrator must not grow
        assert c.sample(1e-3, omega_meas=0.0) == 10.0
    assert c.integral == pytest.approx(50.0 * 1e-3 * 100.0 * 0)  # never integrated: 0 <= v - kp e
    # once the error changes sign the integrator moves again and the output leaves the clamp at once
    u = c.sample(1e-3, omega_meas=105.0)
    assert u == pytest.approx(-5.0) and c.integral == pytest.approx(-50.0 * 1e-3 * 5.0)


def test_feedforward_is_the_steady_state_voltage():
    """u_ff = R M / c_m + c_e w: with it, zero error holds the speed against M (motor eqs., L = 0)."""
    p = {"feedforward": 1.0, "kp": 0.0, "ki": 0.0, "omega_set": 5.0, "u_min": -1e3, "u_max": 1e3}
    c = PiSpeedController(p)
    r = resolve(p)
    u = c.sample(1e-3, omega_meas=5.0, M_load=0.05, J_load=1e-3)
    i = (u - r["c_e"] * 5.0) / r["R"]  # armature current at that voltage and speed
    assert r["c_m"] * i == pytest.approx(0.05, rel=1e-12)  # motor torque = load torque


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1e3, 1e3), min_size=1, max_size=30), st.floats(-50, 0), st.floats(0, 50))
def test_output_always_within_clamp(meas, u_min, u_max):
    c = PiSpeedController({"kp": 3.0, "ki": 30.0, "u_min": u_min, "u_max": u_max, "feedforward": 1.0})
    for w in meas:
        assert u_min <= c.sample(1e-3, omega_meas=w, M_load=w / 100, J_load=1e-3) <= u_max


def test_bad_parameters_name_the_range():
    with pytest.raises(ParameterError, match=r"'kp' = -1.0 .* allowed range \[0, 10000\]"):
        resolve({"kp": -1})
    with pytest.raises(ParameterError, match="u_min <= u_max"):
        resolve({"u_min": 5, "u_max": 1})
    with pytest.raises(ParameterError, match="omega_meas"):
        PiSpeedController().sample(1e-3, omega_meas=math.nan)


def test_ssp_round_trip():
    system = speed_loop_system({"gamma": math.pi, "formulation": "paper", "backlash": False}, {"kp": 3.5})
    back = parse_ssd(system_xml(system))
    assert back.components["cam"].parameters == {"gamma": math.pi, "formulation": "paper", "backlash": False}
    assert back.components["controller"].parameters == {"kp": 3.5}
    assert back.connections == system.connections
    assert Connection("controller", "u", "cam", "u") in back.connections
    assert (back.start_time, back.stop_time, back.step_size) == (0.0, 2.0, 1e-3)


def test_reference_loop_holds_the_setpoint_and_feedforward_cuts_the_ripple():
    runs = {ff: reference_loop(speed_loop_system({"gamma": math.pi}, {"feedforward": float(ff)}, stop_time=3.0))
            for ff in (False, True)}
    for ff, r in runs.items():
        # the initial output kp * 5 rad/s (+ c_e * 5 + R M_f / c_m with feedforward: M(0) = M_f), seen by step 1
        assert r["controller.u"][0] == pytest.approx(10.0 + (0.146 * 5.0 + 19 * 0.012 / 0.14709975 if ff else 0.0),
                                                     abs=1e-6)
        assert abs(r["cam.omega"][1500:].mean() - 5.0) < 0.15  # the integrator removes the mean error
    without, with_ff = (ripple(runs[ff]["time"], runs[ff]["cam.omega"]) for ff in (False, True))
    assert with_ff < without / 3, (without, with_ff)
