"""Every parameter of the cam drive: name, SI unit, default, allowed range, meaning.

This table is the single source of truth: the scene files, the reference
integration, the FMU variables and the docs (docs/scenes.md, docs/fmu.md) all use these names and units.
Only ``math`` is imported here: ``engine/codegen.py`` generates the C engine's table from it at build time.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

from ..kinematics.follower_types import FOLLOWER_TYPES
from ..kinematics.presets import PRESETS
from .units import UnitError, to_si

KGF = 9.80665  # N per kgf: the paper's c_m = 0.015 is in kgf m/A (docs/model.md section 3)
PAPER_A = 0.035  # m, the paper's profile constant A
# A sine or cosine of a mounting angle (gamma, beta) at most MOUNTING_ZERO * max(1, |angle|) in magnitude is
# exactly 0: the angle is a multiple of 90 deg to within a few of its rounding units (sin(pi) = 1.2e-16 in
# doubles is no force; docs/model.md section 4.1). 4 x 2^-52.
MOUNTING_ZERO = 4.0 * 2.220446049250313e-16


def mounting_component(value: float, angle: float) -> float:
    """sin or cos ``value`` of the mounting angle ``angle`` [rad], 0 where the angle makes it 0 (MOUNTING_ZERO)."""
    return 0.0 if abs(value) <= MOUNTING_ZERO * max(1.0, abs(angle)) else value


class ParameterError(ValueError):
    """A parameter value outside its allowed range; the message names both."""


@dataclass(frozen=True)
class ParameterSpec:
    """One parameter. ``kind`` is 'real', 'boolean' or 'string'."""

    name: str
    unit: str
    default: Any
    description: str
    kind: str = "real"
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False  # True: the lower bound itself is not allowed
    zero_ok: bool = False  # True: 0 is allowed besides [low, high] (0 switches the quantity off)
    choices: tuple[str, ...] = ()

    def allowed(self) -> str:
        """Human-readable allowed range, as used in error messages."""
        if self.kind == "boolean":
            return "true or false"
        if self.kind == "string":
            if not self.choices:  # a free string (motion_table): its content is checked where it is used
                return "any text (\"\" = not used)" if self.default == "" else "any text"
            return "one of " + ", ".join(repr(c) for c in self.choices)
        left = "(" if self.low_open else "["
        zero = "0 or " if self.zero_ok else ""
        return f"{zero}{left}{self.low:g}, {self.high:g}]" + (f" {self.unit}" if self.unit not in ("", "1") else "")

    def check(self, value: Any) -> Any:
        """Return the value converted to its kind, or raise ParameterError. A real given as text may carry a unit of
        its quantity ('600rpm', '0.5 mm': physics/units.py); it is returned in the parameter's SI unit."""
        if self.kind == "boolean":
            if isinstance(value, str):
                if value.lower() in ("true", "1", "yes", "on"):
                    return True
                if value.lower() in ("false", "0", "no", "off"):
                    return False
                raise ParameterError(f"parameter {self.name!r} = {value!r}: allowed {self.allowed()}")
            return bool(value)
        if self.kind == "string":
            text = str(value)
            if self.choices and text not in self.choices:
                raise ParameterError(f"parameter {self.name!r} = {value!r}: allowed {self.allowed()}")
            return text
        try:
            number = to_si(self.name, self.unit, value) if isinstance(value, str) else float(value)
        except UnitError as exc:
            raise ParameterError(f"parameter {self.name!r} = {value!r}: {exc}") from None
        except (TypeError, ValueError):
            raise ParameterError(f"parameter {self.name!r} = {value!r} is not a number: allowed {self.allowed()}") from None
        too_low = number <= self.low if self.low_open else number < self.low
        if self.zero_ok and number == 0.0:
            return 0.0
        if not math.isfinite(number) or too_low or number > self.high:
            given = f" (given {value!r})" if isinstance(value, str) and not _plain_number(value) else ""
            raise ParameterError(f"parameter {self.name!r} = {number!r} [{self.unit}]{given} is outside the allowed "
                                 f"range {self.allowed()}")
        return number


