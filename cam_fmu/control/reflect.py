"""What the motor shaft sees over one turn of the cam: the reflected inertia and load torque.

At a constant cam speed omega [rad/s] (omega_dot = 0), for every cam angle theta
(docs/model.md section 4):

- J(theta) = J_m + J_cam + m s'^2 [kg m^2], the inertia the motor drives (at low frequency);
- the load torque M(theta) [N m] and its parts, whose sum it is:
  inertial m s'' omega^2 s' (the follower's acceleration), gravity -F_gx s',
  guide friction sigma f s' (f from the exact two-branch solve, sigma = sgn(s' omega)),
  and shaft friction M_f sgn(omega).

With a compliant shaft (k_shaft > 0, docs/model.md section 12.3) also the undamped
resonance f_r(theta) and anti-resonance f_a(theta) [Hz] of the two-mass system that the
rotor J_m and the cam side J_c(theta) = J_cam + m s'^2 make on the shaft; a rigid drive-train
has none, and the map reports them as None. Plain floats through physics.drive.DriveModel;
numpy only for the arrays.
"""
from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from ..physics.drive import DriveModel, sign, solve_guide_friction

PARTS = ("M_inertial", "M_gravity", "M_guide", "M_shaft")
COLUMNS = ("theta", "J", "M", *PARTS)
FREQUENCIES = ("f_r", "f_a")  # Hz: the columns a compliant shaft adds
UNITS = {"theta": "rad", "J": "kg.m2", "M": "N.m", **{part: "N.m" for part in PARTS}, "f_r": "Hz", "f_a": "Hz"}
# What the map assumes of the follower (refused where it is a body of its own: closure 'spring', or 'form' with a
# clearance): printed and in the JSON.
ASSUMES = ("the follower on the cam at every angle: a groove's two flanks push and pull it, a clearance c is "
           "ignored (docs/model.md section 13)")
RESONANCE_KEYS = ("f_r_min", "f_r_max", "f_a_min", "f_a_max")  # Hz: None with a rigid shaft


class FreeFollowerError(ValueError):
    """The map refuses a follower that can leave the cam; ``closure`` says which ('spring' or 'form')."""

    def __init__(self, closure: str) -> None:
        self.closure = closure
        super().__init__(f"closure {closure!r}: the map holds the follower on the cam at every angle (the kinematic "
                         "rule), while this follower can leave it (docs/model.md section 13)")


def two_mass_frequencies(k: float, J_m: float, J_c: float) -> tuple[float, float]:
    """(f_r, f_a) [Hz]: the undamped resonance and anti-resonance that the rotor J_m [kg m^2] sees on a shaft of
    stiffness k [N m/rad] carrying J_c [kg m^2] (docs/model.md 12.3)."""
    return (math.sqrt(k * (J_m + J_c) / (J_m * J_c)) / (2.0 * math.pi), math.sqrt(k / J_c) / (2.0 * math.pi))


def reflected_map(params: Mapping[str, Any] | None, rpm: float, points: int = 3600) -> dict[str, np.ndarray]:
    """J(theta) and M(theta) with its parts at ``points`` angles over one turn, at ``rpm`` [1/min] of the cam."""
    if not (math.isfinite(rpm) and rpm != 0.0 and abs(rpm) <= 1e6):
        raise ValueError(f"--rpm {rpm!r}: allowed a finite cam speed other than 0, |rpm| <= 1e6 1/min")
    if points < 8:
        raise ValueError(f"points = {points}: at least 8 angles over a turn")
    model = DriveModel(params)
    if model.free_follower:
        raise FreeFollowerError(model.closure)
    omega = rpm * 2.0 * math.pi / 60.0
    direction = 1.0 if omega > 0.0 else -1.0
    thetas = np.linspace(0.0, 2.0 * math.pi, points, endpoint=False)
    columns = COLUMNS + (FREQUENCIES if model.compliant else ())
    out = {name: np.empty(points) for name in columns}
    rotor = model.J_m if model.compliant else 0.0  # J_0 holds J_m already when the shaft is rigid
    for k, theta in enumerate(thetas):
        s, s1, s2, _ = model.program.derivatives(float(theta))
        tan_a = s1 / (model.r_b + s)
        sigma = sign(s1 * direction)
        push = model.m * s2 * omega * omega - model.F_gx
        f = solve_guide_friction(push * tan_a + model.G_y, tan_a, sigma, model.mu, model.N_g, 0.0)
        out["theta"][k] = theta
        J_c = model.J_0 + model.m * s1 * s1
        out["J"][k] = rotor + J_c
        if model.compliant:
            out["f_r"][k], out["f_a"][k] = two_mass_frequencies(model.k_shaft, model.J_m, J_c)
        out["M_inertial"][k] = model.m * s2 * omega * omega * s1
        out["M_gravity"][k] = -model.F_gx * s1
        out["M_guide"][k] = sigma * f * s1
        out["M_shaft"][k] = model.M_f * direction
        out["M"][k] = model.load(float(theta), omega, 0.0, direction).M
    return out


def summary(result: Mapping[str, np.ndarray], rpm: float) -> dict[str, Any]:
    """The extremes and where they occur [rad]: J_min, J_max [kg m^2], M_min, M_max [N m], and the
    resonance keys f_r_min .. f_a_max [Hz] (None: the drive-train is rigid)."""
    theta = result["theta"]
    out: dict[str, Any] = {"rpm": rpm, "omega": rpm * 2.0 * math.pi / 60.0, "assumes": ASSUMES}
    names = [("J", "J"), ("M", "M")] + ([("f_r", "f_r"), ("f_a", "f_a")] if "f_r" in result else [])
    for name, key in names:
        low, high = int(np.argmin(result[name])), int(np.argmax(result[name]))
        out[f"{key}_min"], out[f"theta_{key}_min"] = float(result[name][low]), float(theta[low])
        out[f"{key}_max"], out[f"theta_{key}_max"] = float(result[name][high]), float(theta[high])
    for key in RESONANCE_KEYS:
        out.setdefault(key, None)
        out.setdefault(f"theta_{key}", None)
    return out


__all__ = ["COLUMNS", "FREQUENCIES", "PARTS", "FreeFollowerError", "RESONANCE_KEYS", "UNITS", "reflected_map", "summary",
           "two_mass_frequencies"]
