"""One compiled driver (issue 52): the loops of toolkit/microimpact/solvers counted on the source.

Counted with Python's ast, not by name, so that a new loop written anywhere in solvers/ is found:

* a **compiled adaptive driver** is a numba-compiled function with a loop that takes a step (calls
  a function named ``step`` or ``*_step``) and controls its size (calls ``error_norm``,
  ``shrunk_step`` or ``grown_step``). There must be exactly one: :func:`microimpact.solvers.driver.make_driver`'s
  ``drive``, which the ring law, the JKR/DMT/Hertz laws and the coupled tangential law plug into;
* a **fixed-step compiled loop** takes steps over the motion (a while loop, or a for loop up to a
  step budget) without controlling them: the paper's Runge-Kutta-Gill (rkg.py) only; the root
  finder of :mod:`microimpact.solvers.dopri` re-steps within one step a bounded number of times
  and is no driver;
* the **scipy references** call ``solve_ivp`` and share nothing with the driver (a yardstick does not
  share the code it checks): no name of the driver, the Dormand-Prince core or a compiled kernel
  appears in them.

The driver's cyclomatic complexity is counted by :func:`cyclomatic_complexity`, McCabe's count as
radon makes it (1 + one per if/elif, loop, loop else, except, assert, conditional expression,
comprehension and its ifs, and each extra operand of and/or); radon 6.0.1 gave the same 10 for the
driver, against 48, 42 and 38 for the three loops it replaced.
"""

from __future__ import annotations

import ast
from pathlib import Path

from test_architecture import too_long_functions

SOLVERS = Path(__file__).resolve().parents[1] / "toolkit" / "microimpact" / "solvers"
#: step-size control: a loop that calls one of these is adaptive
_CONTROL = {"error_norm", "shrunk_step", "grown_step"}
#: names of helpers that are not an integration step: the step-size control, the first step, the
#: step of a central difference (normal_models)
_NOT_A_STEP = {"shrunk_step", "grown_step", "_initial_step", "_difference_step"}
#: what the scipy references must not name: the driver, the core, the compiled kernels
_SHARED = {"driver", "dopri", "_drive", "_integrate", "_integrate_many", "_step", "coupled_kernel", "coupled_many",
           "make_driver", "make_step"}
MAX_DRIVER_COMPLEXITY = 40


def _called(node: ast.AST) -> set[str]:
    names = set()
    for sub in ast.walk(node):
        if isinstance(sub, ast.Call):
            f = sub.func
            names.add(f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else "")
    return names


def _compiled(fn: ast.FunctionDef) -> bool:
    for d in fn.decorator_list:
        target = d.func if isinstance(d, ast.Call) else d
        if (target.id if isinstance(target, ast.Name) else getattr(target, "attr", "")) in ("njit", "njit_batch", "jit"):
            return True
    return False


