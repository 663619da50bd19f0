"""The polydyne: the corrected follower motion makes the integrated train's end mass follow the law (the train's
equation solved for the follower, checked by integrating it forward), its motion table through the drive's curve
cancels the residual at the design speed, damped too, and the laws it refuses."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.kinematics.presets import named_law
from cam_fmu.vibration.polydyne import (StrokeProgram, check_smooth, jerk_jumps, polydyne_program, polydyne_table,
                                        table_residual, table_rise)
from cam_fmu.vibration.train import residual_ode, run_train

LIFT, BETA, HZ = 0.1, math.pi, 50.0


def omega_for(r: float) -> float:
    """The cam speed [rad/s] at which the rise over BETA lasts r periods of the HZ train."""
    return BETA * HZ / r


class Undamped:
    """The test's own undamped polydyne of one stroke: y / h = S + A / W^2, y' = V + J / W^2."""

    def __init__(self, law, r):
        self.law, self.W2 = law, (2 * math.pi * r) ** 2

    def scalar(self, u):
        S, V, A, J = self.law.scalar(u)
        return S + A / self.W2, V + J / self.W2, 0.0, 0.0

    def evaluate(self, u):
        S, _, A, _ = self.law.evaluate(u)
        return S + A / self.W2, 0 * S, 0 * S, 0 * S

    def breakpoints(self):
        return (0.0, 1.0)


def end_mass_error(run, law) -> float:
    S = np.where(run.u <= 1.0, law.evaluate(np.minimum(run.u, 1.0))[0], 1.0)
    return float(np.max(np.abs(run.x - S)))


@pytest.mark.parametrize("name", ["polynomial_4567", "cycloidal"])
def test_undamped_the_end_mass_follows_the_law(name):
    law, r = named_law(name), 1.7
    run = run_train(Undamped(law, r), r, 0.0, dwell=1.0, samples=400)
    assert end_mass_error(run, law) < 1e-9
    assert run.residual < 1e-9 < residual_ode(law, r)[0]


def test_the_program_is_the_undamped_closed_form_in_si_units():
    law, r = named_law("polynomial_345"), 2.2
    program = StrokeProgram(law, law, LIFT, BETA, 0.5, 2 * math.pi - BETA - 0.5)
    theta, y = polydyne_program(program, omega_for(r), HZ, 0.0, step_deg=1.0)
    rise = theta <= BETA
    want = LIFT * np.array([Undamped(law, r).scalar(t / BETA)[0] for t in theta[rise]])
    assert np.max(np.abs(y[rise] - want)) < 1e-15
    assert np.all(y[(theta > BETA) & (theta <= BETA + 0.5)] == LIFT)


@pytest.mark.parametrize("zeta", [0.0, 0.05])
def test_the_table_cancels_the_residual_at_the_design_speed(zeta):
    law, r = named_law("polynomial_4567"), 2.5
    program = StrokeProgram(law, law, LIFT, BETA, 0.0, 2 * math.pi - BETA)
    text = polydyne_table(program, omega_for(r), HZ, zeta, step_deg=0.1 if zeta == 0 else 0.25)
    rise = table_rise(text, BETA, LIFT)
    plain = residual_ode(law, [r, r / 1.1, r / 0.9], zeta)
    assert plain[0] > 1e-2
    run = run_train(rise, r, zeta, dwell=0.5, samples=400)
    assert run.residual <= 1e-4 and end_mass_error(run, law) < 1e-6
    # off the design speed the correction no longer cancels the ringing (here it still beats the plain law)
    off = [table_residual(rise, BETA, LIFT, x, zeta) for x in (r / 1.1, r / 0.9)]
    assert all(1e-4 < o < p for o, p in zip(off, plain[1:]))


def test_jerk_jumps_and_refusals():
    assert jerk_jumps(named_law("polynomial_4567")) == []
    assert [t for t, _ in jerk_jumps(named_law("modified_sine"))] == [0.0, 1.0]
    assert jerk_jumps(named_law("cycloidal")) == [(0.0, pytest.approx(4 * math.pi ** 2)),
                                                   (1.0, pytest.approx(-4 * math.pi ** 2))]
    for name in ("simple_harmonic", "constant_acceleration"):
        with pytest.raises(ValueError, match="rise law: its acceleration jumps at T = 0"):
            check_smooth(named_law(name), "rise")
