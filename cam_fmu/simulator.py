"""The drive stepped from one communication point to the next (the FMU's engine).

``DriveSimulator`` owns the model, the solver and every piece of internal state;
the FMU class only maps FMI variables onto it. numpy is not imported here: the
FMU's run-time path is ``math`` only (FMI_NOTES: scipy in an FMU crashes ecos).

Solvers (consistent formulation, voltage drive):
- ``euler``, ``rk4``: fixed internal step min(h_max, stability limit): a step
  beyond the explicit method's stability limit is split, never taken.
- ``rk45``: Dormand-Prince 5(4) with error control (rtol, atol); its step size
  is carried across communication steps; failing to meet the tolerance within
  ``max_steps`` or above the smallest step raises SimulationError.
- ``etdrk4``: exponential RK4, exact on the electrical pole -R/L: stable and
  accurate with L > 0 at steps far above L/R.
Every solver stops at the hybrid events (stick, backlash contact) by re-stepping
to the located zero, and applies the transition there; every step also ends at
the profile breakpoint it would cross (segment ends: the third derivative of s jumps).

The paper formulation runs its own fixed-step algorithm (paper_scheme.py) with
T = the largest step <= h_max that divides the communication step.
"""
from __future__ import annotations

import math
from typing import Any, Mapping

from .drive_model import DriveModel
from .hybrid import HybridDrive, Mode, crossed, follower_along, speed_drive_outputs, speed_engaged
from .integrators import MotorEtdCoefficients, dopri_step, etdrk4_motor_step, euler_step, rk4_step
from .paper_scheme import PaperScheme

INPUTS: tuple[tuple[str, str, float, str], ...] = (
    ("u", "V", 3.5, "armature voltage (voltage drive)"),
    ("omega_ref", "rad/s", 1.0, "imposed cam speed at the start of the step (speed drive)"),
    ("omega_dot_ref", "rad/s2", 0.0, "imposed angular acceleration over the step (speed drive: a ramp of omega is then exact)"),
)
OUTPUTS: tuple[tuple[str, str, str], ...] = (
    ("omega", "rad/s", "cam angular velocity"),
    ("theta", "rad", "cam angle (unbounded; the profile uses theta mod 2 pi)"),
    ("s", "m", "follower position (after backlash)"),
    ("i", "A", "armature current"),
    ("M", "N.m", "total load torque on the shaft: M_f sgn(omega) + M_l"),
    ("J", "kg.m2", "equivalent inertia J_m + m (ds/dtheta)^2 (J_m while free in the gap)"),
    ("v", "m/s", "follower velocity"),
    ("a", "m/s2", "follower acceleration"),
    ("alpha", "rad", "pressure angle"),
    ("s_cam", "m", "cam profile lift at the contact (before backlash)"),
    ("voltage", "V", "armature voltage: u (voltage drive) or the voltage needed (speed drive)"),
)

_STABILITY = {"euler": 1.0, "rk4": 2.5, "etdrk4": 2.5}  # h * |lambda| allowed
_EVENT_ITERATIONS = 60
_TWO_PI = 2.0 * math.pi


class SimulationError(RuntimeError):
    """The simulation cannot go on correctly; the message names the setting."""


