"""The units of the drive's parameters and variables: quantity, SI base-unit exponents, the units a value may be
given in, and the display unit an FMI tool shows.

One table (``UNITS``), keyed by the SI unit that physics/parameters.py and physics/variables.py give each name: the
FMUs' ``<UnitDefinitions>``/``<TypeDefinitions>`` (fmu/model_description.py, model_description3.py), the CLI's
``--set NAME=VALUE[UNIT]`` and a scene file's ``name = "VALUE UNIT"`` (``to_si``, through ``ParameterSpec.check``)
and the docs' tables come from it. ``math`` only. A value in an alternative unit is ``display = factor * SI +
offset``, FMI's DisplayUnit rule, so ``SI = (display - offset) / factor``.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

RPM = 60.0 / (2.0 * math.pi)  # rpm per rad/s
DEG = 180.0 / math.pi  # deg per rad
BASE_UNIT_ORDER = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")  # FMI's BaseUnit attributes, in schema order


class UnitError(ValueError):
    """A value whose unit is not one its quantity accepts; the message names the unit and the accepted ones."""


@dataclass(frozen=True)
class Unit:
    """One SI unit: its quantity (FMI ``quantity``, the CLI's messages), base-unit exponents, the other units a value
    may be given in as (name, factor, offset) with display = factor * SI + offset, and ``display``: the one of them an
    FMI tool shows by default ('' = the SI unit itself)."""

    quantity: str
    base: tuple[tuple[str, int], ...]
    alternatives: tuple[tuple[str, float, float], ...] = ()
    display: str = ""

    @property
    def type_name(self) -> str:
        """FMI type name of the quantity ('angular velocity' -> 'AngularVelocity')."""
        return "".join(word[:1].upper() + word[1:] for word in re.split(r"[^A-Za-z0-9]+", self.quantity))


UNITS: dict[str, Unit] = {
    "V": Unit("voltage", (("kg", 1), ("m", 2), ("s", -3), ("A", -1)), (("mV", 1e3, 0.0),)),
    "A": Unit("current", (("A", 1),), (("mA", 1e3, 0.0),)),
    "A/s": Unit("current rate", (("s", -1), ("A", 1))),
    "Ohm": Unit("resistance", (("kg", 1), ("m", 2), ("s", -3), ("A", -2)), (("mOhm", 1e3, 0.0), ("kOhm", 1e-3, 0.0))),
    "H": Unit("inductance", (("kg", 1), ("m", 2), ("s", -2), ("A", -2)), (("mH", 1e3, 0.0), ("uH", 1e6, 0.0))),
    "V/(rad/s)": Unit("back-EMF constant", (("kg", 1), ("m", 2), ("s", -2), ("A", -1), ("rad", -1)),
                      (("V/rpm", 1.0 / RPM, 0.0),)),
    "V/rad": Unit("voltage per angle", (("kg", 1), ("m", 2), ("s", -3), ("A", -1), ("rad", -1))),
    "N.m/A": Unit("torque constant", (("kg", 1), ("m", 2), ("s", -2), ("A", -1))),
    "kg.m2": Unit("moment of inertia", (("kg", 1), ("m", 2)), (("g.cm2", 1e7, 0.0),)),
    "N.m": Unit("torque", (("kg", 1), ("m", 2), ("s", -2)), (("mN.m", 1e3, 0.0),)),
    "N.m/rad": Unit("torsional stiffness", (("kg", 1), ("m", 2), ("s", -2), ("rad", -1)), (("N.m/deg", 1.0 / DEG, 0.0),)),
    "N.m.s/rad": Unit("torsional damping", (("kg", 1), ("m", 2), ("s", -1), ("rad", -1))),
    "N": Unit("force", (("kg", 1), ("m", 1), ("s", -2)), (("kN", 1e-3, 0.0),)),
    "N/m": Unit("stiffness", (("kg", 1), ("s", -2)), (("N/mm", 1e-3, 0.0),)),
    "N.s/m": Unit("damping", (("kg", 1), ("s", -1))),
    "kg": Unit("mass", (("kg", 1),), (("g", 1e3, 0.0),)),
    "m": Unit("length", (("m", 1),), (("mm", 1e3, 0.0), ("cm", 1e2, 0.0), ("um", 1e6, 0.0)), display="mm"),
    "m/s": Unit("velocity", (("m", 1), ("s", -1)), (("mm/s", 1e3, 0.0),)),
    "m/s2": Unit("acceleration", (("m", 1), ("s", -2)), (("mm/s2", 1e3, 0.0),)),
    "s": Unit("time", (("s", 1),), (("ms", 1e3, 0.0), ("us", 1e6, 0.0))),
    "rad": Unit("angle", (("rad", 1),), (("deg", DEG, 0.0), ("rev", 1.0 / (2.0 * math.pi), 0.0)), display="deg"),
    "rad/s": Unit("angular velocity", (("rad", 1), ("s", -1)), (("rpm", RPM, 0.0), ("deg/s", DEG, 0.0)),
                  display="rpm"),
    "rad/s2": Unit("angular acceleration", (("rad", 1), ("s", -2)), (("deg/s2", DEG, 0.0),)),
    "1": Unit("dimensionless", ()),
}
# A number, then optionally a unit: '600rpm', '0.5 mm', '-1.5e-3m', '2'.
_QUANTITY = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(\S.*?)?\s*$")


def display_unit(unit: str) -> tuple[str, float, float] | None:
    """(name, factor, offset) of the display unit of the SI ``unit``, or None where tools show the SI unit."""
    spec = UNITS.get(unit)
    if spec is None or not spec.display:
        return None
    return next(alt for alt in spec.alternatives if alt[0] == spec.display)


def accepted(unit: str) -> tuple[str, ...]:
    """The unit names a value of the SI ``unit`` may be given in: the SI unit first."""
    spec = UNITS[unit]
    return (unit, *(alt[0] for alt in spec.alternatives)) if unit != "1" else ()


def to_si(name: str, unit: str, text: str) -> float:
    """The value of ``text`` ('600rpm', '0.5 mm', '2.5') in the SI ``unit`` of the quantity ``name``: a bare number
    is taken as SI, a number with a unit of its quantity is converted, any other unit is a UnitError naming ``name``'s
    unit and the units it accepts; a text that is no number is a ValueError."""
    try:
        return float(text)
    except ValueError:
        pass
    match = _QUANTITY.match(text)
    if match is None or match.group(2) is None:
        raise ValueError(f"{text!r} is not a number")
    number, given = float(match.group(1)), match.group(2)
    spec = UNITS.get(unit)
    if spec is None:
        raise UnitError(f"{name} takes a plain value, without a unit: give a number, not {given!r}")
    if given == unit:
        return number
    for alt, factor, offset in spec.alternatives:
        if given == alt:
            return (number - offset) / factor
    if unit == "1":
        raise UnitError(f"{name} is dimensionless: give a plain number, not {given!r}")
    article = "an" if spec.quantity[:1] in "aeiou" else "a"
    raise UnitError(f"{name} is {article} {spec.quantity} in {unit}; give {', '.join(accepted(unit))} "
                    f"(not {given!r})")


def markdown_table() -> str:
    """The docs' table of units (docs/scenes.md): SI unit, quantity, the other units a value may be given in, the
    display unit FMI tools show."""
    lines = ["| unit | quantity | a value may also be given in | FMI tools show it in |", "|---|---|---|---|"]
    for unit, spec in UNITS.items():
        others = ", ".join(f"`{alt[0]}`" for alt in spec.alternatives) or ("a plain number only" if unit == "1" else "-")
        lines.append(f"| `{unit}` | {spec.quantity} | {others} | `{spec.display or unit}` |")
    return "\n".join(lines)
