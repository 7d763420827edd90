"""Signals and the command line's interrupted lines: what a process does when it is asked to stop.

- :func:`deferred_signals`: SIGINT and SIGTERM held back while a file is written and moved into
  place (every writer of :mod:`microimpact.io.files`), acted on afterwards;
- :func:`interrupt_at_checkpoints`: Ctrl-C as a flag that a loop checks between its steps;
- the one line a Ctrl-C prints (:data:`INTERRUPTED_LINE`, :func:`interrupted_after_writing`) and its
  exit status, shared by the console script (:mod:`microimpact._entry`) and the command line
  (:mod:`microimpact.cli`);
- the clock of ``simulate``'s interpreted run (:data:`INTERPRETED_SECONDS`).
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator

__all__ = ["deferred_signals", "interrupt_at_checkpoints", "INTERRUPTED_LINE", "EXIT_INTERRUPTED",
           "interrupted_after_writing", "INTERPRETED_SECONDS", "COMPILED_ENV", "interpreted_budget_over"]


@contextlib.contextmanager
def deferred_signals(signums=(signal.SIGINT, signal.SIGTERM)) -> Iterator[None]:
    """Hold SIGINT and SIGTERM back for the duration of the block, then act on them.

    A KeyboardInterrupt raised inside netCDF4/xarray's writer is raised while xarray holds its
    file lock, and the writer's own cleanup then waits for that lock for ever (a pipeline job
    hung after Ctrl-C). The block therefore runs to its end, and a signal that came
    during it is re-raised afterwards, with the handlers that were in place before. Outside the
    main thread, where Python cannot install handlers, the block runs unchanged.

    Examples
    --------
    >>> with deferred_signals():
    ...     x = 1 + 1
    >>> x
    2
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []
    previous = {}
    for s in signums:
        try:
            previous[s] = signal.signal(s, lambda signum, frame: received.append(signum))
        except (ValueError, OSError):  # pragma: no cover - a signal this platform cannot catch
            pass
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        for s in dict.fromkeys(received):
            signal.raise_signal(s)


@contextlib.contextmanager
def interrupt_at_checkpoints() -> Iterator:
    """Within the block Ctrl-C (SIGINT) only sets a flag; the yielded ``checkpoint()`` raises
    KeyboardInterrupt once it is set, and so does the end of the block. SIGTERM is held the same
    way where a Python handler turns it into an exception (a pipeline job), and that handler is
    called at the checkpoint.

    For loops whose inner calls must not be cut mid-way: emcee prints the whole traceback of a
    KeyboardInterrupt raised inside the likelihood before passing it on (87 lines on a Ctrl-C of
    ``fit --posterior``). Where SIGINT is ignored (a background job) or outside the main thread
    nothing changes for it.

    Examples
    --------
    >>> import os, signal
    >>> try:
    ...     with interrupt_at_checkpoints() as checkpoint:
    ...         os.kill(os.getpid(), signal.SIGINT)  # held: the step runs on
    ...         done = "step"
    ...         checkpoint()
    ... except KeyboardInterrupt:
    ...     print("interrupted after the", done)
    interrupted after the step
    """
    if threading.current_thread() is not threading.main_thread():
        yield lambda: None
        return
    # SIGINT unless ignored (a background job); SIGTERM only where a handler turns it into an
    # exception (a pipeline job, microimpact._runtime.joblog): at its default it ends the process at once
    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    held = [s for s, h in previous.items() if (callable(h) if s == signal.SIGTERM else h is not signal.SIG_IGN)]
    flag: list[int] = []

    def checkpoint() -> None:
        if not flag:
            return
        signum = flag[0]
        handler = previous[signum]
        if callable(handler) and handler is not signal.default_int_handler:
            handler(signum, None)
        raise KeyboardInterrupt

    for s in held:
        signal.signal(s, lambda signum, frame: flag.append(signum))
    try:
        yield checkpoint
    finally:
        for s in held:
            signal.signal(s, previous[s])
    checkpoint()


#: the one line of a Ctrl-C, and its exit status: 128 + 2, as a shell reports a command SIGINT ended
INTERRUPTED_LINE = ("microimpact: interrupted; nothing was written (outputs are written whole or not at all); run the "
                    "same command again to redo it")
EXIT_INTERRUPTED = 130


def interrupted_after_writing(paths) -> str:
    """The one line of a Ctrl-C that came after some outputs were complete and in place (the
    signal is held while files are moved into place, so each named file is whole)."""
    return (f"microimpact: interrupted after writing {', '.join(str(p) for p in paths)} "
            "(complete; nothing else was written)")


#: ``microimpact simulate`` runs its one impact with numba's compilation switched off
#: (``NUMBA_DISABLE_JIT``) for at most this long [s], then starts again compiled (see
#: :func:`_interpreted`); the environment variable ``MICROIMPACT_INTERPRETED_SECONDS`` sets another
INTERPRETED_SECONDS = 4.0
COMPILED_ENV = "MICROIMPACT_COMPILED"  # set in the process started again: compiled, no second try


def interpreted_budget_over() -> None:
    """The impact is solved: the interpreted run's clock stops (the output is not cut short)."""
    if os.environ.get("NUMBA_DISABLE_JIT") == "1" and COMPILED_ENV not in os.environ and hasattr(signal, "setitimer"):
        signal.setitimer(signal.ITIMER_REAL, 0.0)
