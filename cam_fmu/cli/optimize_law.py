"""`cam-fmu optimize-law SCENE --band R1:R2 [--zeta Z] [--max-ca X] [--max-cj X|none] [--front ...] [--json]`.

The split points T1..T6 of the harmonic-trapezoid law that minimise the worst residual vibration over the band of
r = rise time / the train's natural period, with the peak acceleration Ca <= --max-ca (default 1.15 x the
cycloidal's 2 pi) and the peak jerk Cj <= --max-cj (default the modified sine's; ``none``: unbounded)
(vibration/optimize.py). The law found is re-evaluated by integrating the train's equation (vibration/train.py)
at the band's worst point and ends. Writes DIR/<scene>_law.toml (the law as a scene's [parameters]: rise_law =
"custom", rise_T1..rise_T6), DIR/<scene>_optimized.png (its residual against the classic laws) and, unless
--no-front, DIR/<scene>_front.png (the Pareto front: the worst residual against the jerk bound, --front's
bounds, default 40..400). Refused: a band outside r > 0, an unreachable Ca bound, a scene without a rise law.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time

CLASSIC = ("cycloidal", "modified_sine", "modified_trapezoid", "polynomial_345", "polynomial_4567")
FRONT = (40.0, 50.0, 60.0, 80.0, 100.0, 150.0, 200.0, 300.0, 400.0)


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("optimize-law", help="the law's split points shaped against the residual vibration "
                                                   "over a band of r",
                              description="Minimise the worst residual vibration over a band of r = rise time / "
                                          "the train's natural period over the harmonic-trapezoid family.")
    p.add_argument("scene", metavar="SCENE", help="a shipped scene's name or a scene file (.toml)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help="override a parameter")
    p.add_argument("--band", required=True, metavar="R1:R2", help="the band of r (e.g. 1.5:3)")
    p.add_argument("--zeta", type=float, default=0.0, help="the train's damping ratio in [0, 1) (default 0)")
    p.add_argument("--max-ca", type=float, default=None, help="peak acceleration bound (default 1.15 x 2 pi)")
    p.add_argument("--max-cj", default=None, help="peak jerk bound (default the modified sine's; none: unbounded)")
    p.add_argument("--front", default=",".join(f"{b:g}" for b in FRONT),
                   help="jerk bounds of the Pareto front, comma-separated (default 40..400); 'none' adds unbounded")
    p.add_argument("--no-front", action="store_true", help="no Pareto front")
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--no-plot", action="store_true", help="no figures (the law's file is still written)")
    return p


def _bound(part: str, refusal: str) -> float | None:
    """A jerk bound: a number > 0, or None for 'none' (unbounded); ValueError(refusal) otherwise."""
    if part.strip().lower() == "none":
        return None
    try:
        value = float(part)
    except ValueError:
        raise ValueError(refusal) from None
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(refusal)
    return value


def _jerk(text: str | None, default: float) -> float | None:
    if text is None:
        return default
    return _bound(text, f"--max-cj {text!r}: allowed a number > 0 or none")


def _front_bounds(text: str) -> list[float | None]:
    refusal = f"--front {text!r}: allowed jerk bounds > 0 (or none), comma-separated"
    return [_bound(part, refusal) for part in (p.strip() for p in text.split(",")) if part]


def law_toml(scene_name: str, T, worst: float, band, max_ca, max_cj) -> str:
    """The law as a scene's [parameters] (the scene file format, docs/scenes.md)."""
    lines = [f"# cam-fmu optimize-law {scene_name}: worst residual {worst:.6g} of the lift over r = "
             f"{band[0]:g}..{band[1]:g} with Ca <= {max_ca:.6g}, Cj <= "
             + ("unbounded" if max_cj is None else f"{max_cj:.6g}"), "[parameters]", 'rise_law = "custom"']
    lines += [f"rise_T{k} = {float(t)!r}" for k, t in enumerate(T, 1)]
    return "\n".join(lines) + "\n"


