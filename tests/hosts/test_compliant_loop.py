"""The PI loop on the cam's speed around the compliant shaft (models/compliant_loop.ssp, `cam-fmu cosim`): gains
below the resonance keep the shaft quiet, gains above excite it at the two-mass resonance that the reflected
map predicts; the FMUs agree with the same loop run in-process."""
from __future__ import annotations

import copy

import numpy as np
import pytest

from cam_fmu.control.reflect import reflected_map, summary
from cam_fmu.experiments.cosim import reference_loop, simulate_system
from cam_fmu.fmu.build import ensure_ssp
from cam_fmu.fmu.ssp import read_ssp

GAINS = {"quiet": (0.5, 5.0), "resonant": (2.0, 20.0)}


@pytest.fixture(scope="module")
def loops():
    """Both FMUs are C: the loop runs in this process through fmpy, once per pair of gains."""
    system = read_ssp(ensure_ssp("compliant_loop"))
    runs = {}
    for label, (kp, ki) in GAINS.items():
        variant = copy.deepcopy(system)
        variant.components["controller"].parameters.update(kp=kp, ki=ki)
        result = simulate_system(variant, record=["cam.omega", "cam.omega_m"])
        runs[label] = (variant, {k: np.asarray(v) for k, v in result.items()})
    return system, runs


def _slip(run) -> np.ndarray:
    return run["cam.omega_m"] - run["cam.omega"]  # rad/s: the shaft's twist rate


def test_the_shipped_loop_measures_the_cam_through_a_compliant_shaft(loops):
    system, _ = loops
    cam = system.components["cam"].parameters
    assert cam["k_shaft"] > 0.0 and system.step_size == 2e-4
    assert [(c.start_element, c.start_connector, c.end_connector) for c in system.connections] == \
        [("controller", "u", "u"), ("cam", "omega", "omega_meas")]


def test_gains_below_the_resonance_keep_the_shaft_quiet_and_gains_above_excite_it(loops):
    system, runs = loops
    quiet, resonant = runs["quiet"][1], runs["resonant"][1]
    assert np.sqrt(np.mean(_slip(quiet) ** 2)) < 0.05
    assert np.max(np.abs(_slip(resonant))) > 20.0  # bursts of +-30 rad/s of the rotor against the cam
    # the bursts ring at the two-mass resonance of the map, within its range over the turn
    band = summary(reflected_map(system.components["cam"].parameters, 60.0, 720), 60.0)
    slip = _slip(resonant)
    spectrum = np.abs(np.fft.rfft(slip - slip.mean()))
    f = np.fft.rfftfreq(len(slip), system.step_size)
    assert band["f_r_min"] <= f[np.argmax(spectrum)] <= band["f_r_max"]
    for run in (quiet, resonant):  # both loops hold the setpoint on average over the second half
        second = run["time"] >= 1.0
        assert abs(run["cam.omega"][second].mean() - 3.0) < 0.1


def test_the_fmus_run_the_loop_as_the_engine_does_in_process(loops):
    _, runs = loops
    variant, fmu_run = runs["resonant"]
    inline = reference_loop(variant)
    for column in ("cam.omega", "controller.u"):
        assert np.max(np.abs(fmu_run[column] - inline[column])) <= 1e-9 * np.max(np.abs(inline[column]))
