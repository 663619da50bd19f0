"""The cost floor of the bench: a trivial pythonfmu slave with cam.fmu's inputs and outputs."""
from __future__ import annotations

import os
import subprocess
import sys
import uuid
from pathlib import Path

from ...physics.variables import INPUTS, OUTPUTS

FLOOR_TEMPLATE = '''"""Trivial slave for the cam.fmu benchmark: same variables, do_step does nothing."""
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real


class {cls}(Fmi2Slave):
    description = "cost floor of fmpy + pythonfmu (cam_fmu bench)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for name, start in {inputs!r}:
            setattr(self, name, start)
            self.register_variable(Real(name, causality=Fmi2Causality.input,
                                        variability=Fmi2Variability.continuous))
        for name in {outputs!r}:
            setattr(self, name, 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.output,
                                        variability=Fmi2Variability.continuous, initial=Fmi2Initial.exact))

    def do_step(self, current_time, step_size):
        return True
'''


def build_floor_fmu(folder: Path) -> Path:
    """Build the trivial slave (unique module and class name) into ``folder``; return the .fmu."""
    tag = f"{os.getpid()}_{uuid.uuid4().hex[:8]}"
    cls = f"BenchFloor_{tag}"
    script = folder / f"bench_floor_{tag}.py"
    script.write_text(FLOOR_TEMPLATE.format(cls=cls, inputs=[(n, s) for n, _u, s, _d in INPUTS],
                                            outputs=[n for n, _u, _d in OUTPUTS]), encoding="utf-8")
    proc = subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(script), "-d", str(folder)],
                          capture_output=True, text=True, cwd=folder, timeout=300)
    fmu = folder / f"{cls}.fmu"
    if proc.returncode != 0 or not fmu.is_file():
        raise RuntimeError(f"pythonfmu build of the floor slave failed:\n{proc.stdout}\n{proc.stderr}")
    return fmu
