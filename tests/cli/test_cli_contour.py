"""`cam-fmu contour`: JSON fields and values, undercut as a result, exports, the
motion-table route, and one-line errors with exit status 2."""

import json
import math

import ezdxf
import numpy as np
import pytest

from cam_fmu.cli import main
from cam_fmu.kinematics.cam_program import CamProgram, paper_program

UNDERCUT = ["--preset", "cycloidal", "--rise-deg", "60", "--upper-dwell-deg", "120", "--return-deg", "60",
            "--lift-mm", "40", "--base-radius-mm", "30", "--roller-radius-mm", "25"]


def run(capsys, *argv):
    rc = main(["contour", *argv])
    out, err = capsys.readouterr()
    return rc, out, err


def test_json_paper_cam(capsys):
    rc, out, err = run(capsys, "--roller-radius-mm", "20", "--rpm", "60", "--json")
    assert rc == 0 and err == ""
    d = json.loads(out)
    for key in ("min_radius_of_curvature_mm", "min_radius_of_curvature_at_deg", "undercut",
                "undercut_ranges_deg", "max_pressure_angle_deg", "max_pressure_angle_at_deg",
                "warnings", "smallest_base_radius_mm", "speed", "limits"):
        assert key in d
    # in-line follower: CamProgram's own pressure-angle maximum (an independent code path)
    a, at = paper_program().max_pressure_angle(0.1)
    assert d["max_pressure_angle_deg"] == pytest.approx(math.degrees(a), abs=1e-7)
    assert min(abs(d["max_pressure_angle_at_deg"] - math.degrees(at)),
               abs(d["max_pressure_angle_at_deg"] - (360 - math.degrees(at)))) < 1e-3
    # closed form at theta = 0 (s = s' = s'' = 0): rho_p = r_b, contour r_b - r_r
    assert d["min_pitch_radius_of_curvature_mm"] == pytest.approx(100.0, rel=1e-12)
    assert d["min_radius_of_curvature_mm"] == pytest.approx(80.0, rel=1e-12)
    assert d["undercut"] is False and d["ok"] is True and d["warnings"] == []
    assert d["speed"]["peak_velocity_m_s"] == pytest.approx(0.070 * 2 * math.pi, rel=1e-12)
    assert d["smallest_base_radius_mm"] < 100.0


def test_undercut_is_a_result_not_an_error(capsys):
    rc, out, _ = run(capsys, *UNDERCUT, "--json")
    assert rc == 0
    d = json.loads(out)
    assert d["undercut"] is True and d["ok"] is False
    assert d["min_radius_of_curvature_mm"] < 0
    assert {w["check"] for w in d["warnings"]} == {"undercut", "pressure_angle"}
    assert all(0 <= a < b < 360 for a, b in d["undercut_ranges_deg"])
    assert d["smallest_base_radius_mm"] > 30.0
    rc, out, _ = run(capsys, *UNDERCUT)                       # the text report says so too
    assert rc == 0 and "undercut                      yes" in out and "warning: undercut" in out


def test_offset_pressure_angle_in_json(capsys):
    _, out, _ = run(capsys, "--roller-radius-mm", "20", "--offset-mm", "15", "--json")
    d = json.loads(out)
    prog = paper_program()
    th = np.linspace(0, 2 * math.pi, 100001)
    s, s1, _, _ = prog.evaluate(th)
    alpha = np.degrees(np.abs(np.arctan((s1 - 0.015) / (math.sqrt(0.1 ** 2 - 0.015 ** 2) + s))))
    assert d["max_pressure_angle_deg"] == pytest.approx(alpha.max(), abs=1e-5)
    assert d["max_pressure_angle_deg"] > 30 and d["warnings"][0]["check"] == "pressure_angle"


