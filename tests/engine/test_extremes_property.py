"""The extremes property (issue 9) on random cases: correct, or an error that names its cause.

Parameters across their documented ranges (log-uniform where a range spans
decades), a random solver, formulation, drive, communication step and input
steps (cam_fmu.tools.extremes.draw). Each run must either reach stop_time with
finite outputs that agree with the scipy reference to the tolerance its
settings promise (``extremes.promised``; the engine itself checks the energy
bound and the clearance on every step), or end with an error whose message
names a parameter, an input or a setting. Never another exception, never a
NaN. A fixed number of examples, derandomised: the same cases in every CI run.
The longer soak of the same property: ``python -m cam_fmu.tools.extremes --minutes N``.
"""
from __future__ import annotations

import signal

from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from cam_fmu.tools import extremes

HANG = 120  # s: a guard against a hang (a run takes 0.01-2 s), not a speed requirement


def _hang(_signum, _frame):
    raise AssertionError(f"a run did not finish within {HANG} s: a hang")


# No shrinking: a failing case is reported as drawn (shrinking reruns the reference hundreds of times).
@settings(max_examples=60, deadline=None, derandomize=True, database=None,
          phases=(Phase.explicit, Phase.generate), suppress_health_check=list(HealthCheck))
@given(st.randoms(use_true_random=False))
def test_every_extreme_run_is_correct_or_names_its_cause(rng):
    case = extremes.draw(rng)
    previous = signal.signal(signal.SIGALRM, _hang)
    signal.alarm(HANG)
    try:
        problem = extremes.check(case)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert problem is None, f"{problem}\n{case}"


def test_the_property_catches_a_wrong_answer():
    """The checker is not blind: a run whose answer is off the reference by more than promised fails it."""
    import random

    case = extremes.draw(random.Random(5))
    case.params.update(solver="rk45", rtol=1e-10, atol=1e-12, formulation="consistent", drive="voltage")
    original = extremes.reference_thetas
    extremes.reference_thetas = lambda c, rtol=1e-12: [x + 1.0 for x in original(c, rtol)]
    try:
        assert extremes.check(case) is not None
    finally:
        extremes.reference_thetas = original


def test_the_property_rejects_an_error_that_names_nothing():
    assert not extremes.names_a_cause("something went wrong")
    assert extremes.names_a_cause("parameter 'J_m' = 0 is outside the allowed range")
    assert extremes.names_a_cause("solver 'rk45' needed more than max_steps = 10")
