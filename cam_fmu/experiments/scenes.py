"""Scenes: small TOML files that describe one simulation experiment.

The scenes shipped with the package are in ``experiments/scene_files/``;
``find_scene`` takes a scene's name (``paper_fig6``) or the path of any file.

A scene names the drive and its input signal, parameter overrides (effects are
the boolean parameters shaft_friction, guide_friction, gravity,
follower_inertia, backlash, inductance), the duration and the output interval,
and optionally several runs (a parameter sweep, the two formulations) that
share everything else::

    # what the scene reproduces
    description = "paper fig. 6: omega(t) at u = 3.5 V"
    drive = "voltage"              # 'voltage' (input u [V]) or 'speed' (input omega_ref [rad/s])
    u = 3.5                        # or a table: [u] type = "step", time = 0.5, before = 0, after = 3.5
    stop_time = 2.0                # s
    output_interval = 1e-3         # s
    plot = "fig6"                  # figure kind: a key of plots.scene.PLOTS ('time', the default)

    [parameters]                   # names and SI units of parameters.PARAMETERS; angles in rad
    gamma = 3.141592653589793

    [[runs]]                       # optional; the first run is the primary one
    label = "consistent"
    formulation = "consistent"     # parameter overrides on top of [parameters]

Every value is checked through parameters.resolve; unknown keys, unknown
parameter names and bad signal tables raise SceneError naming the key and the
file. The scene's name is the file stem.
"""
from __future__ import annotations

