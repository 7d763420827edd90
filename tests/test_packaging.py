"""The package stands alone: its data ships inside it, and the repository's copies do not drift.

The Kharaz et al. (2001) data and the format documentation that error messages cite
(``data/README.md``) are package data, read through :mod:`importlib.resources`, so the library
works from an installed wheel outside the clone. The repository keeps its ``data/`` copies for the
pipeline and the reader; these tests hold the two copies byte-identical. ``.ci/run`` runs this
file (and the tests of what an install can break) against the installed wheel with ``MICROIMPACT_TEST_INSTALLED=1``,
which also checks that ``import microimpact`` is the installed package, not the clone's sources.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from importlib.metadata import entry_points
from importlib.resources import files
from pathlib import Path

import pytest

import microimpact
from microimpact.analysis.kharaz import default_kharaz_path
from microimpact.io import default_materials_path
from microimpact.solvers import emulator

REPO = Path(__file__).resolve().parents[1]
PACKAGE = files("microimpact")

#: package data file -> its repository copy (None: the package copy is the only one)
BUNDLED = {
    "data/kharaz2001_oblique.csv": REPO / "data" / "kharaz2001_oblique.csv",
    "data/README.md": REPO / "data" / "README.md",
    "io/materials.yaml": None,
}


@pytest.mark.parametrize("name", BUNDLED)
def test_package_data_is_inside_the_package(name):
    assert PACKAGE.joinpath(name).is_file(), name


@pytest.mark.parametrize("name", [n for n, repo in BUNDLED.items() if repo is not None])
def test_package_copies_equal_the_repository_copies(name):
    # one content in two places: the pipeline reads data/, the library (and an installed wheel)
    # the package copy. After editing data/<file>, copy it to toolkit/microimpact/<name>.
    assert PACKAGE.joinpath(name).read_bytes() == BUNDLED[name].read_bytes(), (
        f"toolkit/microimpact/{name} differs from {BUNDLED[name].relative_to(REPO)}: copy the one you "
        "changed over the other")


def test_the_emulator_tables_ship_with_the_package():
    # the posterior's likelihood reads them (microimpact.solvers.emulator.SHIPPED): an install whose
    # wheel lacks them would build each on first use (about a minute) instead of reading it
    for tol, domain in emulator.SHIPPED:
        assert PACKAGE.joinpath("data", "emulator", emulator._table_name(tol, dict(domain))).is_file()


def test_default_data_paths_are_the_package_copies():
    root = Path(microimpact.__file__).resolve().parent
    assert default_kharaz_path().resolve() == root / "data" / "kharaz2001_oblique.csv"
    assert default_materials_path().resolve() == root / "io" / "materials.yaml"


@pytest.mark.skipif(not os.environ.get("MICROIMPACT_TEST_INSTALLED"),
                    reason="only when .ci/run tests the installed wheel (MICROIMPACT_TEST_INSTALLED=1)")
def test_the_installed_wheel_is_under_test():
    here = Path(microimpact.__file__).resolve()
    assert REPO not in here.parents, f"import microimpact resolves to the clone: {here}"
    assert "site-packages" in here.parts, here


def test_library_dependencies_leave_out_the_workflow():
    # Snakemake (about 40 packages) is the [workflow] extra; the test extra includes it, since the
    # tests run Snakemake, so `pip install -e ".[test]"` still sets up everything
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    names = [d.split(">")[0].split("=")[0].split("[")[0].strip().lower() for d in project["dependencies"]]
    assert "snakemake" not in names
    extras = project["optional-dependencies"]
    assert any(d.startswith("snakemake>=") for d in extras["workflow"])
    assert "microimpact[workflow]" in extras["test"]
    assert "microimpact[workflow]" in extras["slurm"]
    for dep in project["dependencies"] + extras["workflow"] + extras["test"]:  # every bound is tested
        assert dep.startswith("microimpact[") or ">=" in dep, dep


def test_license_and_declared_python():
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    assert project["license"] == "BSD-3-Clause"
    assert "BSD 3-Clause License" in (REPO / "LICENSE").read_text()
    tested = f"{sys.version_info.major}.{sys.version_info.minor}"
    assert f"Programming Language :: Python :: {tested}" in project["classifiers"]


def test_import_loads_no_solver_and_no_snakemake():
    # `import microimpact` is light: the solvers (numba) and the presets (through io.provenance,
    # xarray) load on first use (PEP 562), and the library never imports Snakemake
    code = ("import sys, microimpact; bad = [m for m in ('numba', 'snakemake', 'xarray', 'pandas', "
            "'microimpact.solvers.engine') if m in sys.modules]; print(','.join(bad))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == ""


def test_numba_compile_notice_is_registered():
    # numba runs the numba_extensions/init entry point before its first compilation; the listener
    # prints one stderr line on a cache miss of a microimpact function only
    eps = entry_points(group="numba_extensions", name="init")
    assert any(ep.value == "microimpact:_announce_numba_compiles" for ep in eps)


@pytest.mark.extended
def test_numba_compile_notice_only_when_the_cache_is_cold(tmp_path):
    # another package's numba function (compiled on every run) never prints the notice; the
    # microimpact kernel prints it once when numba's cache is cold, and not when it is warm
    code = ("from numba import njit\n"
            "from microimpact.model.tangential import tangential_kernel\n"
            "def g(x):\n    return x + 2\n"
            "print(njit(g)(1))\n"
            "tangential_kernel(1e-12, 1e-24, 1e-6, 0.1, 1.0, 0.0, 0.0, 0.0, 0.0, 1e-12, 0.0)\n")
    script = tmp_path / "notice.py"
    script.write_text(code)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    runs = [subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, check=True,
                           timeout=300) for _ in range(2)]
    assert runs[0].stdout.split() == ["3"]
    notices = [r.stderr.count("microimpact: compiling") for r in runs]
    assert notices == [1, 0], [r.stderr for r in runs]


@pytest.mark.parametrize("package", ["microimpact", "microimpact.io", "microimpact.analysis"])
def test_dir_shows_every_public_name_of_the_lazy_packages(package):
    """``dir()`` and tab completion list the names a lazy package loads on first use (issue 28:
    ``dir(microimpact.io)`` was ``['importlib']``), each name resolves, and for io and analysis the
    table of names holds every module's ``__all__`` (a new public name cannot be missed)."""
    import importlib
    import pkgutil

    pkg = importlib.import_module(package)
    listed = set(dir(pkg))
    helpers = {n for n in listed if not n.startswith("__") and (n.startswith("_") or n == "importlib")}
    assert not helpers, f"dir({package}) shows its private helpers {sorted(helpers)}"
    for name in pkg.__all__:
        assert name in listed, name
        assert getattr(pkg, name) is not None, name
    if package != "microimpact":
        for info in pkgutil.iter_modules(pkg.__path__):
            if info.name.startswith("_"):
                continue
            assert info.name in listed, info.name
            module = importlib.import_module(f"{package}.{info.name}")
            if package == "microimpact.analysis":
                missing = set(getattr(module, "__all__", ())) - set(pkg.__all__)
                assert not missing, (info.name, missing)
    else:
        for name in ("simulate_impact", "simulate_many", "Contact", "io", "analysis", "__version__"):
            assert name in listed, name


