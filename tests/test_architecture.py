"""The layout shows the architecture: imports point one way, and no function grows unreadable.

Rooms of the package (toolkit/microimpact/) and what each may import from the others:
_runtime (the process's plumbing: signals, job logs, locks, progress bars, time budgets) -> nothing,
and every room may use it; model -> nothing; io -> model; solvers -> model, io; dynamics -> solvers; analysis -> dynamics;
studies -> analysis; report -> model, io only (it reads result files and runs no model); the CLI
and the package's ``__init__`` may import anything, and so may the ``__main__.py`` entry points. These are the rules of the architecture notes
(a study never imports the report; the report imports no solver), checked on the source text.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "toolkit" / "microimpact"

ALLOWED = {
    "_runtime": {"_runtime"},
    "model": {"model"},
    "io": {"io", "model", "_runtime"},
    "solvers": {"solvers", "model", "io", "_runtime"},
    "dynamics": {"dynamics", "solvers", "model", "io", "_runtime"},
    "analysis": {"analysis", "dynamics", "solvers", "model", "io", "_runtime"},
    "studies": {"studies", "analysis", "dynamics", "solvers", "model", "io", "presets", "_runtime"},
    "report": {"report", "model", "io", "_runtime"},
}
#: a function longer than this must say in its docstring why (see below)
MAX_LINES = 100


def _modules():
    return sorted(p for p in PACKAGE.rglob("*.py"))


def _room(path: Path) -> str | None:
    parts = path.relative_to(PACKAGE).parts
    return parts[0] if len(parts) > 1 else None


def _imported_rooms(tree: ast.AST) -> set[str]:
    rooms = set()
    for node in ast.walk(tree):
        names = []
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        for name in names:
            parts = name.split(".")
            if parts[0] == "microimpact" and len(parts) > 1:
                rooms.add(parts[1])
    return rooms


# ``__main__.py`` files are command-line entry points (``python -m ...``): they sit above every room
@pytest.mark.parametrize("path", [p for p in _modules() if _room(p) in ALLOWED and p.name != "__main__.py"],
                         ids=lambda p: str(p.relative_to(PACKAGE)))
def test_imports_point_one_way(path):
    room = _room(path)
    rooms = _imported_rooms(ast.parse(path.read_text())) - {"__version__"}
    # the package root itself (``from microimpact import __version__``) is not a room
    forbidden = {r for r in rooms if r not in ALLOWED[room] and ((PACKAGE / r).is_dir() or r == "cli")}
    assert not forbidden, f"{path.relative_to(PACKAGE)} ({room}) imports {sorted(forbidden)}"


def test_every_room_states_its_role():
    for room in ALLOWED:
        doc = ast.get_docstring(ast.parse((PACKAGE / room / "__init__.py").read_text()))
        assert doc and len(doc.split()) >= 8, room


def test_no_function_is_longer_than_about_100_lines_without_saying_why():
    too_long = []
    for path in _modules():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                doc = ast.get_docstring(node) or ""
                if length > MAX_LINES and "Length:" not in doc:
                    too_long.append(f"{path.relative_to(PACKAGE)}:{node.lineno} {node.name} ({length} lines)")
    assert not too_long, "\n".join(too_long)