import math
import re
try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: the same parser as a package (pyproject.toml's tomli)
    import tomli as tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ..physics import parameters as _parameters
from ..physics.signals import OPTIONAL_KEYS, SIGNAL_KEYS, Signal, from_spec
from ..physics.variables import INPUT_RANGES, UNITS
from ..plots.scene import PLOTS  # the figure kinds' one table (matplotlib is imported only to draw)
from .limits import check_steps

TOP_KEYS = ("description", "drive", "u", "omega_ref", "parameters", "stop_time", "output_interval", "plot", "runs")
SCENE_DIR = Path(__file__).resolve().parent / "scene_files"
DEFAULT_LABEL = "base"  # label of the only run of a scene without [[runs]]
_LABEL = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


class SceneError(ValueError):
    """A scene file that cannot be used; the message names the file and the key."""


@dataclass(frozen=True)
class Run:
    """One simulation of a scene: its label and its parameters."""

    label: str
    overrides: dict[str, Any]  # scene [parameters] + drive + this run's overrides, checked (SI units)
    params: dict[str, Any]  # every parameter, resolved and checked

    def start_values(self) -> dict[str, Any]:
        """The overridden parameters converted to their kinds (float, bool, str): FMU start values."""
        return {name: self.params[name] for name in self.overrides}


@dataclass(frozen=True)
class Scene:
    """A loaded and validated scene."""

    name: str
    description: str
    drive: str
    u: Signal | None
    omega_ref: Signal | None
    parameters: dict[str, Any]
    stop_time: float
    output_interval: float
    plot: str
    runs: tuple[Run, ...]
    path: Path | None = None
    raw: dict[str, Any] = field(default_factory=dict, repr=False)

    @property
    def primary(self) -> Run:
        return self.runs[0]

    def with_stop_time(self, stop_time: float) -> "Scene":
        """The same scene over a different duration (e.g. shortened for tests)."""
        from dataclasses import replace
        stop_time = _positive(stop_time, "stop_time", self._where())
        check_steps(stop_time, self.output_interval, f"{self._where()}: stop time / 'output_interval'", SceneError)
        return replace(self, stop_time=stop_time)

    def _where(self) -> str:
        return str(self.path) if self.path else self.name


def load_scene(path: str | Path) -> Scene:
    """Read and validate the scene file ``path`` (TOML)."""
    path = Path(path)
    try:
        with path.open("rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise SceneError(f"scene file {str(path)!r} does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML: {exc}") from None
    except UnicodeDecodeError:
        raise SceneError(f"{path}: not a scene file (not UTF-8 text; a scene is a .toml file)") from None
    except IsADirectoryError:
        raise SceneError(f"{path}: is a directory, not a scene file (.toml)") from None
    return scene_from_dict(data, name=path.stem, path=path)


def scene_from_dict(data: Mapping[str, Any], name: str, path: Path | None = None) -> Scene:
    """Validate a parsed scene table (as from tomllib) and build the Scene."""
    where = str(path) if path else name
    unknown = sorted(set(data) - set(TOP_KEYS))
    if unknown:
        raise SceneError(f"{where}: unknown key(s) {', '.join(map(repr, unknown))}; allowed: {', '.join(TOP_KEYS)}")

    description = data.get("description", "")
    if not isinstance(description, str):
        raise SceneError(f"{where}: 'description' must be a string")

    drive = data.get("drive", "voltage")
    if drive not in _parameters.DRIVES:
        raise SceneError(f"{where}: 'drive' = {drive!r}: allowed {', '.join(map(repr, _parameters.DRIVES))}")

    params = data.get("parameters", {})
    if not isinstance(params, Mapping):
        raise SceneError(f"{where}: 'parameters' must be a table of parameter = value")
    _check_names(params, where, "[parameters]")
    if "drive" in params:
        raise SceneError(f"{where}: set the drive with the top-level key 'drive', not in [parameters]")
    base = {**params, "drive": drive}

    u = _signal(data, "u", where)
    omega_ref = _signal(data, "omega_ref", where)
    check_drive_inputs(drive, u, omega_ref, where)

    if "stop_time" not in data:
        raise SceneError(f"{where}: 'stop_time' [s] is missing")
    stop_time = _positive(data["stop_time"], "stop_time", where)
    if "output_interval" not in data:
        raise SceneError(f"{where}: 'output_interval' [s] is missing")
    output_interval = _positive(data["output_interval"], "output_interval", where)
    if output_interval > stop_time:
        raise SceneError(f"{where}: 'output_interval' = {output_interval} s exceeds 'stop_time' = {stop_time} s")
    check_steps(stop_time, output_interval, f"{where}: 'stop_time' / 'output_interval'", SceneError)

    plot = data.get("plot", "time")
    if plot not in PLOTS:
        raise SceneError(f"{where}: 'plot' = {plot!r}: allowed {', '.join(map(repr, PLOTS))}")

    raw_runs = data.get("runs", [])
    if not isinstance(raw_runs, list) or not all(isinstance(r, Mapping) for r in raw_runs):
        raise SceneError(f"{where}: 'runs' must be an array of tables ([[runs]])")
    runs = []
    if not raw_runs:
        runs.append(_run(DEFAULT_LABEL, base, where, "[parameters]"))
    seen: set[str] = set()
    for k, entry in enumerate(raw_runs):
        ctx = f"runs[{k}]"
        label = entry.get("label")
        if not isinstance(label, str) or not _LABEL.match(label):
            raise SceneError(f"{where}: {ctx} needs a 'label' made of letters, digits, '_', '-', '.' "
                             f"(it names the output file), got {label!r}")
        if label in seen:
            raise SceneError(f"{where}: {ctx}: label {label!r} is used twice")
        seen.add(label)
        overrides = {key: value for key, value in entry.items() if key != "label"}
        bad = sorted(key for key in overrides if key not in _parameters.BY_NAME)
        if bad:
            raise SceneError(f"{where}: {ctx} ({label!r}): unknown key(s) {', '.join(map(repr, bad))}; "
                             "allowed: 'label' and parameter names")
        if "drive" in overrides:
            raise SceneError(f"{where}: {ctx} ({label!r}): 'drive' is set once per scene (top-level key)")
        runs.append(_run(label, {**base, **overrides}, where, f"{ctx} ({label!r})"))

    return Scene(name=name, description=description, drive=drive, u=u, omega_ref=omega_ref,
                 parameters=dict(params), stop_time=stop_time, output_interval=output_interval,
                 plot=plot, runs=tuple(runs), path=path, raw=dict(data))


def _check_names(params: Mapping[str, Any], where: str, ctx: str) -> None:
    bad = sorted(key for key in params if key not in _parameters.BY_NAME)
    if bad:
        raise SceneError(f"{where}: {ctx}: unknown parameter(s) {', '.join(map(repr, bad))}; "
                         f"known: {', '.join(p.name for p in _parameters.PARAMETERS)}")


def _run(label: str, overrides: dict[str, Any], where: str, ctx: str) -> Run:
    try:
        resolved = _parameters.resolve(overrides)
    except _parameters.ParameterError as exc:
        raise SceneError(f"{where}: {ctx}: {exc}") from None
    # a value written with a unit (c = "0.5 mm") is kept as the checked SI value: every run reads numbers
    return Run(label=label, overrides={name: resolved[name] for name in overrides}, params=resolved)


def check_drive_inputs(drive: str, u: Signal | None, omega_ref: Signal | None, where: str) -> None:
    """SceneError unless the drive has its input signal (voltage: u, speed: omega_ref). `simulate` (through
    scene files) and `sweep` (for each case that sets 'drive') check a set-up with this one function."""
    needed = "u" if drive == "voltage" else "omega_ref"
    if (u if needed == "u" else omega_ref) is None:
        raise SceneError(f"{where}: drive = {drive!r} needs the input signal {needed!r} "
                         f"({'V' if needed == 'u' else 'rad/s'}): e.g. {needed} = 1.0")


def _in_range(sig: Signal, key: str, name: str, where: str) -> None:
    """Every value of the signal (piecewise linear or held: its extremes are its table values) lies in
    the FMU input's allowed range (physics.variables.INPUT_RANGES), checked before anything runs."""
    low, high = INPUT_RANGES[name]
    bad = [v for v in sig.values if not (low <= v <= high)]
    if bad:
        what = "its slope (omega_dot_ref)" if name != key else "it"
        raise SceneError(f"{where}: [{key}]: {what} reaches {bad[0]:g} {UNITS[name]}, outside the allowed range "
                         f"of the input {name!r}: [{low:g}, {high:g}] {UNITS[name]}")


def _positive(value: Any, key: str, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise SceneError(f"{where}: {key!r} = {value!r}: must be a number > 0 [s]")
    return float(value)


def _signal(data: Mapping[str, Any], key: str, where: str) -> Signal | None:
    if key not in data:
        return None
    spec = data[key]
    if isinstance(spec, bool) or not isinstance(spec, (int, float, Mapping)):
        raise SceneError(f"{where}: {key!r} must be a number or a table with 'type', got {spec!r}")
    if isinstance(spec, Mapping):
        kind = spec.get("type", "constant")
        if kind not in SIGNAL_KEYS:
            raise SceneError(f"{where}: [{key}] type = {kind!r}: allowed {', '.join(map(repr, SIGNAL_KEYS))}")
        allowed = SIGNAL_KEYS[kind]
        unknown = sorted(set(spec) - set(allowed))
        if unknown:
            raise SceneError(f"{where}: [{key}] (type {kind!r}): unknown key(s) {', '.join(map(repr, unknown))}; "
                             f"allowed: {', '.join(allowed)}")
        missing = [k for k in allowed if k != "type" and k not in OPTIONAL_KEYS and k not in spec]
        if missing:
            raise SceneError(f"{where}: [{key}] (type {kind!r}): missing key(s) {', '.join(map(repr, missing))}")
    try:
        sig = from_spec(spec)
    except (ValueError, TypeError, KeyError) as exc:
        raise SceneError(f"{where}: [{key}]: {exc}") from None
    _in_range(sig, key, key, where)
    if key == "omega_ref":
        _in_range(sig.slope_signal(), key, "omega_dot_ref", where)
    return sig


def scene_files(directory: str | Path = SCENE_DIR) -> list[Path]:
    """The scene files (*.toml) of a directory (default: the shipped scenes), sorted."""
    return sorted(Path(directory).glob("*.toml"))


def scene_names() -> list[str]:
    """Names of the shipped scenes."""
    return [path.stem for path in scene_files()]


def find_scene(name_or_path: str | Path) -> Scene:
    """Load a shipped scene by name (``paper_fig6``) or any scene file by path."""
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists() or len(path.parts) > 1:
        return load_scene(path)
    shipped = SCENE_DIR / f"{path.name}.toml"
    if not shipped.is_file():
        raise SceneError(f"no scene named {str(name_or_path)!r}: shipped scenes are "
                         f"{', '.join(scene_names())}; or give the path of a .toml file")
    return load_scene(shipped)
