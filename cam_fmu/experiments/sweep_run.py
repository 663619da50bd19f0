"""A sweep's cases in batches, serial or on dask.distributed, each finished batch written at once to Parquet.

The table is a Parquet dataset, ``DIR/<scene>_sweep.parquet/``, of part files only, its specification beside it
in ``DIR/<scene>_sweep.json`` (scene, options, the engine's build, the batch size): sweep_store.py. One file
per finished batch, ``part-<first>-<end>.parquet`` holding the cases of index first..end-1 (column ``case``:
index + 1), the varied values, the metrics (headers with units), ``status`` and ``message``. A file appears
whole or not at all (written under a temporary name, then renamed), so whatever stops the driver (Ctrl-C,
kill -9, a lost machine) leaves only finished cases on disk; ``resume=True`` runs the cases no file holds, with
the stored batch size, and refuses a folder whose specification differs. Every case's row depends on the case
alone, so the table (sorted by case) equals an uninterrupted run's bit for bit. One sweep writes a folder at a
time (sweep_lock.py), and a resume repairs or refuses parts that hold a case twice (sweep_store.repair).

Memory stays bounded: the driver holds at most ``2 x workers + 1`` batches in flight (their values and rows),
never the case list or the table; dask's message logs keep LOG_LENGTH messages a stream, not 1000. The batch
size is chosen from a pilot case timed in the driver: about
BATCH_SECONDS of work a batch (dask's per-task cost, a few ms, is then under 1 %), at least 4 batches a
worker (the last batches balance), at most MAX_BATCH cases.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator, Sequence

from .interrupts import InterruptFlag, environment, quiet, sigint_ignored
from .sweep import Design, SweepError, header, run_batch, run_case
from .sweep_lock import hold
from .sweep_store import (cases_on_disk, dataset_path, entries, lock_path, read_spec, repair, spec_path, write_part,
                          write_spec)

BATCH_SECONDS = 1.0  # s of work per batch
MAX_BATCH = 50_000
# dask.distributed keeps the last ``distributed.admin.low-level-log-length`` (default 1000) messages of every
# batched stream for debugging, each under 1 MB kept whole: the scheduler's stream to a worker holds the
# batches' tasks (their values), the client's to the scheduler the same, so the driver (the local scheduler's
# process) grew by a batch's values per batch until 1000 a stream. A short log bounds that to a few batches.
LOG_LENGTH = 8
FORMAT = 1  # of the part files and the specification (sweep_store.py)


@dataclass
class Plan:
    """What to run: the scene (its reference, sent to the workers; ``scene`` the loaded Scene), the cases, the
    metrics, the engine ('engine' or 'fmu' with ``fmu`` a file) and the stop time override."""

    scene_ref: str
    scene: Any
    design: Design
    metrics: Sequence[str]
    engine: str = "engine"
    fmu: str | None = None
    stop_time: float | None = None

    def job(self, start: int, stop: int) -> dict:
        return {"scene_ref": self.scene_ref, "stop_time": self.stop_time, "metrics": tuple(self.metrics),
                "engine": self.engine, "fmu": self.fmu, "start": start, "values": self.design.values(start, stop)}

    def spec(self) -> dict:
        """JSON: what makes the table (compared on resume); the batch size is added by the run."""
        if self.engine == "engine":  # the C sources the library is built from
            csrc = Path(__file__).resolve().parents[1] / "engine" / "csrc"
            digest = hashlib.sha256()
            for path in sorted([*csrc.glob("src/*.c"), *csrc.glob("include/*.h")]):
                digest.update(path.name.encode() + path.read_bytes())
            build_id = digest.hexdigest()[:16]
        else:
            build_id = hashlib.sha256(Path(self.fmu).read_bytes()).hexdigest()[:16]  # type: ignore[arg-type]
        scene_file = self.scene.path
        return {"command": "sweep", "format": FORMAT, "scene": self.scene.name,
                "scene_sha256": hashlib.sha256(Path(scene_file).read_bytes()).hexdigest()[:16] if scene_file else None,
                "stop_time": self.scene.stop_time, **self.design.spec(), "metrics": list(self.metrics),
                "engine": self.engine, "engine_build": build_id, "cases": len(self.design)}


@dataclass
class Summary:
    total: int
    done: int  # cases on disk at the end
    failed: int  # failed cases run by this call
    ran: int  # cases run by this call
    seconds: float
    batch_size: int
    workers: int
    interrupted: bool = False


# ------------------------------------------------------------------ the files
def _schema(plan: Plan, spec: dict):
    import pyarrow as pa

    fields = [pa.field("case", pa.int64())]
    for v in plan.design.varies:
        fields.append(pa.field(header(v.name), pa.float64() if v.numeric else pa.string()))
    fields += [pa.field(header(m), pa.float64()) for m in plan.metrics]
    fields += [pa.field("status", pa.string()), pa.field("message", pa.string())]
    return pa.schema(fields, metadata={"cam_fmu.sweep": json.dumps(spec, sort_keys=True)})


def prepare(plan: Plan, out: str | Path, resume: bool, overwrite: bool) -> tuple[Path, dict, list, list[str]]:
    """The dataset's folder, the stored specification, the parts on disk and a line per repair (run under the
    folder's lock); refuses before any case runs (SweepError naming the option) a resume of a folder made by
    another command, scene or options, a resume of a folder whose parts hold a case twice other than as
    identical copies (sweep_store.repair), and a fresh run over an earlier sweep."""
    folder = dataset_path(out, plan.scene.name)
    spec = plan.spec()
    if resume:
        stored = read_spec(folder)
        if stored is None:
            what = f"holds no sweep (no {spec_path(folder).name} beside it)" if folder.is_dir() else "does not exist"
            raise SweepError(f"--resume: {folder} {what}: nothing to continue")
        if stored.get("command") != "sweep":
            raise SweepError(f"--resume: {folder} was made by the command {stored.get('command')!r}, not sweep")
        for key, value in spec.items():
            if stored.get(key) != value:
                raise SweepError(f"--resume: {folder} was made with {key} = {stored.get(key)!r}, this sweep has "
                                 f"{key} = {value!r}: a resume continues the same sweep only")
        for tmp in folder.glob(".part-*.tmp"):  # a write cut short: that batch runs again
            tmp.unlink()
        try:
            done, notes = repair(folder, len(plan.design))
        except SweepError as exc:
            raise SweepError(f"--resume: {exc}") from None
        return folder, stored, done, notes
    held = entries(folder)
    if held or read_spec(folder) is not None:
        if not overwrite:
            raise SweepError(f"--out: {folder} holds an earlier sweep ({len(held)} part files): --resume continues "
                             "it, --overwrite starts again")
    if folder.exists():
        import shutil

        shutil.rmtree(folder)
    spec_path(folder).unlink(missing_ok=True)
    return folder, spec, [], []


def _todo(n: int, batch: int, done: list[tuple[int, int, Path]]) -> Iterator[tuple[int, int]]:
    """The ranges (start, stop) to run: each batch's cases that no file holds (``done``: disjoint, in order)."""
    k = 0
    for start in range(0, n, batch):
        stop = min(n, start + batch)
        cursor = start
        while k < len(done) and done[k][1] <= cursor:
            k += 1
        j = k
        while j < len(done) and done[j][0] < stop:
            if done[j][0] > cursor:
                yield cursor, done[j][0]
            cursor = max(cursor, done[j][1])
            j += 1
        if cursor < stop:
            yield cursor, stop


