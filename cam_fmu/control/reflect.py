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
has none, and the map reports them as None.

With a follower train (k_train > 0, docs/model.md 14.6) the map is the train's low-frequency limit, the end mass
carried with the follower: J adds m_end s'^2, the inertial part m_end s'' omega^2 s', gravity -F_ex s' (its weight).
Above that the train rings: with a rigid shaft the map adds the undamped anti-resonance f_a_train =
sqrt(k_train / m_end) / (2 pi) (the end mass on its spring, which the cam cannot move there) and the resonance
f_r_train(theta) = sqrt(k_train (1 / m_end + s'^2 / J_c)) / (2 pi) of the cam (J_c = J_0 + m s'^2, a mass J_c / s'^2
along X) and the end mass on the spring between them. Plain floats through physics.drive.DriveModel; numpy only for
the arrays.

Another follower type (a translating flat face, an arm; docs/model.md 16.2): the kind's own terms (control.kind_view,
physics.kind_drive), J = [J_m +] J_0 + I_f q'^2 and M's parts with q = s or psi; the follower's friction in M_guide.
Its train (k_train on a flat, k_train_arm on an arm) enters as the roller's does, in the law's lift units along s: an
arm's J_end psi'^2 = m_end s'^2 with m_end = J_end (lift_angle / lift)^2, and f_r_train, f_a_train the same formulas.
"""
from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from ..physics.drive import DriveModel, own_follower, sign, solve_guide_friction
from ..physics.parameters import resolve
from .kind_view import KindView, kind_view

PARTS = ("M_inertial", "M_gravity", "M_guide", "M_shaft")
COLUMNS = ("theta", "J", "M", *PARTS)
FREQUENCIES = ("f_r", "f_a")  # Hz: the columns a compliant shaft adds
TRAIN_FREQUENCIES = ("f_r_train", "f_a_train")  # Hz: the columns a follower train adds (with a rigid shaft)
UNITS = {"theta": "rad", "J": "kg.m2", "M": "N.m", **{part: "N.m" for part in PARTS}, "f_r": "Hz", "f_a": "Hz",
         "f_r_train": "Hz", "f_a_train": "Hz"}
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


def train_frequencies(k_train: float, m_end: float, J_c: float, s1: float) -> tuple[float, float]:
    """(f_r_train, f_a_train) [Hz] of a train k_train [N/m] with end mass m_end [kg] on a cam side J_c [kg m2] at
    s' [m/rad] (all in the law's lift units along s): the cam, a mass J_c / s'^2 along s, and the end mass on the
    spring between them; the end mass alone on the spring, the cam held (module doc)."""
    return (math.sqrt(k_train * (1.0 / m_end + s1 * s1 / J_c)) / (2.0 * math.pi),
            math.sqrt(k_train / m_end) / (2.0 * math.pi))


def reflected_map(params: Mapping[str, Any] | None, rpm: float, points: int = 3600) -> dict[str, np.ndarray]:
    """J(theta) and M(theta) with its parts at ``points`` angles over one turn, at ``rpm`` [1/min] of the cam."""
    if not (math.isfinite(rpm) and rpm != 0.0 and abs(rpm) <= 1e6):
        raise ValueError(f"--rpm {rpm!r}: allowed a finite cam speed other than 0, |rpm| <= 1e6 1/min")
    if points < 8:
        raise ValueError(f"points = {points}: at least 8 angles over a turn")
    omega = rpm * 2.0 * math.pi / 60.0
    direction = 1.0 if omega > 0.0 else -1.0
    thetas = np.linspace(0.0, 2.0 * math.pi, points, endpoint=False)
    p = resolve(params)
    if p["follower_type"] != "translating_roller":
        if own_follower(p):  # before the kind's model, which refuses it by the rules' message
            raise FreeFollowerError(p["closure"])
        return _kind_map(kind_view(p), omega, direction, thetas)
    model = DriveModel(params)
    if model.free_follower:
        raise FreeFollowerError(model.closure)
    train = model.train if model.train.active else None
    m_end = train.m_end if train else 0.0
    F_ex = model.train_weight()
    columns = COLUMNS + (FREQUENCIES if model.compliant else ()) + (TRAIN_FREQUENCIES if train and not
                                                                     model.compliant else ())
    out = {name: np.empty(points) for name in columns}
    rotor = model.J_m if model.compliant else 0.0  # J_0 holds J_m already when the shaft is rigid
    for k, theta in enumerate(thetas):
        s, s1, s2, _ = model.program.derivatives(float(theta))
        tan_a = s1 / (model.r_b + s)
        sigma = sign(s1 * direction)
        # the end mass carried along (a train's low-frequency limit): its inertia and weight on the follower
        carried = m_end * s2 * omega * omega - F_ex
        push = model.m * s2 * omega * omega - model.F_gx + carried
        f = solve_guide_friction(push * tan_a + model.G_y, tan_a, sigma, model.mu, model.N_g, 0.0)
        out["theta"][k] = theta
        J_c = model.J_0 + model.m * s1 * s1
        out["J"][k] = rotor + J_c + m_end * s1 * s1
        if model.compliant:
            out["f_r"][k], out["f_a"][k] = two_mass_frequencies(model.k_shaft, model.J_m, J_c)
        elif train:
            out["f_r_train"][k], out["f_a_train"][k] = train_frequencies(train.k_train, m_end, J_c, s1)
        out["M_inertial"][k] = (model.m + m_end) * s2 * omega * omega * s1
        out["M_gravity"][k] = -(model.F_gx + F_ex) * s1
        out["M_guide"][k] = sigma * f * s1
        out["M_shaft"][k] = model.M_f * direction
        out["M"][k] = model.load(float(theta), omega, 0.0, direction, True, carried).M
    return out


def _kind_map(view: KindView, omega: float, direction: float, thetas: np.ndarray) -> dict[str, np.ndarray]:
    """The map of a follower of another kind (control.kind_view; physics.kind_drive): with q = s or psi and
    I_f = m or J_arm + m L^2, J = [J_m +] J_c(theta), M_inertial = I_f q'' omega^2 q', M_gravity = V'(q) q', the
    follower's friction mu |P| lambda sgn(omega) (P = I_f q'' omega^2 + V'(q): a flat face's sliding, an arm's pivot)
    in M_guide, M_shaft = M_f sgn(omega); with a compliant shaft f_r, f_a of the rotor J_m and J_c(theta). A train
    (in the law's lift units along s, control.kind_view) is carried as on the roller: J adds m_end s'^2, M_inertial
    m_end s'' omega^2 s', M_gravity -F_ex s', and that force joins P; with a rigid shaft f_r_train, f_a_train."""
    model, train = view.model, view.train
    m_end = train.m_end if train else 0.0
    F_ex = view.train_weight()
    columns = COLUMNS + (FREQUENCIES if view.compliant else ()) + (TRAIN_FREQUENCIES if train and not
                                                                    view.compliant else ())
    out = {name: np.empty(len(thetas)) for name in columns}
    rotor = view.J_m if view.compliant else 0.0
    for k, theta in enumerate(thetas):
        q, q1, q2, s = model.coordinate(float(theta))
        _, s1, s2, _ = model.program.derivatives(float(theta))
        carried = m_end * s2 * omega * omega - F_ex  # N along s: the end mass carried along, on the follower
        load = model.load(float(theta), omega, 0.0, direction, axial=carried)
        J_c = view.cam_side(float(theta))
        out["theta"][k] = theta
        out["J"][k] = rotor + J_c + m_end * s1 * s1
        if view.compliant:
            out["f_r"][k], out["f_a"][k] = two_mass_frequencies(view.k_shaft, view.J_m, J_c)
        elif train:
            out["f_r_train"][k], out["f_a_train"][k] = train_frequencies(train.k_train, m_end, J_c, s1)
        out["M_inertial"][k] = model.I_f * q2 * omega * omega * q1 + m_end * s2 * omega * omega * s1
        out["M_gravity"][k] = model.potential_slope(q) * q1 - F_ex * s1
        out["M_guide"][k] = model.mu * abs(load.P) * load.lever * direction
        out["M_shaft"][k] = model.M_f * direction
        out["M"][k] = load.M
    return out


def summary(result: Mapping[str, np.ndarray], rpm: float) -> dict[str, Any]:
    """The extremes and where they occur [rad]: J_min, J_max [kg m^2], M_min, M_max [N m], and the
    resonance keys f_r_min .. f_a_max [Hz] (None: the drive-train is rigid)."""
    theta = result["theta"]
    out: dict[str, Any] = {"rpm": rpm, "omega": rpm * 2.0 * math.pi / 60.0, "assumes": ASSUMES}
    names = [("J", "J"), ("M", "M")] + ([("f_r", "f_r"), ("f_a", "f_a")] if "f_r" in result else []) \
        + ([(name, name) for name in TRAIN_FREQUENCIES] if "f_r_train" in result else [])
    for name, key in names:
        low, high = int(np.argmin(result[name])), int(np.argmax(result[name]))
        out[f"{key}_min"], out[f"theta_{key}_min"] = float(result[name][low]), float(theta[low])
        out[f"{key}_max"], out[f"theta_{key}_max"] = float(result[name][high]), float(theta[high])
    for key in RESONANCE_KEYS:
        out.setdefault(key, None)
        out.setdefault(f"theta_{key}", None)
    return out


__all__ = ["COLUMNS", "FREQUENCIES", "TRAIN_FREQUENCIES", "PARTS", "FreeFollowerError", "RESONANCE_KEYS", "UNITS",
           "reflected_map", "summary", "train_frequencies", "two_mass_frequencies"]
