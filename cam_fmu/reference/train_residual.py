"""The residual vibration after a rise measured by running the drive (docs/model.md 14.6): the speed drive's
reference with the follower train, the cam turned at the constant speed that makes the rise last r natural
periods of the train, the end mass's free ringing read in the following dwell.

The run: the scene's parameters (its law, lift, rise angle, mounting) in the speed drive (a rigid shaft: k_shaft
= 0), the follower on the cam (closure 'kinematic', c = 0, no return spring nor restitution: the train's reference
runs no follower of its own, and 14.1's residual is that of a follower kept on the cam); a scene without an upper dwell
gets one (the rest of the turn split between the upper dwell and the return, the rise unchanged). The train: an
end mass ``m_end`` on k_train = m_end w_n^2, w_n = 2 pi ``train_hz``, damping d_train = 2 zeta sqrt(k_train m_end);
the cam speed omega = rise_angle / (r T_n), T_n = 1 / train_hz, from theta = 0 (the rise's start). Every follower
type: a translating flat carries the same train along s; an arm a torsional one about its pivot (k_train_arm =
J_end w_n^2, J_end = m_end (lift / lift_angle)^2, so that in the law's lift units, where the drive carries it, it is the
same train), its residual in psi over lift_angle: the same fraction (psi = lift_angle s / lift; docs/model.md 14.6).

The measurement: in the dwell the follower stands still at s = h and the end mass rings freely about its rest
x_e = h + F_ex / k_train (its weight's static deflection; physics/train.py). With e = x_e - s - F_ex / k_train,
e' = v_e - v and w_d = w_n sqrt(1 - zeta^2), the free ringing e = A exp(-zeta w_n t) cos(w_d t + phi) has the
envelope

    A(t) = sqrt(e^2 + ((e' + zeta w_n e) / w_d)^2) = A exp(-zeta w_n t)

at every t of the dwell. It is read at t_m = t_r + min(T_n, half the dwell) and carried back to the dwell's start,
R = A(t_m) exp(zeta w_n (t_m - t_r)) / h: the closed form's quantity (vibration/spectral.py), measured where the
drive runs the dwell. ``at_start`` is the envelope read at t_r itself (the two agree when the dwell rings freely).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping

from ..physics.drive import DriveModel
from ..physics.follower_kind import FollowerKind
from ..physics.kind_drive import KindDriveModel
from ..physics.parameters import ParameterError
from ..physics.signals import constant
from ..physics.train import Train, end_weight

__all__ = ["DriveResidual", "drive_residual", "residual_scene"]


@dataclass(frozen=True)
class DriveResidual:
    """One run of the drive for a ratio r: the residual / lift after the rise, read in the dwell."""

    r: float
    zeta: float
    residual: float     # envelope read at t_measured, carried back to the dwell's start, / lift
    at_start: float     # envelope read at the rise's end t_rise, / lift
    t_rise: float       # s
    t_measured: float   # s
    omega: float        # rad/s, the cam speed


def residual_scene(params: Mapping[str, Any], table_ok: bool = False) -> dict[str, Any]:
    """The scene's parameters for the measurement: speed drive (rigid shaft), follower on the cam (no clearance,
    return spring or restitution), from the rise's start, and an upper dwell after the rise (the rest of the turn
    split with the return when the scene has none). ``table_ok``: a motion table whose rise, lift and upper dwell
    are the parameters' rise_angle, lift and upper_dwell (a polydyne table: vibration/polydyne.py) is measured as
    it is, else refused."""
    p = dict(DriveModel(params).params)
    kind = FollowerKind.from_parameters(p)
    if not kind.default:
        KindDriveModel(p, kind)   # the type's geometry, refused as the drive refuses it
    if p.get("motion_table") and not table_ok:
        raise ParameterError("the residual through the drive needs a rise law: parameter 'motion_table' must be empty")
    # The cam's motion imposed (a rigid shaft), the follower on it: no clearance, no return spring, no restitution.
    p.update(drive="speed", closure="kinematic", c=0.0, k_shaft=0.0, k_spring=0.0, F_spring0=0.0, restitution=0.0,
             theta0=0.0, omega0=0.0)
    if p["upper_dwell"] <= 0.0 and not p.get("motion_table"):
        rest = 2.0 * math.pi - p["rise_angle"]
        back = max(0.5 * rest, 1e-3)
        if rest - back <= 0.0:
            raise ParameterError(f"parameter 'rise_angle' = {p['rise_angle']!r} rad leaves no room for a dwell after "
                                 f"the rise: allowed up to 2 pi - 2e-3 rad")
        p.update(upper_dwell=rest - back, return_angle=back, lower_dwell=0.0)
    return p


def drive_residual(params: Mapping[str, Any], r: float, zeta: float = 0.0, train_hz: float = 50.0,
                   m_end: float = 1.0, rtol: float = 1e-12, atol: float = 1e-13,
                   simulate: Callable[..., Mapping[str, Any]] | None = None, table_ok: bool = False) -> DriveResidual:
    """The residual / lift after the rise of the scene ``params`` for r = rise time / natural period (> 0) and the
    damping ratio ``zeta`` in [0, 1), by running the speed drive's reference with the train (``train_hz`` [Hz],
    ``m_end`` [kg]: the result does not depend on them but through rounding). ``simulate``: another run of the drive
    with ``simulate_reference``'s arguments (experiments.engine_runs.simulate_engine: the C engine's), by default the
    reference; ``table_ok``: see residual_scene."""
    from .integrate import simulate_reference

    simulate = simulate or simulate_reference
    for name, value, ok in (("r", r, r > 0.0), ("zeta", zeta, 0.0 <= zeta < 1.0),
                            ("train_hz", train_hz, train_hz > 0.0), ("m_end", m_end, m_end > 0.0)):
        if not (math.isfinite(value) and ok):
            allowed = {"zeta": "[0, 1) (underdamped)"}.get(name, "> 0")
            raise ValueError(f"{name} = {value!r}: allowed {allowed}")
    p = residual_scene(params, table_ok)
    w_n = 2.0 * math.pi * train_hz
    k = m_end * w_n * w_n
    train: Train | None = Train(k_train=k, d_train=2.0 * zeta * math.sqrt(k * m_end), m_end=m_end)
    deflection = end_weight(train, p) / k
    if FollowerKind.from_parameters(p).oscillating:   # the torsional train that is this one in lift units
        J_end = m_end * (p["lift"] / p["lift_angle"]) ** 2
        k_arm = J_end * w_n * w_n
        p.update(k_train_arm=k_arm, d_train_arm=2.0 * zeta * math.sqrt(k_arm * J_end), J_end=J_end)
        train, deflection = None, 0.0   # from the parameters; an end inertia has no weight along s
    t_rise = r / train_hz
    omega = p["rise_angle"] / t_rise
    t_measured = t_rise + min(1.0 / train_hz, 0.5 * p["upper_dwell"] / omega)
    out = simulate(p, t_measured, t_rise, omega_ref=constant(omega), rtol=rtol, atol=atol, train=train)
    lift = p["lift"]
    w_d = w_n * math.sqrt(1.0 - zeta * zeta)

    def envelope(j: int) -> float:
        e = out["s_end"][j] - out["s"][j] - deflection
        de = out["v_end"][j] - out["v"][j]
        return math.hypot(e, (de + zeta * w_n * e) / w_d) / lift

    decay = math.exp(zeta * w_n * (float(out["time"][-1]) - t_rise))
    return DriveResidual(r=float(r), zeta=float(zeta), residual=envelope(-1) * decay, at_start=envelope(1),
                         t_rise=t_rise, t_measured=float(out["time"][-1]), omega=omega)
