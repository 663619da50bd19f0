"""docs/architecture.md's import rules, checked against the code (every import, parsed with ast).

- the layer table ("may import"): no layer imports one it does not list;
- the table is a stack: its rows run from the bottom up and no layer may import one of a later row;
- the graph of the layers' imports, read from the code alone (every import, deferred ones and those for
  type hints included), has no cycle;
- the leaf modules the text names import nothing of the package;
- the model's layers (kinematics, physics, control: the readable model and the tables the C is generated from)
  import nothing outside themselves and `errors`.
"""
from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "cam_fmu"
DOC = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
MODEL_LAYERS = {"kinematics", "physics", "control"}
LEAVES = ("physics.variables", "physics.signals", "errors")


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
    """layer -> the layers it may import, in the table's order (from the bottom up)."""
    section = DOC[DOC.index("## Dependency direction"):DOC.index("## What the FMUs carry")]
    table = {}
    for row in re.findall(r"^\| `(\w+)` \|([^|]*)\|", section, flags=re.M):
        table[row[0]] = set(re.findall(r"`(\w+)`", row[1]))
    return table


def layer_graph() -> dict[str, set[str]]:
    """layer -> the other layers its modules import, from the code."""
    graph: dict[str, set[str]] = {}
    for module, path in modules().items():
        if module and not module.startswith("__"):
            for target, _ in imports(module, path):
                if target and layer(target) not in (layer(module), "__version__"):
                    graph.setdefault(layer(module), set()).add(layer(target))
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Cycles of a directed graph, one per back edge of a depth-first search (none: the graph is acyclic)."""
    found, state = [], {}

    def visit(node: str, path: list[str]) -> None:
        state[node] = "open"
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                found.append(path[path.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, path + [nxt])
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    return found


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


def test_the_table_is_a_stack():
    order = list(rule_table())
    upward = {name: sorted(allowed - set(order[:order.index(name)])) for name, allowed in rule_table().items()}
    assert not {k: v for k, v in upward.items() if v}, f"layers listing a layer of their own row or a later one: {upward}"


def test_no_cycle_between_layers():
    assert cycles(layer_graph()) == []


def test_the_cycle_check_finds_cycles():
    """The check above could fail: the finder sees a two-layer cycle, a longer one, and none in a stack."""
    assert cycles({"fmu": {"experiments"}, "experiments": {"fmu", "physics"}}) == [["experiments", "fmu", "experiments"]]
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c", "a"]]
    assert cycles({"cli": {"tools", "physics"}, "tools": {"physics"}}) == []


@pytest.mark.parametrize("leaf", LEAVES)
def test_leaf_modules_import_nothing_of_the_package(leaf):
    assert f"`{leaf}`" in DOC
    assert imports(leaf, modules()[leaf]) == []
    if "." in leaf:  # nor does its package's __init__, which importing the leaf runs first
        assert imports(layer(leaf), modules()[layer(leaf)]) == []


def test_the_model_layers_stay_among_themselves():
    for name in MODEL_LAYERS:
        assert rule_table()[name] <= MODEL_LAYERS | {"errors"}, name


def test_every_test_file_the_code_and_docs_cite_exists():
    """A sentence citing tests/test_x.py is a promise; drift (a renamed or removed test file) breaks it."""
    cited = set()
    for path in [*PACKAGE.rglob("*.py"), *(ROOT / "docs").glob("*.md"), ROOT / "README.md"]:
        cited |= {(m, path.name) for m in re.findall(r"tests/((?:\w+/)?test_\w+\.py)", path.read_text(encoding="utf-8"))}
    missing = sorted((name, where) for name, where in cited if not (ROOT / "tests" / name).is_file())
    assert cited and not missing, missing
