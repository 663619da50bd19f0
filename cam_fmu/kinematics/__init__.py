"""Kinematics: motion laws, their presets and characteristic values, cam programs.

Dimensionless laws (``motion_law``), the one table of named laws (``presets``),
characteristic values (``characteristics``) and a full cam cycle in SI units
(``cam_program``). ``math`` and numpy only; the C engine's own laws (``engine/csrc``) are held to these.
"""
