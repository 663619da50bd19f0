"""cam3.fmu's FMI 3.0 directional derivatives: the engine's analytic tangent (jacobian.c, jacobian_follower.c) through
fmi3_me.c, the same call as FMI 2.0's. Checked against cam.fmu's fmi2GetDirectionalDerivative at the same state to the bit (that
one is checked against central differences in tests/fmu_me/test_directional_me.py) and against central differences
of cam3.fmu's own derivatives; the bad requests refused with their reason."""
from __future__ import annotations

from ctypes import POINTER, c_double

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException

from fmi3.test_fmi3_me import NX, Host
from fmu_me.test_directional_me import (CASES, FOLLOWER_CASES, RTOL, Me, enter_follower_mode, random_follower_state,
                                       random_states)


def fmi3_jacobian(host: Host, unknowns: list, knowns: list) -> np.ndarray:
    return np.array([host.model.getDirectionalDerivative(unknowns, [k], [1.0]) for k in knowns]).T


def set_knowns(host: Host, z: np.ndarray) -> None:
    x = np.ascontiguousarray(z[:NX], dtype=float)
    host.model.setContinuousStates(x.ctypes.data_as(POINTER(c_double)), NX)
    host.model.setFloat64([host.vr["u"]], [float(z[NX])])


@pytest.mark.parametrize("case", ["rigid", "compliant_L", "free_in_gap", "stuck", "spring_in_flight",
                                  "groove_other_flank_tilted"])
def test_fmi3_directional_derivatives_are_fmi2s_and_the_differences(cam3_fmu_path, engine_fmu_path, case):
    rng = np.random.default_rng(7)
    me = Me(engine_fmu_path, CASES[case])
    host = Host(cam3_fmu_path)
    host.start(**CASES[case])
    stuck = CASES[case].get("omega0", 1.0) == 0.0
    unknowns = me.ders + me.outputs
    try:
        for _ in range(3):
            random_states(me, rng, stuck)
            z = me.knowns_now()
            set_knowns(host, z)
            j2, j3 = me.jacobian(), fmi3_jacobian(host, unknowns, me.knowns)
            assert np.array_equal(j2, j3)
            assert np.abs(j3).max() > 0.0
            # central differences of cam3.fmu's own derivatives and outputs, in the one known u
            h = 1e-5 * max(1.0, abs(z[NX]))
            rows = []
            for sign in (1.0, -1.0):
                shifted = z.copy()
                shifted[NX] += sign * h
                set_knowns(host, shifted)
                rows.append(np.concatenate([host.array(host.model.getContinuousStateDerivatives, NX),
                                            host.model.getFloat64(me.outputs)]))
            set_knowns(host, z)
            du = (rows[0] - rows[1]) / (2 * h)
            scale = max(np.abs(du).max(), 1e-300)
            assert np.all(np.abs(j3[:, NX] - du) <= RTOL * scale + 1e-12)
    finally:
        me.close()
        host.model.terminate()
        host.model.freeInstance()


class Host3(Host):
    """The FMI 3.0 host with the calls enter_follower_mode and random_follower_state make (Me's, FMI 3.0's names)."""

    def x(self) -> np.ndarray:
        return self.array(self.model.getContinuousStates, NX)

    def set_x(self, x: np.ndarray) -> None:
        x = np.ascontiguousarray(x, dtype=float)
        self.model.setContinuousStates(x.ctypes.data_as(POINTER(c_double)), NX)

    def indicators(self) -> np.ndarray:
        return self.array(self.model.getEventIndicators, self.md.numberOfEventIndicators)

    def event(self) -> None:
        self.model.enterEventMode()
        while self.model.updateDiscreteStates()[0]:
            pass
        self.model.enterContinuousTimeMode()

    def set_u(self, u: float) -> None:
        self.model.setFloat64([self.vr["u"]], [u])

    def f(self, outputs: list) -> np.ndarray:
        return np.concatenate([self.array(self.model.getContinuousStateDerivatives, NX),
                               self.model.getFloat64(outputs)])


@pytest.mark.parametrize("case", ["groove_voltage/flight", "spring_voltage/stuck", "spring_compliant/contact",
                                  "backlash_form/flight_stuck", "groove_friction_L/contact", "spring_train/flight",
                                  "arm_groove/flight"])
