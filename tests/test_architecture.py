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
import io
import tokenize
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
#: no function of the package has more lines of code than this (docstrings, blank lines and
#: comment-only lines aside; see test_no_function_has_more_than_100_lines_of_code)
MAX_CODE_LINES = 100


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


def _code_lines(source: str) -> set[int]:
    """Line numbers of the source that hold code: not blank, not only a comment, not a docstring."""
    lines = set()
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type not in _NOT_CODE:
            lines.update(range(tok.start[0], tok.end[0] + 1))
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
                lines -= set(range(first.lineno, first.end_lineno + 1))
    return lines


_NOT_CODE = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT, tokenize.ENCODING,
             tokenize.ENDMARKER}


def too_long_functions(package: Path, limit: int = MAX_CODE_LINES) -> list[str]:
    """The functions (nested ones too) of the package's modules whose body, from its first statement
    after the docstring to its end, has more than ``limit`` lines of code (:func:`_code_lines`)."""
    found = []
    for path in sorted(package.rglob("*.py")):
        source = path.read_text()
        code = _code_lines(source)
        for node in ast.walk(ast.parse(source)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = sum(1 for line in range(node.body[0].lineno, node.end_lineno + 1) if line in code)
                if n > limit:
                    found.append(f"{path.relative_to(package)}:{node.lineno} {node.name} ({n} lines of code)")
    return found


def test_code_lines_are_counted_without_docstrings_comments_or_blank_lines(tmp_path):
    body = "\n".join(f"    x{i} = {i}" for i in range(4))
    (tmp_path / "m.py").write_text(f'''def f():
    """A docstring
    of three lines.
    """
    # a comment

{body}
    s = """a string
    over two lines"""
''')
    assert too_long_functions(tmp_path, limit=6) == []
    assert too_long_functions(tmp_path, limit=5) == ["m.py:1 f (6 lines of code)"]


def test_no_function_has_more_than_100_lines_of_code():
    too_long = too_long_functions(PACKAGE)
    assert not too_long, "\n".join(too_long)
