"""One build at a time in a models folder: ``ensure_fmu`` and ``ensure_ssp`` hold this lock while they build.

Two commands started together in a fresh checkout (two `cam-fmu` runs, or the test suite's two processes
under pytest-xdist) would otherwise both build models/cam.fmu for every platform (minutes each), and two
writers of one SSP would share its temporary file. The second waits for the first, then finds the file up to
date and builds nothing. The lock is the kernel's (``fcntl.flock`` on POSIX, ``msvcrt.locking`` on Windows):
a holder that dies lets go. The lock file ``.cam_fmu_build.lock`` stays in the folder (empty).
"""
from __future__ import annotations

import contextlib
import os
import sys
import time
from pathlib import Path
from typing import Iterator

LOCK_NAME = ".cam_fmu_build.lock"


@contextlib.contextmanager
def building(folder: Path) -> Iterator[None]:
    """Hold ``folder``'s build lock for the block, waiting while another process holds it."""
    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder / LOCK_NAME, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        if sys.platform == "win32":
            import msvcrt

            while True:
                try:
                    msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
                    break
                except OSError:
                    time.sleep(0.1)
            try:
                yield
            finally:
                os.lseek(fd, 0, os.SEEK_SET)
                msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)
        else:
            import fcntl

            fcntl.flock(fd, fcntl.LOCK_EX)
            try:
                yield
            finally:
                fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)
