"""`cam-fmu simulate SCENE.toml --engine reference|fmu --out DIR`.

Writes DIR/<scene>.csv (the primary run), DIR/<scene>__<label>.csv (each
further run) and DIR/<scene>.png (the scene's figure). CSV columns: time, then
theta, omega, s, i, M, J, then the remaining outputs of physics.variables.OUTPUTS, all in
SI units, named in the header: ``time [s],theta [rad],omega [rad/s],...``
(experiments.columns; the units come from physics.variables.UNITS).
``--set NAME=VALUE`` (repeatable) overrides a parameter in every run of the scene; a value may carry a unit of
the parameter's quantity (``omega0=600rpm``, ``c=0.5mm``: physics/units.py, through ParameterSpec.check).

Progress: a bar on stderr (experiments.progress.ProgressBar), per run on the
reference engine and per communication step on the FMU, drawn only when stderr
is a terminal or CAM_FMU_PROGRESS=1 (CAM_FMU_PROGRESS=0: never). In pipes and
tests stderr carries nothing but the one error line; stdout lists the files.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

FIRST_COLUMNS = ("time", "theta", "omega", "s", "i", "M", "J")


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "simulate",
        help="run a scene (a shipped scene's name or a .toml file) and write its CSV files and figure",
        description="Run every run of a scene file on the reference integration or on the FMU; "
                    "write DIR/<scene>.csv (primary run), DIR/<scene>__<label>.csv (further runs) "
                    "and DIR/<scene>.png.")
    p.add_argument("scene", metavar="SCENE", help="a shipped scene's name (e.g. paper_fig6) or a scene file (.toml)")
    p.add_argument("--engine", choices=("reference", "fmu"), default="reference",
                   help="'reference': scipy integration (default); 'fmu': cam.fmu via fmpy "
                        "(built when missing or older than its sources)")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--fmu", metavar="FILE.fmu", default=None, help="FMU to run with --engine fmu (default: models/cam.fmu in a checkout, else a user cache)")
    p.add_argument("--stop-time", type=float, default=None, metavar="T", help="override the scene's stop_time [s]")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="override a parameter in every run (repeatable), e.g. --set m=0.6 --set rise_law=cycloidal; "
                        "a value may carry its unit, e.g. --set omega0=600rpm --set c=0.5mm")
    p.add_argument("--no-plot", action="store_true", help="write the CSV files only")
    return p


def columns(result) -> list[str]:
    """CSV column order: time, theta, omega, s, i, M, J, then the other outputs."""
    from ..physics.variables import OUTPUT_NAMES

    rest = [name for name in OUTPUT_NAMES if name not in FIRST_COLUMNS]
    rest += [name for name in result if name not in FIRST_COLUMNS and name not in rest]
    return list(FIRST_COLUMNS) + rest


def write_csv(result, path: Path) -> Path:
    from ..experiments.columns import write_csv as write_with_units

    return write_with_units(result, path, columns(result))


def apply_sets(scene, sets: list[str]):
    """The scene with ``NAME=VALUE`` overrides in [parameters] and in every run (checked as in a scene file)."""
    import copy

    from ..experiments.scenes import scene_from_dict
    from ..physics.parameters import BY_NAME
    from .cosim import parse_assignment

    if not sets:
        return scene
    raw = copy.deepcopy(scene.raw)
    params = dict(raw.get("parameters", {}))
    for text in sets:
        name, value = parse_assignment(text)
        if name not in BY_NAME or name == "drive":
            raise ValueError(f"--set {text!r}: unknown parameter {name!r} (the drive is the scene's key 'drive'); "
                             f"known: {', '.join(n for n in BY_NAME if n != 'drive')}")
        params[name] = BY_NAME[name].check(value)
        for entry in raw.get("runs", []):
            entry.pop(name, None)
    raw["parameters"] = params
    raw["runs"] = _distinct_runs(raw.get("runs", []), sets)
    return scene_from_dict(raw, name=scene.name, path=scene.path)


def _distinct_runs(runs: list[dict], sets: list[str]) -> list[dict]:
    """The runs that still differ once ``--set`` has taken their own values: a run that only repeats an
    earlier one would be written under a label that no longer says what it ran (backlash's ``c_0`` run at
    ``--set c=0.5mm``), so it is left out, with a note on stderr."""
    kept: list[dict] = []
    seen: dict[str, str] = {}
    for entry in runs:
        key = repr(sorted((k, repr(v)) for k, v in entry.items() if k != "label"))
        if key in seen:
            print(f"note: run {entry.get('label')!r} is the same as run {seen[key]!r} under "
                  f"{' '.join('--set ' + s for s in sets)}; it is not run", file=sys.stderr)
            continue
        seen[key] = str(entry.get("label"))
        kept.append(entry)
    return kept


def csv_path(out: Path, scene_name: str, label: str | None) -> Path:
    return out / (f"{scene_name}.csv" if label is None else f"{scene_name}__{label}.csv")


def run(args) -> int:
    from ..experiments.progress import ProgressBar
    from ..experiments.runner import EngineError, run_scene
    from ..experiments.scenes import SceneError, find_scene

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {args.out!r} exists and is not a directory")
    bar = None
    try:
        scene = apply_sets(find_scene(args.scene), args.set)
        if args.stop_time is not None:
            scene = scene.with_stop_time(args.stop_time)
        unit = "runs" if args.engine == "reference" else "steps"
        bar = ProgressBar(f"simulate {scene.name} ({args.engine}, {unit})")
        results = run_scene(scene, args.engine, args.fmu, progress=bar)
    except (SceneError, EngineError, ValueError) as exc:
        if bar is not None:
            bar.close()
        print(f"cam-fmu simulate: error: {exc}", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    for k, (label, result) in enumerate(results.items()):
        path = write_csv(result, csv_path(out, scene.name, None if k == 0 else label))
        omega = result["omega"]
        print(f"{path}  [{label}{', primary' if k == 0 else ''}]  t = 0..{result['time'][-1]:g} s, "
              f"omega max {omega.max():.6g} rad/s, mean {omega.mean():.6g} rad/s")
    if not args.no_plot:
        from ..plots.scene import plot_scene
        print(plot_scene(scene, results, out / f"{scene.name}.png", engine=args.engine))
    return 0
