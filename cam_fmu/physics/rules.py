"""The cross-parameter rules: the combinations of parameters the drive refuses, as data.

One table, two readers: ``check_rules`` interprets it here (``DriveModel`` calls it), and
``engine/codegen.py`` writes it into C (``cam_check_rules`` in the generated ``cam_params.c``, which
``cam_model_init`` calls), message for message. A rule is a condition over the parameters (a small
expression tree: ``value`` evaluates it on resolved parameters, ``c`` writes it over the C array ``v``
of ``CamParams``) and the message of its refusal, whose ``{name}`` fields are the parameters' values
as the messages show them (``repr``: 0.5, 'form'). The first rule that holds refuses. Leaf module
over ``parameters`` (``math`` only). docs/model.md 12.1 and 13; docs/architecture.md.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Mapping

from .parameters import (BY_NAME, FOLLOWER_DRIVES, RIGID_ONLY, VOLTAGE_FOLLOWER_FORMULATIONS, ParameterError)


def c_name(text: str) -> str:
    """An upper-case C identifier part (codegen's)."""
    return "".join(ch if ch.isalnum() else "_" for ch in text).upper()


class Expr:
    """A condition or a number over the resolved parameters."""

    def value(self, p: Mapping[str, Any]) -> Any:  # pragma: no cover - abstract
        raise NotImplementedError

    def c(self) -> str:  # pragma: no cover - abstract
        raise NotImplementedError

    def names(self) -> set[str]:
        """The parameters it reads."""
        return set().union(*(x.names() for x in getattr(self, "args", ())))


@dataclass(frozen=True)
class Num(Expr):
    """A real or boolean parameter's value (booleans 1/0) [its unit]."""
    name: str

    def value(self, p: Mapping[str, Any]) -> float:
        return float(p[self.name])

    def c(self) -> str:
        return f"v[CAM_P_{c_name(self.name)}]"

    def names(self) -> set[str]:
        return {self.name}


@dataclass(frozen=True)
class Is(Expr):
    """A string parameter is one of ``choices``."""
    name: str
    choices: tuple[str, ...]

    def value(self, p: Mapping[str, Any]) -> bool:
        return p[self.name] in self.choices

    def c(self) -> str:
        terms = [f"(int)v[CAM_P_{c_name(self.name)}] == CAM_CHOICE_{c_name(self.name)}_{c_name(ch)}"
                 for ch in self.choices]
        return "(" + " || ".join(terms) + ")" if terms else "0"

    def names(self) -> set[str]:
        return {self.name}


@dataclass(frozen=True)
class Cmp(Expr):
    """``a op b`` with op one of ==, !=, >; b a number."""
    a: Expr
    op: str
    b: float = 0.0

    def value(self, p: Mapping[str, Any]) -> bool:
        x = self.a.value(p)
        return {"==": x == self.b, "!=": x != self.b, ">": x > self.b}[self.op]

    def c(self) -> str:
        return f"({self.a.c()} {self.op} {float(self.b)!r})"

    def names(self) -> set[str]:
        return self.a.names()


class _Many(Expr):
    def __init__(self, *args: Expr) -> None:
        self.args = args


class AllOf(_Many):
    """Every one holds."""

    def value(self, p: Mapping[str, Any]) -> bool:
        return all(x.value(p) for x in self.args)

    def c(self) -> str:
        return "(" + " && ".join(x.c() for x in self.args) + ")"


class AnyOf(_Many):
    """One holds at least."""

    def value(self, p: Mapping[str, Any]) -> bool:
        return any(x.value(p) for x in self.args)

    def c(self) -> str:
        return "(" + " || ".join(x.c() for x in self.args) + ")"


class Not(_Many):
    """It does not hold."""

    def value(self, p: Mapping[str, Any]) -> bool:
        return not self.args[0].value(p)

    def c(self) -> str:
        return f"!{self.args[0].c()}"


class Where(_Many):
    """``then`` where ``cond`` holds, else 0."""

    def value(self, p: Mapping[str, Any]) -> float:
        return self.args[1].value(p) if self.args[0].value(p) else 0.0

    def c(self) -> str:
        return f"({self.args[0].c()} ? {self.args[1].c()} : 0.0)"


# The quantities the rules share (physics/drive.py's effective_clearance, follower_mass, own_follower).
CLEARANCE = Where(Cmp(Num("backlash"), "!="), Num("c"))          # m: c where the backlash effect is on
MASS = Where(Cmp(Num("follower_inertia"), "!="), Num("m"))       # kg: m where the follower's inertia is on
SPRING = Is("closure", ("spring",))
FORM = Is("closure", ("form",))
FOLLOWER_MODEL = AnyOf(Is("drive", FOLLOWER_DRIVES), Is("formulation", VOLTAGE_FOLLOWER_FORMULATIONS))
# The follower moves as a body of its own (docs/model.md 13): closure 'spring' always; 'form' where the groove has a
# clearance to fly across, the follower a mass to carry its momentum, and the formulation the follower's momentum.
OWN_FOLLOWER = AnyOf(SPRING, AllOf(FORM, Cmp(CLEARANCE, ">"), Cmp(MASS, ">"), FOLLOWER_MODEL))
COMPLIANT = Cmp(Num("k_shaft"), ">")
TRAIN = Cmp(Num("k_train"), ">")   # the follower train (docs/model.md 14.6)
ARM_TRAIN = Cmp(Num("k_train_arm"), ">")   # an arm's torsional train (14.6)
# The follower's kind (docs/model.md 16): an arm's fields with their units, the arm's three it needs first.
OSCILLATING = Is("follower_type", ("oscillating_roller", "oscillating_flat"))
OTHER_KIND = Not(Is("follower_type", ("translating_roller",)))
# The translating flat's train (docs/model.md 14.6): its path is s, as the roller's, on the cam and on a follower of
# its own.
FLAT_TRAIN = Is("follower_type", ("translating_flat",))
ARM_UNITS = (("arm_length", "m"), ("pivot_distance", "m"), ("lift_angle", "rad"), ("J_arm", "kg.m2"),
             ("m_arm", "kg"), ("r_cm_arm", "m"), ("psi_0", "rad"), ("k_train_arm", "N.m/rad"),
             ("d_train_arm", "N.m.s/rad"), ("J_end", "kg.m2"))

PLASTIC = ("has plastic impacts only (docs/model.md 6.2); allowed with it: 0 (or closure 'form' or 'spring' in the "
           "consistent formulation)")
BODY = "closure 'spring' moves the follower as a body of its own, which needs its mass"


@dataclass(frozen=True)
class Rule:
    """Refuse where ``when`` holds, with ``message`` (``{name}``: that parameter's value as repr shows it)."""
    when: Expr
    message: str

    def fields(self) -> list[str]:
        """The parameters the message shows, in order."""
        return re.findall(r"\{(\w+)\}", self.message)

    def text(self, p: Mapping[str, Any]) -> str:
        """The message at p."""
        return self.message.format(**{name: repr(p[name]) for name in self.fields()})


RULES: tuple[Rule, ...] = (
    Rule(AllOf(Not(SPRING), AnyOf(Cmp(Num("k_spring"), "!="), Cmp(Num("F_spring0"), "!="))),
         "parameters 'k_spring' = {k_spring} N/m, 'F_spring0' = {F_spring0} N: a return spring needs closure "
         "'spring' (closure is {closure}); allowed with it: 0"),
    Rule(AllOf(Is("closure", ("kinematic",)), Cmp(Num("restitution"), "!=")),
         "parameter 'restitution' = {restitution}: closure 'kinematic' " + PLASTIC),
    Rule(AllOf(FORM, Not(FOLLOWER_MODEL), Cmp(Num("restitution"), "!=")),
         "parameter 'restitution' = {restitution}: the paper's formulation (its eqs. 6-8) " + PLASTIC),
    Rule(AllOf(SPRING, Cmp(CLEARANCE, "!=")),
         "parameter 'c' = {c} m: closure 'spring' holds the follower on one flank, there is no clearance; "
         "allowed with it: c = 0"),
    Rule(AllOf(SPRING, Cmp(Num("follower_inertia"), "==")),
         f"parameter 'follower_inertia' = false: {BODY}; allowed with it: follower_inertia true (and m > 0)"),
    Rule(AllOf(SPRING, Not(Cmp(Num("m"), ">"))), f"parameter 'm' = {{m}} kg: {BODY}; allowed with it: m > 0"),
    Rule(AllOf(SPRING, Not(FOLLOWER_MODEL)),
         "parameter 'closure' = {closure} with drive 'voltage': the paper's formulation (steps 1-9) has no follower "
         "of its own; allowed with it: formulation 'consistent'"),
    Rule(AllOf(COMPLIANT, Not(Cmp(Num("J_cam"), ">"))),
         "parameter 'J_cam' = {J_cam} [kg.m2]: a compliant shaft (k_shaft = {k_shaft} N.m/rad) needs the inertia of "
         "its cam side; allowed with k_shaft > 0: J_cam in (0, 100] kg.m2"),
    Rule(AllOf(Not(TRAIN), AnyOf(Cmp(Num("d_train"), "!="), Cmp(Num("m_end"), "!="))),
         "parameters 'd_train' = {d_train} N.s/m, 'm_end' = {m_end} kg with k_train = 0 (no train): they act only "
         "through a train; allowed with it: 0 (a rigid train's mass belongs in m)"),
    Rule(AllOf(OSCILLATING, Not(ARM_TRAIN), AnyOf(Cmp(Num("d_train_arm"), "!="), Cmp(Num("J_end"), "!="))),
         "parameters 'd_train_arm' = {d_train_arm} N.m.s/rad, 'J_end' = {J_end} kg.m2 with k_train_arm = 0 (no "
         "train): they act only through an arm's train; allowed with it: 0 (a rigid train's inertia belongs in J_arm)"),
    Rule(AllOf(OSCILLATING, ARM_TRAIN, Not(Cmp(Num("J_end"), ">"))),
         "parameter 'J_end' = {J_end} kg.m2: an arm's torsional train (k_train_arm = {k_train_arm} N.m/rad) needs its "
         "end inertia; allowed with k_train_arm > 0: J_end in (0, 1e3] kg.m2"),
    Rule(AllOf(TRAIN, Not(Cmp(Num("m_end"), ">"))),
         "parameter 'm_end' = {m_end} kg: a follower train (k_train = {k_train} N/m) needs its end mass; allowed with "
         "k_train > 0: m_end in (0, 1e4] kg"),
    Rule(AllOf(TRAIN, Is("solver", ("etdrk4",))),
         "parameter 'k_train' = {k_train} N/m: solver 'etdrk4' integrates the rigid drive's electrical pole, not the "
         "train's end mass; allowed with it: k_train = 0 (use solver 'rk4', 'rk23' or 'rk45')"),
    Rule(AllOf(TRAIN, Is("formulation", ("paper",))),
         "parameter 'k_train' = {k_train} N/m: the paper's formulation (steps 1-9) has no follower train; allowed "
         "with it: k_train = 0, or formulation 'consistent' (docs/model.md 14.6)"),
    Rule(AllOf(TRAIN, Cmp(CLEARANCE, "!="), Not(OWN_FOLLOWER)),
         "parameter 'k_train' = {k_train} N/m: a train on a follower in a clearance needs the follower as a body of "
         "its own (closure 'form' with its mass m > 0, docs/model.md 14.6); allowed with closure {closure} and c = "
         "{c} m: k_train = 0"),
    *(Rule(AllOf(Not(OSCILLATING), Cmp(Num(name), "!=")),
           f"parameter {name!r} = {{{name}}} {unit} is not used by follower_type {{follower_type}} (only by the "
           f"oscillating types): leave it at its default 0") for name, unit in ARM_UNITS),
    *(Rule(AllOf(OSCILLATING, Not(Cmp(Num(name), ">"))),
           f"parameter {name!r} = {{{name}}} {unit}: follower_type {{follower_type}} needs it; allowed "
           f"{BY_NAME[name].allowed()[5:]}")
      for name, unit in ARM_UNITS[:3]),
    Rule(AllOf(OSCILLATING, Cmp(Num("gravity"), "!="), Cmp(Num("beta"), "!=")),
         "parameter 'beta' = {beta} rad is not used by follower_type {follower_type} (the arm's angle to gravity is "
         "its psi_0): leave it at 0"),
    Rule(AllOf(OTHER_KIND, Cmp(CLEARANCE, "!="), Not(OWN_FOLLOWER)),
         "parameter 'c' = {c} m with follower_type {follower_type}: a clearance needs the follower as a body of its "
         "own (closure 'form' with the follower's mass m > 0, in the consistent formulation or the speed drive; "
         "docs/model.md 16.3); allowed with closure {closure}: c = 0"),
    Rule(AllOf(OTHER_KIND, AnyOf(COMPLIANT, AllOf(TRAIN, Not(FLAT_TRAIN)),
                                 AllOf(Is("solver", ("etdrk4",)), Not(Is("drive", ("speed",)))))),
         "parameter 'follower_type' = {follower_type}: runs on a rigid shaft, with no follower train along X (but "
         "the translating flat's; an arm's is torsional: k_train_arm, d_train_arm, J_end) and a solver other than "
         "'etdrk4' (which integrates the roller's electrical pole) so far; allowed with k_shaft = {k_shaft} N.m/rad, "
         "k_train = {k_train} N/m, solver {solver}: 'translating_roller'"),
    Rule(AllOf(OTHER_KIND, Is("formulation", ("paper",)), Not(Is("drive", ("speed",)))),
         "parameter 'follower_type' = {follower_type}: the paper's formulation (steps 1-9) has the translating "
         "roller only; allowed with it: 'translating_roller' (or formulation 'consistent', docs/model.md 16)"),
    *(Rule(AllOf(COMPLIANT, Is(name, (choice,))),
           f"parameter 'k_shaft' = {{k_shaft}} N.m/rad: {reason}; allowed with {name} {choice!r}: k_shaft = 0"
           f"{instead}") for (name, choice), (reason, instead) in RIGID_ONLY.items()),
)


def refusal(p: Mapping[str, Any]) -> str | None:
    """The message of the first rule that refuses the resolved parameters p, or None."""
    for rule in RULES:
        if rule.when.value(p):
            return rule.text(p)
    return None


def check_rules(p: Mapping[str, Any]) -> None:
    """Raise ParameterError where the resolved parameters p break a rule of RULES."""
    message = refusal(p)
    if message is not None:
        raise ParameterError(message)


def rule_names() -> set[str]:
    """Every parameter the rules read or show (each is in physics.parameters.PARAMETERS)."""
    names = set().union(*(r.when.names() | set(r.fields()) for r in RULES))
    assert names <= set(BY_NAME), names - set(BY_NAME)
    return names
