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


def module_seconds(recorded: dict) -> dict[str, float]:
    """Each test file's recorded seconds: its tests' own times and its module fixtures' set-ups."""
    total: dict[str, float] = defaultdict(float)
    for table in ("tests", "fixtures"):
        for key, seconds in recorded[table].items():
            total[key.split("::")[0]] += seconds
    return total


def longest_modules_first(items: list, recorded: dict) -> list:
    """``items`` (pytest's collected tests) with their modules in the order of their recorded seconds, longest
    first (a module not recorded last), each module's tests in their own order: pytest-xdist's loadscope hands
    whole modules to the workers in this order, so the longest start at once and the short ones fill the end."""
    seconds = module_seconds(recorded)
    first = {}
    for index, item in enumerate(items):
        first.setdefault(item.nodeid.split("::")[0], index)
    return sorted(items, key=lambda item: (-seconds.get(item.nodeid.split("::")[0], 0.0),
                                           first[item.nodeid.split("::")[0]]))


WORKER_OUTPUT = "cam_fmu_durations"  # the key a pytest-xdist worker sends its record under


class DurationRecorder:
    """``--record-durations PATH``: every test's own seconds and its shared fixtures' set-ups, written at the
    end of the session (a full run: `python -m pytest -q -n 2 --record-durations tests/durations.json`).

    Under pytest-xdist every worker records the tests it ran and sends its record to the controlling process
    at its end (``config.workeroutput``, which xdist carries to ``pytest_testnodedown``); the controller writes
    the file from all of them. A module fixture or session fixture set up in more than one worker keeps its
    longest set-up (a session fixture's waiting for another worker's build is no test's cost)."""

    def __init__(self, path: Path, config=None) -> None:
        self.path = path
        self.config = config
        self.workers: list[dict] = []  # the records the xdist workers sent (in the controller)
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
        if self.item_id is not None:  # a test this process runs (xdist's controller sees the workers' reports)
            self.tests[report.nodeid] += report.duration

    def own(self) -> dict[str, dict[str, float]]:
        """This process's record: ``tests`` (own seconds), ``fixtures`` and ``session`` (set-up seconds)."""
        return {"tests": {n: round(max(s - self.shared[n], 0.0), 3) for n, s in self.tests.items()},
                "fixtures": {k: round(s, 3) for k, s in self.fixtures.items()},
                "session": {k: round(s, 3) for k, s in self.session.items()}}

    def pytest_sessionfinish(self, session, exitstatus) -> None:
        """Write the record: a test or fixture that ran replaces its entry, the others keep theirs (a run of some
        modules updates those; a full run updates all, and a test no longer collected keeps its entry, which
        only over-counts the fast loop's bound). An xdist worker sends its record to the controller instead."""
        config = self.config
        if config is not None and hasattr(config, "workerinput"):
            config.workeroutput[WORKER_OUTPUT] = self.own()
            return
        record = load(self.path)
        record["command"] = ".venv/bin/python -m pytest -q -n 2 --record-durations tests/durations.json"
        merged = self.own()
        for worker in self.workers:
            for table in ("tests", "fixtures", "session"):
                for key, seconds in worker[table].items():
                    merged[table][key] = max(seconds, merged[table].get(key, 0.0))
        for table in ("tests", "fixtures", "session"):
            record[table].update(merged[table])
        for table in ("tests", "fixtures", "session"):
            record[table] = dict(sorted(record[table].items()))
        self.path.write_text(json.dumps(record, indent=0) + "\n", encoding="utf-8")


class XdistDurations:
    """The controller's half of ``DurationRecorder`` under pytest-xdist: each worker's record as it ends."""

    def __init__(self, recorder: DurationRecorder) -> None:
        self.recorder = recorder

    def pytest_testnodedown(self, node, error) -> None:
        record = getattr(node, "workeroutput", {}).get(WORKER_OUTPUT)
        if record is not None:
            self.recorder.workers.append(record)
