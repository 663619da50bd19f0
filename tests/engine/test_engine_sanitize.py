"""The engine's motion table parser under AddressSanitizer and UBSan (gcc, a required tool).

tests/engine_c/fuzz_driver.c runs the libFuzzer entry cam_fmu/engine/csrc/fuzz/fuzz_table.c
(its promises: every refusal has a message, an accepted table's curve stays within its
lifts and reproduces its rows) on the bad inputs below and on a short fixed-seed run of
random bytes and table fragments. Any sanitizer report or broken promise fails the test.
"""
from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from cam_fmu.engine import codegen
from cam_fmu.engine.build import CSRC, INCLUDE, SOURCES
from native_support import require

DRIVER = Path(__file__).resolve().parents[1] / "engine_c" / "fuzz_driver.c"
FLAGS = ["-std=c99", "-O1", "-g", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror", "-pedantic",
         "-fsanitize=address,undefined", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer"]

BAD_INPUTS = [b"0,O\n90,1\n", b"\xef\xbb\xbf", b"\xef\xbb", b"0,0\n90,", b"0,0\n90,1e", b"0,0\n90,1\r",
              b"0,0\n90,1\n90,2\n", b"0,0\n" + b"9" * 5000 + b",1\n", b"\x00\x01\xff\xfe", b"#", b"0,0,0,0\n",
              b"\xc3", b"0\t\t\t;;;,,, 1\r\n359.9999999,0\n", b"0,0\n360,0\n360,0\n", b"nan,nan\n", b"-0,-0\n1,1\n"]


@pytest.fixture(scope="module")
def driver(tmp_path_factory):
    gcc = require("gcc")
    folder = tmp_path_factory.mktemp("engine_c")
    exe = folder / "fuzz_driver"
    generated = [str(p) for p in codegen.write(folder / "gen") if p.suffix == ".c"]  # the variable table
    sources = sorted(str(p) for p in SOURCES.glob("*.c")) + generated
    cmd = [gcc, *FLAGS, f"-I{INCLUDE}", f"-I{folder / 'gen'}", *sources, str(CSRC / "fuzz" / "fuzz_table.c"),
           str(DRIVER), "-o", str(exe), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return exe


def run(exe, *args):
    proc = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=600,
                          env={"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0", "UBSAN_OPTIONS": "print_stacktrace=1"})
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr[-3000:]
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout


def test_bad_inputs_are_clean_under_asan_and_ubsan(driver, tmp_path):
    files = []
    for k, data in enumerate(BAD_INPUTS):
        path = tmp_path / f"bad{k}.csv"
        path.write_bytes(data)
        files.append(path)
    assert run(driver, "-n", 0, *files).strip() == f"ok {len(files)}"


def test_a_fixed_seed_run_of_random_bytes_is_clean(driver):
    assert run(driver, "-n", 3000, "-s", 19).strip() == "ok 3000"


def test_the_driver_fails_on_a_broken_promise(driver, tmp_path):
    """The harness is not vacuous: a sanitizer report fails the run (here: a deliberate overflow)."""
    gcc = require("gcc")
    src = tmp_path / "broken.c"
    src.write_text("#include <stdint.h>\n#include <stddef.h>\n#include <stdlib.h>\n"
                   "int LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) {\n"
                   "    volatile char *p = malloc(4); p[4 + (n > 1000)] = 1; free((void *)p); (void)d; return 0; }\n")
    exe = tmp_path / "broken"
    subprocess.run([gcc, *FLAGS[:-4], "-fsanitize=address", str(src), str(DRIVER), "-o", str(exe)], check=True)
    proc = subprocess.run([str(exe), "-n", "1"], capture_output=True, text=True)
    assert proc.returncode != 0 and "AddressSanitizer" in proc.stderr
