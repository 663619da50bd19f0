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

from cam_fmu.experiments.scenes import find_scene
from cam_fmu.physics.variables import OUTPUTS, STATES

NX = len(STATES)
RTOL = 1e-6
# (label, start values): every drive-train and mode the tangent covers. Closure 'kinematic' keeps the follower on the
# cam (jacobian.c); a follower of its own (jacobian_follower.c) starts on its flank, or, at 150 rad/s where the cam
# falls away faster than the spring pulls the follower (theta0 = 1.2 rad), in flight: FLIGHT names those.
SPRING = {"closure": "spring", "k_spring": 200.0, "F_spring0": 1.0}
SHAFT = {"k_shaft": 50.0, "d_shaft": 1e-3, "J_m": 3e-5, "J_cam": 1.41e-5, "L": 1e-3}
TILT = {"gamma": 1.2, "beta": 0.7, "mu": 0.05}
LIFTED = {"omega0": 150.0, "theta0": 1.2}
FOLLOWER = {
    "spring_on_flank": {"omega0": 20.0, **SPRING},
    "spring_stuck": {"omega0": 0.0, "u": 0.0, "theta0": 1.0, **SPRING},
    "spring_in_flight": {**LIFTED, **SPRING},
    "spring_in_flight_tilted": {**LIFTED, **SPRING, **TILT},
    "spring_in_flight_L": {**LIFTED, **SPRING, "L": 1e-3, "i0": -1.0},   # the current brakes: it lifts off
    "spring_in_flight_compliant_L": {**LIFTED, **SPRING, **SHAFT},
    "groove_on_flank": {"omega0": 20.0, "c": 5e-4},
    "groove_other_flank_tilted": {**LIFTED, "c": 5e-4, **TILT},
    "groove_compliant_L": {"omega0": 20.0, "c": 5e-4, **SHAFT},
    "groove_stuck": {"omega0": 0.0, "u": 0.0, "c": 5e-4},
}
# The follower's kind (kind.c, docs/model.md 16) on the scene's cam: an arm with a roller or a flat face, gravity
# tilted; without and with the type's friction (mu: the face's sliding, the arm's pivot; the branch sgn(P) held).
ARM = {"arm_length": 0.15, "pivot_distance": 0.18, "J_arm": 2e-3, "m_arm": 0.2, "r_cm_arm": 0.07, "psi_0": 0.3,
       "mu": 0.0, "gamma": 1.2}
# With friction, a cycloidal rise, dwell, return, dwell of 90 deg each (its s'' of one sign over most of a rise: the
# lever's rate psi'' is not small where the default law's middle runs at nearly constant speed).
CYCLOID = {"rise_law": "cycloidal", "return_law": "cycloidal", "rise_angle": math.pi / 2, "upper_dwell": math.pi / 2,
           "return_angle": math.pi / 2, "lower_dwell": math.pi / 2, "lift": 0.02, "r_b": 0.08, "J_cam": 2e-4}
