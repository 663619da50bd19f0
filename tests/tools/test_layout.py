"""The architecture's rules, checked: one source per table, registries, module size, relative imports."""
from __future__ import annotations

import ast
import re
from pathlib import Path

from cam_fmu.engine.solvers import SOLVERS
from cam_fmu.kinematics.presets import PRESETS
from cam_fmu.physics import parameters
from cam_fmu.physics.formulations import FORMULATIONS
from cam_fmu.physics.units import UNITS
from cam_fmu.physics.variables import INPUTS, OUTPUTS, STATES

PACKAGE = Path(__file__).resolve().parents[2] / "cam_fmu"
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
    from cam_fmu.control import pi

    units = {p.unit for p in (*parameters.PARAMETERS, *pi.PARAMETERS) if p.kind == "real"}
    units |= {row[1] for row in (*INPUTS, *OUTPUTS, *pi.INPUTS, *pi.OUTPUTS)}
    units |= {row[k] for row in STATES for k in (1, 2)}
    assert units - set(UNITS) == set()


def test_no_module_over_400_lines():
    long = {str(p.relative_to(PACKAGE)): n for p in MODULES if (n := len(p.read_text().splitlines())) > 400}
    assert long == {}


def test_no_c_file_over_700_lines():
    """The engine's C: one job per file (the FMI glue, the largest, included)."""
    sources = [*(PACKAGE / "engine" / "csrc").rglob("*.[ch]")]
    assert len(sources) >= 20
    long = {str(p.relative_to(PACKAGE)): n for p in sources if (n := len(p.read_text().splitlines())) > 700}
    assert long == {}


def test_imports_inside_the_package_are_relative():
    """So the package works under any name (a pythonfmu block's slave script, a top-level module in its FMU, excepted)."""
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
        if rel in (Path("engine/solvers.py"), Path("physics/formulations/__init__.py")):
            continue
        for k, line in enumerate(path.read_text().splitlines(), 1):
            if pattern.search(line):
                found.append(f"{rel}:{k}: {line.strip()}")
    assert found == []


def _package_imports(path: Path) -> set[str]:
    """Dotted names of the cam_fmu modules that module ``path`` imports (relative imports resolved;
    ``from . import x`` counts as importing the package and its member ``x``)."""
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    package = parts[:-1]  # a module's package; an __init__.py's parts end in "__init__": the package itself
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = ".".join(package[:len(package) - node.level + 1]) if node.level else ""
            module = ".".join(filter(None, (base, node.module)))
            found.add(module)
            found |= {f"{module}.{a.name}" for a in node.names}
    return {name for name in found if name.split(".")[0] == "cam_fmu"}


# The run-time engine: the reference's readable model must not use its code (FMU against reference is a
# check of two implementations).
ENGINE = ("cam_fmu.engine", "cam_fmu.fmu")


def _under(name: str, prefixes: tuple[str, ...]) -> bool:
    return any(name == p or name.startswith(p + ".") for p in prefixes)


def test_the_model_and_the_reference_import_nothing_of_the_engine():
    """physics, kinematics and reference never import the engine or the FMU layer: the scipy reference
    integrates physics, a model written independently of the code that runs in the FMU."""
    layers = [PACKAGE / layer for layer in ("physics", "kinematics", "reference")]
    checked = [p for p in MODULES if any(layer in p.parents for layer in layers)]
    assert len(checked) >= 20
    found = [f"{p.relative_to(PACKAGE)}: {name}" for p in checked for name in sorted(_package_imports(p))
             if _under(name, ENGINE)]
    assert found == []


def test_kinematics_imports_no_other_layer():
    kinematics = PACKAGE / "kinematics"
    found = [f"{p.relative_to(PACKAGE)}: {name}" for p in MODULES if kinematics in p.parents
             for name in sorted(_package_imports(p)) if not _under(name, ("cam_fmu.kinematics",))]
    assert found == []


def test_the_import_check_resolves_relative_imports():
    """The checks above see through relative imports (the package's only kind)."""
    assert "cam_fmu.physics.drive" in _package_imports(PACKAGE / "reference" / "integrate.py")
    assert "cam_fmu.engine.library" in _package_imports(PACKAGE / "engine" / "simulator.py")
    formulations = _package_imports(PACKAGE / "physics" / "formulations" / "__init__.py")
    assert "cam_fmu.physics.drive" in formulations
