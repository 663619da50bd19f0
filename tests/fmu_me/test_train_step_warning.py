"""A follower train under a host's fixed step in Model Exchange (docs/model.md 14.7, issue 41): the FMU cannot refuse
a host's step before the run (the host does not declare it), so at the first completed integrator step that spans
more than a radian of the train's ringing it says so, once, as fmi2Warning / fmi3Warning naming the train's
parameters, the step and the step rk4 would need; explicit Euler's growing ringing then ends in the energy bound's
error. A resolving step and an adaptive host (CVode) hear nothing."""
from __future__ import annotations

import fmpy
import pytest

TRAIN = dict(u=3.5, k_train=2e4, d_train=2.0, m_end=0.2, M_f=0.0, mu=0.0)   # 326 1/s of ringing


def run(fmu, **options) -> tuple[bool, list[str], list[str]]:
    """fmpy's Model Exchange run of 0.2 s: (finished, warnings, errors) from the FMU's log."""
    logged: list[tuple[int, str]] = []

    def logger(*args):   # FMI 2.0's (env, name, status, category, message), FMI 3.0's without the name
        status, message = args[-3], args[-1]
        logged.append((status, message.decode() if isinstance(message, bytes) else str(message)))

    try:
        fmpy.simulate_fmu(str(fmu), fmi_type="ModelExchange", start_values=TRAIN, stop_time=0.2,
                          output_interval=options.get("step_size", 1e-3), logger=logger, **options)
        finished = True
    except fmpy.fmi1.FMICallException:
        finished = False
    return finished, [m for s, m in logged if s == 1], [m for s, m in logged if s >= 3]


@pytest.mark.parametrize("version", ["fmi2", "fmi3"])
def test_a_step_spanning_the_train_s_ringing_is_said_once(version, engine_fmu_path, cam3_fmu_path):
    fmu = engine_fmu_path if version == "fmi2" else cam3_fmu_path
    finished, warnings, errors = run(fmu, solver="Euler", step_size=5e-3)   # 1.63 rad a step
    assert len(warnings) == 1, warnings
    for part in ("host's step of 0.005 s", "1.63 rad", "k_train", "m_end", "0.00113 s"):
        assert part in warnings[0], (part, warnings[0])
    assert not finished and errors and "energy was created" in errors[0]   # Euler grows it: the bound stops it


@pytest.mark.parametrize("options", [dict(solver="Euler", step_size=1e-5), dict(solver="CVode")],
                         ids=["euler-1e-5", "cvode"])
def test_a_resolving_step_or_an_adaptive_host_hears_nothing(options, engine_fmu_path):
    finished, warnings, errors = run(engine_fmu_path, **options)
    assert finished and warnings == [] and errors == []
