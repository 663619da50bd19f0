"""The contract every solver of the FMU keeps, and the error it raises.

A stepper advances a continuous state y (a list of floats) by one step of a
hybrid system (see ``HybridSystem``) whose right-hand side ``f(y)`` is fixed
over the step. Fixed-step methods are cut to their stability limit by the
integrator (``stability`` is the h |lambda| they allow); adaptive methods
control their own step (``adaptive = True``, method ``attempt``).
``math`` only: this runs on the FMU's hot path.
"""
from __future__ import annotations

import math
from typing import Any, Callable, ClassVar, Mapping, Protocol, Sequence

Vector = Sequence[float]
Derivative = Callable[[Vector], tuple]


from ..errors import SimulationError, StepRejected  # noqa: F401  (re-exported: the solvers raise them)


class HybridSystem(Protocol):
    """What a hybrid system offers the integrator (the consistent drive implements it)."""

    has_current: bool  # True: y holds the armature current (an electrical pole)
    error_caps: tuple[float, ...]  # per slot: the largest magnitude that scales its error (inf: none)

    def rhs(self, u: float, mode: Any) -> Derivative: ...
    def event_names(self, mode: Any) -> tuple[str, ...]: ...
    def event_values(self, y: Vector, u: float, mode: Any) -> tuple[float, ...]: ...
    def apply_event(self, y: list, u: float, mode: Any, name: str) -> None: ...
    def settle(self, y: list, u: float, mode: Any) -> None: ...
    def stuck_state(self, y: Vector, u: float, dt: float) -> list[float]: ...
    def stiffness_rate(self, y: Vector, mode: Any, electrical: bool) -> float: ...
    def profile_rate(self, y: Vector) -> float: ...
    def first_breakpoint_passed(self, start: float, end: float) -> float | None: ...


class Stepper:
    """One solver. Subclasses set ``name`` and implement ``step``."""

    name: ClassVar[str] = ""
    stability: ClassVar[float] = math.inf  # h |lambda| allowed on the negative real axis
    adaptive: ClassVar[bool] = False
    exact_electrical_pole: ClassVar[bool] = False  # the pole -R/L needs no stability cut
    # Fixed-step methods: the cam turns at most this fraction of the profile's finest angular
    # detail per internal step (an accuracy limit: a step cannot resolve a shorter feature).
    resolution: ClassVar[float] = math.inf
    # A fixed-step method without resolution sub-steps refuses (SimulationError naming h_max) a step
    # that sweeps more than this fraction of the profile's finest feature.
    max_sweep: ClassVar[float] = math.inf
    # The relative theta error its limits keep a run within (fixed-step methods; measured at 100 and
    # 400 V against the reference, docs/performance.md); an adaptive method promises ~ its rtol instead.
    promised_relative: ClassVar[float] = math.inf

    def __init__(self, settings: Mapping[str, Any]) -> None:
        self.h_max = settings["h_max"]  # s, largest internal step
        self.rtol = settings["rtol"]
        self.atol = settings["atol"]
        self.h_next = min(self.h_max, 1e-4)  # s, first trial step of an adaptive method

    def step(self, f: Derivative, y: Vector, dt: float, system: HybridSystem, u: float, mode: Any) -> list[float]:
        """y after one step dt [s] with f fixed (no error control)."""
        raise NotImplementedError
