"""An FMI 3.0 Model Exchange host in C (tests/engine_c/me_host3.c: tests/engine_c/me_host.c's explicit Euler with
event handling, in FMI 3.0's calls) linked with cam3.fmu's functions and built with AddressSanitizer and UBSan: no
report, the refusals fmi3Error, and the same final state, to the bit, as the FMI 2.0 host on cam.fmu's functions
(one event update under both glues). gcc is required."""
from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from cam_fmu.engine import build as engine_build
from cam_fmu.engine import codegen
from cam_fmu.fmu.engine_fmu import binary_sources
from fmu_me import test_engine_fmu_me_host as host2
from native_support import require

HOST3 = Path(__file__).resolve().parents[1] / "engine_c" / "me_host3.c"


def compile_host3(folder: Path, extra: list[str]) -> Path:
    generated = [str(p) for p in codegen.write(folder / "gen") if p.suffix == ".c"]
    exe = folder / "me_host3"
    cmd = [require("gcc"), *host2.FLAGS, *extra, f'-DMODEL_GUID="{host2.GUID}"', f"-I{engine_build.INCLUDE}",
           f"-I{folder / 'gen'}", f"-I{engine_build.fmi_headers(3)}", *generated,
           *map(str, binary_sources("cam", 3)), str(HOST3), "-o", str(exe), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return exe


@pytest.mark.parametrize("params, step, stop", [(host2.BACKLASH, host2.STEP, host2.STOP),
                                                (host2.COMPLIANT, 1e-5, 0.1)], ids=["backlash", "compliant"])
def test_fmi3_euler_with_events_is_clean_and_is_the_fmi2_hosts_to_the_bit(tmp_path, params, step, stop):
    three = host2.run(compile_host3(tmp_path / "three", host2.SANITIZE), params=params, step=step, stop=stop)
    two = host2.run(host2.compile_host(tmp_path / "two", []), params=params, step=step, stop=stop)
    assert three["refused"] == [3, 3, 3, 3]  # wrong count, NULL out-argument, fmi3DoStep, NaN time
    assert three["paper"] == 3 and "fmi3ExitInitializationMode: formulation 'paper'" in three["out"]
    assert three["events"] == two["events"] and three["final"] == two["final"]
    assert three["final"][0] == pytest.approx(stop, rel=1e-12) and three["final"][1] > 0.1
