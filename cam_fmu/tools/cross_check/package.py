"""Write the cross-check folders: the FMU, ``_in.csv``, ``_ref.csv``, ``_ref.opt``, ReadMe.md.

The reference of an (FMU, interface) pair is computed once, on this machine's
binary, the way an importer runs the entry: the ``_in.csv`` and ``_ref.opt`` just
written are read back with fmpy's readers and passed to ``fmpy.simulate_fmu``.
Folders of other platforms (win64 on linux) get the same reference; their
ReadMe.md says which binary computed it.
"""
from __future__ import annotations

import shutil
from pathlib import Path
from typing import Iterable

import numpy as np

from .experiment import Experiment, fig6_experiment, input_table, opt_lines, reference_outputs, simulate
from .layout import CrossCheckError, Entry, entries, host_platform
from .readme import readme_text

MAX_CSV_BYTES = 1_000_000  # the rules' limit of a CSV file


def write_csv(path: Path, table: np.ndarray) -> Path:
    """``table`` (time first) as the rules' CSV: quoted names, C floating literals, no trailing comma."""
    names = table.dtype.names
    lines = [",".join(f'"{name}"' for name in names)]
    lines += [",".join(_literal(row[name]) for name in names) for row in table]
    text = "\n".join(lines) + "\n"
    if len(text) > MAX_CSV_BYTES:
        raise CrossCheckError(f"{path.name}: {len(text)} bytes, over the rules' 1 MB: fewer rows or columns")
    path.write_text(text, encoding="ascii")
    return path


def _literal(x: float) -> str:
    """12 significant digits, always with a '.' or an exponent (a C floating literal, not an integer)."""
    text = f"{float(x):.12g}"
    return text if any(c in text for c in ".en") else text + ".0"


def write_entry(entry: Entry, root: Path, exp: Experiment, reference: np.ndarray | None = None) -> np.ndarray:
    """Write ``entry``'s folder under ``root``; return its reference. ``reference``: one computed for the
    same FMU and interface on another platform's folder (else it is computed here, which needs this
    machine's binary)."""
    from fmpy import read_model_description
    from fmpy.util import read_csv, read_ref_opt_file

    folder = entry.folder(root)
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    shutil.copyfile(entry.fmu, entry.file(root, ".fmu"))
    md = read_model_description(str(entry.fmu))
    inputs = input_table(md, exp)
    if inputs is not None:
        write_csv(entry.file(root, "_in.csv"), inputs)
    opt = entry.file(root, "_ref.opt")
    opt.write_text("\n".join(opt_lines(exp, entry.fmi_type)) + "\n", encoding="ascii")
    if reference is None:
        if not entry.runs_here:
            raise CrossCheckError(f"{entry.fmu}: no binary for this machine ({host_platform(entry.fmi_version)}) "
                                  f"to compute the reference with")
        given = read_csv(entry.file(root, "_in.csv")) if inputs is not None else None
        reference = simulate(str(entry.file(root, ".fmu")), entry.fmi_type, read_ref_opt_file(str(opt)), given,
                             reference_outputs(md))
    write_csv(entry.file(root, "_ref.csv"), reference)
    computed_on = host_platform(entry.fmi_version)
    (folder / "ReadMe.md").write_text(readme_text(entry, md, exp, computed_on, inputs is not None), encoding="utf-8")
    return reference


def write_package(root: str | Path, fmus: Iterable[str | Path], exp: Experiment | None = None) -> list[Entry]:
    """Every folder of every FMU in ``fmus`` under ``root/fmus/...``; the entries written, in order.

    CrossCheckError when two FMUs would share a folder or an FMU has no binary for
    this machine (its reference could not be computed): checked before anything is written.
    """
    root = Path(root)
    if root.exists() and not root.is_dir():
        raise CrossCheckError(f"DIR {str(root)!r} exists and is not a directory")
    exp = exp or fig6_experiment()
    todo: list[Entry] = []
    for fmu in fmus:
        found = entries(fmu)
        here = {e.fmi_version for e in found if e.runs_here}
        if not here:
            raise CrossCheckError(f"--fmu {str(fmu)!r}: no binary for this machine "
                                  f"({host_platform(found[0].fmi_version)}; it carries "
                                  f"{', '.join(sorted({e.platform for e in found}))}): the reference is "
                                  f"computed by running it here")
        todo += found
    seen: dict[Path, Entry] = {}
    for entry in todo:
        other = seen.setdefault(entry.folder(root), entry)
        if other is not entry:
            raise CrossCheckError(f"{other.fmu} and {entry.fmu} would share the folder {entry.folder(root)}: "
                                  f"give FMUs of one FMI version different file names")
    # this machine's platform first: its reference serves the pair's other platforms
    todo.sort(key=lambda e: not e.runs_here)
    references: dict[tuple[Path, str], np.ndarray] = {}
    for entry in todo:
        key = (entry.fmu, entry.fmi_type)
        references[key] = write_entry(entry, root, exp, references.get(key))
    return todo
