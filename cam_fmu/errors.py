"""The errors a simulation reports, shared by every layer (no imports: any layer may import it).

SimulationError: the run cannot go on correctly (the FMU: fmi2Error); its message names the
parameter, input or setting and what to change. StepRejected: this step cannot be completed
at this size, the state is as before the step (the FMU: fmi2Discard where the host has it).
"""


class SimulationError(RuntimeError):
    """The simulation cannot go on correctly; the message names the setting."""


class StepRejected(SimulationError):
    """The step cannot be completed at this size (a shorter communication step may succeed)."""

    fmi_status = "discard"
