"""The reference with a follower of another kind (physics.follower_kind.FollowerKind, docs/model.md 16).

The drive's own integrators run the kind's model (physics.kind_drive.KindDriveModel, a DriveModel with the kind's
load, inertia and friction): the voltage drive through the consistent formulation's hybrid loop (its stop,
break-away and side events; the side event is where the kind's P changes sign), the speed drive through its
imposed angle. The outputs add KIND_OUTPUTS: the arm's angle and rate (0 for a translating face).
"""
from __future__ import annotations

import numpy as np

from ..physics.formulations import formulation_name
from ..physics.kind_drive import KindDriveModel
from ..physics.parameters import ParameterError
from ..physics.signals import Signal

__all__ = ["KIND_OUTPUTS", "KIND_REFERENCES", "kind_reference"]

# The columns a run with a follower kind adds [unit, meaning].
KIND_OUTPUTS: tuple[tuple[str, str, str], ...] = (
    ("psi", "rad", "the arm's angle about its pivot, lift_angle s / h (0 for a translating follower)"),
    ("psi_dot", "rad/s", "the arm's rate psi' omega (0 for a translating follower)"),
)


def _speed(model: KindDriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal,
           options: dict) -> dict[str, np.ndarray]:
    from .hybrid import collect

    if model.free_follower:  # a follower of its own (docs/model.md 16.3)
        from .kind_flight import kind_speed_flight
        return kind_speed_flight(model, grid, omega_ref, options)
    from .integrate import _speed_rows

    return collect(_speed_rows(model, grid, omega_ref), grid)


def _consistent(model: KindDriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal,
                options: dict) -> dict[str, np.ndarray]:
    from .integrate import _Consistent

    if model.free_follower:  # a follower of its own (docs/model.md 16.3)
        from .kind_flight import kind_voltage_flight
        return kind_voltage_flight(model, grid, u, options)
    return _Consistent(model, u, options["rtol"], options["atol"], options["energy"], options["method"]).run(grid)


# The reference with a follower kind, by formulation (the paper's scheme has none).
KIND_REFERENCES = {"consistent": _consistent, "speed": _speed}


def kind_reference(model: KindDriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal,
                   options: dict) -> dict[str, np.ndarray]:
    """The drive with ``model``'s follower kind on ``grid`` [s]: the drive's outputs and KIND_OUTPUTS."""
    run = KIND_REFERENCES.get(formulation_name(model))
    if run is None:
        raise ParameterError(f"follower_type {model.kind.follower_type!r} runs in the consistent formulation and "
                             f"the speed drive only (parameter 'formulation' = {model.formulation!r})")
    result = run(model, grid, u, omega_ref, options)
    if model.free_follower:  # the follower's own psi, psi_dot are in its rows
        return result
    return with_arm_angle(model, result)


def with_arm_angle(model: KindDriveModel, result: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """``result`` with the columns psi [rad] and psi_dot [rad/s] of a follower on the cam: an arm's angle and rate at
    the result's theta and omega, 0 for a translating follower."""
    if model.kind.oscillating:
        psi, psi1 = model.cam.arm.derivatives(np.asarray(result["theta"], dtype=float))[:2]
        result["psi"], result["psi_dot"] = psi, psi1 * result["omega"]
    else:
        result["psi"], result["psi_dot"] = np.zeros_like(result["theta"]), np.zeros_like(result["theta"])
    return result


def with_arm_end(model: KindDriveModel, result: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """``result`` with an arm's train end in its own units (docs/model.md 14.6): psi_end = k s_end, psi_dot_end =
    k v_end [rad, rad/s] and its torque M_train = F_train / k [N m], k = lift_angle / lift (without a train the end
    is the arm: its psi, psi_dot); 0 for a translating follower."""
    zero = np.zeros_like(np.asarray(result["theta"], dtype=float))
    if not model.kind.oscillating:
        result["psi_end"], result["psi_dot_end"], result["M_train"] = zero, zero.copy(), zero.copy()
        return result
    k = model._scale   # lift_angle / lift, the kind's (physics.kind_drive; KindFlank reads it too)
    result["psi_end"] = k * np.asarray(result["s_end"], dtype=float)
    result["psi_dot_end"] = k * np.asarray(result["v_end"], dtype=float)
    result["M_train"] = np.asarray(result["F_train"], dtype=float) / k
    return result
