"""Figure of a disc cam with an oscillating or flat-faced follower: the contour, the pitch curve (the roller
centre's or the face's reference point's path), the base circle and the follower at theta = 0 (cam frame,
mm); the pressure angle (rollers) or the contact's position along the face (flat faces) and the contour's
radius of curvature over the cycle.  The translating roller's figure is plots.cam.  Headless: Agg backend."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..kinematics.flat_cam import FlatFaceCam, OscillatingFlatCam  # noqa: E402


def _follower_at_zero(ax, cam, mm: float) -> None:
    """The follower at theta = 0 (the cam frame is the fixed frame there)."""
    circ = np.linspace(0.0, 2.0 * math.pi, 181)
    r_b = cam.base_radius
    if isinstance(cam, FlatFaceCam):
        ys = cam.face_position(np.linspace(0.0, 2.0 * math.pi, 721))
        if isinstance(cam, OscillatingFlatCam):   # the face runs down from the pivot: y = P_y - l
            px, py = cam.pivot
            y0, y1 = py - ys.max() - 0.1 * r_b, py
            ax.plot([px * mm, px * mm], [y0 * mm, y1 * mm], color="tab:orange", lw=2.5, label="face (through the pivot)")
        else:
            y0, y1 = ys.min() - 0.1 * r_b, ys.max() + 0.1 * r_b
            ax.plot([r_b * mm, r_b * mm], [y0 * mm, y1 * mm], color="tab:orange", lw=2.5, label="face")
            ax.plot([r_b * mm, 1.4 * r_b * mm], [0.0, 0.0], color="tab:orange", lw=4, alpha=0.6)
    else:
        r_r = cam.roller_radius
        x, y = cam.pitch(0.0)
        ax.plot((x + r_r * np.cos(circ)) * mm, (y + r_r * np.sin(circ)) * mm, color="tab:orange", lw=1.5,
                label="roller")
        px, py = cam.pivot
        ax.plot([px * mm, x * mm], [py * mm, y * mm], color="tab:orange", lw=3, alpha=0.7, label="arm")
    if hasattr(cam, "pivot"):
        px, py = cam.pivot
        ax.plot([px * mm], [py * mm], "o", color="tab:red", ms=7, label="pivot")
        ax.plot([0, px * mm], [0, py * mm], color="0.5", lw=0.8, ls="--")
        ax.annotate(f"d = {cam.pivot_distance * mm:.4g} mm", (0.5 * px * mm, 0.5 * py * mm), fontsize=8,
                    color="0.3")


def plot_follower(cam, path: str | Path, report, title: str = "") -> Path:
    """Write a PNG of `cam` with its follower (see the module docstring)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = plt.figure(figsize=(14, 7.5), constrained_layout=True)
    gs = fig.add_gridspec(2, 2, width_ratios=(1.1, 1.0))
    ax, axa = fig.add_subplot(gs[:, 0]), fig.add_subplot(gs[0, 1])
    axr = fig.add_subplot(gs[1, 1], sharex=axa)
    fig.suptitle(title, fontsize=13)
    th = np.linspace(0.0, 2.0 * math.pi, 3601)
    mm = 1e3
    cx, cy = cam.contour(th)
    px, py = cam.pitch(th)
    ax.fill(cx * mm, cy * mm, color="0.88", zorder=0)
    ax.plot(cx * mm, cy * mm, color="k", lw=1.8, label="contour")
    flat = isinstance(cam, FlatFaceCam)
    ax.plot(px * mm, py * mm, color="tab:blue", lw=1.0, ls="--",
            label="face's reference point's path" if flat else "pitch curve (roller centre)")
    circ = np.linspace(0.0, 2.0 * math.pi, 361)
    rbc = cam.base_circle_radius
    ax.plot(rbc * mm * np.cos(circ), rbc * mm * np.sin(circ), color="0.4", lw=0.8, ls=":",
            label=f"base circle {rbc * mm:.4g} mm")
    _follower_at_zero(ax, cam, mm)
    ax.plot([0], [0], "k+", ms=10)
    ax.set_aspect("equal")
    ax.set_xlabel("x  [mm]  (cam frame at θ = 0; cam turns counterclockwise)")
    ax.set_ylabel("y  [mm]")
    ax.grid(alpha=0.25)
    ax.legend(loc="lower left", fontsize=8)

    deg = np.degrees(th)
    if flat:
        axa.plot(deg, cam.face_position(th) * mm, lw=1.5)
        where = "from the pivot" if isinstance(cam, OscillatingFlatCam) else "from the axis (+Y)"
        axa.set_ylabel(f"contact along the face {where}  [mm]")
        axa.set_title(f"face width needed {report.face_width * mm:.4g} mm (pressure angle 0)", fontsize=10)
        rho = cam.radius_of_curvature(th) * mm
        axr.plot(deg, rho, lw=1.5, color="k", label="contour ρ")
    else:
        alpha = np.degrees(cam.pressure_angle(th))
        lim = math.degrees(report.limits.max_pressure_angle)
        axa.plot(deg, alpha, lw=1.5)
        for sgn in (1, -1):
            axa.axhline(sgn * lim, color="tab:red", lw=0.9, ls="--")
        axa.set_ylabel("pressure angle α  [deg]")
        axa.set_title(f"max |α| = {math.degrees(report.max_pressure_angle):.4g} deg at θ = "
                      f"{math.degrees(report.max_pressure_angle_at):.4g} deg (limit ±{lim:.3g} deg)", fontsize=10)
        rho = cam.contour_radius_of_curvature(th) * mm
        clip = 4.0 * cam.base_radius * mm
        axr.plot(deg, np.where(np.abs(rho) < clip, rho, np.nan), lw=1.5, color="k", label="contour ρ_p - r_r")
        axr.set_ylim(-clip, clip)
    axr.axhline(0.0, color="0.5", lw=0.6)
    axr.set_title(f"min contour ρ = {report.min_radius_of_curvature * mm:.4g} mm at θ = "
                  f"{math.degrees(report.min_radius_at):.4g} deg", fontsize=10)
    axa.grid(alpha=0.3)
    axr.set_xlim(0, 360)
    axr.set_xticks(np.arange(0, 361, 45))
    axr.set_xlabel("cam angle θ  [deg]")
    axr.set_ylabel("radius of curvature  [mm]")
    axr.legend(fontsize=8, loc="lower right")
    axr.grid(alpha=0.3)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path