def run(args) -> int:
    import numpy as np

    from ..kinematics.characteristics import characteristics
    from ..kinematics.motion_law import MotionLaw
    from ..kinematics.presets import named_law
    from ..vibration.optimize import DEFAULT_CA, check_band, optimize_law, pareto_front, worst_residual
    from ..vibration.spectral import check_zeta, residual
    from ..vibration.train import residual_ode
    from ._train_scene import out_dir, parse_range, scene_and_law

    started = time.perf_counter()
    r1, r2 = check_band(*parse_range(args.band, "--band"))
    scene, label, _ = scene_and_law(args.scene, args.set)
    zeta = check_zeta(args.zeta)
    max_ca = DEFAULT_CA if args.max_ca is None else args.max_ca
    ms_jerk = characteristics(named_law("modified_sine")).Jm
    max_cj = _jerk(args.max_cj, ms_jerk)
    bounds = [] if args.no_front else _front_bounds(args.front)
    best = optimize_law(r1, r2, zeta, max_ca, max_cj)
    law = MotionLaw(best.T)
    classic = {}
    for name in CLASSIC:
        item = named_law(name)
        worst, where = worst_residual(item, r1, r2, zeta)
        jm = characteristics(item).Jm if isinstance(item, MotionLaw) else None
        classic[name] = {"worst": worst, "r_worst": where, "Cj": jm}
    best_classic = min(classic, key=lambda n: classic[n]["worst"])
    check_r = np.array(sorted({r1, best.r_worst, r2}))
    ode = residual_ode(law, check_r, zeta)
    front = pareto_front(r1, r2, bounds, zeta, max_ca) if bounds else []
    elapsed = time.perf_counter() - started
    destination = out_dir(args.out)
    law_path = destination / f"{scene.name}_law.toml"
    law_path.write_text(law_toml(scene.name, best.T, best.worst, (r1, r2), max_ca, max_cj), encoding="utf-8")
    written = [law_path]
    if not args.no_plot:
        from ..plots.residual import plot_front, plot_residual

        r = np.linspace(max(0.25, r1 - 1.0), r2 + 1.0, 601)
        curves = {"optimised": (r, residual(law, r, zeta))}
        curves.update({name: (r, residual(named_law(name), r, zeta)) for name in CLASSIC})
        written.append(plot_residual(curves, f"{scene.name}: the optimised law against the classic laws",
                                     destination / f"{scene.name}_optimized.png", band=(r1, r2)))
        if front:
            points = {name: (v["Cj"], v["worst"]) for name, v in classic.items() if v["Cj"] is not None}
            finite = [o for o in front if o.max_cj is not None]
            written.append(plot_front([o.max_cj for o in finite], [o.worst for o in finite], points,
                                      f"{scene.name}: worst residual over r = {r1:g}..{r2:g}",
                                      destination / f"{scene.name}_front.png"))
    out = {"scene": scene.name, "scene_law": label, "band": [r1, r2], "zeta": zeta, "max_ca": max_ca,
           "max_cj": max_cj, "T": list(best.T), "worst": best.worst, "r_worst": best.r_worst, "Ca": best.Ca,
           "Cj": best.Cj, "best_classic": best_classic, "ratio_to_best_classic": best.worst
           / classic[best_classic]["worst"], "classic": classic, "ode_check_r": check_r.tolist(),
           "ode_residual": ode.tolist(), "front": [{"max_cj": o.max_cj, "worst": o.worst, "T": list(o.T),
                                                    "Ca": o.Ca, "Cj": o.Cj} for o in front],
           "seconds": elapsed, "files": [str(p) for p in written]}
    if args.json:
        print(json.dumps(out))
        return 0
    cj_text = "unbounded" if max_cj is None else f"{max_cj:.6g}"
    print(f"scene {scene.name}: band r = {r1:g}..{r2:g}, zeta = {zeta:g}, Ca <= {max_ca:.6g}, Cj <= {cj_text}")
    print("  T = " + " ".join(f"{t:.6g}" for t in best.T) + f": worst residual {best.worst:.6g} of the lift at r = "
          f"{best.r_worst:.6g} (Ca {best.Ca:.6g}, Cj " + ("unbounded" if best.Cj is None else f"{best.Cj:.6g}")
          + f"), {out['ratio_to_best_classic']:.4g} x the best classic law's ({best_classic}, "
          f"{classic[best_classic]['worst']:.6g})")
    print("  the integrated train at r = " + ", ".join(f"{x:.6g}" for x in check_r) + ": "
          + ", ".join(f"{x:.6g}" for x in ode))
    for o in front:
        print(f"  front: Cj <= " + ("unbounded" if o.max_cj is None else f"{o.max_cj:g}") + f": worst {o.worst:.6g}")
    print(f"  {elapsed:.2f} s")
    for path in written:
        print(path)
    sys.stdout.flush()
    return 0
