"""A follower train under a host's own integration in Model Exchange (docs/model.md 14.7, docs/fmu.md, issue 41).
The FMU cannot refuse a host's method or step before the run (the host declares neither); it judges them from how the
host samples the drive while the train rings by more than 1e-4 of the lift, and says once, as fmi2Warning /
fmi3Warning with its reason, where the answer may be aliased, damped or grown: explicit Euler (one derivative
evaluation a step, at its start: fmpy's Euler) past a drift w^2 h t / 2 of 0.01, any other past 0.25 rad of the
ringing between two samples (rk4's stages h / 2 apart; CVode at a loose tolerance). Each warning is checked against what it warns of:
the run's F_train against co-simulation's (the engine's rk45 at its tolerance), and a quiet host is right."""
from __future__ import annotations

import fmpy
import numpy as np
import pytest

from rk4_host import WARNING, run_rk4

TRAIN = dict(u=3.5, k_train=2e4, d_train=0.5, m_end=0.2, M_f=0.0, mu=0.0)   # 318.7 1/s of ringing
STOP = 0.3   # s: the cam starts and enters the rise; F_train swings over 2.1 N
RATE = 318.7  # 1/s: sqrt(k_train / m_end) + d_train / m_end, the rate the messages name


@pytest.fixture(scope="module")
def co_simulation(engine_fmu_path) -> dict:
    return fmpy.simulate_fmu(str(engine_fmu_path), start_values=TRAIN, stop_time=STOP, output_interval=1e-4,
                             output=["F_train"])


def off(run: dict, co_simulation: dict) -> float:
    """N: the largest |F_train - co-simulation's| over the run."""
    return float(np.max(np.abs(run["F_train"] - np.interp(run["time"], co_simulation["time"],
                                                           co_simulation["F_train"]))))


def fmpy_run(fmu, **options) -> tuple[dict | None, list[str], list[str]]:
    """fmpy's Model Exchange run: (result or None when it stopped, warnings, errors) from the FMU's log."""
    logged: list[tuple[int, str]] = []

    def logger(*args):   # FMI 2.0's (env, name, status, category, message), FMI 3.0's without the name
        status, message = args[-3], args[-1]
        logged.append((status, message.decode() if isinstance(message, bytes) else str(message)))

    try:
        result = fmpy.simulate_fmu(str(fmu), fmi_type="ModelExchange", start_values=TRAIN, stop_time=STOP,
                                   output_interval=options.get("step_size", 1e-3), logger=logger,
                                   output=["F_train"], **options)   # fmpy's Euler steps at the output interval
    except fmpy.fmi1.FMICallException:
        result = None
    return result, [m for s, m in logged if s == WARNING], [m for s, m in logged if s >= 3]


def test_an_adaptive_host_at_the_declared_tolerance_hears_nothing_and_is_right(engine_fmu_path, co_simulation):
    """fmpy's CVode at the DefaultExperiment's tolerance: no warning, F_train within 1e-4 N (measured 3.2e-5)."""
    result, warnings, errors = fmpy_run(engine_fmu_path, solver="CVode")
    assert result is not None and warnings == [] and errors == []
    assert off(result, co_simulation) < 1e-4


@pytest.mark.parametrize("rtol", [1e-4, 1e-3])
def test_an_adaptive_host_at_a_loose_tolerance_is_warned_where_it_steps_over_the_ringing(rtol, engine_fmu_path,
                                                                                      co_simulation):
    """CVode at rtol 1e-4 takes steps of 1.2 ms (0.37 rad) across a ringing of 1.8e-5 m: warned once, and rightly:
    its F_train is off by 1.7 N of the 2.1 N it swings (1.0 N at 1e-3), the ringing damped."""
    result, warnings, errors = fmpy_run(engine_fmu_path, solver="CVode", relative_tolerance=rtol)
    assert result is not None and errors == [] and len(warnings) == 1, warnings
    for part in ("sampled the drive", "rad of the follower train's ringing", "k_train", "m_end", "of the lift"):
        assert part in warnings[0], (part, warnings[0])
    assert off(result, co_simulation) > 0.5


@pytest.mark.parametrize("phase, warned, bound", [(0.2, False, 2e-3), (0.6, True, None), (1.5, True, None)])
def test_rk4_is_warned_past_a_quarter_radian_between_its_stages(phase, warned, bound, engine_fmu_path,
                                                               co_simulation):
    """This file's rk4 host (its stages h / 2 apart) at w h = 0.2: silent, F_train within 1.1e-3 N; at 0.6 and 1.5
    (0.3 and 0.75 rad between samples): one fmi2Warning, and F_train off by 0.08 and 0.52 N (damped ringing)."""
    run = run_rk4(engine_fmu_path, TRAIN, phase / RATE, STOP, ("F_train",))
    warnings = [m for s, m in run["log"] if s == WARNING]
    assert run["failed"] is None
    assert run["statuses"].count(WARNING) == len(warnings) == (1 if warned else 0), warnings
    if warned:
        assert f"{phase / 2:.3g} rad of the follower train's ringing" in warnings[0], warnings[0]
        assert off(run, co_simulation) > 0.05
    else:
        assert off(run, co_simulation) < bound


@pytest.mark.parametrize("version", ["fmi2", "fmi3"])
@pytest.mark.parametrize("step", [1e-5, 1e-4])
def test_a_first_order_host_is_warned_by_the_drift_it_gives_the_ringing(step, version, engine_fmu_path,
                                                                        cam3_fmu_path, co_simulation):
    """fmpy's Euler evaluates the derivatives once a step: explicit Euler grows a ringing's amplitude by
    exp(w^2 h t / 2), past 1 % at t = 0.0197 s with h = 1e-5 s. Warned once (FMI 2.0 and 3.0), and rightly: F_train
    off by 0.085 N at 1e-5 s and 2.5 N at 1e-4 s, however short the step looks against the train's period."""
    fmu = engine_fmu_path if version == "fmi2" else cam3_fmu_path
    result, warnings, errors = fmpy_run(fmu, solver="Euler", step_size=step)
    assert result is not None and errors == [] and len(warnings) == 1, warnings
    for part in ("once a step, at its start (explicit Euler)", "w^2 h t / 2", "k_train", "0.02 / (w^2 T)"):
        assert part in warnings[0], (part, warnings[0])
    assert off(result, co_simulation) > 0.02