class DriveSimulator:
    """One cam drive, advanced by ``do_step`` (times in s, SI units throughout)."""

    def __init__(self, params: Mapping[str, Any] | None = None) -> None:
        self.model = model = DriveModel(params)
        p = model.params
        self.solver = p["solver"]
        self.h_max = p["h_max"]
        self.rtol = p["rtol"]
        self.atol = p["atol"]
        self.max_steps = int(p["max_steps"])
        self.time = 0.0
        self.u = INPUTS[0][2]
        self.omega_ref = INPUTS[1][2]
        self.omega_dot_ref = INPUTS[2][2]
        self.h_next = min(self.h_max, 1e-4)  # rk45's first trial step [s]
        self.steps_taken = 0  # internal steps, for benchmarks
        self._etd: MotorEtdCoefficients | None = None
        self._outputs: dict[str, float] | None = None
        self._breakpoints = model.program.breakpoints()  # rad, in [0, 2 pi)
        self._fsal: tuple[tuple, float] | None = None  # (f(y), u) of rk45's last stage
        theta0, omega0, i0 = p["theta0"], p["omega0"], p["i0"]
        self.kind = "speed" if model.drive == "speed" else model.formulation
        if self.kind == "speed":
            self.theta = theta0
            self.speed = self.omega_ref  # rad/s, omega at the current time
            self.s = model.program.derivatives(theta0)[0]
        elif self.kind == "paper":
            self.scheme = PaperScheme(model, theta0, omega0, i0)
        else:
            self.hybrid = HybridDrive(model)
            self.y, self.mode = self.hybrid.initial(theta0, omega0, i0)
            self.hybrid.settle(self.y, self.u, self.mode)

    # ------------------------------------------------------------ public
    def set_inputs(self, u: float, omega_ref: float, omega_dot_ref: float = 0.0) -> None:
        """Inputs used by ``outputs`` before the first step [V, rad/s, rad/s2]."""
        self.u = _finite("u", u)
        self.omega_ref = _finite("omega_ref", omega_ref)
        self.omega_dot_ref = _finite("omega_dot_ref", omega_dot_ref)
        if self.kind == "speed":
            self.speed = self.omega_ref
        elif self.kind == "consistent":
            self.hybrid.settle(self.y, self.u, self.mode)  # at rest: stuck, or starting now
        self._outputs = None

    def do_step(self, t: float, h: float, u: float, omega_ref: float, omega_dot_ref: float = 0.0) -> None:
        """Advance from t to t + h [s] with inputs held over the step (FMI co-simulation).

        Speed drive: omega(t) = omega_ref + omega_dot_ref (t - t_k) over the step.
        """
        if not (math.isfinite(h) and h > 0.0):
            raise SimulationError(f"communication step size = {h!r} s: allowed (0, inf)")
        self.set_inputs(u, omega_ref, omega_dot_ref)
        if self.kind == "speed":
            self._step_speed(h)
        elif self.kind == "paper":
            n = max(1, math.ceil(h / self.h_max - 1e-9))
            for _ in range(n):
                self.scheme.step(h / n, u)
            self.steps_taken += n
        else:
            self._step_hybrid(h, u)
        self.time = t + h
        self._outputs = None
        for name, value in self.outputs().items():
            if not math.isfinite(value):
                raise SimulationError(
                    f"output {name!r} became {value!r} at t = {self.time:g} s with solver "
                    f"{self.solver!r}, h_max = {self.h_max:g} s: reduce h_max or use 'rk45'/'etdrk4'")

    def outputs(self) -> dict[str, float]:
        """Current value of every output in OUTPUTS (computed once per state)."""
        if self._outputs is None:
            if self.kind == "speed":
                model = self.model
                engaged = speed_engaged(model.program, self.theta, self.s, self.speed, model.c)
                out = speed_drive_outputs(model, self.theta, self.speed, self.omega_dot_ref, self.s, engaged)
            elif self.kind == "paper":
                out = self.scheme.outputs()
            else:
                fsal = self._fsal
                omega_dot = fsal[0][1] if fsal is not None and fsal[1] == self.u else None
                out = self.hybrid.outputs(self.y, self.u, self.mode, omega_dot)
            self._outputs = out
        return self._outputs

    def get_state(self) -> dict[str, Any]:
        """Complete internal state, JSON-serialisable."""
        state: dict[str, Any] = {
            "time": self.time, "u": self.u, "omega_ref": self.omega_ref, "omega_dot_ref": self.omega_dot_ref,
            "h_next": self.h_next, "steps_taken": self.steps_taken,
        }
        if self.kind == "speed":
            state.update(theta=self.theta, s=self.s, speed=self.speed)
        elif self.kind == "paper":
            state["scheme"] = self.scheme.get_state()
        else:
            state.update(y=list(self.y), mode=self.mode.to_dict())
        return state

    def set_state(self, state: Mapping[str, Any]) -> None:
        self._outputs = None
        self._fsal = None
        self.time = float(state["time"])
        self.u = float(state["u"])
        self.omega_ref = float(state["omega_ref"])
        self.omega_dot_ref = float(state["omega_dot_ref"])
        self.h_next = float(state["h_next"])
        self.steps_taken = int(state["steps_taken"])
        if self.kind == "speed":
            self.theta = float(state["theta"])
            self.s = float(state["s"])
            self.speed = float(state["speed"])
        elif self.kind == "paper":
            self.scheme.set_state(state["scheme"])
        else:
            self.y = [float(x) for x in state["y"]]
            self.mode = Mode(**state["mode"])

    # ------------------------------------------------------ speed drive
    def _step_speed(self, h: float) -> None:
        """theta follows omega_ref + omega_dot_ref t; the play operator sees every extremum of s_cam."""
        model = self.model
        end = self.theta + (self.omega_ref + 0.5 * self.omega_dot_ref * h) * h
        self.speed = self.omega_ref + self.omega_dot_ref * h
        self.s = follower_along(model.program, self.s, self.theta, end, model.c)
        self.theta = end
        self.steps_taken += 1

    # ---------------------------------------------- consistent, voltage
    def _step_hybrid(self, h: float, u: float) -> None:
        hybrid, mode = self.hybrid, self.mode
        y = self.y
        t = 0.0
        steps = 0
        was_stuck = mode.stuck
        hybrid.settle(y, u, mode)
        # rk45's first-same-as-last derivative f(y), kept across communication
        # steps while u, the mode and y are those it was computed for.
        k1 = self._fsal[0] if self._fsal is not None and self._fsal[1] == u and not was_stuck else None

        f = hybrid.rhs(u, mode)
        while h - t > 1e-12 * h:
            if mode.stuck and not hybrid.has_current:
                break  # nothing evolves until the input changes
            steps += 1
            if steps > self.max_steps:
                raise SimulationError(
                    f"solver {self.solver!r} needed more than max_steps = {self.max_steps} internal steps "
                    f"in one communication step of {h:g} s at t = {self.time + t:g} s: raise max_steps, "
                    "loosen rtol/atol or use 'etdrk4' for a stiff electrical pole")
            remaining = h - t
            if mode.stuck:
                dt = remaining
                y_new = self._stuck_current(y, u, dt)
            elif self.solver == "rk45":
                dt, y_new, k1 = self._adaptive_step(f, y, remaining, k1)
                cut, y_cut = self._stop_at_breakpoint(f, y, y_new, dt, mode)
                if cut != dt:  # ends on a breakpoint: its FSAL derivative belonged to the longer step
                    dt, y_new, k1 = cut, y_cut, None
            else:
                dt = min(remaining, self._fixed_step_size(y, mode))
                y_new = self._fixed_step(f, y, dt)
                dt, y_new = self._stop_at_breakpoint(f, y, y_new, dt, mode)
            hit = self._first_event(f, y, y_new, dt, u, mode)
            if hit is None:
                y, t = y_new, t + dt
                continue
            name, tau, y_event = hit
            y, t = y_event, t + tau
            hybrid.apply_event(y, u, mode, name)
            f = hybrid.rhs(u, mode)  # the mode changed
            k1 = None
        self.y = y
        self.steps_taken += steps
        self._fsal = None if k1 is None or mode.stuck else (k1, u)

    def _stop_at_breakpoint(self, f, y, y_new, dt: float, mode: Mode):
        """Shorten a step so that it ends at the first profile breakpoint it crosses.

        Where the third derivative of s jumps, a fixed-step method stepping
        across loses its order (MODEL.md section 6). Measured on fig. 6 at 1 ms:
        rk4's theta error stopped falling near 1e-6 rad as h_max went from 2.5e-4
        to 1e-4 s (now 7.6e-7 and 6.4e-9 rad at 2.5e-4 and 1.25e-4 s), and rk45's
        error at rtol 1e-8 was 1.3e-5 rad, dominated by these crossings (now
        8.5e-9 rad at the same cost). The step is cut at the located crossing
        (just past it), so every step sees one smooth piece of the profile.
        """
        crossed_points = crossed(self._breakpoints, y[0], y_new[0])
        if not crossed_points:
            return dt, y_new
        target, direction = crossed_points[0], mode.direction

        def gap(state):
            return direction * (target - state[0])

        return _locate(gap, lambda tau: self._fixed_step(f, y, tau), gap(y), gap(y_new), dt, y_new)

    def _stuck_current(self, y, u: float, dt: float) -> list[float]:
        """While stuck, only i moves: exact exponential approach to u / R."""
        model = self.model
        target = u / model.R
        return [y[0], 0.0, target + (y[2] - target) * math.exp(-dt * model.R / model.L)]

    def _fixed_step_size(self, y, mode: Mode) -> float:
        """h_max, cut to the explicit method's stability limit at this state [s]."""
        model = self.model
        s, s1, s2, s3 = model.program.derivatives(y[0])
        engaged = mode.contact != 0
        J = model.J_m + (model.m * s1 * s1 if engaged else 0.0)
        rate = 0.0
        if engaged:
            # d(omega_dot)/d(omega), and the theta-omega oscillation that the
            # profile's curvature makes: frequency |omega| sqrt(m (s2^2 + |s1 s3|) / J).
            rate = (2.0 * model.m * abs(s1 * s2 * y[1])
                    + abs(y[1]) * math.sqrt(model.m * J * (s2 * s2 + abs(s1 * s3)))) / J
        if model.L > 0.0:
            if self.solver != "etdrk4":
                rate += model.R / model.L + math.sqrt(model.c_e * model.c_m / (J * model.L))
        else:
            rate += model.c_e * model.c_m / (model.R * J)
        limit = _STABILITY[self.solver] / rate if rate > 0.0 else math.inf
        return min(self.h_max, limit)

    def _fixed_step(self, f, y, dt: float) -> list[float]:
        if self.solver == "euler":
            return euler_step(f, y, dt)
        if self.solver == "rk4":
            return rk4_step(f, y, dt)
        if self.solver == "rk45":
            return dopri_step(f, y, dt)[0]
        if not self.hybrid.has_current:
            return rk4_step(f, y, dt)  # ETDRK4 with no linear part is the classical RK4
        # ETD on the current's deviation e = i - (u - c_e omega) / R from its
        # quasi-static value: de/dt = -(R/L) e + (c_e/R) omega_dot, and on e's
        # torque c_m e / J on omega. The forcing stays bounded as L -> 0, so the
        # stiff limit and the fast transient after a break-away are exact.
        # Measured before: ETD on i alone lags the back-EMF by one step (order 1,
        # 2.4e-2 rad at 1 ms with L = 1e-6 H) and a diagonal ETD on e still
        # missed the transient's torque (7e-3 rad).
        model, u = self.model, self.u
        R, ce, rate = model.R, model.c_e, model.R / model.L
        coef = self._etd
        if coef is None or coef.h != dt:
            coef = self._etd = MotorEtdCoefficients(-rate, dt)
        s1 = model.program.derivatives(y[0])[1]
        a = model.c_m / (model.J_m + (model.m * s1 * s1 if self.mode.contact != 0 else 0.0))

        def deviation_rate(z):
            i = (u - ce * z[1]) / R + z[2]
            d = f((z[0], z[1], i))
            return (d[0], d[1], -rate * z[2] + ce / R * d[1])

        z = etdrk4_motor_step(deviation_rate, (y[0], y[1], y[2] - (u - ce * y[1]) / R), coef, a)
        return [z[0], z[1], z[2] + (u - ce * z[1]) / R]

    def _adaptive_step(self, f, y, remaining: float, k1):
        """One accepted Dormand-Prince step: (dt, y_new, f(y_new))."""
        dt = min(self.h_next, remaining, self.h_max)
        floor = 1e-14 * max(1.0, self.time)
        while True:
            y5, err, k7 = dopri_step(f, y, dt, k1)
            # theta grows without bound but enters the physics mod 2 pi: its error is
            # scaled by at most 2 pi, so its accuracy does not decay over many turns
            # (scaled by |theta|, rk45 lost 1e-4 rad within 1 s at 100 V, ~100 turns).
            total = (err[0] / (self.atol + self.rtol * min(max(abs(y[0]), abs(y5[0])), _TWO_PI))) ** 2
            for e, a, b in zip(err[1:], y[1:], y5[1:]):
                total += (e / (self.atol + self.rtol * max(abs(a), abs(b)))) ** 2
            norm = math.sqrt(total / len(y))
            if norm <= 1.0:
                factor = 5.0 if norm == 0.0 else min(5.0, 0.9 * norm ** -0.2)
                if dt < remaining or factor < 1.0:
                    self.h_next = min(dt * factor, 1e3)
                else:
                    self.h_next = max(self.h_next, dt * min(factor, 1.0))
                return dt, y5, k7
            if not math.isfinite(norm):
                norm = 1e10
            dt *= max(0.1, 0.9 * norm ** -0.2)
            if dt < floor:
                raise SimulationError(
                    f"solver 'rk45' cannot meet rtol = {self.rtol:g}, atol = {self.atol:g}: its step fell "
                    f"below {floor:g} s at t = {self.time:g} s")

    def _first_event(self, f, y, y_new, dt: float, u: float, mode: Mode):
        """Earliest event in (0, dt]: (name, time from step start, state there), or None."""
        hybrid = self.hybrid
        before = hybrid.event_values(y, u, mode)
        if not before:
            return None
        after = hybrid.event_values(y_new, u, mode)
        names = hybrid.event_names(mode)
        fired = [k for k, (g0, g1) in enumerate(zip(before, after)) if g0 > 0.0 and g1 <= 0.0]
        if not fired:
            return None
        advance = (lambda tau: self._stuck_current(y, u, tau)) if mode.stuck else (lambda tau: self._fixed_step(f, y, tau))
        best = None
        for k in fired:
            tau, y_root = _locate(lambda s: hybrid.event_values(s, u, mode)[k], advance, before[k], after[k], dt, y_new)
            if best is None or tau < best[1]:
                best = (names[k], tau, y_root)
        return best


def _locate(g, advance, g_lo: float, g_hi: float, dt: float, y_hi):
    """Illinois false position for the zero of g(advance(tau)) in (0, dt].

    Returns the time and the state just past the zero (g <= 0 there), so the
    transition is applied on the far side of the event.
    """
    lo, hi = 0.0, dt
    side = 0
    for _ in range(_EVENT_ITERATIONS):
        if hi - lo <= 1e-13 * max(dt, 1e-300) + 1e-15:
            break
        tau = hi - g_hi * (hi - lo) / (g_hi - g_lo) if g_hi != g_lo else 0.5 * (lo + hi)
        if not lo < tau < hi:
            tau = 0.5 * (lo + hi)
        y_tau = advance(tau)
        g_tau = g(y_tau)
        if g_tau <= 0.0:
            hi, g_hi, y_hi = tau, g_tau, y_tau
            if side == -1:
                g_lo *= 0.5
            side = -1
        else:
            lo, g_lo = tau, g_tau
            if side == 1:
                g_hi *= 0.5
            side = 1
    return hi, list(y_hi)


def _finite(name: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value):
        raise SimulationError(f"input {name!r} = {value!r}: allowed any finite value")
    return value
