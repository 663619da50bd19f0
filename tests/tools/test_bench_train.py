"""`cam-fmu bench train` and `cam-fmu bench kinds` (tools/bench/train.py, kinds.py over variants.py): each feature
is measured on runs that differ by it alone, and what is reported is consistent: the train's run takes more
internal steps than the rigid one (it resolves the 50 Hz ringing), every ratio is the quotient of the figures
reported beside it. No time is asserted."""
from __future__ import annotations

import csv
from types import SimpleNamespace

import pytest

from cam_fmu.tools.bench import BENCHMARKS, kinds, train


@pytest.mark.parametrize("module, name", [(train, "train"), (kinds, "kinds")])
def test_the_feature_benchmarks_report_consistent_ratios(tmp_path, module, name):
    said: list[str] = []
    ctx = SimpleNamespace(quick=True, out=tmp_path, say=said.append)
    assert BENCHMARKS[name][0] == name and module.run(ctx) == 0
    rows = list(csv.DictReader(open(tmp_path / f"{name}.csv", encoding="utf-8")))
    labels = list(train.SETTINGS if module is train else kinds.KINDS)
    assert [r["setting"] for r in rows] == labels and len(said) == len(rows)
    for r in rows:
        n_base, n_variant = int(r["base_steps"]), int(r["variant_steps"])
        assert n_base > 0 and n_variant > 0
        if module is train:
            assert n_variant > n_base
        t_base, t_variant = float(r["base_ms"]), float(r["variant_ms"])
        assert float(r["run_ratio"]) == pytest.approx(t_variant / t_base, rel=1e-12)
        assert float(r["step_ratio"]) == pytest.approx((t_variant / n_variant) / (t_base / n_base), rel=1e-12)
    if module is train:
        assert int(rows[-1]["base_steps"]) == round(train.STOP / train.STEP)   # the rigid speed drive: one a step
