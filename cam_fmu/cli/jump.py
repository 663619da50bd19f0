"""`cam-fmu jump SCENE [--set NAME=VALUE ...] [--rpm N] [--target-rpm N] [--safety S] [--json] [--out DIR]`.

The speed at which a spring-closed follower (closure = 'spring') first leaves the cam on a rigid drive at
constant speed (physics.follower; docs/model.md section 13), whatever the scene's drive:

    omega_jump = min over theta with s'' < 0 of sqrt((F0 + k s - F_gx + f0) / (m |s''|))

with the guide friction at zero contact force f0 = mu (|G_y| + |N_g|) taken as it opposes the rise's velocity. It
prints omega_jump [rad/s] and [1/min], the angle and lift where contact is first lost; with ``--rpm N`` the least
contact force over a turn at that speed (the margin [N], negative: the follower leaves) and the ratio
omega_jump / omega; with ``--target-rpm N`` the preload F_spring0 (at the scene's k_spring) and the spring rate
k_spring (at the scene's F_spring0) that hold the follower at that speed with the force safety factor
``--safety S`` (default 1.5: the spring gives S times the force the deceleration needs, so omega_jump =
sqrt(S) x target). Writes DIR/<scene>_jump.png (no --no-plot): the available and the needed force over a turn at
the speeds given (or at omega_jump). ``--json`` prints one JSON object (keys omega_jump [rad/s], rpm_jump,
theta_jump [rad], s_jump [m]; margin_N, theta_margin, speed_ratio with --rpm; preload_N, theta_preload,
k_spring_N_per_m, theta_k_spring, safety with --target-rpm; null where not asked). A spring answer beyond its
parameter's range (physics/parameters.py: F_spring0, k_spring) is null, with the reason in beyond_range (the value
needed and the range); where neither is in range the command fails (exit 2) naming both, and says whether a spring
with both changed does it or no spring in range does.

Another follower type (follower_type, docs/model.md 16.2; physics.kind_jump): the spring acts along the roller's
path, at arm_length L for an arm, omega_jump = min over q'' < 0 of sqrt(C / (I_f |q''|)) with an arm's closing
torque C = L (F0 + k L psi) + W cos(psi + psi_0) and I_f = J_arm + m L^2 (a translating flat face: the roller's,
s-based, without guide friction); the forces it reports are along the roller's path and the JSON adds psi_jump
[rad] (null for a translating follower).
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

RPM = 2.0 * math.pi / 60.0  # rad/s per 1/min


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("jump", help="the cam speed at which a spring-closed follower leaves the cam",
                              description="Jump speed, margin and spring sizing of a spring-closed cam (closure "
                                          "'spring') at constant speed.")
    p.add_argument("scene", metavar="SCENE", help="a shipped scene's name (e.g. spring_jump) or a scene file (.toml)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="override a parameter (repeatable), e.g. --set k_spring=3000; a value may carry its unit, "
                        "e.g. --set k_spring=3N/mm")
    p.add_argument("--rpm", type=float, default=None, help="cam speed [1/min] at which to report the margin")
    p.add_argument("--target-rpm", type=float, default=None,
                   help="cam speed [1/min] the spring must hold: the preload and rate it needs")
    p.add_argument("--safety", type=float, default=1.5,
                   help="force safety factor S >= 1 for --target-rpm (default 1.5: omega_jump = sqrt(S) target)")
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--no-plot", action="store_true", help="no figure")
    return p


def _speed(value: float | None, option: str) -> float | None:
    if value is None:
        return None
    if not (math.isfinite(value) and 0.0 < value <= 1e6):
        raise ValueError(f"{option} {value!r}: allowed a cam speed in (0, 1e6] 1/min")
    return value * RPM


def report(params, omega: float | None, target: float | None, safety: float) -> dict:
    """The jump speed, the margin at omega [rad/s] and the spring for target [rad/s] (None: not asked)."""
    from ..physics.drive import DriveModel
    from ..physics.follower import contact_margin, jump_speed, preload_for, rate_for

    if params["closure"] != "spring":
        raise ValueError(f"closure {params['closure']!r}: a groove (closures 'kinematic' and 'form') holds the "
                         "follower on both flanks, it does not jump (it crosses its clearance where the force changes "
                         "sign); jump needs closure 'spring' (--set closure=spring --set F_spring0=... "
                         "--set k_spring=...)")
    if not (math.isfinite(safety) and 1.0 <= safety <= 100.0):
        raise ValueError(f"--safety {safety!r}: allowed [1, 100]")
    if params.get("follower_type", "translating_roller") != "translating_roller":
        return _kind_report(params, omega, target, safety)
    model = DriveModel(dict(params, drive="speed"))  # a rigid drive at constant speed, whatever the scene drives
    f0 = model.mu * (abs(model.G_y) + model.N_g)
    args = (model.m, model.k_spring, model.F_spring0, model.F_gx, f0)
    jump = jump_speed(model.program, *args)
    out = {"omega_jump": jump.omega_jump, "rpm_jump": jump.omega_jump / RPM, "theta_jump": jump.theta,
           "s_jump": jump.s, "reason": jump.reason, "margin_N": None, "theta_margin": None, "speed_ratio": None,
           "preload_N": None, "theta_preload": None, "k_spring_N_per_m": None, "theta_k_spring": None,
           "safety": None, "beyond_range": None}
    if omega is not None:
        out["margin_N"], out["theta_margin"] = contact_margin(model.program, omega, *args)
        out["speed_ratio"] = jump.omega_jump / omega
    if target is not None:
        out["safety"] = safety
        out["preload_N"], out["theta_preload"] = preload_for(model.program, target, safety, model.m,
                                                             model.k_spring, model.F_gx, f0)
        out["k_spring_N_per_m"], out["theta_k_spring"] = rate_for(model.program, target, safety, model.m,
                                                                  model.F_spring0, model.F_gx, f0)
        _within_range(out, model.k_spring, model.F_spring0, target, safety,
                      lambda k: preload_for(model.program, target, safety, model.m, k, model.F_gx, f0)[0])
    return _finite(out)


def _finite(out: dict) -> dict:
    """``out`` with every non-finite float as None (JSON's null)."""
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in out.items()}


