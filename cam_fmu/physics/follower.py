"""The follower as a body of its own: closing force, jump speed, free flight, impacts (docs/model.md section 13).

Plain functions of plain floats (``math`` only), written independently of the C engine. X is the rise
direction; the cam's flank pushes the follower along +X with the normal force N >= 0 (a spring-closed
cam), and the closing force ``F_close(s) = F0 + k s - F_gx`` pulls it back along -X: the return spring
(preload F0 [N] at s = 0, rate k [N/m]) and gravity's component along the stroke (F_gx [N] > 0 pulls
along the rise, docs/model.md 4.1, so it helps the cam and counts against the spring). Guide friction
of magnitude ``f`` [N] opposes the follower's velocity v.

In contact the follower follows the cam, ``a = s'' omega^2 + s' omega_dot``, and the flank must supply

    N cos(alpha) = m a + F_close(s) + sgn(v) f          (docs/model.md 4.2 with the spring added)

Because ``N cos(alpha) - sgn(v) f(N)`` grows with N while ``mu |tan(alpha)| < 1``, N has the sign of
that right-hand side taken with the friction at N = 0, ``f0 = mu (|G_y| + |N_g|)`` (``contact_sign``):
contact holds while it is > 0 and is lost where it reaches 0 while the cam would pull.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

from ..kinematics.motion_law import golden_max

# Samples per smooth piece of the program before the golden-section refinement of the jump search.
SAMPLES = 400


def closing_force(s: float, k: float, F0: float, F_gx: float = 0.0) -> float:
    """N, the force pulling the follower at lift s [m] back onto the cam: F0 + k s - F_gx."""
    return F0 + k * s - F_gx


def required_force(m: float, s2: float, omega: float, s1: float = 0.0, omega_dot: float = 0.0) -> float:
    """N, the force along +X the follower's motion needs: m (s'' omega^2 + s' omega_dot)."""
    return m * (s2 * omega * omega + s1 * omega_dot)


def contact_sign(m: float, s: float, s1: float, s2: float, omega: float, k: float, F0: float,
                 F_gx: float = 0.0, f0: float = 0.0, omega_dot: float = 0.0) -> float:
    """N, the normal force along X the flank must give with the guide friction taken at N = 0 [N].

    Its sign is that of the contact force (module docstring): > 0 in contact, <= 0 where the cam
    would have to pull. ``f0`` [N] is the guide friction at N = 0, mu (|G_y| + |N_g|).
    """
    v = s1 * omega
    friction = f0 if v > 0.0 else (-f0 if v < 0.0 else 0.0)
    return required_force(m, s2, omega, s1, omega_dot) + closing_force(s, k, F0, F_gx) + friction


@dataclass(frozen=True)
class Jump:
    """Where and at what cam speed a spring-closed follower first leaves the cam (constant speed)."""

    omega_jump: float  # rad/s, the lowest speed at which contact is lost (0: lost at any speed; inf: never)
    theta: float  # rad, the angle where it is first lost (nan if never)
    s: float  # m, lift there
    s2: float  # m/rad2, s'' there (< 0: the follower decelerates along the rise)
    reason: str  # a sentence for the reader


def _pieces(breakpoints: Sequence[float]) -> list[tuple[float, float]]:
    """The smooth pieces of one turn [rad] between the program's breakpoints."""
    cuts = sorted({0.0, 2.0 * math.pi, *(b % (2.0 * math.pi) for b in breakpoints)})
    return [(a, b) for a, b in zip(cuts[:-1], cuts[1:]) if b - a > 1e-12]


def minimise_over_turn(fn: Callable[[float], float], breakpoints: Sequence[float],
                       samples: int = SAMPLES) -> tuple[float, float]:
    """(min value, theta) of fn over one turn: each smooth piece sampled, its best bracket refined.

    The pieces' ends are taken just inside (1e-12 rad), so a jump of s'' at a breakpoint counts from
    both sides.
    """
    best = (math.inf, math.nan)
    for a, b in _pieces(breakpoints):
        lo, hi = a + 1e-12, b - 1e-12
        xs = [lo + (hi - lo) * j / samples for j in range(samples + 1)]
        ys = [fn(x) for x in xs]
        j = min(range(len(ys)), key=ys.__getitem__)
        x, _ = golden_max(lambda theta: -fn(theta), xs[max(j - 1, 0)], xs[min(j + 1, samples)])
        for cand in (x, xs[j]):
            y = fn(cand)
            if y < best[0]:
                best = (y, cand)
    return best