KIND = {
    "oscillating_roller": {"omega0": 20.0, "follower_type": "oscillating_roller", "lift_angle": 0.3, **ARM},
    "oscillating_roller_stuck_L": {"omega0": 0.0, "u": 0.0, "L": 1e-3, "theta0": 1.0,
                                   "follower_type": "oscillating_roller", "lift_angle": 0.3, **ARM},
    "oscillating_flat_L": {"omega0": 20.0, "L": 1e-3, "follower_type": "oscillating_flat", "lift_angle": 0.15, **ARM},
    "translating_flat": {"omega0": 20.0, "follower_type": "translating_flat", "mu": 0.0, "gamma": 1.2, "beta": 0.7},
    "oscillating_roller_friction": {"omega0": 20.0, "follower_type": "oscillating_roller", "lift_angle": 0.3, **ARM,
                                    **CYCLOID, "mu": 0.05},
    "oscillating_roller_friction_stuck_L": {"omega0": 0.0, "u": 0.0, "L": 1e-3, "theta0": 1.0,
                                            "follower_type": "oscillating_roller", "lift_angle": 0.3, **ARM,
                                            **CYCLOID, "mu": 0.05},
    "oscillating_flat_friction_L": {"omega0": 20.0, "L": 1e-3, "follower_type": "oscillating_flat",
                                    "lift_angle": 0.15, **ARM, **CYCLOID, "mu": 0.05},
    "translating_flat_friction": {"omega0": 20.0, "follower_type": "translating_flat", "mu": 0.05, "gamma": 1.2,
                                  "beta": 0.7, **CYCLOID},
    "oscillating_roller_train": {"omega0": 20.0, "follower_type": "oscillating_roller", "lift_angle": 0.3, **ARM,
                                 "k_train_arm": 500.0, "d_train_arm": 0.05, "J_end": 2e-3, **CYCLOID},
    "oscillating_flat_train_friction": {"omega0": 20.0, "follower_type": "oscillating_flat", "lift_angle": 0.15,
                                        **ARM, "mu": 0.05, "k_train_arm": 500.0, "d_train_arm": 0.05, "J_end": 2e-3,
                                        **CYCLOID},
    "translating_flat_train": {"omega0": 20.0, "follower_type": "translating_flat", "mu": 0.05, "gamma": 1.2,
                               "beta": 0.7, "k_train": 2e4, "d_train": 2.0, "m_end": 0.2, "L": 1e-3, **CYCLOID},
}
FLIGHT = {"spring_in_flight", "spring_in_flight_tilted", "spring_in_flight_L", "spring_in_flight_compliant_L"}
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
    "train": {"omega0": 20.0, "k_train": 2e4, "d_train": 2.0, "m_end": 0.2, "M_f": 0.0, "mu": 0.0},
    "train_L": {"omega0": 20.0, "k_train": 2e4, "d_train": 2.0, "m_end": 0.2, "M_f": 0.0, "mu": 0.0, "L": 1e-3,
                "gamma": 0.8},
    "train_friction": {"omega0": 20.0, "k_train": 2e4, "d_train": 2.0, "m_end": 0.2, "mu": 0.05, "gamma": 1.2,
                       "beta": 0.7},
    "train_compliant": {"omega0": 20.0, "k_train": 2e4, "d_train": 2.0, "m_end": 0.2, "k_shaft": 50.0, "d_shaft": 1e-3,
                        "J_m": 3e-5, "J_cam": 1.41e-5, "L": 1e-3},
    **FOLLOWER,
    **KIND,
}


def scene_start(name: str, **changes) -> dict:
    """A shipped scene's start values and its input at t = 0, with changes."""
    scene = find_scene(name)
    return {**scene.primary.start_values(), "u": scene.u.value(0.0), **changes}


# A follower of its own in the shipped scenes, each mode reached by the FMU's own event updates (FOLLOWER above starts
# in its mode): label -> (start values, mode, cam speed [rad/s] at which the flank lets the follower go). The modes:
# on a flank with the shaft moving ('contact') or stuck ('stuck': from rest with u = 0), in flight with the cam moving
# ('flight': lifted off by an event update where the contact force is < 0) or stuck under it ('flight_stuck': then
# stopped with u = 0).
_GROOVE = scene_start("groove_voltage")
_SPRING = scene_start("spring_voltage")
_BACKLASH_FORM = scene_start("backlash", closure="form", omega0=20.0)
_BACKLASH_SPRING = scene_start("backlash", closure="spring", c=0.0, omega0=20.0)   # one flank: no clearance
_FRICTION_L = {"mu": 0.05, "L": 1e-3}
_SHAFT = {"k_shaft": 100.0, "d_shaft": 0.01, "J_m": 3e-5, "mu": 0.05}
FOLLOWER_CASES = {
    "groove_voltage/contact": (_GROOVE, "contact", 0.0),
    "groove_voltage/flight": (_GROOVE, "flight", 60.0),
    "groove_voltage/flight_stuck": (_GROOVE, "flight_stuck", 60.0),
    "groove_friction_L/contact": ({**_GROOVE, **_FRICTION_L}, "contact", 0.0),
    "groove_friction_L/flight": ({**_GROOVE, **_FRICTION_L}, "flight", 60.0),
    "spring_voltage/contact": (_SPRING, "contact", 0.0),
    "spring_voltage/stuck": ({**_SPRING, "omega0": 0.0, "u": 0.0}, "stuck", 0.0),
    "spring_voltage/flight": (_SPRING, "flight", 150.0),
    "spring_voltage/flight_stuck": (_SPRING, "flight_stuck", 150.0),
    "spring_compliant/contact": ({**_SPRING, **_SHAFT}, "contact", 0.0),
    "spring_compliant/flight": ({**_SPRING, **_SHAFT}, "flight", 150.0),
    "spring_compliant_L/stuck": ({**_SPRING, **_SHAFT, "L": 1e-3, "omega0": 0.0, "u": 0.0}, "stuck", 0.0),
    "backlash_form/contact": (_BACKLASH_FORM, "contact", 0.0),
    "backlash_form/stuck": ({**_BACKLASH_FORM, "omega0": 0.0, "u": 0.0}, "stuck", 0.0),
    "backlash_form/flight": ({**_BACKLASH_FORM, "mu": 0.05}, "flight", 60.0),
    "backlash_form/flight_stuck": ({**_BACKLASH_FORM, "mu": 0.05}, "flight_stuck", 60.0),
    "backlash_spring/contact": (_BACKLASH_SPRING, "contact", 0.0),
    "backlash_spring/flight": (_BACKLASH_SPRING, "flight", 150.0),
}
# Every follower type as a body of its own (docs/model.md 16.3): an arm in a groove (its gap an angle) and on a
# spring about its pivot, a flat face on a spring; the weight tilted and each type's friction on.
_ARM_OWN = {**CYCLOID, **ARM, "follower_type": "oscillating_roller", "lift_angle": 0.3, "mu": 0.05, "M_f": 0.01,
            "G": 4.0}