def _functions(tree: ast.AST, prefix: str = ""):
    """(qualified name, node) of every function, nested ones too (make_driver.drive)."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield prefix + node.name, node
            yield from _functions(node, prefix + node.name + ".")
        elif isinstance(node, ast.ClassDef):
            yield from _functions(node, prefix + node.name + ".")


def _own_loops(fn: ast.FunctionDef):
    """The loops of fn itself, not of the functions nested in it."""
    stack = list(fn.body)
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            continue
        if isinstance(node, (ast.While, ast.For)):
            yield node
        stack.extend(ast.iter_child_nodes(node))


def _over_the_motion(loop) -> bool:
    """A while loop, or a for loop over a range whose bound is a variable (a step budget): a bounded
    search (``for _ in range(60)``, a root finder's trials) is not a loop over the motion."""
    if isinstance(loop, ast.While):
        return True
    it = loop.iter
    return isinstance(it, ast.Call) and any(not isinstance(a, ast.Constant) for a in it.args)


def loops(package: Path) -> dict[str, list[str]]:
    """{"adaptive": [...], "fixed_step": [...], "scipy": [...]}: "module:function" of each kind."""
    found = {"adaptive": [], "fixed_step": [], "scipy": []}
    for path in sorted(package.glob("*.py")):
        for name, fn in _functions(ast.parse(path.read_text())):
            where = f"{path.name}:{name}"
            if "solve_ivp" in _called(fn):
                found["scipy"].append(where)
            if not _compiled(fn):
                continue
            for loop in _own_loops(fn):
                calls = _called(loop)
                steps = {c for c in calls if (c == "step" or c.endswith("_step")) and c not in _NOT_A_STEP}
                if steps and calls & _CONTROL:
                    found["adaptive"].append(where)
                    break
                if steps and _over_the_motion(loop):
                    found["fixed_step"].append(where)
                    break
    return found


def cyclomatic_complexity(fn: ast.FunctionDef) -> int:
    """McCabe's cyclomatic complexity of fn as radon counts it (module docstring)."""
    n = 1
    for node in ast.walk(fn):
        if isinstance(node, (ast.If, ast.IfExp, ast.ExceptHandler, ast.Assert)):
            n += 1
        elif isinstance(node, (ast.For, ast.While, ast.AsyncFor)):
            n += 1 + bool(node.orelse)
        elif isinstance(node, ast.comprehension):
            n += 1 + len(node.ifs)
        elif isinstance(node, ast.BoolOp):
            n += len(node.values) - 1
    return n


def _function(path: Path, qualified: str) -> ast.FunctionDef:
    return dict(_functions(ast.parse(path.read_text())))[qualified]


def test_loops_are_counted_on_the_source(tmp_path):
    """The count finds a second adaptive loop, a fixed-step loop and a scipy loop where they are
    written (so the test below can fail)."""
    (tmp_path / "m.py").write_text('''
@njit(cache=True)
def a(u, h):
    while True:
        step(u, h)
        h = dopri.shrunk_step(h, error_norm(u))

@njit(cache=True)
def b(u, h):
    while u[0] > 0.0:
        _fixed_step(u, h)

def c():
    while True:
        solve_ivp(f, (0, 1), [0.0])
''')
    assert loops(tmp_path) == {"adaptive": ["m.py:a"], "fixed_step": ["m.py:b"], "scipy": ["m.py:c"]}
    branchy = ast.parse("def f(x):\n    if x and x > 1 or x < -1:\n        return [y for y in x if y]\n"
                        "    while x:\n        x -= 1\n    else:\n        pass\n").body[0]
    assert cyclomatic_complexity(branchy) == 1 + 1 + 2 + 2 + 2


def test_one_compiled_driver_the_scipy_references_and_rkg():
    found = loops(SOLVERS)
    assert found["adaptive"] == ["driver.py:make_driver.drive"], found["adaptive"]
    # the paper's Runge-Kutta-Gill: one impact, and the state at a given time (the phase plane)
    assert found["fixed_step"] == ["rkg.py:_rkg_impact", "rkg.py:_rkg_state_core"], found["fixed_step"]
    # the independent references: reference.py (the 3-D equations), the JKR/DMT reference, the DEM
    # tangential laws and the hysteretic and plastic references
    modules = {where.split(":")[0] for where in found["scipy"]}
    assert {"reference.py", "normal_models.py", "dem_tangential.py"} <= modules, modules


def test_the_scipy_references_share_no_code_with_the_driver():
    for where in loops(SOLVERS)["scipy"]:
        module, name = where.split(":")
        fn = _function(SOLVERS / module, name)
        names = {n.id for n in ast.walk(fn) if isinstance(n, ast.Name)} | {
            n.attr for n in ast.walk(fn) if isinstance(n, ast.Attribute)}
        assert not names & _SHARED, f"{where} uses {sorted(names & _SHARED)}"


def test_the_driver_is_short_and_simple():
    drive = _function(SOLVERS / "driver.py", "make_driver.drive")
    assert cyclomatic_complexity(drive) < MAX_DRIVER_COMPLEXITY
    assert not too_long_functions(SOLVERS), too_long_functions(SOLVERS)


def test_every_compiled_law_plugs_into_the_driver():
    """The ring law, the JKR/DMT/Hertz laws and the coupled law each build their driver from a
    Law and return its one solution record, Trace."""
    from microimpact.solvers import coupled, driver, engine, normal_models

    for module in (engine, normal_models, coupled):
        assert "driver.make_driver(driver.Law(" in Path(module.__file__).read_text(), module.__name__
    names = ("status", "outcome", "y_end", "tau_end", "friction_impulse", "twist_impulse", "max_approach",
             "tau_capture", "final_energy", "n_steps", "state")
    assert all(name in driver.Trace._fields for name in names)
