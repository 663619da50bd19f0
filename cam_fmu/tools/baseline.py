"""The drive engine's outputs recorded as a baseline, and a replay that holds any engine to it.

    python -m cam_fmu.tools.baseline --write    # record (the engine of this checkout)
    python -m cam_fmu.tools.baseline --check    # replay and compare; prints the largest difference
    python -m cam_fmu.tools.baseline --rerecord WHY [--keep NAME=VALUE] [--only CASE ...]   # only the moved cases
    python -m cam_fmu.tools.baseline --add WHY        # record only the cases not recorded yet (a new solver)

Engine-agnostic: a case runs through the public in-process API only,
``DriveSimulator(params)``, ``set_inputs``, ``do_step(t, h, u, omega_ref, omega_dot_ref)``
and ``outputs()``, so a new engine behind that API is compared with the old one's record
(tests/engine/test_engine_baseline.py).

The cases:
- every shipped scene (experiments/scene_files) x each of its runs x every solver x each
  formulation the scene admits ('consistent' and 'paper' for a voltage scene; the speed drive
  is its own formulation, run with every solver all the same), with the run's own parameters,
  the scene's input signals (``runner.input_signals``, what its FMU runs get), output interval
  and stop time. Runs that come out with the same parameters are recorded once;
- 60 cases of the extremes property test (tests/engine/test_extremes_property.py): its own
  ``extremes.draw``, with random.Random(seed) for seeds 0..59. Not the test's hypothesis draws
  themselves: those are not reproducible outside it (hypothesis mixes into its draws the
  constants of the modules imported so far: the same derandomised test draws other cases when
  the engine was imported before it, as in the full suite, than when run alone).
Each case is stored whole (parameters, communication step, stop time, input signals), so the
replay needs neither the scene files nor the draw; the test checks apart that every run of
every shipped scene is among the recorded cases (an edited scene fails there, not in the replay).

The replay: inputs set at t = 0, then communication step k (k = 1..n, n = round(stop /
comm)) from t = (k-1) comm to k comm (the clock of extremes.run), inputs = each signal's
value at the step's start. A case that is refused or stops with an exception records the
exception's class, the step k at which it was raised (0: at DriveSimulator(params) or
set_inputs) and its message: that is behaviour too.

What is recorded, and why it suffices: every output at step 0 and at every s-th step,
s = max(1, n // 100) (>= 100 samples per run; all steps of the short extremes cases), always
the last step reached, and the full outputs at the end. The engine carries its state from
step to step, so a difference at any step (a constant, an operation order, an event found one
step later, a changed step size of rk45) shows in every later sample: sampling loses nothing
but the step at which a divergence began. Floats are written by ``json`` with ``repr``, which
round-trips exactly. The files also hold the Python, numpy, scipy and hypothesis versions
(the first records also the Cython version of the engine they recorded) and the git commit the
record was made at; a change of the engine that moves answers on purpose re-records only the cases
it moves, and the file's "re_recorded" list names them with the commit they were re-recorded on and
why (``rerecord``; ``load`` reads it; ``write`` records everything anew). Where the move is a changed default
(closure 'form'), ``--keep closure=kinematic`` keeps each moved case's former record beside it, under the old
default named explicitly, so the old behaviour stays held to the former engine's record.

The comparison (``compare``): every recorded sample to RTOL = 1e-12 relative, where a value
below ZERO = 1e-3 of its output's scale (the largest |value| of that output over the case's
samples) is held to the absolute floor RTOL * ZERO * scale (about 5 ulp of the scale); an
output that is 0 throughout must stay 0. An error case: the same class at the same step, the
same message with its numbers (printed to 6 digits) equal to 1e-5 relative.
"""
from __future__ import annotations

import argparse
import json
import math
import platform
import re
import subprocess
import sys
from pathlib import Path
from typing import Any, Iterator

ROOT = Path(__file__).resolve().parents[2]
RECORD_DIR = ROOT / "tests" / "data" / "engine_baseline"
EXTREMES = 60  # extremes cases, as many as the property test draws
SAMPLES = 100  # at least this many samples per run
RTOL = 1e-12
ZERO = 1e-3  # |value| < ZERO * scale counts as ~0
MESSAGE_RTOL = 1e-5
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|\b(?:nan|inf)\b")


# ------------------------------------------------------------------ cases
def _signal_dict(sig: Any) -> dict[str, Any]:
    return {"times": list(sig.times), "values": list(sig.values), "hold": sig.hold}


