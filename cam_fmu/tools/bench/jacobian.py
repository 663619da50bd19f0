"""Stiff runs with and without cam.fmu's directional derivatives (issue 42 item 3).

    cam-fmu bench jacobian [--quick]

The `inductance` scene's primary run (L = 1 mH: the electrical pole R/L = 19,000 1/s beside the mechanics) and the
`compliant_shaft` scene's with L = 1 mH too, from omega0 = 20 rad/s (moving, the follower engaged) over 0.2 s
(--quick: 0.05 s), integrated by scipy's BDF and Radau on cam.fmu's Model Exchange interface through fmpy's fmi2 API:
the right-hand side is fmi2SetContinuousStates + fmi2GetDerivatives, the Jacobian either fmi2GetDirectionalDerivative
(one seed per carried state) or scipy's own differencing of the right-hand side. Reported: right-hand-side
evaluations (every fmi2GetDerivatives, the differencing's included), Jacobian evaluations, wall time, and the largest
difference of the final states between the two, relative to the tolerance. No events are crossed in these windows
(the drive keeps turning forward, the follower on the cam); the profile's breakpoints are no mode change.

And a run through events (event_run): the `backlash` scene's groove under closure 'form' (c = 0.5 mm, a follower of
its own: lift-offs, touch-downs with restitution, the shaft's break-away from rest) at u = 3.5 V over 2 s (--quick:
0.5 s), by scipy's BDF and Radau stepped one step at a time (their OdeSolver classes): after every step
fmi2CompletedIntegratorStep and the event indicators; at a sign change the event located by bisection on the step's
dense output (to 1e-12 s), the FMU's event iteration there, and a new solver from the state after it (as a host
restarting its integrator at each event does; the profile's breakpoints, indicator 3, are events too). The Jacobian
is the FMU's (jacobian_follower.c) or scipy's differencing, which a restart redoes.
"""
from __future__ import annotations

import time
from ctypes import POINTER, c_double
from pathlib import Path

import numpy as np

from ...physics.variables import STATES

NX = len(STATES)
RTOL, ATOL = 1e-6, 1e-8


def slots(*names: str) -> list[int]:
    """The indices of Model Exchange's states ``names`` (physics.variables.STATES)."""
    order = [row[0] for row in STATES]
    return [order.index(name) for name in names]



# scene's parameters for the measured run; carried: the slots the drive integrates (the rest are held at 0)
RUNS = {
    "inductance": ({"gamma": np.pi, "L": 1e-3, "omega0": 20.0}, slots("x_theta", "x_omega", "x_i")),
    "compliant_shaft": ({"gamma": np.pi, "L": 1e-3, "omega0": 20.0, "J_m": 3e-5, "J_cam": 1.41e-5, "k_shaft": 50.0,
                         "d_shaft": 1e-3}, slots("x_theta", "x_omega", "x_i", "x_twist", "x_omega_m")),
}


class MeRhs:
    """cam.fmu in continuous-time mode as f(t, x) and J(t, x) over its carried slots, counting the calls."""

    def __init__(self, fmu: Path, start: dict, carried: list) -> None:
        import fmpy
        from fmpy.fmi2 import FMU2Model

        md = fmpy.read_model_description(str(fmu))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        self.model = FMU2Model(guid=md.guid, unzipDirectory=fmpy.extract(str(fmu)), modelIdentifier="cam",
                               instanceName="bench_jacobian")
        self.model.instantiate()
        self.model.setupExperiment(startTime=0.0)
        self.model.enterInitializationMode()
        for name, value in start.items():
            if isinstance(value, str):
                self.model.setString([vr[name]], [value])
            elif isinstance(value, bool):
                self.model.setBoolean([vr[name]], [value])
            else:
                self.model.setReal([vr[name]], [value])
        self.model.exitInitializationMode()
        while self.model.newDiscreteStates()[0]:
            pass
        self.model.enterContinuousTimeMode()
        self.carried = carried
        self.full = np.zeros(NX)
        self.model.getContinuousStates(self.full.ctypes.data_as(POINTER(c_double)), NX)
        self.states = [vr[STATES[k][0]] for k in carried]
        self.ders = [vr[f"der({STATES[k][0]})"] for k in carried]
        self.nfev = self.njev = self.nindicators = 0
        self.n_indicators = md.numberOfEventIndicators

    def _set(self, t: float, x: np.ndarray) -> None:
        self.full[self.carried] = x
        self.model.setTime(t)
        self.model.setContinuousStates(self.full.ctypes.data_as(POINTER(c_double)), NX)

    def x0(self) -> np.ndarray:
        return self.full[self.carried].copy()

    def f(self, t: float, x: np.ndarray) -> np.ndarray:
        self.nfev += 1
        self._set(t, x)
        dx = np.zeros(NX)
        self.model.getDerivatives(dx.ctypes.data_as(POINTER(c_double)), NX)
        return dx[self.carried]

    def jac(self, t: float, x: np.ndarray) -> np.ndarray:
        self.njev += 1
        self._set(t, x)
        return np.array([self.model.getDirectionalDerivative(self.ders, [k], [1.0]) for k in self.states]).T

    def indicators(self, t: float, x: np.ndarray) -> np.ndarray:
        self.nindicators += 1
        self._set(t, x)
        z = np.zeros(self.n_indicators)
        self.model.getEventIndicators(z.ctypes.data_as(POINTER(c_double)), self.n_indicators)
        return z

    def event(self, t: float, x: np.ndarray) -> np.ndarray:
        """The FMU's event iteration at (t, x): the states after it (an impact changes them)."""
        self._set(t, x)
        self.model.enterEventMode()
        while self.model.newDiscreteStates()[0]:
            pass
        self.model.enterContinuousTimeMode()
        self.model.getContinuousStates(self.full.ctypes.data_as(POINTER(c_double)), NX)
        return self.x0()

    def close(self) -> None:
        self.model.terminate()
        self.model.freeInstance()


