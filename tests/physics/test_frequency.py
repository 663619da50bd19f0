"""The frequency response (control.frequency, `cam-fmu bode`): the C engine's small-signal response against
the analytic transfer function of the linearised drive (docs/model.md 12.3), and that model against the
two-mass closed forms of section 12.3."""
from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from cam_fmu.control.frequency import EXTREMUM_TOLERANCE, analytic_response, linear_model, locate_extrema
from cam_fmu.experiments.frequency import (MAX_HOLDS, MAX_INTERNAL_STEPS, OperatingPoint, measured_response,
                                           operating_point)
from cam_fmu.control.reflect import two_mass_frequencies
from cam_fmu.experiments.scenes import find_scene
from cam_fmu.physics.drive import DriveModel

SCENE = find_scene("compliant_shaft")
SHAFT = dict(SCENE.parameters, **SCENE.runs[0].overrides)
F = np.geomspace(3.0, 700.0, 6)  # Hz: below, around and above the resonance (207-363 Hz) and anti-resonance


def _difference(measured, exact) -> float:
    """The largest |measured - exact| relative to the peak of |exact| over the sweep."""
    return float(np.max(np.abs(measured - exact)) / np.max(np.abs(exact)))


@pytest.mark.parametrize("name, params, theta_deg, tol_motor", [
    ("compliant, constant s'", SHAFT, 60.0, 2e-3),
    ("compliant, L = 2 mH", dict(SHAFT, L=2e-3), 60.0, 2e-3),
    ("compliant, gravity's stiffness", dict(SHAFT, gamma=math.pi / 2, beta=math.pi, G=1.0), 20.0, 2e-3),
    ("rigid", dict(SHAFT, k_shaft=0.0), 60.0, 2e-3),
])
def test_the_engine_responds_as_the_linearised_drive_at_a_frozen_angle(name, params, theta_deg, tol_motor):
    theta0 = math.radians(theta_deg)
    exact = analytic_response(params, theta0, F)
    seen = measured_response(params, F, theta0=theta0)
    assert _difference(seen.motor, exact.motor) < tol_motor, name
    assert _difference(seen.cam, exact.cam) < 1e-4, name
    assert seen.u0 == exact.u0


def test_a_turning_drive_without_follower_is_the_linear_two_mass_system():
    """Without a follower the drive is linear while it turns (the shaft friction is a constant torque), so
    the response at a mean speed is the frozen one, at any angle."""
    params = dict(SHAFT, follower_inertia=False, gravity=False, guide_friction=False)
    seen = measured_response(params, F, u0=3.5)
    exact = analytic_response(params, 0.0, F)
    assert _difference(seen.motor, exact.motor) < 1e-3 and _difference(seen.cam, exact.cam) < 1e-3
    assert "turning under u0 = 3.5 V" in seen.note


def test_the_linear_model_has_the_two_mass_resonance_of_the_closed_form():
    """The oscillatory poles of the linearised drive (no back-EMF to speak of, no damping) sit at the
    resonance f_r of docs/model.md 12.3, and |H_motor| dips to nothing at the anti-resonance f_a."""
    quiet = dict(SHAFT, d_shaft=0.0, c_e=1e-6)
    for theta_deg in (0.0, 60.0, 100.0):
        theta0 = math.radians(theta_deg)
        A, _, _ = linear_model(quiet, theta0)
        pole = max(np.linalg.eigvals(A).imag) / (2.0 * math.pi)
        model = DriveModel(quiet)
        s1 = model.program.derivatives(theta0)[1]
        f_r, f_a = two_mass_frequencies(model.k_shaft, model.J_m, model.J_0 + model.m * s1 * s1)
        assert pole == pytest.approx(f_r, rel=1e-6)
        dip = analytic_response(quiet, theta0, [0.9 * f_a, f_a, 1.1 * f_a]).motor
        assert abs(dip[1]) < 1e-6 * min(abs(dip[0]), abs(dip[2]))


def test_an_unstable_standstill_and_a_cam_that_does_not_turn_are_refused():
    tilted = dict(SHAFT, gamma=math.pi / 2, beta=math.pi, G=1.0)
    with pytest.raises(ValueError, match="k_g"):
        measured_response(tilted, [10.0], theta0=math.radians(170.0))
    with pytest.raises(ValueError, match="does not turn"):
        measured_response(SHAFT, [10.0], u0=0.5)


