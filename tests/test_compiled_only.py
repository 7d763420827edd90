"""The list of tests an interpreted run leaves out (tests/compiled_only.txt, read by conftest.py)."""

import ast
from pathlib import Path

from conftest import COMPILED_ONLY, compiled_only_entries, is_compiled_only

TESTS = Path(__file__).resolve().parent


def _functions(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return {n.name for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}


def test_every_entry_names_a_test_that_exists():
    entries = compiled_only_entries()
    assert entries, f"{COMPILED_ONLY} lists nothing"
    for entry in entries:
        module, _, name = entry.partition("::")
        path = TESTS.parent / module
        assert path.is_file(), f"{COMPILED_ONLY.name}: {entry}: no file {module}"
        assert path.name.startswith("test_"), entry
        if name:
            function = name.split("[", 1)[0].split("::")[-1]
            assert function in _functions(path), f"{COMPILED_ONLY.name}: {entry}: no test {function} in {module}"
    assert len(entries) == len(set(entries)), "an entry is listed twice"


def test_an_entry_covers_whole_names_and_their_parameters_only():
    entries = ["tests/test_a.py::test_b", "tests/test_c.py"]
    assert is_compiled_only("tests/test_a.py::test_b", entries)
    assert is_compiled_only("tests/test_a.py::test_b[1e-8]", entries)
    assert is_compiled_only("tests/test_c.py::test_x", entries)
    assert not is_compiled_only("tests/test_a.py::test_bc", entries)
    assert not is_compiled_only("tests/test_cd.py::test_x", entries)
    assert not is_compiled_only("tests/test_a.py::test_a", entries)


def test_comments_and_blank_lines_are_no_entries(tmp_path):
    listed = tmp_path / "list.txt"
    listed.write_text("# header\n\ntests/test_a.py::test_b  # 31 s\n   \n", encoding="utf-8")
    assert compiled_only_entries(listed) == ["tests/test_a.py::test_b"]
