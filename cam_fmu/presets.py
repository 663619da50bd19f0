"""Named split points (T1..T6) of the general harmonic-trapezoid curve.

    name                    T1     T2     T3    T4    T5      T6
    cycloidal               1/4    1/4    1/2   1/2   3/4     3/4
    modified_sine           1/8    1/8    1/2   1/2   7/8     7/8
    modified_trapezoid      1/8    3/8    1/2   1/2   5/8     7/8
    simple_harmonic         0      0      1/2   1/2   1       1
    constant_acceleration   0      1/2    1/2   1/2   1/2     1
    mcv50                   1/16   1/16   1/4   3/4   15/16   15/16
    paper                   1/8    1/8    1/4   3/4   7/8     7/8

Sources: MODEL.md section 1 for the five classical members.  `mcv50` is the
modified constant-velocity curve with a 50 % constant-velocity part (T4 - T3
= 1/2) whose ramps are modified-sine shaped (quarter sine over 1/16, quarter
cosine over 3/16, the 1:3 ratio of the modified sine), the "MCV50" of Makino's
universal cam curve tables (H. Makino, cam-mechanism handbooks; the same table
is reproduced in index-drive makers' catalogues); these T reproduce its
tabulated Vm = 1.28, Am = 8.01, Jm = 201.4, (AV)m = 5.73 (checked in
tests/test_characteristics.py).  `paper` is the law of the paper's profile
(seed 002, section 2.1; MODEL.md section 2).

The data live in motion_law.py so that the FMU bundle needs only motion_law
and cam_program; this module is their documented public home.
"""

from .motion_law import PRESETS, law

__all__ = ["PRESETS", "law"]
