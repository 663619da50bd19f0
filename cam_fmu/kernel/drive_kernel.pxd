# C types for drive_kernel.py (Cython pure-Python mode): the .py stays the source and the fallback.
cimport cython
from libc cimport math  # math.sin & co. in the .py become C calls

cdef double TWO_PI, INF, NAN
cdef int SHAPE_CONST, SHAPE_SIN, SHAPE_COS, SEGMENT_FIELDS

cpdef double solve_guide_friction(double n0, double kappa, double sigma, double mu, double n_support,
                                  double side=*)


@cython.locals(k=int, p=double, angle=double, best=double)
cpdef double first_angle_crossed(double[:] points, int n, double start, double end)


cdef class Profile:
    cdef public double s, s1, s2, s3
    cdef public long long evaluations
    cdef double law_S, law_V, law_A, law_J
    cdef double[:] points
    cdef public int n_points
    cdef public bint laws
    cdef object program_derivatives
    cdef double[:] rise
    cdef double[:] ret
    cdef int n_rise, n_ret
    cdef double b1, b2, b3, lift, kr0, kr1, kr2, kr3, kd0, kd1, kd2, kd3

    @cython.locals(k=int, base=int, t0=double, F=double, c=double, kind=double, V0=double, S0=double,
                   u=double, x=double, sx=double, cx=double, cF=double)
    cdef void law(self, double[:] segs, int n, double T) except *
    @cython.locals(th=double)
    cpdef void profile(self, double theta) except *
    cpdef tuple derivatives(self, double theta)
    cpdef double first_breakpoint(self, double start, double end)


cdef int O_OMEGA, O_THETA, O_S, O_I, O_M, O_J, O_V, O_A, O_ALPHA, O_S_CAM, O_VOLTAGE
cdef double A21, A31, A32, A41, A42, A43, A51, A52, A53, A54, A61, A62, A63, A64, A65
cdef double B1, B3, B4, B5, B6, E1, E3, E4, E5, E6, E7
cdef int STOP, CONTACT, ENGAGE_UP, ENGAGE_DOWN, BREAK_AWAY, SIDE, EVENT_ITERATIONS
cdef double _HYSTERESIS


cdef class EnergyBudget


cdef class DriveKernel(Profile):
    cdef public double J_m, m, M_f, F_gx, G_y, N_g, mu, r_b, c, R, L, c_e, c_m
    cdef public bint follower, has_current, backlash, guide_side
    cdef public int size
    cdef public double y0, y1, y2
    cdef public bint stuck
    cdef public double direction
    cdef public int contact
    cdef public double s_free, side
    cdef double x0, J, sigma, f, n0, kappa
    cdef public double load_M, load_J, load_f, load_v, load_a, load_alpha, load_s
    cdef double d0, d1, d2
    cdef public double h_next, h_max, rtol, atol
    cdef public int max_steps
    cdef public bint k1_valid
    cdef public double k1_0, k1_1, k1_2
    cdef double z0, z1, z2, e0, e1, e2, k7_0, k7_1, k7_2
    cdef double n0_, n1_, n2_, kn0, kn1, kn2, hi0, hi1, hi2
    cdef public double fsal_u
    cdef double[:] before
    cdef double[:] after
    cdef int[:] codes
    cdef int n_events, hit
    cdef bint have_before
    cdef public object apply_event, settle_python, fail
    cdef double[:] saved

    cpdef void snapshot(self)
    cpdef void rollback(self)

    @cython.locals(s=double, s1=double, m=double, J=double, inertial=double, v_sign=double, tan_a=double)
    cdef void load_terms(self, double theta, double omega, double drive, double direction, double side) except *
    @cython.locals(drive=double)
    cpdef double omega_dot(self, double theta, double omega, double torque, double direction, bint engaged,
                           double side) except? -1e300
    cpdef double side_force(self, double theta, double omega, double torque, double direction,
                            double side) except? -1e300
    cdef double torque(self, double omega, double i, double u) noexcept
    cdef void rhs(self, double theta, double omega, double i, double u) except *
    @cython.locals(n_r=double)
    cpdef void choose_side(self, double u) except *
    cpdef void settle(self, double u) except *
    @cython.locals(torque=double, forward=double, backward=double)
    cdef double breakaway_margin(self, double theta, double i, double u) except? -1e300
    @cython.locals(s=double, s1=double, tan_a=double, shaft=double, v=double, a=double, v_sign=double,
                   sigma=double, push=double, f=double)
    cpdef void load(self, double theta, double omega, double omega_dot, double direction, bint engaged) except *
    @cython.locals(theta=double, omega=double, i=double, engaged=bint)
    cpdef void outputs(self, double u, double omega_dot, bint known, double[:] out) except *
    @cython.locals(total=double, k=int)
    cpdef int publishable(self, double[:] out, EnergyBudget budget, double u, double h) except -1
    @cython.locals(n=int)
    cdef int event_codes(self) except -1
    cdef double event_value(self, int code, double theta, double omega, double i, double u) except? -1e300

    @cython.locals(y0=double, y1=double, y2=double, p1_0=double, p1_1=double, p1_2=double,
                   p2_0=double, p2_1=double, p2_2=double, p3_0=double, p3_1=double, p3_2=double,
                   p4_0=double, p4_1=double, p4_2=double, p5_0=double, p5_1=double, p5_2=double,
                   p6_0=double, p6_1=double, p6_2=double)
    cdef void dopri_step(self, double h, double u) except *
    cdef void ensure_k1(self, double u) except *
    @cython.locals(dt=double, floor=double, atol=double, rtol=double, scale=double, total=double, norm=double,
                   factor=double)
    cdef double attempt(self, double u, double remaining, double time, double span) except? -1e300
    cdef void trial(self, double tau, double u) except *
    @cython.locals(target=double)
    cdef double current_at_rest(self, double dt, double u) noexcept
    cdef double zero_value(self, int code, double target, double theta, double omega, double i,
                           double u) except? -1e300
    @cython.locals(lo=double, hi=double, side=int, _=int, tau=double, g_tau=double)
    cdef double locate(self, int code, double target, double g_lo, double g_hi, double dt,
                       double u) except? -1e300
    @cython.locals(n=int, k=int, best=double, b0=double, b1=double, b2=double, tau=double)
    cdef double first_event(self, double dt, double u) except? -1e300
    @cython.locals(t=double, steps=int, was_stuck=bint, remaining=double, next_valid=bint, dt=double,
                   target=double, cut=double, tau=double)
    cpdef int advance(self, double u, double h, double time) except -1
    cdef public int steps
    cpdef int advance_checked(self, double u, double h, double time, double[:] out, EnergyBudget budget) except -1


cdef double _SLACK


cdef class EnergyBudget:
    cdef double c_e, L, R, F_gx
    cdef public double ratio, work_in, work_abs, theta, i, e_mech0, e_mag0

    cdef double _mech(self, double omega, double s, double J) noexcept
    @cython.locals(w=double)
    cpdef void step(self, double u, double h, double theta, double i) except *
    @cython.locals(excess=double, tolerance=double)
    cpdef double surplus(self, double omega, double s, double J, double i) except? -1e300
    @cython.locals(e_mech=double, e_mag=double, lhs=double, rhs=double, scale=double)
    cpdef tuple excess(self, double omega, double s, double J, double i)