def test_exports_and_plot(tmp_path, capsys):
    csv, dxf, png = tmp_path / "c.csv", tmp_path / "c.dxf", tmp_path / "fig" / "c.png"
    rc, out, _ = run(capsys, "--roller-radius-mm", "20", "--points", "360", "--export-csv", str(csv),
                     "--export-dxf", str(dxf), "--plot", str(png))
    assert rc == 0 and f"csv written to {csv}" in out
    rows = csv.read_text().splitlines()
    pts = np.array([[float(v) for v in r.split(",")] for r in rows[1:]])
    assert rows[0] == "x_mm,y_mm" and len(pts) == 361 and np.array_equal(pts[0], pts[-1])
    lw = {e.dxf.layer: e for e in ezdxf.readfile(dxf).modelspace()}
    assert np.allclose([v[:2] for v in lw["CONTOUR"].get_points("xy")], pts[:-1], atol=1e-12)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_motion_table_route(tmp_path, capsys):
    prog = CamProgram("cycloidal", "modified_sine", 0.03, math.radians(100), math.radians(40),
                      math.radians(120), math.radians(100))
    deg = np.arange(0.0, 360.0, 0.5)
    s = prog.evaluate(np.radians(deg))[0] * 1e3
    table = tmp_path / "motion.csv"
    table.write_text("angle_deg,lift_mm\n" + "\n".join(f"{a:g},{float(v)!r}" for a, v in zip(deg, s)) + "\n")
    rc, out, _ = run(capsys, "--table", str(table), "--base-radius-mm", "60", "--roller-radius-mm", "10",
                     "--rpm", "100", "--json")
    assert rc == 0
    d = json.loads(out)
    a, _ = prog.max_pressure_angle(0.06)
    # the table's s' is O(h^2) (the shape-preserving cubic): 5e-4 deg at 0.5 deg spacing
    assert d["max_pressure_angle_deg"] == pytest.approx(math.degrees(a), abs=1e-3)
    w = 2 * math.pi * 100 / 60
    assert d["speed"]["peak_velocity_m_s"] == pytest.approx(2 * 0.03 / math.radians(100) * w, rel=1e-4)


@pytest.mark.parametrize("argv, fragment", [
    (["--roller-radius-mm", "120"], "--roller-radius-mm 120 must be < --base-radius-mm 100"),
    (["--roller-radius-mm", "-1"], "--roller-radius-mm must be a number >= 0 (0: a knife edge)"),
    (["--roller-radius-mm", "10", "--offset-mm", "-100"], "--offset-mm must satisfy |e| < r_b = 100 mm"),
    (["--roller-radius-mm", "10", "--rpm", "0"], "--rpm must be a number > 0"),
    (["--roller-radius-mm", "10", "--max-pressure-angle-deg", "90"], "--max-pressure-angle-deg must lie in (0, 90)"),
    (["--roller-radius-mm", "10", "--preset", "nope"], "known presets: cycloidal"),
    (["--roller-radius-mm", "10", "--table", "/nonexistent/t.csv"], "--table: cannot read"),
    (["--roller-radius-mm", "10", "--export-csv", "/proc/nope/x.csv"], "cannot write"),
])
def test_errors_are_one_line_exit_2(capsys, argv, fragment):
    rc, out, err = run(capsys, *argv)
    assert rc == 2 and out == ""
    assert err.startswith("cam-fmu contour: error: ") and fragment in err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_bad_table_is_an_error(tmp_path, capsys):
    t = tmp_path / "t.csv"
    t.write_text("angle_deg,lift_mm\n0,0\n90,5\n90,6\n")
    rc, _, err = run(capsys, "--roller-radius-mm", "10", "--table", str(t))
    assert rc == 2 and "angles must increase strictly" in err


def _max_alpha(prog, r_b: float, e: float) -> float:
    """max |pressure angle| [deg] by the closed form tan alpha = (s' - e) / (sqrt(r_b^2 - e^2) + s) on a dense grid."""
    th = np.linspace(0, 2 * math.pi, 200001)
    s, s1, _, _ = prog.evaluate(th)
    return float(np.degrees(np.abs(np.arctan((s1 - e) / (math.sqrt(r_b ** 2 - e ** 2) + s)))).max())


