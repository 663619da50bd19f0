"""cam.fmu's directional derivatives in Model Exchange (csrc/src/jacobian.c through fmi/directional.c): against
central differences of the FMU's own derivatives and outputs at random states of every drive and mode, away from
events; the ModelStructure's dependencies against a numerical sparsity probe; bad requests refused with the reason."""
from __future__ import annotations

import math
from ctypes import POINTER, c_double

import fmpy
import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Model

from cam_fmu.physics.variables import OUTPUTS, STATES

NX = len(STATES)
RTOL = 1e-6
# (label, start values): every drive-train and mode the tangent covers; closure 'kinematic' keeps the follower on the
# cam (a follower of its own is refused, test_follower_of_its_own_is_refused).
CASES = {
    "rigid": {"omega0": 20.0},
    "rigid_L": {"omega0": 20.0, "L": 1e-3},
    "no_guide_friction": {"omega0": 20.0, "guide_friction": 0.0},
    "tilted": {"omega0": 20.0, "gamma": 1.2, "beta": 0.7, "mu": 0.05},
    "compliant": {"omega0": 20.0, "k_shaft": 50.0, "d_shaft": 1e-3, "J_m": 3e-5, "J_cam": 1.41e-5},
    "compliant_L": {"omega0": 20.0, "k_shaft": 50.0, "d_shaft": 1e-3, "J_m": 3e-5, "J_cam": 1.41e-5, "L": 1e-3},
    "free_in_gap": {"omega0": 20.0, "c": 1e-3, "closure": "kinematic"},
    "stuck": {"omega0": 0.0, "u": 0.0},
    "stuck_L": {"omega0": 0.0, "u": 0.0, "L": 1e-3},
}


class Me:
    """cam.fmu in continuous-time mode through fmpy's fmi2 API, with the calls the tests need."""

    def __init__(self, fmu, start: dict) -> None:
        md = fmpy.read_model_description(str(fmu))
        self.md = md
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.kind = {v.name: v.type for v in md.modelVariables}
        self.model = FMU2Model(guid=md.guid, unzipDirectory=fmpy.extract(str(fmu)), modelIdentifier="cam",
                               instanceName="jac")
        self.model.instantiate()
        self.model.setupExperiment(startTime=0.0)
        self.model.enterInitializationMode()
        for name, value in start.items():
            if isinstance(value, str):
                self.model.setString([self.vr[name]], [value])
            elif self.kind[name] == "Boolean":
                self.model.setBoolean([self.vr[name]], [bool(value)])
            else:
                self.model.setReal([self.vr[name]], [value])
        self.model.exitInitializationMode()
        while self.model.newDiscreteStates()[0]:
            pass
        self.model.enterContinuousTimeMode()
        self.states = [self.vr[row[0]] for row in STATES]
        self.ders = [self.vr[f"der({row[0]})"] for row in STATES]
        self.outputs = [self.vr[row[0]] for row in OUTPUTS]
        self.knowns = self.states + [self.vr["u"]]

    def x(self) -> np.ndarray:
        values = np.zeros(NX)
        self.model.getContinuousStates(values.ctypes.data_as(POINTER(c_double)), NX)
        return values

    def set_x(self, x: np.ndarray) -> None:
        x = np.ascontiguousarray(x, dtype=float)
        self.model.setContinuousStates(x.ctypes.data_as(POINTER(c_double)), NX)

    def f(self) -> np.ndarray:
        """The state derivatives and the outputs at the FMU's state and inputs."""
        dx = np.zeros(NX)
        self.model.getDerivatives(dx.ctypes.data_as(POINTER(c_double)), NX)
        return np.concatenate([dx, self.model.getReal(self.outputs)])

    def knowns_now(self) -> np.ndarray:
        return np.concatenate([self.x(), self.model.getReal([self.vr["u"]])])

    def set_knowns(self, z: np.ndarray) -> None:
        self.set_x(z[:NX])
        self.model.setReal([self.vr["u"]], [float(z[NX])])

    def jacobian(self) -> np.ndarray:
        """The FMU's analytic Jacobian of (derivatives, outputs) by (states, u), one seed per known."""
        unknowns = self.ders + self.outputs
        cols = [self.model.getDirectionalDerivative(unknowns, [k], [1.0]) for k in self.knowns]
        return np.array(cols).T

    def central(self, rel: float) -> np.ndarray:
        """Central differences of the FMU's own derivatives and outputs, step rel max(1, |z_j|) (x_gap's scale 1e-3)."""
        z = self.knowns_now()
        cols = []
        for j in range(len(z)):
            h = rel * max(1.0, abs(z[j])) * (1e-3 if j in (NX - 2, NX - 1) else 1.0)
            plus, minus = z.copy(), z.copy()
            plus[j] += h
            minus[j] -= h
            self.set_knowns(plus)
            fp = self.f()
            self.set_knowns(minus)
            fm = self.f()
            cols.append((fp - fm) / (2 * h))
        self.set_knowns(z)
        return np.array(cols).T

    def close(self) -> None:
        self.model.terminate()
        self.model.freeInstance()


def random_states(me: Me, rng: np.random.Generator, stuck: bool) -> None:
    """A random state near the drive's own: any cam angle, speed 5..40 rad/s in the mode's direction (0 at rest),
    current and twist of their scale."""
    x = me.x()
    x[0] = rng.uniform(0.0, 2 * math.pi)
    x[1] = 0.0 if stuck else rng.uniform(5.0, 40.0)
    x[2] = rng.uniform(0.05, 0.3)
    x[3] = rng.uniform(-2e-4, 2e-4)
    x[4] = x[1] + rng.uniform(-2.0, 2.0)
    me.set_x(x)
    me.model.setReal([me.vr["u"]], [rng.uniform(1.0, 5.0)])


def smooth_differences(me: Me) -> np.ndarray | None:
    """Central differences at two steps that agree (no breakpoint of the profile within them), else None."""
    coarse, fine = me.central(1e-5), me.central(5e-6)
    scale = np.maximum(np.abs(fine).max(axis=1, keepdims=True), 1e-300)
    if np.all(np.abs(coarse - fine) <= 1e-8 * scale + 1e-8 * np.abs(fine)):
        return fine
    return None


@pytest.mark.parametrize("case", list(CASES))
def test_directional_derivatives_match_central_differences(engine_fmu_path, case):
    """At 4 random states per drive and mode, away from events and breakpoints, the analytic Jacobian of the state
    derivatives and outputs by the states and u agrees with central differences of fmi2GetDerivatives / fmi2GetReal
    to 1e-6 relative (of each row's largest entry)."""
    rng = np.random.default_rng(42)
    me = Me(engine_fmu_path, CASES[case])
    stuck = CASES[case].get("omega0", 1.0) == 0.0
    checked = 0
    try:
        for _ in range(40):
            random_states(me, rng, stuck)
            fd = smooth_differences(me)
            if fd is None:
                continue
            analytic = me.jacobian()
            scale = np.abs(fd).max(axis=1, keepdims=True)
            err = np.abs(analytic - fd)
            assert np.all(err <= RTOL * scale + 1e-12), (case, np.argwhere(err > RTOL * scale + 1e-12))
            assert np.abs(analytic).max() > 0.0
            checked += 1
            if checked == 4:
                break
    finally:
        me.close()
    assert checked == 4
