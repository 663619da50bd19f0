"""The test layout's markers from recorded durations (tests/README.md, "Markers and the fast loop").

``external`` is by folder and module (a tool beyond Python and gcc); ``slow`` is by measurement: a full run
records every test's duration into ``tests/durations.json``

    python -m pytest -q --record-durations tests/durations.json

and a test is ``slow`` when its own time, or the set-up of a module-scoped fixture it uses, exceeds
``SLOW_SECONDS``. A test's own time is its set-up, call and tear-down less the set-up of the module- and
session-scoped fixtures it was the first to need (those are recorded apart, so a module's first test does not
carry the module's fixtures; the session's FMU builds are not charged to any test), plus the seconds of the
reference runs it read from the session's cache (reference_runs.py: each reader is charged, not only the first,
since the fast loop may lack the first). A test the file does not
hold (added since the last record) is not slow: it runs in the fast loop until the next record.
"""
from __future__ import annotations

import json
import time
from collections import defaultdict
from pathlib import Path
from typing import Iterable

import pytest

HERE = Path(__file__).resolve().parent
DURATIONS = HERE / "durations.json"
SLOW_SECONDS = 0.15 # a test (or a module fixture it needs) recorded above this is `slow` [s]
FAST_LOOP_SECONDS = 60.0  # the fast loop's target on the 2-core development machine [s]
# what the fast loop spends outside the recorded tests: start-up, collection and the session's FMU builds for
# this machine (measured: tests/README.md) [s]
FAST_LOOP_OVERHEAD_SECONDS = 20.0

EXTERNAL = {  # outside hosts/: modules that need wine, qemu, valgrind, sanitizers or a C host
    "test_engine_c_host", "test_engine_sanitize", "test_engine_state_fuzz", "test_engine_fmu_me_host", "test_fmi3",
    "test_fmi3_me_host",
    "test_bench_floors", "test_bench_memory",
}


def is_external(nodeid: str) -> bool:
    """Every test of hosts/ and of the modules in EXTERNAL needs a tool beyond Python and gcc."""
    path = Path(nodeid.split("::")[0])
    return path.parent.name == "hosts" or path.stem in EXTERNAL


def fixture_key(nodeid: str, name: str) -> str:
    """A module-scoped fixture's record: its test file and its name (``tests/x/test_y.py::fixture``)."""
    return f"{nodeid.split('::')[0]}::{name}"


def load(path: Path = DURATIONS) -> dict:
    """The recorded durations: ``tests`` (node id -> own seconds), ``fixtures`` (module fixture -> seconds of
    its set-ups), ``session`` (session fixture -> seconds); empty tables when there is no file."""
    if not path.is_file():
        return {"tests": {}, "fixtures": {}, "session": {}}
    return json.loads(path.read_text(encoding="utf-8"))


def is_slow(nodeid: str, fixturenames: Iterable[str], recorded: dict) -> bool:
    """Recorded above SLOW_SECONDS: the test's own time, or a module fixture of its file that it uses."""
    if recorded["tests"].get(nodeid, 0.0) > SLOW_SECONDS:
        return True
    return any(recorded["fixtures"].get(fixture_key(nodeid, name), 0.0) > SLOW_SECONDS for name in fixturenames)


def fast_loop_bound(recorded: dict) -> tuple[float, int]:
    """An upper bound of the fast loop's recorded seconds, and its number of tests: the own time of every test
    neither external nor slow by its own time, plus every module fixture at most SLOW_SECONDS of a file that has
    such a test (whether or not those tests use it; a slow fixture's tests are counted too: the file does not
    say which tests use which fixture, so the bound over-counts and never under-counts)."""
    fast = {n: s for n, s in recorded["tests"].items() if not is_external(n) and s <= SLOW_SECONDS}
    files = {n.split("::")[0] for n in fast}
    fixtures = sum(s for key, s in recorded["fixtures"].items()
                   if s <= SLOW_SECONDS and key.rsplit("::", 1)[0] in files)
    return sum(fast.values()) + fixtures, len(fast)


class DurationRecorder:
    """``--record-durations PATH``: every test's own seconds and its shared fixtures' set-ups, written at the
    end of the session (a full run: `python -m pytest -q --record-durations tests/durations.json`)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.tests: dict[str, float] = defaultdict(float)
        self.shared: dict[str, float] = defaultdict(float)  # per test: its shared fixtures' set-ups
        self.fixtures: dict[str, float] = defaultdict(float)
        self.session: dict[str, float] = defaultdict(float)
        self.item_id: str | None = None
        self.nested = [0.0]  # set-up seconds of fixtures set up inside the one being timed

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_protocol(self, item, nextitem):
        from reference_runs import CHARGED  # the session's reference runs it read from the cache

        self.item_id = item.nodeid
        CHARGED[0] = 0.0
        yield
        self.tests[item.nodeid] += CHARGED[0]
        self.item_id = None

    @pytest.hookimpl(hookwrapper=True)
    def pytest_fixture_setup(self, fixturedef, request):
        from reference_runs import CHARGED

        self.nested.append(0.0)
        charged = CHARGED[0]
        start = time.perf_counter()
        yield
        total = time.perf_counter() - start
        inner = self.nested.pop()
        self.nested[-1] += total
        if fixturedef.scope == "function" or self.item_id is None:
            return
        # a fixture that asked for another inside its body: each counted once; the cached reference runs a
        # shared fixture read are its own, not its first test's
        own = total - inner + CHARGED[0] - charged
        CHARGED[0] = charged
        self.shared[self.item_id] += own
        if fixturedef.scope == "session":
            self.session[fixturedef.argname] += own
        else:
            self.fixtures[fixture_key(self.item_id, fixturedef.argname)] += own

    def pytest_runtest_logreport(self, report) -> None:
        self.tests[report.nodeid] += report.duration

    def pytest_sessionfinish(self, session, exitstatus) -> None:
        """Write the record: a test or fixture that ran replaces its entry, the others keep theirs (a run of some
        modules updates those; a full run updates all, and a test no longer collected keeps its entry, which
        only over-counts the fast loop's bound)."""
        record = load(self.path)
        record["command"] = ".venv/bin/python -m pytest -q --record-durations tests/durations.json"
        record["tests"].update({n: round(max(s - self.shared[n], 0.0), 3) for n, s in self.tests.items()})
        record["fixtures"].update({k: round(s, 3) for k, s in self.fixtures.items()})
        record["session"].update({k: round(s, 3) for k, s in self.session.items()})
        for table in ("tests", "fixtures", "session"):
            record[table] = dict(sorted(record[table].items()))
        self.path.write_text(json.dumps(record, indent=0) + "\n", encoding="utf-8")
