"""cam.fmu's own linux64 FMI 2.0 binary: C wrapper (fmi2_python.c), Python bridge (bridge.py), build (compile.py)."""
