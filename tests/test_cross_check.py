"""The FMI Cross-Check package (`cam-fmu cross-check DIR`): fmpy's own cross-check validation of each model
folder, a fresh run of each FMU against its `_ref.csv` with fmpy's `validate_signal`, and the same check failing
on a reference that is off (so it can fail) and on a run without the input (so the input is used)."""
from __future__ import annotations

import shutil
import subprocess
import sys

import numpy as np
import pytest
from fmpy.cross_check.validate_vendor_repo import read_csv, validate_test_fmu
from fmpy.util import validate_signal

from cam_fmu.tools.cross_check import OUTPUTS, simulate


@pytest.fixture(scope="module")
def package(engine_fmu_path, tmp_path_factory):
    from conftest import _build_fmu

    folder = tmp_path_factory.mktemp("cross_check")
    cam3 = _build_fmu(folder / "build" / "cam3.fmu", "cam3")
    done = subprocess.run([sys.executable, "-m", "cam_fmu", "cross-check", str(folder / "repo"), "--fmu",
                           str(engine_fmu_path), "--fmu", str(cam3)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    models = sorted((folder / "repo" / "fmus").glob("*/*/*/cam_fmu/*/cam"))
    return folder, models


def _outside(model, result, column: str) -> int:
    ref = read_csv(str(model / "cam_ref.csv"))
    t_ref, y_ref = np.array(ref["time"]), np.array(ref[column])
    t, y = np.array(result["time"], dtype=float), np.array(result[column], dtype=float)  # plain arrays, not fmpy results
    _, _, _, outside = validate_signal(t, y, t_ref, y_ref)
    return int(np.count_nonzero(outside))


def test_every_fmi_version_and_interface_gets_its_folder_and_fmpy_finds_no_problem(package):
    _, models = package
    kinds = sorted("/".join(m.parts[-6:-3]) for m in models)
    assert kinds == ["2.0/cs/linux64", "3.0/cs/x86_64-linux"]
    for model in models:
        assert validate_test_fmu(str(model)) == []
        for name in ("cam.fmu", "cam_in.csv", "cam_ref.csv", "cam_ref.opt", "ReadMe.md", "validation.txt"):
            assert (model / name).is_file(), (model, name)
        assert "no problems" in (model / "validation.txt").read_text()


def test_a_fresh_run_of_each_fmu_lies_within_its_reference(package):
    _, models = package
    for model in models:
        kind = model.parts[-5]
        result = simulate(model / "cam.fmu", kind)
        for column in OUTPUTS:
            assert _outside(model, result, column) == 0, (model, column)


def test_the_check_fails_a_shifted_reference_and_a_run_without_the_input(package, tmp_path):
    _, models = package
    model = tmp_path / "cam"
    shutil.copytree(models[0], model)
    ref = read_csv(str(model / "cam_ref.csv"))
    shifted = -np.array(ref["omega"])  # a sign error (fmpy's band is 10 % of the range wide: a scale error of 20 % hides in it)
    lines = (model / "cam_ref.csv").read_text().splitlines()
    header = lines[0].split(",")
    k = [h.strip('"') for h in header].index("omega")
    rows = [line.split(",") for line in lines[1:]]
    for row, value in zip(rows, shifted):
        row[k] = repr(float(value))
    (model / "cam_ref.csv").write_text("\n".join([lines[0]] + [",".join(r) for r in rows]) + "\n")
    result = simulate(model / "cam.fmu", "cs")
    assert _outside(model, result, "omega") > 100
    from fmpy import simulate_fmu

    idle = simulate_fmu(str(models[0] / "cam.fmu"), stop_time=2.0, output_interval=1e-3, output=list(OUTPUTS),
                        start_values={"u": 0.0})
    assert _outside(models[0], idle, "theta") > 100  # the reference depends on the input it was made with
