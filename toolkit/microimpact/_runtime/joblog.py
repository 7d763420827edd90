"""The log of a pipeline job: its output in the log file, a failure's reason on the terminal too.

Every script in ``workflow/scripts/`` starts with :func:`log_job`. Snakemake shows a failed job as
"Error in rule ... check log file(s)"; the reason itself would be only in the log. Here the full
traceback still goes to the log, and one line with the rule, the exception and its message goes
to the terminal, where the analyst is looking. A job stopped by Ctrl-C (SIGINT) or SIGTERM is not a
failure of the job: its log and the terminal get one line saying so and how to resume, no
traceback, and the job ends by its signal as an unhandled one would end it (status 130 or 143).
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import traceback

__all__ = ["log_job", "one_line_reason", "interrupted_line", "JobTerminated", "redeliver_swallowed_signals"]

#: how to finish a run that was stopped (the resume command of docs/guide/pipeline.md)
RESUME = "snakemake --cores 2 --rerun-incomplete"


class JobTerminated(Exception):
    """SIGTERM arrived: raised in the main thread so that the job unwinds (atomic writers abandon
    their temporary files) instead of dying where it stands.

    Examples
    --------
    :func:`log_job` installs the SIGTERM handler that raises it (called here directly, not by a
    signal):

    >>> import signal, sys
    >>> from types import SimpleNamespace
    >>> saved = (sys.stdout, sys.stderr, sys.excepthook, sys.unraisablehook,
    ...          signal.signal(signal.SIGTERM, signal.SIG_DFL))
    >>> log_job(SimpleNamespace(rule="fit", log=["fit.log"]))
    >>> handler = signal.getsignal(signal.SIGTERM)
    >>> sys.stdout.close()
    >>> sys.stdout, sys.stderr, sys.excepthook, sys.unraisablehook = saved[:4]
    >>> _ = signal.signal(signal.SIGTERM, saved[4])
    >>> handler(signal.SIGTERM, None)
    Traceback (most recent call last):
    ...
    microimpact._runtime.joblog.JobTerminated: SIGTERM
    """


def _redeliver(unraisable) -> None:
    exc_type = unraisable.exc_type
    if exc_type is not None and issubclass(exc_type, (KeyboardInterrupt, JobTerminated)):
        signum = signal.SIGINT if issubclass(exc_type, KeyboardInterrupt) else signal.SIGTERM
        # not from inside the hook: a signal handled before the hook returns would be swallowed again
        timer = threading.Timer(0.05, os.kill, (os.getpid(), signum))
        timer.daemon = True
        timer.start()
        return
    sys.__unraisablehook__(unraisable)


def redeliver_swallowed_signals() -> None:
    """Make a Ctrl-C or SIGTERM that lands in a finaliser stop the process all the same.

    Python runs signal handlers between bytecodes of the main thread, and that may be inside a
    ``__del__`` or a weakref callback. An exception raised there cannot propagate: Python prints
    "Exception ignored in ..." with a traceback and carries on, so the interrupted job went on
    working and its log held a traceback (a SIGTERM can land so in xarray's
    WeakValueDictionary). With this hook such a KeyboardInterrupt or :class:`JobTerminated` is
    not printed; the same signal is sent again a moment later, when the finaliser has returned.
    Other unraisable exceptions go to Python's own hook.

    Examples
    --------
    >>> redeliver_swallowed_signals()
    >>> sys.unraisablehook is _redeliver
    True
    >>> sys.unraisablehook = sys.__unraisablehook__
    """
    sys.unraisablehook = _redeliver


def interrupted_line(rule: str, signame: str) -> str:
    """``microimpact: rule RULE interrupted (SIGINT): ...``: one line for a job stopped by a signal.

    Examples
    --------
    >>> interrupted_line("fit", "SIGINT")[:45]
    'microimpact: rule fit interrupted (SIGINT); i'
    """
    return (f"microimpact: rule {rule} interrupted ({signame}); its outputs were not written (files "
            f"written earlier are complete); resume the run with {RESUME}")


def one_line_reason(rule: str, exc: BaseException, log_path: str) -> str:
    """``microimpact: rule RULE failed: Type: first line of the message (traceback: LOG)``.

    Examples
    --------
    >>> one_line_reason("fit", ValueError("row 3: bad value\\nmore detail"), "logs/fit.log")
    'microimpact: rule fit failed: ValueError: row 3: bad value (traceback: logs/fit.log)'
    """
    message = str(exc).strip().splitlines()
    first = f": {message[0]}" if message else ""
    return f"microimpact: rule {rule} failed: {type(exc).__name__}{first} (traceback: {log_path})"


def log_job(snakemake, *, keep_stderr: bool = False) -> None:
    """Send the job's stdout (and stderr, unless ``keep_stderr``) to its log file, and report an
    uncaught exception as one line on the terminal besides the traceback in the log.

    Parameters
    ----------
    snakemake : snakemake.script.Snakemake
        The ``snakemake`` object of a ``script:`` job; ``snakemake.log[0]`` is the log file.
    keep_stderr : bool
        Leave stderr on the terminal, and show a failure's whole message there (a job whose error
        message is itself meant for the analyst, such as the data validation's list of problems).

    Examples
    --------
    A job's printout goes to its log; an uncaught exception puts its traceback in the log and one
    line on the terminal (here the example's output), a Ctrl-C the line that says how to resume:

    >>> import signal, sys
    >>> from pathlib import Path
    >>> from types import SimpleNamespace
    >>> saved = (sys.stdout, sys.stderr, sys.excepthook, sys.unraisablehook,
    ...          signal.getsignal(signal.SIGTERM))
    >>> sys.stderr = sys.stdout  # the terminal
    >>> log_job(SimpleNamespace(rule="fit", log=["fit.log"]))
    >>> print("fitting 12 impacts")
    >>> sys.excepthook(ValueError, ValueError("row 3: bad value"), None)
    microimpact: rule fit failed: ValueError: row 3: bad value (traceback: fit.log)
    >>> sys.excepthook(KeyboardInterrupt, KeyboardInterrupt(), None)
    microimpact: rule fit interrupted (SIGINT); its outputs were not written ... --rerun-incomplete
    >>> sys.stdout.close()
    >>> sys.stdout, sys.stderr, sys.excepthook, sys.unraisablehook = saved[:4]
    >>> _ = signal.signal(signal.SIGTERM, saved[4])
    >>> Path("fit.log").read_text().splitlines()
    ['fitting 12 impacts', 'ValueError: row 3: bad value',
     'microimpact: rule fit interrupted (SIGINT); its outputs were not written ...']
    """
    log_path = str(snakemake.log[0])
    log = open(log_path, "w", buffering=1)  # noqa: SIM115  (open for the job's lifetime)
    terminal = sys.stderr
    sys.stdout = log
    if not keep_stderr:
        sys.stderr = log

    def report(exc_type, exc, tb):
        if issubclass(exc_type, (KeyboardInterrupt, JobTerminated)):
            sig = signal.SIGINT if issubclass(exc_type, KeyboardInterrupt) else signal.SIGTERM
            line = interrupted_line(snakemake.rule, sig.name)
            print(line, file=log, flush=True)
            print(line, file=terminal, flush=True)
            if sig is signal.SIGTERM:  # end as SIGTERM ends a process (Python does so for SIGINT itself)
                signal.signal(signal.SIGTERM, signal.SIG_DFL)
                os.kill(os.getpid(), signal.SIGTERM)
            return
        traceback.print_exception(exc_type, exc, tb, file=log)
        log.flush()
        print(one_line_reason(snakemake.rule, exc, log_path), file=terminal, flush=True)
        if keep_stderr:  # the rest of the message too: it lists the problems
            print("\n".join(str(exc).strip().splitlines()[1:]), file=terminal, flush=True)

    sys.excepthook = report
    redeliver_swallowed_signals()

    def terminate(signum, frame):
        raise JobTerminated("SIGTERM")

    if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
        signal.signal(signal.SIGTERM, terminate)
