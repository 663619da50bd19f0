"""`cam-fmu cross-check DIR`: the FMI Cross-Check folders, checked with fmpy's own cross-check code.

- the folders are exactly what the FMU offers (its modelDescription.xml's interfaces x
  its binaries/ folders, read here independently), each with the rules' files;
- fmpy's validate_test_fmu (what the cross-check repository's CI runs) and
  validate_repo find no problem;
- a fresh fmpy run from _in.csv and _ref.opt reproduces _ref.csv (fmpy.util.validate_signal:
  no sample outside the band; fmpy.cross_check.validate_result: passed); a _ref.csv with
  an output shifted fails both, and the command's own validation reports it;
- the input file matters: without it (u at 3.5 V from t = 0) the run fails against the
  reference; the reference agrees with the scipy reference (physics/, a second
  implementation) driven by the same step of u.
cam.fmu hosts no Python: it is loaded in this process (conftest.engine_fmu_path).
"""
from __future__ import annotations

import shutil
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.util import read_csv, read_ref_opt_file, validate_signal

from cam_fmu import __version__
from cam_fmu.cli import main

FILES = ("{m}.fmu", "{m}_in.csv", "{m}_ref.csv", "{m}_ref.opt", "ReadMe.md", "{m}_fmpy.log")


@pytest.fixture(scope="module")
def shipped(cam_fmu_path, cam3_fmu_path) -> list[Path]:
    """Every FMU the command packages by default (the drive's: cam.fmu, cam3.fmu): the session's builds from this
    checkout (conftest.py). A new FMU of the drive fails here until it has its session build."""
    from cam_fmu.fmu.build import ENGINE_MODELS

    built = {"cam": cam_fmu_path, "cam3": cam3_fmu_path}
    drives = [name for name, (c_model, _v) in ENGINE_MODELS.items() if c_model == "cam"]
    assert sorted(drives) == sorted(built), f"the drive's FMUs {drives}: give each a session build in conftest.py"
    return [built[name] for name in drives]


@pytest.fixture(scope="module")
def package(shipped, tmp_path_factory):
    root = tmp_path_factory.mktemp("xcheck")
    status = main(["cross-check", str(root), "--fmu", *map(str, shipped)])
    folders = sorted(p.parent for p in root.glob("fmus/*/*/*/*/*/*/*.fmu"))
    return {"root": root, "status": status, "folders": folders, "fmus": {f.stem: f for f in shipped}}


def _offers(fmu: Path) -> set[tuple[str, str, str]]:
    """(version, type, platform) read from the FMU without the package's code."""
    md = read_model_description(str(fmu))
    types = {"cs"} if md.coSimulation else set()
    types |= {"me"} if md.modelExchange else set()
    with zipfile.ZipFile(fmu) as z:
        platforms = {n.split("/")[1] for n in z.namelist()
                     if n.startswith("binaries/") and n.endswith((".so", ".dll", ".dylib"))}
    return {(md.fmiVersion, t, p) for t in types for p in platforms}


def _runs_here(folder: Path) -> bool:
    import fmpy
    version, platform = folder.parts[-6], folder.parts[-4]
    return platform == (fmpy.platform_tuple if version.startswith("3") else fmpy.platform)


def _fresh_run(folder: Path, with_inputs: bool = True) -> np.ndarray:
    """fmpy as an importer: the FMU run from the folder's _ref.opt (and _in.csv), the _ref.csv columns."""
    m = folder.name
    opts = read_ref_opt_file(str(folder / f"{m}_ref.opt"))
    names = list(read_csv(str(folder / f"{m}_ref.csv")).dtype.names[1:])
    inputs = read_csv(str(folder / f"{m}_in.csv")) if with_inputs else None
    fmi_type = {"cs": "CoSimulation", "me": "ModelExchange"}[folder.parts[-5]]
    return simulate_fmu(str(folder / f"{m}.fmu"), fmi_type=fmi_type, stop_time=opts["StopTime"],
                        output_interval=opts["OutputIntervalLength"], relative_tolerance=opts["RelTol"],
                        input=inputs, output=names, **({"solver": "CVode"} if fmi_type == "ModelExchange" else {}))


def _band_outliers(result: np.ndarray, reference: np.ndarray) -> dict[str, int]:
    out = {}
    for name in reference.dtype.names[1:]:
        *_, i_out = validate_signal(result["time"], result[name], np.array(reference["time"]), reference[name])
        out[name] = int(np.count_nonzero(i_out))
    return out


