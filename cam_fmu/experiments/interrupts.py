"""Interrupts and quiet for the sweep's driver: SIGINT ignored while processes start, a flag instead of
KeyboardInterrupt while the driver must not be cut short, environment and logging set for a block."""
from __future__ import annotations

import contextlib
import os


@contextlib.contextmanager
def sigint_ignored():
    """SIGINT ignored while the block starts processes: they inherit the disposition (Python and asyncio install
    no KeyboardInterrupt handler where SIGINT is ignored), so a Ctrl-C to the terminal's process group reaches only
    this process, which stops the sweep; dask's worker processes print no traceback."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


class InterruptFlag:
    """SIGINT sets ``event`` instead of raising KeyboardInterrupt (in the main thread; elsewhere nothing changes);
    ``restore`` puts the former handler back."""

    def __init__(self) -> None:
        import signal
        import threading

        self.event = threading.Event()
        self.previous = None
        if threading.current_thread() is threading.main_thread():
            self.previous = signal.signal(signal.SIGINT, lambda signum, frame: self.event.set())

    def is_set(self) -> bool:
        return self.event.is_set()

    def wait(self, seconds: float) -> None:
        self.event.wait(seconds)

    def restore(self) -> None:
        import signal

        if self.previous is not None:
            signal.signal(signal.SIGINT, self.previous)
            self.previous = None


@contextlib.contextmanager
def environment(**values: str):
    """os.environ with ``values`` inside the block (what processes started there inherit)."""
    saved = {name: os.environ.get(name) for name in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


@contextlib.contextmanager
def quiet(logger: str):
    """The logger ``logger`` and its children silent below CRITICAL inside the block."""
    import logging

    log = logging.getLogger(logger)
    level = log.level
    log.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        log.setLevel(level)
