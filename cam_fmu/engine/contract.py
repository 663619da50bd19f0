"""The engine's contract with its callers, as data: the one source of what C and Python must agree on.

``codegen.py`` writes it into C (``cam_contract.h``/``.c``: the state slots, the event codes and their names, the
saved state's layout and format version, the structures a binding reads, the error statuses), and
``simulator.py`` builds its ctypes structures and slot numbers from the same tables, so nothing is copied from a
C header by hand. The model's parameters, variables and cross-parameter rules are ``physics/`` (parameters.py,
variables.py, rules.py); the event names are the hybrid system's (physics/formulations/consistent.py).
"""
from __future__ import annotations

import ctypes
from functools import lru_cache

from ..physics.formulations.consistent import EVENT_NAMES
from ..physics.train import G_N
from ..physics.variables import STATES

# The continuous state x (cam_model.h): C slot name and its Model Exchange variable (physics.variables.STATES, in
# order). A rigid drive carries the first NX_RIGID; a compliant shaft adds its twist and the motor's speed, a follower
# train (docs/model.md 14.6) its end mass's position and velocity (a drive with either carries all NX).
X_SLOTS: tuple[tuple[str, str], ...] = (("THETA", "x_theta"), ("OMEGA", "x_omega"), ("CURRENT", "x_i"),
                                        ("TWIST", "x_twist"), ("OMEGA_M", "x_omega_m"), ("X_END", "x_end"),
                                        ("V_END", "x_v_end"), ("GAP", "x_gap"), ("RATE", "x_gap_rate"))
NX = len(X_SLOTS)
# The last two slots are the voltage drive's follower of its own (docs/model.md 13.6): its gap to the flank it left last
# and the gap's rate, held at 0 on a flank and without a follower of its own. Co-simulation and Model Exchange carry
# this one vector (a compliant shaft or a train carries the first NX_SHAFT slots, a follower of its own all NX).
NX_RIGID = 3
NX_SHAFT = 7
MAX_EVENTS = 4          # event functions a mode has active at once at most (cam_event_codes)
MESSAGE_LEN = 1024      # bytes of an error's message

# The error statuses (cam_error.h): C name, value, what Python raises (engine/simulator.py raise_for), meaning.
STATUSES: tuple[tuple[str, int, str, str], ...] = (
    ("CAM_OK", 0, "", "done"),
    ("CAM_ERR_PARAMETER", 1, "ParameterError", "a parameter outside its range, or parameters that contradict"),
    ("CAM_ERR_SIMULATION", 2, "SimulationError", "the run cannot go on correctly (FMI: Error)"),
    ("CAM_ERR_REJECTED", 3, "StepRejected", "this step cannot be done at this size, state as before (FMI: Discard)"),
    ("CAM_ERR_MEMORY", 4, "MemoryError", "an allocation failed"),
)

# The saved state (cam_drive.h cam_drive_get_state): a flat array of doubles, its entries in this order, each a
# name and how many doubles; STATE_LEN leaves room for entries a later version adds. Bump STATE_VERSION whenever
# the layout changes: a state of another layout is refused by its version.
STATE_VERSION = 4.0     # 2: the compliant shaft's two slots in x; 3: the train's end mass's two; 4: the follower's
# gap and rate in x, its flank left and flight direction in the mode
STATE_LEN = 64
STATE_LAYOUT: tuple[tuple[str, int], ...] = (
    ("VERSION", 1), ("FORMULATION", 1), ("TIME", 1), ("U", 1), ("OMEGA_REF", 1), ("OMEGA_DOT_REF", 1),
    ("H_NEXT", 1), ("STEPS_TAKEN", 1), ("X", NX),
    ("STUCK", 1), ("DIRECTION", 1), ("CONTACT", 1), ("S_FREE", 1), ("SIDE", 1), ("LEFT", 1), ("SIGMA", 1),   # mode
    ("FORM_U", 1), ("HAVE_BUDGET", 1),
    ("WORK_IN", 1), ("WORK_ABS", 1), ("BUDGET_THETA", 1), ("BUDGET_I", 1), ("E_MECH0", 1), ("E_MAG0", 1),
    ("PAPER", 11),      # CamPaperState in order: theta, omega, i, J, M, s, v, a, alpha, voltage, M_l
    ("SPEED", 8),       # CamSpeedState in order: theta, s, speed, v, contact, impacts, rebound, fresh
)