def test_the_bode_command_writes_its_table_and_summary(tmp_path):
    done = subprocess.run([sys.executable, "-m", "cam_fmu", "bode", "compliant_shaft", "--theta", "60", "--fmin", "5",
                           "--fmax", "500", "--points", "4", "--json", "--out", str(tmp_path)],
                          capture_output=True, text=True, check=True)
    summary = json.loads(done.stdout)
    assert summary["motor_difference"] < 2e-3 and summary["cam_difference"] < 1e-4
    assert "frozen at theta0 = 1.0472 rad" in summary["operating_point"]
    lines = (tmp_path / "compliant_shaft_bode.csv").read_text().splitlines()
    assert lines[0].startswith("f [Hz],motor_gain [(rad/s)/V],motor_phase [deg]") and len(lines) == 5
    assert (tmp_path / "compliant_shaft_bode.png").stat().st_size > 10000


# ------------------------------------------------------------------ resonances and anti-resonances (located)
def _dense_extrema(params, theta0, lo, hi, output):
    """The extrema of the linearised drive's |H| between lo and hi [Hz], found independently of
    control.frequency's search: a 100,000-point log grid, each local extremum polished by scipy's bounded Brent
    search on ln f to 1e-9, kept where it stands out by 1 % from the curve's next turn on either side."""
    from scipy.optimize import minimize_scalar

    A, B, C = linear_model(params, theta0)
    row = 0 if output == "motor" else 1

    def gain(f):
        return abs(C[row] @ np.linalg.solve(2j * math.pi * f * np.eye(len(A)) - A, B))

    f = np.geomspace(lo, hi, 100_000)
    stacked = 2j * math.pi * f[:, None, None] * np.eye(len(A)) - A  # every (j w I - A) at once
    g = np.log(np.abs(np.linalg.solve(stacked, np.broadcast_to(B[:, None], (len(f), len(B), 1)))[:, :, 0] @ C[row]))
    found = []
    turns = [k for k in range(1, len(f) - 1) if (g[k] - g[k - 1]) * (g[k + 1] - g[k]) < 0]
    for j, k in enumerate(turns):
        kind = "resonance" if g[k] > g[k - 1] else "anti-resonance"
        left = g[turns[j - 1]] if j > 0 else g[0]
        right = g[turns[j + 1]] if j + 1 < len(turns) else g[-1]
        sign = 1.0 if kind == "resonance" else -1.0
        if sign * (g[k] - max(left, right) if kind == "resonance" else g[k] - min(left, right)) < math.log1p(0.01):
            continue
        best = minimize_scalar(lambda x: -sign * math.log(gain(math.exp(x))),
                               bounds=(math.log(f[k - 1]), math.log(f[k + 1])), method="bounded",
                               options={"xatol": 1e-9})
        found.append((kind, math.exp(best.x), gain(math.exp(best.x))))
    return found


TILTED = dict(SHAFT, gamma=math.pi / 2, beta=math.pi, G=1.0)


@pytest.mark.parametrize("params, theta_deg, grid", [
    (dict(SHAFT, L=2e-3), 100.0, (3.0, 700.0, 25)),
    (SHAFT, 60.0, (1.0, 1000.0, 9)),
    (TILTED, 20.0, (1.0, 1000.0, 31)),  # gravity's stiffness: a 3 Hz mode below the shaft's
    (dict(TILTED, k_shaft=0.0), 20.0, (0.5, 50.0, 7)),  # rigid: the gravity mode alone
    (dict(SHAFT, d_shaft=0.0, c_e=1e-6), 45.0, (10.0, 500.0, 400)),  # undamped: sharp, on a fine grid
], ids=["L=2mH 100deg", "60deg coarse", "tilted", "rigid tilted", "undamped fine"])
def test_every_extremum_is_located_as_the_independent_search_finds_it(params, theta_deg, grid):
    """control.frequency.locate_extrema on the linearised drive's sampled curve (the refinement evaluating the
    same curve) finds every resonance and anti-resonance an independent dense search finds in the grid's
    span, of the same kind, to its stated tolerance, and nothing else; an end of the grid is never one."""
    theta0 = math.radians(theta_deg)
    f = np.geomspace(*grid)
    sampled = analytic_response(params, theta0, f)
    found = locate_extrema(sampled, lambda fk: analytic_response(params, theta0, [fk]))
    for output in ("motor", "cam"):
        mine = [(e.kind, e.f, e.gain, e.tolerance) for e in found if e.output == output]
        truth = _dense_extrema(params, theta0, f[0], f[-1], output)
        gain = np.abs(getattr(sampled, output))
        # a coarse grid may step over an extremum (no sample turns there): only those whose neighbourhood the grid
        # turns in must be found; every one found is a true one
        seen = [t for t in truth if any(f[k - 1] < t[1] < f[k + 1] and (gain[k] - gain[k - 1]) * (gain[k + 1] - gain[k]) < 0
                                        for k in range(1, len(f) - 1))]
        assert [m[0] for m in mine] == [t[0] for t in seen], (output, mine, truth)
        for (kind, fk, gk, width), (_, f_true, g_true) in zip(mine, seen):
            assert width <= EXTREMUM_TOLERANCE
            assert abs(fk / f_true - 1.0) <= EXTREMUM_TOLERANCE, (output, kind, fk, f_true)
            assert (gk <= g_true * (1 + 1e-9)) if kind == "resonance" else (gk >= g_true * (1 - 1e-9))
    assert len(found) >= 1


