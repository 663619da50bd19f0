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
        self.first: int | None = None  # units done at the first call

    def __call__(self, done: int, total: int, failed: int | None = None) -> None:
        """``failed``: failures so far (a sweep), shown with the rate [units/s] after the time left."""
        if not self.enabled:
            return
        now = time.monotonic()
        if done < total and now - self.last < 0.2:
            return
        self.last = now
        frac = done / total if total else 1.0
        filled = int(round(self.width * frac))
        elapsed = now - self.start
        if self.first is None:  # what was done before this run (a resumed sweep): not in the rate
            self.first = done
        rate = (done - self.first) / elapsed if elapsed > 0 else 0.0
        eta = (total - done) / rate if rate > 0 else (0.0 if done >= total else float("nan"))
        self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} "
                          f"{elapsed:5.1f} s, {eta:5.1f} s left "
                          + ("" if failed is None else f"{rate:,.0f}/s, {failed} failed "))
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
