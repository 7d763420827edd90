"""A child command (Snakemake, for ``microimpact workflow``) run so that any stop signal ends it
and everything it started within seconds, with one line of the wrapper's and none of the child's.

- Ctrl-C in a terminal reaches the wrapper and the child alike (one process group). A SIGTERM
  (or a SIGINT) sent to the wrapper alone is passed on as SIGINT to the child and every process it
  started (what Ctrl-C does; Snakemake then stops its jobs, removes their unfinished outputs and
  releases its lock), so ``kill PID`` no longer leaves a pipeline running detached.
- The child's stdout and stderr pass through the wrapper; once a stop signal has come they are
  dropped, so what a child prints while it is stopped in its start-up (a KeyboardInterrupt
  traceback from an import, an event-loop traceback as jobs launch) never reaches the user.
- While the child runs the wrapper is its jobs' subreaper (Linux ``prctl(PR_SET_CHILD_SUBREAPER)``):
  a job the child starts as it ends on a signal, too late for the wrapper to have seen it, is
  re-parented to the wrapper instead of init, and killed with the rest when the child has ended.
- A child that has not ended :data:`STOP_GRACE` seconds after the signal is killed with its
  descendants (SIGKILL); what it leaves (a lock, an unfinished output) is what a plain rerun of
  ``microimpact workflow`` clears (its stale-lock check and ``--rerun-incomplete``).
"""

from __future__ import annotations

import ctypes
import os
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

__all__ = ["STOP_GRACE", "descendants", "run_supervised"]

#: seconds a child is given to stop after a stop signal before it and its descendants are killed
#: (issue 55 asks for an end within 5 s; Snakemake stops its jobs in well under this)
STOP_GRACE = 3.5
#: seconds each line of the child's output is held before it is copied (:func:`_copy`)
HOLD = 0.1
#: seconds after a SIGINT at which it is passed on to a child that still runs (a SIGINT to the
#: wrapper alone; the terminal's Ctrl-C reaches the child itself)
SIGINT_PASS_ON = 1.0
#: the stop signals the wrapper takes and passes on
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
#: prctl's option that makes a process the subreaper of its descendants' orphans (linux/prctl.h)
PR_SET_CHILD_SUBREAPER = 36


def _set_subreaper(on: bool) -> bool:
    """Make this process the subreaper of its descendants' orphans (or stop being one); False where
    the system has no such call (not Linux)."""
    try:
        return ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, int(on), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def descendants(pid: int) -> list[int]:
    """Process ids of every live descendant of ``pid`` (children first), from Linux's
    ``/proc/<pid>/task/<tid>/children``; empty where there is no ``/proc``.

    Examples
    --------
    >>> descendants(os.getpid()) == [] or all(isinstance(p, int) for p in descendants(os.getpid()))
    True
    """
    found, todo = [], [pid]
    while todo:
        parent = todo.pop(0)
        for children in Path(f"/proc/{parent}/task").glob("*/children"):
            try:
                kids = [int(w) for w in children.read_text().split()]
            except (OSError, ValueError):
                continue
            for kid in kids:
                if kid not in found:
                    found.append(kid)
                    todo.append(kid)
    return found


def _signal_all(pids, signum) -> None:
    for pid in pids:
        try:
            os.kill(pid, signum)
        except (ProcessLookupError, PermissionError):
            pass


def _kill_orphans(pids, wait: float = 1.0) -> None:
    """SIGKILL each of ``pids`` still alive in this process group (a job the stopped child left
    behind when it ended first: a SIGTERM to the group once left one running, issue 55), and wait
    up to ``wait`` seconds for them to be gone. The group check keeps a reused pid safe."""
    group = os.getpgrp()
    alive = []
    for pid in pids:
        try:
            if os.getpgid(pid) == group:
                os.kill(pid, signal.SIGKILL)
                alive.append(pid)
        except (ProcessLookupError, PermissionError):
            pass
    end = time.monotonic() + wait
    while alive and time.monotonic() < end:
        alive = [p for p in alive if _running(p)]
        time.sleep(0.02)


def _reap(pids) -> None:
    """SIGKILL ``pids`` (the child's orphans, re-parented to this process as their subreaper) and
    collect their exit status, so that none is left running or as a zombie."""
    _signal_all(pids, signal.SIGKILL)
    for pid in pids:
        try:
            os.waitpid(pid, 0)
        except ChildProcessError:  # an orphan's own descendant: its parent, killed here, was ours
            pass


def _running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    status = Path(f"/proc/{pid}/status")
    try:
        return "zombie" not in status.read_text()
    except OSError:
        return False