def test_the_bode_command_locates_the_resonance_the_grid_steps_over(tmp_path):
    """L = 2 mH at a frozen 100 deg, 3-700 Hz, 25 points: the grid's largest sample is 224.79 Hz at 1.143, but
    the rotor's |H| peaks at 207.43 Hz at 3.584. Every extremum of both outputs is reported with its kind, on the
    engine and on the analytic curve, and agrees with the independent dense search."""
    done = subprocess.run([sys.executable, "-m", "cam_fmu", "bode", "compliant_shaft", "--set", "L=2e-3", "--theta",
                           "100", "--fmin", "3", "--fmax", "700", "--points", "25", "--json", "--out", str(tmp_path)],
                          capture_output=True, text=True, check=True)
    summary = json.loads(done.stdout)
    assert summary["extremum_tolerance"] == EXTREMUM_TOLERANCE
    params, theta0 = dict(SHAFT, L=2e-3), math.radians(100.0)
    for output in ("motor", "cam"):
        seen = [e for e in summary["extrema"] if e["output"] == output]
        truth = _dense_extrema(params, theta0, 3.0, 700.0, output)
        assert [e["kind"] for e in seen] == [t[0] for t in truth], output
        for e, (_, f_true, g_true) in zip(seen, truth):
            assert abs(e["f"] / f_true - 1.0) < 2 * EXTREMUM_TOLERANCE, (output, e, f_true)  # the engine's curve
            assert abs(e["f_analytic"] / f_true - 1.0) < 1e-6, (output, e, f_true)
            assert abs(e["gain"] / g_true - 1.0) < 2e-3, (output, e, g_true)
    rotor = [e for e in summary["extrema"] if e["output"] == "motor" and e["kind"] == "resonance"]
    assert len(rotor) == 1 and rotor[0]["f"] == pytest.approx(207.43, abs=0.2) and rotor[0]["gain"] == pytest.approx(3.584, rel=1e-3)
    assert (tmp_path / "compliant_shaft_bode.png").stat().st_size > 10000


# ------------------------------------------------------------------ what bode refuses, before it runs
def _bode(tmp_path, *args):
    done = subprocess.run([sys.executable, "-m", "cam_fmu", "bode", *args, "--out", str(tmp_path / "out")],
                          capture_output=True, text=True)
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(lines) == 1 and "Traceback" not in done.stderr, done.stderr[-2000:]
    assert not (tmp_path / "out").exists()
    return lines[0]


@pytest.mark.parametrize("args, option", [
    (["--theta", "100", "--fmin", "5000", "--fmax", "10000"], "--fmax 10000 Hz"),  # was a MemoryError at 5.5 GB
    (["--fmax", "1e9"], "--fmax 1e+09 Hz"),  # was 6.6 TiB asked
    (["--fmin", "1e-6", "--fmax", "1e-5"], "--fmin 1e-06 Hz"),  # was the engine's max_steps on a 1953 s step
])
def test_a_frequency_out_of_reach_is_refused_naming_the_reachable_range(tmp_path, args, option):
    line = _bode(tmp_path, "compliant_shaft", *args)
    assert line.startswith(f"cam-fmu bode: error: {option} is out of reach at this operating point: reachable ")
    theta0 = math.radians(float(args[1])) if args[0] == "--theta" else 0.0
    point = operating_point(SHAFT, theta0)
    lo, hi = point.reachable()
    assert f"reachable {lo:.4g} to {hi:.4g} Hz" in line