def scene_cases(name: str) -> list[dict[str, Any]]:
    """The cases of one shipped scene: its runs x solvers x formulations, duplicates dropped."""
    from ..experiments.runner import every_input, input_signals
    from ..experiments.scenes import find_scene
    from ..physics.parameters import FORMULATIONS, SOLVERS, resolve

    scene = find_scene(name)
    inputs = {k: _signal_dict(s) for k, s in every_input(input_signals(scene)).items()}
    formulations = FORMULATIONS if scene.drive == "voltage" else (None,)  # the speed drive: its own
    cases, seen = [], []
    for run in scene.runs:
        for solver in SOLVERS:
            for formulation in formulations:
                params = dict(run.overrides, solver=solver)
                if formulation:
                    params["formulation"] = formulation
                resolved = resolve(params)
                if resolved in seen:
                    continue
                seen.append(resolved)
                cases.append({"name": f"{name}/{run.label}/{solver}/{formulation or scene.drive}", "params": params,
                              "comm_step": scene.output_interval, "stop_time": scene.stop_time, "inputs": inputs})
    return cases


def extremes_cases(count: int = EXTREMES) -> list[dict[str, Any]]:
    """``count`` cases of the extremes property (``extremes.draw``), drawn with random.Random(seed)
    for seeds 0..count-1."""
    import random

    from . import extremes

    cases = []
    for seed in range(count):
        case = extremes.draw(random.Random(seed))
        u = {"times": [t for t, _u in case.u_steps], "values": [u for _t, u in case.u_steps], "hold": True}
        inputs = {"u": u, "omega_ref": {"times": [0.0], "values": [case.omega_ref], "hold": False},
                  "omega_dot_ref": {"times": [0.0], "values": [0.0], "hold": False}}
        cases.append({"name": f"extremes/seed{seed}", "params": dict(case.params), "comm_step": case.comm_step,
                      "stop_time": case.stop_time, "inputs": inputs})
    return cases