def test_fmi3_follower_of_its_own_derivatives(cam3_fmu_path, engine_fmu_path, case):
    """A follower of its own in each mode (reached by each version's own event updates): fmi3GetDirectionalDerivative
    is fmi2GetDirectionalDerivative at the same state to the bit, and central differences of cam3.fmu's own
    fmi3GetContinuousStateDerivatives and outputs agree with it to 1e-6 relative (of each row's largest entry)."""
    start, mode, speed = FOLLOWER_CASES[case]
    rng = np.random.default_rng(5)
    me = Me(engine_fmu_path, start)
    host = Host3(cam3_fmu_path)
    host.start(**start)
    unknowns = me.ders + me.outputs
    checked = 0
    try:
        train = start.get("k_train", 0.0) > 0.0
        enter_follower_mode(me, mode, speed, train)
        enter_follower_mode(host, mode, speed, train)
        for _ in range(20):
            random_follower_state(me, rng, mode, start.get("c", 1e-3))
            z = me.knowns_now()
            set_knowns(host, z)
            j2, j3 = me.jacobian(), fmi3_jacobian(host, unknowns, me.knowns)
            assert np.array_equal(j2, j3)
            differences = []
            for rel in (1e-5, 5e-6):
                columns = []
                for j in range(len(z)):
                    h = rel * max(1.0, abs(z[j])) * (1e-3 if j in (NX - 2, NX - 1) else 1.0)
                    rows = []
                    for sign in (1.0, -1.0):
                        shifted = z.copy()
                        shifted[j] += sign * h
                        set_knowns(host, shifted)
                        rows.append(host.f(me.outputs))
                    columns.append((rows[0] - rows[1]) / (2 * h))
                differences.append(np.array(columns).T)
            set_knowns(host, z)
            coarse, fine = differences
            scale = np.maximum(np.abs(fine).max(axis=1, keepdims=True), 1e-300)
            if not np.all(np.abs(coarse - fine) <= 1e-8 * scale + 1e-8 * np.abs(fine)):
                continue   # a breakpoint of the profile within the steps
            assert np.all(np.abs(j3 - fine) <= RTOL * scale + 1e-12), np.argwhere(np.abs(j3 - fine) > RTOL * scale)
            assert np.abs(j3).max() > 0.0
            checked += 1
            if checked == 3:
                break
    finally:
        me.close()
        host.model.terminate()
        host.model.freeInstance()
    assert checked == 3


def test_fmi3_bad_directional_requests_are_errors_with_the_reason(cam3_fmu_path):
    host = Host(cam3_fmu_path)
    host.start(omega0=20.0)
    model, vr = host.model, host.vr
    der_omega = vr["der(x_omega)"]
    for unknowns, knowns in (([der_omega], [99999]), ([vr["x_theta"]], [vr["x_theta"]]), ([der_omega], [vr["R"]])):
        with pytest.raises(FMICallException):
            model.getDirectionalDerivative(unknowns, knowns, [1.0])
    seed = (c_double * 2)(1.0, 1.0)
    out = (c_double * 1)(123.0)
    vrs = (model.dll.fmi3GetDirectionalDerivative.argtypes[1]._type_ * 2)(vr["x_theta"], vr["u"])
    unknown = (model.dll.fmi3GetDirectionalDerivative.argtypes[1]._type_ * 1)(der_omega)
    status = model.dll.fmi3GetDirectionalDerivative(model.component, unknown, 1, vrs, 2, seed, 1, out, 1)
    assert status == 3 and out[0] == 0.0   # nSeed != nKnowns: an error, no number in the derivative's place
    texts = host.errors()
    assert any("value reference 99999" in t for t in texts)
    assert any("('x_theta') is no unknown" in t for t in texts)
    assert any("nSeed (1) must equal nKnowns (2)" in t for t in texts)
    assert model.getDirectionalDerivative([der_omega], [vr["u"]], [1.0])[0] > 0.0   # a right request still answers
    model.terminate()
    model.freeInstance()
    spring = Host(cam3_fmu_path)   # a follower of its own: the same refusals, and a right request answers
    spring.start(omega0=20.0, closure="spring")
    with pytest.raises(FMICallException):
        spring.model.getDirectionalDerivative([der_omega], [99999], [1.0])
    assert any("value reference 99999" in t for t in spring.errors())
    assert spring.model.getDirectionalDerivative([der_omega], [vr["u"]], [1.0])[0] > 0.0
    spring.model.terminate()
    spring.model.freeInstance()