def _validate_result(result, reference, opts):
    from fmpy.cross_check import validate_result
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # fmpy imports scipy.ndimage.filters
        return validate_result(result, reference, opts["StartTime"], opts["StopTime"])


def test_one_folder_per_interface_and_binary(package):
    assert package["status"] == 0
    root = package["root"]
    for name, fmu in package["fmus"].items():
        found = {(f.parts[-6], f.parts[-5], f.parts[-4]) for f in package["folders"] if f.name == name}
        assert found == _offers(fmu)
    assert len(package["folders"]) == sum(len(_offers(fmu)) for fmu in package["fmus"].values())
    assert ("2.0", "cs", "linux64", "cam") in {(*f.parts[-6:-3], f.name) for f in package["folders"]}
    for folder in package["folders"]:
        assert folder.relative_to(root).parts[0] == "fmus"
        assert folder.parts[-3:-1] == ("cam_fmu", __version__)
        assert sorted(p.name for p in folder.iterdir()) == sorted(f.format(m=folder.name) for f in FILES)
        assert (folder / f"{folder.name}.fmu").read_bytes() == package["fmus"][folder.name].read_bytes()


def test_by_default_the_fmus_of_the_drive(monkeypatch):
    """Without --fmu: every model fmu.build builds on the drive's C model (cam.fmu, cam3.fmu): the folders'
    experiment is a step of the drive's u, which pi_speed.fmu does not have."""
    import cam_fmu.fmu.build as fmu_build
    from cam_fmu.fmu.build import MODELS
    from cam_fmu.tools.cross_check.layout import shipped_fmus
    monkeypatch.setattr(fmu_build, "ensure_fmu", lambda path, log=None, model="cam": Path(f"{model}.fmu"))
    names = [p.stem for p in shipped_fmus()]
    assert names == ["cam", "cam3"] and "pi_speed" in MODELS


def test_fmpy_cross_check_validation_finds_no_problem(package):
    from fmpy.cross_check.validate_vendor_repo import validate_repo, validate_test_fmu
    for folder in package["folders"]:
        assert validate_test_fmu(str(folder)) == []
        log = (folder / f"{folder.name}_fmpy.log").read_text()
        assert log.rstrip().endswith("result: passed")
        assert "Compliance Checker (fmuCheck): not run" in log
    fmu_count, result_count, problems = validate_repo(str(package["root"]))  # FMI 1.0 and 2.0 only
    assert problems == []
    assert fmu_count == len(package["folders"]) and result_count == 0


def test_files_follow_the_csv_and_opt_rules(package):
    for folder in package["folders"]:
        m = folder.name
        opts = read_ref_opt_file(str(folder / f"{m}_ref.opt"))
        md = read_model_description(str(folder / f"{m}.fmu"))
        kinds = {v.name: v.causality for v in md.modelVariables}
        for suffix, causality in (("_in.csv", "input"), ("_ref.csv", "output")):
            path = folder / f"{m}{suffix}"
            lines = path.read_text().splitlines()
            header = lines[0].split(",")
            assert header[0] == '"time"' and all(h.startswith('"') and h.endswith('"') for h in header)
            assert all(kinds[h.strip('"')] == causality for h in header[1:])
            if causality == "input":
                assert sorted(h.strip('"') for h in header[1:]) == sorted(n for n, c in kinds.items() if c == "input")
            rows = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
            assert rows.shape[1] == len(header) and path.stat().st_size < 1_000_000
            assert np.all(np.diff(rows[:, 0]) >= 0)
            assert rows[0, 0] == opts["StartTime"] and rows[-1, 0] == pytest.approx(opts["StopTime"], abs=1e-12)
        assert len(read_csv(str(folder / f"{m}_ref.csv")).dtype.names) - 1 <= 10


def test_a_fresh_run_reproduces_the_reference(package):
    ran = 0
    for folder in package["folders"]:
        if not _runs_here(folder):
            continue
        m = folder.name
        reference = read_csv(str(folder / f"{m}_ref.csv"))
        result = _fresh_run(folder)
        assert _band_outliers(result, reference) == dict.fromkeys(reference.dtype.names[1:], 0)
        assert _validate_result(result, reference, read_ref_opt_file(str(folder / f"{m}_ref.opt"))) is None
        ran += 1
    assert ran >= 1


