"""The FMU: the co-simulation engine (formulation + solver), the pythonfmu slave,
the model description, and the build of cam.fmu.

Kept import-free: the FMU bundles ``engine`` and the slave script's closure only.
"""
