"""A wall-clock limit for a block of code (used by the benchmark and the stress test)."""

from __future__ import annotations

import contextlib
import signal
import threading
import time

from microimpact._runtime.budget import TimeBudgetExceeded

__all__ = ["TimeLimitExceeded", "time_limit"]


#: The error a :func:`time_limit` block that ran out of time raises: :class:`TimeBudgetExceeded`
#: itself (one class for every time budget of the package; this name is kept for its callers).
TimeLimitExceeded = TimeBudgetExceeded


@contextlib.contextmanager
def time_limit(seconds: float | None, what: str | None = None):
    """Raise :class:`TimeLimitExceeded` in the block after ``seconds`` [s].

    Uses SIGALRM, so the limit applies only in the main thread on POSIX; elsewhere, and with
    ``seconds`` None, the block runs without a limit. The previous SIGALRM handler is restored.
    Limits nest: a block inside another runs for at most what is left of the outer one, and a
    limit that has passed raises again at short intervals until its block has ended, so a per-case limit
    inside a whole-run budget (``microimpact benchmark --time-budget``), whose caller catches the
    case's TimeLimitExceeded and goes on, does not cancel the budget; a block that ends past its
    limit raises too, also when it ends in another exception (the code the alarm interrupted turned
    it into an error of its own, which becomes the ``__cause__``).

    Parameters
    ----------
    seconds : float or None
        The limit [s]; None: none.
    what : str, optional
        The computation, for the message ("``what``: time budget of ``seconds`` s exceeded").

    Examples
    --------
    >>> import time
    >>> try:
    ...     with time_limit(0.05, "nap"):
    ...         time.sleep(1.0)
    ... except TimeLimitExceeded as exc:
    ...     print(exc)
    nap: time budget of 0.05 s exceeded
    """
    usable = (seconds is not None and hasattr(signal, "setitimer")
              and threading.current_thread() is threading.main_thread())
    if not usable:
        yield
        return
    message = f"{what}: time budget of {seconds:g} s exceeded" if what else ""
    if _active and time.perf_counter() >= min(end for end, _ in _active):
        raise TimeLimitExceeded(_expired_message())  # an enclosing limit has passed (its signal was caught)
    previous = signal.signal(signal.SIGALRM, _on_alarm) if not _active else None
    end = time.perf_counter() + seconds
    entry = (end, message)
    try:
        # inside the try: a limit shorter than these two calls (--time-budget 5e-324) fires as _arm
        # returns, and raised before the try, it left the timer repeating and the handler installed
        _active.append(entry)
        _arm()
        yield
    except TimeLimitExceeded:
        raise
    except Exception as exc:
        if time.perf_counter() >= min(e for e, _ in _active):
            # the alarm landed in code that turned it into an error of its own (numba's compiler,
            # interrupted, raises "no compiled object yet for <Library ...>"): the limit ended the block
            raise TimeLimitExceeded(_expired_message()) from exc
        raise
    finally:
        # no alarm raises while the limit is taken down (a subscript store runs no signal handler,
        # so nothing can raise before it): raised here, it left the same timer and handler behind
        _closing[0] += 1
        try:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            if entry in _active:
                del _active[len(_active) - 1 - _active[::-1].index(entry)]
            if _active:
                _arm()
            else:
                signal.signal(signal.SIGALRM, previous)
        finally:
            _closing[0] -= 1
    if time.perf_counter() >= end:  # ran past the limit, and the block's callees caught the signal
        raise TimeLimitExceeded(message)


#: (end as time.perf_counter(), message) of the time_limit blocks in force, outermost first
_active: list[tuple[float, str]] = []
#: how many time_limit blocks are being taken down (their alarms are then ignored)
_closing = [0]
#: after a limit has passed its timer fires again this often [s] until its block has ended: a
#: TimeLimitExceeded caught by an inner block's caller (a per-case limit) does not end the outer one
_REPEAT = 0.1


def _expired_message() -> str:
    """The message of the outermost limit that has passed (else of the innermost)."""
    now = time.perf_counter()
    return next((msg for end, msg in _active if now >= end), _active[-1][1] if _active else "")


#: the compiler's modules: an exception raised from inside them leaves numba's state broken
_COMPILER_MODULES = ("numba", "llvmlite")


def _in_compiler(frame) -> bool:
    """Whether ``frame`` or a frame that called it is numba's or llvmlite's Python code."""
    while frame is not None:
        if frame.f_globals.get("__name__", "").partition(".")[0] in _COMPILER_MODULES:
            return True
        frame = frame.f_back
    return False


def _on_alarm(signum, frame):
    # Not inside a compile: a compile interrupted half way leaves a library registered but never
    # finalised ("no compiled object yet for <Library ...>"), and a later call that links to it
    # crashed a CI worker with a segmentation fault. The timer repeats every _REPEAT s after the
    # limit, so the block ends at the first alarm after the compile (one uninterruptible step).
    if _in_compiler(frame) or _closing[0]:
        return
    raise TimeLimitExceeded(_expired_message())


def _arm() -> None:
    """Set the timer to the earliest end of the limits in force (at once if it has passed)."""
    left = min(end for end, _ in _active) - time.perf_counter()
    signal.setitimer(signal.ITIMER_REAL, max(left, 1e-6), _REPEAT)