_ARM_GROOVE = {**_ARM_OWN, "closure": "form", "c": 5e-4, "restitution": 0.5, "omega0": 20.0}
_ARM_SPRING = {**_ARM_OWN, "follower_type": "oscillating_flat", "lift_angle": 0.15, "closure": "spring",
               "k_spring": 300.0, "F_spring0": 3.0, "omega0": 20.0, "L": 1e-3}
_FLAT_SPRING = {**CYCLOID, "follower_type": "translating_flat", "mu": 0.05, "gamma": 1.2, "beta": 0.7, "G": 4.0,
                "closure": "spring", "k_spring": 300.0, "F_spring0": 3.0, "omega0": 20.0}
# A follower train on the follower of its own (docs/model.md 14.6): its end mass rings on the flank and in flight.
_TRAIN = {"k_train": 2e4, "d_train": 5.0, "m_end": 0.2}
# the flat face's on a spring whose preload holds it under the random states' pull of the train (up to 25 N)
_FLAT_TRAIN = {**_FLAT_SPRING, **_TRAIN, "k_spring": 3000.0, "F_spring0": 40.0}
_ARM_TRAIN = {"k_train_arm": 500.0, "d_train_arm": 0.05, "J_end": 2e-3}   # an arm's torsional train
FOLLOWER_CASES.update({
    "spring_train/contact": ({**_SPRING, **_TRAIN}, "contact", 0.0),
    "spring_train/stuck": ({**_SPRING, **_TRAIN, "omega0": 0.0, "u": 0.0}, "stuck", 0.0),
    "spring_train/flight": ({**_SPRING, **_TRAIN}, "flight", 150.0),
    "groove_train_friction_L/contact": ({**_GROOVE, **_TRAIN, **_FRICTION_L}, "contact", 0.0),
    "groove_train_friction_L/flight": ({**_GROOVE, **_TRAIN, **_FRICTION_L}, "flight", 60.0),
    "groove_train/flight_stuck": ({**_GROOVE, **_TRAIN}, "flight_stuck", 60.0),
    "arm_groove/contact": (_ARM_GROOVE, "contact", 0.0),
    "arm_groove/flight": (_ARM_GROOVE, "flight", 100.0),
    "arm_groove/flight_stuck": (_ARM_GROOVE, "flight_stuck", 100.0),
    "arm_spring_L/contact": (_ARM_SPRING, "contact", 0.0),
    "arm_spring_L/stuck": ({**_ARM_SPRING, "omega0": 0.0, "u": 0.0, "theta0": 2.0}, "stuck", 0.0),   # a dwell
    "arm_spring_L/flight": (_ARM_SPRING, "flight", 150.0),
    "flat_spring/contact": (_FLAT_SPRING, "contact", 0.0),
    "flat_spring/flight": (_FLAT_SPRING, "flight", 150.0),
    "arm_groove_train/contact": ({**_ARM_GROOVE, **_ARM_TRAIN}, "contact", 0.0),
    "arm_groove_train/flight": ({**_ARM_GROOVE, **_ARM_TRAIN}, "flight", 100.0),
    "arm_spring_train_L/contact": ({**_ARM_SPRING, **_ARM_TRAIN}, "contact", 0.0),
    "arm_spring_train_L/stuck": ({**_ARM_SPRING, **_ARM_TRAIN, "omega0": 0.0, "u": 0.0, "theta0": 2.0}, "stuck", 0.0),
    "flat_spring_train/contact": (_FLAT_TRAIN, "contact", 0.0),
    "flat_spring_train/stuck": ({**_FLAT_TRAIN, "omega0": 0.0, "u": 0.0}, "stuck", 0.0),
    "flat_spring_train/flight": (_FLAT_TRAIN, "flight", 150.0),
})


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

    def indicators(self) -> np.ndarray:
        values = np.zeros(self.md.numberOfEventIndicators)
        self.model.getEventIndicators(values.ctypes.data_as(POINTER(c_double)), len(values))
        return values

    def event(self) -> None:
        """An event iteration at the current state and inputs (the transitions of the indicators below zero)."""
        self.model.enterEventMode()
        while self.model.newDiscreteStates()[0]:
            pass
        self.model.enterContinuousTimeMode()

    def set_u(self, u: float) -> None:
        self.model.setReal([self.vr["u"]], [u])

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
    if x[5] != 0.0:   # a train's end mass about its start (held at 0 without one)
        x[5] += rng.uniform(-1e-3, 1e-3)
        x[6] = rng.uniform(-1.0, 1.0)
        me.set_x(x)


