"""The FMUs: every one a C model on the one FMI glue (``engine_fmu``), their model descriptions, the
controller's generated variable table, the build of every FMU and SSP (``build``), and pythonfmu for blocks
users write in Python (``python_block``). Kept import-free."""
