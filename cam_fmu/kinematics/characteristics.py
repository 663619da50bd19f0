"""Characteristic values of a motion law: Vm, Amp, Amm, Am, Jm, Qm and where they occur.

Vm = max|V|, Am = max|A| = max(Amp, Amm), Jm = max|J|, Qm = max|A V|, each
with the T where it first occurs (the smallest such T; at a jump of A this is
the split point where the one-sided supremum is reached).  Where A jumps,
at an end or inside, J contains a Dirac impulse: Jm is None and
``jerk_unbounded`` is True, rather than a finite number from the smooth parts.

Vm, Am and Jm follow from the structure of the curve (V rises while A >= 0 and
falls after, so Vm = V(T3); Amp is reached at T1 and Amm at T5; |J| peaks at
the sine ends: Amp/F1 at 0, Amp/F3 at T3, Amm/F5 at T4, Amm/F7 at 1).  Qm is
found numerically per segment (dense sampling, then golden-section search on
the exact scalar evaluation: Qm to ~1e-15 relative, its T to ~1e-8,
since the maximum is flat).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .motion_law import SHAPE_COS, SHAPE_SIN, MotionLaw, golden_max

__all__ = ["Characteristics", "characteristics"]

@dataclass(frozen=True)
class Characteristics:
    T: tuple[float, ...]
    Amp: float
    Amm: float
    Vm: float
    Am: float
    Jm: float | None
    jerk_unbounded: bool
    Qm: float
    at: dict = field(default_factory=dict)   # {"Vm": T, "Am": T, "Jm": T or None, "Qm": T}
    jumps: tuple[float, ...] = ()            # T values where A jumps

    def to_json_dict(self) -> dict:
        """The CLI's `--json` object (exactly these keys)."""
        return {
            "T": list(self.T),
            "Amp": self.Amp,
            "Amm": self.Amm,
            "Vm": self.Vm,
            "Am": self.Am,
            "Jm": self.Jm,
            "jerk_unbounded": self.jerk_unbounded,
            "Qm": self.Qm,
            "at": dict(self.at),
        }


def _first_max(candidates: list[tuple[float, float]], rtol: float = 1e-12) -> tuple[float, float]:
    """(value, T) of the largest value; among near-ties the smallest T."""
    vmax = max(v for v, _ in candidates)
    return min(((v, t) for v, t in candidates if v >= vmax * (1.0 - rtol)), key=lambda p: p[1])


def characteristics(law: MotionLaw, samples: int = 401) -> Characteristics:
    T1, T2, T3, T4, T5, T6 = law.T
    Vm = law.scalar(T3)[1]
    Am, at_Am = _first_max([(law.Amp, T1), (law.Amm, T5)])

    jumps = law.jumps()
    if jumps:
        Jm, at_Jm = None, None
    else:
        cand = []
        for end, start, F, c, kind, _, _ in law.segments():
            if kind == SHAPE_SIN:      # |J| = |c|/F cos x: peak at the segment start
                cand.append((abs(c) / F, start))
            elif kind == SHAPE_COS:    # |J| = |c|/F sin x: peak at the segment end
                cand.append((abs(c) / F, end))
        Jm, at_Jm = _first_max(cand)

    def absq(t: float) -> float:
        _, v, a, _ = law.scalar(t)
        return abs(a * v)

    cand = []
    for end, start, _, c, kind, _, _ in law.segments():
        if c == 0.0:
            continue
        t = np.linspace(start, end, samples)
        _, V, A, _ = law.evaluate(t)
        q = np.abs(A * V)
        # Segment start belongs to the previous segment: use the right limit.
        q[0] = abs(c * (0.0 if kind == SHAPE_SIN else 1.0) * V[0])
        k = int(np.argmax(q))
        if k in (0, samples - 1):
            cand.append((float(q[k]), float(t[k])))
        else:
            x, v = golden_max(absq, float(t[k - 1]), float(t[k + 1]))
            cand.append((v, x))
    Qm, at_Qm = _first_max(cand)

    return Characteristics(
        T=law.T, Amp=law.Amp, Amm=law.Amm, Vm=Vm, Am=Am, Jm=Jm,
        jerk_unbounded=bool(jumps), Qm=Qm,
        at={"Vm": T3, "Am": at_Am, "Jm": at_Jm, "Qm": at_Qm}, jumps=jumps)