def _plain_number(text: str) -> bool:
    """True where ``text`` is a number without a unit."""
    try:
        float(text)
    except ValueError:
        return False
    return True


LAW_CHOICES = (*PRESETS, "custom")  # derived from the one preset table
# Checked against the registries (physics.formulations.FORMULATIONS, solvers.SOLVERS) by tests/tools/test_layout.py.
FORMULATIONS = ("consistent", "paper")
DRIVES = ("voltage", "speed")
SOLVERS = ("euler", "rk4", "rk45", "etdrk4", "rk23")
# The choices that model a rigid drive-train only: k_shaft > 0 with one of them is refused, with the reason and
# what to use instead (docs/model.md section 12.1).
RIGID_ONLY: dict[tuple[str, str], tuple[str, str]] = {
    ("drive", "speed"): ("the speed drive imposes the cam's speed on a rigid drive-train", ""),
    ("formulation", "paper"): ("the paper's algorithm models a rigid drive-train", " (use formulation 'consistent')"),
    ("solver", "etdrk4"): ("solver 'etdrk4' integrates the rigid drive's electrical pole", " (use solver 'rk45')"),
}
EFFECTS = ("shaft_friction", "guide_friction", "gravity", "follower_inertia", "backlash", "inductance")

_P = ParameterSpec
_MODEL = (
    _P("R", "Ohm", 19.0, "armature resistance", low=1e-3, high=1e4),
    _P("L", "H", 0.0, "armature inductance (0: neglected, as in the paper)", low=1e-9, high=10.0, zero_ok=True),
    _P("c_e", "V/(rad/s)", 0.146, "back-EMF constant", low=1e-6, high=100.0),
    _P("c_m", "N.m/A", 0.015 * KGF, "torque constant (the paper's 0.015 is kgf m/A)", low=1e-6, high=100.0),
    _P("J_m", "kg.m2", 4.41e-5, "motor rotor and encoder inertia (rigid shaft: the cam's too, or J_cam)", low=1e-9, high=100.0),
    _P("J_cam", "kg.m2", 0.0, "cam and cam-shaft inertia (rigid shaft: added to J_m; compliant: the cam side, > 0)", low=0.0, high=100.0),
    _P("k_shaft", "N.m/rad", 0.0, "torsional stiffness of the shaft between rotor and cam (0: rigid, docs/model.md section 12)", low=1e-6, high=1e9, zero_ok=True),
    _P("d_shaft", "N.m.s/rad", 0.0, "torsional damping of that shaft (used only with k_shaft > 0)", low=0.0, high=1e6),
    _P("M_f", "N.m", 0.012, "shaft friction torque (Coulomb)", low=0.0, high=1e3),
    _P("m", "kg", 0.4, "follower mass", low=0.0, high=1e4),
    _P("G", "N", 4.0, "follower weight", low=0.0, high=1e5),
    _P("mu", "1", 0.001, "guide friction coefficient (another follower type: its face's sliding or its arm's pivot, "
       "docs/model.md 16)", low=0.0, high=0.5),
    _P("gamma", "rad", math.pi, "angle of gravity to Z (pi: horizontal mounting)", low=-2 * math.pi, high=2 * math.pi),
    _P("beta", "rad", 0.0, "angle of gravity's XY component to the rise direction X", low=-2 * math.pi, high=2 * math.pi),
    _P("r_b", "m", 0.1, "base-circle radius (keeps the paper profile's pressure angle under 30 deg)", low=1e-4, high=10.0),
    _P("c", "m", 0.0, "clearance of the follower (backlash half-width, paper eqs. 6-8)", low=0.0, high=0.1),
    _P("theta0", "rad", 0.0, "initial cam angle", low=-1e6, high=1e6),
    _P("omega0", "rad/s", 0.0, "initial angular velocity", low=-1e4, high=1e4),
    _P("i0", "A", 0.0, "initial armature current (used only with L > 0)", low=-1e3, high=1e3),
)

