"""The follower's kind in cam.fmu (FMI 2.0 co-simulation and Model Exchange under fmpy's CVode) and cam3.fmu (FMI 3.0
co-simulation): an oscillating roller's and an oscillating flat face's outputs, the arm's psi and psi_dot among them,
and every type with its friction (mu), against the scipy reference (physics/kind_drive.py, written apart from the
engine; docs/model.md 16); a follower its friction would wedge is an FMI error with the reference's message."""
from __future__ import annotations

import math

import fmpy
import numpy as np
import pytest

from cam_fmu.physics.parameters import defaults
from cam_fmu.physics.signals import constant
from cam_fmu.reference.integrate import simulate_reference

STOP, STEP, U = 0.5, 0.01, 40.0
RISE = math.pi / 2
ARM = {"rise_law": "cycloidal", "return_law": "cycloidal", "rise_angle": RISE, "upper_dwell": RISE,
       "return_angle": RISE, "lower_dwell": RISE, "lift": 0.02, "r_b": 0.08, "closure": "kinematic", "m": 0.4,
       "G": 4.0, "M_f": 0.012, "mu": 0.0, "gamma": 1.2, "J_cam": 2e-4, "arm_length": 0.15, "pivot_distance": 0.18,
       "J_arm": 2e-3, "m_arm": 0.2, "r_cm_arm": 0.07, "psi_0": 0.3}
ARM_ONLY = ("arm_length", "pivot_distance", "J_arm", "m_arm", "r_cm_arm", "psi_0")
KINDS = {"oscillating_roller": {**ARM, "follower_type": "oscillating_roller", "lift_angle": 0.3},
         "oscillating_flat": {**ARM, "follower_type": "oscillating_flat", "lift_angle": 0.15}}
# each type with its friction (the face's sliding, the arm's pivot): the reference integrated by Radau (DOP853 took
# one inaccurate step over a breakpoint after a side event, tests/engine/test_engine_follower_kinds.py)
KINDS.update({f"{name}_friction": {**params, "mu": 0.05} for name, params in KINDS.items()})
KINDS["translating_flat_friction"] = {**{k: v for k, v in ARM.items() if k not in ARM_ONLY}, "beta": 0.3,
                                      "follower_type": "translating_flat", "mu": 0.05}
NAMES = ["theta", "omega", "i", "M", "J", "s", "v", "a", "alpha", "N_contact", "psi", "psi_dot"]
# max |FMU - reference| / max |reference| measured: co-simulation (the engine at its rtol; cam.fmu and cam3.fmu
# alike) at most 1.2e-8 (face) and 2.0e-7 (roller), both in M; Model Exchange with CVode at rtol 1e-10 at most 1.6e-5
# (roller) and 1.8e-5 (face), in M: CVode's own error (theta 7e-8, omega 3.5e-6 of their largest; at rtol 1e-12 M's
# falls to 3.0e-7)
BOUNDS = {"CoSimulation": 1e-6, "ModelExchange": 5e-5}


def error(result, reference: dict, name: str) -> float:
    rows = [np.nonzero(np.isclose(result["time"], t, rtol=0.0, atol=1e-9))[0][-1] for t in reference["time"]]
    scale = np.max(np.abs(reference[name]))
    return float(np.max(np.abs(result[name][rows] - reference[name])) / (scale if scale > 0.0 else 1.0))


def fmu_against_reference(fmu, fmi_type: str | None, start: dict, reference: dict, bound: float):
    """cam.fmu (or cam3.fmu: fmi_type None) run from `start` at U against `reference`: every NAMES output within
    `bound` of its largest (error); the result."""
    options = {"relative_tolerance": 1e-10} if fmi_type == "ModelExchange" else {}
    if fmi_type is not None:
        options["fmi_type"] = fmi_type
    result = fmpy.simulate_fmu(str(fmu), start_values=dict(start, u=U), stop_time=STOP, output_interval=STEP,
                               output=NAMES, **options)
    for output in NAMES:
        assert error(result, reference, output) < bound, (fmi_type, output, error(result, reference, output))
    return result


@pytest.fixture(scope="module", params=list(KINDS))
def kind(request) -> tuple[str, dict]:
    params = KINDS[request.param]
    method = "Radau" if params["mu"] else None
    return request.param, simulate_reference(dict(defaults(), **params), STOP, STEP, u=constant(U), method=method)


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
def test_cam_fmu_runs_the_kind_as_the_reference_does(engine_fmu_path, kind, fmi_type):
    name, reference = kind
    result = fmu_against_reference(engine_fmu_path, fmi_type, KINDS[name], reference, BOUNDS[fmi_type])
    if name.startswith("oscillating"):
        assert np.max(result["psi"]) > 0.9 * KINDS[name]["lift_angle"]   # the arm swings through its law
    else:
        assert np.max(result["s"]) > 0.9 * KINDS[name]["lift"]


