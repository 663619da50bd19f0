"""The frequency response's figure: gain and phase of u -> omega_m and u -> omega over f (Agg backend)."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence


def plot_bode(measured: Any, analytic: Any, title: str, path: Path, extrema: Sequence[Any] = (),
              causes: Sequence[str] | None = None) -> Path:
    """A Bode plot of control.frequency Responses: measured as markers, the analytic response as lines, each located
    resonance (a triangle up) and anti-resonance (a triangle down) marked and labelled with its frequency.
    ``causes``: what each extremum is, added to its label (a turning drive's: 'harmonic 6', 'shaft', ...); then the
    legend calls the triangles maxima and minima, since not every one is a resonance."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, (gain, phase) = plt.subplots(2, 1, figsize=(8.0, 6.4), sharex=True)
    for name, color in (("motor", "tab:blue"), ("cam", "tab:orange")):
        H = getattr(measured, name)
        label = "motor speed omega_m" if name == "motor" else "cam speed omega"
        gain.loglog(measured.f, np.abs(H), "o", color=color, markersize=3, label=f"{label} (engine)")
        phase.semilogx(measured.f, np.degrees(np.unwrap(np.angle(H))), "o", color=color, markersize=3)
        if analytic is not None:
            exact = getattr(analytic, name)
            gain.loglog(analytic.f, np.abs(exact), "-", color=color, linewidth=1.0, label=f"{label} (linearised)")
            phase.semilogx(analytic.f, np.degrees(np.unwrap(np.angle(exact))), "-", color=color, linewidth=1.0)
    colors = {"motor": "tab:blue", "cam": "tab:orange"}
    for k, ex in enumerate(extrema):
        up = ex.kind == "resonance"
        gain.plot([ex.f], [ex.gain], "^" if up else "v", color=colors[ex.output], markersize=9,
                  markeredgecolor="black", zorder=5)
        note = f"{ex.f:.4g} Hz" + (f", {causes[k]}" if causes is not None and causes[k] else "")
        gain.annotate(note, (ex.f, ex.gain), textcoords="offset points", xytext=(6, 8 if up else -14),
                      fontsize=7, color=colors[ex.output])
    if extrema:
        up, down = (("resonance", "anti-resonance") if causes is None else ("maximum", "minimum"))
        gain.plot([], [], "^", color="grey", markeredgecolor="black", label=f"{up} (located)")
        gain.plot([], [], "v", color="grey", markeredgecolor="black", label=f"{down} (located)")
    gain.set_ylabel("|H| [(rad/s)/V]")
    gain.grid(True, which="both", alpha=0.3)
    gain.legend(fontsize=8)
    phase.set_ylabel("phase [deg]")
    phase.set_xlabel("frequency [Hz]")
    phase.grid(True, which="both", alpha=0.3)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
