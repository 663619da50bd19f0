"""fmpy's validation of a cross-check folder, written to ``{model}_fmpy.log``.

Three checks, each fmpy's own:

- ``fmpy.validation.validate_fmu``: the model description against the schema and its rules;
- ``fmpy.cross_check.validate_vendor_repo.validate_test_fmu``: what the cross-check
  repository checks of an exported FMU's folder (FMI version and type against the
  path, the ``_ref.opt`` keys, the CSV files' names, columns and time, file sizes);
- where this machine runs the folder's binary: a fresh run, as an importer makes it
  from ``_in.csv`` and ``_ref.opt``, against ``_ref.csv`` by
  ``fmpy.cross_check.validate_result`` (at most 10 % of the samples of any column
  outside fmpy's band around the reference: the importers' pass criterion) and by
  ``fmpy.util.validate_signal`` (no sample outside: the same binary must reproduce it).

The FMU Compliance Checker (fmuCheck) is not run: it has no PyPI or Debian package.
The log says so.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from .experiment import simulate
from .layout import Entry, host_platform
from .readme import VALIDATION_SUFFIX


def rerun_problem(entry: Entry, root: Path) -> str | None:
    """A fresh run of the folder's FMU from its ``_in.csv`` and ``_ref.opt`` against its ``_ref.csv``:
    None when fmpy's validate_result passes it and no sample is outside validate_signal's band, else what
    failed."""
    from fmpy.cross_check import validate_result
    from fmpy.util import read_csv, read_ref_opt_file

    opts = read_ref_opt_file(str(entry.file(root, "_ref.opt")))
    in_csv = entry.file(root, "_in.csv")
    inputs = read_csv(str(in_csv)) if in_csv.is_file() else None
    reference = read_csv(str(entry.file(root, "_ref.csv")))
    names = list(reference.dtype.names[1:])
    result = simulate(str(entry.file(root, ".fmu")), entry.fmi_type, opts, inputs, names)
    with warnings.catch_warnings():  # fmpy 0.3.32 imports scipy.ndimage.filters (deprecated, same functions)
        warnings.simplefilter("ignore", DeprecationWarning)
        problem = validate_result(result=result, reference=reference, t_start=opts["StartTime"],
                                  t_stop=opts["StopTime"])
    if problem is not None:
        return problem
    outside = {name: n for name in names if (n := outliers(result, reference, name))}
    if outside:
        return "samples outside fmpy.util.validate_signal's band: " + ", ".join(
            f"{n} of {name!r}" for name, n in outside.items())
    return None


def outliers(result, reference, name: str) -> int:
    """How many samples of ``result[name]`` lie outside fmpy.util.validate_signal's band around the
    reference (stricter than validate_result, which lets 10 % of them out: the same FMU on the same
    machine must reproduce its reference)."""
    from fmpy.util import validate_signal

    t_ref = np.array(reference["time"], dtype=float)  # validate_signal edits t_ref in place
    *_, i_out = validate_signal(t=result["time"], y=result[name], t_ref=t_ref, y_ref=reference[name])
    return int(np.count_nonzero(i_out))


def validate_entry(entry: Entry, root: str | Path) -> list[str]:
    """fmpy's problems with ``entry``'s folder under ``root`` (empty: valid); writes ``{model}_fmpy.log``."""
    import fmpy
    from fmpy.cross_check.validate_vendor_repo import validate_test_fmu
    from fmpy.validation import validate_fmu

    root = Path(root)
    fmu = entry.file(root, ".fmu")
    lines = [f"fmpy {fmpy.__version__}: validation of {entry.model} (FMI {entry.fmi_version}, {entry.interface}, "
             f"{entry.platform})", "FMU Compliance Checker (fmuCheck): not run: it has no PyPI or Debian package"]
    problems: list[str] = []
    for label, found in (("fmpy.validation.validate_fmu", validate_fmu(str(fmu))),
                         ("fmpy.cross_check.validate_vendor_repo.validate_test_fmu",
                          validate_test_fmu(str(entry.folder(root))))):
        lines.append(f"{label}: {len(found)} problem(s)")
        lines += [f"  {' '.join(str(p).split())}" for p in found]
        problems += [f"{label}: {' '.join(str(p).split())}" for p in found]
    if entry.runs_here:
        try:
            problem = rerun_problem(entry, root)
        except Exception as exc:  # noqa: BLE001 - a run that fails is a problem to report, not a crash
            problem = f"the run failed: {' '.join(str(exc).split()) or type(exc).__name__}"
        lines.append(f"fresh run against {entry.model}_ref.csv (fmpy.cross_check.validate_result, "
                     f"fmpy.util.validate_signal): "
                     f"{'passed' if problem is None else problem}")
        if problem is not None:
            problems.append(f"fresh run: {problem}")
    else:
        lines.append(f"fresh run: not made, this machine runs {host_platform(entry.fmi_version)} binaries, "
                     f"not {entry.platform}")
    lines.append(f"result: {'passed' if not problems else 'FAILED'}")
    entry.file(root, VALIDATION_SUFFIX).write_text("\n".join(lines) + "\n", encoding="utf-8")
    return problems
