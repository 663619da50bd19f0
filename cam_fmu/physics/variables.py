"""The drive's inputs and outputs: one table each (name, SI unit, [start,] meaning).

The FMU's variables, its model description, the docs tables, the CSV
headers and every formulation's output record derive from these tuples.
``math``-free and import-free: ``engine/codegen.py`` reads it at build time (the FMU carries the C table).
"""
from __future__ import annotations

from typing import Any

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
    ("J", "kg.m2", "equivalent inertia J_m + J_cam + m (ds/dtheta)^2 (J_m + J_cam while free in the gap)"),
    ("v", "m/s", "follower velocity"),
    ("a", "m/s2", "follower acceleration"),
    ("alpha", "rad", "pressure angle"),
    ("s_cam", "m", "cam profile lift at the contact (before backlash)"),
    ("voltage", "V", "armature voltage: u (voltage drive) or the voltage needed (speed drive)"),
    ("theta_m", "rad", "motor angle (a rigid shaft: theta)"),
    ("omega_m", "rad/s", "motor angular velocity (a rigid shaft: omega)"),
    ("M_shaft", "N.m", "torque of the compliant shaft on the cam, k_shaft twist + d_shaft twist rate (rigid: 0)"),
    ("N_contact", "N", "the cam's normal force on the follower's roller along the contact normal (pressure angle "
     "alpha): > 0 where the cam pushes along the rise, < 0 where a groove's other flank pushes; 0 off the cam or "
     "free in the clearance"),
    ("s_end", "m", "the follower train's end mass position along X (docs/model.md 14.6; without a train: s)"),
    ("v_end", "m/s", "the end mass velocity (without a train: v)"),
    ("a_end", "m/s2", "the end mass acceleration (without a train: a)"),
    ("F_train", "N", "the train's force k_train (s - s_end) + d_train (v - v_end), on the end mass along X (without a "
     "train: 0)"),
    ("psi", "rad", "an oscillating follower's arm angle about its pivot, lift_angle s / lift (docs/model.md 16; 0 for "
     "a translating follower)"),
    ("psi_dot", "rad/s", "the arm's rate psi' omega (0 for a translating follower)"),
    ("psi_end", "rad", "an arm's torsional train: its end inertia's angle, lift_angle s_end / lift (docs/model.md "
     "14.6; without a train: psi; 0 for a translating follower)"),
    ("psi_dot_end", "rad/s", "an arm's train: its end inertia's rate, lift_angle v_end / lift (without a train: "
     "psi_dot; 0 for a translating follower)"),
    ("M_train", "N.m", "an arm's train: its torque k_train_arm (psi - psi_end) + d_train_arm (psi_dot - "
     "psi_dot_end) on the end inertia, F_train lift / lift_angle (0 without a train and for a translating follower)"),
)
# The columns the reference adds for the follower as a body of its own (closures 'form' and 'spring', docs/model.md
# section 13): the engine computes the contact and the count too but publishes neither (not FMU variables).
FOLLOWER_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("contact", "1", "+1 on the flank pushing along the rise, -1 on a groove's other flank, 0 off the cam"),
    ("impacts", "1", "touch-downs so far"),
)
# Allowed range of each input [its unit]: far beyond any real drive, finite so that
# the arithmetic stays finite (a value outside is an error naming the input and the range).
INPUT_RANGES: dict[str, tuple[float, float]] = {
    "u": (-1e4, 1e4),
    "omega_ref": (-1e4, 1e4),
    "omega_dot_ref": (-1e8, 1e8),
}
INPUT_NAMES: tuple[str, ...] = tuple(row[0] for row in INPUTS)
INPUT_STARTS: dict[str, float] = {row[0]: row[2] for row in INPUTS}
OUTPUT_NAMES: tuple[str, ...] = tuple(row[0] for row in OUTPUTS)
UNITS: dict[str, str] = {row[0]: row[1] for row in INPUTS + OUTPUTS}  # type: ignore[operator]
FOLLOWER_UNITS: dict[str, str] = {row[0]: row[1] for row in FOLLOWER_COLUMNS}


def output_record(**values: Any) -> dict[str, float]:
    """Every output, in table order, from keyword values (a missing one is a KeyError; without a train the end mass's
    columns are the follower's s, v, a and F_train = 0 (an arm's psi_end, psi_dot_end its psi, psi_dot, M_train 0), a
    translating follower's psi and psi_dot 0, unless given)."""
    psi, psi_dot = values.get("psi", 0.0), values.get("psi_dot", 0.0)
    rigid = {"s_end": values["s"], "v_end": values["v"], "a_end": values["a"], "F_train": 0.0, "psi": psi,
             "psi_dot": psi_dot, "psi_end": psi, "psi_dot_end": psi_dot, "M_train": 0.0}
    return {name: values[name] if name in values else rigid[name] for name in OUTPUT_NAMES}

