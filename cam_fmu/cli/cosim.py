"""`cam-fmu cosim SSP [--set comp.NAME=VALUE] [--gains KP:KI,...] [--feedforward off|on|both] [--out DIR]`.

Runs an SSP file (default: models/speed_loop.ssp, built when missing) on the
project's fixed-step co-simulation master (experiments.cosim.simulate_system)
and writes DIR/<system>.csv (every connector, unit headers) and
DIR/<system>.png (speed error and armature voltage). With --gains and/or
--feedforward it runs the speed loop once per combination (labels
``kp=2 ki=20`` and ``kp=2 ki=20+ff``), writes one CSV per run, one figure and
DIR/<system>_ripple.csv: the peak-to-peak speed ripple of each run over the
second half of the run.

An interrupt (Ctrl-C, SIGINT) stops the run at the next communication step and
keeps what finished: the CSV files of the runs before it and the interrupted
run's rows up to that step; one line on stderr says so; exit status 130.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "cosim", help="run an SSP (e.g. models/speed_loop.ssp) on the project's co-simulation master",
        description="Fixed-step (Jacobi) co-simulation of an SSP file on fmpy's FMU2Slave: parameter values "
                    "of the file applied, the first step sees each FMU's initial outputs, rows labelled with "
                    "the time their values belong to. Writes CSV (unit headers) and a figure.")
    p.add_argument("ssp", metavar="SSP", nargs="?", default=None,
                   help="SSP file (default: models/speed_loop.ssp, built when missing or stale)")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--stop-time", type=float, default=None, metavar="T", help="override the SSP's stop time [s]")
    p.add_argument("--step-size", type=float, default=None, metavar="H",
                   help="override the SSP's communication step [s]")
    p.add_argument("--set", action="append", default=[], metavar="COMP.NAME=VALUE",
                   help="parameter value for a component (repeatable), e.g. controller.kp=5 or cam.m=0.6; a value "
                        "may carry its unit, e.g. controller.omega_set=600rpm")
    p.add_argument("--gains", metavar="KP:KI,...", default=None,
                   help="run once per controller gain pair, e.g. 1:10,2:20,5:50 [V/(rad/s)]:[V/rad]")
    p.add_argument("--feedforward", choices=("off", "on", "both"), default=None,
                   help="controller feedforward in the runs (default: as the SSP says)")
    p.add_argument("--controller", metavar="FMU", default=None,
                   help="close the speed loop around cam.fmu with this controller FMU instead of an SSP (e.g. a "
                        "block written in Python: cam-fmu python-block); it needs an input omega_meas and an "
                        "output u, and gets M_load and J_load when it has them")
    p.add_argument("--no-plot", action="store_true", help="write the CSV files only")
    return p


def controller_loop(controller: Path, folder: Path) -> Path:
    """The speed loop of models/speed_loop.ssp with ``controller`` (an FMU file) in place of pi_speed.fmu,
    written into ``folder``; the connections follow the controller's inputs (M_load, J_load when it has them)."""
    from fmpy import read_model_description

    from ..fmu.build import ensure_fmu
    from ..fmu.ssp import SPEED_LOOP_CAM, speed_loop_system, write_ssp

    if not controller.is_file():
        raise ValueError(f"--controller {str(controller)!r}: no such FMU file")
    variables = {v.name: v.causality for v in read_model_description(str(controller)).modelVariables}
    missing = [name for name, causality in (("omega_meas", "input"), ("u", "output"))
               if variables.get(name) != causality]
    if missing:
        raise ValueError(f"--controller {str(controller)!r}: needs an input 'omega_meas' and an output 'u' "
                         f"(missing or of another causality: {', '.join(missing)})")
    feedforward = variables.get("M_load") == "input" and variables.get("J_load") == "input"
    system = speed_loop_system(SPEED_LOOP_CAM, {}, feedforward_connections=feedforward,
                               name=f"speed_loop_{controller.stem}")
    return write_ssp(system, {"cam": ensure_fmu(None), "controller": controller}, folder / f"{system.name}.ssp")


def parse_assignment(text: str, option: str = "--set") -> tuple[str, str]:
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise ValueError(f"{option} {text!r}: expected NAME=VALUE")
    return name.strip(), value.strip()


def _gains(text: str) -> list[tuple[float, float]]:
    pairs = []
    for item in text.split(","):
        kp, sep, ki = item.partition(":")
        try:
            pairs.append((float(kp), float(ki)))
        except ValueError:
            raise ValueError(f"--gains {text!r}: expected KP:KI pairs separated by commas, e.g. 1:10,2:20") from None
        if not sep:
            raise ValueError(f"--gains {text!r}: expected KP:KI pairs separated by commas, e.g. 1:10,2:20")
    return pairs


def _typed(value: str):
    low = value.lower()
    if low in ("true", "false"):
        return low == "true"
    try:
        return float(value)
    except ValueError:
        return value


