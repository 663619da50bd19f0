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
"""
from __future__ import annotations

import time
from ctypes import POINTER, c_double
from pathlib import Path

import numpy as np

from ...physics.variables import STATES

NX = len(STATES)
RTOL, ATOL = 1e-6, 1e-8
# scene's parameters for the measured run; carried: the slots the drive integrates (the rest are held at 0)
RUNS = {
    "inductance": ({"gamma": np.pi, "L": 1e-3, "omega0": 20.0}, [0, 1, 2]),
    "compliant_shaft": ({"gamma": np.pi, "L": 1e-3, "omega0": 20.0, "J_m": 3e-5, "J_cam": 1.41e-5, "k_shaft": 50.0,
                         "d_shaft": 1e-3}, [0, 1, 2, 3, 4]),
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
        self.nfev = self.njev = 0

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


def run(ctx) -> int:
    """`cam-fmu bench jacobian`: the table of compare(); 1 when a run with the Jacobian needs more right-hand sides."""
    rows = compare(ctx.fmu, 0.05 if ctx.quick else 0.2)
    ctx.say(f"stiff runs from omega0 = 20 rad/s, L = 1 mH, rtol {RTOL:g}, atol {ATOL:g}: differenced -> FMU Jacobian")
    worse = 0
    for r in rows:
        fd, an = r["fd"], r["analytic"]
        ctx.say(f"  {r['scene']:16s} {r['method']:5s} rhs {fd['nfev']:6d} -> {an['nfev']:6d} "
                f"({r['rhs_ratio']:.2f}x fewer), jac {fd['njev']:4d} -> {an['njev']:4d}, steps {fd['steps']} -> "
                f"{an['steps']}, wall {fd['wall'] * 1e3:.0f} -> {an['wall'] * 1e3:.0f} ms ({r['wall_ratio']:.2f}x), "
                f"final states differ by {r['difference']:.2g} of the tolerance")
        worse += r["rhs_ratio"] < 1.0
    return 1 if worse else 0
