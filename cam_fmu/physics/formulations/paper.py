"""The paper's discrete simulation algorithm (section 3, steps 1-9), reproduced.

Reproduced as printed, except for the OCR errors docs/model.md corrects: step 3 sums
omega (not alpha), eq. (1) keeps its mu, c_m is in N m/A, and v/omega is taken
as ds/dtheta from the profile (undefined at omega = 0 otherwise). Signed v and
a on a fixed X axis replace the paper's unsigned values and beta flip.

What makes it differ from the consistent formulation (docs/model.md section 5):
eq. (12) divides by J = J_m + m s'^2 and subtracts an M_l that holds m a s'
with a = s'' omega^2 + s' omega_dot taken from backward differences, so the
follower's inertia m s'^2 omega_dot is counted twice, one step late. The lag
also gives a step-to-step oscillation of ratio -m s'^2 / J (about -0.98 at
the paper's peak s' = 70 mm/rad), which the fig. 6 comparison shows.

Stiction, which the paper leaves out: at omega = 0 the shaft stays at rest
while |c_m i - M_l| <= M_f, and a step that would reverse omega stops it at 0.
"""
from __future__ import annotations

import math
from ...errors import StepRejected
from ..contact import play
from ..drive import DriveModel, sign, solve_guide_friction
from ..variables import output_record


class PaperScheme:
    """State of steps 1-9 between two calls of ``step`` (SI units)."""

    FIELDS = ("theta", "omega", "i", "M", "J", "s", "v", "a", "alpha", "voltage")

    def __init__(self, model: DriveModel, theta0: float, omega0: float, i0: float) -> None:
        self.model = model
        # Step 1: initial values.
        self.theta = theta0
        self.omega = omega0
        self.i = i0 if model.L > 0.0 else 0.0
        self.J = model.J_0
        self.M = model.M_f if omega0 >= 0.0 else -model.M_f
        self.s = model.program.derivatives(theta0)[0]
        self.v = 0.0
        self.a = 0.0
        self.alpha = 0.0
        self.voltage = 0.0
        self.M_l = 0.0

    def _shaft_friction(self, drive_torque: float) -> float | None:
        """M_f with its sign, or None when the shaft stays stuck this step."""
        model = self.model
        if self.omega != 0.0:
            return model.M_f * sign(self.omega)
        net = drive_torque - self.M_l
        if abs(net) <= model.M_f:
            return None
        return model.M_f * sign(net)

    def step(self, T: float, u: float, budget: int | None = None) -> int:
        """Steps 2-8 for one calculation step T [s] under the voltage u [V]; returns the RK4 sub-steps taken.

        Raises StepRejected, before any change, when the step needs more than ``budget``
        sub-steps (default: the parameter max_steps).
        """
        model = self.model
        n = rk4_substeps(model, self.J, T)
        if n > (int(model.params["max_steps"]) if budget is None else budget):
            raise StepRejected(
                f"the paper formulation needs {n} RK4 sub-steps in one calculation step of {T:g} s "
                f"(motor rate {model.motor.electrical_rate(self.J):.3g} 1/s, L = {model.L:g} H), more than "
                f"max_steps allows: lower h_max, raise max_steps, or use formulation 'consistent' "
                f"(with solver 'etdrk4' for a stiff electrical pole)")
        self.voltage = u
        L = model.L
        motor = model.motor
        drive = model.c_m * (self.i if L > 0.0 else motor.quasi_static_current(u, self.omega))
        shaft = self._shaft_friction(drive)
        omega_old = self.omega
        if shaft is not None:
            self.M = shaft + self.M_l
            # Step 2: RK4 on eq. (12) with M and J frozen over the step.
            if L > 0.0:
                self.omega, self.i = _rk4_motor_inductive(model, self.omega, self.i, self.M, self.J, u, T)
            else:
                self.omega = _rk4_motor(model, self.omega, self.M, self.J, u, T)
            if omega_old != 0.0 and self.omega * omega_old < 0.0:
                self.omega = 0.0  # friction cannot reverse the motion
            elif omega_old == 0.0 and self.omega * shaft < 0.0:
                self.omega = 0.0
        elif L > 0.0:
            self.i = motor.current_at_rest(self.i, u, T)
        if L == 0.0:
            self.i = motor.quasi_static_current(u, self.omega)
        # Step 3: theta by summation of omega (printed as alpha: an OCR error).
        self.theta += self.omega * T
        # Step 4: profile and backlash law (eqs. 6-8).
        s_cam, s1, _, _ = model.program.derivatives(self.theta)
        s_new = play(s_cam, self.s, model.c) if model.c > 0.0 else s_cam
        # Steps 5-6: backward differences.
        v_new = (s_new - self.s) / T
        self.a = (v_new - self.v) / T
        self.v = v_new
        moved = s_new != self.s or model.c == 0.0
        self.s = s_new
        # Step 7: eqs. (1) and (3). X = ds/dtheta of the follower: the profile's while it follows.
        X = s1 if moved else 0.0
        tan_a = s1 / (model.r_b + s_cam)
        self.alpha = math.atan(tan_a)
        push = model.m * self.a - model.F_gx
        sigma = sign(self.v)
        f = solve_guide_friction(push * tan_a + model.G_y, tan_a, sigma, model.mu, model.N_g)
        self.M_l = (push + sigma * f) * X
        # Step 8: eq. (4).
        self.J = model.J_0 + model.m * X * X
        self.M = model.M_f * sign(self.omega) + self.M_l
        return n

    def contact_force(self) -> float:
        """N, the normal force of step 7's balance, (m a - F_gx + sgn(v) f) / cos(alpha) with the recorded a and v,
        while the follower follows the profile (it moved in the last step, or c = 0); 0 at rest in the clearance."""
        model = self.model
        if self.v == 0.0 and model.c > 0.0:
            return 0.0
        s_cam, s1, _, _ = model.program.derivatives(self.theta)
        tan_a = s1 / (model.r_b + s_cam)
        push, sigma = model.m * self.a - model.F_gx, sign(self.v)
        f = solve_guide_friction(push * tan_a + model.G_y, tan_a, sigma, model.mu, model.N_g)
        return (push + sigma * f) / math.cos(math.atan(tan_a))

    def outputs(self) -> dict[str, float]:
        s_cam = self.model.program.derivatives(self.theta)[0]
        return output_record(omega=self.omega, theta=self.theta, s=self.s, i=self.i, M=self.M, J=self.J,
                             v=self.v, a=self.a, alpha=self.alpha, s_cam=s_cam, voltage=self.voltage,
                             N_contact=self.contact_force(),
                             theta_m=self.theta, omega_m=self.omega, M_shaft=0.0)  # a rigid drive-train


