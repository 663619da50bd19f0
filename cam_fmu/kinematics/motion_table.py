"""A user motion table (cam angle, lift) as a shape-preserving periodic cubic cam program.

The format (docs/cam_design.md "User motion tables"): CSV text, one row
``angle_deg, lift_mm`` per line (two fields separated by commas, semicolons,
blanks or tabs; ``#`` starts a comment to the end of the line; lines end with
LF, CRLF or CR; a leading UTF-8 byte order mark is dropped). The first line
with fields is a header, skipped, only when none of its fields is a number.
Angles lie in [0, 360) deg and increase strictly; a last row at exactly 360 deg
repeating the lift of a first row at 0 deg closes the period and is dropped.
Lifts lie in [0, 10000] mm (the ``lift`` parameter's 10 m), measured from the
prime circle. At least 2 rows, at most 10^7. Every refusal names the line, the
row and the text.

Interpolation: the periodic piecewise cubic Hermite curve through the rows
(knots), period 2 pi, whose slope at each knot is the slope of the parabola
through the knot and its two neighbours, limited as Fritsch and Carlson's
monotone interpolation requires (Hyman's filter): 0 where the chords on the
two sides differ in sign or one is 0, otherwise at most 3 times the smaller
chord slope. So each piece is monotone between its two lifts: s never leaves
the range of the two rows around it (it is also clamped there against
rounding), a local extremum of the table is one of s, and a run of equal lifts
(a dwell) is exactly flat (s' = s'' = s''' = 0). s and s' are continuous; s''
jumps at the knots (which ``breakpoints()`` returns so that the solvers stop
there), s''' is constant on each piece. Convention at a knot: the piece ending
there (left limit); knot 0 ends the last piece.

This module is the readable model: the engine's C parser and curve
(cam_fmu/engine/csrc/src/motion_table.c) do the same operations in the same
order (tests/engine/test_engine_profile.py compares them). ``derivatives`` uses
``math`` and ``bisect`` only; ``evaluate`` is its numpy twin.
"""

from __future__ import annotations

import bisect
import math
import re
from pathlib import Path
from typing import NamedTuple, Sequence

import numpy as np

from .cam_program import ProgramBase

__all__ = ["TableProgram", "parse_motion_table", "program_from_table_text", "read_motion_table",
           "MAX_ROWS", "MAX_LIFT_MM", "MAX_NUMBER", "MIN_SPACING_DEG"]

TWO_PI = 2.0 * math.pi
MAX_ROWS = 10_000_000          # rows of a table, at most
MAX_LIFT_MM = 10000.0          # mm: the lift parameter's upper bound, 10 m
MAX_NUMBER = 100               # characters of one number, at most
MIN_SPACING_DEG = 1e-6         # deg: closer rows are refused (the curve's third derivative would overflow)
QUOTE_CHARS = 40               # characters of a user's text quoted in a message
_MIN_SPACING_RAD = MIN_SPACING_DEG * (math.pi / 180.0)
_LINES = re.compile(r"\r\n|\r|\n")
_FIELDS = re.compile(r"[^ \t,;]+")
_DECIMAL = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?", re.ASCII)
_WORDS = ("inf", "infinity", "nan")
_SEPARATORS = " \t,;"


def _is_number(field: str) -> bool:
    """Python's float() grammar without underscores and blanks: the C parser's ``classify``."""
    if _DECIMAL.fullmatch(field):
        return True
    body = field[1:] if field[:1] in ("+", "-") else field
    return body.isascii() and body.lower() in _WORDS


def _quote(text: str) -> str:
    """'text' cut to QUOTE_CHARS characters (then '...'), non-printable-ASCII characters as '?'."""
    cut = "".join(c if " " <= c <= "~" else "?" for c in text[:QUOTE_CHARS])
    return f"'{cut}{'...' if len(text) > QUOTE_CHARS else ''}'"


class _Row(NamedTuple):
    line: int
    row: int
    angle_text: str
    lift_text: str
    degrees: float
    radians: float
    mm: float