def run(args) -> int:
    import copy

    from ..control import pi
    from ..experiments.columns import write_csv
    from ..experiments.cosim import CosimInterrupted, ripple, simulate_system
    from ..fmu.build import ensure_ssp
    from ..fmu.ssp import read_ssp
    from ..physics.parameters import BY_NAME, resolve

    if args.controller and args.ssp:
        raise ValueError("give either an SSP file or --controller FMU, not both")
    out = Path(args.out)
    if args.controller:
        out.mkdir(parents=True, exist_ok=True)
        system = read_ssp(controller_loop(Path(args.controller), out))
    else:
        system = read_ssp(ensure_ssp(args.ssp, log=print))  # progress on stdout: stderr carries only the error line
    for text in args.set:
        name, value = parse_assignment(text)
        comp, _, var = name.partition(".")
        if comp not in system.components or not var:
            raise ValueError(f"--set {text!r}: expected COMP.NAME=VALUE with COMP one of "
                             f"{', '.join(system.components)}")
        if comp == "controller" and args.controller:  # a controller of the user's: its FMU checks its values
            system.components[comp].parameters[var] = _typed(value)
            continue
        table = pi.BY_NAME if comp == "controller" else BY_NAME
        if var not in table:
            raise ValueError(f"--set {text!r}: {comp} has no parameter {var!r}; known: {', '.join(table)}")
        system.components[comp].parameters[var] = table[var].check(_typed(value))
    variants = {"": {}}
    if args.gains or args.feedforward:
        if args.controller and args.feedforward:
            raise ValueError("--feedforward is pi_speed.fmu's parameter: not for --controller")
        if "controller" not in system.components:
            raise ValueError("--gains/--feedforward need a component named 'controller' (pi_speed.fmu)")
        gains = _gains(args.gains) if args.gains else [(None, None)]
        ffs = {"off": [False], "on": [True], "both": [False, True], None: [None]}[args.feedforward]
        variants = {}
        for ff in ffs:
            for kp, ki in gains:
                label = "" if kp is None else f"kp={kp:g} ki={ki:g}"
                label = (label or "base") + ("+ff" if ff else "")
                over = {} if kp is None else {"kp": kp, "ki": ki}
                if ff is not None:
                    over["feedforward"] = 1.0 if ff else 0.0
                variants[label] = over
    resolve(system.components.get("cam").parameters if "cam" in system.components else {})
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    runs, ripples, setpoints = {}, {}, {}
    for label, over in variants.items():
        sysk = copy.deepcopy(system)
        if over:
            sysk.components["controller"].parameters.update(over)
        ctrl = (pi.resolve(sysk.components["controller"].parameters)
                if "controller" in sysk.components and not args.controller else None)
        stop = args.stop_time if args.stop_time is not None else sysk.stop_time
        bar = _progress(f"{label or system.name}")
        cam = sysk.components.get("cam")
        compliant = cam is not None and float(cam.parameters.get("k_shaft", 0.0)) > 0.0
        record = ["cam.omega", "cam.omega_m"] if compliant else None  # both sides of the shaft
        stem = label.replace("=", "").replace(" ", "_").replace("+", "_")
        name = system.name if not label else f"{system.name}__{stem}"
        try:
            result = simulate_system(sysk, stop, args.step_size, record=record, progress=bar)
        except CosimInterrupted as stop_early:  # keep what finished: this run's rows so far, the runs before it
            bar.close()
            path = write_csv(stop_early.result, out / f"{name}.csv")
            steps = len(stop_early.result["time"]) - 1
            before = f"; the {len(runs)} runs before it in {out}" if runs else ""
            print(f"cam-fmu cosim: interrupted at t = {stop_early.result['time'][-1]:.6g} s ({steps} of "
                  f"{stop_early.steps} steps): kept in {path}{before}", file=sys.stderr)
            return 130
        path = write_csv(result, out / f"{name}.csv")
        key = label or system.name
        runs[key] = result
        if "cam.omega" in result:
            ripples[key] = ripple(result["time"], result["cam.omega"])
            setpoints[key] = ctrl["omega_set"] if ctrl else float("nan")
            print(f"{path}  ripple {ripples[key]:.6g} rad/s (peak-to-peak, 2nd half), "
                  f"mean omega {result['cam.omega'][len(result['time']) // 2:].mean():.6g} rad/s")
        else:
            print(path)
    if ripples and len(variants) > 1:
        with open(out / f"{system.name}_ripple.csv", "w", encoding="utf-8") as fh:
            fh.write("run,ripple [rad/s]\n")
            for key, value in ripples.items():
                fh.write(f"{key},{value:.6g}\n")
        print(out / f"{system.name}_ripple.csv")
    if not args.no_plot and runs and all("cam.omega_m" in r for r in runs.values()):
        from ..plots.speed_loop import plot_two_speeds
        print(plot_two_speeds(runs, out / f"{system.name}.png",
                              title=f"{system.name}: PI loop around a compliant shaft (engine: cam-fmu cosim)"))
    elif not args.no_plot and ripples and all("controller.u" in r for r in runs.values()):
        from ..plots.speed_loop import plot_speed_loop
        print(plot_speed_loop(runs, setpoints, ripples, out / f"{system.name}.png",
                              title=f"{system.name}: PI speed loop around cam.fmu (engine: cam-fmu cosim)"))
    return 0


def _progress(label: str):
    """A progress callback drawing a bar on stderr when it is a terminal (quiet in pipes and tests)."""
    from ..experiments.progress import ProgressBar

    return ProgressBar(label)