# ------------------------------------------------------------------ the run
def choose_batch_size(case_seconds: float, cases: int, workers: int) -> int:
    """About BATCH_SECONDS of work a batch, at least 4 batches a worker, between 1 and MAX_BATCH cases."""
    by_time = math.ceil(BATCH_SECONDS / max(case_seconds, 1e-6))
    by_balance = math.ceil(cases / (4 * max(1, workers)))
    return max(1, min(by_time, by_balance, MAX_BATCH))


def pilot_seconds(plan: Plan) -> float:
    """Seconds of case 0, run twice in this process (the second timed: the engine loaded, the FMU extracted)."""
    values = plan.design.values(0, 1)
    case = {name: vals[0] for name, vals in values.items()}
    run_case(plan.scene_ref, case, plan.metrics, plan.engine, plan.fmu, plan.stop_time)
    t0 = time.perf_counter()
    run_case(plan.scene_ref, case, plan.metrics, plan.engine, plan.fmu, plan.stop_time)
    return time.perf_counter() - t0


def run_sweep(plan: Plan, out: str | Path, workers: int | None = None, scheduler: str | None = None,
              serial: bool = False, resume: bool = False, overwrite: bool = False, batch_size: int | None = None,
              progress: Callable[[int, int, int], None] | None = None,
              started: Callable[[str, int, int], None] | None = None,
              notes: Callable[[str], None] | None = None, locked: bool = False) -> Summary:
    """Run every case not on disk yet; ``progress(done, total, failed)`` after each case (serial) or batch;
    ``started(where, batch size, cases to run)`` once the engine is up; ``notes(line)`` for each repair of the
    folder (sweep_store.repair). An interrupt (SIGINT) stops the run with every finished batch written (serial:
    the cases finished in the current batch too). The folder's lock (sweep_lock.hold) is held for the run;
    ``locked``: the caller holds it already."""
    if batch_size is not None and batch_size < 1:
        raise SweepError(f"--batch-size {batch_size}: allowed >= 1")
    folder = dataset_path(out, plan.scene.name)
    with contextlib.ExitStack() as lock:
        if not locked:
            lock.enter_context(hold(lock_path(folder), folder))
        return _run_locked(plan, out, workers, scheduler, serial, resume, overwrite, batch_size, progress, started,
                           notes)


