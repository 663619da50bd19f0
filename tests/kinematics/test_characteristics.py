"""Characteristic values against handbook tables and closed forms.

Handbook oracle: H. Makino's table of dimensionless characteristic values of
the standard cam curves (Vm, Am, Jm, (AV)m), as commonly tabulated in cam
design handbooks (e.g. F. Y. Chen, "Mechanics and Design of Cam Mechanisms",
Pergamon 1982, and Japanese index-drive makers' catalogues):

    curve                   Vm     Am     Jm      (AV)m
    cycloidal               2.00   6.28   39.5    8.16
    modified sine           1.76   5.53   69.5    5.46
    modified trapezoid      2.00   4.89   61.4    8.09
    simple harmonic         1.57   4.93   inf     3.88
    constant acceleration   2.00   4.00   inf     8.00
    MCV50                   1.28   8.01   201.4   5.73

Values are compared to half a unit in the last tabulated digit.
"""

import math

import numpy as np
import pytest

from cam_fmu.kinematics.characteristics import characteristics
from cam_fmu.kinematics.motion_law import MotionLaw
from cam_fmu.kinematics.presets import PRESETS

HANDBOOK = {  # name: (Vm, Am, Jm or None for unbounded, Qm) as printed
    "cycloidal": ("2.00", "6.28", "39.5", "8.16"),
    "modified_sine": ("1.76", "5.53", "69.5", "5.46"),
    "modified_trapezoid": ("2.00", "4.89", "61.4", "8.09"),
    "simple_harmonic": ("1.57", "4.93", None, "3.88"),
    "constant_acceleration": ("2.00", "4.00", None, "8.00"),
    "mcv50": ("1.28", "8.01", "201.4", "5.73"),
}


def _close_to_printed(value, printed):
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    return abs(value - float(printed)) <= 0.5 * 10 ** -decimals + 1e-12


@pytest.mark.parametrize("name", HANDBOOK)
def test_handbook_values(name):
    c = characteristics(MotionLaw(PRESETS[name]))
    Vm, Am, Jm, Qm = HANDBOOK[name]
    assert _close_to_printed(c.Vm, Vm), c.Vm
    assert _close_to_printed(c.Am, Am), c.Am
    assert _close_to_printed(c.Qm, Qm), c.Qm
    if Jm is None:
        assert c.jerk_unbounded and c.Jm is None and c.at["Jm"] is None
    else:
        assert not c.jerk_unbounded
        assert _close_to_printed(c.Jm, Jm), c.Jm


def test_closed_forms():
    """Exact values where the curve has an elementary closed form."""
    c = characteristics(MotionLaw(PRESETS["cycloidal"]))
    assert c.Vm == pytest.approx(2.0, rel=1e-14)
    assert c.Am == pytest.approx(2 * math.pi, rel=1e-14)
    assert c.Jm == pytest.approx(4 * math.pi**2, rel=1e-14)
    # A V = 2 pi sin(2 pi T) (1 - cos 2 pi T): max at 2 pi T = 2 pi/3
    assert c.Qm == pytest.approx(3 * math.sqrt(3) * math.pi / 2, rel=1e-12)
    assert c.at["Qm"] == pytest.approx(1 / 3, abs=1e-7)
    c = characteristics(MotionLaw(PRESETS["simple_harmonic"]))
    assert c.Vm == pytest.approx(math.pi / 2, rel=1e-14)
    assert c.Am == pytest.approx(math.pi**2 / 2, rel=1e-14)
    assert c.Qm == pytest.approx(math.pi**3 / 8, rel=1e-12)
    assert c.jumps == (0.0, 1.0)
    c = characteristics(MotionLaw(PRESETS["paper"]))
    assert c.Vm == pytest.approx(4 / 3, rel=1e-14)        # 2A / (h / pi) with h = 3 pi A / 2


@pytest.mark.parametrize("T", list(PRESETS.values()) + [
    (0.1, 0.2, 0.35, 0.5, 0.6, 0.9), (0.0, 0.2, 0.2, 0.7, 0.7, 1.0), (0.02, 0.3, 0.31, 0.31, 0.8, 0.81)])
def test_against_brute_force_sampling(T):
    m = MotionLaw(T)
    c = characteristics(m)
    t = np.linspace(0, 1, 400001)
    S, V, A, J = m.evaluate(t)
    assert c.Vm == pytest.approx(np.abs(V).max(), rel=1e-9)
    assert c.Am == pytest.approx(np.abs(A).max(), rel=1e-6)
    assert c.Amp == pytest.approx(A.max(), rel=1e-6)
    assert c.Amm == pytest.approx(-A.min(), rel=1e-6)
    assert c.Qm == pytest.approx(np.abs(A * V).max(), rel=1e-6)
    assert c.Qm >= np.abs(A * V).max() * (1 - 1e-12)
    for key, q in (("Vm", np.abs(V)), ("Qm", np.abs(A * V))):
        k = np.argmax(q)
        assert abs(c.at[key] - t[k]) < 1e-3 or q[np.searchsorted(t, c.at[key])] >= q[k] * (1 - 1e-6)
    if not c.jerk_unbounded:
        assert c.Jm == pytest.approx(np.abs(J).max(), rel=1e-6)


def test_unbounded_jerk_inside_and_json_shape():
    c = characteristics(MotionLaw((0.1, 0.2, 0.2, 0.7, 0.8, 0.9)))   # A jumps Amp -> 0 at 0.2
    assert c.jerk_unbounded and c.jumps == (0.2,)
    d = c.to_json_dict()
    assert set(d) == {"T", "Amp", "Amm", "Vm", "Am", "Jm", "jerk_unbounded", "Qm", "at"}
    assert set(d["at"]) == {"Vm", "Am", "Jm", "Qm"}
    assert d["Jm"] is None and d["at"]["Jm"] is None


def test_asymmetric_am_location():
    m = MotionLaw((0.1, 0.2, 0.35, 0.5, 0.6, 0.9))
    c = characteristics(m)
    assert c.Am == max(m.Amp, m.Amm)
    assert c.at["Am"] == (0.1 if m.Amp >= m.Amm else 0.6)