def stiff_run(fmu: Path, scene: str, method: str, analytic: bool, t_end: float) -> dict:
    """One run: {'nfev', 'njev', 'wall' [s], 'x' (final carried states), 'steps'}."""
    from scipy.integrate import solve_ivp

    start, carried = RUNS[scene]
    rhs = MeRhs(fmu, start, carried)
    try:
        began = time.perf_counter()
        sol = solve_ivp(rhs.f, (0.0, t_end), rhs.x0(), method=method, rtol=RTOL, atol=ATOL,
                        jac=rhs.jac if analytic else None)
        wall = time.perf_counter() - began
    finally:
        rhs.close()
    if not sol.success:
        raise RuntimeError(f"{scene} {method}: {sol.message}")
    return {"nfev": rhs.nfev, "njev": rhs.njev if analytic else sol.njev, "wall": wall, "x": sol.y[:, -1],
            "steps": sol.t.size - 1}


# the run through events: the backlash scene's groove with a follower of its own, from rest; carried: theta, omega and
# the follower's gap and its rate (L = 0: x_i held; a rigid shaft)
EVENT_RUN = ({"gamma": np.pi, "backlash": True, "c": 5e-4, "closure": "form", "u": 3.5},
             slots("x_theta", "x_omega", "x_gap", "x_gap_rate"))
LOCATE = 1e-12   # s: an event's bracket


def _crossing(rhs: MeRhs, dense, a: float, b: float, za: np.ndarray, zb: np.ndarray) -> tuple[float, int] | None:
    """The earliest time in (a, b] where an indicator goes from > 0 to <= 0 along the step's dense output (bisection
    to LOCATE, the end where it is <= 0) and its slot, or None."""
    slots = [k for k in range(len(za)) if za[k] > 0.0 and zb[k] <= 0.0]
    if not slots:
        return None
    first, slot = b, slots[0]
    for k in slots:
        lo, hi = a, first
        if rhs.indicators(hi, dense(hi))[k] > 0.0:
            continue   # crosses after an earlier slot's event
        while hi - lo > LOCATE:
            mid = 0.5 * (lo + hi)
            if rhs.indicators(mid, dense(mid))[k] > 0.0:
                lo = mid
            else:
                hi = mid
        first, slot = hi, k
    return first, slot