def enter_follower_mode(me, mode: str, speed: float, train: bool = False) -> None:
    """Put a follower of its own (in contact after the start) into `mode` (FOLLOWER_CASES) by the FMU's own event
    updates: the first cam angle (of 721) where the contact force at `speed` is < 0 (indicator slot 1), an event
    there (the lift-off); for 'flight_stuck' then u = 0 and the cam a hair past its stop, an event (stuck). `me` is an
    FMI 2.0 (Me) or FMI 3.0 host with x, set_x, indicators, event and set_u; `train`: a follower train's end mass is
    put where it pulls the follower off."""
    if mode in ("contact", "stuck"):
        return
    x = me.x()
    for theta in np.linspace(0.0, 2 * math.pi, 721):
        x[0], x[1] = theta, speed
        if train:   # the train's end mass 5 cm above the follower pulls it off
            x[5], x[6] = 0.05, 0.0
        me.set_x(x)
        if me.indicators()[1] < 0.0:
            break
    else:
        raise AssertionError(f"the flank holds the follower at every angle at {speed} rad/s")
    me.event()
    if mode == "flight_stuck":
        me.set_u(0.0)
        x = me.x()
        x[1] = -1e-9
        me.set_x(x)
        me.event()


def random_follower_state(me, rng: np.random.Generator, mode: str, clearance: float) -> None:
    """A random state in `mode`: random_states' cam side (at rest in the stuck modes), in flight a gap within 0.1..1.9
    of the clearance (1 mm for a spring) and a rate within +-5 cm/s."""
    x = me.x()
    x[0] = rng.uniform(0.0, 2 * math.pi)
    x[1] = 0.0 if mode in ("stuck", "flight_stuck") else rng.uniform(5.0, 40.0)
    x[2] = rng.uniform(0.05, 0.3)
    x[3] = rng.uniform(-2e-4, 2e-4)
    x[4] = x[1] + rng.uniform(-2.0, 2.0)
    if mode.startswith("flight"):
        x[NX - 2] = rng.uniform(0.1, 1.9) * clearance
        x[NX - 1] = rng.uniform(-0.05, 0.05)
    me.set_x(x)
    me.set_u(rng.uniform(1.0, 5.0))


def assert_follower_mode(x: np.ndarray, dx: np.ndarray, mode: str) -> None:
    """The FMU's derivatives say the mode: in flight der(x_gap) = x_gap_rate, on a flank the gap's slots held; stuck
    (on a flank or under the flying follower) the cam's angle and speed held."""
    if mode.startswith("flight"):
        assert dx[NX - 2] == x[NX - 1] != 0.0
    else:
        assert dx[NX - 2] == dx[NX - 1] == 0.0
    if mode in ("stuck", "flight_stuck"):
        assert dx[0] == dx[1] == 0.0
    else:
        assert dx[0] == x[1] != 0.0


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

    def draw() -> None:
        random_states(me, rng, stuck)

    def mode_holds(analytic: np.ndarray) -> None:
        if case in FOLLOWER:   # the mode the case is named for: the gap's rate moves the gap only in flight
            gap_by_rate = analytic[[row[0] for row in STATES].index("x_gap"), NX - 1]
            assert gap_by_rate == (1.0 if case in FLIGHT else 0.0), (case, gap_by_rate)
        assert np.abs(analytic).max() > 0.0

    try:
        assert_matches_differences(me, case, draw, mode_holds)
    finally:
        me.close()