# The structures a binding reads (C type, field, comment): written as C typedefs, built as ctypes.Structure.
STRUCTS: dict[str, tuple[tuple[str, str, str], ...]] = {
    "CamMode": (   # the discrete mode (physics.formulations.consistent.Mode)
        ("int", "stuck", "1: the shaft is held by static friction"),
        ("double", "direction", "+1/-1: sgn(omega) while moving (the trial direction at rest)"),
        ("CamFlank", "contact", "the follower on the lower flank (+1: the cam drives it along +X), the upper (-1), in "
                                "flight or free in a backlash's gap (0); +1 without a clearance"),
        ("double", "s_free", "m: the follower's position while contact == 0"),
        ("double", "side", "+1/-1: sign of the guide's side force N_r (the friction branch)"),
        ("CamFlank", "left", "a follower of its own: the flank it left last (+1, -1), its gap's origin"),
        ("double", "sigma", "a follower of its own in flight: sgn(v) held between events (0: halted by friction)"),
    ),
    "CamEventRecord": (   # one transition, as the event log keeps it (not part of the saved state)
        ("int", "code", "CAM_EV_*"),
        ("double", "time", "s"),
        ("double[CAM_NX]", "x_before", "the state before"),
        ("double[CAM_NX]", "x_after", "and after"),
        ("CamMode", "mode_before", "the mode before"),
    ),
    "CamLaw": (   # one dimensionless law (cam_profile.h): its non-empty segments, CAM_SEGMENT_FIELDS doubles each
        ("double[CAM_LAW_SEGMENTS * CAM_SEGMENT_FIELDS]", "segments", "end, start, F, c, kind, V0, S0 per segment"),
        ("int", "n_segments", "non-empty segments"),
    ),
    "CamTable": (   # a user's motion table after parsing: the knots of its periodic interpolant (cam_profile.h)
        ("double*", "angle", "rad, strictly increasing, in [0, 2 pi); the one allocation, owned"),
        ("double*", "lift", "m"),
        ("double*", "slope", "m/rad: Hermite slopes at the knots"),
        ("double*", "width", "rad: piece widths, > 0"),
        ("double*", "c2", "m/rad^2: half s'' at a piece's start (right limit)"),
        ("double*", "e2", "m/rad^2: half s'' at a piece's end (left limit)"),
        ("double*", "c3", "m/rad^3: a sixth of s''', constant on a piece"),
        ("size_t", "n", "knots = pieces"),
    ),
    "CamProfile": (   # the cam program (cam_profile.h): two laws and dwells, or a motion table
        ("CamProgramKind", "kind", "CAM_PROGRAM_LAWS or CAM_PROGRAM_TABLE"),
        ("CamLaw", "rise", "laws: the rise"), ("CamLaw", "ret", "and the return"),
        ("double", "lift", "m"),
        ("double", "b1", "rad: end of rise"), ("double", "b2", "rad: of upper dwell"),
        ("double", "b3", "rad: of return"),
        ("double", "kr0", "1/beta of the rise"), ("double", "kr1", "h/beta"), ("double", "kr2", "h/beta^2"),
        ("double", "kr3", "h/beta^3"),
        ("double", "kd0", "the same of the return"), ("double", "kd1", ""), ("double", "kd2", ""),
        ("double", "kd3", ""),
        ("CamTable", "table", "a table program's interpolant"),
        ("double*", "points", "rad, ascending in [0, 2 pi): the breakpoints (laws: owned; a table: table.angle)"),
        ("size_t", "n_points", "breakpoints"),
        ("double", "feature_angle", "rad: the program's finest angular detail (as the Python programs')"),
    ),
    "CamError": (   # the one error path (cam_error.h): a status and its message
        ("CamStatus", "status", "CAM_OK or the refusal's CAM_ERR_*"),
        ("char[CAM_MESSAGE_LEN]", "message", "what is wrong and what to change"),
    ),
}


def state_slots() -> dict[str, int]:
    """Name -> index of each saved-state entry (its first double), and END: the entries' count."""
    slots, at = {}, 0
    for name, count in STATE_LAYOUT:
        slots[name] = at
        at += count
    slots["END"] = at
    assert at <= STATE_LEN, "STATE_LEN must cover the layout"
    return slots


def event_names() -> tuple[str, ...]:
    """The event codes' names, code k the k-th (CAM_EV_*; physics/formulations/consistent.py EVENT_NAMES)."""
    return EVENT_NAMES


def event_c_name(name: str) -> str:
    """An event's C code name (CAM_EV_STOP)."""
    return "CAM_EV_" + "".join(ch if ch.isalnum() else "_" for ch in name).upper()


LAW_SEGMENTS, SEGMENT_FIELDS = 7, 7   # segments of one law; doubles per segment
# The constants the structures' array sizes name, and the enumerations they use (C name, value).
CONSTANTS = {"CAM_NX": NX, "CAM_MESSAGE_LEN": MESSAGE_LEN, "CAM_LAW_SEGMENTS": LAW_SEGMENTS,
             "CAM_SEGMENT_FIELDS": SEGMENT_FIELDS,
             "CAM_G_N": G_N}   # m/s2: standard gravity, the end mass's weight (physics/train.py)
ENUMS: dict[str, tuple[tuple[str, int], ...]] = {
    "CamProgramKind": (("CAM_PROGRAM_LAWS", 0), ("CAM_PROGRAM_TABLE", 1)),
    # where the follower is (physics/modes.py Follower; docs/model.md 13.7), its value the flank's sign along X:
    # a flying follower held by the guide's friction is CAM_IN_FLIGHT with CamMode.sigma 0 (halted)
    "CamFlank": (("CAM_ON_UPPER_FLANK", -1), ("CAM_IN_FLIGHT", 0), ("CAM_ON_LOWER_FLANK", 1)),
}
_CTYPES = {"int": ctypes.c_int, "double": ctypes.c_double, "char": ctypes.c_char, "size_t": ctypes.c_size_t,
           "double*": ctypes.POINTER(ctypes.c_double), "CamStatus": ctypes.c_int, "CamProgramKind": ctypes.c_int,
           "CamFlank": ctypes.c_int}


def _ctype(c_type: str) -> type:
    base, _, count = c_type.partition("[")
    kind = _CTYPES.get(base) or structure(base)
    if not count:
        return kind
    size = 1
    for factor in count.rstrip("]").split("*"):
        size *= CONSTANTS[factor.strip()]
    return kind * size


@lru_cache(maxsize=None)
def structure(name: str) -> type:
    """The ctypes.Structure of STRUCTS[name], its fields as the C typedef has them."""
    fields = [(field, _ctype(c_type)) for c_type, field, _ in STRUCTS[name]]
    return type(name, (ctypes.Structure,), {"_fields_": fields, "__doc__": f"cam_contract.h {name}."})


def check_states() -> None:
    """X_SLOTS name Model Exchange's states, in order (physics.variables.STATES)."""
    assert [s[1] for s in X_SLOTS] == [row[0] for row in STATES], "X_SLOTS and physics.variables.STATES"