def jump_speed(program, m: float, k: float, F0: float, F_gx: float = 0.0, f0: float = 0.0) -> Jump:
    """The speed [rad/s] above which a spring-closed follower leaves the cam at constant speed.

    omega_jump = min over theta with s''(theta) < 0 of sqrt(F(theta) / (m |s''(theta)|)) with
    F = F0 + k s - F_gx + f0 (the friction at N = 0 opposes the rise's velocity: it helps hold the
    follower down while it rises, against it on the return: there F = F0 + k s - F_gx - f0). Where F
    <= 0 the follower is not held even at rest: omega_jump = 0. Without a deceleration along the
    rise anywhere (or m = 0) it never leaves: inf.
    """
    def held(theta: float) -> float:  # N, the closing force at theta, friction counted as when moving forward
        s, s1, _, _ = program.derivatives(theta)
        return contact_sign(0.0, s, s1, 0.0, 1.0, k, F0, F_gx, f0)

    weakest, theta_w = minimise_over_turn(held, program.breakpoints())
    scale = abs(F0) + abs(F_gx) + f0 + k * abs(minimise_over_turn(lambda x: -program.derivatives(x)[0],
                                                                  program.breakpoints())[0])
    if weakest < -1e-12 * scale:  # below the rounding of F0 + k s at a stroke's end
        s, _, s2, _ = program.derivatives(theta_w)
        return Jump(0.0, theta_w, s, s2, f"the closing force F0 + k s - F_gx (with friction) is {weakest:.6g} N < 0 "
                                         f"at theta = {theta_w:.6g} rad: the follower is not held even at rest")
    if m == 0.0:
        return Jump(math.inf, math.nan, math.nan, math.nan, "a massless follower needs no force: it never jumps")

    def ratio(theta: float) -> float:  # (rad/s)^2, the squared speed at which N reaches 0 at theta
        s, s1, s2, _ = program.derivatives(theta)
        if s2 >= 0.0:
            return math.inf
        return held(theta) / (m * -s2)

    value, theta = minimise_over_turn(ratio, program.breakpoints())
    if not math.isfinite(value):
        return Jump(math.inf, math.nan, math.nan, math.nan, "s'' >= 0 everywhere: the cam never has to pull")
    s, _, s2, _ = program.derivatives(theta)
    return Jump(math.sqrt(value), theta, s, s2, "contact is first lost where the spring's force, "
                                               "F0 + k s - F_gx, equals the inertial force m |s''| omega^2")


def contact_margin(program, omega: float, m: float, k: float, F0: float, F_gx: float = 0.0,
                   f0: float = 0.0) -> tuple[float, float]:
    """(least contact force along X [N], theta [rad]) over a turn at the constant speed omega [rad/s].

    Negative: the follower leaves the cam at that speed.
    """
    def force(theta: float) -> float:
        s, s1, s2, _ = program.derivatives(theta)
        return contact_sign(m, s, s1, s2, omega, k, F0, F_gx, f0)

    return minimise_over_turn(force, program.breakpoints())


def preload_for(program, omega: float, safety: float, m: float, k: float, F_gx: float = 0.0,
                f0: float = 0.0) -> tuple[float, float]:
    """(least preload F0 [N], theta [rad] that sets it) holding the follower at omega [rad/s] with the
    force safety factor ``safety`` (>= 1) at the spring rate k [N/m].

    Holding with a safety factor S means F0 + k s - F_gx + f0 >= S m |s''| omega^2 wherever s'' < 0
    and F0 + k s - F_gx + f0 > 0 everywhere: then omega_jump >= sqrt(S) omega.
    """
    def need(theta: float) -> float:  # N, the preload this angle asks for (negated: the largest wins)
        s, s1, s2, _ = program.derivatives(theta)
        inertial = safety * m * max(-s2, 0.0) * omega * omega
        return -(inertial - contact_sign(0.0, s, s1, 0.0, 1.0, k, 0.0, F_gx, f0))

    value, theta = minimise_over_turn(need, program.breakpoints())
    return -value, theta


def rate_for(program, omega: float, safety: float, m: float, F0: float, F_gx: float = 0.0,
             f0: float = 0.0) -> tuple[float, float]:
    """(least spring rate k [N/m], theta [rad] that sets it) holding the follower at omega [rad/s] with
    the force safety factor ``safety`` at the preload F0 [N] (see ``preload_for``).

    inf where no rate can: an angle at lift s <= 0 asks for more force than F0 gives.
    """
    def need(theta: float) -> float:  # N/m, the rate this angle asks for (negated)
        s, s1, s2, _ = program.derivatives(theta)
        short = safety * m * max(-s2, 0.0) * omega * omega - contact_sign(0.0, s, s1, 0.0, 1.0, 0.0, F0, F_gx, f0)
        if short <= 0.0:
            return 0.0
        return -short / s if s > 0.0 else -math.inf

    value, theta = minimise_over_turn(need, program.breakpoints())
    return -value, theta


