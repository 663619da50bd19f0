"""The reference of a follower of its own for every kind (docs/model.md 16.3).

The translating roller's hybrid runs (reference/voltage_flight.py, reference/flight.py: their events, transitions and
rows) with the kind's equations in the follower's slots (physics.kind_follower): y = (theta, omega, i, q_f, q_f_dot)
in the voltage drive, (theta, q_f, q_f_dot) in the speed drive. Rows add psi and psi_dot (the arm's own angle and
rate, 0 for a translating face), contact and impacts (and the energy integrals with E_impact in the voltage drive).
With a follower train the runs are reference/train_flight.py's with the kind's body carrying it
(physics.kind_train_follower): y adds the end mass's (x_e, v_e) in the law's lift units.
"""
from __future__ import annotations

import numpy as np

from ..physics.kind_follower import KindSpeedFollower, KindVoltageFollower
from ..physics.kind_train_follower import KindTrainSpeedFollower, KindTrainVoltageFollower
from ..physics.signals import Signal
from .flight import FollowerRun
from .train_flight import TrainFollowerRun, TrainSpeedFollowerRun
from .voltage_flight import VoltageFollowerRun

__all__ = ["KindFollowerRun", "KindTrainFollowerRun", "KindTrainSpeedFollowerRun", "KindVoltageFollowerRun",
           "kind_speed_flight", "kind_voltage_flight"]


class KindVoltageFollowerRun(VoltageFollowerRun):
    """The voltage drive (consistent formulation) with a follower of its own of another kind."""

    label = "kind follower voltage reference"
    BODY = KindVoltageFollower


class KindFollowerRun(FollowerRun):
    """The speed drive with a follower of its own of another kind (impacts leave omega unchanged)."""

    label = "kind follower speed reference"
    BODY = KindSpeedFollower


def kind_voltage_flight(model, grid: np.ndarray, u: Signal, options: dict) -> dict[str, np.ndarray]:
    """The voltage drive with ``model``'s (a KindDriveModel) follower of its own on ``grid`` [s]."""
    run = KindVoltageFollowerRun(model, u, options["rtol"], options["atol"], options["energy"], options["method"])
    return run.run(grid)


def kind_speed_flight(model, grid: np.ndarray, omega_ref: Signal, options: dict) -> dict[str, np.ndarray]:
    """The speed drive with ``model``'s (a KindDriveModel) follower of its own on ``grid`` [s]."""
    return KindFollowerRun(model, omega_ref, options["rtol"], options["atol"]).run(grid, model.params["theta0"])


class KindTrainFollowerRun(TrainFollowerRun):
    """The voltage drive with a follower of its own of another kind carrying the train."""

    label = "kind train follower voltage reference"
    BODY = KindTrainVoltageFollower


class KindTrainSpeedFollowerRun(TrainSpeedFollowerRun):
    """The speed drive with a follower of its own of another kind carrying the train."""

    label = "kind train follower speed reference"
    BODY = KindTrainSpeedFollower
