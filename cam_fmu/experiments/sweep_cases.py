"""A sweep's cases: the --vary parameters and the Design that gives case k's values from k alone.

- a full grid: the cartesian product of the varied values (``--vary m=0.2:0.6:5`` = 5 values from 0.2
  to 0.6; ``--vary rise_law=paper,cycloidal`` = a list), the first --vary changing slowest;
- a sample (``--sample lhs:N | sobol:N | random:N``, scipy.stats.qmc, reproducible with ``--seed``) over
  ranges (``--vary m=0.2:0.8`` = LOW:HIGH) and lists (categorical: each value equally likely);
- a Saltelli design (``--sensitivity N``, SALib) over ranges, for the Sobol indices (sensitivity.py).

No case list is built, whatever the count: a grid's case k is its mixed-radix digits, a Sobol sample is
fast-forwarded to k, random values come from the generator of k's block of RANDOM_BLOCK cases (seeded by
(seed, block)); a Latin hypercube and a Saltelli design hold their N x d unit array (8 bytes a number).
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from ..physics import parameters as _parameters
from ..physics.units import UnitError, to_si
from .limits import MAX_CASES

SAMPLERS = ("lhs", "sobol", "random")
RANDOM_BLOCK = 4096  # random sampling draws case k's values from the generator of block k // RANDOM_BLOCK
CHECK_ALL_UP_TO = 100_000  # sweeps up to this many cases are checked case by case before any runs


class SweepError(ValueError):
    """Bad sweep specification; the message names the option and the allowed values."""


@dataclass(frozen=True)
class Vary:
    """One --vary: ``values`` (a grid's N values or a list) or a range ``low``..``high`` (values empty)."""

    name: str
    values: tuple[Any, ...] = ()
    low: float | None = None
    high: float | None = None
    kind: str = "grid"  # grid (START:STOP:N), list (a,b,c), range (LOW:HIGH)
    text: str = ""

    @property
    def numeric(self) -> bool:
        return self.kind == "range" or all(isinstance(v, float) for v in self.values)


def parse_vary(text: str) -> Vary:
    """'NAME=START:STOP:N' (N values, linear, both ends included), 'NAME=LOW:HIGH' (a range, for --sample and
    --sensitivity) or 'NAME=a,b,c' (a list)."""
    name, sep, spec = text.partition("=")
    name = name.strip()
    if not sep or not name or not spec.strip():
        raise SweepError(f"--vary {text!r}: expected NAME=START:STOP:N, NAME=LOW:HIGH or NAME=a,b,c")
    if name not in _parameters.BY_NAME:
        raise SweepError(f"--vary {text!r}: unknown parameter {name!r}; known: {', '.join(_parameters.BY_NAME)}")
    pspec = _parameters.BY_NAME[name]
    try:
        if ":" in spec:
            parts = spec.split(":")
            if len(parts) == 2:
                try:
                    low, high = _number(pspec, parts[0]), _number(pspec, parts[1])
                except _parameters.ParameterError:
                    raise
                except ValueError:
                    raise SweepError(f"--vary {text!r}: expected NAME=LOW:HIGH with numbers LOW < HIGH") from None
                if not low < high:
                    raise SweepError(f"--vary {text!r}: range LOW = {low:g} is not below HIGH = {high:g}: "
                                     "allowed LOW < HIGH")
                pspec.check(low), pspec.check(high)
                return Vary(name, low=low, high=high, kind="range", text=text)
            try:
                start, stop, n = _number(pspec, parts[0]), _number(pspec, parts[1]), int(parts[2])
                if len(parts) != 3:
                    raise ValueError
            except _parameters.ParameterError:
                raise
            except (ValueError, IndexError):
                raise SweepError(f"--vary {text!r}: expected NAME=START:STOP:N with numbers START, STOP "
                                 "and an integer N >= 1, or NAME=LOW:HIGH") from None
            if n < 1 or (n == 1 and start != stop) or n > MAX_CASES:
                raise SweepError(f"--vary {text!r}: N = {n}: allowed 2 <= N <= {MAX_CASES} "
                                 f"(or N = 1 with START = STOP)")
            values = tuple(pspec.check(float(v)) for v in np.linspace(start, stop, n))
            return Vary(name, values, kind="grid", text=text)
        return Vary(name, tuple(pspec.check(v.strip()) for v in spec.split(",")), kind="list", text=text)
    except _parameters.ParameterError as exc:
        raise SweepError(f"--vary {text!r}: {exc}") from None


def _number(pspec: _parameters.ParameterSpec, text: str) -> float:
    """A --vary bound in the parameter's SI unit: a number, or a number with a unit of its quantity ('0.5mm');
    ValueError where it is no number, ParameterError naming the parameter's unit where the unit does not fit."""
    try:
        return to_si(pspec.name, pspec.unit, text)
    except UnitError as exc:
        raise _parameters.ParameterError(f"parameter {pspec.name!r} = {text.strip()!r}: {exc}") from None


def parse_sample(text: str) -> tuple[str, int]:
    """'lhs:N', 'sobol:N' or 'random:N' -> (kind, N), N >= 1."""
    kind, _, count = text.partition(":")
    if kind not in SAMPLERS:
        raise SweepError(f"--sample {text!r}: expected KIND:N with KIND one of {', '.join(SAMPLERS)}")
    try:
        n = int(count)
    except ValueError:
        raise SweepError(f"--sample {text!r}: N = {count!r} is not an integer: allowed 1 <= N <= {MAX_CASES}") from None
    if not 1 <= n <= MAX_CASES:
        raise SweepError(f"--sample {text!r}: N = {n}: allowed 1 <= N <= {MAX_CASES}")
    return kind, n


# ------------------------------------------------------------------ designs
@dataclass
class Design:
    """The cases of a sweep, by index: ``values(start, stop)`` = {name: list of values of cases start..stop-1}.

    ``sample``: None (the full grid), (kind, N) or ("saltelli", N) (--sensitivity: N (d + 2) cases)."""

    varies: tuple[Vary, ...]
    sample: tuple[str, int] | None = None
    seed: int = 0
    _unit: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        names = [v.name for v in self.varies]
        if len(set(names)) != len(names):
            raise SweepError(f"--vary names a parameter twice: {', '.join(names)}")
        if not self.varies:
            raise SweepError("--vary: at least one parameter to vary")
        if self.sample is None:
            ranges = [v.text for v in self.varies if v.kind == "range"]
            if ranges:
                raise SweepError(f"--vary {ranges[0]!r}: a range LOW:HIGH needs --sample or --sensitivity "
                                 "(a grid is NAME=START:STOP:N)")
            return
        kind, n = self.sample
        grids = [v.text for v in self.varies if v.kind == "grid"]
        option = "--sensitivity" if kind == "saltelli" else "--sample"
        if grids:
            raise SweepError(f"--vary {grids[0]!r}: {option} samples ranges NAME=LOW:HIGH (or lists), not a grid")
        if kind == "saltelli":
            lists = [v.text for v in self.varies if v.kind != "range"]
            if lists:
                raise SweepError(f"--sensitivity with --vary {lists[0]!r}: Sobol indices need ranges NAME=LOW:HIGH, "
                                 "not a list of values")
            if not 1 <= n or n * (len(self.varies) + 2) > MAX_CASES:
                raise SweepError(f"--sensitivity {n}: N (d + 2) = {n * (len(self.varies) + 2)} cases; allowed "
                                 f"1 <= N and at most {MAX_CASES} cases")

    @property
    def names(self) -> list[str]:
        return [v.name for v in self.varies]

    def __len__(self) -> int:
        if self.sample is None:
            n = math.prod(len(v.values) for v in self.varies)
            if n > MAX_CASES:
                raise SweepError(f"--vary: {' x '.join(str(len(v.values)) for v in self.varies)} = {n} cases; "
                                 f"at most {MAX_CASES} in one sweep")
            return n
        kind, n = self.sample
        return n * (len(self.varies) + 2) if kind == "saltelli" else n

    def problem(self) -> dict:
        """SALib's problem: the ranges (--sensitivity)."""
        return {"num_vars": len(self.varies), "names": self.names,
                "bounds": [[v.low, v.high] for v in self.varies]}

    def _units(self, start: int, stop: int) -> np.ndarray:
        """(stop - start, d) points of the unit cube (a sampled design)."""
        kind, n = self.sample  # type: ignore[misc]
        d = len(self.varies)
        if kind == "sobol":
            import warnings

            from scipy.stats import qmc  # scipy.stats takes a second or two to import: only where needed

            engine = qmc.Sobol(d, scramble=True, seed=self.seed)
            if start:
                engine.fast_forward(start)
            with warnings.catch_warnings():  # a batch's count is rarely a power of 2; the design's N should be
                warnings.simplefilter("ignore")
                return engine.random(stop - start)
        if kind == "random":
            blocks = range(start // RANDOM_BLOCK, (stop - 1) // RANDOM_BLOCK + 1)
            block = np.concatenate([np.random.default_rng([self.seed, b]).random((RANDOM_BLOCK, d)) for b in blocks])
            first = blocks[0] * RANDOM_BLOCK
            return block[start - first:stop - first]
        if self._unit is None:
            if kind == "lhs":
                from scipy.stats import qmc

                self._unit = qmc.LatinHypercube(d, seed=self.seed).random(n)
            else:  # saltelli: SALib's design in the real ranges; here mapped back to the unit cube
                import warnings

                from SALib.sample import sobol as salib_sobol

                with warnings.catch_warnings():  # N not a power of 2: SALib warns on stderr
                    warnings.simplefilter("ignore")
                    real = salib_sobol.sample(self.problem(), n, calc_second_order=False, seed=self.seed)
                lows = np.array([v.low for v in self.varies])
                self._unit = (real - lows) / np.array([v.high - v.low for v in self.varies])
                self._real = real
        return self._unit[start:stop]

    def values(self, start: int, stop: int) -> dict[str, list]:
        """The varied values of cases start..stop-1 (lists, by name)."""
        if self.sample is None:
            counts = [len(v.values) for v in self.varies]
            k = np.arange(start, stop)
            out = {}
            for j in range(len(self.varies) - 1, -1, -1):  # the last --vary changes fastest
                k, index = np.divmod(k, counts[j])
                values = self.varies[j].values
                out[self.varies[j].name] = [values[i] for i in index]
            return {name: out[name] for name in self.names}
        units = self._units(start, stop)
        out = {}
        for j, v in enumerate(self.varies):
            if v.kind == "range":
                if self.sample[0] == "saltelli":  # SALib's own numbers, not a round trip through the unit cube
                    out[v.name] = [float(x) for x in self._real[start:stop, j]]
                else:
                    out[v.name] = [float(x) for x in v.low + units[:, j] * (v.high - v.low)]
            else:
                count = len(v.values)
                out[v.name] = [v.values[min(int(x * count), count - 1)] for x in units[:, j]]
        return out

    def representative(self) -> Iterable[dict[str, Any]]:
        """Cases checked before a large sweep runs: every combination of each parameter's extremes (LOW and
        HIGH, a grid's ends, every value of a list), at most CHECK_ALL_UP_TO of them."""
        ends = []
        for v in self.varies:
            if v.kind == "range":
                ends.append((v.low, v.high))
            elif v.kind == "grid":
                ends.append(tuple(dict.fromkeys((v.values[0], v.values[-1]))))
            else:
                ends.append(v.values)
        names = self.names
        return ({n: x for n, x in zip(names, combo)} for combo in itertools.islice(itertools.product(*ends),
                                                                                    CHECK_ALL_UP_TO))

    def spec(self) -> dict:
        """JSON: what makes these cases (compared on --resume)."""
        return {"vary": [v.text for v in self.varies], "sample": list(self.sample) if self.sample else None,
                "seed": self.seed if self.sample else None}


def cases(varies: Sequence[Vary]) -> list[dict[str, Any]]:
    """The cartesian product of the varied values, in a fixed order (the first --vary changes slowest): a list
    (small grids: tests, plots)."""
    design = Design(tuple(varies))
    values = design.values(0, len(design))
    return [dict(zip(values, combo)) for combo in zip(*values.values())]


def check_cases(scene: Any, todo: Iterable[Mapping[str, Any]]) -> None:
    """SweepError for the first case `simulate` would refuse as a scene: a parameter out of range or
    inconsistent with the others, a drive without its input signal (``--vary drive=speed`` on a voltage
    scene). ``scene``: the experiments.scenes.Scene swept."""
    from .scenes import SceneError, check_drive_inputs

    for case in todo:
        label = ", ".join(f"{k}={v}" for k, v in case.items())
        try:
            params = _parameters.resolve({**scene.primary.overrides, **case})
            check_drive_inputs(params["drive"], scene.u, scene.omega_ref, f"{scene.name}, case {label}")
        except (_parameters.ParameterError, SceneError) as exc:
            raise SweepError(f"--vary: {exc}") from None


def check_design(scene: Any, design: Design) -> None:
    """check_cases on every case (up to CHECK_ALL_UP_TO cases, in chunks), else on design.representative()."""
    n = len(design)
    if n > CHECK_ALL_UP_TO:
        check_cases(scene, design.representative())
        return
    for start in range(0, n, 10_000):
        values = design.values(start, min(n, start + 10_000))
        check_cases(scene, (dict(zip(values, combo)) for combo in zip(*values.values())))
