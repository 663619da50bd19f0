"""ReadMe.md of a cross-check folder: what the model is, the experiment, how the reference was made."""
from __future__ import annotations

from typing import Any

from ... import __version__
from .experiment import STEP_INPUT, Experiment, reference_outputs
from .layout import TOOL, Entry

VALIDATION_SUFFIX = "_fmpy.log"  # {model}_fmpy.log: fmpy's validation of the folder (validate.py)


def _unit(md: Any, name: str) -> str:
    var = next(v for v in md.modelVariables if v.name == name)
    unit = getattr(var, "unit", None) or (var.declaredType.unit if getattr(var, "declaredType", None) else None)
    return f" [{unit}]" if unit else ""


def readme_text(entry: Entry, md: Any, exp: Experiment, computed_on: str, has_inputs: bool) -> str:
    """The folder's ReadMe.md (Markdown), from the model description ``md`` and the experiment."""
    import fmpy

    m = entry.model
    held = [v for v in md.modelVariables if v.causality == "input" and v.name != STEP_INPUT]
    lines = [
        f"## {m} FMU", "", "### Model info", "",
        f"|Model Name|{m}|", "|-|-|",
        f"|Description|{' '.join((md.description or md.modelName).split())}|",
        f"|FMI Version|{entry.fmi_version}|", f"|FMI Type|{entry.interface}|", f"|Platform|{entry.platform}|",
        f"|Generation Tool|{md.generationTool or TOOL} (package version {__version__})|",
        f"|Packaged by|`cam-fmu cross-check` of {TOOL} {__version__}|", "",
        "### Experiment", "",
        f"Parameters: the FMU's defaults (an importer sets none); they are the parameters of the "
        f"scene `{exp.scene}` (the drive started from rest).",
    ]
    if has_inputs:
        lines += [
            "", f"Inputs (`{m}_in.csv`): `{STEP_INPUT}` = 0 until t = {exp.step_time:g} s, then "
            f"{exp.u_after:g} (the voltage of the scene `{exp.scene}`): the repeated time stamp is the jump; "
            f"between rows interpolate linearly, as the rules say."
            + (f" Held at their start values: {', '.join(f'`{v.name}` = {v.start}' for v in held)}." if held else ""),
        ]
    lines += [
        "", f"Settings (`{m}_ref.opt`): 0 to {exp.stop_time:g} s, "
        + (f"communication step {exp.step_size:g} s" if entry.fmi_type == "cs" else
           f"variable-step solver (StepSize 0; CVode in fmpy), output every {exp.step_size:g} s")
        + f", RelTol {exp.rel_tol:g}.", "",
        "### Reference", "",
        f"`{m}_ref.csv` holds time [s] and "
        + ", ".join(f"`{n}`{_unit(md, n)}" for n in reference_outputs(md))
        + f". It is this FMU's own result: fmpy {fmpy.__version__} `simulate_fmu` "
        f"(fmi_type '{entry.interface}'"
        + (", solver 'CVode'" if entry.fmi_type == "me" else "")
        + f", relative_tolerance = RelTol, output_interval = OutputIntervalLength) with `{m}_ref.opt` and "
        f"`{m}_in.csv` read back by fmpy's readers, on the {computed_on} binary of this FMU.",
    ]
    if entry.fmi_type == "cs":
        lines += ["", "fmpy sets the inputs at every communication point and the FMU holds them over the step; "
                      "the FMU's own integrator settings are its parameters' defaults (modelDescription.xml)."]
    if entry.platform != computed_on:
        lines += ["", f"This folder's {entry.platform} binary was not run to compute it: the reference is "
                      f"the {computed_on} binary's, built from the same C sources."]
    lines += [
        "", "### Validation", "",
        f"`{m}{VALIDATION_SUFFIX}` is fmpy's validation of this folder: `fmpy.validation.validate_fmu`, "
        f"`fmpy.cross_check.validate_vendor_repo.validate_test_fmu` (the cross-check repository's own check "
        f"of these files) and, where this machine runs the binary, a fresh run from `{m}_in.csv` and "
        f"`{m}_ref.opt` compared with `{m}_ref.csv` by `fmpy.cross_check.validate_result` (the importers' criterion: at "
        f"most 10 % of the samples outside fmpy's band) and `fmpy.util.validate_signal` (no sample outside). "
        f"The FMU Compliance Checker (fmuCheck) was not run: it has no PyPI or Debian package.", "",
    ]
    return "\n".join(lines)
