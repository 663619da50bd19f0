"""Reproducible builds: two builds of one commit give the same bytes for every FMU, SSP and wheel.

Build time only. What would differ between two builds, and what fixes it:

- the time: every zip entry (FMU, SSP; the wheels through ``bdist_wheel``) carries ``SOURCE_DATE_EPOCH``
  (the reproducible-builds convention), by default the last commit's time, outside git ``FIXED_EPOCH``;
- the order and the permissions of the zip entries: sorted by name, 0644, one compression (``write_zip``);
- the build folders (random temporary folders): the compiler maps them away (``prefix_map_flags``: what
  ``__FILE__`` and debug information would carry), and the linker writes its output under its bare name
  (a macOS library records the path it was linked to as its install name).
"""
from __future__ import annotations

import os
import subprocess
import time
import zipfile
from pathlib import Path
from typing import Iterable, Mapping

FIXED_EPOCH = 315532800  # 1980-01-01 00:00:00 UTC: the earliest time a zip entry can carry
ROOT = Path(__file__).resolve().parents[2]  # the repository root when the package runs from a checkout


def source_date_epoch() -> int:
    """The build's time in seconds since 1970 (UTC): ``$SOURCE_DATE_EPOCH``, else the checkout's last commit
    time, else ``FIXED_EPOCH``; never earlier than FIXED_EPOCH (a zip cannot say it)."""
    value = os.environ.get("SOURCE_DATE_EPOCH", "").strip()
    if value:
        try:
            return max(int(value), FIXED_EPOCH)
        except ValueError:
            raise ValueError(f"SOURCE_DATE_EPOCH={value!r}: an integer number of seconds since 1970 "
                             f"(UTC) is allowed") from None
    try:
        out = subprocess.run(["git", "log", "-1", "--format=%ct"], cwd=ROOT, capture_output=True, text=True,
                             timeout=60)
        if out.returncode == 0 and out.stdout.strip():
            return max(int(out.stdout.strip()), FIXED_EPOCH)
    except (OSError, ValueError, subprocess.SubprocessError):
        pass  # no git, or not a checkout
    return FIXED_EPOCH


def build_env() -> dict[str, str]:
    """This process's environment with ``SOURCE_DATE_EPOCH`` set (for a child that builds: ``pip wheel``)."""
    return {**os.environ, "SOURCE_DATE_EPOCH": str(source_date_epoch())}


def zip_time(epoch: int | None = None) -> tuple[int, int, int, int, int, int]:
    """A zip entry's date_time (UTC) of ``epoch`` (default: ``source_date_epoch()``)."""
    return time.gmtime(source_date_epoch() if epoch is None else epoch)[:6]


def write_zip(dest: Path, entries: Mapping[str, bytes | Path]) -> Path:
    """Write the zip ``dest`` of ``entries`` (archive name -> bytes or a file to read): sorted by name, each
    with the build's time and permissions 0644, deflated. Returns ``dest``."""
    stamp = zip_time()
    with zipfile.ZipFile(dest, "w") as z:
        for name in sorted(entries):
            data = entries[name]
            info = zipfile.ZipInfo(name, date_time=stamp)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = (0o100644 << 16)  # a regular file, rw-r--r--
            info.create_system = 3  # Unix: the permissions above are read as such on every system
            z.writestr(info, data if isinstance(data, bytes) else Path(data).read_bytes())
    return Path(dest)


def tree_entries(folder: Path) -> dict[str, Path]:
    """Every file under ``folder``, by its path relative to it (a zip's names)."""
    return {p.relative_to(folder).as_posix(): p for p in Path(folder).rglob("*") if p.is_file()}


def prefix_map_flags(folders: Iterable[Path]) -> list[str]:
    """The compiler flags that map ``folders`` (absolute) to ``.`` in everything the compiler writes
    (``__FILE__``, debug information): ``-ffile-prefix-map`` is both ``-fdebug-prefix-map`` and
    ``-fmacro-prefix-map`` (gcc 8, clang 10 and zig). Longest first, so a nested folder maps before its parent."""
    unique = {str(Path(f).resolve()) for f in folders}
    return [f"-ffile-prefix-map={f}=." for f in sorted(unique, key=lambda f: (-len(f), f))]


__all__ = ["FIXED_EPOCH", "build_env", "prefix_map_flags", "source_date_epoch", "tree_entries", "write_zip",
           "zip_time"]
