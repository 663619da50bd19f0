"""CSV and DXF export: closed curves in mm, the DXF read back with ezdxf gives the CSV's points."""

import math

import ezdxf
import numpy as np
import pytest

from cam_fmu.kinematics.cam_program import CamProgram, paper_program
from cam_fmu.kinematics.disc_cam import DiscCam
from cam_fmu.kinematics.export import write_contour_csv, write_dxf


def _csv(path):
    lines = path.read_text().splitlines()
    assert lines[0] == "x_mm,y_mm"
    return np.array([[float(v) for v in line.split(",")] for line in lines[1:]])


def test_csv_is_closed_in_mm_and_on_the_contour(tmp_path):
    cam = DiscCam(paper_program(), 0.1, 0.02, 0.01)
    pts = _csv(write_contour_csv(tmp_path / "c.csv", cam, n=720))
    assert pts.shape == (721, 2) and np.array_equal(pts[0], pts[-1])
    # point k belongs to theta_k = 2 pi k / n and lies r_r = 20 mm from the roller centre there
    th = 2 * math.pi * np.arange(720) / 720
    px, py = cam.pitch(th)
    assert np.allclose(np.hypot(pts[:-1, 0] - px * 1e3, pts[:-1, 1] - py * 1e3), 20.0, atol=1e-9)
    # mm: the contour reaches r_b - r_r = 80 mm at zero lift (theta = 0) and r_b + h - r_r at the top
    r = np.hypot(pts[:, 0], pts[:, 1])
    assert r.min() == pytest.approx(math.sqrt(80.0 ** 2 + 0.0), abs=0.5)
    assert r.max() == pytest.approx(math.hypot(math.sqrt(100.0 ** 2 - 10.0 ** 2) + 164.934, 10.0) - 20.0,
                                    abs=0.5)


def test_dxf_reads_back_as_the_csv_points(tmp_path):
    prog = CamProgram("modified_sine", "cycloidal", 0.03, math.radians(100), math.radians(50),
                      math.radians(120), math.radians(90))
    cam = DiscCam(prog, 0.07, 0.015, -0.01)
    n = 1000
    pts = _csv(write_contour_csv(tmp_path / "c.csv", cam, n=n))
    doc = ezdxf.readfile(write_dxf(tmp_path / "c.dxf", cam, n=n, groove=True))
    assert doc.header["$INSUNITS"] == 4                    # millimetres
    polylines = {e.dxf.layer: e for e in doc.modelspace().query("LWPOLYLINE")}
    assert set(polylines) == {"CONTOUR", "PITCH", "BASE_CIRCLE", "CONTOUR_OUTER"}
    assert all(p.closed for p in polylines.values())
    got = {k: np.array([v[:2] for v in p.get_points("xy")]) for k, p in polylines.items()}
    assert got["CONTOUR"].shape == (n, 2)
    assert np.allclose(got["CONTOUR"], pts[:-1], rtol=0, atol=1e-12)
    # pitch and contour vertices pair up at r_r = 15 mm, the outer wall on the other side
    assert np.allclose(np.hypot(*(got["PITCH"] - got["CONTOUR"]).T), 15.0, atol=1e-9)
    assert np.allclose(np.hypot(*(got["CONTOUR_OUTER"] - got["PITCH"]).T), 15.0, atol=1e-9)
    assert np.allclose(np.hypot(*got["BASE_CIRCLE"].T), 70.0 - 15.0, atol=1e-9)
    # the contour touches its base circle along the lower dwell
    assert np.hypot(*got["CONTOUR"].T).min() == pytest.approx(55.0, abs=1e-9)


def test_plate_cam_dxf_has_three_layers_and_points_are_validated(tmp_path):
    cam = DiscCam(paper_program(), 0.1, 0.02)
    doc = ezdxf.readfile(write_dxf(tmp_path / "p.dxf", cam, n=64))
    assert sorted(e.dxf.layer for e in doc.modelspace()) == ["BASE_CIRCLE", "CONTOUR", "PITCH"]
    with pytest.raises(ValueError, match="points must be an integer >= 16"):
        write_contour_csv(tmp_path / "x.csv", cam, n=3)
