"""cam_fmu: cam motion laws and an electromechanical cam drive as an FMI 2.0 FMU.

Kept light on purpose: importing the package imports no submodule.  Use
``from cam_fmu.kinematics.motion_law import MotionLaw``,
``from cam_fmu.kinematics.presets import law``,
``from cam_fmu.kinematics.cam_program import CamProgram, paper_program``
(the layers are described in docs/architecture.md).
"""

__version__ = "0.1.0"
