"""The electrical pole at any L: the default solver runs and is accurate over the whole documented range.

Issue 18: with L = 1e-6 H, rk45 at 10 ms steps was refused (max_steps used up: the pole -R/L held
Dormand-Prince's step below its stability limit, 3.3 L/R). Now the default solver takes the pole
exponentially where it is stiff (docs/model.md, section 6.4). Against the FMI interface, like
tests/fmu_cs/test_fmi_boundary.py, and against the scipy reference (Radau where the pole is stiff).
"""
from __future__ import annotations

import pytest

from fmi_slave import OK, extract
from test_fmi_wrong_answers import _run

INDUCTANCES = (1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0, 10.0)  # H: the documented range
COMM_STEPS = (1e-4, 1e-3, 1e-2)  # s: the span of communication steps
STOP = 0.1  # s: the cam starts and the follower rises (a break-away and a stop-free run)


@pytest.fixture(scope="module")
def unzipped(cam_fmu_path, tmp_path_factory):
    return extract(cam_fmu_path, tmp_path_factory.mktemp("cam_fmu_pole"))


def _reference_theta(reference_runs, L: float) -> float:
    return float(reference_runs.simulate({"L": L}, STOP, 1e-3)["theta"][-1])


@pytest.mark.parametrize("h", COMM_STEPS)
@pytest.mark.parametrize("L", INDUCTANCES)
def test_the_default_solver_runs_and_is_accurate_at_any_inductance(unzipped, L, h, reference_runs):
    n = int(round(STOP / h))
    ok, out, errors = _run(unzipped, {"L": L}, [h] * n, ("theta", "i"))
    assert ok, errors
    theta, i = out
    # rk45's promise at the default rtol 1e-10 (tools/extremes.promised: 1e4 rtol per radian turned)
    assert theta == pytest.approx(_reference_theta(reference_runs, L), rel=1e-6, abs=1e-8)
    assert 0.0 < i < 3.5 / 19.0 * 1.0001  # the current never exceeds u / R at rest


def test_a_tiny_inductance_is_the_limit_of_none(unzipped):
    """L -> 0 converges to L = 0 (the quasi-static current): the exponential treatment has no
    floor of its own."""
    ok, with_l, errors = _run(unzipped, {"L": 1e-9}, [1e-3] * 100, ("theta", "omega"))
    assert ok, errors
    ok, without, errors = _run(unzipped, {"L": 0.0}, [1e-3] * 100, ("theta", "omega"))
    assert ok, errors
    assert with_l[0] == pytest.approx(without[0], rel=1e-6)
    assert with_l[1] == pytest.approx(without[1], rel=1e-5)
