"""Export of a disc cam for manufacturing: contour points as CSV, curves as DXF.

The cam is any follower type's (follower_types.make_cam: DiscCam, OscillatingRollerCam, TranslatingFlatCam,
OscillatingFlatCam).  Coordinates: the cam frame at theta = 0 (origin on the cam axis, the follower's
reference at zero lift on +X at theta = 0; see disc_cam), in mm.  Points at n equally spaced cam
angles theta_k = 2 pi k / n, in the order of increasing theta (clockwise
around the cam).

- CSV: header ``x_mm,y_mm``, one point a line, the first point repeated at
  the end (a closed polygon).
- DXF (ezdxf, R2010, $INSUNITS = mm): one closed LWPOLYLINE (n vertices, no
  repeated point) on each layer CONTOUR (the inner contour, the plate cam's
  surface), PITCH (the roller-centre path; a flat face's reference point's) and BASE_CIRCLE (radius
  r_b - r_r; a flat face's r_b),
  and with ``groove=True`` also CONTOUR_OUTER (the groove's outer wall).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .disc_cam import DiscCam

__all__ = ["curve_points_mm", "write_contour_csv", "write_dxf", "LAYERS"]

LAYERS = {"CONTOUR": 1, "PITCH": 5, "BASE_CIRCLE": 8, "CONTOUR_OUTER": 3}   # name -> ACI colour


def _angles(n: int) -> np.ndarray:
    if not (isinstance(n, (int, np.integer)) and n >= 16):
        raise ValueError(f"points must be an integer >= 16, got {n!r}")
    return 2.0 * math.pi * np.arange(n) / n


def curve_points_mm(cam: DiscCam, curve: str = "contour", n: int = 3600) -> np.ndarray:
    """(n, 2) array of points [mm]: curve 'contour' (inner), 'outer', 'pitch' or 'base_circle'."""
    th = _angles(n)
    if curve == "contour":
        x, y = cam.contour(th, "inner")
    elif curve == "outer":
        x, y = cam.contour(th, "outer")
    elif curve == "pitch":
        x, y = cam.pitch(th)
    elif curve == "base_circle":
        r = cam.base_circle_radius
        x, y = r * np.cos(th), -r * np.sin(th)
    else:
        raise ValueError(f"curve must be 'contour', 'outer', 'pitch' or 'base_circle', got {curve!r}")
    return np.column_stack([x, y]) * 1e3


def write_contour_csv(path: str | Path, cam: DiscCam, n: int = 3600, curve: str = "contour") -> Path:
    """Write the closed contour (x_mm, y_mm; first point repeated last) as CSV."""
    pts = curve_points_mm(cam, curve, n)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w") as f:
        f.write("x_mm,y_mm\n")
        for x, y in np.vstack([pts, pts[:1]]):
            f.write(f"{float(x)!r},{float(y)!r}\n")
    return path


def write_dxf(path: str | Path, cam: DiscCam, n: int = 3600, groove: bool = False) -> Path:
    """Write the contour, pitch curve and base circle (and the groove's outer
    wall) as closed LWPOLYLINEs in mm on their own layers."""
    import ezdxf
    from ezdxf import units

    doc = ezdxf.new("R2010")
    doc.units = units.MM
    msp = doc.modelspace()
    curves = [("CONTOUR", "contour"), ("PITCH", "pitch"), ("BASE_CIRCLE", "base_circle")]
    if groove:
        curves.append(("CONTOUR_OUTER", "outer"))
    for layer, curve in curves:
        doc.layers.add(layer, color=LAYERS[layer])
        pts = curve_points_mm(cam, curve, n)
        msp.add_lwpolyline([(float(x), float(y)) for x, y in pts], format="xy", close=True,
                           dxfattribs={"layer": layer})
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    doc.saveas(path)
    return path
