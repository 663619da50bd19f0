"""physics/units.py, the one table of units: every unit a value may be given in converts by the closed conversion
(tests/display_units.py's table, written from the units' definitions), and the parser's refusals name the reason."""
from __future__ import annotations

import math

import pytest

from cam_fmu.physics import units
from display_units import CLOSED


def test_every_alternative_unit_converts_by_its_closed_factor():
    seen = set()
    for unit, spec in units.UNITS.items():
        for name, _factor, _offset in spec.alternatives:
            si, factor = CLOSED[name]
            assert si == unit
            for text in (f"2.5{name}", f" 2.5 {name} ", f"25e-1{name}", f"-2.5{name}"):
                sign = -1.0 if text.strip().startswith("-") else 1.0
                assert math.isclose(units.to_si("x", unit, text), sign * 2.5 / factor, rel_tol=1e-15), text
            seen.add(name)
        if unit != "1":
            assert units.to_si("x", unit, f"2.5{unit}") == 2.5  # the SI unit itself
    assert seen == set(CLOSED)


def test_a_plain_number_is_si_and_text_without_a_number_is_refused():
    assert units.to_si("c", "m", "1e-3") == 1e-3 and units.to_si("c", "m", "-0.5") == -0.5
    for text in ("mm", "", "1.2.3mm", "--1mm"):
        with pytest.raises(ValueError):
            units.to_si("c", "m", text)


def test_display_units_are_rpm_deg_and_mm():
    assert units.display_unit("rad/s") == ("rpm", 60.0 / (2.0 * math.pi), 0.0)
    assert units.display_unit("rad") == ("deg", 180.0 / math.pi, 0.0)
    assert units.display_unit("m") == ("mm", 1000.0, 0.0)
    assert {u for u in units.UNITS if units.display_unit(u)} == {"rad/s", "rad", "m"}


def test_quantity_type_names_are_distinct():
    names = [spec.type_name for spec in units.UNITS.values()]
    assert len(set(names)) == len(names) and units.UNITS["rad/s"].type_name == "AngularVelocity"



def test_docs_units_table_is_the_generated_one():
    """docs/scenes.md's table of units is ``units.markdown_table()``: it cannot drift from the code."""
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[2] / "docs" / "scenes.md").read_text(encoding="utf-8")
    assert units.markdown_table().strip() in doc


# The SI definitions of the symbols the units are written with (N = kg m / s2, V = W / A, Ohm = V / A, H = Wb / A).
SYMBOLS = {"kg": {"kg": 1}, "m": {"m": 1}, "s": {"s": 1}, "A": {"A": 1}, "rad": {"rad": 1},
           "N": {"kg": 1, "m": 1, "s": -2}, "V": {"kg": 1, "m": 2, "s": -3, "A": -1},
           "Ohm": {"kg": 1, "m": 2, "s": -3, "A": -2}, "H": {"kg": 1, "m": 2, "s": -2, "A": -2}}


def _exponents(text: str) -> dict[str, int]:
    """Base-unit exponents of a unit written as in the table: products '.', quotients '/', powers 'm2', '(...)'."""
    import re

    tokens = re.findall(r"[A-Za-z]+\d*|[./()]", text)
    pos = 0

    def factor() -> dict[str, int]:
        nonlocal pos
        if tokens[pos] == "(":
            pos += 1
            inner = expr()
            assert tokens[pos] == ")"
            pos += 1
            return inner
        name, power = re.fullmatch(r"([A-Za-z]+)(\d*)", tokens[pos]).groups()
        pos += 1
        return {k: v * int(power or 1) for k, v in SYMBOLS[name].items()}

    def combine(a: dict[str, int], b: dict[str, int], sign: int) -> dict[str, int]:
        out = dict(a)
        for k, v in b.items():
            out[k] = out.get(k, 0) + sign * v
        return {k: v for k, v in out.items() if v}

    def term() -> dict[str, int]:
        nonlocal pos
        result = factor()
        while pos < len(tokens) and tokens[pos] == ".":
            pos += 1
            result = combine(result, factor(), 1)
        return result

    def expr() -> dict[str, int]:
        nonlocal pos
        result = term()
        while pos < len(tokens) and tokens[pos] == "/":
            pos += 1
            result = combine(result, term(), -1)
        return result

    found = expr()
    assert pos == len(tokens), text
    return found


def test_every_units_base_exponents_follow_from_its_name():
    """The table's BaseUnit exponents (what an FMI tool converts with) against the unit's name read with the SI
    definitions of its symbols: N.m.s/rad = kg m2 s-1 rad-1, V/(rad/s) = kg m2 s-2 A-1 rad-1, ..."""
    for unit, spec in units.UNITS.items():
        expected = {} if unit == "1" else _exponents(unit)
        assert dict(spec.base) == expected, unit
