"""The speed drive: omega(t) is imposed; the torque, current and voltage it needs are outputs.

Over a communication step omega(t) = omega_ref + omega_dot_ref (t - t_k), so a
ramp of omega is exact in co-simulation (docs/model.md section 8).
"""
from __future__ import annotations

from ..drive import DriveModel
from ..variables import output_record


def speed_drive_outputs(model: DriveModel, theta: float, omega: float, omega_dot: float, s: float, engaged: bool,
                        direction: float | None = None, axial: float = 0.0,
                        axial_rate: float = 0.0) -> dict[str, float]:
    """Torque, inertia, current and voltage needed for a given motion.

    c_m i = J_0 omega_dot + M, J_0 = J_m + J_cam (consistent formulation); the voltage adds
    L di/dt, with di/dt = omega dM/dtheta at constant speed (central difference,
    1e-6 rad). ``direction`` (+1, -1, 0) is the way the cam moves, sgn(omega) unless given (at a stop, the
    left limit's: the way it moved into it). ``axial`` [N] and ``axial_rate`` [N/s]: a further force on the follower
    against X and its time derivative (the follower train's, docs/model.md 14.6; 0 without one).
    """
    if direction is None:
        direction = 1.0 if omega > 0.0 else (-1.0 if omega < 0.0 else 0.0)
    load = model.load(theta, omega, omega_dot, direction, engaged, axial)
    i = (model.J_0 * omega_dot + load.M) / model.c_m
    voltage = model.motor.voltage(i, omega)
    if model.L > 0.0 and omega != 0.0:
        d = 1e-6
        dM = (model.load(theta + d, omega, omega_dot, direction, engaged, axial).M
              - model.load(theta - d, omega, omega_dot, direction, engaged, axial).M) / (2 * d)
        voltage += model.L * omega * dM / model.c_m
        if axial_rate:  # the train's force changes in time too: dM/dF_train = s' (1 + sigma df/dF_train), linear
            e = 1e-6 * max(1.0, abs(axial))  # on the friction's branch: the central difference is exact there
            dM_dF = (model.load(theta, omega, omega_dot, direction, engaged, axial + e).M
                     - model.load(theta, omega, omega_dot, direction, engaged, axial - e).M) / (2 * e)
            voltage += model.L * axial_rate * dM_dF / model.c_m
    s_cam = model.program.derivatives(theta)[0]
    return output_record(omega=omega, theta=theta, s=s, i=i, M=load.M, J=load.J, v=load.v, a=load.a,
                         alpha=load.alpha, s_cam=s_cam, voltage=voltage, N_contact=load.N,
                         theta_m=theta, omega_m=omega, M_shaft=0.0)  # a rigid drive-train