def assert_matches_differences(me: Me, case: str, draw, check_analytic) -> None:
    """At 4 of up to 40 states that draw() sets, where differences at two steps agree (away from events and
    breakpoints): the analytic Jacobian against them to RTOL of each row's largest entry, and check_analytic on it."""
    checked = 0
    for _ in range(40):
        draw()
        fd = smooth_differences(me)
        if fd is None:
            continue
        analytic = me.jacobian()
        check_analytic(analytic)
        scale = np.abs(fd).max(axis=1, keepdims=True)
        err = np.abs(analytic - fd)
        assert np.all(err <= RTOL * scale + 1e-12), (case, np.argwhere(err > RTOL * scale + 1e-12))
        checked += 1
        if checked == 4:
            return
    raise AssertionError(f"{case}: fewer than 4 states away from events and breakpoints")


@pytest.mark.parametrize("case", list(FOLLOWER_CASES))
def test_follower_of_its_own_derivatives_match_central_differences(engine_fmu_path, case):
    """A follower of its own in each mode (reached by the FMU's own event updates), at 4 random states away from
    events and breakpoints: the analytic Jacobian of the state derivatives (the gap's too) and outputs by the states
    and u agrees with central differences of fmi2GetDerivatives / fmi2GetReal to 1e-6 relative (of each row's largest
    entry); in flight with the cam moving the gap rate's row is not zero."""
    start, mode, speed = FOLLOWER_CASES[case]
    rng = np.random.default_rng(11)
    me = Me(engine_fmu_path, start)
    def draw() -> None:
        random_follower_state(me, rng, mode, start.get("c", 1e-3))   # an arm's gap too: m along its roller's arc
        assert_follower_mode(me.x(), me.f()[:NX], mode)

    def moving(analytic: np.ndarray) -> None:
        assert np.abs(analytic[NX - 1 if mode == "flight" else slice(None)]).max() > 0.0

    try:
        enter_follower_mode(me, mode, speed, start.get("k_train", 0.0) + start.get("k_train_arm", 0.0) > 0.0)
        assert_matches_differences(me, case, draw, moving)
    finally:
        me.close()


def test_model_structure_lists_what_a_sparsity_probe_finds(engine_fmu_path):
    """The <Derivatives>/<Outputs> dependencies of modelDescription.xml hold every state and input that central
    differences of the FMU's derivatives and outputs move, over every case at random states (a follower of its own on
    its flank and in flight among them), and no more. fmpy's validation is clean and the FMU says it provides
    directional derivatives."""
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(engine_fmu_path)) == []
    md = fmpy.read_model_description(str(engine_fmu_path))
    assert md.modelExchange.providesDirectionalDerivative
    listed = {u.variable.name: {d.name for d in u.dependencies} for u in md.derivatives + md.outputs}
    for u in md.derivatives + md.outputs:
        assert u.dependenciesKind == ["dependent"] * len(u.dependencies)
    rng = np.random.default_rng(7)
    found: dict[str, set] = {name: set() for name in listed}
    for case, start in CASES.items():
        me = Me(engine_fmu_path, start)
        names = [f"der({row[0]})" for row in STATES] + [row[0] for row in OUTPUTS]
        knowns = [row[0] for row in STATES] + ["u"]
        for _ in range(3):
            random_states(me, rng, start.get("omega0", 1.0) == 0.0)
            fd = me.central(1e-6)
            scale = np.maximum(np.abs(fd).max(axis=1, keepdims=True), 1e-300)
            for r, c in np.argwhere(np.abs(fd) > 1e-9 * scale):
                found[names[r]].add(knowns[c])
        me.close()
    for start, mode, speed in FOLLOWER_CASES.values():   # and in every mode the event updates reach
        me = Me(engine_fmu_path, start)
        enter_follower_mode(me, mode, speed, start.get("k_train", 0.0) + start.get("k_train_arm", 0.0) > 0.0)
        for _ in range(3):
            random_follower_state(me, rng, mode, start.get("c", 1e-3))
            fd = me.central(1e-6)
            scale = np.maximum(np.abs(fd).max(axis=1, keepdims=True), 1e-300)
            for r, c in np.argwhere(np.abs(fd) > 1e-9 * scale):
                found[names[r]].add(knowns[c])
        me.close()
    for name in listed:
        assert found[name] == listed[name], (name, found[name] ^ listed[name])


