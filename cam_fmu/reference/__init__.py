"""The direct-Python reference integration (scipy): the ground truth the FMU is tested against."""
from .integrate import ENERGY, simulate_reference

__all__ = ["ENERGY", "simulate_reference"]
