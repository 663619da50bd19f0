"""The follower's kind in cam.fmu (FMI 2.0 co-simulation and Model Exchange under fmpy's CVode) and cam3.fmu (FMI 3.0
co-simulation): an oscillating roller's and an oscillating flat face's outputs, the arm's psi and psi_dot among them,
against the scipy reference (physics/kind_drive.py, written apart from the engine; docs/model.md 16)."""
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
KINDS = {"oscillating_roller": {**ARM, "follower_type": "oscillating_roller", "lift_angle": 0.3},
         "oscillating_flat": {**ARM, "follower_type": "oscillating_flat", "lift_angle": 0.15}}
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


@pytest.fixture(scope="module", params=list(KINDS))
def kind(request) -> tuple[str, dict]:
    params = KINDS[request.param]
    return request.param, simulate_reference(dict(defaults(), **params), STOP, STEP, u=constant(U))


@pytest.mark.parametrize("fmi_type", ["CoSimulation", "ModelExchange"])
def test_cam_fmu_runs_the_kind_as_the_reference_does(engine_fmu_path, kind, fmi_type):
    name, reference = kind
    options = {"relative_tolerance": 1e-10} if fmi_type == "ModelExchange" else {}
    result = fmpy.simulate_fmu(str(engine_fmu_path), fmi_type=fmi_type, start_values=dict(KINDS[name], u=U),
                               stop_time=STOP, output_interval=STEP, output=NAMES, **options)
    for output in NAMES:
        assert error(result, reference, output) < BOUNDS[fmi_type], (fmi_type, output, error(result, reference, output))
    assert np.max(result["psi"]) > 0.9 * KINDS[name]["lift_angle"]   # the arm swings through its law


def test_cam3_fmu_runs_the_kind_as_the_reference_does(cam3_fmu_path, kind):
    name, reference = kind
    result = fmpy.simulate_fmu(str(cam3_fmu_path), start_values=dict(KINDS[name], u=U), stop_time=STOP,
                               output_interval=STEP, output=NAMES)
    for output in NAMES:
        assert error(result, reference, output) < BOUNDS["CoSimulation"], (output, error(result, reference, output))


def test_a_kind_the_engine_cannot_run_is_an_fmi_error_with_its_reason(engine_fmu_path):
    logged: list[str] = []

    def logger(*args):
        logged.append(args[-1].decode() if isinstance(args[-1], bytes) else str(args[-1]))

    with pytest.raises(Exception):
        fmpy.simulate_fmu(str(engine_fmu_path), start_values=dict(KINDS["oscillating_roller"], arm_length=0.05),
                          stop_time=0.1, output_interval=0.01, logger=logger)
    assert any("'arm_length' = 0.05" in text and "cannot reach" in text for text in logged), logged
