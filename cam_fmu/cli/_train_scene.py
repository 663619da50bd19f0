"""What the vibration commands (`residual`, `optimize-law`) read of a scene: its rise law, rise angle and, when
the scene has a train (parameters k_train > 0 and m_end > 0), its natural frequency and damping ratio."""
from __future__ import annotations

import math


def scene_and_law(name: str, sets: list[str]):
    """(scene, its rise law's label, the law); ValueError for a scene whose cam has no rise law (a motion
    table)."""
    from ..experiments.scenes import find_scene
    from ..kinematics.presets import named_law
    from ..physics.parameters import law_spec
    from .simulate import apply_sets

    scene = apply_sets(find_scene(name), sets)
    params = scene.primary.params
    if params.get("motion_table"):
        raise ValueError(f"scene {scene.name}: its cam is a motion table (parameter motion_table), which has no "
                         "rise law to evaluate; give a scene whose cam program has a rise (rise_law)")
    spec = law_spec(params, "rise")
    label = spec if isinstance(spec, str) else "custom T = " + " ".join(f"{t:.6g}" for t in spec)
    return scene, label, named_law(spec)


def train_of(params) -> tuple[float | None, float | None]:
    """(natural frequency [Hz], damping ratio) of the scene's train, (None, None) when it has none (an arm's
    torsional train: k_train_arm, J_end, d_train_arm)."""
    names = ("k_train", "m_end", "d_train")
    if float(params.get("k_train_arm", 0.0) or 0.0) > 0.0:
        names = ("k_train_arm", "J_end", "d_train_arm")
    k, m, d = (float(params.get(n, 0.0) or 0.0) for n in names)
    if k > 0.0 and m > 0.0:
        return math.sqrt(k / m) / (2.0 * math.pi), d / (2.0 * math.sqrt(k * m))
    return None, None


def parse_range(text: str, option: str) -> tuple[float, float]:
    """'R1:R2' as two floats; ValueError naming the option otherwise."""
    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError
        return float(parts[0]), float(parts[1])
    except ValueError:
        raise ValueError(f"{option} {text!r}: allowed R1:R2, two numbers (e.g. 1.5:3)") from None


def out_dir(path: str):
    """The output folder, made; ValueError when it exists as a file."""
    from pathlib import Path

    destination = Path(path)
    if destination.exists() and not destination.is_dir():
        raise ValueError(f"--out {path!r} exists and is not a directory")
    destination.mkdir(parents=True, exist_ok=True)
    return destination