@pytest.mark.parametrize("settle, window, h_max", [(14.18, 0.0, 1e-3), (0.31, 0.0, 1e-3), (0.5, 3.0, 1e-4),
                                                    (0.0, 0.0, 1e-3), (200.0, 0.0, 1e-2)])
def test_the_reachable_range_is_where_the_work_is_bounded(settle, window, h_max):
    """Within the range a run holds at most MAX_HOLDS inputs and takes at most MAX_INTERNAL_STEPS internal steps
    (the simulated time / h_max, counted here from the settling rule); just outside it does not."""
    point = OperatingPoint({"h_max": h_max}, 0.0, settle, window, "")
    lo, hi = point.reachable()

    def work(f):
        settle_periods = max(20, math.ceil(settle * f))
        periods = max(10, math.ceil(window * f))
        holds = 64 * (settle_periods + periods)
        return holds, (settle_periods + periods) / f / h_max

    for f in np.geomspace(lo, hi, 50)[1:-1]:
        holds, internal = work(f)
        assert holds <= MAX_HOLDS and internal <= MAX_INTERNAL_STEPS, f
    assert work(lo * 0.999)[1] > MAX_INTERNAL_STEPS
    assert work(hi * 1.001)[0] > MAX_HOLDS or (settle == window == 0.0 and hi > 1e11)  # nothing grows with f
    with pytest.raises(ValueError, match="out of reach"):
        point.check([hi * 1.01])
    with pytest.raises(ValueError, match="no frequency is reachable"):  # settling alone beyond the internal steps
        OperatingPoint({"h_max": h_max}, 0.0, 2.0 * MAX_INTERNAL_STEPS * h_max, window, "").check([1.0])


def test_a_speed_drive_and_a_negative_amplitude_are_refused_with_their_reason(tmp_path):
    """`bode speed_drive` exited 0 with gain 0 (u plays no part in a speed drive); `--amplitude -1e-3` was
    argparse's "expected one argument"."""
    line = _bode(tmp_path, "speed_drive")
    assert "drive = 'speed'" in line and "u plays no part" in line and "'voltage'" in line
    assert _bode(tmp_path, "compliant_shaft", "--amplitude", "-1e-3") == \
        "cam-fmu bode: error: --amplitude -0.001 V: allowed > 0"
    with pytest.raises(ValueError, match="drive = 'speed'"):
        measured_response(dict(SHAFT, drive="speed"), [10.0], theta0=0.0)


def test_every_numeric_option_of_every_command_takes_a_negative_number_in_any_notation():
    """The class of `--amplitude -1e-3`: argparse took -1e-3 for an option. Every float or int option of every
    subcommand parses -1e-3 (float) or -3 (int) as its value, whatever the command then says of its range."""
    from cam_fmu.cli import build_parser

    parser = build_parser()
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices
    checked = 0
    for name, sub in commands.items():
        positionals = [(a.choices[0] if a.choices else "x") for a in sub._actions
                       if not a.option_strings and a.nargs in (None, 1)]
        for a in sub._actions:  # required options, with a value of theirs
            if a.option_strings and a.required:
                positionals += [a.option_strings[-1], *[str(a.choices[0]) if a.choices else "1"] *
                                (a.nargs if isinstance(a.nargs, int) else 1)]
        for action in sub._actions:
            if action.option_strings and action.type in (float, int):
                text = "-1e-3" if action.type is float else "-3"
                count = action.nargs if isinstance(action.nargs, int) else 1  # e.g. curve's --T takes six
                args = parser.parse_args([name, *positionals, action.option_strings[-1], *[text] * count])
                value = getattr(args, action.dest)
                assert (value if isinstance(action.nargs, int) else [value]) == [action.type(text)] * count, name
                checked += 1
    assert checked >= 10