def _kind_report(params, omega: float | None, target: float | None, safety: float) -> dict:
    """report() for a follower type other than the translating roller (physics.kind_jump: an arm's spring at
    arm_length along the roller's path; forces along that path); psi_jump [rad] the arm's angle there (None for a
    translating face)."""
    from ..physics.kind_jump import KindSpring

    spring = KindSpring(dict(params, drive="speed"))
    jump = spring.jump()
    psi = spring.model.coordinate(jump.theta)[0] if spring.kind.oscillating and math.isfinite(jump.theta) else None
    out = {"omega_jump": jump.omega_jump, "rpm_jump": jump.omega_jump / RPM, "theta_jump": jump.theta,
           "s_jump": jump.s, "psi_jump": psi, "reason": jump.reason, "margin_N": None, "theta_margin": None,
           "speed_ratio": None, "preload_N": None, "theta_preload": None, "k_spring_N_per_m": None,
           "theta_k_spring": None, "safety": None, "beyond_range": None}
    if omega is not None:
        out["margin_N"], out["theta_margin"] = spring.margin(omega)
        out["speed_ratio"] = jump.omega_jump / omega
    if target is not None:
        out["safety"] = safety
        out["preload_N"], out["theta_preload"] = spring.preload_for(target, safety)
        out["k_spring_N_per_m"], out["theta_k_spring"] = spring.rate_for(target, safety)
        _within_range(out, spring.k, spring.F0, target, safety,
                      lambda k: spring.preload_for(target, safety, k)[0])
    return _finite(out)


def _within_range(out: dict, k_spring: float, F_spring0: float, target: float, safety: float, stiffest_preload) -> None:
    """Keep only the spring answers within the parameters' ranges (physics/parameters.py): an answer beyond its
    range becomes None with the reason in out["beyond_range"]; where neither is in range, raise ValueError naming
    each parameter, the value needed and the range, and whether a spring with both changed (the largest rate in
    range and the preload it needs, ``stiffest_preload(k)`` [N]) does it. k_spring [N/m], F_spring0 [N]: the scene's."""
    from ..physics.parameters import BY_NAME

    F0_spec, k_spec = BY_NAME["F_spring0"], BY_NAME["k_spring"]
    beyond = []
    if out["preload_N"] > F0_spec.high:
        beyond.append(f"the preload F_spring0 would have to be {out['preload_N']:.6g} N at k_spring = "
                      f"{k_spring:g} N/m, allowed {F0_spec.allowed()}")
        out["preload_N"] = out["theta_preload"] = None
    if out["k_spring_N_per_m"] is not None and math.isfinite(out["k_spring_N_per_m"]) \
            and out["k_spring_N_per_m"] > k_spec.high:
        beyond.append(f"the spring rate k_spring would have to be {out['k_spring_N_per_m']:.6g} N/m at F_spring0 = "
                      f"{F_spring0:g} N, allowed {k_spec.allowed()}")
        out["k_spring_N_per_m"] = out["theta_k_spring"] = None
    out["beyond_range"] = "; ".join(beyond) or None
    if out["preload_N"] is not None or (out["k_spring_N_per_m"] is not None
                                        and math.isfinite(out["k_spring_N_per_m"])):
        return
    stiffest = stiffest_preload(k_spec.high)
    if stiffest <= F0_spec.high:
        both = (f"only a spring with both changed: k_spring = {k_spec.high:g} N/m with F_spring0 >= "
                f"{max(stiffest, 0.0):.6g} N")
    else:
        both = (f"no spring in range does it: even k_spring = {k_spec.high:g} N/m needs F_spring0 = {stiffest:.6g} N "
                f"(allowed {F0_spec.allowed()})")
    reasons = "; ".join(beyond) if beyond else "no rate can (a lift of 0 needs more than the preload)"
    raise ValueError(f"--target-rpm {target / RPM:g} with --safety {safety:g}: {reasons}; {both}")


