"""The package's errors: one time-budget error, and the solvers' errors under one base (issue 52)."""

import importlib
import inspect
import pkgutil

import microimpact
from microimpact.solvers import SolverError, TimeBudgetExceeded


def _exception_classes():
    """Every exception class defined in a module of the package (by identity, aliases once)."""
    found = {}
    for info in pkgutil.walk_packages(microimpact.__path__, "microimpact."):
        if info.name.startswith("microimpact._entry") or ".__main__" in info.name:
            continue  # the console entry point re-executes itself; it defines no error a caller catches
        module = importlib.import_module(info.name)
        for _, obj in inspect.getmembers(module, inspect.isclass):
            if issubclass(obj, BaseException) and obj.__module__.startswith("microimpact"):
                found[id(obj)] = obj
    return list(found.values())


def test_there_is_exactly_one_time_budget_error():
    classes = _exception_classes()
    named = [c for c in classes if c.__name__ == "TimeBudgetExceeded"]
    assert named == [TimeBudgetExceeded]
    # no other class of the package is a time budget's error, beside it or under it
    timed = [c for c in classes if "time" in c.__name__.lower() and ("budget" in c.__name__.lower()
                                                                  or "limit" in c.__name__.lower())]
    assert timed == [TimeBudgetExceeded]
    assert [c for c in classes if c is not TimeBudgetExceeded and issubclass(c, TimeBudgetExceeded)] == []


def test_the_old_names_are_the_one_class_and_their_except_sites_still_catch():
    from microimpact._runtime.budget import TimeBudgetExceeded as from_budget
    from microimpact._runtime.timeout import TimeLimitExceeded, time_limit

    assert TimeLimitExceeded is TimeBudgetExceeded is from_budget
    caught = None
    try:
        with time_limit(0.05, "nap"):
            while True:
                pass
    except TimeLimitExceeded as exc:  # the benchmark harness's except site
        caught = exc
    assert isinstance(caught, TimeBudgetExceeded) and str(caught) == "nap: time budget of 0.05 s exceeded"


def test_the_family_solve_budget_is_a_solver_error_not_a_time_budget():
    from microimpact.solvers.family import FamilyBudgetExceeded

    assert issubclass(FamilyBudgetExceeded, SolverError)
    assert not issubclass(FamilyBudgetExceeded, TimeBudgetExceeded)
