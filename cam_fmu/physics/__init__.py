"""Physics of the cam drive: parameters, variables, motor, contact, drive model, formulations.

Plain functions and classes on floats (``math`` only), testable without the
FMU; the FMU bundles this layer.
"""
