"""`cam-fmu bench jacobian` (tools/bench/jacobian.py): a stiff run with cam.fmu's directional derivatives gives the
answer of the same integrator differencing the model, and its Jacobians are the FMU's (not scipy's differencing)."""
from __future__ import annotations

import numpy as np
import pytest

from cam_fmu.tools.bench import jacobian


@pytest.mark.parametrize("scene", list(jacobian.RUNS))
def test_stiff_run_with_the_fmu_jacobian_matches_the_differenced_one(engine_fmu_path, scene):
    """BDF over 0.02 s with L = 1 mH: final states within the tolerance of the differenced run's, the analytic run's
    Jacobians all came through fmi2GetDirectionalDerivative, and it needs no more right-hand sides."""
    fd = jacobian.stiff_run(engine_fmu_path, scene, "BDF", False, 0.02)
    an = jacobian.stiff_run(engine_fmu_path, scene, "BDF", True, 0.02)
    assert an["njev"] >= 1
    tol = jacobian.ATOL + jacobian.RTOL * np.abs(fd["x"])
    assert np.all(np.abs(an["x"] - fd["x"]) <= tol)
    assert an["nfev"] <= fd["nfev"]


def test_run_through_events_with_the_fmu_jacobian_is_co_simulations(engine_fmu_path):
    """The backlash scene's groove under closure 'form' over 1 s through its events, BDF and Radau restarted at each:
    with and without the FMU's Jacobian the same events and breakpoints, the final theta and omega within 1e-5 of
    their ranges of co-simulation's (its own integrator at rtol 1e-10; measured BDF 1.8e-6 of omega's range, Radau
    5e-9), and fewer right-hand sides with the Jacobian (measured 1153 -> 1012 and 1930 -> 1779)."""
    import fmpy

    cs = fmpy.simulate_fmu(str(engine_fmu_path), fmi_type="CoSimulation", start_values=dict(jacobian.EVENT_RUN[0]),
                           stop_time=1.0, output_interval=1e-3, output=["theta", "omega"])
    end = np.array([cs["theta"][-1], cs["omega"][-1]])
    ranges = np.array([np.abs(cs["theta"]).max(), np.abs(cs["omega"]).max()])
    for method in ("BDF", "Radau"):
        fd = jacobian.event_run(engine_fmu_path, method, False, 1.0)
        an = jacobian.event_run(engine_fmu_path, method, True, 1.0)
        assert an["njev"] >= an["restarts"] == fd["restarts"]   # a Jacobian of the FMU's at every restart at least
        assert an["events"] == fd["events"] >= 2 and an["breakpoints"] == fd["breakpoints"] >= 1
        for run in (fd, an):
            assert np.all(np.abs(run["x"][:2] - end) <= 1e-5 * ranges), (method, run["x"][:2] - end)
        assert an["nfev"] < fd["nfev"]