@pytest.mark.parametrize("argv, prog, cause", [
    # the paper's symmetric cam, 10 mm offset: the offset is the cause (in line it passes, 29.24 deg)
    (["--offset-mm", "10"], paper_program(), "the offset e = 10 mm raises it on the return"),
    (["--offset-mm", "-10"], paper_program(), "the offset e = -10 mm raises it on the rise"),
    # a steep rise (120 deg) and a gentle return: the offset that lowers it is positive, -5 mm must be reversed
    (["--rise-deg", "120", "--return-deg", "240", "--offset-mm", "-5"],
     CamProgram("paper", "paper", lift=1.5 * math.pi * 0.035, rise_angle=math.radians(120), upper_dwell=0.0,
                return_angle=math.radians(240), lower_dwell=0.0), "reverse the offset to e = "),
])
def test_pressure_angle_advice_lowers_it(capsys, argv, prog, cause):
    """`contour --offset-mm 10` said "offset the follower" when the offset was the cause. Every change advised
    lowers the max pressure angle, by the closed form on a dense grid: the offset advised (the least: 0.5 mm
    either side is no lower), the in-line follower where it is the cure, and the base radius (the smallest that
    meets the limit at the cam's own offset)."""
    rc, out, _ = run(capsys, "--roller-radius-mm", "5", *argv, "--json")
    assert rc == 0
    d = json.loads(out)
    (warning,) = [w for w in d["warnings"] if w["check"] == "pressure_angle"]
    message, advice = warning["message"], warning["advice"]
    assert cause in message and "offset the follower" not in message, message
    r_b, e, limit = 0.1, d["offset_mm"] * 1e-3, d["limits"]["max_pressure_angle_deg"]
    now = _max_alpha(prog, r_b, e)
    assert d["max_pressure_angle_deg"] == pytest.approx(now, abs=1e-5) and now > limit
    best = advice["best_offset_mm"] * 1e-3
    assert f"e = {advice['best_offset_mm']:.4g} mm" in message or (best == 0.0 and "in line, e = 0" in message)
    at_best = _max_alpha(prog, r_b, best)
    assert at_best < now - 0.1 and at_best == pytest.approx(advice["best_offset_max_pressure_angle_deg"], abs=1e-5)
    assert _max_alpha(prog, r_b, best - 5e-4) > at_best and _max_alpha(prog, r_b, best + 5e-4) > at_best
    assert advice["inline_max_pressure_angle_deg"] == pytest.approx(_max_alpha(prog, r_b, 0.0), abs=1e-5)
    if "raises it" in message:
        assert advice["inline_max_pressure_angle_deg"] < now
    r_min = advice["base_radius_mm"] * 1e-3
    assert f"r_b = {advice['base_radius_mm']:.5g} mm" in message
    assert _max_alpha(prog, r_min, e) <= limit + 1e-6 and _max_alpha(prog, r_min * (1 - 1e-4), e) > limit


# -- every follower type (issue 40, item 2) --------------------------------------------------------------------

CYC = ["--preset", "cycloidal", "--rise-deg", "120", "--upper-dwell-deg", "60", "--return-deg", "120"]
CYC_PROG = CamProgram("cycloidal", "cycloidal", 1.5 * math.pi * 0.035, math.radians(120), math.radians(60),
                      math.radians(120), math.radians(60))
ROCKER = ["--follower-type", "oscillating_roller", "--roller-radius-mm", "15", "--arm-length-mm", "150",
          "--pivot-distance-mm", "180", "--lift-angle-deg", "25", "--base-radius-mm", "80"]
FACE = ["--follower-type", "oscillating_flat", "--arm-length-mm", "150", "--pivot-distance-mm", "180",
        "--lift-angle-deg", "12", "--base-radius-mm", "100"]
TH = np.linspace(0.0, 2 * math.pi, 200001)


