"""The reference's named modes and its one event table (physics/modes.py, reference/hybrid.py; docs/model.md 13.7).

A follower halted in a horizontal groove by the guide's friction is checked against the kinematics of a constant
deceleration; the tables of docs/model.md 13.7 against the enumerations and the runs' transitions.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.formulations.consistent import EVENT_NAMES, EVENTS, Mode as RigidMode
from cam_fmu.physics.modes import Event, Follower, Shaft
from cam_fmu.physics.signals import constant
from cam_fmu.reference.flight import FollowerRun
from cam_fmu.reference.integrate import _Consistent, output_grid
from cam_fmu.reference.voltage_flight import VoltageFollowerRun

MODEL_MD = Path(__file__).resolve().parents[2] / "docs" / "model.md"


class _Modes(FollowerRun):
    """FollowerRun that keeps the follower's mode of every output row."""

    def __init__(self, *args) -> None:
        super().__init__(*args)
        self.modes: list[Follower] = []

    def _row(self, t, y, mode, left):
        self.modes.append(mode.follower)
        return super()._row(t, y, mode, left)


def test_a_follower_halted_by_the_guide_friction_stays_where_the_deceleration_stops_it():
    """A horizontal groove without spring (F_gx = 0, k = F0 = 0): in flight only the guide's friction f0 acts, so the
    follower decelerates at f0/m and halts at s + v |v| m / (2 f0) from any row (s, v) of that flight; halted (net
    force 0 <= f0) it stays there, v = a = 0, until a flank catches it."""
    model = DriveModel(dict(drive="speed", closure="form", c=1e-3, restitution=0.0, mu=0.3))
    f0 = model.mu * (abs(model.G_y) + model.N_g)
    assert f0 > 0.0 and model.F_gx == 0.0
    run = _Modes(model, constant(10.0), 1e-12, 1e-13)
    stop = 2 * math.pi / 10.0
    r = run.run(output_grid(stop, stop / 2000), 0.0)
    modes = np.array([m.name for m in run.modes])
    halted = np.flatnonzero(modes == "HALTED")
    assert len(halted) >= 10 and set(modes) == {"LOWER", "UPPER", "FLIGHT", "HALTED"}
    assert np.all(r["v"][halted] == 0.0) and np.all(r["a"][halted] == 0.0) and np.all(r["contact"][halted] == 0.0)
    assert np.all(r["v"][modes == "FLIGHT"] != 0.0)
    stretches = np.split(halted, np.flatnonzero(np.diff(halted) > 1) + 1)
    for stretch in stretches:
        assert np.ptp(r["s"][stretch]) == 0.0   # held: it does not move
        k = stretch[0] - 1
        flight = []
        while modes[k] == "FLIGHT":
            flight.append(k)
            k -= 1
        assert len(flight) >= 2
        for k in flight:   # m (measured 5.6e-17 over 18 rows before 2 halts)
            assert abs(r["s"][k] + r["v"][k] * abs(r["v"][k]) * model.m / (2.0 * f0) - r["s"][stretch[0]]) < 1e-12


def _table(heading: str) -> str:
    text = MODEL_MD.read_text(encoding="utf-8")
    start = text.index(heading)
    return text[start:text.index("\n## ", start) if "\n## " in text[start:] else len(text)]


def test_the_event_table_of_the_docs_is_the_reference_s():
    """Every row of model.md 13.7's event table names a member of Event and every member has its row; every event
    has its transition in a run's one table, and the rigid drive's events (section 10) are members too."""
    section = _table("### 13.7 The modes and events of the follower of its own")
    named = set(re.findall(r"^\| [^|]*\(`([A-Z_]+)`\) \|", section, flags=re.M))
    assert named == {kind.name for kind in Event}
    handled = set(FollowerRun.TRANSITIONS) | set(VoltageFollowerRun.TRANSITIONS) | set(_Consistent.TRANSITIONS)
    assert handled == set(Event)
    assert set(EVENTS) == set(EVENT_NAMES) and set(EVENTS.values()) <= set(_Consistent.TRANSITIONS)


def test_the_mode_table_of_the_docs_names_every_mode():
    """model.md 13.7's mode table has a row for each Follower and Shaft member, and the rigid drive's mode names
    its state in them."""
    section = _table("### 13.7 The modes and events of the follower of its own")
    named = set(re.findall(r"`(Follower|Shaft)\.([A-Z]+)`", section))
    assert named == {("Follower", m.name) for m in Follower} | {("Shaft", m.name) for m in Shaft}
    assert [RigidMode(contact=c).follower for c in (1, -1, 0)] == [Follower.LOWER, Follower.UPPER, Follower.FLIGHT]
    assert RigidMode(stuck=True).shaft is Shaft.STUCK and RigidMode().shaft is Shaft.TURNING
