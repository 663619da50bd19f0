"""What the engine's solvers (the parameter ``solver``; csrc/src/methods.c) are and promise, for tools.

``adaptive``: the step is chosen by error control on rtol and atol (the C method's
``adaptive`` flag, which tests/engine/test_engine_solvers.py reads back from the library).
``promised_relative``: the relative theta error a fixed-step method's stability and
resolution limits keep a run within, measured at 100 and 400 V against the
reference (docs/performance.md); an adaptive method promises about its rtol instead.
``taylor_order``: a fixed-step explicit Runge-Kutta method whose step multiplies a linear mode e^(lambda t) by the
Taylor polynomial of e^z of that degree (z = h lambda; train_step.py); 0 for the others.
"""
from __future__ import annotations

from typing import NamedTuple

from ..physics.parameters import SOLVERS as SOLVER_NAMES


class Solver(NamedTuple):
    name: str
    adaptive: bool
    promised_relative: float
    taylor_order: int = 0


SOLVERS: dict[str, Solver] = {s.name: s for s in (
    Solver("euler", False, 0.25, 1),      # first order: 9 % measured at 100 V
    Solver("rk4", False, 1e-2, 4),      # 6e-5 measured at 100 V
    Solver("rk45", True, float("inf")),
    Solver("etdrk4", False, 1e-2),     # 2.5e-4 measured at 400 V
    Solver("rk23", True, float("inf")),
)}
assert tuple(SOLVERS) == SOLVER_NAMES, "one entry per choice of the parameter 'solver'"

__all__ = ["SOLVERS", "Solver"]
