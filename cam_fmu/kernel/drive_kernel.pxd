# C types for drive_kernel.py (Cython pure-Python mode): the .py stays the source and the fallback.
cimport cython

cpdef double solve_guide_friction(double n0, double kappa, double sigma, double mu, double n_support,
                                  double side)


cdef class Profile:
    cdef public double s, s1, s2, s3
    cdef double law_S, law_V, law_A, law_J
    cdef public object points
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
    @cython.locals(k=int, p=double, angle=double, best=double)
    cpdef double first_breakpoint(self, double start, double end)
