"""Every CLI error is one line `cam-fmu CMD: error: ...` with exit status 2, never a traceback."""
from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = str(ROOT / "README.md")
BINARY = sys.executable  # a binary file given as a scene

CASES = [
    (["curve", "--base-radius-mm", "-5"], "curve", "--base-radius-mm -5: allowed a number > 0"),
    (["simulate", "paper_fig6", "--engine", "fmu", "--fmu", README], "simulate", "is not an FMU"),
    (["simulate", "paper_fig6", "--out", README], "simulate", "--out"),
    (["simulate", BINARY], "simulate", "not a scene file"),
    (["simulate", "paper_fig6", "--set", "m=-1"], "simulate", "'m' = -1.0 [kg] is outside the allowed range"),
    (["simulate", "paper_fig6", "--set", "mass=1"], "simulate", "unknown parameter 'mass'"),
    (["sweep", "paper_fig6", "--vary", "m=1:2"], "sweep", "NAME=START:STOP:N"),
    (["sweep", "paper_fig6", "--vary", "m=0:1:2", "--metric", "bogus", "--serial"], "sweep", "--metric bogus"),
    (["sweep", BINARY, "--vary", "m=0:1:2"], "sweep", "not a scene file"),
    (["cosim", README], "cosim", "not an SSP file"),
    (["cosim", "--set", "controller.kp=-1"], "cosim", "'kp' = -1.0"),
    # issue 20: inputs that ended in a traceback; what a command allocates is bounded (experiments/limits.py)
    (["cosim", "--step-size", "1e-9", "--no-plot"], "cosim", "= 2e+09 steps; at most 1,000,000 steps per run"),
    (["cosim", "--stop-time", "1e9", "--no-plot"], "cosim", "= 1e+12 steps; at most 1,000,000 steps per run"),
    (["cosim", "{long_ssp}", "--no-plot"], "cosim", "1e+12 s / 0.001 s = 1e+15 steps"),
    (["cosim", "{fine_ssp}", "--no-plot"], "cosim", "2 s / 1e-12 s = 2e+12 steps"),
    (["curve", "--rise-deg", "1e-300"], "curve", "rise and return angles must be >= 0.000174533 rad (0.01 deg)"),
    (["contour", "--rise-deg", "1e-300", "--roller-radius-mm", "5"], "contour", "rise_angle=1.745"),
    (["contour", "--rpm", "1e300", "--roller-radius-mm", "5"], "contour", "--rpm must be a number > 0 and <= 1e+06"),
    (["sweep", "paper_fig6", "--vary", "m=0:1:100000000"], "sweep", "N = 100000000: allowed 2 <= N <= 10000000"),
    (["sweep", "paper_fig6", "--vary", "m=0:1:4000", "--vary", "mu=0:0.1:4000"],
     "sweep", "4000 x 4000 = 16000000 cases; at most 10000000"),
    (["sweep", "paper_fig6", "--vary", "drive=speed", "--serial"], "sweep",
     "drive = 'speed' needs the input signal 'omega_ref'"),
    (["simulate", "paper_fig6", "--stop-time", "1e9"], "simulate", "= 1e+12 steps; at most 1,000,000"),
    (["simulate", "{huge_u_scene}"], "simulate", "reaches 1e+09 V, outside the allowed range of the input 'u'"),
    (["simulate", "{steep_speed_scene}"], "simulate", "outside the allowed range of the input 'omega_dot_ref'"),
    (["simulate", "paper_fig6", "--engine", "fmu", "--fmu", "{cam_fmu}", "--set", "max_steps=1", "--stop-time", "0.01",
      "--no-plot"],
     "simulate", "engine 'fmu' ({cam_fmu}): fmi2DoStep: solver 'rk45' needed more than max_steps = 1"),
    (["bench", "--fmu", "{pi_speed_fmu}", "--out", "out"], "bench", "is not a cam.fmu: it lacks"),
]


@pytest.fixture(scope="module")
def files(tmp_path_factory, cam_fmu_path) -> dict:
    """What the {placeholders} of CASES name: SSPs with extreme experiments, scenes, FMUs."""
    from cam_fmu.fmu.ssp import speed_loop_system, write_ssp

    d = tmp_path_factory.mktemp("cli_inputs")
    fake = d / "fake.fmu"  # read_ssp checks the FMUs' form; the step bound is checked before any loads
    with zipfile.ZipFile(fake, "w") as z:
        z.writestr("modelDescription.xml", "<fmiModelDescription/>")
    fmus = {"cam": fake, "controller": fake}
    (d / "huge_u.toml").write_text("u = 1e9\nstop_time = 0.1\noutput_interval = 1e-3\n")
    (d / "steep.toml").write_text('drive = "speed"\nomega_ref = {type = "ramp", start = 0, stop = 1e-9, '
                                  'from = 0, to = 10}\nstop_time = 0.1\noutput_interval = 1e-3\n')
    # pi_speed.fmu: any FMU that is not a cam.fmu (a model description with the controller's variables)
    pi = d / "pi_speed.fmu"
    with zipfile.ZipFile(pi, "w") as z:
        z.writestr("modelDescription.xml", PI_LIKE_MD)
    return {"long_ssp": write_ssp(speed_loop_system(stop_time=1e12), fmus, d / "long.ssp"),
            "fine_ssp": write_ssp(speed_loop_system(step_size=1e-12), fmus, d / "fine.ssp"),
            "huge_u_scene": d / "huge_u.toml", "steep_speed_scene": d / "steep.toml",
            "pi_speed_fmu": pi, "cam_fmu": cam_fmu_path}


PI_LIKE_MD = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="pi_speed" guid="{00000000-0000-0000-0000-000000000000}">
  <CoSimulation modelIdentifier="pi_speed"/>
  <ModelVariables>
    <ScalarVariable name="omega_meas" valueReference="0" causality="input" variability="continuous">
      <Real start="0"/></ScalarVariable>
    <ScalarVariable name="u" valueReference="1" causality="output" variability="continuous"><Real/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2"/></Outputs></ModelStructure>
</fmiModelDescription>
"""


@pytest.mark.parametrize("args,command,message", CASES, ids=[" ".join(c[0][:2]) + f" #{k}" for k, c in enumerate(CASES)])
def test_one_line_error_exit_2(args, command, message, tmp_path, files):
    args = [a.format(**files) for a in args]
    proc = subprocess.run([sys.executable, "-m", "cam_fmu.cli", *args], capture_output=True, text=True,
                          cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT), "CAM_FMU_PROGRESS": "0"},
                          timeout=300)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"cam-fmu {command}: error: "), proc.stderr
    assert message.format(**files) in lines[0] and "Traceback" not in proc.stderr
    assert "[ERROR]" not in proc.stdout  # an FMU's log lines are the error line's cause, not stdout's
