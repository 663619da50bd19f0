"""The FMI Cross-Check package of the project's FMUs (`cam-fmu cross-check DIR`).

For every FMU and interface it offers (read from its modelDescription.xml, so a Model Exchange
interface or another FMI version joins by itself), the folder the FMI Cross-Check rules ask of an
exporting tool:

    DIR/fmus/<fmi version>/<cs|me>/<platform>/cam_fmu/<package version>/<model>/
        <model>.fmu        the FMU
        <model>_in.csv     the input u [V]: a step from 0 to 3.5 V at 0.1 s (the paper's fig. 6 voltage)
        <model>_ref.csv    time and the reference outputs theta, omega, i, from a run of the FMU through fmpy
        <model>_ref.opt    StartTime, StopTime, StepSize, RelTol
        ReadMe.md          what the model is and how the reference was made
        validation.txt     fmpy's validation of the FMU (the FMU Compliance Checker is not installable here)

Platform names are the cross-check repository's (linux64 for FMI 2.0, x86_64-linux for 3.0); the
win64 binaries are in the FMUs, but their references are made on linux64 only.
"""
from __future__ import annotations

import shutil
from pathlib import Path
from typing import Iterable, List

import numpy as np

TOOL = "cam_fmu"
MODEL = "cam"
OUTPUTS = ("theta", "omega", "i")
STOP, STEP, REL_TOL = 2.0, 1e-3, 1e-4
U_STEP_TIME, U_VALUE = 0.1, 3.5
PLATFORMS = {"2.0": "linux64", "3.0": "x86_64-linux"}


def package_version() -> str:
    """The installed cam_fmu's version (the cross-check tree's tool version)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("cam_fmu")
    except PackageNotFoundError:
        return "0.1.0"


def interfaces(fmu: Path) -> List[tuple[str, str]]:
    """(FMI version, 'cs' or 'me') for every interface ``fmu`` offers."""
    from fmpy import read_model_description

    md = read_model_description(str(fmu))
    kinds = [("cs", md.coSimulation), ("me", md.modelExchange)]
    return [(md.fmiVersion, kind) for kind, offered in kinds if offered is not None]


def input_table() -> np.ndarray:
    """fmpy's structured input array of the step in u (a jump is a repeated time)."""
    rows = [(0.0, 0.0), (U_STEP_TIME, 0.0), (U_STEP_TIME, U_VALUE), (STOP, U_VALUE)]
    return np.array(rows, dtype=[("time", np.float64), ("u", np.float64)])


def simulate(fmu: Path, kind: str) -> np.ndarray:
    """A fresh fmpy run of ``fmu`` with the package's input, as its reference is made."""
    from fmpy import simulate_fmu

    return simulate_fmu(str(fmu), fmi_type="CoSimulation" if kind == "cs" else "ModelExchange", stop_time=STOP,
                        step_size=STEP, output_interval=STEP, relative_tolerance=REL_TOL if kind == "me" else None,
                        input=input_table(), output=list(OUTPUTS))


def _write_csv(path: Path, table: np.ndarray, names: Iterable[str]) -> None:
    names = list(names)
    with path.open("w", encoding="utf-8") as f:
        f.write(",".join(f'"{n}"' if n != "time" else "time" for n in names) + "\n")
        for row in table:
            f.write(",".join(repr(float(row[n])) for n in names) + "\n")


README = """# {model}: {title}

The cam drive of cam_fmu {version}: a DC motor turning a disc cam that lifts a translating roller
follower (energy-consistent hybrid model: stiction, guide friction, gravity at any mounting, backlash,
an optional compliant shaft), compiled from C (no Python inside).

- FMI {fmi}, {interface}, platform {platform}.
- Input: `u` [V], a step from 0 to {u} V at {t_step} s (`{model}_in.csv`).
- Reference (`{model}_ref.csv`): `theta` [rad], `omega` [rad/s], `i` [A] of this FMU run by fmpy
  {fmpy} with that input, {step} s communication steps, 0 to {stop} s (`{model}_ref.opt`).
- Validation: fmpy's `validate_fmu` (`validation.txt`). The FMU Compliance Checker is not installable
  from PyPI or Debian here, so its log is not part of the package.
"""


def write_package(directory: Path, fmus: Iterable[Path]) -> List[Path]:
    """Write the cross-check folders of ``fmus`` under ``directory``; the model folders written."""
    import fmpy
    from fmpy.validation import validate_fmu

    written = []
    version = package_version()
    for fmu in fmus:
        for fmi, kind in interfaces(fmu):
            platform = PLATFORMS[fmi]
            folder = Path(directory) / "fmus" / fmi / kind / platform / TOOL / version / MODEL
            folder.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(fmu, folder / f"{MODEL}.fmu")
            _write_csv(folder / f"{MODEL}_in.csv", input_table(), ("time", "u"))
            result = simulate(folder / f"{MODEL}.fmu", kind)
            _write_csv(folder / f"{MODEL}_ref.csv", result, ("time", *OUTPUTS))
            (folder / f"{MODEL}_ref.opt").write_text(
                f"StartTime,0.0\nStopTime,{STOP}\nStepSize,{STEP}\nRelTol,{REL_TOL}\n", encoding="utf-8")
            problems = validate_fmu(str(folder / f"{MODEL}.fmu"))
            (folder / "validation.txt").write_text(
                f"fmpy {fmpy.__version__} validate_fmu: " + ("no problems\n" if not problems else
                                                             "\n".join(problems) + "\n"), encoding="utf-8")
            title = "co-simulation" if kind == "cs" else "model exchange"
            (folder / "ReadMe.md").write_text(README.format(
                model=MODEL, title=title, version=version, fmi=fmi, interface=title, platform=platform,
                u=U_VALUE, t_step=U_STEP_TIME, fmpy=fmpy.__version__, step=STEP, stop=STOP), encoding="utf-8")
            written.append(folder)
    return written


__all__ = ["OUTPUTS", "input_table", "interfaces", "simulate", "write_package"]
