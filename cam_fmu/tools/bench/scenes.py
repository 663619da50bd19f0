"""Per-step cost of cam.fmu against the C floor, per shipped scene at the defaults.

cam.fmu (as measured: ``--fmu``) and the C floor (``c_floor.py``: cam.fmu's variables, a trivial model:
what fmpy costs with nearly no model) run alternately in one process through ``simulate_fmu`` (see
``timing.alternated``), best of the rounds, each twice per scene: fmpy recording theta and omega only
(``record = "theta,omega"``) and every output (``"all"``, what the error grid does). OUT/scenes.csv.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ...experiments.scenes import find_scene, scene_names
from .cases import SOLVER_KEYS

COMM = 1e-3  # s: the communication step of the per-step tables
FIRST_SCENES = ("paper_fig6", "backlash", "inductance", "tilted")  # then the other shipped scenes, by name
RECORDS = {"theta,omega": ["theta", "omega"], "all": None}  # fmpy's `output`: None records every output
KINDS = ("cam", "c_floor")
# fig. 6 with theta and omega recorded gets 3x the rounds: a slow spell of the shared machine can last
# through all 5 rounds of one FMU's runs; 15 rounds span longer than any such spell seen.
LONG_CELL, LONG_ROUNDS = ("paper_fig6", "theta,omega"), 3
COLUMNS = ("scene", "drive", "record", "comm_step", "n_steps", "stop_time", "cam_us", "c_floor_us", "cam_c_ratio",
           "repeats", "error")
HEADER = f"{'scene':<13}{'record':<13}{'cam':>8}{'c_flr':>8}{'cam/c':>8}   [us/step; ratio]"


@dataclass
class SceneCase:
    name: str
    drive: str
    start_values: dict[str, Any]  # the scene's primary run without solver settings: the defaults
    inputs: Any  # fmpy input array
    stop_time: float


def scene_list(quick: bool) -> list[str]:
    if quick:
        return ["paper_fig6"]
    shipped = scene_names()
    return [n for n in FIRST_SCENES if n in shipped] + sorted(n for n in shipped if n not in FIRST_SCENES)


def load_scene_case(name: str) -> SceneCase:
    from ...experiments.runner import signals_table

    scene = find_scene(name)
    values = {k: v for k, v in scene.primary.start_values().items() if k not in SOLVER_KEYS}
    values["drive"] = scene.drive
    signal = {"u": scene.u} if scene.drive == "voltage" else {"omega_ref": scene.omega_ref}
    return SceneCase(name, scene.drive, values, signals_table(signal, scene.stop_time), scene.stop_time)


def measure_scene(case: SceneCase, runners: dict, record: str, repeats: int) -> dict:
    """One row: cam.fmu and the C floor alternated at COMM, recording ``record``."""
    from .timing import alternated

    n = int(round(case.stop_time / COMM))
    entries = {kind: (runners[kind], case.start_values if kind == "cam" else {}) for kind in KINDS}
    got = alternated(entries, case.stop_time, COMM, case.inputs, RECORDS[record], repeats)
    us = {kind: got[kind][1] / n * 1e6 for kind in KINDS}
    return dict(scene=case.name, drive=case.drive, record=record, comm_step=COMM, n_steps=n,
                stop_time=case.stop_time, cam_us=us["cam"], c_floor_us=us["c_floor"],
                cam_c_ratio=us["cam"] / us["c_floor"], repeats=repeats,
                error="; ".join(f"{kind}: {got[kind][2]}" for kind in KINDS if got[kind][2]))


def format_row(row: dict) -> str:
    from .report import _fmt

    return (f"{row['scene']:<13}{row['record']:<13}{_fmt(row['cam_us'], '.1f', 8)}{_fmt(row['c_floor_us'], '.1f', 8)}"
            f"{_fmt(row['cam_c_ratio'], '.2f', 8)}" + (f"   error: {row['error']}" if row["error"] else ""))


def run(ctx, repeats: int = 5) -> int:
    """The scene table into OUT/scenes.csv; fig. 6's cell on the last line."""
    from .report import write_csv

    runners = {kind: ctx.runner(kind) for kind in KINDS}
    ctx.say(f"# per communication step ({COMM:g} s) at the defaults through fmpy's simulate_fmu, alternated in "
            "this process: cam = cam.fmu, c_floor = a trivial C FMU; record: the outputs fmpy records")
    ctx.say(HEADER)
    rows = []
    for name in scene_list(ctx.quick):
        case = load_scene_case(name)
        for record in RECORDS:
            row = measure_scene(case, runners, record, repeats * LONG_ROUNDS if (name, record) == LONG_CELL
                                else repeats)
            rows.append(row)
            ctx.say(format_row(row))
    write_csv(rows, ctx.out / "scenes.csv", columns=COLUMNS)
    r = rows[0]  # paper_fig6, theta and omega
    ctx.say(f"# fig6 through simulate_fmu (defaults, 1 ms, theta+omega recorded): cam.fmu {r['cam_us']:.1f} us/step "
            f"(best of {r['repeats']} rounds) = {r['cam_c_ratio']:.2f}x the C floor ({r['c_floor_us']:.1f} us)")
    return 0
