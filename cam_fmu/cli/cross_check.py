"""`cam-fmu cross-check DIR [--fmu PATH ...]`: the FMI Cross-Check package of the project's FMUs.

Writes DIR/fmus/<fmi version>/<cs|me>/<platform>/cam_fmu/<version>/cam/ for every FMU (default:
models/cam.fmu and models/cam3.fmu, built when missing or stale) and every interface it offers:
the FMU, its input and reference CSV files, the options file, a ReadMe and fmpy's validation
(cam_fmu/tools/cross_check.py; docs/fmu.md "Cross-check package").
"""
from __future__ import annotations

import argparse
from pathlib import Path


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("cross-check", help="the FMI Cross-Check package of the FMUs",
                              description="Write the files the FMI Cross-Check rules ask of an exported FMU.")
    p.add_argument("directory", metavar="DIR", help="where the fmus/ tree is written")
    p.add_argument("--fmu", action="append", default=None, metavar="PATH",
                   help="an FMU to package (repeatable; default: models/cam.fmu and models/cam3.fmu)")
    return p


def run(args) -> int:
    from ..experiments.fmu_file import ensure_fmu
    from ..tools.cross_check import write_package

    fmus = [ensure_fmu(path) for path in args.fmu] if args.fmu else [ensure_fmu(None, print, m)
                                                                      for m in ("cam", "cam3")]
    for folder in write_package(Path(args.directory), fmus):
        print(folder)
    return 0
