"""argparse's exits as return values, for the ``main(argv) -> int`` of every command line.

argparse ends ``--help``, ``--version`` and a usage error with :class:`SystemExit`; a ``main`` that
documents a returned status (the CLI, ``python -m microimpact.studies.stress``, the developer
studies under tests/) turns it into that status here, once.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence


def exit_status(exc: SystemExit) -> int:
    """The process status that ``exc`` stands for: its code if an int, 0 for None, else 2 (a message).

    Examples
    --------
    >>> exit_status(SystemExit()), exit_status(SystemExit(2)), exit_status(SystemExit("bad input"))
    (0, 2, 2)
    """
    return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)


def parse_or_status(parser: argparse.ArgumentParser, argv: Sequence[str] | None,
                    check: Callable[[argparse.Namespace], None] | None = None):
    """``(namespace, None)``, or ``(None, status)`` where argparse (or ``check``, which may call
    ``parser.error``) would have exited: 0 after ``--help``, 2 after a usage error (its message is
    on stderr, as argparse writes it).

    Examples
    --------
    >>> import contextlib, io
    >>> p = argparse.ArgumentParser(prog="demo")
    >>> _ = p.add_argument("--cases", type=int, default=1)
    >>> def positive(args):
    ...     if args.cases < 0:
    ...         p.error("--cases must be >= 0")
    >>> parse_or_status(p, ["--cases", "3"], positive)[0].cases
    3
    >>> with contextlib.redirect_stderr(io.StringIO()) as err:
    ...     print(parse_or_status(p, ["--cases", "-1"], positive))
    (None, 2)
    >>> err.getvalue().splitlines()[-1]
    'demo: error: --cases must be >= 0'
    """
    try:
        args = parser.parse_args(argv)
        if check is not None:
            check(args)
    except SystemExit as exc:
        return None, exit_status(exc)
    return args, None
