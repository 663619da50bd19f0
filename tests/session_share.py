"""Work done once per test session, whether the session runs in one process or in pytest-xdist's workers.

Under ``pytest -n 2`` each worker is its own Python process with its own session fixtures: a fixture that
builds an FMU would build it once per worker. ``once`` builds it once for the whole session: the workers
share the folder above their own temporary folders (``tmp_path_factory.getbasetemp().parent``, one per
session, the pattern pytest-xdist documents), and an operating-system lock (``fcntl.flock``, released by the
kernel however its holder ends) lets one worker produce while the others wait, then read its result. A
failure is kept with its message: the other workers fail with it instead of trying again. Without xdist
the folder is the session's own temporary folder (its parent is shared by every session of the user).
"""
from __future__ import annotations

import contextlib
import fcntl
import os
import pickle
from pathlib import Path
from typing import Callable, Iterator, TypeVar

import pytest

T = TypeVar("T")


def shared_folder(tmp_path_factory) -> Path:
    """The folder every process of this session sees: the workers' common parent under xdist, else the
    session's own temporary folder."""
    base = tmp_path_factory.getbasetemp()
    folder = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "shared"
    folder.mkdir(exist_ok=True)
    return folder


@contextlib.contextmanager
def locked(path: Path) -> Iterator[None]:
    """Hold the exclusive lock ``path`` (created when missing) for the block, waiting for another holder."""
    with open(path, "a") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def once(tmp_path_factory, name: str, produce: Callable[[Path], T]) -> T:
    """``produce(folder)`` run once per session for ``name`` (in an empty ``folder`` of its own), its result
    (picklable) shared with every worker; a failure (``pytest.fail`` or an exception) fails every caller with
    its message."""
    root = shared_folder(tmp_path_factory)
    done, failed = root / f"{name}.result", root / f"{name}.failed"
    with locked(root / f"{name}.lock"):
        if done.is_file():
            return pickle.loads(done.read_bytes())
        if failed.is_file():
            pytest.fail(f"{name}, as another worker of this session found:\n{failed.read_text()}")
        folder = root / name
        folder.mkdir()
        try:
            result = produce(folder)
        except BaseException as exc:
            failed.write_text(f"{type(exc).__name__}: {exc}")
            raise
        done.write_bytes(pickle.dumps(result))
        return result