def _run_locked(plan: Plan, out, workers, scheduler, serial, resume, overwrite, batch_size, progress, started,
                notes) -> Summary:
    folder, spec, done, repaired = prepare(plan, out, resume, overwrite)
    for line in repaired:
        if notes:
            notes(line)
    n = len(plan.design)
    t0 = time.perf_counter()
    on_disk = cases_on_disk(done)  # disjoint parts within the n cases (sweep_store.parts): 0 <= on_disk <= n
    logs = contextlib.ExitStack()
    if serial:
        n_workers, client, cluster = 1, None, None
    else:
        import dask

        logs.enter_context(dask.config.set({"distributed.admin.low-level-log-length": LOG_LENGTH}))
        try:
            client, cluster = _client(workers, scheduler)
            n_workers = max(1, len(client.scheduler_info()["workers"]))
        except BaseException:
            logs.close()
            raise
    try:
        if "batch_size" not in spec:
            spec["batch_size"] = batch_size or choose_batch_size(pilot_seconds(plan), n, n_workers)
        folder.mkdir(parents=True, exist_ok=True)
        write_spec(folder, spec)
        schema = _schema(plan, {k: v for k, v in spec.items() if k != "batch_size"})
        todo = _todo(n, spec["batch_size"], done)
        where = "serial" if serial else (scheduler or f"local cluster of {n_workers} workers")
        if started:
            started(where, spec["batch_size"], n - on_disk)
        counts = [on_disk, 0, 0]  # on disk, failed, ran
        if serial:
            interrupted = _serial(plan, folder, schema, todo, counts, n, progress)
        else:
            interrupted = _distributed(plan, client, n_workers, folder, schema, todo, counts, n, progress)
    finally:
        if client is not None:
            with sigint_ignored(), quiet("distributed"):  # shutting down after an interrupt: no noise
                client.close()
                if cluster is not None:
                    cluster.close()
        logs.close()
    return Summary(n, counts[0], counts[1], counts[2], time.perf_counter() - t0, spec["batch_size"], n_workers,
                   interrupted)