def event_run(fmu: Path, method: str, analytic: bool, t_end: float) -> dict:
    """The run through events: {'nfev', 'njev', 'wall' [s], 'x', 'steps', 'events' (the mode's: slots 0 to 2, or the
    FMU's request at a completed step), 'breakpoints' (slot 3), 'restarts'}."""
    from scipy.integrate import BDF, Radau

    start, carried = EVENT_RUN
    rhs = MeRhs(fmu, start, carried)
    solver_class = {"BDF": BDF, "Radau": Radau}[method]
    steps = events = breakpoints = restarts = njev = 0
    t, x = 0.0, rhs.x0()
    try:
        began = time.perf_counter()
        while t < t_end:
            solver = solver_class(rhs.f, t, x, t_end, rtol=RTOL, atol=ATOL, jac=rhs.jac if analytic else None)
            restarts += 1
            z = rhs.indicators(t, x)
            while solver.status == "running":
                a = solver.t
                message = solver.step()
                if solver.status == "failed":
                    raise RuntimeError(f"event run {method}: {message} at t = {a} s")
                steps += 1
                zb = rhs.indicators(solver.t, solver.y)
                found = _crossing(rhs, solver.dense_output(), a, solver.t, z, zb)
                if found is not None:
                    t, x = found[0], rhs.event(found[0], solver.dense_output()(found[0]))
                    breakpoints += found[1] == rhs.n_indicators - 1
                    events += found[1] != rhs.n_indicators - 1
                    break
                rhs._set(solver.t, solver.y)
                if rhs.model.completedIntegratorStep()[0]:   # an indicator at zero heading below: its event now
                    t, x = solver.t, rhs.event(solver.t, solver.y)
                    events += 1
                    break
                z = zb
                t, x = solver.t, solver.y
            njev += solver.njev
        wall = time.perf_counter() - began
    finally:
        rhs.close()
    return {"nfev": rhs.nfev, "njev": rhs.njev if analytic else njev, "wall": wall, "x": x, "steps": steps,
            "events": events, "breakpoints": breakpoints, "restarts": restarts}


def compare(fmu: Path, t_end: float) -> list:
    """Every (scene, method) with and without the FMU's Jacobian: the two runs and the ratios."""
    rows = []
    for scene in RUNS:
        for method in ("BDF", "Radau"):
            fd = stiff_run(fmu, scene, method, False, t_end)
            an = stiff_run(fmu, scene, method, True, t_end)
            diff = np.max(np.abs(an["x"] - fd["x"]) / (ATOL + RTOL * np.abs(fd["x"])))
            rows.append({"scene": scene, "method": method, "fd": fd, "analytic": an,
                         "rhs_ratio": fd["nfev"] / an["nfev"], "wall_ratio": fd["wall"] / an["wall"],
                         "difference": float(diff)})
    return rows


def compare_events(fmu: Path, t_end: float) -> list:
    """The run through events by BDF and Radau with and without the FMU's Jacobian: the two runs and the ratios."""
    rows = []
    for method in ("BDF", "Radau"):
        fd = event_run(fmu, method, False, t_end)
        an = event_run(fmu, method, True, t_end)
        diff = np.max(np.abs(an["x"] - fd["x"]) / (ATOL + RTOL * np.abs(fd["x"])))
        rows.append({"scene": "backlash, form", "method": method, "fd": fd, "analytic": an,
                     "rhs_ratio": fd["nfev"] / an["nfev"], "wall_ratio": fd["wall"] / an["wall"],
                     "difference": float(diff)})
    return rows


def run(ctx) -> int:
    """`cam-fmu bench jacobian`: the tables of compare() and compare_events(); 1 when a stiff run (compare's) with the
    Jacobian needs more right-hand sides (the run through events is measured, held to nothing)."""
    rows = compare(ctx.fmu, 0.05 if ctx.quick else 0.2)
    ctx.say(f"stiff runs from omega0 = 20 rad/s, L = 1 mH, rtol {RTOL:g}, atol {ATOL:g}: differenced -> FMU Jacobian")
    worse = _report(ctx, rows)
    t_end = 0.5 if ctx.quick else 2.0
    rows = compare_events(ctx.fmu, t_end)
    ctx.say(f"through events: the backlash scene's groove under closure 'form' from rest, u = 3.5 V, {t_end:g} s, "
            f"a new solver after each event")
    for r in rows:
        ctx.say(f"  {r['method']:5s} events {r['fd']['events']} -> {r['analytic']['events']}, breakpoints "
                f"{r['fd']['breakpoints']} -> {r['analytic']['breakpoints']}")
    _report(ctx, rows)   # measured, not held to a ratio: whether the Jacobian pays near events is the question
    return 1 if worse else 0


def _report(ctx, rows: list) -> int:
    """One line per row of compare(); how many runs with the Jacobian needed more right-hand sides."""
    worse = 0
    for r in rows:
        fd, an = r["fd"], r["analytic"]
        ctx.say(f"  {r['scene']:16s} {r['method']:5s} rhs {fd['nfev']:6d} -> {an['nfev']:6d} "
                f"({r['rhs_ratio']:.2f}x fewer), jac {fd['njev']:4d} -> {an['njev']:4d}, steps {fd['steps']} -> "
                f"{an['steps']}, wall {fd['wall'] * 1e3:.0f} -> {an['wall'] * 1e3:.0f} ms ({r['wall_ratio']:.2f}x), "
                f"final states differ by {r['difference']:.2g} of the tolerance")
        worse += r["rhs_ratio"] < 1.0
    return worse