@pytest.mark.parametrize("column", ["omega", "theta", "s", "i", "M"])
def test_a_shifted_output_in_the_reference_fails(package, column, tmp_path):
    """Each output offset by 20 % of its range (fmpy's band is 10 % of it wide) fails fmpy's importer
    criterion, the strict band check and the command's validation."""
    from cam_fmu.tools.cross_check import entries, validate_entry

    src = next(f for f in package["folders"] if f.parts[-5] == "cs" and _runs_here(f))
    m = src.name
    rel = src.relative_to(package["root"])
    clean = read_csv(str(src / f"{m}_ref.csv"))
    result = _fresh_run(src)
    opts = read_ref_opt_file(str(src / f"{m}_ref.opt"))
    offset = clean.copy()
    offset[column] += 0.2 * (clean[column].max() - clean[column].min())
    assert _validate_result(result, offset, opts) == \
        f'More than 10% of the samples outside epsilon band for variable "{column}"'
    assert _band_outliers(result, offset)[column] > 0
    assert _band_outliers(result, clean)[column] == 0

    shutil.copytree(src, tmp_path / rel)
    header = ",".join(f'"{n}"' for n in offset.dtype.names)
    np.savetxt(tmp_path / rel / f"{m}_ref.csv", offset, delimiter=",", header=header, comments="", fmt="%.12g")
    entry = next(e for e in entries(tmp_path / rel / f"{m}.fmu") if e.fmi_type == "cs" and e.runs_here)
    problems = validate_entry(entry, tmp_path)
    assert problems and f'variable "{column}"' in problems[-1]
    assert (tmp_path / rel / f"{m}_fmpy.log").read_text().rstrip().endswith("result: FAILED")


def test_the_input_file_is_used(package):
    from cam_fmu.tools.cross_check.experiment import STEP_TIME
    for folder in package["folders"]:
        if not _runs_here(folder):
            continue
        m = folder.name
        reference = read_csv(str(folder / f"{m}_ref.csv"))
        before = reference["time"] < STEP_TIME
        assert np.all(reference["omega"][before] == 0.0) and np.all(reference["theta"][before] == 0.0)
        assert reference["omega"][~before].max() > 10.0  # the fig. 6 start-up after the step
        without = _fresh_run(folder, with_inputs=False)  # u = 3.5 V (its start value) from t = 0
        assert without["omega"][without["time"] < STEP_TIME].max() > 1.0  # it starts at once
        problem = _validate_result(without, reference, read_ref_opt_file(str(folder / f"{m}_ref.opt")))
        assert problem is not None and "outside epsilon band" in problem


def test_the_reference_agrees_with_the_scipy_reference(package, reference_runs):
    """The same step of u on physics/ integrated by scipy (rtol 1e-12): co-simulation within
    test_fmu_vs_reference's rk45 tolerances (theta 1e-6 rad, omega 1e-4 of its peak); every folder
    passes fmpy's importer criterion against it."""
    from cam_fmu.experiments.scenes import find_scene
    from cam_fmu.physics.signals import Signal
    from cam_fmu.tools.cross_check.experiment import STEP_TIME

    scene = find_scene("paper_fig6")
    u_after = scene.u.values[0]
    for folder in package["folders"]:
        m = folder.name
        opts = read_ref_opt_file(str(folder / f"{m}_ref.opt"))
        reference = read_csv(str(folder / f"{m}_ref.csv"))
        assert opts["StopTime"] == pytest.approx(STEP_TIME + scene.stop_time)
        u = Signal((0.0, STEP_TIME, STEP_TIME), (0.0, 0.0, u_after))
        scipy_run = reference_runs.simulate(scene.primary.overrides, opts["StopTime"], opts["OutputIntervalLength"],
                                            u=u)
        names = reference.dtype.names
        as_table = np.array(list(zip(*(scipy_run[n] for n in names))), dtype=reference.dtype)
        assert _validate_result(as_table, reference, opts) is None
        if folder.parts[-5] == "cs":
            assert np.allclose(reference["time"], scipy_run["time"], rtol=0, atol=1e-12)
            assert np.max(np.abs(reference["theta"] - scipy_run["theta"])) < 1e-6
            peak = np.max(np.abs(scipy_run["omega"]))
            assert np.max(np.abs(reference["omega"] - scipy_run["omega"])) < 1e-4 * peak


def test_the_fmu_defaults_are_the_fig6_scene(shipped):
    """The ReadMe says the parameters are the FMU's defaults and those of paper_fig6: no importer sets any."""
    from cam_fmu.experiments.scenes import find_scene
    values = find_scene("paper_fig6").primary.start_values()
    assert {"gamma", "theta0", "omega0", "formulation"} <= set(values)
    for fmu in shipped:
        md = read_model_description(str(fmu))
        starts = {v.name: v.start for v in md.modelVariables if v.causality == "parameter"}
        for name, value in values.items():
            if isinstance(value, str):
                assert starts[name] == value, (fmu.name, name)
            elif isinstance(value, bool):
                assert starts[name] in (value, str(value).lower()), (fmu.name, name)
            else:
                assert float(starts[name]) == pytest.approx(float(value), rel=1e-15), (fmu.name, name)