def test_translating_flat_face_json(capsys):
    rc, out, _ = run(capsys, *CYC, "--follower-type", "translating_flat", "--base-radius-mm", "100", "--json")
    assert rc == 0
    d = json.loads(out)
    s, s1, s2, _ = CYC_PROG.evaluate(TH)
    h, b = CYC_PROG.lift, math.radians(120)
    # the face the contact needs: max s' - min s' = 2 h / b twice (cycloidal, Vm = 2, on rise and return)
    assert d["face_width_mm"] == pytest.approx(4 * h / b * 1e3, rel=1e-9)
    assert d["face_extent_mm"] == pytest.approx([-2 * h / b * 1e3, 2 * h / b * 1e3], rel=1e-9)
    assert d["min_radius_of_curvature_mm"] == pytest.approx((0.1 + s + s2).min() * 1e3, abs=1e-6)
    assert d["smallest_base_radius_mm"] == pytest.approx(-(s + s2).min() * 1e3, abs=2e-3)
    assert d["max_pressure_angle_deg"] == 0.0 and d["ok"] is True and d["follower_type"] == "translating_flat"


def test_oscillating_roller_json(capsys):
    rc, out, _ = run(capsys, *CYC, *ROCKER, "--rpm", "60", "--json")
    assert rc == 0
    d = json.loads(out)
    r_b, L, dd, lift = 0.08, 0.15, 0.18, math.radians(25)
    s, s1, _, _ = CYC_PROG.evaluate(TH)
    psi, psi1 = lift * s / CYC_PROG.lift, lift * s1 / CYC_PROG.lift
    delta = math.acos((dd * dd + L * L - r_b * r_b) / (2 * dd * L)) + psi     # the angle at the pivot
    alpha = np.degrees(np.abs(np.arctan((dd * np.cos(delta) - L * (1 - psi1)) / (dd * np.sin(delta)))))
    assert d["max_pressure_angle_deg"] == pytest.approx(alpha.max(), abs=1e-6)
    assert d["offset_mm"] is None and d["arm_length_mm"] == 150.0 and d["lift_angle_deg"] == pytest.approx(25.0)
    assert math.hypot(*d["pivot_mm"]) == pytest.approx(180.0, rel=1e-12)
    assert d["speed"]["peak_arm_rate_rad_s"] == pytest.approx(lift * 2 / math.radians(120) * 2 * math.pi, rel=1e-9)
    (warning,) = d["warnings"]
    assert warning["check"] == "pressure_angle" and "raise the base radius or move the pivot" in warning["message"]
    assert "advice" not in warning
    # at this pivot and arm no base radius meets 30 deg: the least max |alpha| over the radii the triangle
    # allows, by the closed form, is above it
    assert d["smallest_base_radius_mm"] is None
    assert "no base radius in (30, 195) mm" in d["smallest_base_radius_error"]
    th = np.linspace(0.0, 2 * math.pi, 20001)
    s, s1, _, _ = CYC_PROG.evaluate(th)
    psi, psi1 = lift * s / CYC_PROG.lift, lift * s1 / CYC_PROG.lift
    least = min(np.degrees(np.abs(np.arctan((dd * np.cos(dl) - L * (1 - psi1)) / (dd * np.sin(dl))))).max()
                for r in np.linspace(0.0301, 0.1949, 400)
                for dl in [math.acos((dd * dd + L * L - r * r) / (2 * dd * L)) + psi])
    assert 30.5 < least < 35.0
    rc, out, _ = run(capsys, *CYC, *ROCKER, "--max-pressure-angle-deg", "35")
    assert rc == 0 and "oscillating: L = 150 mm, d = 180 mm" in out and "warning" not in out


def test_oscillating_flat_face_json(capsys):
    rc, out, _ = run(capsys, *CYC, *FACE, "--json")
    assert rc == 0
    d = json.loads(out)
    r_b, dd, lift = 0.1, 0.18, math.radians(12)
    s, s1, _, _ = CYC_PROG.evaluate(TH)
    psi, psi1 = lift * s / CYC_PROG.lift, lift * s1 / CYC_PROG.lift
    ell = dd * np.cos(math.asin(r_b / dd) + psi) / (1 - psi1)
    assert d["face_extent_mm"] == pytest.approx([ell.min() * 1e3, ell.max() * 1e3], abs=1e-6)
    assert d["face_width_mm"] == pytest.approx((ell.max() - ell.min()) * 1e3, abs=1e-6)
    assert d["min_radius_of_curvature_mm"] > 0 and d["ok"] is True


