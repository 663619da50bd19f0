"""`cam-fmu curve`: table, --json, --list, --plot, errors, and cheap imports."""

import json
import math
import re
import subprocess
import sys

import pytest

from cam_fmu.cli import main


def run(capsys, *argv):
    rc = main(["curve", *argv])
    out, err = capsys.readouterr()
    return rc, out, err


def test_json_is_one_object_with_exact_fields(capsys):
    rc, out, _ = run(capsys, "--preset", "modified_sine", "--json")
    assert rc == 0
    d = json.loads(out)                       # exactly one JSON document
    assert set(d) == {"T", "Amp", "Amm", "Vm", "Am", "Jm", "jerk_unbounded", "Qm", "at"}
    assert set(d["at"]) == {"Vm", "Am", "Jm", "Qm"}
    assert d["T"] == [0.125, 0.125, 0.5, 0.5, 0.875, 0.875]
    # Makino's table (see test_characteristics.py): MS Vm 1.76, Am 5.53, Jm 69.5, Qm 5.46
    assert abs(d["Vm"] - 1.76) < 0.005 and abs(d["Am"] - 5.53) < 0.005
    assert abs(d["Jm"] - 69.5) < 0.05 and abs(d["Qm"] - 5.46) < 0.005
    assert d["jerk_unbounded"] is False


def test_json_with_T_and_unbounded_jerk(capsys):
    rc, out, _ = run(capsys, "--T", "0", "0.5", "0.5", "0.5", "0.5", "1", "--json")
    d = json.loads(out)
    assert rc == 0 and d["Jm"] is None and d["at"]["Jm"] is None and d["jerk_unbounded"] is True
    assert d["Vm"] == 2.0 and d["Am"] == 4.0 and d["Qm"] == 8.0


def test_table_and_list(capsys):
    rc, out, _ = run(capsys, "--preset", "simple_harmonic")
    assert rc == 0
    assert "Vm" in out and "1.5708" in out and "unbounded" in out
    assert "max pressure angle" in out
    rc, out, _ = run(capsys, "--list")
    assert rc == 0
    for name in ("cycloidal", "modified_sine", "modified_trapezoid", "simple_harmonic",
                 "constant_acceleration", "mcv50", "paper"):
        assert name in out
    assert "0.0625" in out


def test_default_is_the_paper_law(capsys):
    _, out, _ = run(capsys, "--json")
    assert json.loads(out)["T"] == [0.125, 0.125, 0.25, 0.75, 0.875, 0.875]


@pytest.mark.parametrize("argv, fragment", [
    (["--preset", "nope"], "known presets: cycloidal"),
    (["--T", "0.5", "0.4", "0.5", "0.5", "0.6", "0.7"], "T1=0.5 > T2=0.4"),
    (["--preset", "paper", "--rise-deg", "200"], "2\\*pi"),
])
def test_errors(capsys, argv, fragment):
    rc, _, err = run(capsys, *argv)
    assert rc == 2
    assert re.search(fragment, err)


def test_plot_writes_png(tmp_path, capsys):
    target = tmp_path / "sub" / "curve.png"
    rc, _, _ = run(capsys, "--preset", "cycloidal", "--return-preset", "modified_sine",
                   "--rise-deg", "120", "--upper-dwell-deg", "60", "--return-deg", "90",
                   "--lift-mm", "20", "--plot", str(target))
    assert rc == 0
    data = target.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20000


def test_imports_stay_cheap():
    code = ("import sys, cam_fmu; a = set(sys.modules); import cam_fmu.cli; "
            "b = set(sys.modules); cam_fmu.cli.build_parser(); "
            "heavy = [m for m in ('matplotlib', 'scipy', 'numpy', 'sympy') if m in a]; "
            "heavy_cli = [m for m in ('matplotlib', 'scipy') if m in sys.modules]; "
            "print(heavy, heavy_cli)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[] []"


def test_a_command_imports_its_own_module_and_not_the_others():
    """`cam-fmu CMD` builds the parser of CMD only: a run (every subprocess test's start-up) imports its own
    subcommand, not the eleven others (sweep's metrics imported numpy and dask's table code for `curve`);
    `cam-fmu --help` still lists every command."""
    code = ("import sys; from cam_fmu.cli import main, SUBCOMMANDS; status = main(['curve', '--preset', 'cycloidal', "
            "'--json']); print(status, sorted(m for m in sys.modules if m.startswith('cam_fmu.cli.')), "
            "'cam_fmu.experiments.sweep' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip().splitlines()[-1] == "0 ['cam_fmu.cli._program_options', 'cam_fmu.cli.curve'] False"
    listed = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "--help"], capture_output=True, text=True,
                            check=True).stdout
    from cam_fmu.cli import SUBCOMMANDS
    assert all(name.replace("_", "-") in listed for name in SUBCOMMANDS)
    wrong = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "curves"], capture_output=True, text=True)
    assert wrong.returncode == 2 and "invalid choice: 'curves'" in wrong.stderr and "cross-check" in wrong.stderr


def test_module_entry_point_runs():
    out = subprocess.run([sys.executable, "-m", "cam_fmu.cli", "curve", "--preset", "cycloidal", "--json"],
                         capture_output=True, text=True, check=True).stdout
    assert json.loads(out)["Jm"] == pytest.approx(4 * math.pi**2, rel=1e-12)
