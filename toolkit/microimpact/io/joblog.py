"""The log of a pipeline job: its output in the log file, a failure's reason on the terminal too.

Every script in ``workflow/scripts/`` starts with :func:`log_job`. Snakemake shows a failed job as
"Error in rule ... check log file(s)"; the reason itself would be only in the log. Here the full
traceback still goes to the log, and one line with the rule, the exception and its message goes
to the terminal, where the analyst is looking.
"""

from __future__ import annotations

import sys
import traceback

__all__ = ["log_job", "one_line_reason"]


def one_line_reason(rule: str, exc: BaseException, log_path: str) -> str:
    """``microimpact: rule RULE failed: Type: first line of the message (traceback: LOG)``."""
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
    """
    log_path = str(snakemake.log[0])
    log = open(log_path, "w", buffering=1)  # noqa: SIM115  (open for the job's lifetime)
    terminal = sys.stderr
    sys.stdout = log
    if not keep_stderr:
        sys.stderr = log

    def report(exc_type, exc, tb):
        traceback.print_exception(exc_type, exc, tb, file=log)
        log.flush()
        print(one_line_reason(snakemake.rule, exc, log_path), file=terminal, flush=True)
        if keep_stderr:  # the rest of the message too: it lists the problems
            print("\n".join(str(exc).strip().splitlines()[1:]), file=terminal, flush=True)

    sys.excepthook = report