def _field_value(field: str, name: str, where: str) -> float:
    if not _is_number(field):
        raise ValueError(f"{where}the {name} field is not a number: {_quote(field)}")
    if len(field) > MAX_NUMBER:
        raise ValueError(f"{where}the {name} field has more than {MAX_NUMBER} characters: {_quote(field)}")
    return float(field)


def _parse_rows(text: str) -> list[_Row]:
    """The table's rows in one period (the closing row dropped), every refusal as the C parser's."""
    if text.startswith("\ufeff"):
        text = text[1:]
    rows: list[_Row] = []
    first_line, closing = True, None
    row = 0
    for line, raw in enumerate(_LINES.split(text), 1):
        content = raw.split("#", 1)[0]
        fields = _FIELDS.findall(content)
        if not fields:
            continue
        if first_line:
            first_line = False
            if not any(_is_number(f) for f in fields):
                continue                                   # a header
        row += 1
        where = f"motion table line {line} (row {row}): "
        if closing is not None:
            raise ValueError(f"{where}no row may follow the closing row at 360 deg "
                             f"(row {closing.row}, line {closing.line})")
        if len(fields) != 2:
            shown = _quote(content.strip(_SEPARATORS))
            raise ValueError(f"{where}expected 2 fields 'angle_deg, lift_mm', got {len(fields)}: {shown}")
        degrees = _field_value(fields[0], "angle_deg", where)
        mm = _field_value(fields[1], "lift_mm", where)
        if not (math.isfinite(degrees) and 0.0 <= degrees <= 360.0):
            raise ValueError(f"{where}angle_deg must lie in [0, 360) (or be 360 in a closing row), "
                             f"got {_quote(fields[0])}")
        if not (math.isfinite(mm) and 0.0 <= mm <= MAX_LIFT_MM):
            raise ValueError(f"{where}lift_mm must be a number in [0, 10000], got {_quote(fields[1])}")
        r = _Row(line, row, fields[0], fields[1], degrees, degrees * (math.pi / 180.0), mm)
        if degrees == 360.0:
            if not rows or rows[0].degrees != 0.0:
                raise ValueError(f"{where}a row at 360 deg closes the period: it must come last, "
                                 f"after a first row at 0 deg")
            first = rows[0]
            if abs(mm - first.mm) > 1e-9 * max(1.0, abs(first.mm)):
                raise ValueError(f"{where}the closing row at 360 deg must repeat the lift of row {first.row} "
                                 f"(line {first.line}), {_quote(first.lift_text)} mm, got {_quote(fields[1])} mm")
            closing = r
            continue
        if rows:
            prev = rows[-1]
            if degrees <= prev.degrees:
                verb = "repeats" if degrees == prev.degrees else "is below"
                raise ValueError(f"{where}angle {_quote(fields[0])} deg {verb} {_quote(prev.angle_text)} deg of "
                                 f"row {prev.row} (line {prev.line}); angles must increase strictly")
            if degrees - prev.degrees < MIN_SPACING_DEG:
                raise ValueError(f"{where}angle {_quote(fields[0])} deg is closer than 1e-06 deg to "
                                 f"{_quote(prev.angle_text)} deg of row {prev.row} (line {prev.line})")
        if len(rows) >= MAX_ROWS:
            raise ValueError(f"motion table: more than {MAX_ROWS} rows (line {line})")
        rows.append(r)
    if len(rows) < 2:
        raise ValueError(f"motion table: need at least 2 rows 'angle_deg, lift_mm' (a closing row at 360 deg "
                         f"not counted), got {len(rows)}")
    first, last = rows[0], rows[-1]
    if (first.degrees + 360.0) - last.degrees < MIN_SPACING_DEG:
        raise ValueError(f"motion table line {last.line} (row {last.row}): angle {_quote(last.angle_text)} deg is "
                         f"closer than 1e-06 deg to {_quote(first.angle_text)} deg + 360 deg of row {first.row} "
                         f"(line {first.line}), where the period starts again")
    return rows


