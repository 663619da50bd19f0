"""Run cam.fmu in ``ecos``, a native (C++) co-simulation engine, and read its result.

The ``ecospy`` wheel ships the ``ecos`` command-line program in
``ecospy/binaries/ecos`` (not executable as installed: it is chmod-ed here, or
copied to a cache directory when site-packages is read-only). It needs Debian's
``libtbb12``. ecos loads the FMU's binary directly; it runs here in
an empty environment (``PATH=/usr/bin:/bin`` only): cam.fmu's own binary needs no set-up.

``ecos simulate --path FMU --stopTime T --stepSize H`` writes ``<name>.csv`` in
its working directory (columns ``iterations, time, instance::omega[REAL], ...``,
values with 6 decimals); each run here uses a fresh temporary directory.
Standard library and numpy only.
"""
from __future__ import annotations

import csv
import importlib.util
import os
import shutil
import stat
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Sequence

import numpy as np



class EcosError(RuntimeError):
    pass


@dataclass
class EcosResult:
    returncode: int
    stdout: str
    stderr: str
    command: List[str]
    columns: Dict[str, np.ndarray] = field(default_factory=dict)  # 'time', 'omega', ... (instance prefix removed)

    @property
    def stop_time(self) -> float:
        return float(self.columns["time"][-1]) if "time" in self.columns and len(self.columns["time"]) else float("nan")


def ecos_binary() -> Path:
    """Path of an executable ``ecos`` from the installed ecospy wheel (EcosError if unusable)."""
    spec = importlib.util.find_spec("ecospy")
    if spec is None or not spec.submodule_search_locations:
        raise EcosError("the 'ecospy' package is not installed (pip install ecospy): it ships the ecos engine")
    binary = Path(list(spec.submodule_search_locations)[0]) / "binaries" / "ecos"
    if not binary.is_file():
        raise EcosError(f"ecospy is installed but has no ecos binary at {binary}")
    if not os.access(binary, os.X_OK):
        try:
            binary.chmod(binary.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
        except OSError:
            cache = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "cam_fmu"
            cache.mkdir(parents=True, exist_ok=True)
            copy = cache / "ecos"
            shutil.copy2(binary, copy)
            copy.chmod(copy.stat().st_mode | stat.S_IXUSR)
            # its shared libraries (libecosc.so, proxyfmu) sit next to it
            for sibling in binary.parent.iterdir():
                if sibling.name != "ecos" and not (cache / sibling.name).exists():
                    shutil.copy2(sibling, cache / sibling.name)
            binary = copy
    missing = missing_libraries(binary)
    if missing:
        hint = " (Debian: apt-get install libtbb12)" if any("tbb" in m for m in missing) else ""
        raise EcosError(f"ecos cannot start: missing shared libraries {', '.join(missing)}{hint}")
    return binary


def missing_libraries(binary: Path) -> List[str]:
    """Shared libraries ``ldd`` reports as 'not found' for ``binary`` (empty when ldd is unavailable)."""
    try:
        out = subprocess.run(["ldd", str(binary)], capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return []
    return [line.split("=>")[0].strip() for line in out.splitlines() if "not found" in line]


def read_csv(path: Path, keep_instance: bool = False) -> Dict[str, np.ndarray]:
    """ecos' numeric CSV columns as {'iterations', 'time', '<variable>': array}.

    'instance::omega[REAL]' becomes 'omega' ('instance.omega' with ``keep_instance``,
    for systems whose instances share variable names); STRING columns are left out.
    """
    with open(path, encoding="utf-8", newline="") as fh:
        rows = list(csv.reader(fh))
    header = [h.strip() for h in rows[0]]
    columns: Dict[str, np.ndarray] = {}
    for k, h in enumerate(header):
        if h.endswith("[STRING]"):
            continue
        name = h.replace("::", ".", 1) if keep_instance else h.split("::", 1)[-1]
        if name.endswith("]") and "[" in name:
            name = name[: name.rindex("[")]
        try:
            columns[name] = np.array([float(row[k]) for row in rows[1:] if len(row) == len(header)])
        except ValueError:
            continue  # not numeric (e.g. booleans written as words)
    return columns


def simulate(fmu: Path, stop_time: float, step_size: float, start_time: float = 0.0,
             extra_args: Sequence[str] = (), timeout: float = 300.0, workdir: Optional[Path] = None,
             env: Optional[Dict[str, str]] = None) -> EcosResult:
    """Run ``ecos simulate`` on ``fmu`` in a fresh directory; never raises for a failing run.

    ecos died with a floating point exception on runs of fewer than 10 steps
    (its progress report): give it at least 10 steps.
    """
    if (stop_time - start_time) / step_size < 10 - 1e-9:
        raise EcosError("ecos needs at least 10 steps (it crashes in its progress report otherwise)")
    fmu = Path(fmu).resolve()
    binary = ecos_binary()
    # An empty environment, as a new user's tool would have: cam.fmu's own binary finds the Python
    # recorded at build time by itself (docs/fmu.md). ``env`` adds to the caller's environment instead.
    run_env = {"PATH": "/usr/bin:/bin"} if env is None else {**os.environ, **env}
    command = [str(binary), "simulate", "--path", str(fmu), "--startTime", repr(float(start_time)),
               "--stopTime", repr(float(stop_time)), "--stepSize", repr(float(step_size)), *extra_args]
    with tempfile.TemporaryDirectory(prefix="cam_fmu_ecos_") as tmp:
        cwd = Path(workdir) if workdir else Path(tmp)
        proc = subprocess.run(command, cwd=cwd, env=run_env, capture_output=True, text=True, timeout=timeout)
        result = EcosResult(proc.returncode, proc.stdout, proc.stderr, command)
        csvs = sorted(cwd.glob("*.csv"))
        if csvs:
            result.columns = read_csv(csvs[0])
    return result
