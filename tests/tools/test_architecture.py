"""docs/architecture.md's import rules, checked against the code (every import, parsed with ast).

- the layer table ("may import"): no layer imports one it does not list;
- the leaf modules the text names import nothing of the package;
- the four layers the FMU bundles import nothing outside themselves and `errors`;
- the upward imports the table calls "inside functions" or "for type hints only" are not executed at
  import time.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "cam_fmu"
DOC = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
BUNDLED = {"kinematics", "physics", "control"}
LEAVES = ("physics.variables", "experiments.signals", "errors")


def modules() -> dict[str, Path]:
    out = {}
    for f in PACKAGE.rglob("*.py"):
        parts = list(f.relative_to(PACKAGE).with_suffix("").parts)
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = f
    return out


def imports(name: str, path: Path) -> list[tuple[str, bool]]:
    """(imported module of the package, e.g. 'physics.variables'; at import time?) of one module."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    pkg = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    pkg = [p for p in pkg if p]
    top_level = {id(n) for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))}
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = pkg[: len(pkg) - node.level + 1]
            targets = [".".join(base + [node.module])] if node.module else \
                [".".join(base + [a.name]) for a in node.names]
            out += [(t, id(node) in top_level) for t in targets]
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names = [node.module] if isinstance(node, ast.ImportFrom) else [a.name for a in node.names]
            out += [(n.split(".", 1)[1], id(node) in top_level) for n in names if n and n.startswith("cam_fmu.")]
    return out


def layer(module: str) -> str:
    return module.split(".")[0]


def rule_table() -> dict[str, set[str]]:
    section = DOC[DOC.index("## Dependency direction"):DOC.index("## What the FMUs carry")]
    table = {}
    for row in re.findall(r"^\| `(\w+)` \|([^|]*)\|", section, flags=re.M):
        table[row[0]] = set(re.findall(r"`(\w+)`", row[1]))
    return table


def layers() -> set[str]:
    return {layer(m) for m in modules() if m and not m.startswith("__")}


def test_the_table_names_every_layer():
    assert set(rule_table()) == layers()


@pytest.mark.parametrize("name", sorted(layers()))
def test_a_layer_imports_only_what_the_table_allows(name):
    allowed = rule_table()[name] | {name}
    found = {}
    for module, path in modules().items():
        if module and layer(module) == name:
            for target, _ in imports(module, path):
                if target and layer(target) not in allowed and layer(target) != "__version__":
                    found.setdefault(layer(target), []).append(f"{module} -> {target}")
    assert not found, f"docs/architecture.md does not let {name!r} import: {found}"


@pytest.mark.parametrize("leaf", LEAVES)
def test_leaf_modules_import_nothing_of_the_package(leaf):
    assert f"`{leaf}`" in DOC
    assert imports(leaf, modules()[leaf]) == []
    if "." in leaf:  # nor does its package's __init__, which importing the leaf runs first
        assert imports(layer(leaf), modules()[layer(leaf)]) == []


def test_the_bundled_layers_stay_among_themselves():
    for name in BUNDLED:
        assert rule_table()[name] <= BUNDLED | {"errors"}, name


@pytest.mark.parametrize("importer,target", [("fmu.build", "experiments"), ("fmu.engine_fmu", "experiments"), ("plots.scene", "experiments"),
                                             ("experiments.scenes", "plots")])
def test_upward_imports_are_not_run_at_import_time(importer, target):
    found = [(t, top) for t, top in imports(importer, modules()[importer]) if layer(t) == target]
    assert found and not any(top for _, top in found), found


def test_every_test_file_the_code_and_docs_cite_exists():
    """A sentence citing tests/test_x.py is a promise; drift (a renamed or removed test file) breaks it."""
    cited = set()
    for path in [*PACKAGE.rglob("*.py"), *(ROOT / "docs").glob("*.md"), ROOT / "README.md"]:
        cited |= {(m, path.name) for m in re.findall(r"tests/((?:\w+/)?test_\w+\.py)", path.read_text(encoding="utf-8"))}
    missing = sorted((name, where) for name, where in cited if not (ROOT / "tests" / name).is_file())
    assert cited and not missing, missing