@pytest.mark.parametrize("argv, fragment", [
    (["--follower-type", "translating_flat", "--roller-radius-mm", "10"],
     "--roller-radius-mm is not used by --follower-type translating_flat (only by translating_roller and "
     "oscillating_roller)"),
    (["--follower-type", "translating_flat", "--offset-mm", "5"], "--offset-mm is not used by --follower-type"),
    (["--roller-radius-mm", "10", "--arm-length-mm", "100"],
     "--arm-length-mm is not used by --follower-type translating_roller"),
    (["--follower-type", "oscillating_roller", "--roller-radius-mm", "10", "--arm-length-mm", "100",
      "--lift-angle-deg", "20"], "--follower-type oscillating_roller needs --pivot-distance-mm"),
    (["--follower-type", "translating_roller"], "--follower-type translating_roller needs --roller-radius-mm"),
    (FACE + ["--lift-mm", "30"], "--lift-mm is not used by --follower-type oscillating_flat"),
    (["--follower-type", "translating_flat", "--groove"], "--groove is for roller followers"),
    (["--follower-type", "oscillating_roller", "--roller-radius-mm", "10", "--arm-length-mm", "40",
      "--pivot-distance-mm", "300", "--lift-angle-deg", "20"], "the arm cannot reach the cam"),
    (["--follower-type", "oscillating_roller", "--roller-radius-mm", "10", "--arm-length-mm", "100",
      "--pivot-distance-mm", "60", "--lift-angle-deg", "20"], "puts the pivot inside the cam's base circle"),
    (["--follower-type", "oscillating_roller", "--roller-radius-mm", "10", "--arm-length-mm", "150",
      "--pivot-distance-mm", "180", "--lift-angle-deg", "160"], "the pressure angle reaches 90 deg"),
    (["--follower-type", "oscillating_flat", "--arm-length-mm", "150", "--pivot-distance-mm", "90",
      "--lift-angle-deg", "10"], "puts the pivot inside the base circle"),
    (CYC + ["--follower-type", "translating_flat", "--base-radius-mm", "20"],
     "radius of curvature r_b + s + s'' = "),
    (["--follower-type", "oscillating_flat", "--arm-length-mm", "150", "--pivot-distance-mm", "180",
      "--lift-angle-deg", "-5"], "--lift-angle-deg must be a number > 0"),
])
def test_follower_type_errors_are_one_line_exit_2(capsys, argv, fragment):
    rc, out, err = run(capsys, *argv)
    assert rc == 2 and out == ""
    assert err.startswith("cam-fmu contour: error: ") and fragment in err, err
    assert err.count("\n") == 1 and "Traceback" not in err


@pytest.mark.parametrize("argv", [CYC + ["--follower-type", "translating_flat", "--base-radius-mm", "100"],
                                  CYC + ROCKER, CYC + FACE, ["--roller-radius-mm", "0"]],
                         ids=["translating_flat", "oscillating_roller", "oscillating_flat", "knife_edge"])
def test_every_type_exports_and_plots(tmp_path, capsys, argv):
    csv, dxf, png = tmp_path / "c.csv", tmp_path / "c.dxf", tmp_path / "c.png"
    rc, out, err = run(capsys, *argv, "--points", "720", "--export-csv", str(csv), "--export-dxf", str(dxf),
                       "--plot", str(png))
    assert rc == 0, err
    pts = np.array([[float(v) for v in r.split(",")] for r in csv.read_text().splitlines()[1:]])
    assert len(pts) == 721 and np.array_equal(pts[0], pts[-1])
    lw = {e.dxf.layer: np.array([v[:2] for v in e.get_points("xy")]) for e in ezdxf.readfile(dxf).modelspace()}
    assert set(lw) == {"CONTOUR", "PITCH", "BASE_CIRCLE"}
    assert np.allclose(lw["CONTOUR"], pts[:-1], atol=1e-12)
    # the contour touches its base circle (zero lift) and never enters it
    r = np.hypot(*pts.T)
    base = np.hypot(*lw["BASE_CIRCLE"].T)
    assert np.allclose(base, base[0], rtol=1e-12) and r.min() == pytest.approx(base[0], abs=1e-6)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
