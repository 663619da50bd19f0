"""Cost per effect: fig. 6 at the defaults, theta and omega recorded, 1 ms, cam.fmu alternated with the C
floor; each effect of ``physics.parameters.EFFECTS`` switched off in turn (fig. 6 has them all on),
backlash and inductance also switched on with the shipped scenes' values (in fig. 6 they are on but idle
through c = 0 and L = 0), and all off: us/step, the difference to the defaults and the ratio to the floor.
OUT/effects.csv.
"""
from __future__ import annotations

from typing import Any

from ...physics.parameters import EFFECTS
from .scenes import COMM, RECORDS, load_scene_case

# effects that are off in fig. 6 through a zero parameter: switched ON with the shipped scene's value
EFFECT_ON = {"backlash": {"c": 5e-4}, "inductance": {"L": 1e-3}}
COLUMNS = ("config", "change", "us_per_step", "delta_us", "c_ratio", "c_floor_us", "repeats", "error")


def effect_configs() -> list[tuple[str, str, dict[str, Any]]]:
    """(config, change, parameter overrides) on top of fig. 6 at the defaults: the defaults, each effect
    switched off (on, with the shipped scene's value, where fig. 6 has it off through a zero parameter), and
    all off."""
    configs = [("defaults", "fig. 6 as shipped", {})]
    for name in EFFECTS:
        configs.append((f"{name} off", f"{name} = false", {name: False}))
        if name in EFFECT_ON:
            extra = ", ".join(f"{k} = {v:g}" for k, v in EFFECT_ON[name].items())
            configs.append((f"{name} on", extra, dict(EFFECT_ON[name])))
    configs.append(("all off", "every effect false", {name: False for name in EFFECTS}))
    return configs


def measure(case, cam, floor, repeats: int) -> list[dict]:
    """One row per configuration: cam.fmu in every configuration and the floor, alternated."""
    from .timing import alternated

    n = int(round(case.stop_time / COMM))
    configs = effect_configs()
    entries = {config: (cam, dict(case.start_values, **overrides)) for config, _c, overrides in configs}
    entries["c_floor"] = (floor, {})
    got = alternated(entries, case.stop_time, COMM, case.inputs, RECORDS["theta,omega"], repeats)
    us = {name: got[name][1] / n * 1e6 for name in got}
    return [dict(config=config, change=change, us_per_step=us[config], delta_us=us[config] - us["defaults"],
                 c_ratio=us[config] / us["c_floor"], c_floor_us=us["c_floor"], repeats=repeats, error=got[config][2])
            for config, change, _o in configs]


def format_effects(rows: list[dict]) -> str:
    lines = ["# cost per effect: fig. 6 at the defaults, 1 ms, theta and omega recorded, cam.fmu; "
             "delta: against the defaults",
             f"{'config':<24}{'change':<24}{'us/step':>9}{'delta':>9}{'/c_flr':>9}"]
    for r in rows:
        lines.append(f"{r['config']:<24}{r['change']:<24}{r['us_per_step']:>9.1f}{r['delta_us']:>+9.1f}"
                     f"{r['c_ratio']:>9.2f}" + (f"  error: {r['error']}" if r["error"] else ""))
    return "\n".join(lines)


def run(ctx, repeats: int = 5) -> int:
    from .report import write_csv

    rows = measure(load_scene_case("paper_fig6"), ctx.runner("cam"), ctx.runner("c_floor"),
                   2 if ctx.quick else repeats)
    write_csv(rows, ctx.out / "effects.csv", columns=COLUMNS)
    ctx.say(format_effects(rows))
    return 0
