"""A dependency-free progress bar on stderr: ``bar(done, total)``; drawn only on a terminal
(or when CAM_FMU_PROGRESS=1), at most every 0.2 s, and finished with a newline."""
from __future__ import annotations

import os
import sys
import time


class ProgressBar:
    def __init__(self, label: str, stream=None, width: int = 30) -> None:
        self.label, self.width = label, width
        self.stream = stream or sys.stderr
        self.enabled = os.environ.get("CAM_FMU_PROGRESS") == "1" or (
            os.environ.get("CAM_FMU_PROGRESS") != "0" and hasattr(self.stream, "isatty") and self.stream.isatty())
        self.start = time.monotonic()
        self.last = 0.0
        self.open = False  # a line drawn and not yet finished with its newline

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if done < total and now - self.last < 0.2:
            return
        self.last = now
        frac = done / total if total else 1.0
        filled = int(round(self.width * frac))
        elapsed = now - self.start
        eta = elapsed / frac - elapsed if frac > 0 else float("nan")
        self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} "
                          f"{elapsed:5.1f} s, {eta:5.1f} s left ")
        self.open = done < total
        if not self.open:
            self.stream.write("\n")
        self.stream.flush()

    def close(self) -> None:
        """End an unfinished line (a run that failed), so that what follows starts on its own line."""
        if self.open:
            self.stream.write("\n")
            self.stream.flush()
            self.open = False
