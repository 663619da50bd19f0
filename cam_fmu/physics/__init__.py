"""Physics of the cam drive: parameters, variables, motor, contact, drive model, formulations.

Plain functions and classes on floats (``math`` only), testable without the
engine: the readable model the scipy reference integrates, written apart from the C engine (no FMU carries
Python; docs/architecture.md).
"""