# ----------------------------------------------------------------------------- free flight
@dataclass(frozen=True)
class Flight:
    """The follower's own motion off the cam: m s_dd = -(F0 + k s) + F_gx - sgn(v) f (SI units)."""

    m: float  # kg
    k: float  # N/m
    F0: float  # N
    F_gx: float = 0.0  # N, gravity along X
    f: float = 0.0  # N, guide friction magnitude while flying (mu (|G_y| + |N_g|))

    def _piece(self, t: float, s0: float, v0: float, sigma: float) -> tuple[float, float, float]:
        """(s, v, a) at t [s] from (s0, v0) with the friction's direction -sigma held."""
        force = -self.F0 + self.F_gx - sigma * self.f  # N, the constant part
        if self.k > 0.0:
            wn = math.sqrt(self.k / self.m)
            s_eq = force / self.k
            c, sn = math.cos(wn * t), math.sin(wn * t)
            s = s_eq + (s0 - s_eq) * c + v0 / wn * sn
            v = -(s0 - s_eq) * wn * sn + v0 * c
            return s, v, -wn * wn * (s - s_eq)
        b = force / self.m
        return s0 + v0 * t + 0.5 * b * t * t, v0 + b * t, b

    def _stop_time(self, s0: float, v0: float, sigma: float) -> float:
        """s: when v first reaches 0 on the piece with friction direction sigma (inf if never)."""
        force = -self.F0 + self.F_gx - sigma * self.f
        if self.k > 0.0:
            wn = math.sqrt(self.k / self.m)
            d = s0 - force / self.k
            # v = -d wn sin(wn t) + v0 cos(wn t) = 0  ->  tan(wn t) = v0 / (d wn)
            phase = math.atan2(v0, d * wn)
            if phase <= 0.0:
                phase += math.pi
            return phase / wn
        b = force / self.m
        t = -v0 / b if b != 0.0 else math.inf
        return t if t > 0.0 else math.inf

    def state(self, t: float, s0: float, v0: float) -> tuple[float, float, float]:
        """(s [m], v [m/s], a [m/s2]) t [s] after leaving (s0, v0), friction's direction followed exactly.

        At a halt (v = 0) the follower stays if the net force is within the friction f (static
        friction), else restarts the way the net force pushes it.
        """
        s, v, elapsed = s0, v0, 0.0
        for _ in range(10000):
            sigma = 1.0 if v > 0.0 else -1.0 if v < 0.0 else 0.0
            if sigma == 0.0:
                net = -self.F0 - self.k * s + self.F_gx
                if abs(net) <= self.f:
                    return s, 0.0, 0.0
                sigma = 1.0 if net > 0.0 else -1.0
            stop = self._stop_time(s, v, sigma)
            if t - elapsed <= stop:
                return self._piece(t - elapsed, s, v, sigma)
            s, _, _ = self._piece(stop, s, v, sigma)
            v, elapsed = 0.0, elapsed + stop
        raise RuntimeError("free flight: more than 10000 halts")

    def energy(self, s: float, v: float) -> float:
        """J, the follower's kinetic energy plus the spring's and gravity's potential (0 at s = 0)."""
        return 0.5 * self.m * v * v + self.F0 * s + 0.5 * self.k * s * s - self.F_gx * s


# ----------------------------------------------------------------------------- impacts
@dataclass(frozen=True)
class Impact:
    """Velocities after an impact of the follower on the cam's flank, and what it cost."""

    omega: float  # rad/s, the cam's speed after
    v: float  # m/s, the follower's velocity after
    impulse: float  # N s, the flank's impulse on the follower along X
    loss: float  # J, kinetic energy lost: (1 - e^2) (1/2) m_eff w^2


def impact(J_0: float, m: float, s1: float, omega: float, v: float, e: float) -> Impact:
    """The impact of the follower (mass m [kg], velocity v [m/s]) on the flank of the cam turning at omega
    [rad/s] with the inertia J_0 [kg m2] (what turns with the cam), restitution e in [0, 1].

    The contact moves the follower along X at s' omega; the relative normal velocity w = v - s' omega
    becomes -e w. The impulse P on the follower (-s' P on the cam) conserves the generalised momentum
    J_0 omega + m s' v for every e, and the kinetic energy lost is (1 - e^2) (1/2) m_eff w^2 with
    m_eff = m J_0 / (J_0 + m s'^2). J_0 = inf is a cam at imposed speed (m_eff = m). e = 0 with v = 0
    is docs/model.md 6.2's plastic impact, omega+ = J_0 omega / (J_0 + m s'^2).
    """
    w = v - s1 * omega
    if math.isinf(J_0):
        m_eff = m
    else:
        m_eff = m * J_0 / (J_0 + m * s1 * s1)
    impulse = -(1.0 + e) * m_eff * w
    omega_after = omega if math.isinf(J_0) else omega - s1 * impulse / J_0
    return Impact(omega_after, v + impulse / m, impulse, 0.5 * (1.0 - e * e) * m_eff * w * w)


