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
        self.note = ""  # the note last drawn
        self.drawn = 0  # characters of the line last drawn

    def __call__(self, done: int, total: int, failed: int | None = None, note: str = "") -> None:
        """``failed``: failures so far (a sweep), shown with the rate [units/s] after the time left; ``note``: what
        is under way (a build's platform), after the counts; a new note is drawn at once."""
        if not self.enabled:
            return
        now = time.monotonic()
        if done < total and now - self.last < 0.2 and note == self.note:
            return
        self.note = note
        self.last = now
        frac = done / total if total else 1.0
        filled = int(round(self.width * frac))
        elapsed = now - self.start
        if self.first is None:  # what was done before this run (a resumed sweep): not in the rate
            self.first = done
        rate = (done - self.first) / elapsed if elapsed > 0 else 0.0
        eta = (total - done) / rate if rate > 0 else (0.0 if done >= total else float("nan"))
        line = (f"{self.label} [{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} "
                + (f"{note}, " if note else "") + f"{elapsed:5.1f} s, " + (f"{eta:5.1f} s left " if eta == eta else "    ? s left ")
                + ("" if failed is None else f"{rate:,.0f}/s, {failed} failed "))
        self.stream.write("\r" + line + " " * max(0, self.drawn - len(line)))  # blanks over a longer line's rest
        self.drawn = len(line)
        self.open = done < total
        if not self.open:
            self.stream.write("\n")
            self.drawn = 0
        self.stream.flush()

    def close(self) -> None:
        """End an unfinished line (a run that failed), so that what follows starts on its own line."""
        if self.open:
            self.stream.write("\n")
            self.drawn = 0
            self.stream.flush()
            self.open = False