def _copy(source, target, stopped: threading.Event) -> None:
    """Copy the child's stream ``source`` to ``target`` until it closes, each line :data:`HOLD`
    seconds after it was read, dropping every line not yet written once ``stopped`` is set.

    The hold is what makes the drop work: a Ctrl-C reaches the child and the wrapper at once, the
    child prints at once ("Terminating processes on user request"), and the wrapper's handler,
    which runs in its main thread, may come a moment after this thread has read that line. Lines
    read together age together, so a burst is held once, not once per line."""
    lines: queue.Queue = queue.Queue()

    def read():
        for line in iter(source.readline, b""):
            lines.put((time.monotonic(), line))
        lines.put((None, None))
        source.close()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    raw = getattr(target, "buffer", None)  # a text stream without one (a test's capture) gets text
    while True:
        read_at, line = lines.get()
        if line is None:
            return
        time.sleep(max(0.0, read_at + HOLD - time.monotonic()))
        if stopped.is_set():
            continue
        try:
            (raw.write(line) if raw is not None else target.write(line.decode(errors="replace")))
            (raw or target).flush()
        except (OSError, ValueError):  # the wrapper's own stream went away: keep draining
            pass


def run_supervised(command: list[str], grace: float = STOP_GRACE) -> tuple[int, int | None]:
    """Run ``command``; (its exit status, the stop signal that came or None).

    Parameters
    ----------
    command : list of str
        The child's command line.
    grace : float
        Seconds the child has to stop after a stop signal before it and its descendants are
        killed. [s]

    Returns
    -------
    status : int
        The child's exit status (negative: the signal that ended it, as :mod:`subprocess` says).
    signum : int or None
        SIGINT or SIGTERM if one came while the child ran (the caller prints its one line).

    Examples
    --------
    >>> import sys
    >>> run_supervised([sys.executable, "-c", "raise SystemExit(3)"])
    (3, None)
    """
    received: list[int] = []
    stopped = threading.Event()

    def on_signal(signum, frame):
        received.append(signum)
        stopped.set()

    previous = {s: signal.signal(s, on_signal) for s in STOP_SIGNALS}
    ours = set(descendants(os.getpid()))  # what the caller had started itself is left alone
    subreaper = _set_subreaper(True)
    try:
        proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        copiers = [threading.Thread(target=_copy, args=(stream, target, stopped), daemon=True)
                   for stream, target in ((proc.stdout, sys.stdout), (proc.stderr, sys.stderr))]
        for c in copiers:
            c.start()
        seen = _wait(proc, received, grace)
        # nothing it started outlives it (a job whose parent was killed)
        _signal_all(descendants(proc.pid), signal.SIGKILL)
        _kill_orphans(seen)
        _reap([pid for pid in descendants(os.getpid()) if pid not in ours])  # re-parented to us
        for c in copiers:
            c.join(timeout=1.0 + HOLD)
    finally:
        if subreaper:
            _set_subreaper(False)
        for s, handler in previous.items():
            signal.signal(s, handler)
    return proc.returncode, (received[0] if received else None)


def _wait(proc: subprocess.Popen, received: list[int], grace: float) -> set[int]:
    """Wait for ``proc``; after a stop signal pass SIGINT on to it and its descendants, and kill
    them all ``grace`` seconds after the signal if it has not ended.

    A SIGTERM is passed on at once: sent to the wrapper alone (``kill PID``) it reached nobody
    else. A SIGINT is most often the terminal's Ctrl-C, which the child and its jobs got
    themselves, and a second one in the middle of Snakemake's clean-up would cut it short; it is
    passed on only if the child still runs :data:`SIGINT_PASS_ON` seconds later (a SIGINT to the
    wrapper alone)."""
    came = passed_on = None
    seen: set[int] = set()
    while True:
        # once the child has ended its jobs are orphans, nobody's descendants: the last ones seen
        # before a stop signal (a child may end at once on it) and all seen after it are remembered
        current = descendants(proc.pid)
        seen = seen | set(current) if received else set(current)
        try:
            proc.wait(timeout=0.05)
            return seen
        except subprocess.TimeoutExpired:
            pass
        if received and came is None:
            came = time.monotonic()
        if came is not None and passed_on is None and (
                signal.SIGTERM in received or time.monotonic() - came > SIGINT_PASS_ON):
            passed_on = time.monotonic()
            _signal_all([proc.pid, *descendants(proc.pid)], signal.SIGINT)
        if came is not None and time.monotonic() - came > grace:
            _signal_all([proc.pid, *descendants(proc.pid)], signal.SIGKILL)
            proc.wait()
            return seen