# ------------------------------------------------------------------ replay
def stride(n: int) -> int:
    """Record every stride(n)-th of n communication steps: at least SAMPLES samples."""
    return max(1, n // SAMPLES)


def replay(case: dict[str, Any]) -> dict[str, Any]:
    """Run one case on the engine: the sampled outputs, the final outputs and the error (or None)."""
    from ..physics.signals import Signal
    from ..fmu.engine import DriveSimulator
    from ..physics.variables import OUTPUT_NAMES

    signals = {name: Signal(tuple(s["times"]), tuple(s["values"]), s["hold"]) for name, s in case["inputs"].items()}
    comm = case["comm_step"]
    n = max(1, round(case["stop_time"] / comm))
    every = stride(n)
    steps: list[int] = []
    samples: dict[str, list[float]] = {name: [] for name in OUTPUT_NAMES}
    error = None
    out: dict[str, float] = {}

    def sample(k: int) -> None:
        steps.append(k)
        for name in OUTPUT_NAMES:
            samples[name].append(out[name])

    k = 0
    try:
        sim = DriveSimulator(case["params"])
        sim.set_inputs(*(sig.value(0.0) for sig in signals.values()))
        out = sim.outputs()
        sample(0)
        for k in range(1, n + 1):
            t = (k - 1) * comm
            sim.do_step(t, k * comm - t, *(sig.value(t) for sig in signals.values()))
            out = sim.outputs()
            if k % every == 0 or k == n:
                sample(k)
    except Exception as exc:  # noqa: BLE001 - a refusal or a failure is recorded as behaviour
        error = {"class": type(exc).__name__, "step": k, "message": str(exc)}
        if steps and steps[-1] != k - 1 and k > 0:
            sample(k - 1)  # the last step reached
    return {"steps": steps, "outputs": samples, "final": dict(out), "error": error}


# ------------------------------------------------------------------ compare
def compare(recorded: dict[str, Any], result: dict[str, Any], rtol: float = RTOL) -> tuple[list[str], float]:
    """The differences of ``result`` (a replay) from ``recorded``, and the largest
    |difference| / tolerance over the samples (<= 1 passes; 0: bit-identical). ``rtol``: the
    relative tolerance (RTOL unless a change of the engine is meant to move the numbers)."""
    problems, worst = [], 0.0
    if result["error"] is None or recorded["error"] is None:
        if result["error"] != recorded["error"]:
            problems.append(f"error {recorded['error']} recorded, {result['error']} now")
    else:
        problems += _compare_error(recorded["error"], result["error"])
    if result["steps"] != recorded["steps"]:
        problems.append(f"sampled steps differ: recorded up to {recorded['steps'][-1:]}, now {result['steps'][-1:]}")
        return problems, math.inf
    for name, old in recorded["outputs"].items():
        new = result["outputs"][name]
        scale = max((abs(x) for x in old), default=0.0)
        for k, a, b in zip(recorded["steps"], old, new):
            if a == b or (math.isnan(a) and math.isnan(b)):
                continue
            tol = rtol * max(abs(a), ZERO * scale)
            ratio = abs(a - b) / tol if tol > 0.0 else math.inf
            worst = max(worst, ratio)
            if not ratio <= 1.0:
                problems.append(f"{name} at step {k}: recorded {a!r}, now {b!r} (|diff| = {abs(a - b):.3g}, "
                                f"tolerance {tol:.3g})")
                break  # the first divergence per output: later samples follow from it
    return problems, worst


def _compare_error(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    if (old["class"], old["step"]) != (new["class"], new["step"]):
        return [f"error {old['class']} at step {old['step']} recorded, {new['class']} at step {new['step']} now"]
    words_old, words_new = _NUMBER.sub("#", old["message"]), _NUMBER.sub("#", new["message"])
    numbers = zip(_NUMBER.findall(old["message"]), _NUMBER.findall(new["message"]))
    if words_old != words_new or not all(_close(a, b) for a, b in numbers):
        return [f"message {old['message']!r} recorded, {new['message']!r} now"]
    return []


def _close(a: str, b: str) -> bool:
    x, y = float(a), float(b)
    return x == y or (math.isnan(x) and math.isnan(y)) or abs(x - y) <= MESSAGE_RTOL * max(abs(x), abs(y))


# ------------------------------------------------------------------ files
# The shipped scenes when the record was made (before the C engine replaced the Python one). Scenes added
# since (the compliant shaft's) model what the former engine could not: they are checked against the
# scipy reference instead (tests/physics/test_compliant_shaft.py).
RECORDED_SCENES = ("backlash", "inductance", "paper_fig4", "paper_fig5a", "paper_fig5b", "paper_fig6",
                   "speed_drive", "tilted")
def groups() -> Iterator[tuple[str, list[dict[str, Any]]]]:
    """(file stem, cases): one group per shipped scene, then 'extremes'."""
    for name in RECORDED_SCENES:
        yield name, scene_cases(name)
    yield "extremes", extremes_cases()


def provenance() -> dict[str, Any]:
    """Versions, platform and git commit of this recording."""
    import numpy
    import scipy

    info: dict[str, Any] = {"python": platform.python_version(), "numpy": numpy.__version__,
                            "scipy": scipy.__version__, "machine": platform.machine()}
    for module in ("hypothesis",):
        try:
            info[module.lower()] = __import__(module).__version__
        except ImportError:
            info[module.lower()] = None
    git = ["git", "-C", str(ROOT)]
    try:
        commit = subprocess.run(git + ["rev-parse", "HEAD"], capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(git + ["status", "--porcelain", "--", "cam_fmu"], capture_output=True, text=True,
                               check=True).stdout.strip()
        info["commit"] = commit + ("+uncommitted changes in cam_fmu" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        info["commit"] = None
    return info


def write(directory: Path = RECORD_DIR) -> list[Path]:
    """Record every group into directory/<stem>.json."""
    directory.mkdir(parents=True, exist_ok=True)
    about = provenance()
    written = []
    for stem, cases in groups():
        for case in cases:
            case["result"] = replay(case)
        path = directory / f"{stem}.json"
        rows = ",\n".join(json.dumps(case, separators=(",", ":")) for case in cases)  # a case per line
        path.write_text(f'{{"recorded_with":{json.dumps(about)},\n"cases":[\n{rows}]}}\n')
        written.append(path)
        print(f"{path}: {len(cases)} cases, {path.stat().st_size / 1e3:.0f} kB", flush=True)
    return written


def load(directory: Path = RECORD_DIR) -> dict[str, dict[str, Any]]:
    """The recorded files, by stem."""
    return {path.stem: json.loads(path.read_text()) for path in sorted(directory.glob("*.json"))}


def rerecord(why: str, directory: Path = RECORD_DIR, keep: dict[str, Any] | None = None,
             only: list[str] | None = None) -> list[str]:
    """Re-record only the cases a change of the engine moves on purpose, and name them with ``why`` and the commit
    in their file's "re_recorded" list; every other case keeps its record. Without ``keep`` a case moved where its
    replay differs from its record. ``keep``: the parameters of the old behaviour where a default changed (e.g.
    {"closure": "kinematic"}): a case moved where its replay differs from its replay under them, and its record is
    kept beside the new one, under them (" [k=v]" appended to its name), still the former engine's. ``only``: the
    cases to look at (None: all). The paper formulation's cases differ from their record at step 0 without moving
    (the voltage there is the input u since issue 19; the test applies that fix, ``compare`` does not): name the
    moved cases with ``only`` so that those keep their record. Returns the names of the moved cases."""
    moved_all: list[str] = []
    commit = provenance()["commit"]
    tag = "".join(f" [{k}={v}]" for k, v in (keep or {}).items())
    for stem, data in load(directory).items():
        cases, moved, kept = [], [], []
        for case in data["cases"]:
            if only is not None and case["name"] not in only:
                cases.append(case)
                continue
            now = replay(case)
            if keep:
                if case["name"].endswith(tag):
                    kept.append(case)
                    continue
                old = dict(case, name=case["name"] + tag, params={**case["params"], **keep})
                unmoved = compare(replay(old), now)[0] == []
            else:
                unmoved = compare(case["result"], now)[0] == []
            if unmoved:
                cases.append(case)
                continue
            moved.append(case["name"])
            if keep:
                kept.append(old)
            names = case["result"]["outputs"]  # the outputs the record holds (outputs added since are not in it)
            now = dict(now, outputs={k: now["outputs"][k] for k in names},
                       final={k: v for k, v in now["final"].items() if k in names})
            cases.append(dict(case, result=now))
        if not moved:
            continue
        data["cases"] = cases + kept
        data.setdefault("re_recorded", []).append({"commit": commit, "why": why, "cases": moved})
        if keep:
            data["re_recorded"][-1]["kept_as"] = tag.strip()
        path = save(directory, stem, data)
        print(f"{path}: {len(moved)} case(s) re-recorded: {', '.join(moved)}", flush=True)
        moved_all += moved
    return moved_all


def save(directory: Path, stem: str, data: dict[str, Any]) -> Path:
    """One group's file: its provenance, its re-recorded and added lists, a case per line."""
    path = directory / f"{stem}.json"
    rows = ",\n".join(json.dumps(case, separators=(",", ":")) for case in data["cases"])
    lists = "".join(f'"{key}":{json.dumps(data[key])},\n' for key in ("re_recorded", "added") if key in data)
    path.write_text(f'{{"recorded_with":{json.dumps(data["recorded_with"])},\n{lists}"cases":[\n{rows}]}}\n')
    return path


def add(why: str, directory: Path = RECORD_DIR) -> list[str]:
    """Record the cases that are new (a new solver or scene run: in ``groups()`` but not in the files), naming them
    with ``why`` and the commit in their file's "added" list; every recorded case keeps its record. Returns their
    names."""
    recorded = load(directory)
    commit = provenance()["commit"]
    added_all: list[str] = []
    for stem, cases in groups():
        data = recorded[stem]
        known = {case["name"] for case in data["cases"]}
        new = [dict(case, result=replay(case)) for case in cases if case["name"] not in known]
        if not new:
            continue
        data["cases"] += new
        data.setdefault("added", []).append({"commit": commit, "why": why, "cases": [c["name"] for c in new]})
        path = save(directory, stem, data)
        print(f"{path}: {len(new)} case(s) added", flush=True)
        added_all += [c["name"] for c in new]
    return added_all


def check(directory: Path = RECORD_DIR) -> int:
    """Replay every recorded case; print the problems and the largest difference."""
    failures, worst = 0, 0.0
    for stem, data in load(directory).items():
        for case in data["cases"]:
            problems, ratio = compare(case["result"], replay(case))
            worst = max(worst, ratio)
            if problems:
                failures += 1
                print(f"{case['name']}: " + "; ".join(problems[:3]), flush=True)
    print(f"{failures} case(s) differ; largest |difference| / tolerance = {worst:.3g}")
    return 1 if failures else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cam_fmu.tools.baseline", description=__doc__.split("\n\n")[0])
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--write", action="store_true", help=f"record the baseline into {RECORD_DIR}")
    what.add_argument("--check", action="store_true", help="replay the recorded cases and compare")
    what.add_argument("--rerecord", metavar="WHY", help="re-record only the cases that moved, naming them with WHY")
    what.add_argument("--add", metavar="WHY", help="record only the cases not recorded yet (a new solver, a new run)")
    parser.add_argument("--keep", action="append", default=[], metavar="NAME=VALUE",
                        help="with --rerecord: keep each moved case's record beside it under this parameter "
                             "(repeatable; e.g. closure=kinematic when a default moved)")
    parser.add_argument("--only", action="append", default=None, metavar="CASE",
                        help="with --rerecord: look at this case only (repeatable)")
    parser.add_argument("--dir", type=Path, default=RECORD_DIR, help="where the JSON files are")
    args = parser.parse_args(argv)
    if args.write:
        write(args.dir)
        return 0
    if args.rerecord:
        keep = dict(item.split("=", 1) for item in args.keep)
        rerecord(args.rerecord, args.dir, keep, args.only)
        return 0
    if args.add:
        add(args.add, args.dir)
        return 0
    return check(args.dir)


if __name__ == "__main__":
    sys.exit(main())
