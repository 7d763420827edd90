"""A wall-clock limit for a block of code (used by the benchmark and the stress test)."""

from __future__ import annotations

import contextlib
import signal
import threading

from microimpact.solvers import TimeBudgetExceeded

__all__ = ["TimeLimitExceeded", "time_limit"]


class TimeLimitExceeded(TimeBudgetExceeded):
    """Raised inside a :func:`time_limit` block that ran out of time (a
    :class:`microimpact.solvers.TimeBudgetExceeded`, so one type covers every time budget)."""


@contextlib.contextmanager
def time_limit(seconds: float | None):
    """Raise :class:`TimeLimitExceeded` in the block after ``seconds`` [s].

    Uses SIGALRM, so the limit applies only in the main thread on POSIX; elsewhere, and with
    ``seconds`` None, the block runs without a limit. The previous SIGALRM handler is restored.
    """
    usable = (seconds is not None and hasattr(signal, "setitimer")
              and threading.current_thread() is threading.main_thread())
    if not usable:
        yield
        return

    def handler(signum, frame):
        raise TimeLimitExceeded()

    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)