_PROGRAM = (
    _P("rise_law", "", "paper", "motion law of the rise: a preset name or 'custom' (then rise_T1..rise_T6)", kind="string", choices=LAW_CHOICES),
    *(_P(f"rise_T{k}", "1", v, f"split point T{k} of a custom rise law", low=0.0, high=1.0)
      for k, v in enumerate((0.125, 0.125, 0.25, 0.75, 0.875, 0.875), start=1)),
    _P("return_law", "", "paper", "motion law of the return: a preset name or 'custom' (then return_T1..return_T6)", kind="string", choices=LAW_CHOICES),
    *(_P(f"return_T{k}", "1", v, f"split point T{k} of a custom return law", low=0.0, high=1.0)
      for k, v in enumerate((0.125, 0.125, 0.25, 0.75, 0.875, 0.875), start=1)),
    _P("lift", "m", 1.5 * math.pi * PAPER_A, "lift h (paper: 3 pi A / 2 with A = 35 mm)", low=1e-6, high=10.0),
    _P("rise_angle", "rad", math.pi, "cam angle of the rise", low=1e-3, high=2 * math.pi),
    _P("upper_dwell", "rad", 0.0, "cam angle of the upper dwell", low=0.0, high=2 * math.pi),
    _P("return_angle", "rad", math.pi, "cam angle of the return", low=1e-3, high=2 * math.pi),
    _P("lower_dwell", "rad", 0.0, "cam angle of the lower dwell", low=0.0, high=2 * math.pi),
    _P("motion_table", "", "", "a user motion table as CSV text 'angle_deg,lift_mm' (optional header line; "
       "shape-preserving periodic cubic, docs/cam_design.md; when given, the laws, lift and angles above are not used)", kind="string"),
)

_MODE = (
    _P("formulation", "", "consistent", "'consistent' (energy-consistent, docs/model.md section 5) or 'paper' (published steps 1-9)", kind="string", choices=FORMULATIONS),
    _P("drive", "", "voltage", "'voltage': u(t) is the input; 'speed': omega_ref(t) is imposed", kind="string", choices=DRIVES),
    *(_P(name, "", True, f"model the {name.replace('_', ' ')} (false: the effect is off and costs nothing)", kind="boolean")
      for name in EFFECTS),
)

_SOLVER = (
    _P("solver", "", "rk45", "integrator: 'euler', 'rk4' (fixed step), 'rk45' (adaptive Dormand-Prince), 'etdrk4' (exponential RK4, exact on the electrical pole), 'rk23' (adaptive Bogacki-Shampine 3(2): half rk45's stages a step, for loose tolerances); each runs a follower of its own in either drive (docs/model.md 13.6; the speed drive's rigid follower is a closed form and takes none)", kind="string", choices=SOLVERS),
    _P("h_max", "s", 1e-3, "largest internal step (fixed-step solvers: the internal step; the speed drive's only with a "
       "follower of its own, docs/model.md 13.4)",
       low=1e-9, high=10.0),
    _P("rtol", "1", 1e-10, "relative tolerance of 'rk45' and 'rk23' (the speed drive's only with a follower of its own or a "
       "train)", low=1e-14, high=0.1),
    _P("atol", "1", 1e-12, "absolute tolerance of 'rk45' (on rad, rad/s, A; not used where rtol is not)",
       low=1e-16, high=1.0),
    _P("max_steps", "1", 10000.0, "most internal steps in one communication step before an error is reported (a stiff pole or a huge step: see etdrk4); bounds the work of one step", low=1.0, high=1e6),
)

