"""The C cost floor of the bench: an FMI 2.0 co-simulation FMU with cam.fmu's inputs and outputs.

Its model is trivial (two states, one forward-Euler step per ``fmi2DoStep``,
``c_floor/floor.c``), so a run through fmpy measures what the host itself costs
per communication step. The model description is written here from
``physics.variables`` (the same names, causalities and input start values as
cam.fmu); the binary is compiled with the system C compiler against the official FMI 2.0
headers (vendored in the engine's csrc/fmi/headers), and both are zipped into ``folder/c_floor.fmu``.
"""
from __future__ import annotations

import subprocess
import uuid
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

from ...physics.variables import INPUTS, OUTPUTS

HERE = Path(__file__).resolve().parent
C_SOURCE = HERE / "c_floor" / "floor.c"
MODEL_IDENTIFIER = "c_floor"


class CFloorError(RuntimeError):
    pass


def value_references() -> dict[str, int]:
    """Value reference of each variable: the inputs first, then the outputs (floor.c's r[k])."""
    names = [n for n, *_ in INPUTS] + [n for n, *_ in OUTPUTS]
    return {name: k for k, name in enumerate(names)}


def model_description(guid: str) -> str:
    vrs = value_references()
    variables, outputs = [], []
    for name, unit, start, meaning in INPUTS:
        variables.append(f'    <ScalarVariable name={quoteattr(name)} valueReference="{vrs[name]}" '
                         f'description={quoteattr(meaning)} causality="input" variability="continuous">\n'
                         f'      <Real start="{start!r}"/>\n    </ScalarVariable>')
    for name, unit, meaning in OUTPUTS:
        variables.append(f'    <ScalarVariable name={quoteattr(name)} valueReference="{vrs[name]}" '
                         f'description={quoteattr(meaning)} causality="output" variability="continuous" '
                         f'initial="exact">\n      <Real start="0.0"/>\n    </ScalarVariable>')
        outputs.append(f'      <Unknown index="{len(variables)}"/>')
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n'
            f'<fmiModelDescription fmiVersion="2.0" modelName="c_floor" guid="{{{guid}}}" '
            f'description="cost floor of the cam_fmu bench: cam.fmu\'s variables, a trivial C model" '
            f'generationTool="cam_fmu bench" variableNamingConvention="flat" numberOfEventIndicators="0">\n'
            f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" canHandleVariableCommunicationStepSize="true" '
            f'canInterpolateInputs="false" canGetAndSetFMUstate="false" canSerializeFMUstate="false"/>\n'
            f'  <DefaultExperiment startTime="0.0" stopTime="2.0" stepSize="0.001"/>\n'
            f'  <ModelVariables>\n' + "\n".join(variables) + '\n  </ModelVariables>\n'
            f'  <ModelStructure>\n    <Outputs>\n' + "\n".join(outputs) + '\n    </Outputs>\n'
            f'  </ModelStructure>\n</fmiModelDescription>\n')


def fmi2_include_dir() -> Path:
    """The official FMI 2.0 headers (fmi2Functions.h, ...), vendored with the engine (csrc/fmi/headers/fmi2)."""
    from ...engine.build import fmi_headers

    return fmi_headers(2)


def defines() -> dict[str, object]:
    """The macros c_floor/floor.c is compiled with: its variable counts, value references and u's start [V]."""
    vrs = value_references()
    return {"N_INPUTS": len(INPUTS), "N_OUTPUTS": len(OUTPUTS), "VR_U": vrs["u"], "VR_THETA": vrs["theta"],
            "VR_OMEGA": vrs["omega"], "START_U": repr(float(dict((n, s) for n, _u, s, _d in INPUTS)["u"]))}


def compile_binary(dest_so: Path, compiler: str | None = None) -> Path:
    from ...engine.build import find_compiler

    cc = compiler or find_compiler()
    cmd = [cc, "-shared", "-fPIC", "-O2", "-Wall", "-Wextra", f"-I{fmi2_include_dir()}",
           *(f"-D{k}={v}" for k, v in defines().items()), str(C_SOURCE), "-o", str(dest_so)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise CFloorError(f"compiling {C_SOURCE.name} failed:\n{' '.join(cmd)}\n{proc.stderr}")
    return dest_so


def build_c_floor_fmu(folder: Path, compiler: str | None = None) -> Path:
    """Compile floor.c and zip it with its model description into ``folder/c_floor.fmu``; return the .fmu."""
    import platform
    import sys

    if not sys.platform.startswith("linux") or platform.machine() not in ("x86_64", "AMD64"):
        raise CFloorError(f"the C floor is built for linux64 only (this is {sys.platform} {platform.machine()})")
    folder = Path(folder)
    so = compile_binary(folder / f"{MODEL_IDENTIFIER}.so", compiler)
    fmu = folder / f"{MODEL_IDENTIFIER}.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("modelDescription.xml", model_description(str(uuid.uuid4())))
        z.write(so, f"binaries/linux64/{MODEL_IDENTIFIER}.so")
        z.write(C_SOURCE, f"sources/{C_SOURCE.name}")
    return fmu
