"""The polydyne: the cam displacement that makes the train's end mass follow the law exactly at one speed.

The train's damper acts across it (between the follower and the end mass, as in ``train.py``), so for the end
mass to move as x = s(t) the follower must move as y = s + z with (model.md section 14.5)

    k_t z + d_t z' = m_e s''     (t: time),

undamped z = (m_e / k_t) s'' (in a stroke's own units y / h = S + A / W^2, W = 2 pi r); damped, z is s'' through
a first-order lag of time constant d_t / k_t, taken over the whole turn as its periodic solution (the program
repeats). (A damper from the end mass to the frame instead would give y = s + (m_e / k_t) s'' + (d_t / k_t) s'.)
y is continuous only where s'' is: a law whose acceleration jumps is refused. The follower's velocity jumps
wherever the law's jerk does (reported: the cam then needs an infinite follower acceleration there; the
4-5-6-7 polynomial has none). The correction is written as a motion table (kinematics/motion_table.py:
'angle_deg,lift_mm', the drive's shape-preserving periodic cubic) over the whole turn. ``table_residual`` drives
the train with that table's curve (the drive's interpolation) at any speed and returns the residual after the
rise.
"""

from __future__ import annotations

import math

import numpy as np

from ..kinematics.motion_law import SHAPE_COS, SHAPE_SIN, MotionLaw
from ..kinematics.motion_table import TableProgram, program_from_table_text
from .spectral import check_ratios, check_zeta
from .train import run_train

__all__ = ["StrokeProgram", "corrected", "jerk_jumps", "check_smooth", "polydyne_program", "polydyne_table",
           "table_rise", "table_residual"]


def jerk_jumps(law) -> list[tuple[float, float]]:
    """(T, jump of J) where the law's jerk jumps, the dwells at both ends (J = 0) included."""
    if isinstance(law, MotionLaw):
        # J at a segment's start and end: a quarter sine c sin(x/F) starts at c/F and ends at 0, a quarter cosine
        # starts at 0 and ends at -c/F, a constant is 0 throughout.
        ends = {}
        for seg in law.segments():
            j0 = seg.c / seg.F if seg.kind == SHAPE_SIN else 0.0
            j1 = -seg.c / seg.F if seg.kind == SHAPE_COS else 0.0
            ends.setdefault(seg.start, [0.0, 0.0])[1] = j0
            ends.setdefault(seg.end, [0.0, 0.0])[0] = j1
        scale = 1e-9 * max(law.Amp, law.Amm)
        return [(t, right - left) for t, (left, right) in sorted(ends.items()) if abs(right - left) > scale]
    out = []
    for t, j in ((0.0, law.scalar(0.0)[3]), (1.0, -law.scalar(1.0)[3])):
        if abs(j) > 1e-12:
            out.append((t, j))
    return out


def check_smooth(law, what: str) -> None:
    """ValueError when the law's acceleration jumps (the corrected cam would jump)."""
    jumps = law.jumps()
    if jumps:
        raise ValueError(f"{what} law: its acceleration jumps at T = {', '.join(f'{t:g}' for t in jumps)}, so "
                         "the corrected cam y = s + (m/k) s'' + (d/k) s' would jump there; a polydyne needs a "
                         "law whose acceleration is continuous (cycloidal, modified_sine, polynomial_345, "
                         "polynomial_4567, ...)")


def corrected(law, r: float, zeta: float, u: np.ndarray) -> np.ndarray:
    """Undamped (zeta = 0 only): y / h = S + A / W^2 at the points u of a stroke."""
    if check_zeta(zeta) != 0.0:
        raise ValueError("corrected(): the closed form is the undamped one; polydyne_table solves the damped lag")
    W = 2.0 * math.pi * float(check_ratios(r)[0])
    S, _, A, _ = law.evaluate(u)
    return S + A / (W * W)


class StrokeProgram:
    """Rise, upper dwell, return, lower dwell of laws of either family (MotionLaw or PolynomialLaw): the cam
    program's s(theta) and its derivatives, as kinematics.cam_program.CamProgram gives them for MotionLaw."""

    def __init__(self, rise_law, return_law, lift: float, rise_angle: float, upper_dwell: float,
                 return_angle: float) -> None:
        self.rise_law, self.return_law, self.lift = rise_law, return_law, float(lift)
        self.rise_angle, self.upper_dwell = float(rise_angle), float(upper_dwell)
        self.return_angle = float(return_angle)
        self._b2 = self.rise_angle + self.upper_dwell
        self._b3 = self._b2 + self.return_angle

    def evaluate(self, theta):
        th = np.mod(np.asarray(theta, dtype=float), 2.0 * math.pi)
        b1, b2, b3, h = self.rise_angle, self._b2, self._b3, self.lift
        rise, ret = th <= b1, (th > b2) & (th <= b3)
        out_r = self.rise_law.evaluate(np.where(rise, th / b1, 0.0))
        out_d = self.return_law.evaluate(np.where(ret, (th - b2) / self.return_angle, 0.0))
        upper = (th > b1) & (th <= b2)
        s = np.where(rise, h * out_r[0], np.where(upper, h, np.where(ret, h * (1 - out_d[0]), 0.0)))
        derivs = [np.where(rise, h * out_r[k] / b1 ** k, np.where(ret, -h * out_d[k] / self.return_angle ** k, 0.0))
                  for k in (1, 2, 3)]
        return (s, *derivs)

    def derivatives(self, theta: float):
        return tuple(float(q[0]) for q in self.evaluate(np.array([theta])))

    def breakpoints(self) -> tuple[float, ...]:
        def points(law):
            return law.T if isinstance(law, MotionLaw) else ()
        pts = [0.0, self.rise_angle, self._b2, self._b3]
        pts += [self.rise_angle * t for t in points(self.rise_law)]
        pts += [self._b2 + self.return_angle * t for t in points(self.return_law)]
        return tuple(sorted(p for p in set(pts) if p < 2.0 * math.pi))


