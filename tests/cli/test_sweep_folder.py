"""A sweep's folder holds every case once: one writer at a time (the lock), parts that overlap repaired only when
provably identical and refused otherwise, the dataset folder of part files only (pyarrow and pandas read it),
the earlier layout still read and moved on --resume.

Sweeps run on the C engine in child processes (`cam-fmu sweep`), as users run them."""
from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cam_fmu.experiments.sweep_cases import SweepError
from cam_fmu.experiments.sweep_lock import hold
from cam_fmu.experiments.sweep_store import iter_rows, parts, repair
from cli_run import cli, csv_rows, env

SMALL = ["sweep", "paper_fig6", "--vary", "m=0.2:0.8:12", "--metric", "peak_M,final_omega", "--stop-time", "0.2",
         "--serial", "--batch-size", "4", "--no-plot"]


def _names(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def _one_line(proc: subprocess.CompletedProcess) -> str:
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    return lines[0]


@pytest.fixture(scope="module")
def small(tmp_path_factory) -> Path:
    """A finished sweep of 12 cases in parts of 4 (its output folder); tests copy it."""
    out = tmp_path_factory.mktemp("small") / "out"
    cli(*SMALL, "--out", str(out), cwd=out.parent)
    return out


def _copy(src: Path, dest: Path) -> Path:
    import shutil

    shutil.copytree(src, dest)
    return dest


# ------------------------------------------------------------------ the layout
@pytest.mark.slow
def test_the_dataset_folder_holds_part_files_only_and_reads_as_one_table(small):
    """The specification sits beside the dataset, the lock is gone after the run: pyarrow and pandas read the
    folder as it is (the read failed on sweep.json inside it), and equal the CSV, which carries the case index."""
    import pandas
    import pyarrow.parquet as pq

    folder = small / "paper_fig6_sweep.parquet"
    assert _names(small) == ["paper_fig6_sweep.csv", "paper_fig6_sweep.json", "paper_fig6_sweep.parquet"]
    assert _names(folder) == [f"part-{a:010d}-{a + 4:010d}.parquet" for a in (0, 4, 8)]
    spec = json.loads((small / "paper_fig6_sweep.json").read_text())
    assert spec["cases"] == 12 and spec["batch_size"] == 4 and spec["command"] == "sweep"
    table = pq.read_table(folder).sort_by("case")
    frame = pandas.read_parquet(folder).sort_values("case")
    rows = csv_rows(small / "paper_fig6_sweep.csv")
    assert rows[0] == ["case", "m [kg]", "peak_M [N.m]", "final_omega [rad/s]", "status", "message"]
    assert table.column_names == rows[0] and list(frame.columns) == rows[0]
    assert table["case"].to_pylist() == list(frame["case"]) == [int(r[0]) for r in rows[1:]] == list(range(1, 13))
    assert [repr(x) for x in table["peak_M [N.m]"].to_pylist()] == [r[2] for r in rows[1:]]
    assert [repr(float(x)) for x in frame["final_omega [rad/s]"]] == [r[3] for r in rows[1:]]


@pytest.mark.slow
def test_a_folder_of_the_earlier_layout_is_read_and_resumed_with_its_specification_moved_beside(small, tmp_path):
    """sweep.json inside the dataset folder (the layout before): the rows still read, a fresh run still refuses
    to write over it, and --resume runs the missing cases and moves the file out, after which pyarrow reads it."""
    import pyarrow.parquet as pq

    out = _copy(small, tmp_path / "out")
    folder = out / "paper_fig6_sweep.parquet"
    (out / "paper_fig6_sweep.json").rename(folder / "sweep.json")
    (folder / "part-0000000008-0000000012.parquet").unlink()
    assert [r["case"] for r in iter_rows(folder)] == list(range(1, 9))
    with pytest.raises(Exception, match="sweep.json"):
        pq.read_table(folder)
    fresh = cli(*SMALL, "--out", str(out), cwd=tmp_path, check=2)
    assert "holds an earlier sweep" in _one_line(fresh)
    again = cli(*SMALL, "--out", str(out), "--resume", cwd=tmp_path)
    assert "12 cases (4 to run)" in again.stderr
    assert _names(folder) == [f"part-{a:010d}-{a + 4:010d}.parquet" for a in (0, 4, 8)]
    assert json.loads((out / "paper_fig6_sweep.json").read_text())["cases"] == 12
    assert (out / "paper_fig6_sweep.csv").read_text() == (small / "paper_fig6_sweep.csv").read_text()
    assert pq.read_table(folder).num_rows == 12


# ------------------------------------------------------------------ one writer
def test_the_lock_has_one_holder_names_it_and_is_free_once_it_lets_go(tmp_path):
    """In this process: a second hold of a held lock is refused naming the holder; the file goes with the holder;
    a file left behind (a holder killed) holds nothing; a folder made for a refused lock does not stay."""
    lock, folder = tmp_path / "out" / "s_sweep.lock", tmp_path / "out" / "s_sweep.parquet"
    with hold(lock, folder):
        info = json.loads(lock.read_text())
        assert info["pid"] == os.getpid() and info["host"] == socket.gethostname()
        with pytest.raises(SweepError) as refused:
            with hold(lock, folder):
                pass
        assert str(refused.value) == (f"--out: {folder} is being written by another sweep, pid {os.getpid()} on host "
                                      f"{socket.gethostname()} since {info['started']} (lock {lock}): one sweep "
                                      "writes a folder at a time; wait for it to end or stop it")
    assert not lock.exists() and not lock.parent.exists()  # the folder was made for the lock alone
    lock.parent.mkdir()
    lock.write_text(json.dumps({"pid": 1, "host": "elsewhere", "started": "2026-01-01T00:00:00Z"}))
    with hold(lock, folder):
        assert json.loads(lock.read_text())["pid"] == os.getpid()
    assert not lock.exists() and lock.parent.is_dir()


@pytest.mark.slow
def test_a_held_lock_refuses_a_second_sweep_naming_its_holder_and_changes_nothing(small, tmp_path):
    """This process holds the folder's lock: --resume and --overwrite (which would delete the holder's files) are
    refused on one line naming the holder's pid, host and start time; once it lets go, the resume runs."""
    out = _copy(small, tmp_path / "out")
    folder = out / "paper_fig6_sweep.parquet"
    (folder / "part-0000000004-0000000008.parquet").unlink()
    before = _names(folder)
    lock = out / "paper_fig6_sweep.lock"
    with hold(lock, folder):
        info = json.loads(lock.read_text())
        for option in ("--resume", "--overwrite"):
            line = _one_line(cli(*SMALL, "--out", str(out), option, cwd=tmp_path, check=2))
            assert line == (f"cam-fmu sweep: error: --out: {folder} is being written by another sweep, pid "
                            f"{os.getpid()} on host {socket.gethostname()} since {info['started']} (lock {lock}): "
                            "one sweep writes a folder at a time; wait for it to end or stop it")
            assert _names(folder) == before
    assert not lock.exists()
    again = cli(*SMALL, "--out", str(out), "--resume", cwd=tmp_path)
    assert "12 cases (4 to run)" in again.stderr and not lock.exists()
    assert (out / "paper_fig6_sweep.csv").read_text() == (small / "paper_fig6_sweep.csv").read_text()


@pytest.mark.slow
def test_a_lock_file_no_process_holds_does_not_stop_a_sweep(small, tmp_path):
    """A lock file left by a holder that died (its pid gone on this host), and one naming a live pid (this
    process: a pid reused) that holds no lock: the operating system's lock is free, so the resume runs."""
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    with pytest.raises(ProcessLookupError):
        os.kill(dead.pid, 0)  # gone on this host
    for pid in (dead.pid, os.getpid()):
        out = _copy(small, tmp_path / f"out{pid}")
        (out / "paper_fig6_sweep.parquet" / "part-0000000000-0000000004.parquet").unlink()
        lock = out / "paper_fig6_sweep.lock"
        lock.write_text(json.dumps({"pid": pid, "host": socket.gethostname(), "started": "2026-01-01T00:00:00Z"}))
        again = cli(*SMALL, "--out", str(out), "--resume", cwd=tmp_path)
        assert "12 cases (4 to run)" in again.stderr and not lock.exists()
        assert (out / "paper_fig6_sweep.csv").read_text() == (small / "paper_fig6_sweep.csv").read_text()


# ------------------------------------------------------------------ parts that overlap
def _stray(folder: Path, first: int, end: int, change=None, name: str | None = None) -> Path:
    """A part holding the rows of cases first+1..end as the folder's parts hold them (optionally changed), named
    for those cases or ``name``."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    pieces = []
    for start, stop, path in parts(folder):
        if start < end and first < stop:
            lo, hi = max(first, start), min(end, stop)
            pieces.append(pq.read_table(path).slice(lo - start, hi - lo))
    table = pa.concat_tables(pieces)
    if change:
        table = change(table)
    path = folder / (name or f"part-{first:010d}-{end:010d}.parquet")
    pq.write_table(table, path)
    return path


@pytest.mark.slow
def test_a_stray_part_that_repeats_cases_with_the_same_bits_is_removed_by_resume(small, tmp_path):
    """A stray part holding cases 5 and 6 again, as part 4-8 holds them: reading refuses the folder (a case
    twice), --resume removes the stray, says so, runs nothing ("0 to run", never a negative count) and exits 0
    with every case once."""
    out = _copy(small, tmp_path / "out")
    folder = out / "paper_fig6_sweep.parquet"
    stray = _stray(folder, 4, 6)
    with pytest.raises(SweepError, match=r"holds cases 5 to 6 twice, in part-0000000004-0000000006.parquet and "
                                         r"part-0000000004-0000000008.parquet"):
        list(iter_rows(folder))
    again = cli(*SMALL, "--out", str(out), "--resume", cwd=tmp_path)
    assert ("# paper_fig6: removed part-0000000004-0000000006.parquet: its cases 5 to 6 are in "
            "part-0000000004-0000000008.parquet with the same bits") in again.stderr
    assert "12 cases (0 to run)" in again.stderr and "12 of 12 on disk" in again.stderr
    assert not stray.exists() and [r["case"] for r in iter_rows(folder)] == list(range(1, 13))
    assert (out / "paper_fig6_sweep.csv").read_text() == (small / "paper_fig6_sweep.csv").read_text()


def _bump(table):
    """The table with its first peak_M one unit in the last place larger."""
    import math

    import pyarrow as pa

    values = table["peak_M [N.m]"].to_pylist()
    values[0] = math.nextafter(values[0], math.inf)
    return table.set_column(table.schema.get_field_index("peak_M [N.m]"), table.schema.field("peak_M [N.m]"),
                            pa.array(values, pa.float64()))


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["different bits", "crossing", "beyond the cases", "renamed", "swapped",
                                  "not a part"])
def test_overlapping_or_foreign_files_are_refused_and_nothing_is_removed(small, tmp_path, kind):
    """A copy that differs in one bit, a part crossing two others, a part past the case count, a part whose rows
    are not the cases its name says, and a file that is no part: --resume refuses on one line (exit 2), names the
    file and leaves every file in place."""
    out = _copy(small, tmp_path / "out")
    folder = out / "paper_fig6_sweep.parquet"
    if kind == "different bits":
        _stray(folder, 4, 6, _bump)
        words = "holds cases 5 to 6 twice, in part-0000000004-0000000008.parquet and " \
                "part-0000000004-0000000006.parquet, with different values"
    elif kind == "crossing":
        _stray(folder, 6, 10)  # cases 7..10, as parts 4-8 and 8-12 hold them
        words = "holds cases 7 to 8 twice, in part-0000000004-0000000008.parquet and part-0000000006-0000000010"
    elif kind == "beyond the cases":
        _stray(folder, 8, 12, name="part-0000000012-0000000016.parquet")
        words = "holds cases 13 to 16, beyond this sweep's 12: not a part of it"
    elif kind == "renamed":  # cases 9..12 under the name of 5..6, which part 4-8 holds
        (folder / "part-0000000008-0000000012.parquet").rename(folder / "part-0000000004-0000000006.parquet")
        words = "part-0000000004-0000000006.parquet is named for cases 5 to 6 but holds 4 rows of cases 9 to 12"
    elif kind == "swapped":  # two parts' names exchanged: no overlap by name, but not the cases they say
        (folder / "part-0000000000-0000000004.parquet").rename(folder / "x")
        (folder / "part-0000000008-0000000012.parquet").rename(folder / "part-0000000000-0000000004.parquet")
        (folder / "x").rename(folder / "part-0000000008-0000000012.parquet")
        words = "part-0000000000-0000000004.parquet is named for cases 1 to 4 but holds 4 rows of cases 9 to 12"
    else:
        (folder / "notes.txt").write_text("mine\n")
        words = "holds notes.txt, not a part file"
    before = _names(folder)
    line = _one_line(cli(*SMALL, "--out", str(out), "--resume", cwd=tmp_path, check=2))
    assert line.startswith("cam-fmu sweep: error: --resume: ") and words in line, line
    assert _names(folder) == before


# ------------------------------------------------------------------ the run
@pytest.mark.slow
def test_a_resume_started_while_a_sweep_runs_is_refused_and_the_folder_never_holds_a_case_twice(tmp_path):
    """Issue 39: a serial sweep (120 cases, batches of 25) runs; a --resume of the same folder starts while it runs
    (the first is held still by SIGSTOP while the second tries, so the order is certain); then the first is
    interrupted (SIGINT to its group, Ctrl-C) in the middle of a batch. Before the lock the resume ran the batch
    the first was in too (measured with 240 cases in batches of 50: part-150-186 beside part-150-200, 276 rows,
    then "-36 to run ... 276 of 240 on disk" and exit 0). Now the second is refused naming the first, and a last
    --resume completes the table: every case once, equal to an uninterrupted run's."""
    args = ["sweep", "paper_fig6", "--vary", "m=0.2:0.8:120", "--metric", "peak_M,final_omega", "--stop-time", "2",
            "--serial", "--batch-size", "25", "--no-plot"]
    whole = tmp_path / "whole"
    cli(*args, "--out", str(whole), cwd=tmp_path)
    out = tmp_path / "out"
    folder = out / "paper_fig6_sweep.parquet"
    err = tmp_path / "first.err"
    with open(err, "w") as fh:
        first = subprocess.Popen([sys.executable, "-m", "cam_fmu.cli", *args, "--out", str(out)], env=env(),
                                 cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=fh, start_new_session=True)
    try:
        while first.poll() is None and len(list(folder.glob("part-*.parquet"))) < 2:
            time.sleep(0.005)
        os.killpg(first.pid, signal.SIGSTOP)
        assert first.poll() is None, err.read_text()  # still running: 50 of 120 cases on disk at least
        before = _names(folder)
        second = cli(*args, "--out", str(out), "--resume", cwd=tmp_path, check=2)
        line = _one_line(second)
        started = re.search(r"since (\S+) \(lock", line)
        assert f"is being written by another sweep, pid {first.pid} on host {socket.gethostname()}" in line, line
        assert started and re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", started[1])
        assert _names(folder) == before
        os.killpg(first.pid, signal.SIGINT)
        os.killpg(first.pid, signal.SIGCONT)
        assert first.wait(timeout=600) == 130, err.read_text()
    finally:
        if first.poll() is None:
            os.killpg(first.pid, signal.SIGKILL)
            first.wait()
    kept = int(err.read_text().strip().splitlines()[-1].split("interrupted: ")[1].split(" of ")[0])
    assert 50 <= kept < 120 and not (out / "paper_fig6_sweep.lock").exists()
    last = cli(*args, "--out", str(out), "--resume", cwd=tmp_path)
    assert f"120 cases ({120 - kept} to run)" in last.stderr and "120 of 120 on disk" in last.stderr
    held = [(a, b) for a, b, _ in parts(folder, 120)]  # disjoint, or parts() refuses
    assert sum(b - a for a, b in held) == 120 and held[0][0] == 0 and held[-1][1] == 120
    assert [r["case"] for r in iter_rows(folder)] == list(range(1, 121))
    assert (out / "paper_fig6_sweep.csv").read_text() == (whole / "paper_fig6_sweep.csv").read_text()
    assert repair(folder, 120) == (parts(folder, 120), [])  # nothing left to repair