# ------------------------------------------------------------------ a turning drive: what each extremum is
def _turning_frequency(params, u0: float, stop: float = 12.0) -> float:
    """Turns per second of the drive turning under u0 [V], from the scipy reference (independent of the engine
    and of bode's operating point): the last whole turn between two crossings of a multiple of 2 pi."""
    from cam_fmu.physics.signals import constant
    from cam_fmu.reference.integrate import simulate_reference

    run = simulate_reference(params, stop, 1e-3, u=constant(u0))
    t, theta = run["time"], run["theta"]
    turns = np.floor(theta / (2 * math.pi))
    k = np.nonzero(np.diff(turns))[0]
    crossings = [np.interp(2 * math.pi * turns[j + 1], theta[j:j + 2], t[j:j + 2]) for j in k[-2:]]
    return 1.0 / (crossings[1] - crossings[0])


def test_a_turning_drives_peaks_are_the_turnings_harmonics_not_resonances(tmp_path):
    """`bode --u0 3.5` called a peak of 174 (rad/s)/V at 8.23 Hz a resonance. On the rigid paper drive turning
    under 3.5 V (no mechanical resonance at all) every peak between 5 and 12 Hz is a multiple of the turning
    frequency: the 4th, 6th and 8th harmonics, hundreds of times the response between them, and even, as the
    paper's cam repeats its load every half turn (rise and return mirror images of a symmetric law). None is
    called a resonance, in the text or the JSON."""
    args = [sys.executable, "-m", "cam_fmu", "bode", "paper_fig6", "--u0", "3.5", "--fmin", "5", "--fmax", "12",
            "--points", "8", "--no-plot", "--out", str(tmp_path)]
    summary = json.loads(subprocess.run([*args, "--json"], capture_output=True, text=True, check=True).stdout)
    f_turn = _turning_frequency(dict(find_scene("paper_fig6").primary.params), 3.5)
    assert summary["f_turn"] == pytest.approx(f_turn, rel=1e-4) and summary["shaft_bands"] is None
    peaks = [e for e in summary["extrema"] if e["kind"] == "peak"]
    assert {e["kind"] for e in summary["extrema"]} <= {"peak", "dip"}  # a rigid shaft: nothing mechanical
    for e in summary["extrema"]:
        k = round(e["f"] / f_turn)
        if e["cause"] == "turning harmonic":
            assert e["kind"] == "peak" and e["harmonic"] == k and abs(e["f"] / (k * f_turn) - 1) < 5e-3, e
        else:
            assert e["cause"] == "neither" and e["harmonic"] is None, e
    harmonics = sorted({e["harmonic"] for e in peaks if e["cause"] == "turning harmonic"})
    assert harmonics == [4, 6, 8], summary["extrema"]
    dips = [e["gain"] for e in summary["extrema"] if e["kind"] == "dip"]
    assert min(e["gain"] for e in peaks) > 100 * max(dips)
    text = subprocess.run([*args[:7], "--fmin", "7.5", "--fmax", "9", "--points", "3", *args[-3:]],
                          capture_output=True, text=True, check=True).stdout  # the 6th harmonic alone, in words
    assert "resonance" not in text.replace("not a resonance", "").replace("no mechanical resonance", ""), text
    assert text.count(" speed: peak at ") == 2 and text.count(": the turning's harmonic 6 (6 x 1.3758") == 2, text


def test_what_an_extremum_of_a_turning_drive_is():
    """turning_cause: the shaft's band first (of the extremum's kind), then a maximum within half the fit's main
    lobe, 1 / (2 span), of a multiple of f_turn; a minimum is never a harmonic; anything else is neither."""
    from cam_fmu.control.frequency import turning_cause

    bands = {"resonance": (207.0, 363.0), "anti-resonance": (25.3, 300.0)}
    assert turning_cause(8.2242, "resonance", 1.37139, 1.46) == ("turning harmonic", 6)
    assert turning_cause(8.2242, "resonance", 1.37139, 1.46, bands) == ("turning harmonic", 6)
    assert turning_cause(8.2283 + 0.5 / 1.46 * 1.01, "resonance", 1.37139, 1.46) == ("neither", None)
    assert turning_cause(8.2283, "anti-resonance", 1.37139, 1.46) == ("neither", None)
    assert turning_cause(205.6, "resonance", 1.37139, 1.46, bands) == ("shaft", None)  # 0.7 % below f_r_min
    assert turning_cause(48.0, "anti-resonance", 1.37139, 1.46, bands) == ("shaft", None)
    assert turning_cause(48.0, "resonance", 1.37139, 1.46, bands) == ("turning harmonic", 35)
    assert turning_cause(400.0, "resonance", 1.37139, 1.46, bands) == ("neither", None)  # 10 % above the band
    cam = {"resonance": bands["resonance"], "anti-resonance": None}  # the cam's speed has no anti-resonance
    assert turning_cause(48.0, "anti-resonance", 1.37139, 1.46, cam) == ("neither", None)
    with pytest.raises(ValueError, match="f_turn"):
        turning_cause(8.0, "resonance", 0.0, 1.0)


