"""`cam-fmu cross-check DIR [--fmu PATH ...]`: the FMI Cross-Check folders of the project's FMUs.

Writes DIR/fmus/{FMI version}/{cs|me}/{platform}/cam_fmu/{version}/{model}/ for every
FMU (default: every shipped FMU that runs without Python, built when missing or
stale), every interface its modelDescription.xml offers and every platform it
carries a binary for: the FMU, {model}_in.csv, {model}_ref.csv, {model}_ref.opt,
ReadMe.md and {model}_fmpy.log, fmpy's validation of the folder
(tools.cross_check; docs/fmu.md#cross-check-package). Prints one line per folder;
exit status 1 when a folder fails validation (its files stay for inspection).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "cross-check", help="the FMI Cross-Check folders of the project's FMUs, validated by fmpy",
        description="Writes the files the FMI Cross-Check rules ask of an exported FMU (the FMU, input, "
                    "reference, options, ReadMe) under DIR/fmus/..., one folder per FMI version, interface and "
                    "platform, and validates each folder with fmpy.")
    p.add_argument("dir", metavar="DIR", type=Path, help="output folder (the fmus/ tree is written inside it)")
    p.add_argument("--fmu", metavar="PATH", type=Path, nargs="+", default=None,
                   help="the FMUs to package (default: the shipped FMUs that need no Python, built when missing "
                        "or older than their sources)")
    return p


def run(args) -> int:
    from ..fmu.build import ensure_fmu
    from ..tools.cross_check import validate_entry, write_package
    from ..tools.cross_check.layout import shipped_fmus

    fmus = [ensure_fmu(path) for path in args.fmu] if args.fmu else shipped_fmus()
    written = write_package(args.dir, fmus)
    failed = 0
    for entry in written:
        problems = validate_entry(entry, args.dir)
        note = "" if entry.runs_here else " (reference from this machine's binary; not re-run)"
        print(f"{entry.folder(args.dir)}: {'passed' if not problems else 'FAILED'}{note}")
        for problem in problems:
            print(f"  {problem}")
        failed += bool(problems)
    sys.stdout.flush()
    if failed:
        print(f"cam-fmu cross-check: {failed} of {len(written)} folder(s) failed fmpy's validation",
              file=sys.stderr)
        return 1
    return 0
