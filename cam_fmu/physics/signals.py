"""Input signals of a scene and of the reference: constant, step, ramp, table (value in V or rad/s, time in s)."""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence


# Relative distance [1] within which a time stamp counts as the time asked (left_value, left_slope): the rounding of
# a grid time k h (a few ulps), far below any input's own time scale.
LEFT_TOLERANCE = 1e-12


@dataclass(frozen=True)
class Signal:
    """Piecewise-linear signal through (times, values); ``hold`` makes it a staircase.

    A repeated time stamp is a jump: before it the first value, from it on the
    second (right-continuous), as fmpy reads input tables.
    """

    times: tuple[float, ...]
    values: tuple[float, ...]
    hold: bool = False
    breaks: tuple[float, ...] = field(init=False)

    def __post_init__(self) -> None:
        if len(self.times) != len(self.values) or not self.times:
            raise ValueError("signal: 'times' and 'values' must have the same, non-zero length")
        if any(b < a for a, b in zip(self.times, self.times[1:])):
            raise ValueError(f"signal: 'times' must not decrease, got {list(self.times)}")
        if not all(math.isfinite(x) for x in self.times + self.values):
            raise ValueError("signal: 'times' and 'values' must be finite numbers")
        object.__setattr__(self, "breaks", tuple(sorted(set(self.times))))

    def value(self, t: float) -> float:
        times, values = self.times, self.values
        k = bisect.bisect_right(times, t)
        if k == 0:
            return values[0]
        if k == len(times) or self.hold:
            return values[k - 1]
        t0, t1 = times[k - 1], times[k]
        return values[k - 1] + (values[k] - values[k - 1]) * (t - t0) / (t1 - t0)

    def left_value(self, t: float) -> float:
        """The limit from the left at t: the value held up to t (at a jump the value before it; at a kink, or
        anywhere the signal is continuous, ``value(t)``; at or before the first time stamp the first value). A time
        stamp within LEFT_TOLERANCE of t counts as t (a grid time 3 * 0.1 s is 0.30000000000000004 s, and a
        co-simulation master steps to it with the input before the stamp 0.3 s). The outputs at an input's
        discontinuity are this side's (docs/model.md 8.1)."""
        times, values = self.times, self.values
        tol = LEFT_TOLERANCE * max(1.0, abs(t))
        k = bisect.bisect_left(times, t - tol)
        if k == 0:
            return values[0]
        if self.hold:
            return values[k - 1]
        if k == len(times):
            return values[-1]
        if times[k] <= t + tol:   # a knot at t: its first value (a repeated stamp's is the one before the jump)
            return values[k]
        t0, t1 = times[k - 1], times[k]
        return values[k - 1] + (values[k] - values[k - 1]) * (t - t0) / (t1 - t0)

    def left_slope(self, t: float) -> float:
        """d(value)/dt on the piece that ends at t or runs through it (the limit from the left, stamps within
        LEFT_TOLERANCE of t counting as t; at or before the first stamp ``slope(t)``; 0 for a staircase)."""
        times, values = self.times, self.values
        k = bisect.bisect_left(times, t - LEFT_TOLERANCE * max(1.0, abs(t)))
        if k == 0:
            return self.slope(t)
        if self.hold or k == len(times):
            return 0.0
        return (values[k] - values[k - 1]) / (times[k] - times[k - 1])

    def slope(self, t: float) -> float:
        """d(value)/dt on the piece that starts at or before t (0 for a staircase)."""
        times, values = self.times, self.values
        k = bisect.bisect_right(times, t)
        if self.hold or k == 0 or k == len(times):
            return 0.0
        return (values[k] - values[k - 1]) / (times[k] - times[k - 1])

    def slope_signal(self) -> "Signal":
        """The slope as a staircase signal (for the FMU's omega_dot_ref input)."""
        return Signal(self.breaks, tuple(self.slope(t) for t in self.breaks), hold=True)

    def sampled(self, step: float, stop: float) -> "Signal":
        """The zero-order hold a co-simulation master applies at communication points."""
        n = int(round(stop / step))
        times = tuple(k * step for k in range(n + 1))
        return Signal(times, tuple(self.value(t) for t in times), hold=True)


def constant(value: float) -> Signal:
    return Signal((0.0,), (float(value),))


def _step(spec: Mapping[str, Any]) -> Signal:
    t, a, b = float(spec["time"]), float(spec["before"]), float(spec["after"])
    return Signal((0.0, t, t), (a, a, b)) if t > 0.0 else constant(b)


def _ramp(spec: Mapping[str, Any]) -> Signal:
    t0, t1 = float(spec["start"]), float(spec["stop"])
    a, b = float(spec["from"]), float(spec["to"])
    if not t1 > t0 >= 0.0:
        raise ValueError(f"ramp: need 0 <= start < stop, got start = {t0}, stop = {t1}")
    return Signal((0.0, t0, t1), (a, a, b))


def _table(spec: Mapping[str, Any]) -> Signal:
    return Signal(tuple(map(float, spec["time"])), tuple(map(float, spec["value"])), bool(spec.get("hold", False)))


# The one table of signal kinds: the keys each takes (after 'type') and its builder.
SIGNAL_KINDS: dict[str, tuple[tuple[str, ...], Callable[[Mapping[str, Any]], Signal]]] = {
    "constant": (("value",), lambda spec: constant(spec["value"])),
    "step": (("time", "before", "after"), _step),
    "ramp": (("start", "stop", "from", "to"), _ramp),
    "table": (("time", "value", "hold"), _table),
}
OPTIONAL_KEYS = ("hold",)
SIGNAL_KEYS: dict[str, tuple[str, ...]] = {kind: ("type",) + keys for kind, (keys, _b) in SIGNAL_KINDS.items()}


def from_spec(spec: Mapping[str, Any] | float) -> Signal:
    """Signal from a scene entry: a number, or a table with 'type'.

    {type = "constant", value = 3.5}; {type = "step", time = 0.5, before = 0, after = 3.5};
    {type = "ramp", start = 0, stop = 1, from = 0, to = 3.5};
    {type = "table", time = [...], value = [...], hold = false}
    """
    if isinstance(spec, (int, float)):
        return constant(spec)
    kind = spec.get("type", "constant")
    if kind not in SIGNAL_KINDS:
        raise ValueError(f"signal type {kind!r}: allowed {', '.join(map(repr, SIGNAL_KINDS))}")
    return SIGNAL_KINDS[kind][1](spec)


def as_table(signal: Signal, stop: float) -> tuple[Sequence[float], Sequence[float]]:
    """Time and value columns for fmpy's input array (jumps as repeated times)."""
    times = [t for t in signal.times if t <= stop]
    values = list(signal.values[: len(times)])
    if signal.hold:  # make each hold explicit as a jump for fmpy's linear interpolation
        t2, v2 = [], []
        for k, (t, v) in enumerate(zip(times, values)):
            if k:
                t2.append(t)
                v2.append(values[k - 1])
            t2.append(t)
            v2.append(v)
        times, values = t2, v2
    if not times or times[-1] < stop:
        times.append(stop)
        values.append(signal.value(stop))
    return times, values
