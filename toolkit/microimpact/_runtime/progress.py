"""Progress feedback on stderr for long computations (sweeps, fits, flags, stress, benchmark).

One small bar, no dependency: a terminal gets ``label  37% |#######     | 370/1000  2.1 s, ~3.6 s
left``, redrawn at most ten times a second; when stderr is not a terminal (a pipe, a log file, a
Snakemake job) nothing is written, so logs stay clean. Library functions take ``progress=None``
(silent) and the CLI passes ``progress=True``.

Example
-------
>>> with progress_bar(1000, "sweep", enabled=False) as advance:
...     for i in range(1000):
...         advance(1)
"""

from __future__ import annotations

import contextlib
import sys
import time

__all__ = ["progress_bar", "wants_progress"]

_WIDTH = 24
_REDRAW_S = 0.1


def wants_progress(progress) -> bool:
    """Whether a bar should be drawn: ``progress`` is True (or a truthy flag) and stderr is a terminal.

    Examples
    --------
    Never when not asked for, and not when stderr is not a terminal (as under doctest, in a pipe or a
    log file):

    >>> wants_progress(False), wants_progress(True)
    (False, False)
    """
    if not progress:
        return False
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):  # a closed or replaced stderr
        return False


def _line(label: str, done: int, total: int, elapsed: float) -> str:
    fraction = min(done / total, 1.0) if total > 0 else 1.0
    filled = int(round(_WIDTH * fraction))
    left = f", ~{elapsed * (1.0 - fraction) / fraction:.1f} s left" if 0.0 < fraction < 1.0 else ""
    return f"\r{label}  {100 * fraction:3.0f}% |{'#' * filled}{' ' * (_WIDTH - filled)}| {done}/{total}  {elapsed:.1f} s{left}"


@contextlib.contextmanager
def progress_bar(total: int, label: str, enabled=True):
    """A context manager yielding ``advance(n=1)``; draws a bar on stderr if :func:`wants_progress`.

    Parameters
    ----------
    total : int
        Number of units of work (cases, rows, solves).
    label : str
        Shown before the bar.
    enabled : bool
        The caller's wish (e.g. the CLI passes True); a bar is drawn only on a terminal.

    Examples
    --------
    Off a terminal (here stderr is a string buffer) the bar is not drawn and ``advance`` only
    counts:

    >>> import contextlib, io
    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err), progress_bar(3, "cases", enabled=True) as advance:
    ...     for _ in range(3):
    ...         advance()
    >>> err.getvalue()
    ''
    """
    if not wants_progress(enabled):
        yield lambda n=1: None
        return
    start = time.perf_counter()
    state = {"done": 0, "drawn": 0.0}

    def advance(n=1):
        state["done"] += n
        now = time.perf_counter()
        if now - state["drawn"] >= _REDRAW_S or state["done"] >= total:
            state["drawn"] = now
            sys.stderr.write(_line(label, state["done"], total, now - start))
            sys.stderr.flush()

    try:
        yield advance
    finally:
        sys.stderr.write(_line(label, state["done"], total, time.perf_counter() - start) + "\n")
        sys.stderr.flush()
