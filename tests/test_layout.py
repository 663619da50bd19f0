"""The architecture's rules, checked: one source per table, registries, module size, relative imports."""
from __future__ import annotations

import ast
import math
import re
from pathlib import Path

from cam_fmu.fmu.camdrive_fmu_slave import DEFAULT_EXPERIMENT
from cam_fmu.fmu.model_description import BASE_UNITS
from cam_fmu.kinematics.presets import PRESETS
from cam_fmu.physics import parameters
from cam_fmu.physics.formulations import FORMULATIONS
from cam_fmu.physics.variables import INPUTS, OUTPUTS
from cam_fmu.solvers import SOLVERS
from cam_fmu.experiments.scenes import find_scene

PACKAGE = Path(__file__).resolve().parents[1] / "cam_fmu"
MODULES = sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def test_parameter_choices_are_the_registries():
    assert parameters.BY_NAME["solver"].choices == tuple(SOLVERS) == parameters.SOLVERS
    assert set(parameters.FORMULATIONS) | {"speed"} == set(FORMULATIONS)
    assert parameters.BY_NAME["formulation"].choices == parameters.FORMULATIONS
    assert parameters.LAW_CHOICES == (*PRESETS, "custom")
    assert parameters.BY_NAME["rise_law"].choices == parameters.BY_NAME["return_law"].choices == parameters.LAW_CHOICES


def test_every_formulation_has_a_reference():
    from cam_fmu.reference.integrate import REFERENCES
    assert set(REFERENCES) == set(FORMULATIONS)


def test_every_unit_in_use_has_base_units():
    units = {p.unit for p in parameters.PARAMETERS if p.kind == "real"}
    units |= {row[1] for row in INPUTS} | {row[1] for row in OUTPUTS}
    assert units - set(BASE_UNITS) == set()


def test_default_experiment_is_the_paper_fig6_scene():
    scene = find_scene("paper_fig6")
    assert DEFAULT_EXPERIMENT.start_time == 0.0
    assert math.isclose(DEFAULT_EXPERIMENT.stop_time, scene.stop_time)
    assert math.isclose(DEFAULT_EXPERIMENT.step_size, scene.output_interval)


def test_no_module_over_400_lines():
    """400 lines at most; a compiled module (kernel.COMPILED_MODULES) 800: it is one extension, whose
    methods call each other in C. Split in two, those calls would become Python calls, or cimports
    naming the package, which the FMU renames to its private name."""
    from cam_fmu.kernel import COMPILED_MODULES

    compiled = {PACKAGE / "kernel" / f"{name}.py" for name in COMPILED_MODULES}
    long = {str(p.relative_to(PACKAGE)): n for p in MODULES
            if (n := len(p.read_text().splitlines())) > (800 if p in compiled else 400)}
    assert long == {}


def test_each_pxd_is_the_twin_of_a_compiled_module():
    """The C types (.pxd, read by cam_fmu/kernel/compile.py) exist exactly for COMPILED_MODULES, beside their .py."""
    from cam_fmu.kernel import COMPILED_MODULES

    pxds = {p.relative_to(PACKAGE) for p in PACKAGE.rglob("*.pxd")}
    assert pxds == {Path("kernel") / f"{m}.pxd" for m in COMPILED_MODULES}
    assert all((PACKAGE / "kernel" / f"{m}.py").is_file() for m in COMPILED_MODULES)


def test_imports_inside_the_package_are_relative():
    """So the FMU's bundle can live under any package name (the slave scripts, top-level modules, excepted)."""
    absolute = []
    for path in MODULES:
        if path.name.endswith("_fmu_slave.py"):  # an FMU's slave script: a top-level module in its FMU
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names = [node.module or ""]
            absolute += [f"{path.relative_to(PACKAGE)}: {n}" for n in names if n.split(".")[0] == "cam_fmu"]
    assert absolute == []


def test_no_string_dispatch_on_solver_or_formulation_outside_the_registries():
    names = "|".join(map(re.escape, list(SOLVERS) + list(FORMULATIONS)))
    pattern = re.compile(rf"(==|!=)\s*[\"']({names})[\"']|[\"']({names})[\"']\s*(==|!=)")
    found = []
    for path in MODULES:
        rel = path.relative_to(PACKAGE)
        if rel in (Path("solvers/__init__.py"), Path("physics/formulations/__init__.py")):
            continue
        for k, line in enumerate(path.read_text().splitlines(), 1):
            if pattern.search(line):
                found.append(f"{rel}:{k}: {line.strip()}")
    assert found == []
