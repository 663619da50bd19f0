"""One writer at a time in a sweep's folder: an operating-system lock on ``<out>/<scene>_sweep.lock``.

The lock is the kernel's (``fcntl.flock`` on POSIX, ``msvcrt.locking`` on Windows), not a file whose presence
means "taken": the kernel drops a process's locks when the process ends, however it ends (Ctrl-C, kill -9, a
crash), so a dead holder never leaves the folder stuck, and a live one is never taken over because its pid
looks gone or was reused (a pid check also cannot see processes on another host). The file holds the
holder's pid, host and start time (JSON) for the message that refuses a second writer; the holder removes it
when it lets go. A file left by a dead holder is unlocked: the next run takes it and writes its own line.
"""
from __future__ import annotations

import contextlib
import datetime
import json
import os
import socket
import sys
import time
from pathlib import Path
from typing import Iterator

from .sweep_cases import SweepError

_WINDOWS_BYTE = 1 << 30  # Windows locks a byte range and no other process may read it: the byte locked lies far
#                          beyond the holder's line, which stays readable


def holder_text(path: Path) -> str:
    """'pid 123 on host h since 2026-11-28T01:02:03Z' from the lock file (its holder's line), or why not."""
    for _ in range(50):  # the holder writes its line right after taking the lock: a moment's wait
        try:
            info = json.loads(path.read_text(encoding="utf-8"))
            return f"pid {info['pid']} on host {info['host']} since {info['started']}"
        except FileNotFoundError:
            return "a process that has just let go"
        except (ValueError, KeyError, TypeError, OSError):
            time.sleep(0.01)
    return "an unknown process (the lock file names none)"


def _try_lock(fd: int) -> bool:
    """Take the lock on ``fd`` without waiting: True when taken, False when another process holds it."""
    if sys.platform == "win32":
        import msvcrt

        os.lseek(fd, _WINDOWS_BYTE, os.SEEK_SET)
        try:
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        except PermissionError:
            return False
        except OSError as exc:
            if exc.errno in (13, 36):  # EACCES, EDEADLOCK: held by another process
                return False
            raise
        return True
    import fcntl

    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


def _acquire(path: Path, folder: Path) -> int:
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            taken = _try_lock(fd)
        except OSError as exc:
            os.close(fd)
            raise SweepError(f"--out: cannot lock {path} ({exc.strerror or exc}): this file system offers no "
                             "file locks; write the sweep to a local folder") from None
        if not taken:
            os.close(fd)
            raise SweepError(f"--out: {folder} is being written by another sweep, {holder_text(path)} "
                             f"(lock {path}): one sweep writes a folder at a time; wait for it to end or stop it")
        try:  # the previous holder may have removed the file between our open and our lock: lock the file there
            same = os.path.samestat(os.fstat(fd), os.stat(path))
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)


@contextlib.contextmanager
def hold(path: str | Path, folder: str | Path) -> Iterator[Path]:
    """Hold the lock ``path`` of the sweep folder ``folder`` for the block; SweepError (naming the holder's pid,
    host and start time) when another process holds it."""
    path, folder = Path(path), Path(folder)
    created = not path.parent.exists()
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        fd = _acquire(path, folder)
    except BaseException:
        if created:
            with contextlib.suppress(OSError):
                path.parent.rmdir()
        raise
    try:
        started = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        line = json.dumps({"pid": os.getpid(), "host": socket.gethostname(), "started": started}) + "\n"
        os.lseek(fd, 0, os.SEEK_SET)
        os.ftruncate(fd, 0)
        os.write(fd, line.encode())
        yield path
    finally:
        if sys.platform == "win32":  # an open file cannot be removed there: close, then remove unless taken again
            os.close(fd)
            with contextlib.suppress(OSError):
                os.unlink(path)
        else:  # removed while held: a process that opened it meanwhile sees, once it has the lock, that it is gone
            with contextlib.suppress(OSError):
                os.unlink(path)
            os.close(fd)
        if created:  # a folder made for the lock alone (a refused run) does not stay behind
            with contextlib.suppress(OSError):
                path.parent.rmdir()
