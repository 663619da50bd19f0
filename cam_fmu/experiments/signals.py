"""The former path of the input signals, kept for existing imports: they are ``cam_fmu.physics.signals``
now (the reference integrates them, and the reference imports nothing of the experiments)."""
from ..physics.signals import (OPTIONAL_KEYS, SIGNAL_KEYS, SIGNAL_KINDS, Signal, as_table,  # noqa: F401
                               constant, from_spec)