def test_readme_says_what_was_run_where(package):
    for folder in package["folders"]:
        text = (folder / "ReadMe.md").read_text()
        assert f"|FMI Version|{folder.parts[-6]}|" in text and f"|Platform|{folder.parts[-4]}|" in text
        assert "paper_fig6" in text and "fmuCheck) was not run" in text
        here = _runs_here(folder)
        assert ("was not run to compute it" in text) != here


def _fmu_without(src: Path, dest: Path, prefix: str) -> Path:
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dest, "w") as zout:
        for item in zin.infolist():
            if not item.filename.startswith(prefix):
                zout.writestr(item, zin.read(item.filename))
    return dest


def test_bad_input_is_one_line_exit_2(engine_fmu_path, tmp_path, capsys):
    import fmpy
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    shutil.copyfile(engine_fmu_path, tmp_path / "cam-2.fmu")
    (tmp_path / "other").mkdir()
    shutil.copyfile(engine_fmu_path, tmp_path / "other" / "cam.fmu")
    # an FMU built for other machines only (the session's build may be this machine's only: the fast loop)
    other_platforms_only = _fmu_without(engine_fmu_path, tmp_path / "cam.fmu", f"binaries/{fmpy.platform}/")
    with zipfile.ZipFile(other_platforms_only, "a") as z:
        if not any(n.startswith("binaries/") and not n.endswith("/") for n in z.namelist()):
            z.writestr("binaries/win64/cam.dll", b"MZ")
    cases = [
        ([str(tmp_path / "out"), "--fmu", str(tmp_path / "missing.fmu")], "does not exist"),
        ([str(tmp_path / "out"), "--fmu", str(a_file)], "is not an FMU"),
        ([str(a_file), "--fmu", str(engine_fmu_path)], "exists and is not a directory"),
        ([str(tmp_path / "out"), "--fmu", str(tmp_path / "cam-2.fmu")], "the file name is the model name"),
        ([str(tmp_path / "out"), "--fmu", str(engine_fmu_path), str(tmp_path / "other" / "cam.fmu")],
         "would share the folder"),
        ([str(tmp_path / "out"), "--fmu", str(other_platforms_only)], f"no binary for this machine ({fmpy.platform}"),
    ]
    for args, message in cases:
        assert main(["cross-check", *args]) == 2, args
        err = capsys.readouterr().err.strip()
        assert err.startswith("cam-fmu cross-check: error: ") and message in err and "\n" not in err, err
    assert not (tmp_path / "out").exists()  # refused before anything was written


def test_an_interface_added_to_the_model_description_gets_its_folders(engine_fmu_path, tmp_path):
    """Model exchange (another helper's work) is found from the model description alone: a copy of cam.fmu
    whose modelDescription.xml also declares it gets cs and me folders for each binary, and the me
    folder's _ref.opt (StepSize 0: a variable-step solver) passes fmpy's reader."""
    from cam_fmu.tools.cross_check import entries
    from cam_fmu.tools.cross_check.experiment import fig6_experiment, opt_lines

    dest = tmp_path / "cam.fmu"
    with zipfile.ZipFile(engine_fmu_path) as zin, zipfile.ZipFile(dest, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                assert text.count("<CoSimulation ") == 1
                data = text.replace("<CoSimulation ", '<ModelExchange modelIdentifier="cam"/>\n  <CoSimulation ').encode()
            zout.writestr(item, data)
    assert read_model_description(str(dest)).modelExchange is not None
    found = {(e.fmi_version, e.fmi_type, e.platform) for e in entries(dest)}
    platforms = {p for _, _, p in _offers(engine_fmu_path)}
    assert "linux64" in platforms
    assert found == _offers(dest) == {("2.0", t, p) for t in ("cs", "me") for p in platforms}
    opt = tmp_path / "me_ref.opt"
    opt.write_text("\n".join(opt_lines(fig6_experiment(), "me")) + "\n")
    opts = read_ref_opt_file(str(opt))
    assert opts["StepSize"] == 0.0 and opts["OutputIntervalLength"] == 1e-3 and opts["StopTime"] == 2.5
