"""A sweep's files in its output folder DIR, and the checks that keep every case in them once.

- ``DIR/<scene>_sweep.parquet/``: the table, a Parquet dataset of part files only (pyarrow and pandas read the
  folder as one table): ``part-<first>-<end>.parquet`` holds the cases of index first..end-1 (column ``case``:
  index + 1), written under a hidden temporary name and renamed (whole or absent; readers skip hidden files);
- ``DIR/<scene>_sweep.json``: the sweep's specification (compared on --resume);
- ``DIR/<scene>_sweep.lock``: while a sweep writes the folder (sweep_lock.py).

Before this layout the specification sat inside the dataset folder (``sweep.json``), where pyarrow and pandas
took it for a part and failed: such a folder is still read here, and a --resume moves the file beside it.

Parts must not overlap: reading refuses a folder whose parts hold a case twice; ``repair`` (run by --resume,
under the lock) removes a part whose every row another part holds with the same bits (what two writers left:
the same batch cut short by one and finished by the other) and refuses any other overlap.
"""
from __future__ import annotations

import json
import os
import re
import uuid
from pathlib import Path
from typing import Any, Iterator, Sequence

from .sweep import header
from .sweep_cases import SweepError

LEGACY_SPEC = "sweep.json"  # the specification's place inside the dataset folder before this layout
PART = re.compile(r"part-(\d{10})-(\d{10})\.parquet")


# ------------------------------------------------------------------ where
def dataset_path(out: str | Path, scene_name: str) -> Path:
    """The table's folder: ``out/<scene>_sweep.parquet``."""
    return Path(out) / f"{scene_name}_sweep.parquet"


def spec_path(folder: str | Path) -> Path:
    """The specification beside the table: ``out/<scene>_sweep.json``."""
    folder = Path(folder)
    return folder.with_name(folder.name.removesuffix(".parquet") + ".json")


def lock_path(folder: str | Path) -> Path:
    """The writer's lock beside the table: ``out/<scene>_sweep.lock``."""
    folder = Path(folder)
    return folder.with_name(folder.name.removesuffix(".parquet") + ".lock")


# ------------------------------------------------------------------ the specification
def read_spec(folder: str | Path) -> dict | None:
    """The stored specification (beside the folder, or inside it in the earlier layout), None without one."""
    for path in (spec_path(folder), Path(folder) / LEGACY_SPEC):
        if path.is_file():
            return json.loads(path.read_text(encoding="utf-8"))
    return None