def test_the_shaft_band_of_a_turning_drive_is_the_two_mass_closed_form():
    """bode's shaft bands are f_r and f_a of the rotor against the cam side J_cam + m s'^2 at the lightest and the
    heaviest angle (docs/model.md 12.3)."""
    from cam_fmu.cli.bode import shaft_bands

    model = DriveModel(SHAFT)
    s1 = np.array([model.program.derivatives(t)[1] for t in np.linspace(0, 2 * math.pi, 7201)])
    light, heavy = model.J_0 + model.m * (s1 ** 2).min(), model.J_0 + model.m * (s1 ** 2).max()
    bands = shaft_bands(SHAFT, 1.37)
    f_r_heavy, f_a_heavy = two_mass_frequencies(model.k_shaft, model.J_m, heavy)
    f_r_light, f_a_light = two_mass_frequencies(model.k_shaft, model.J_m, light)
    assert bands["resonance"] == pytest.approx([f_r_heavy, f_r_light], rel=1e-5)
    assert bands["anti-resonance"] == pytest.approx([f_a_heavy, f_a_light], rel=1e-5)
    assert shaft_bands(dict(SHAFT, k_shaft=0.0), 1.37) is None


TRAIN = {"k_train": 2e4, "m_end": 0.2}   # 50.3 Hz on its own (docs/model.md 14.6)


def test_the_engine_responds_as_the_linearised_drive_with_a_train():
    """The follower train in the frozen-angle response: the engine's measurement against the linear model with the
    end mass's two states, under vertical gravity (the end mass's weight in the holding voltage and gravity's
    stiffness); measured 2.9e-6 of the peak (an undamped train rings through the measuring window: 2.9e-4)."""
    params = dict(TRAIN, d_train=0.5, gamma=math.pi / 2)
    theta0 = math.radians(60.0)
    f = np.array([20.0, 45.0, 50.0, 55.0, 61.4, 90.0])
    exact = analytic_response(params, theta0, f)
    seen = measured_response(params, f, theta0=theta0)
    assert _difference(seen.cam, exact.cam) < 1e-4 and _difference(seen.motor, exact.motor) < 1e-4
    plain = analytic_response(dict(gamma=math.pi / 2), theta0, f)
    assert exact.u0 < plain.u0 < 0.0   # the end mass's weight held too


def test_a_train_is_an_anti_resonance_at_its_own_frequency_and_a_resonance_with_the_cam():
    """Undamped, gravity off, no back-EMF: the train's reaction on the cam is s'^2 m_end s^2 k / (m_end s^2 + k) in
    the cam's angle, infinite at s = j sqrt(k / m_end): |H| dips to nothing at f_a = sqrt(k / m_end) / (2 pi), and the
    cam (a mass J_c / s'^2 along X) on the train's spring with the end mass resonates at
    f_r = sqrt(k (1 / m_end + s'^2 / J_c)) / (2 pi), J_c = J_0 + m s'^2 (closed forms written here)."""
    quiet = dict(TRAIN, c_e=1e-6, gravity=False)
    for theta_deg in (30.0, 60.0, 100.0):
        theta0 = math.radians(theta_deg)
        model = DriveModel(quiet)
        s1 = model.program.derivatives(theta0)[1]
        J_c = model.J_0 + model.m * s1 * s1
        f_a = math.sqrt(2e4 / 0.2) / (2.0 * math.pi)
        f_r = math.sqrt(2e4 * (1.0 / 0.2 + s1 * s1 / J_c)) / (2.0 * math.pi)
        A, _, _ = linear_model(quiet, theta0)
        assert max(np.linalg.eigvals(A).imag) / (2.0 * math.pi) == pytest.approx(f_r, rel=1e-6)
        dip = analytic_response(quiet, theta0, [0.99 * f_a, f_a, 1.01 * f_a]).cam
        assert abs(dip[1]) < 1e-6 * min(abs(dip[0]), abs(dip[2]))