def test_cam3_fmu_runs_the_kind_as_the_reference_does(cam3_fmu_path, kind):
    name, reference = kind
    fmu_against_reference(cam3_fmu_path, None, KINDS[name], reference, BOUNDS["CoSimulation"])


def refused_at_initialisation(fmu, start: dict) -> list[str]:
    """The FMU's log lines when it refuses `start` at the exit of initialisation (fmi2Error there, asserted)."""
    logged: list[str] = []

    def logger(*args):
        logged.append(args[-1].decode() if isinstance(args[-1], bytes) else str(args[-1]))

    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        fmpy.simulate_fmu(str(fmu), start_values=start, stop_time=0.1, output_interval=0.01, logger=logger)
    return logged


def test_a_kind_the_engine_cannot_run_is_an_fmi_error_with_its_reason(engine_fmu_path):
    logged = refused_at_initialisation(engine_fmu_path, dict(KINDS["oscillating_roller"], arm_length=0.05))
    assert any("'arm_length' = 0.05" in text and "cannot reach" in text for text in logged), logged


def test_a_follower_its_friction_would_wedge_is_an_fmi_error_with_the_reference_message(engine_fmu_path):
    """An oscillating flat face at mu = 0.5 without J_cam: J_0 + I_f q' (q' - mu lambda) < 0 on the return; the FMU
    refuses it at the exit of initialisation with the message the reference raises."""
    from cam_fmu.physics.parameters import ParameterError

    params = {**KINDS["oscillating_flat"], "mu": 0.5, "J_cam": 0.0}
    with pytest.raises(ParameterError) as reference_error:
        simulate_reference(dict(defaults(), **params), 0.1, 0.01, u=constant(U))
    logged = refused_at_initialisation(engine_fmu_path, dict(params, u=U))
    assert "wedge" in str(reference_error.value)
    assert any(str(reference_error.value) in text for text in logged), (str(reference_error.value), logged)


# Every type as a body of its own (docs/model.md 16.3), with its friction: an arm in a 0.3 mm groove and on a spring
# about its pivot, a translating face on a spring; the follower flies and strikes at 40 V.
OWN = {"oscillating_roller_groove": {**KINDS["oscillating_roller_friction"], "closure": "form", "c": 3e-4,
                                     "restitution": 0.5},
       "oscillating_flat_spring": {**KINDS["oscillating_flat_friction"], "closure": "spring", "k_spring": 100.0,
                                   "F_spring0": 1.0, "restitution": 0.5},
       "translating_flat_spring": {**KINDS["translating_flat_friction"], "closure": "spring", "k_spring": 100.0,
                                   "F_spring0": 1.0, "restitution": 0.5}}
# max |FMU - reference| / max |reference| measured: co-simulation and cam3.fmu 1.7e-11 (translating face) .. 4.8e-8
# (the arm in its groove, 172 impacts in 0.5 s), Model Exchange under CVode at rtol 1e-10 (its own steps, the events
# located by the FMU's indicators) 4.2e-7 .. 1.2e-5 (the arm's a)
OWN_BOUNDS = {"CoSimulation": 5e-7, "ModelExchange": 1e-4}


@pytest.fixture(scope="module", params=list(OWN))
def own(request) -> tuple[str, dict]:
    params = OWN[request.param]
    return request.param, simulate_reference(dict(defaults(), **params), STOP, STEP, u=constant(U))


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
def test_cam_fmu_flies_every_kind_as_the_reference_does(engine_fmu_path, own, fmi_type):
    name, reference = own
    fmu_against_reference(engine_fmu_path, fmi_type, OWN[name], reference, OWN_BOUNDS[fmi_type])
    assert np.sum(reference["contact"] == 0.0) >= 5 and reference["impacts"][-1] >= 3


def test_cam3_fmu_flies_every_kind_as_the_reference_does(cam3_fmu_path, own):
    name, reference = own
    fmu_against_reference(cam3_fmu_path, None, OWN[name], reference, OWN_BOUNDS["CoSimulation"])


@pytest.mark.parametrize("changes,words", [
    ({**KINDS["translating_flat_friction"], "r_b": 0.005}, ("'r_b' = 0.005", "a cusp")),
    ({**KINDS["oscillating_roller"], "pivot_distance": 0.1, "arm_length": 0.1, "lift_angle": 1.0},
     ("'pivot_distance' = 0.1", "sweep over the pivot")),
])
def test_a_contour_that_cannot_be_built_is_an_fmi_error_as_the_reference_refuses_it(engine_fmu_path, changes, words):
    """A flat face's cusp and a rocker's cam sweeping over its pivot (the contour on a 0.1 deg grid): fmi2Error at the
    exit of initialisation naming the parameter, where the reference refuses the same geometry."""
    from cam_fmu.physics.parameters import ParameterError

    with pytest.raises(ParameterError):
        simulate_reference(dict(defaults(), **changes), 0.1, 0.01, u=constant(U))
    logged = refused_at_initialisation(engine_fmu_path, dict(changes, u=U))
    assert any(all(word in text for word in words) for text in logged), logged
