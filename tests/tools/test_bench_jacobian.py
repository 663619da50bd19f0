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