@pytest.mark.extended
def test_result_reprs_are_one_line_with_the_estimates(tmp_path):
    """A result's repr is one short line of its estimates (issue 28: DampingFit's repr printed its
    whole DataFrame); an exact target solve shows no uncertainty."""
    from pathlib import Path

    from microimpact.analysis import analyse_impacts, damping_from_target
    from microimpact.io import default_materials_path, read_impacts, read_materials
    from microimpact.presets import WALL_1990

    pairs = read_materials(default_materials_path())
    table = read_impacts(Path(__file__).resolve().parents[1] / "data" / "synthetic_microspheres.csv", materials=pairs)
    fit = analyse_impacts(table.iloc[::5], pairs["ammonium_fluorescein_on_silicon"], confidence_intervals=False)
    text = repr(fit.damping)
    assert "\n" not in text and len(text) < 200, text
    assert text.startswith("DampingFit(zeta_hertz=") and "+/-" in text and "(fixed)" in text, text
    assert repr(fit).startswith("AnalystFit(DampingFit(") and "\n" not in repr(fit)
    # in a notebook: the whole report, escaped
    import html

    for result in (fit, fit.damping):
        shown = result._repr_html_()
        assert shown == f"<pre>{html.escape(result.report())}</pre>" and "zeta_hertz" in shown
    exact = repr(damping_from_target([0.5, 0.6], [2.0, 3.0], WALL_1990, n_points=5))
    assert "exact(" in exact and "+/-" not in exact, exact


def test_approx_has_no_hidden_absolute_tolerance():
    """tests/conftest.py: ``pytest.approx`` without ``abs=`` is relative only, so an SI quantity of
    a microsphere (1e-13 kg, 1e-14 J) compared with ``rel=`` fails when the result is 0."""
    assert 0.0 != pytest.approx(2.3e-13, rel=1e-6)
    assert 0.0 != pytest.approx(1e-14)
    assert 2.3e-13 * (1 + 1e-9) == pytest.approx(2.3e-13, rel=1e-6)


def test_every_solver_failure_has_one_base_class():
    """One ``except SolverError`` catches a failure of any solver (issue 26, item 7)."""
    from microimpact.solvers import SolverError
    from microimpact.solvers.coupled import CoupledError
    from microimpact.solvers.engine import EngineError
    from microimpact.solvers.reference import ReferenceSolverError

    for error in (EngineError, CoupledError, ReferenceSolverError):
        assert issubclass(error, SolverError) and issubclass(error, RuntimeError), error
