"""`cam-fmu bench train` (tools/bench/train.py): the train's cost is measured on runs that differ by the train alone,
and what it reports is consistent: the train's run takes more internal steps than the rigid one (it resolves the
50 Hz ringing), its ratios are the quotients of the figures reported beside them. No time is asserted."""
from __future__ import annotations

import csv
from types import SimpleNamespace

import pytest

from cam_fmu.tools.bench import BENCHMARKS, train


def test_the_train_benchmark_reports_consistent_ratios(tmp_path):
    said: list[str] = []
    ctx = SimpleNamespace(quick=True, out=tmp_path, say=said.append)
    assert BENCHMARKS["train"][0] == "train" and train.run(ctx) == 0
    rows = list(csv.DictReader(open(tmp_path / "train.csv", encoding="utf-8")))
    assert [r["setting"] for r in rows] == list(train.SETTINGS) and len(said) == len(rows)
    for r in rows:
        n_rigid, n_train = int(r["rigid_steps"]), int(r["train_steps"])
        assert n_train > n_rigid > 0
        t_rigid, t_train = float(r["rigid_ms"]), float(r["train_ms"])
        assert float(r["run_ratio"]) == pytest.approx(t_train / t_rigid, rel=1e-12)
        assert float(r["step_ratio"]) == pytest.approx((t_train / n_train) / (t_rigid / n_rigid), rel=1e-12)
    speed = rows[-1]
    assert int(speed["rigid_steps"]) == round(train.STOP / train.STEP)   # the rigid speed drive: one per step