def curves(params, speeds: dict[str, float], points: int = 1440) -> dict:
    """The figure's columns over a turn: theta [rad], the available force, the needed force at each speed [N] (for
    another follower type, along the roller's path: physics.kind_jump)."""
    from ..physics.drive import DriveModel

    if params.get("follower_type", "translating_roller") != "translating_roller":
        return _kind_curves(params, speeds, points)
    model = DriveModel(dict(params, drive="speed"))
    f0 = model.mu * (abs(model.G_y) + model.N_g)
    result: dict = {"theta": [], "available": [], "speeds": {}}
    for k, (label, omega) in enumerate(speeds.items()):
        result["speeds"][f"need{k}"] = label
        result[f"need{k}"], result[f"margin_need{k}"] = [], []
    for j in range(points):
        theta = 2.0 * math.pi * j / points
        s, s1, s2, _ = model.program.derivatives(theta)
        available = model.F_spring0 + model.k_spring * s - model.F_gx + (f0 if s1 > 0 else -f0 if s1 < 0 else 0.0)
        result["theta"].append(theta)
        result["available"].append(available)
        for k, omega in enumerate(speeds.values()):
            result[f"need{k}"].append(model.m * max(-s2, 0.0) * omega * omega)
            result[f"margin_need{k}"].append(available + model.m * s2 * omega * omega)
    return result


def _kind_curves(params, speeds: dict[str, float], points: int) -> dict:
    """curves() for a follower type other than the translating roller (physics.kind_jump)."""
    from ..physics.kind_jump import KindSpring

    spring = KindSpring(dict(params, drive="speed"))
    result: dict = {"theta": [], "available": [], "speeds": {}}
    for k, label in enumerate(speeds):
        result["speeds"][f"need{k}"] = label
        result[f"need{k}"], result[f"margin_need{k}"] = [], []
    for j in range(points):
        theta = 2.0 * math.pi * j / points
        available = spring.closing(theta)
        q2 = spring.parts(theta)[2]
        result["theta"].append(theta)
        result["available"].append(available)
        for k, omega in enumerate(speeds.values()):
            result[f"need{k}"].append(spring.need(theta, omega))
            result[f"margin_need{k}"].append(available + spring.model.I_f * q2 * omega * omega / spring.a)
    return result


def run(args) -> int:
    from ..experiments.scenes import find_scene
    from .simulate import apply_sets

    scene = apply_sets(find_scene(args.scene), args.set)
    omega, target = _speed(args.rpm, "--rpm"), _speed(args.target_rpm, "--target-rpm")
    try:
        out = report(scene.primary.params, omega, target, args.safety)
    except ValueError as exc:
        raise ValueError(f"scene {scene.name}: {exc}") from None
    written = []
    if not args.no_plot:
        from ..plots.jump import plot_jump

        speeds = {f"needed at {args.rpm:g} 1/min": omega} if omega is not None else {}
        if out["omega_jump"] is not None and out["omega_jump"] > 0.0:
            speeds[f"needed at omega_jump ({out['rpm_jump']:.6g} 1/min)"] = out["omega_jump"]
        destination = Path(args.out)
        if destination.exists() and not destination.is_dir():
            raise ValueError(f"--out {args.out!r} exists and is not a directory")
        destination.mkdir(parents=True, exist_ok=True)
        written.append(plot_jump(curves(scene.primary.params, speeds), f"{scene.name}: closing force against the "
                                 "force the follower needs", destination / f"{scene.name}_jump.png"))
    if args.json:
        print(json.dumps(out))
        return 0
    if out["omega_jump"] is None:
        print(f"omega_jump: none ({out['reason']})")
    else:
        print(f"omega_jump: {out['omega_jump']:.6g} rad/s = {out['rpm_jump']:.6g} 1/min at theta = "
              f"{out['theta_jump']:.6g} rad, s = {out['s_jump']:.6g} m ({out['reason']})")
    if omega is not None:
        print(f"at {args.rpm:g} 1/min: least contact force {out['margin_N']:.6g} N at theta = {out['theta_margin']:.6g} "
              f"rad ({'held' if out['margin_N'] > 0 else 'the follower leaves the cam'}); omega_jump / omega = "
              + ("inf" if out["speed_ratio"] is None else f"{out['speed_ratio']:.6g}"))
    if target is not None:
        beyond = out["beyond_range"] or ""
        if out["k_spring_N_per_m"] is not None:
            k_text = (f"{out['k_spring_N_per_m']:.6g} N/m at the preload F_spring0 (set by theta = "
                      f"{out['theta_k_spring']:.6g} rad)")
        elif "k_spring" in beyond:
            k_text = "none in range (" + next(part for part in beyond.split("; ") if "k_spring would" in part) + ")"
        else:
            k_text = "none can (a lift of 0 needs more than the preload)"
        F0_text = (f"{out['preload_N']:.6g} N at the rate k_spring (set by theta = {out['theta_preload']:.6g} rad)"
                   if out["preload_N"] is not None else
                   "none in range (" + next(part for part in beyond.split("; ") if "F_spring0 would" in part) + ")")
        print(f"to hold {args.target_rpm:g} 1/min with safety {args.safety:g}: preload {F0_text}; spring rate {k_text}")
    for path in written:
        print(path)
    sys.stdout.flush()
    return 0
