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
from fmu_me.test_directional_me import CASES, RTOL, Me, random_states


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