def rk4_substeps(model: DriveModel, J: float, T: float) -> int:
    """RK4 sub-steps that keep one calculation step T [s] inside RK4's stability limit.

    The motor's own rate (the back-EMF damping c_e c_m / (R J), or the electrical
    pole with L > 0) times the sub-step stays at or below 2. At the paper's T = 1 ms
    this is 1 (J = J_m: rate 25.6 1/s); with T = 1 s it is 13 instead of a step that
    diverged and was clipped to omega = 0 (the cam never moved).
    """
    return max(1, math.ceil(T * model.motor.electrical_rate(J) / 2.0))


def _rk4_motor(model: DriveModel, omega: float, M: float, J: float, u: float, T: float) -> float:
    """RK4 on eq. (12): omega_dot = (c_m u - R M - c_e c_m omega) / (R J), in rk4_substeps sub-steps."""
    R, cm, ce = model.R, model.c_m, model.c_e
    n = rk4_substeps(model, J, T)
    h = T / n

    def f(w: float) -> float:
        return (cm * u - R * M - ce * cm * w) / (R * J)

    for _ in range(n):
        k1 = f(omega)
        k2 = f(omega + 0.5 * h * k1)
        k3 = f(omega + 0.5 * h * k2)
        k4 = f(omega + h * k3)
        omega = omega + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return omega


def _rk4_motor_inductive(model: DriveModel, omega: float, i: float, M: float, J: float, u: float,
                         T: float) -> tuple[float, float]:
    """RK4 on eqs. (9)-(10) with L > 0, in rk4_substeps sub-steps (inside RK4's stability limit)."""
    motor = model.motor
    cm, current_rate = motor.c_m, motor.current_rate
    n = rk4_substeps(model, J, T)
    h = T / n

    def f(w: float, c: float) -> tuple[float, float]:
        return (cm * c - M) / J, current_rate(u, c, w)

    for _ in range(n):
        a1, b1 = f(omega, i)
        a2, b2 = f(omega + 0.5 * h * a1, i + 0.5 * h * b1)
        a3, b3 = f(omega + 0.5 * h * a2, i + 0.5 * h * b2)
        a4, b4 = f(omega + h * a3, i + h * b3)
        omega += h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4)
        i += h / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4)
    return omega, i


def calculation_steps(h: float, h_max: float) -> int:
    """How many calculation steps T = h_max one communication step of h [s] is: the grid is fixed, so the
    scheme's answer does not follow the host's step pattern. StepRejected when h is no whole number of
    them (to 1e-9 relative)."""
    ratio = h / h_max
    n = math.floor(ratio + 0.5)
    if n < 1 or abs(ratio - n) > 1e-9 * n:
        raise StepRejected(
            f"formulation 'paper' computes on a fixed grid of calculation steps of h_max = {h_max:g} s; a "
            f"communication step of {h:g} s is not a whole number of them: use communication steps that are "
            "multiples of h_max, or set h_max to the communication step")
    return n