def polydyne_program(program, omega: float, train_hz: float, zeta: float, step_deg: float = 0.1,
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(theta [rad], y [m]) over one turn of a CamProgram run at omega [rad/s] with a train of natural
    frequency ``train_hz`` [Hz] and damping ratio zeta: rows every ``step_deg`` and at every breakpoint."""
    check_smooth(program.rise_law, "rise")
    check_smooth(program.return_law, "return")
    if not (math.isfinite(step_deg) and 1e-3 <= step_deg <= 5.0):
        raise ValueError(f"--step-deg {step_deg!r}: allowed 0.001..5 deg")
    z = check_zeta(zeta)
    Wn = 2.0 * math.pi * train_hz
    n = int(math.ceil(360.0 / step_deg))
    theta = np.unique(np.concatenate((np.linspace(0.0, 2.0 * math.pi, n + 1)[:-1], program.breakpoints())))
    theta = theta[np.concatenate(([True], np.diff(theta) > 1e-7))]          # rows at least ~6e-6 deg apart
    theta = theta[theta < 2.0 * math.pi - 1e-7]
    s, _, s2, _ = program.evaluate(theta)
    forcing = s2 * (omega / Wn) ** 2          # (m_e / k_t) s'' with s'' = omega^2 d2s/dtheta2
    if z == 0.0:
        return theta, s + forcing
    from scipy.integrate import solve_ivp

    rate = Wn / (2.0 * z * omega)             # (k_t / d_t) per rad of cam angle

    def lag(th, q):
        return [rate * (program.derivatives(th)[2] * (omega / Wn) ** 2 - q[0])]

    def turn(q0: float) -> np.ndarray:
        grid = np.append(theta, 2.0 * math.pi)
        sol = solve_ivp(lag, (0.0, 2.0 * math.pi), [q0], method="Radau", t_eval=grid, rtol=1e-10, atol=1e-14,
                        max_step=math.radians(step_deg))
        return sol.y[0]

    first = turn(0.0)
    decay = math.exp(-rate * 2.0 * math.pi)
    periodic = turn(first[-1] / (1.0 - decay))   # z(0) = z(2 pi): the program repeats
    return theta, s + periodic[:-1]


def polydyne_table(program, omega: float, train_hz: float, zeta: float, step_deg: float = 0.1) -> str:
    """The corrected program (``polydyne_program``) as motion-table text 'angle_deg,lift_mm'."""
    theta, y = polydyne_program(program, omega, train_hz, zeta, step_deg)
    if np.any(y < -1e-12 * program.lift):
        k = int(np.argmin(y))
        raise ValueError(f"the corrected cam would go below the base circle ({y[k] * 1e3:.6g} mm at "
                         f"{math.degrees(theta[k]):.6g} deg): the design speed is too high for this train")
    lines = ["angle_deg,lift_mm"] + [f"{math.degrees(float(t))!r},{max(float(v), 0.0) * 1e3!r}"
                                     for t, v in zip(theta, y)]
    return "\n".join(lines) + "\n"


class _TableRise:
    """The table's rise as a law of u in [0, 1]: (y / h, dy/du / h, ., .) for the train's integration."""

    def __init__(self, program: TableProgram, angle: float, lift: float) -> None:
        self.program, self.angle, self.lift = program, angle, lift

    def scalar(self, u: float):
        s, ds, _, _ = self.program.derivatives(self.angle * u)
        return s / self.lift, ds * self.angle / self.lift, 0.0, 0.0

    def evaluate(self, u):
        s, ds, _, _ = self.program.evaluate(self.angle * np.asarray(u, dtype=float))
        return s / self.lift, ds * self.angle / self.lift, 0.0 * s, 0.0 * s

    def breakpoints(self):
        return (0.0, 1.0)


def table_rise(table_text: str, rise_angle: float, lift: float) -> _TableRise:
    """The rise of a motion table (over [0, rise_angle] [rad], to ``lift`` [m]) through the drive's curve."""
    return _TableRise(program_from_table_text(table_text), rise_angle, lift)


def table_residual(table_text: str | _TableRise, rise_angle: float, lift: float, r: float, zeta: float) -> float:
    """Residual / lift after the rise of a motion table (its rise over [0, rise_angle]) driving the train at the
    ratio r (the table's rise lasting r natural periods)."""
    rise = table_text if isinstance(table_text, _TableRise) else table_rise(table_text, rise_angle, lift)
    return run_train(rise, r, zeta, dwell=0.5, samples=8).residual