def _serial(plan: Plan, folder: Path, schema, todo, counts: list, n: int, progress) -> bool:
    """Batch after batch in this process; a Ctrl-C (KeyboardInterrupt) stops after writing the current batch's
    finished cases, and one during a write waits for the write to end (a flag, not an exception)."""
    for start, stop in todo:
        columns: dict[str, list] = {"case": []}
        interrupted = False
        try:
            job = plan.job(start, stop)
            names = list(job["values"])
            columns.update({k: [] for k in names}, **{m: [] for m in plan.metrics}, status=[], message=[])
            for k in range(stop - start):
                case = {name: job["values"][name][k] for name in names}
                row = run_case(plan.scene_ref, case, plan.metrics, plan.engine, plan.fmu, plan.stop_time)
                for key in columns:
                    columns[key].append(start + k + 1 if key == "case" else row[key])
                counts[1] += row["status"] == "failed"
                counts[2] += 1
                if progress:
                    progress(counts[0] + k + 1, n, counts[1])
        except KeyboardInterrupt:
            interrupted = True
            kept = min(len(values) for values in columns.values())  # a row cut short between two columns
            for values in columns.values():
                del values[kept:]
        flag = InterruptFlag()
        try:
            if columns["case"]:
                write_part(folder, schema, columns)
                counts[0] += len(columns["case"])
        finally:
            flag.restore()
        if interrupted or flag.is_set():
            return True
    return False


def _client(workers: int | None, scheduler: str | None):
    from distributed import Client, LocalCluster

    # The worker processes ignore a Ctrl-C to the process group (sigint_ignored) and log errors only: closing the
    # cluster after an interrupt cancels the batches they run, which each would report as a warning.
    with sigint_ignored(), environment(DASK_LOGGING__DISTRIBUTED="error"):
        if scheduler:
            return Client(scheduler, timeout="30s"), None
        n = workers or os.cpu_count() or 1
        if n < 1:
            raise SweepError(f"--workers {n}: allowed >= 1")
        # no dashboard; the scheduler's own HTTP server on a free port (its default, 8787, may be taken by
        # another cluster on the machine: distributed then warns on stderr)
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                               host="127.0.0.1", scheduler_kwargs={"dashboard_address": "127.0.0.1:0"})
        return Client(cluster), cluster


def _distributed(plan: Plan, client, n_workers: int, folder: Path, schema, todo, counts: list, n: int,
                 progress) -> bool:
    from distributed import as_completed

    window = 2 * n_workers + 1
    tag = uuid.uuid4().hex[:8]
    finished = as_completed()
    in_flight = 0

    def submit() -> bool:
        nonlocal in_flight
        for start, stop in todo:
            finished.add(client.submit(run_batch, plan.job(start, stop), pure=False, key=f"sweep-{tag}-{start}"))
            in_flight += 1
            return True
        return False

    stop = InterruptFlag()  # Ctrl-C sets a flag: a KeyboardInterrupt inside the client's calls left dask's
    try:                      # event loop logging tracebacks (a cancelled sync, the workers' heartbeats)
        while in_flight < window and submit():
            pass
        while in_flight and not stop.is_set():
            batch = finished.next_batch(block=False)
            if not batch:
                stop.wait(0.02)
            for future in batch:
                columns = future.result()
                in_flight -= 1
                write_part(folder, schema, columns)
                counts[0] += len(columns["case"])
                counts[1] += sum(s == "failed" for s in columns["status"])
                counts[2] += len(columns["case"])
                if progress:
                    progress(counts[0], n, counts[1])
                submit()
        return stop.is_set()
    except KeyboardInterrupt:  # before the flag's handler was in place
        return True
    finally:
        stop.restore()
