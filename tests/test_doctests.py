"""Every docstring example of the package runs and prints what it says (the Examples sections of
the API reference). One test per module, so a failure names the module and the example."""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import microimpact

MODULES = sorted(m.name for m in pkgutil.walk_packages(microimpact.__path__, "microimpact.")
                 if not m.name.endswith("__main__"))
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def test_every_module_is_found():
    """The walk sees the packages and their modules (a broken walk would pass every test below)."""
    assert {"microimpact.cli", "microimpact.model.law", "microimpact.solvers.engine",
            "microimpact.analysis.fitting", "microimpact._runtime.joblog"} <= set(MODULES)


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an example that writes a file writes it here
    module = importlib.import_module(name)
    tests = [t for t in doctest.DocTestFinder(exclude_empty=True).find(module, name)
             if t.examples and getattr(t, "filename", None) and t.name.startswith(name)]
    if not tests:
        pytest.skip(f"{name} has no docstring examples")
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    failures: list[str] = []
    attempted = sum(runner.run(test, out=failures.append).attempted for test in tests)
    assert not failures, "".join(failures)
    assert attempted > 0  # (every example skipped would make this module's test vacuous)