class TableProgram(ProgramBase):
    """The shape-preserving periodic cubic through (theta_i [rad], s_i [m]); the CamProgram interface.

    ``angles`` strictly increasing in [0, 2 pi), ``lifts`` finite and >= 0, at least 2
    points. ``lift`` is the largest table lift [m]. Piece i runs from knot i to knot
    i + 1 (the last to knot 0 + 2 pi), ``widths[i]`` wide; ``slopes`` are s' at the knots;
    ``coefficients[i]`` = (c0, c1, c2, c3) of s = c0 + c1 u + c2 u^2 + c3 u^3 with
    u = theta - angles[i], and ``end_coefficients[i]`` the same about the piece's end
    (v = u - width): the first is used for u <= width / 2, the second beyond.
    """

    def __init__(self, angles: Sequence[float], lifts: Sequence[float]) -> None:
        th = [float(t) for t in angles]
        y = [float(v) for v in lifts]
        n = len(th)
        if n != len(y):
            raise ValueError(f"angles and lifts must be two sequences of equal length, got {n} and {len(y)}")
        if n < 2:
            raise ValueError(f"a motion table needs at least 2 points, got {n}")
        if not all(math.isfinite(v) for v in th + y):
            raise ValueError("motion table angles and lifts must be finite numbers")
        for k in range(n):
            if not 0.0 <= th[k] < TWO_PI:
                raise ValueError(f"motion table angles must lie in [0, 2 pi) rad: point {k + 1} is {th[k]!r} rad")
            if k and th[k] <= th[k - 1]:
                raise ValueError(f"motion table angles must increase strictly: point {k + 1} "
                                 f"({th[k]!r} rad) follows {th[k - 1]!r} rad")
            if k and th[k] - th[k - 1] < _MIN_SPACING_RAD:
                raise ValueError(f"motion table angles must be at least 1e-06 deg apart: point {k + 1} "
                                 f"({th[k]!r} rad) and {th[k - 1]!r} rad")
            if y[k] < 0.0:
                raise ValueError(f"motion table lift must be >= 0, got {y[k]!r} m at point {k + 1}")
        if (th[0] + TWO_PI) - th[-1] < _MIN_SPACING_RAD:
            raise ValueError(f"motion table angles must be at least 1e-06 deg apart: the last point "
                             f"({th[-1]!r} rad) and the first + 2 pi")
        # The same operations in the same order as motion_table.c's build().
        width = [(th[i + 1] if i + 1 < n else th[0] + TWO_PI) - th[i] for i in range(n)]
        chord = [(y[(i + 1) % n] - y[i]) / width[i] for i in range(n)]
        slope = []
        for i in range(n):
            a, b, ha, hb = chord[i - 1], chord[i], width[i - 1], width[i]
            d = 0.0
            if (a > 0.0 and b > 0.0) or (a < 0.0 and b < 0.0):
                limit = 3.0 * min(abs(a), abs(b))
                d = (hb * a + ha * b) / (ha + hb)
                if abs(d) > limit:
                    d = math.copysign(limit, d)
            slope.append(d)
        coef, end = [], []
        for i in range(n):
            w, d0, d1, c = width[i], slope[i], slope[(i + 1) % n], chord[i]
            c3 = (d0 + d1 - 2.0 * c) / (w * w)
            coef.append((y[i], d0, (3.0 * c - 2.0 * d0 - d1) / w, c3))
            end.append((y[(i + 1) % n], d1, (d0 + 2.0 * d1 - 3.0 * c) / w, c3))
        self.angles = tuple(th)                 # knots [rad]
        self.lifts = tuple(y)                   # table lifts [m]
        self.lift = max(y)
        self.slopes = tuple(slope)              # s' at the knots [m/rad]
        self.widths = tuple(width)              # piece widths [rad]
        self.coefficients = tuple(coef)
        self.end_coefficients = tuple(end)
        self._knots = np.array(th)

    def __repr__(self):
        return (f"TableProgram({len(self.angles)} knots, {math.degrees(self.angles[0]):.6g}.."
                f"{math.degrees(self.angles[-1]):.6g} deg, lift={self.lift!r})")

    @staticmethod
    def _reduce(theta: float) -> float:
        """theta mod 2 pi in [0, 2 pi); a knot is its own reduction."""
        th = math.fmod(theta, TWO_PI)
        if th < 0.0:
            th += TWO_PI
            if th >= TWO_PI:      # -tiny + 2 pi rounds to 2 pi
                th = 0.0
        return th

    def derivatives(self, theta: float) -> tuple[float, float, float, float]:
        """(s [m], ds/dtheta [m/rad], d2s/dtheta2 [m/rad^2], d3s/dtheta3 [m/rad^3]), plain floats;
        NaN for a NaN or infinite theta."""
        if not math.isfinite(theta):
            return math.nan, math.nan, math.nan, math.nan
        th = self._reduce(theta)
        k = bisect.bisect_left(self.angles, th)
        if k == 0:                       # up to knot 0 (included): the last piece, ending at knot 0 + 2 pi
            i = len(self.angles) - 1
            u = (th + TWO_PI) - self.angles[i]
        else:
            i = k - 1
            u = th - self.angles[i]
        w = self.widths[i]
        if u <= 0.5 * w:
            c0, c1, c2, c3 = self.coefficients[i]
        else:
            c0, c1, c2, c3 = self.end_coefficients[i]
            u = u - w
        s = c0 + u * (c1 + u * (c2 + u * c3))
        y0, y1 = self.coefficients[i][0], self.end_coefficients[i][0]
        s = min(max(s, min(y0, y1)), max(y0, y1))       # monotone piece: rounding must not leave it
        return s, c1 + u * (2.0 * c2 + 3.0 * c3 * u), 2.0 * c2 + 6.0 * c3 * u, 6.0 * c3

    def evaluate(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The same four quantities over an array of theta [rad] (the same operations, elementwise)."""
        theta = np.asarray(theta, dtype=float)
        finite = np.isfinite(theta)
        th = np.fmod(np.where(finite, theta, 0.0), TWO_PI)
        low = th < 0.0
        th = np.where(low, th + TWO_PI, th)
        th = np.where(low & (th >= TWO_PI), 0.0, th)
        k = np.searchsorted(self._knots, th, side="left")
        n = len(self.angles)
        i = np.where(k == 0, n - 1, k - 1)
        widths = np.array(self.widths)
        u = np.where(k == 0, (th + TWO_PI) - self._knots[i], th - self._knots[i])
        w = widths[i]
        left = u <= 0.5 * w
        coef, end = np.array(self.coefficients), np.array(self.end_coefficients)
        c0, c1, c2, c3 = (np.where(left, coef[i, m], end[i, m]) for m in range(4))
        u = np.where(left, u, u - w)
        s = c0 + u * (c1 + u * (c2 + u * c3))
        y0, y1 = coef[i, 0], end[i, 0]
        s = np.minimum(np.maximum(s, np.minimum(y0, y1)), np.maximum(y0, y1))
        out = (s, c1 + u * (2.0 * c2 + 3.0 * c3 * u), 2.0 * c2 + 6.0 * c3 * u, 6.0 * c3)
        return tuple(np.where(finite, q, np.nan) for q in out)

    def feature_angle(self) -> float:
        """The shortest knot spacing [rad]: the profile's finest angular detail."""
        return min(self.widths)

    def breakpoints(self) -> tuple[float, ...]:
        """The knots (in [0, 2 pi), ascending): s'' jumps there."""
        return self.angles


def parse_motion_table(text: str) -> tuple[list[float], list[float]]:
    """(angles [deg], lifts [mm]) of the rows in one period; see the module docstring for the format."""
    rows = _parse_rows(text)
    return [r.degrees for r in rows], [r.mm for r in rows]


def program_from_table_text(text: str) -> TableProgram:
    """A TableProgram from CSV text 'angle_deg, lift_mm' (the FMU's String parameter form)."""
    rows = _parse_rows(text)
    return TableProgram([r.radians for r in rows], [r.mm * 1e-3 for r in rows])


def read_motion_table(path: str | Path) -> TableProgram:
    """A TableProgram from a CSV file 'angle_deg, lift_mm' (UTF-8, with or without a BOM)."""
    return program_from_table_text(Path(path).read_text(encoding="utf-8"))
