"""Every docstring example of the package runs and prints what it says (the Examples sections of
the API reference). One test per module, so a failure names the module and the example; the few
examples that are studies in miniature (tens of seconds each, :data:`SLOW_EXAMPLES`) run with the
slow tests (``pytest -m slow``), one test each; the modules whose examples take seconds
(:data:`EXTENDED_MODULES`) with the extended tests."""

from __future__ import annotations

import doctest
import importlib
import pkgutil
from pathlib import Path

import pytest

import microimpact

MODULES = sorted(m.name for m in pkgutil.walk_packages(microimpact.__path__, "microimpact.")
                 if not m.name.endswith("__main__"))
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
#: docstrings (by the function's name, wherever its module is) whose examples take tens of seconds:
#: each ranks or fits several laws or runs a coverage study; their functions have tests of their own
SLOW_EXAMPLES = ("rank_dem_tangential_laws", "dem_friction_coverage", "plot_model_comparison",
                 "model_comparison_section", "compare_normal_models",
                 "build_ring_emulator", "ring_emulator", "restitution")  # each builds a small emulator table
#: modules whose examples together take seconds of CPU (each fits, samples a posterior or draws a
#: report page): with the extended tests (``pytest -m extended``, run by .ci/run), not the default run
EXTENDED_MODULES = frozenset({
    "microimpact.analysis.posterior", "microimpact.report.analyst", "microimpact.analysis.dem_friction",
    "microimpact.analysis.dem_fit", "microimpact.report.posterior_figures", "microimpact.report.figures",
    "microimpact.analysis.kharaz", "microimpact.studies.benchmark.family", "microimpact.studies.material",
    "microimpact.analysis.oblique", "microimpact.analysis.analyst_fit", "microimpact.analysis.fit_result",
    "microimpact.analysis.flags", "microimpact.analysis.plastic_fit"})


def _doctests(name: str) -> list[doctest.DocTest]:
    """The docstrings with examples of module ``name`` (not those of what it imports)."""
    module = importlib.import_module(name)
    return [t for t in doctest.DocTestFinder(exclude_empty=True).find(module, name)
            if t.examples and getattr(t, "filename", None) and t.name.startswith(name)]


def _run(tests: list[doctest.DocTest]) -> None:
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    failures: list[str] = []
    attempted = sum(runner.run(test, out=failures.append).attempted for test in tests)
    assert not failures, "".join(failures)
    assert attempted > 0  # (every example skipped would make this test vacuous)


def _is_slow(test: doctest.DocTest) -> bool:
    return test.name.rsplit(".", 1)[-1] in SLOW_EXAMPLES


def test_every_module_is_found():
    """The walk sees the packages and their modules (a broken walk would pass every test below)."""
    assert {"microimpact.cli", "microimpact.model.law", "microimpact.solvers.engine",
            "microimpact.analysis.fitting", "microimpact._runtime.joblog"} <= set(MODULES)


@pytest.mark.parametrize("name", [pytest.param(m, marks=pytest.mark.extended) if m in EXTENDED_MODULES else m
                                  for m in MODULES])
def test_docstring_examples(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an example that writes a file writes it here
    tests = [t for t in _doctests(name) if not _is_slow(t)]
    if not tests:
        pytest.skip(f"{name} has no docstring examples (outside SLOW_EXAMPLES)")
    _run(tests)


@pytest.mark.slow
@pytest.mark.parametrize("function", SLOW_EXAMPLES)
def test_slow_docstring_examples(function, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    tests = [t for name in MODULES for t in _doctests(name) if t.name.rsplit(".", 1)[-1] == function]
    assert len(tests) == 1, f"{function}: {len(tests)} docstrings with examples of that name"
    _run(tests)


def test_every_extended_module_exists():
    """A renamed module must not leave its examples unrun."""
    assert EXTENDED_MODULES <= set(MODULES), sorted(EXTENDED_MODULES - set(MODULES))


def test_every_slow_example_exists():
    """Each name of SLOW_EXAMPLES is a function of the package with examples in its docstring (a
    rename must not leave them unrun); read from the sources, without importing every module."""
    sources = {p: p.read_text() for p in Path(microimpact.__file__).parent.rglob("*.py")}
    for function in SLOW_EXAMPLES:
        # module-level functions only (a method of the same name is another function)
        hits = [text.split(f"\ndef {function}(", 1)[1] for text in sources.values() if f"\ndef {function}(" in text]
        assert len(hits) == 1, f"{function}: defined {len(hits)} times"
        assert ">>> " in hits[0].split('"""', 2)[1], f"{function}: no examples in its docstring"