def refusal(me: Me, unknowns: list, knowns: list, logged: list) -> str:
    """The message of a refused fmi2GetDirectionalDerivative (fmi2Error), with the unknowns' values."""
    with pytest.raises(FMICallException) as info:
        me.model.getDirectionalDerivative(unknowns, knowns, [1.0] * len(knowns))
    assert info.value.status == 3
    return logged[-1]


def collecting_callbacks(messages: list):
    """fmi2 callbacks of this test's own that collect the log: fmpy's defaultCallbacks call freed memory once an
    earlier test in the process ran simulate_fmu with a logger (tests/fmu_cs/test_fmu_interface.py)."""
    from fmpy.fmi2 import (calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                           fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free)

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(lambda _e, _n, _s, _c, text: messages.append(text.decode()))
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    return callbacks


def logging_me(fmu, start: dict) -> tuple[Me, list]:
    messages: list[str] = []
    callbacks = collecting_callbacks(messages)
    original = FMU2Model.instantiate
    FMU2Model.instantiate = lambda self, **kw: original(self, callbacks=callbacks, **kw)
    try:
        me = Me(fmu, start)
    finally:
        FMU2Model.instantiate = original
    me.callbacks = callbacks   # kept alive with the instance
    return me, messages


def test_bad_requests_are_errors_with_the_reason(engine_fmu_path):
    """An unknown value reference, a parameter as a known, an output or state as an unknown of the wrong kind:
    fmi2Error and the reason in the log, never a zero that looks like a derivative."""
    me, logged = logging_me(engine_fmu_path, {"omega0": 20.0})
    try:
        der_omega, x_theta = me.vr["der(x_omega)"], me.vr["x_theta"]
        assert "value reference 99999 ('no variable') is no known" in refusal(me, [der_omega], [99999], logged)
        assert "('R') is no known (a continuous state or input)" in refusal(me, [der_omega], [me.vr["R"]], logged)
        assert "('x_theta') is no unknown (a state derivative or output)" in refusal(me, [x_theta], [x_theta], logged)
        assert "('u') is no unknown" in refusal(me, [me.vr["u"]], [x_theta], logged)
        good = me.model.getDirectionalDerivative([der_omega], [me.vr["u"]], [1.0])[0]
        assert good > 0.0   # more voltage, more acceleration: the same call answers once the request is right
    finally:
        me.close()
    # a follower of its own answers (jacobian_follower.c) and refuses the same bad requests
    me, logged = logging_me(engine_fmu_path, {"omega0": 20.0, "closure": "spring"})
    try:
        der_omega = me.vr["der(x_omega)"]
        assert "value reference 99999 ('no variable') is no known" in refusal(me, [der_omega], [99999], logged)
        assert "('x_gap') is no unknown" in refusal(me, [me.vr["x_gap"]], [me.vr["x_gap"]], logged)
        assert me.model.getDirectionalDerivative([der_omega], [me.vr["u"]], [1.0])[0] > 0.0
    finally:
        me.close()


def test_outside_model_exchange_is_an_error(engine_fmu_path):
    """Before initialisation and in a co-simulation instance the call is refused with the reason."""
    md = fmpy.read_model_description(str(engine_fmu_path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    model = FMU2Model(guid=md.guid, unzipDirectory=fmpy.extract(str(engine_fmu_path)), modelIdentifier="cam",
                      instanceName="early")
    messages: list[str] = []
    callbacks = collecting_callbacks(messages)
    model.instantiate(callbacks=callbacks)
    with pytest.raises(FMICallException):
        model.getDirectionalDerivative([vr["der(x_omega)"]], [vr["x_theta"]], [1.0])
    assert any(text.startswith("fmi2GetDirectionalDerivative: ") for text in messages)
    model.freeInstance()
    from fmpy.fmi2 import FMU2Slave

    slave = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(str(engine_fmu_path)), modelIdentifier="cam",
                      instanceName="cs")
    slave.instantiate(callbacks=callbacks)
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.exitInitializationMode()
    with pytest.raises(FMICallException):
        slave.getDirectionalDerivative([vr["omega"]], [vr["u"]], [1.0])
    assert "co-simulation" in messages[-1]
    slave.terminate()
    slave.freeInstance()