# Model Exchange's states: the engine's x[CAM_NX] (engine/contract.py X_SLOTS, in order), whose last two are a free
# follower's gap and its rate (CAM_GAP, CAM_RATE; docs/model.md 13.6), each with
# its derivative variable ``der(<name>)``; value references after the parameters (the co-simulation references
# above stay where they were). The C build checks the count against CAM_ME_NX. A rigid drive carries the first three only: x_twist and x_omega_m are then held
# (derivative 0); x_gap and x_gap_rate are held at 0 in contact and without a follower of its own.
STATES: tuple[tuple[str, str, str, str], ...] = (
    ("x_theta", "rad", "rad/s", "continuous state: the cam angle (= output theta)"),
    ("x_omega", "rad/s", "rad/s2", "continuous state: the cam speed (= output omega)"),
    ("x_i", "A", "A/s", "continuous state: the armature current (held at 0 when L = 0: i is then quasi-static)"),
    ("x_twist", "rad", "rad/s", "continuous state: the shaft's twist theta_m - theta (held at 0 when k_shaft = 0)"),
    ("x_omega_m", "rad/s", "rad/s2", "continuous state: the motor's speed (held when k_shaft = 0: omega_m = omega)"),
    ("x_end", "m", "m/s", "continuous state: the follower train's end mass position (= output s_end; held at 0 "
     "without a train, k_train = 0)"),
    ("x_v_end", "m/s", "m/s2", "continuous state: the end mass velocity (= output v_end; held at 0 without a train)"),
    ("x_gap", "m", "m/s", "continuous state: a free follower's gap to the flank it left last, in flight, along its "
     "path (an arm: the roller's arc L (psi - psi_flank); closures 'form', 'spring'; held at 0 in contact and "
     "without one)"),
    ("x_gap_rate", "m/s", "m/s2", "continuous state: the rate of x_gap (held at 0 in contact and without a free "
     "follower)"),
)
# The outputs that depend directly on an input at a fixed state in Model Exchange, and those inputs: the
# quasi-static current (L = 0) and the voltage follow u, the load torque, the follower's acceleration and
# the contact force follow the cam's acceleration, hence u (tests/fmu_me/test_engine_fmu_me.py measures it both ways).
FEEDTHROUGH: tuple[str, ...] = ("i", "M", "a", "voltage", "N_contact", "a_end")
FEEDTHROUGH_INPUTS: tuple[str, ...] = ("u",)
# Model Exchange's ModelStructure: what each state derivative and output may depend on at a fixed mode (the knowns of
# fmi2GetDirectionalDerivative: the states and the inputs; omega_ref and omega_dot_ref drive no Model Exchange run),
# the union over every drive-train, effect and mode. Probed numerically by tests/fmu_me/test_directional_me.py (central
# differences of the FMU's derivatives and outputs, a follower of its own in flight among the cases), which finds
# exactly these. In flight (voltage_follower_events.c) der(x_gap) = x_gap_rate, and der(x_gap_rate), s and a depend on
# the gap through the spring at the follower's position, and on its rate through a train's damper (the guide's
# friction keeps the flight's direction over the mode); the load M and N_contact never depend on the gap (0 and M_f
# in flight); a train's end mass feels the follower's own gap and rate.
_TRAIN = ("x_end", "x_v_end")     # the train's force pulls the cam's follower (docs/model.md 14.6)
_SHAFT = ("x_theta", "x_omega", "x_i", "x_twist", "x_omega_m", "u")
_CAM = _SHAFT + _TRAIN
_GAP = ("x_gap", "x_gap_rate")   # a follower of its own's (its train's damper takes the gap's rate too)
_FLIGHT = _SHAFT + _GAP
DEPENDENCIES: dict[str, tuple[str, ...]] = {
    "der(x_theta)": ("x_omega",),
    "der(x_omega)": _CAM,
    "der(x_i)": ("x_omega", "x_i", "x_omega_m", "u"),
    "der(x_twist)": ("x_omega", "x_omega_m"),
    "der(x_omega_m)": ("x_omega", "x_i", "x_twist", "x_omega_m", "u"),
    "der(x_end)": ("x_v_end",),
    "der(x_v_end)": ("x_theta", "x_omega") + _TRAIN + _GAP,
    "der(x_gap)": ("x_gap_rate",),
    "der(x_gap_rate)": _FLIGHT + _TRAIN,
    "omega": ("x_omega",),
    "theta": ("x_theta",),
    "s": ("x_theta", "x_gap"),
    "i": ("x_omega", "x_i", "x_omega_m", "u"),
    "M": _CAM,
    "J": ("x_theta",),
    "v": ("x_theta", "x_omega", "x_gap_rate"),
    "a": _FLIGHT + _TRAIN,
    "alpha": ("x_theta",),
    "s_cam": ("x_theta",),
    "voltage": ("u",),
    "theta_m": ("x_theta", "x_twist"),
    "omega_m": ("x_omega", "x_omega_m"),
    "M_shaft": ("x_omega", "x_twist", "x_omega_m"),
    "N_contact": _CAM,
    "s_end": ("x_theta", "x_end", "x_gap"),   # without a train the end is the follower: s's
    "v_end": ("x_theta", "x_omega", "x_v_end", "x_gap_rate"),
    "a_end": _FLIGHT + _TRAIN,
    "F_train": ("x_theta", "x_omega") + _TRAIN + _GAP,
    "psi": ("x_theta", "x_gap"),   # an arm's angle (docs/model.md 16, 16.3; 0 for a translating follower)
    "psi_dot": ("x_theta", "x_omega", "x_gap_rate"),
    "psi_end": ("x_theta", "x_end", "x_gap"),   # an arm's end: its s_end's
    "psi_dot_end": ("x_theta", "x_omega", "x_v_end", "x_gap_rate"),
    "M_train": ("x_theta", "x_omega") + _TRAIN + _GAP,
}
# Model Exchange's event indicators: the CAM_MAX_EVENTS slots of the mode's event functions, then the
# next profile breakpoint (cam_fmu/engine/csrc/fmi/exchange.h; the C build checks the count).
EVENT_INDICATORS = 4