def write_spec(folder: Path, spec: dict) -> None:
    """Write the specification beside the folder (whole or absent) and remove an earlier layout's copy inside."""
    path = spec_path(folder)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    tmp.write_text(json.dumps(spec, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    os.replace(tmp, path)
    legacy = folder / LEGACY_SPEC
    if legacy.is_file():
        legacy.unlink()


# ------------------------------------------------------------------ the parts
def entries(folder: Path) -> list[Path]:
    """What the folder holds that a reader of the dataset sees (hidden files and the earlier layout's
    specification aside)."""
    if not folder.is_dir():
        return []
    return sorted(p for p in folder.iterdir() if not p.name.startswith((".", "_")) and p.name != LEGACY_SPEC)


def _listing(folder: Path) -> list[tuple[int, int, Path]]:
    """(first, end, file) of every part by its name, in case order; SweepError for a file that is not a part."""
    found = []
    for path in entries(folder):
        match = PART.fullmatch(path.name)
        if not match or not path.is_file() or int(match[1]) >= int(match[2]):
            raise SweepError(f"{folder} holds {path.name}, not a part file (part-<first>-<end>.parquet, first < "
                             "end): a sweep's folder holds its part files only; move it away")
        found.append((int(match[1]), int(match[2]), path))
    return sorted(found)


def _check_range(found: Sequence[tuple[int, int, Path]], cases: int | None) -> None:
    if cases is not None and found:
        first, end, path = max(found, key=lambda p: p[1])
        if end > cases:
            raise SweepError(f"{path} holds cases {first + 1} to {end}, beyond this sweep's {cases}: not a part of it")


def _check_disjoint(folder: Path, found: Sequence[tuple[int, int, Path]]) -> None:
    for (f1, e1, p1), (f2, e2, p2) in zip(found, found[1:]):
        if f2 < e1:
            raise SweepError(f"{folder} holds cases {f2 + 1} to {min(e1, e2)} twice, in {p1.name} and {p2.name}: "
                             "--resume removes a part whose rows another holds with the same bits; otherwise "
                             "remove one of them")


def parts(folder: str | Path, cases: int | None = None) -> list[tuple[int, int, Path]]:
    """(first case, end, file) of every finished batch, in case order; SweepError for a file that is not a part,
    a part beyond ``cases`` and parts that hold a case twice (naming the files and the cases)."""
    folder = Path(folder)
    found = _listing(folder)
    _check_range(found, cases)
    _check_disjoint(folder, found)
    return found


def cases_on_disk(found: Sequence[tuple[int, int, Path]]) -> int:
    """Cases the (disjoint) parts hold."""
    return sum(end - first for first, end, _ in found)


def _check_cases(table, first: int, end: int, path: Path) -> None:
    import numpy as np

    if "case" not in table.column_names:
        raise SweepError(f"{path} has no column 'case': not a part of a sweep; move it away")
    case = table["case"].to_numpy()
    if not np.array_equal(case, np.arange(first + 1, end + 1)):
        raise SweepError(f"{path} is named for cases {first + 1} to {end} but holds {len(case)} rows of cases "
                         f"{case.min() if len(case) else '-'} to {case.max() if len(case) else '-'}: not a part of "
                         "this sweep; move it away")


def _same_bits(a, b) -> bool:
    """Two pyarrow tables hold the same columns and values, bit for bit (NaN equals NaN)."""
    import numpy as np

    if a.schema.names != b.schema.names or a.schema.types != b.schema.types or a.num_rows != b.num_rows:
        return False
    for x, y in zip(a.columns, b.columns):
        x, y = x.to_numpy(zero_copy_only=False), y.to_numpy(zero_copy_only=False)
        if x.dtype.kind == "f":
            x, y = x.view(np.uint64), y.view(np.uint64)
        if not np.array_equal(x, y):
            return False
    return True


def repair(folder: str | Path, cases: int) -> tuple[list[tuple[int, int, Path]], list[str]]:
    """The parts after removing each one whose every row a larger part holds with the same bits, and a line per
    file removed; SweepError, with nothing removed, for a file that is not a part, a part beyond ``cases`` or
    whose rows are not the cases its name says, and any other overlap (parts that cross, or that disagree on a
    case: which copy is right is then unknown)."""
    import pyarrow.parquet as pq

    folder = Path(folder)
    found = _listing(folder)
    _check_range(found, cases)
    found.sort(key=lambda p: (p[0], -p[1]))  # a larger part before the ones it holds
    kept: list[tuple[int, int, Path]] = []
    redundant, notes = [], []
    for first, end, path in found:
        if kept and first < kept[-1][1] and end <= kept[-1][1]:
            f0, e0, p0 = kept[-1]
            mine, theirs = pq.read_table(path), pq.read_table(p0)
            _check_cases(mine, first, end, path)
            if not _same_bits(mine, theirs.slice(first - f0, end - first)):
                raise SweepError(f"{folder} holds cases {first + 1} to {end} twice, in {p0.name} and {path.name}, "
                                 "with different values: which is right is unknown; remove the wrong one (or "
                                 "--overwrite)")
            redundant.append(path)
            notes.append(f"removed {path.name}: its cases {first + 1} to {end} are in {p0.name} with the same bits")
        else:
            kept.append((first, end, path))
    _check_disjoint(folder, kept)
    for first, end, path in kept:
        _check_cases(pq.read_table(path, columns=["case"]), first, end, path)
    for path in redundant:
        path.unlink()
    return kept, notes


# ------------------------------------------------------------------ reading and writing
def iter_rows(folder: str | Path, columns: Sequence[str] | None = None) -> Iterator[dict[str, Any]]:
    """The table's rows in case order, one file at a time, keyed by name without unit ('m', 'peak_i', 'case',
    'status', 'message'); ``columns``: only those (by name). SweepError when the parts hold a case twice or a
    part's rows are not the cases its name says."""
    import pyarrow.parquet as pq

    for first, end, path in parts(Path(folder)):
        table = pq.read_table(path)
        _check_cases(table, first, end, path)
        table = table.rename_columns([f.split(" [")[0] for f in table.column_names])
        if columns is not None:
            table = table.select(list(columns))
        yield from table.to_pylist()


def failed_on_disk(folder: str | Path) -> int:
    """Failed cases in the dataset (column status, file by file)."""
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    return sum(int(pc.sum(pc.equal(pq.read_table(path, columns=["status"])["status"], "failed")).as_py() or 0)
               for _, _, path in parts(Path(folder)))


def write_part(folder: Path, schema, columns: dict[str, list]) -> None:
    """One batch's rows (``columns``: 'case', the varied names, the metrics, status, message; ``schema``: the
    columns with their units) as ``part-<first>-<end>.parquet``, written under a hidden temporary name and
    renamed: whole or absent."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    first, count = columns["case"][0] - 1, len(columns["case"])
    data = {(name if name in ("case", "status", "message") else header(name)): values
            for name, values in columns.items()}
    table = pa.table({f.name: pa.array(data[f.name], type=f.type) for f in schema}, schema=schema)
    tmp = folder / f".part-{first:010d}-{uuid.uuid4().hex}.tmp"
    pq.write_table(table, tmp)
    os.replace(tmp, folder / f"part-{first:010d}-{first + count:010d}.parquet")