# How the follower is held on the cam (docs/model.md section 13). 'form' (the default) is a two-sided groove whose
# follower flies across the clearance c; 'kinematic' the paper's rule, where it rests in the clearance until a flank
# takes it along (eqs. 6-8).
CLOSURES = ("kinematic", "form", "spring")
FOLLOWER_DRIVES = ("speed",)  # the drives computing closures 'form' and 'spring' with every effect (docs/model.md 13)
VOLTAGE_FOLLOWER_FORMULATIONS = ("consistent",)  # the voltage drive's formulations with a follower of its own (13.6)
# The follower as a body of its own (the speed drive and the consistent voltage drive compute closures 'form' and
# 'spring', the voltage drive with guide friction and a rigid or compliant shaft, from rest or turning; docs/model.md 13
# and 13.6).
FOLLOWER_PARAMETERS: tuple[ParameterSpec, ...] = (
    _P("closure", "", "form", "how the follower is held: 'form' (the default: a groove; with a clearance c > 0 the "
       "follower of mass m flies across it under gravity, friction and its momentum and strikes the other flank; "
       "c = 0, m = 0 or follower_inertia false, or the paper's formulation (its eqs. 6-8): the kinematic rule, bit for "
       "bit), 'kinematic' (the paper's rule, eqs. 6-8, in any formulation: the follower rests in the clearance until a "
       "flank takes it along), 'spring' (one flank and a return spring k_spring, F_spring0; c = 0, m > 0). A flight: "
       "speed drive, and voltage drive (consistent, solver 'rk45' with its tolerances; docs/model.md 13)",
       kind="string", choices=CLOSURES),
    _P("k_spring", "N/m", 0.0, "rate of the return spring (closure 'spring')", low=0.0, high=1e9),
    _P("F_spring0", "N", 0.0, "preload of the return spring at s = 0 (closure 'spring')", low=0.0, high=1e6),
    _P("restitution", "1", 0.0, "coefficient of restitution of the follower's impacts on the cam (closures 'form' and "
       "'spring'; 0: plastic, 1: elastic)", low=0.0, high=1.0),
)
# The follower train (docs/model.md 14.6): a spring-damper from the follower to an end mass, carried along X. The
# drive runs it with the follower on the cam (closure 'kinematic', or 'form' without clearance) in the speed drive
# and in the consistent voltage drive without friction, clearance or compliant shaft (physics/rules.py says why).
TRAIN_PARAMETERS: tuple[ParameterSpec, ...] = (
    _P("k_train", "N/m", 0.0, "stiffness of the follower train between the follower and its end mass m_end (0: no "
       "train, the rigid drive; docs/model.md 14.6)", low=0.0, high=1e12),
    _P("d_train", "N.s/m", 0.0, "damping of the follower train (used only with k_train > 0)", low=0.0, high=1e9),
    _P("m_end", "kg", 0.0, "the train's end mass, moved by the train along X (used only with k_train > 0: a rigid "
       "train's mass belongs in m)", low=0.0, high=1e4),
)
# The follower's kind (docs/model.md 16): translating or oscillating, roller or flat face; an arm's data. The same
# names, defaults and ranges as physics/follower_kind.py's FollowerKind (0 for the three an arm needs: not set; the
# rules refuse an arm without them, and any of them set on a translating follower, naming the type).
FOLLOWER_KIND_PARAMETERS: tuple[ParameterSpec, ...] = (
    _P("follower_type", "", "translating_roller", "the follower: 'translating_roller' (the paper's), "
       "'translating_flat', 'oscillating_roller' (an arm about a pivot with a roller; its pitch curve, r_roller = 0), "
       "'oscillating_flat' (an arm with a flat face); docs/model.md 16", kind="string", choices=FOLLOWER_TYPES),
    _P("arm_length", "m", 0.0, "an oscillating follower's arm L, pivot to the roller centre or the face's reference "
       "point (0: not set; needed by the oscillating types)", low=0.0, high=10.0, low_open=True, zero_ok=True),
    _P("pivot_distance", "m", 0.0, "an oscillating follower's pivot distance d from the cam axis (0: not set; needed "
       "by the oscillating types)", low=0.0, high=20.0, low_open=True, zero_ok=True),
    _P("lift_angle", "rad", 0.0, "an oscillating follower's swing: psi = lift_angle s / lift, in (0, pi) (0: not "
       "set; needed by the oscillating types)", low=0.0, high=math.nextafter(math.pi, 0.0), low_open=True,
       zero_ok=True),   # below pi: an arm cannot swing half a turn
    _P("J_arm", "kg.m2", 0.0, "an oscillating follower's arm about its pivot, without m (which sits at arm_length)",
       low=0.0, high=1e3),
    _P("m_arm", "kg", 0.0, "an oscillating follower's own arm mass (its weight acts at r_cm_arm)", low=0.0, high=1e4),
    _P("r_cm_arm", "m", 0.0, "pivot to the arm's own centre of mass, along the arm", low=-10.0, high=10.0),
    _P("psi_0", "rad", 0.0, "the arm's angle above the horizontal (of the cam's plane) at psi = 0", low=-math.pi,
       high=math.pi),
)
# An oscillating follower's train is torsional (docs/model.md 14.6): a torsion spring-damper from the arm to an end
# inertia J_end, under parameters of their own units (no parameter changes unit with the type).
ARM_TRAIN_PARAMETERS: tuple[ParameterSpec, ...] = (
    _P("k_train_arm", "N.m/rad", 0.0, "an oscillating follower's torsional train stiffness between the arm and its end "
       "inertia J_end (0: no train; docs/model.md 14.6)", low=0.0, high=1e9),
    _P("d_train_arm", "N.m.s/rad", 0.0, "damping of the arm's torsional train (used only with k_train_arm > 0)",
       low=0.0, high=1e6),
    _P("J_end", "kg.m2", 0.0, "the arm's train's end inertia about its own axis (used only with k_train_arm > 0)",
       low=0.0, high=1e3),
)
PARAMETERS: tuple[ParameterSpec, ...] = (_MODEL + _PROGRAM + _MODE + _SOLVER + FOLLOWER_PARAMETERS + TRAIN_PARAMETERS
                                         + FOLLOWER_KIND_PARAMETERS + ARM_TRAIN_PARAMETERS)
