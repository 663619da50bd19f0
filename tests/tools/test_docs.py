"""The documentation runs as written and stands on its own.

- Every ```python block of README.md and docs/*.md runs as pasted: in a fresh
  temporary folder, in its own interpreter, with this checkout first on
  PYTHONPATH, and exits with status 0. A block that is deliberately not
  runnable uses another fence language (```text, ```bash, ```toml).
- Every relative link of those files points to a file that exists, and to a
  heading of it when the link has an anchor.
- Every ``cam_fmu.x.y`` name they mention imports (module or attribute), and
  every ``cam_fmu/...``, ``tests/...`` and ``docs/...`` path they mention exists:
  a restructure cannot leave stale paths behind.
- No tracked text file mentions the project notes outside the repository.
"""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC_FILES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```([^\n`]*)\n(.*?)^```[ \t]*$", re.M | re.S)
# Built from parts so that this file does not match itself.
OUTSIDE_REFERENCES = ("MODEL" + ".md", "../" + "shared")


def _blocks(language: str) -> list[tuple[str, str]]:
    """(id 'FILE:LINE', code) of every fenced block of ``language``."""
    found = []
    for path in DOC_FILES:
        text = path.read_text(encoding="utf-8")
        for match in FENCE.finditer(text):
            if match.group(1).strip() == language:
                line = text.count("\n", 0, match.start()) + 1
                found.append((f"{path.relative_to(ROOT)}:{line}", match.group(2)))
    return found


PYTHON_BLOCKS = _blocks("python")


def _env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PYTHONPATH"] = str(ROOT)  # this checkout, whatever is installed
    env["MPLBACKEND"] = "Agg"
    return env


def test_the_docs_have_python_blocks():
    files = {block_id.split(":")[0] for block_id, _ in PYTHON_BLOCKS}
    assert "README.md" in files and len(PYTHON_BLOCKS) >= 5, files


@pytest.mark.parametrize("code", [code for _, code in PYTHON_BLOCKS], ids=[i for i, _ in PYTHON_BLOCKS])
def test_python_block_runs_as_pasted(code, tmp_path):
    script = tmp_path / "block.py"
    script.write_text(code, encoding="utf-8")
    proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=_env(),
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"exit {proc.returncode}\n--- stdout\n{proc.stdout[-3000:]}\n--- stderr\n{proc.stderr[-3000:]}"


def _anchor(heading: str) -> str:
    """GitHub's anchor of a Markdown heading."""
    text = heading.strip().lower().replace("`", "")
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def _anchors(path: Path) -> set[str]:
    text = FENCE.sub("", path.read_text(encoding="utf-8"))
    return {_anchor(m.group(1)) for m in re.finditer(r"^#+\s+(.*)$", text, re.M)}


def test_relative_links_resolve():
    broken = []
    for path in DOC_FILES:
        text = FENCE.sub("", path.read_text(encoding="utf-8"))
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"[a-z]+:", target):
                continue  # http(s), mailto
            file_part, _, anchor = target.partition("#")
            dest = (path.parent / file_part).resolve() if file_part else path
            if not dest.exists():
                broken.append(f"{path.name}: {target} (no such file)")
            elif anchor and dest.suffix == ".md" and anchor not in _anchors(dest):
                broken.append(f"{path.name}: {target} (no such heading)")
    assert not broken, "\n".join(broken)


CHECK_NAMES = r"""
import importlib, json, sys
bad = []
for name in json.loads(sys.argv[1]):
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:k]))
        except ImportError:
            continue
        try:
            for attr in parts[k:]:
                obj = getattr(obj, attr)
        except AttributeError:
            bad.append(name)
        break
    else:
        bad.append(name)
print(json.dumps(bad))
"""


def test_module_names_and_paths_in_the_docs_exist():
    names, paths = set(), set()
    for path in DOC_FILES:
        text = path.read_text(encoding="utf-8")
        names.update(n.rstrip(".") for n in re.findall(r"\bcam_fmu(?:\.[A-Za-z_]\w*)+", text))
        paths.update(p.rstrip(".,:;") for p in re.findall(r"(?<![\w/.])((?:cam_fmu|tests|docs)/[\w/.*-]+)", text))
    missing_paths = sorted(p for p in paths if not any(ROOT.glob(p)))
    assert not missing_paths, f"paths in the docs that do not exist: {missing_paths}"
    proc = subprocess.run([sys.executable, "-c", CHECK_NAMES, json.dumps(sorted(names))], cwd=ROOT,
                          env=_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert json.loads(proc.stdout.splitlines()[-1]) == [], "names in the docs that do not import"


def _tracked_text_files() -> list[Path]:
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
        files = [ROOT / name for name in out.decode().split("\0") if name]
    except (OSError, subprocess.CalledProcessError):  # not a git checkout: every file but build outputs
        skip = {".git", "build", "dist", "out", "__pycache__", ".pytest_cache", ".hypothesis", ".benchmarks"}
        files = [p for p in ROOT.rglob("*") if p.is_file() and not skip & set(p.relative_to(ROOT).parts)]
    texts = []
    for path in files:
        try:
            path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, FileNotFoundError):
            continue  # binary (the figure) or deleted in the work tree
        texts.append(path)
    return texts


def test_the_repository_stands_on_its_own():
    files = _tracked_text_files()
    assert any(p.name == "README.md" for p in files)
    offenders = [f"{p.relative_to(ROOT)}: {needle}" for p in files for needle in OUTSIDE_REFERENCES
                 if needle in p.read_text(encoding="utf-8")]
    assert not offenders, "\n".join(offenders)
