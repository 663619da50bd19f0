"""Figure of a disc cam: contour, pitch curve, base and prime circles, the roller
at a few angles (cam frame, mm); pressure angle and radius of curvature over
the cycle with the check limits.  Headless: Agg backend."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..kinematics.design_checks import CheckReport, check_design  # noqa: E402
from ..kinematics.disc_cam import DiscCam  # noqa: E402


def plot_cam(cam: DiscCam, path: str | Path, report: CheckReport | None = None, title: str = "",
             roller_angles_deg=(0, 45, 90, 135, 180, 225, 270, 315), groove: bool = False) -> Path:
    """Write a PNG of `cam` (see the module docstring)."""
    rep = report or check_design(cam)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = plt.figure(figsize=(14, 7.5), constrained_layout=True)
    gs = fig.add_gridspec(2, 2, width_ratios=(1.1, 1.0))
    ax = fig.add_subplot(gs[:, 0])
    axa = fig.add_subplot(gs[0, 1])
    axr = fig.add_subplot(gs[1, 1], sharex=axa)
    fig.suptitle(title or "Disc cam with translating roller follower", fontsize=13)

    th = np.linspace(0.0, 2.0 * math.pi, 3601)
    mm = 1e3
    r_b, r_r = cam.base_radius, cam.roller_radius
    px, py = cam.pitch(th)
    cx, cy = cam.contour(th, "inner")
    circ = np.linspace(0.0, 2.0 * math.pi, 361)
    ax.fill(cx * mm, cy * mm, color="0.88", zorder=0)
    ax.plot(cx * mm, cy * mm, color="k", lw=1.8, label="contour (inner)")
    if groove:
        ox, oy = cam.contour(th, "outer")
        ax.plot(ox * mm, oy * mm, color="tab:green", lw=1.4, label="groove outer wall")
    ax.plot(px * mm, py * mm, color="tab:blue", lw=1.0, ls="--", label="pitch curve")
    rbc = cam.base_circle_radius
    ax.plot(rbc * mm * np.cos(circ), rbc * mm * np.sin(circ), color="0.4", lw=0.8, ls=":",
            label=f"base circle r_b - r_r = {rbc * mm:.4g} mm")
    ax.plot(r_b * mm * np.cos(circ), r_b * mm * np.sin(circ), color="tab:blue", lw=0.6, ls=":",
            label=f"prime circle r_b = {r_b * mm:.4g} mm")
    for deg in roller_angles_deg:
        t = math.radians(deg)
        x, y = cam.pitch(t)
        ax.plot((x + r_r * np.cos(circ)) * mm, (y + r_r * np.sin(circ)) * mm, color="tab:orange", lw=0.9)
        ax.plot([x * mm], [y * mm], ".", color="tab:orange", ms=3)
        ax.annotate(f"{deg:g}°", (x * mm, y * mm), textcoords="offset points", xytext=(4, 4),
                    fontsize=8, color="tab:orange")
    for a, b in rep.undercut_ranges:
        t = np.linspace(a, b if b > a else b + 2.0 * math.pi, 200)
        ux, uy = cam.contour(t, "inner")
        ax.plot(ux * mm, uy * mm, color="tab:red", lw=3, label="undercut")
    ax.plot([0], [0], "k+", ms=10)
    e_mm = -cam.offset * mm                                  # the follower axis is y = -e
    ax.annotate("", xy=(0.25 * r_b * mm, e_mm), xytext=(0.0, e_mm),
                arrowprops=dict(arrowstyle="->", color="0.3"))
    ax.text(0.26 * r_b * mm, e_mm, "X (follower axis, y = -e)", fontsize=8, va="center", color="0.3")
    ax.set_aspect("equal")
    ax.set_xlabel("x  [mm]  (cam frame at θ = 0; cam turns counterclockwise)")
    ax.set_ylabel("y  [mm]")
    ax.grid(alpha=0.25)
    handles, labels = ax.get_legend_handles_labels()
    uniq = dict(zip(labels, handles))
    ax.legend(uniq.values(), uniq.keys(), loc="lower left", fontsize=8)
    ax.set_title(f"roller r_r = {r_r * mm:.4g} mm (orange, at the angles marked), offset e = "
                 f"{cam.offset * mm:.4g} mm", fontsize=10)

    deg = np.degrees(th)
    alpha = np.degrees(cam.pressure_angle(th))
    lim = math.degrees(rep.limits.max_pressure_angle)
    axa.plot(deg, alpha, lw=1.5)
    for sgn in (1, -1):
        axa.axhline(sgn * lim, color="tab:red", lw=0.9, ls="--")
    axa.plot([math.degrees(rep.max_pressure_angle_at)],
             [math.degrees(cam.pressure_angle(rep.max_pressure_angle_at))], "o", color="tab:red")
    axa.set_ylabel("pressure angle α  [deg]")
    axa.set_title(f"max |α| = {math.degrees(rep.max_pressure_angle):.4g} deg at θ = "
                  f"{math.degrees(rep.max_pressure_angle_at):.4g} deg (limit ±{lim:.3g} deg)", fontsize=10)
    axa.grid(alpha=0.3)

    rho_p = cam.pitch_radius_of_curvature(th) * mm
    rho_c = rho_p - r_r * mm
    clip = 4.0 * r_b * mm
    axr.plot(deg, np.where(np.abs(rho_p) < clip, rho_p, np.nan), lw=1.2, ls="--", label="pitch ρ_p")
    axr.plot(deg, np.where(np.abs(rho_c) < clip, rho_c, np.nan), lw=1.5, color="k", label="contour ρ_p - r_r")
    rho_lim = (rep.limits.min_radius_of_curvature
               if rep.limits.min_radius_of_curvature is not None else r_r) * mm
    axr.axhline(rho_lim, color="tab:red", lw=0.9, ls="--", label=f"limit {rho_lim:.3g} mm")
    axr.axhline(0.0, color="0.5", lw=0.6)
    axr.plot([math.degrees(rep.min_radius_at)], [rep.min_radius_of_curvature * mm], "o", color="tab:red")
    axr.set_ylim(-clip, clip)
    axr.set_xlim(0, 360)
    axr.set_xticks(np.arange(0, 361, 45))
    axr.set_xlabel("cam angle θ  [deg]")
    axr.set_ylabel("radius of curvature  [mm]\n(> 0 convex, |ρ| > 4 r_b hidden)")
    axr.set_title(f"min contour ρ on convex parts = {rep.min_radius_of_curvature * mm:.4g} mm at θ = "
                  f"{math.degrees(rep.min_radius_at):.4g} deg" + ("   UNDERCUT" if rep.undercut else ""),
                  fontsize=10)
    axr.legend(fontsize=8, loc="lower right")
    axr.grid(alpha=0.3)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
