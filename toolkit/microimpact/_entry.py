"""The ``microimpact`` console script: :func:`microimpact.cli.main` in a process of its own.

What only a process of its own may do lives here, not in :mod:`microimpact.cli`, which a test or
a program imports and calls: install signal handlers. A Ctrl-C while the command imports numpy
ends in the same one line as one during the work, not in a
traceback from inside numpy; and a signal that lands in a finaliser still stops the command
(:func:`microimpact._runtime.joblog.redeliver_swallowed_signals`). Where SIGINT is ignored (a
background job) it stays ignored. After the one line of a Ctrl-C the process ends at once
(``os._exit``), without the finalisers of a compile the signal cut short. Warnings are printed
as one line each, ``microimpact: warning: ...``.
"""

from __future__ import annotations

import faulthandler
import os
import signal
import sys
import warnings

from microimpact._runtime.signals import COMPILED_ENV, EXIT_INTERRUPTED, INTERPRETED_SECONDS, INTERRUPTED_LINE

def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one line, ``microimpact: warning: MESSAGE``: Python's form names a file and a
    source line of the installation, not the analyst's input; other libraries' warnings keep
    their category's name."""
    own = category.__module__.startswith("microimpact")
    print(f"microimpact: warning: {message}" + ("" if own else f" ({category.__name__})"),
          file=sys.stderr if file is None else file)


class _CompileInstead(BaseException):
    """The interpreted impact ran past :data:`INTERPRETED_SECONDS` (a BaseException: no handler of
    the command's errors takes it for one)."""


def _too_slow(signum, frame):
    raise _CompileInstead


def _interpreted(argv) -> bool:
    """Whether this process solves ``simulate``'s impact interpreted.

    Compiled, one impact is quick, but numba compiles the solvers first (after an install) or loads
    them from its cache, which takes far longer than the impact; the same Python code run by the
    interpreter takes less for an impact of ordinary difficulty, and its numbers are the compiled
    code's, bit for bit, since no kernel uses fastmath (tests/test_cli.py compares them). An
    impact that needs more than :data:`INTERPRETED_SECONDS` (millions of steps) is started again
    compiled, as is one whose interpreted run fails in a way the compiled one might not. Not where
    numba is already imported (nothing to gain), where the user set ``NUMBA_DISABLE_JIT``, or in
    the process started again."""
    return (argv[:1] == ["simulate"] and "numba" not in sys.modules and "NUMBA_DISABLE_JIT" not in os.environ
            and COMPILED_ENV not in os.environ)


def _start_compiled(argv):
    """Replace this process by the same command with numba compiling (exec: same pid, no output
    written yet).

    The interpreted run's interval timer is cancelled first: a timer survives ``execve``, and its
    SIGALRM, whose handler the new image no longer has, would kill the compiled command (exit 142,
    nothing printed) a few seconds into its compile."""
    signal.setitimer(signal.ITIMER_REAL, 0.0)
    signal.signal(signal.SIGALRM, signal.SIG_DFL)
    sys.stdout.flush()
    sys.stderr.flush()
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_JIT"} | {COMPILED_ENV: "1"}
    os.execve(sys.executable, [sys.executable, "-m", "microimpact._entry", *argv], env)


def _interrupted_while_starting(signum, frame):
    print(INTERRUPTED_LINE, file=sys.stderr)
    raise SystemExit(EXIT_INTERRUPTED)


def main() -> int:
    """Run the command line of ``sys.argv``; the exit status."""
    # a crash of compiled code (SIGSEGV, SIGBUS, SIGFPE, SIGABRT) prints where it happened before the
    # process dies as before, instead of nothing (a fit stopped by Ctrl-C has been seen to end so)
    faulthandler.enable()
    starting = signal.getsignal(signal.SIGINT) is signal.default_int_handler
    if starting:
        signal.signal(signal.SIGINT, _interrupted_while_starting)
    from microimpact.cli import main as cli_main
    from microimpact._runtime.joblog import redeliver_swallowed_signals

    if starting:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    redeliver_swallowed_signals()
    warnings.showwarning = _show_warning
    argv = sys.argv[1:]
    interpreted = _interpreted(argv) and hasattr(signal, "setitimer")
    if interpreted:
        os.environ["NUMBA_DISABLE_JIT"] = "1"  # read by numba when it is first imported, below
    try:
        if interpreted:
            # armed inside the try: an alarm due before the command's first line (a short budget on
            # a loaded machine) is a restart, not an uncaught _CompileInstead
            signal.signal(signal.SIGALRM, _too_slow)
            signal.setitimer(signal.ITIMER_REAL, float(os.environ.get("MICROIMPACT_INTERPRETED_SECONDS", INTERPRETED_SECONDS)))
        status = cli_main(argv)
    except _CompileInstead:
        _start_compiled(argv)
    except Exception:
        if not interpreted:
            raise
        _start_compiled(argv)  # an error of the interpreted run only: the compiled one decides
    finally:
        if interpreted:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
    if status == EXIT_INTERRUPTED:
        # The one line is printed and nothing was written; skip the interpreter's finalisation.
        # A Ctrl-C that stops numba in the middle of a compile leaves llvmlite objects whose
        # finalisers print "Exception ignored in: ObjectRef.__del__" at exit, a second message
        # after the one line.
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    return status


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