BY_NAME: dict[str, ParameterSpec] = {p.name: p for p in PARAMETERS}


def defaults() -> dict[str, Any]:
    """All parameters at their default values."""
    return {p.name: p.default for p in PARAMETERS}


def resolve(overrides: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Defaults updated with ``overrides``, every value checked.

    Raises ParameterError for an unknown name, a value outside its range, or
    program angles that do not sum to 2 pi.
    """
    values = defaults()
    for name, value in (overrides or {}).items():
        if name not in BY_NAME:
            raise ParameterError(f"unknown parameter {name!r}; known: {', '.join(sorted(BY_NAME))}")
        values[name] = BY_NAME[name].check(value)
    total = values["rise_angle"] + values["upper_dwell"] + values["return_angle"] + values["lower_dwell"]
    if abs(total - 2 * math.pi) > 1e-9:
        raise ParameterError(
            "parameters 'rise_angle' + 'upper_dwell' + 'return_angle' + 'lower_dwell' "
            f"= {total!r} rad must equal 2 pi = {2 * math.pi!r} rad (to 1e-9 rad)"
        )
    return values


def law_spec(values: Mapping[str, Any], stroke: str) -> str | tuple[float, ...]:
    """The law of 'rise' or 'return' as a preset name or a 6-tuple of split points."""
    name = values[f"{stroke}_law"]
    if name == "custom":
        return tuple(float(values[f"{stroke}_T{k}"]) for k in range(1, 7))
    return name


def markdown_table() -> str:
    """The docs' parameter table (name, unit, default, allowed, meaning), generated from PARAMETERS."""
    lines = ["| name | unit | default | allowed | description |", "|---|---|---|---|---|"]
    for p in PARAMETERS:
        if p.kind == "real":
            default = f"{p.default:.6g}"
        elif p.kind == "boolean":
            default = "true" if p.default else "false"
        else:
            default = f"`{p.default}`" if p.default else '`""`'
        lines.append(f"| `{p.name}` | {p.unit or '-'} | {default} | {p.allowed().replace('|', '/')} | "
                     f"{p.description.replace('|', '/')} |")
    return "\n".join(lines)