# ----------------------------------------------------------------------------- between the flanks
# A rebound that would rise less than this above the flank [m] ends the bouncing: the follower stays on the flank
# (a plastic impact). The bounces' heights fall as e^2n, so a sequence with e < 1 ends after finitely many (Zeno
# guard); 1 nm lies far above the reference's resolution of positions (atol 1e-13) and far below any clearance.
ZENO_HEIGHT = 1e-9


class FlankFollower:
    """The follower of its own on a cam's flanks (closures 'form' and 'spring'): what the speed drive's
    (speed_follower.py) and the voltage drive's (voltage_follower.py) share. A flank is named by its sign: +1 pushes
    along +X (a spring-closed cam's only flank; a groove's lower flank, at s = s_cam - c), -1 a groove's upper flank
    (s = s_cam + c)."""

    def __init__(self, model) -> None:
        self.model, self.program = model, model.program
        self.two_sided = model.closure == "form"
        self.c = model.c if self.two_sided else 0.0
        self.m, self.e = model.m, model.restitution
        self.k, self.F0, self.F_gx = model.k_spring, model.F_spring0, model.F_gx  # no spring unless 'spring'
        self.mu, self.G_y, self.N_g = model.mu, model.G_y, model.N_g
        self.f0 = self.mu * (abs(self.G_y) + self.N_g)  # N, the guide's friction at no contact force (in flight)

    def flank(self, theta: float, contact: float) -> tuple[float, float, float, float]:
        """(s [m], s' [m/rad], s'' [m/rad2], s_cam [m]) of the follower on the flank ``contact`` at theta [rad]."""
        s_cam, s1, s2, _ = self.program.derivatives(theta)
        return s_cam - contact * self.c, s1, s2, s_cam

    # m, the rebound's height below which an impact is plastic (the Zeno guard), in the follower's coordinate
    zeno = ZENO_HEIGHT

    def closing(self, s: float) -> float:
        """N, the force pulling the follower at s [m] back toward the +1 flank: F_close(s) = F0 + k s - F_gx."""
        return closing_force(s, self.k, self.F0, self.F_gx)

    def flank_closing(self, s: float, v: float) -> float:
        """N, what closes the follower at s [m], moving at v [m/s], onto its +1 flank: F_close(s) (a train adds its
        force, physics/train_follower.py)."""
        return self.closing(s)

    def gaps(self, theta: float, s: float) -> tuple[float, float]:
        """(gap to the +1 flank, gap to the -1 flank) [m], both >= 0 in flight (inf: no such flank)."""
        s_cam = self.program.derivatives(theta)[0]
        return s - (s_cam - self.c), ((s_cam + self.c) - s) if self.two_sided else math.inf

    def free_acceleration(self, s: float, sigma: float) -> float:
        """m/s2, the flying follower's acceleration (-F_close(s) - sigma f0) / m with the friction's direction
        -sigma = -sgn(v); sigma = 0 at a halt, where the guide's static friction holds the follower while the net
        force is within f0 (then 0), else it starts the way that force pushes."""
        net = -self.closing(s)
        if sigma == 0.0:
            if abs(net) <= self.f0:
                return 0.0
            sigma = 1.0 if net > 0.0 else -1.0
        return (net - sigma * self.f0) / self.m

    def direction(self, s: float, v: float) -> float:
        """The sign of the flying follower's velocity v [m/s] at s [m] over the next piece: sgn(v), or at a halt the
        way the net force pushes it beyond the guide's static friction (0: held)."""
        if v != 0.0:
            return 1.0 if v > 0.0 else -1.0
        net = -self.closing(s)
        return (1.0 if net > 0.0 else -1.0) if abs(net) > self.f0 else 0.0

    def rebounds(self, w: float, scale: float) -> bool:
        """Does the relative speed w [m/s] off a flank rise ``zeno`` (ZENO_HEIGHT) or more at the acceleration
        ``scale`` [m/s2] (w^2 >= 2 A ZENO_HEIGHT)? Below it an impact is plastic (the Zeno guard)."""
        return w * w >= 2.0 * scale * self.zeno
