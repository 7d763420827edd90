"""Wall-clock budgets of long computations: the error a spent budget raises and the deadline that checks it.

A caller gives a computation a ``time_budget`` [s]; the computation makes a :class:`Deadline` of it
and checks it between units of work. Re-exported by :mod:`microimpact.solvers`, where the
solvers' other errors are.
"""

from __future__ import annotations

import math
import numbers
import time
from dataclasses import dataclass

__all__ = ["TimeBudgetExceeded", "check_time_budget", "Deadline"]


class TimeBudgetExceeded(RuntimeError):
    """A computation ran past the time budget [s] its caller gave it (``time_budget=`` of
    :func:`microimpact.solvers.reference.simulate_reference`, the fits, the posterior, the flags,
    the sweeps and the reproduction table; ``case_time_limit`` of the stress sweep). The message
    says which computation, the budget and how far it got. No partial result is returned.

    The message is one line. A budget that runs out while numba compiles comes back re-raised by
    numba as the same type with its compile pass on a line before the message; ``str()`` gives the
    budget's own line only, so every caller that prints it prints one line.

    Examples
    --------
    >>> str(TimeBudgetExceeded("Failed in nopython mode pipeline (step: parfor prelowering)\\n"
    ...                        "benchmark: time budget of 3 s exceeded"))
    'benchmark: time budget of 3 s exceeded'
    """

    def __str__(self) -> str:
        return (super().__str__().splitlines() or [""])[-1]


def check_time_budget(time_budget, name: str = "time_budget") -> float | None:
    """``time_budget`` as seconds (float > 0; inf means no limit) or None; ValueError naming ``name`` else."""
    if time_budget is None:
        return None
    if isinstance(time_budget, bool) or not isinstance(time_budget, numbers.Real) or not time_budget > 0.0:
        raise ValueError(f"{name} must be a number of seconds > 0 (or None: no limit), got {time_budget!r}")
    return float(time_budget)


@dataclass(frozen=True)
class Deadline:
    """The wall-clock end of a time budget, checked between units of work of a long computation.

    Make one with :meth:`start` from a caller's ``time_budget``; :meth:`check` raises
    :class:`TimeBudgetExceeded` once the budget is spent. A check is one ``time.perf_counter``
    call, so it may run after every model evaluation.

    Attributes
    ----------
    what : str
        The computation, first word of the message (e.g. ``"fit"``).
    budget : float or None
        The budget; None: no limit. [s]
    end : float
        ``time.perf_counter()`` at which the budget is spent (inf without a limit). [s]
    """

    what: str
    budget: float | None
    end: float

    @classmethod
    def start(cls, time_budget, what: str) -> "Deadline":
        """A deadline ``time_budget`` seconds from now (None or inf: none), for computation ``what``.

        ``time_budget`` may itself be a Deadline: a stage of a larger computation then shares the
        budget of the whole, under its own name. A bad budget is a ValueError naming ``time_budget``.
        """
        if isinstance(time_budget, Deadline):
            return cls(what, time_budget.budget, time_budget.end)
        budget = check_time_budget(time_budget)
        limited = budget is not None and math.isfinite(budget)
        return cls(what, budget if limited else None, time.perf_counter() + budget if limited else math.inf)

    @property
    def limited(self) -> bool:
        """Whether there is a budget to run out of."""
        return self.budget is not None

    def check(self, done: str) -> None:
        """Raise :class:`TimeBudgetExceeded` if the budget is spent; ``done`` says how far the work got
        (e.g. ``"312 function evaluations"``) and ends the message."""
        if time.perf_counter() > self.end:
            raise TimeBudgetExceeded(f"{self.what}: time budget of {self.budget:g} s exceeded after {done}")

    def ticking(self, advance, total: int, unit: str):
        """``advance(n=1)`` of a :func:`microimpact._runtime.progress.progress_bar` that also checks the deadline
        after each advance, reporting ``"<done> of <total> <unit>"``; ``advance`` itself if unlimited."""
        if not self.limited:
            return advance
        done = [0]

        def step(n=1):
            advance(n)
            done[0] += n
            self.check(f"{done[0]} of {total} {unit}")

        return step

    def iter_cb(self, stage: str):
        """An lmfit ``iter_cb`` that checks the deadline after every function evaluation of ``stage``,
        or None when unlimited (lmfit then runs exactly as without a budget).

        It raises rather than returning True: lmfit's own abort would return a half-finished fit
        as a result."""
        if not self.limited:
            return None
        calls = [0]  # counted here: lmfit's own count restarts inside conf_interval

        def iter_cb(params, nfev, resid, *args, **kwargs):
            calls[0] += 1
            self.check(f"{calls[0]} function evaluations of {stage}")

        return iter_cb
