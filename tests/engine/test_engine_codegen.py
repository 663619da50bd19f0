"""The engine's variable table is generated from physics/parameters.py and physics/variables.py: a C
program compiled with the generated files prints the table, which must be the Python tables' (names,
value references, kinds, units, defaults, ranges, choices, presets), every number to the bit."""
from __future__ import annotations

import subprocess

from cam_fmu.engine import build, codegen
from cam_fmu.kinematics.presets import PRESETS
from cam_fmu.physics.parameters import PARAMETERS
from cam_fmu.physics.variables import INPUT_RANGES, INPUTS, OUTPUTS

PRINTER = r"""
#include <stdio.h>
#include "cam_params.h"
int main(void)
{
    int k, j;
    for (k = 0; k < CAM_N_PARAMS; k++) {
        const CamParamSpec *s = cam_param_spec(k);
        printf("P|%s|%s|%d|%u|%a|%s|%a|%a|%d|%d|", s->name, s->unit, (int)s->kind, s->vr, s->default_value,
               s->default_text ? s->default_text : "-", s->low, s->high, s->low_open, s->zero_ok);
        for (j = 0; j < s->n_choices; j++)
            printf("%s,", s->choices[j]);
        printf("|%s\n", s->description);
    }
    for (k = 0; k < CAM_N_INPUTS; k++) {
        const CamVariableSpec *s = cam_input_spec(k);
        printf("I|%s|%s|%u|%a|%a|%a|%s\n", s->name, s->unit, s->vr, s->start, s->low, s->high, s->description);
    }
    for (k = 0; k < CAM_N_OUTPUTS; k++) {
        const CamVariableSpec *s = cam_output_spec(k);
        printf("O|%s|%s|%u|%s\n", s->name, s->unit, s->vr, s->description);
    }
    for (k = 0; k < CAM_N_PRESETS; k++) {
        const double *T = cam_preset_T(k);
        printf("T|%a|%a|%a|%a|%a|%a\n", T[0], T[1], T[2], T[3], T[4], T[5]);
    }
    printf("N|%d|%d|%d|%d\n", cam_param_spec(CAM_N_PARAMS) == NULL, CAM_P_SOLVER, CAM_CHOICE_SOLVER_RK45,
           CAM_O_S_CAM);
    return 0;
}
"""


def _table(tmp_path) -> list[list[str]]:
    gen = tmp_path / "gen"
    files = codegen.write(gen)
    (tmp_path / "printer.c").write_text(PRINTER)
    exe = tmp_path / "printer"
    cmd = [build.find_compiler(), *build.CFLAGS, f"-I{gen}", str(tmp_path / "printer.c"),
           *(str(p) for p in files if p.name == codegen.SOURCE), "-o", str(exe)]  # the table stands alone
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    return [line.split("|") for line in out.splitlines()]


NUMBERS = {"P": (5, 7, 8), "I": (4, 5, 6), "T": (1, 2, 3, 4, 5, 6)}  # the %a fields of each row kind


def _numbers(row: list[str]) -> list:
    """The row with its numbers read back (C's %a and Python's hex() spell a double differently)."""
    return [float.fromhex(f) if k in NUMBERS.get(row[0], ()) else f for k, f in enumerate(row)]


def test_the_generated_table_is_the_python_tables(tmp_path):
    rows = [_numbers(row) for row in _table(tmp_path)]
    params = [r for r in rows if r[0] == "P"]
    assert len(params) == len(PARAMETERS)
    n_vars = len(INPUTS) + len(OUTPUTS)
    for k, (row, spec) in enumerate(zip(params, PARAMETERS)):
        if spec.kind == "string":
            default = float(spec.choices.index(spec.default)) if spec.choices else 0.0
        else:
            default = float(spec.default)
        expected = ["P", spec.name, spec.unit, str(["real", "boolean", "string"].index(spec.kind)), str(n_vars + k),
                    float(default), spec.default if spec.kind == "string" else "-",
                    float(spec.low), float(spec.high), str(int(spec.low_open)),
                    str(int(spec.zero_ok)), "".join(c + "," for c in spec.choices), spec.description]
        assert row == expected
    inputs = [r for r in rows if r[0] == "I"]
    assert inputs == [["I", name, unit, str(k), float(start), float(INPUT_RANGES[name][0]),
                       float(INPUT_RANGES[name][1]), desc] for k, (name, unit, start, desc) in enumerate(INPUTS)]
    outputs = [r for r in rows if r[0] == "O"]
    assert outputs == [["O", name, unit, str(len(INPUTS) + k), desc] for k, (name, unit, desc) in enumerate(OUTPUTS)]
    presets = [r[1:] for r in rows if r[0] == "T"]
    assert presets == [[float(t) for t in T] for T in PRESETS.values()]
    names = [p.name for p in PARAMETERS]
    solver = next(p for p in PARAMETERS if p.name == "solver")
    assert rows[-1] == ["N", "1", str(names.index("solver")), str(solver.choices.index("rk45")),
                        str([o[0] for o in OUTPUTS].index("s_cam"))]


def test_the_library_digest_follows_the_generated_text(monkeypatch):
    before = build.digest()
    monkeypatch.setattr(codegen, "generated", lambda: {"cam_params.h": "/* changed */", "cam_params.c": ""})
    assert build.digest() != before
