"""Effect switches: an effect that is off is absent from the physics and costs nothing per step."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.fmu.engine import DriveSimulator

R, C_E, C_M, J_M, M_F = 19.0, 0.146, 0.015 * 9.80665, 4.41e-5, 0.012
FOLLOWER_OFF = {"follower_inertia": False, "gravity": False, "guide_friction": False}


def _run(params: dict, u: float = 3.5, stop: float = 0.5, h: float = 1e-3) -> dict[str, np.ndarray]:
    sim = DriveSimulator(params)
    sim.set_inputs(u, 1.0)
    rows = [dict(sim.outputs())]
    for k in range(int(round(stop / h))):
        sim.do_step(k * h, h, u, 1.0)
        rows.append(dict(sim.outputs()))
    out = {name: np.array([r[name] for r in rows]) for name in rows[0]}
    out["time"] = np.arange(len(rows)) * h
    return out


@pytest.mark.parametrize("shaft_friction", [True, False])
def test_without_the_follower_the_drive_is_the_bare_first_order_motor(shaft_friction):
    """J = J_m, M = M_f: omega(t) = w_inf (1 - exp(-t / tau)), w_inf = (c_m u / R - M_f) R / (c_e c_m)."""
    run = _run({**FOLLOWER_OFF, "shaft_friction": shaft_friction})
    m_f = M_F if shaft_friction else 0.0
    w_inf = (C_M * 3.5 / R - m_f) * R / (C_E * C_M)
    tau = R * J_M / (C_E * C_M)
    exact = w_inf * (1.0 - np.exp(-run["time"] / tau))
    assert np.max(np.abs(run["omega"] - exact)) < 1e-8 * w_inf
    assert np.all(run["J"] == J_M)
    assert np.allclose(run["M"][1:], m_f, rtol=0, atol=1e-15)  # no follower load at all


def test_a_switched_off_follower_leaves_the_bare_motor():
    """With the follower's inertia, gravity and guide friction off, the shaft is the bare motor with
    Coulomb friction: omega(t) = w (1 - exp(-t/tau)), w = (c_m u/R - M_f) R/(c_m c_e), tau = R J_m/(c_m c_e)
    (the closed form; 1e-9 relative over 0.1 s), and it costs fewer internal steps than the full drive."""
    from cam_fmu.physics.parameters import defaults

    p = defaults()
    off, on = DriveSimulator(FOLLOWER_OFF), DriveSimulator({})
    for k in range(100):
        off.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
        on.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
    R, c_e, c_m, J_m, M_f = (p[n] for n in ("R", "c_e", "c_m", "J_m", "M_f"))
    w = (c_m * 3.5 / R - M_f) * R / (c_m * c_e)
    tau = R * J_m / (c_m * c_e)
    assert off.outputs()["omega"] == pytest.approx(w * (1.0 - np.exp(-0.1 / tau)), rel=1e-9)
    assert 100 <= off.steps_taken < on.steps_taken


def test_inductance_switch_off_ignores_L():
    """inductance = false with L = 1 mH is the L = 0 drive, to the bit."""
    off = _run({"L": 1e-3, "inductance": False})
    zero = _run({})
    for name in ("theta", "omega", "i", "M"):
        assert np.array_equal(off[name], zero[name]), name


@pytest.mark.parametrize("switch, parameter, value", [
    ("gravity", "G", 0.0), ("guide_friction", "mu", 0.0), ("shaft_friction", "M_f", 0.0),
    ("follower_inertia", "m", 0.0), ("backlash", "c", 0.0),
])
def test_a_switch_off_equals_its_coefficient_at_zero(switch, parameter, value):
    """Tilted mounting (gravity matters): each switch removes exactly its term."""
    tilted = {"gamma": math.pi / 2, "beta": math.pi / 4, "c": 1e-3}
    off = _run({**tilted, switch: False}, u=20.0, stop=0.3)
    zero = _run({**tilted, parameter: value}, u=20.0, stop=0.3)
    assert np.array_equal(off["theta"], zero["theta"]) and np.array_equal(off["M"], zero["M"])
    on = _run(tilted, u=20.0, stop=0.3)
    assert np.max(np.abs(on["theta"] - off["theta"])) > 1e-6  # and the effect is not nothing
