"""Snakemake's lock of a run directory: who holds it, and removing it when nobody does.

Snakemake marks a directory it works in with files in ``.snakemake/locks/`` and removes them when
it ends, also after Ctrl-C. A run that is killed (SIGKILL, a closed session, a power loss) leaves
them behind, and every later run stops with "Directory cannot be locked" until ``--unlock``. The
lock files record no process, so whether one is stale is decided here from the processes that
exist: a lock is stale when no Snakemake process (the scheduler or one of its jobs, whose command
lines all name Snakemake or its ``.snakemake/`` scripts) works in the directory. Linux shows each
process's working directory and command line under ``/proc``; elsewhere the question cannot be
answered and nothing is removed.

A run whose scheduler lives on another machine (a cluster's login node, with the directory on a
shared file system) is invisible here, so :func:`remove_stale_lock` is only for runs started on
this machine, as ``microimpact workflow`` starts them.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

__all__ = ["lock_files", "snakemake_processes_in", "remove_stale_lock"]


def lock_files(directory) -> list[Path]:
    """The lock files Snakemake keeps in ``directory`` (empty when it is not locked).

    Examples
    --------
    >>> import tempfile
    >>> lock_files(tempfile.mkdtemp())
    []
    """
    return sorted((Path(directory) / ".snakemake" / "locks").glob("*.lock"))


def _is_under(path: Path, directory: Path) -> bool:
    return path == directory or directory in path.parents


def snakemake_processes_in(directory) -> list[int] | None:
    """Process ids of the Snakemake processes that work in ``directory``, or None where this
    platform cannot list them (no ``/proc``).

    A process counts when its command line names Snakemake (``snakemake``, ``-m snakemake`` or a
    job script in ``.snakemake/``) and either its working directory is ``directory`` (or below it)
    or its command line names ``directory`` (a Snakemake started with ``--directory`` before it
    changes into it). This process itself does not count.

    Examples
    --------
    >>> import tempfile
    >>> snakemake_processes_in(tempfile.mkdtemp()) in ([], None)
    True
    """
    proc = Path("/proc")
    if not (proc / "self" / "cwd").exists():
        return None
    directory = Path(directory).resolve()
    found = []
    entries = [e for e in proc.iterdir() if e.name.isdigit() and int(e.name) != os.getpid()]
    for _ in range(2):
        blank = []
        for entry in entries:
            pid = _snakemake_process(entry, directory)
            if pid == 0:
                blank.append(entry)
            elif pid is not None:
                found.append(pid)
        if not blank:
            break
        # a process in the middle of exec shows an empty command line for a moment (kernel
        # threads always do): look at those once more
        entries = blank
        time.sleep(0.05)
    return sorted(found)


def _snakemake_process(entry: Path, directory: Path) -> int | None:
    """The process id of ``/proc/<pid>`` if it is a Snakemake process working in ``directory``,
    None if not, 0 if its command line is empty (being exec'd, or a kernel thread)."""
    try:
        words = (entry / "cmdline").read_bytes().decode(errors="replace").split("\0")
        cwd = Path(os.readlink(entry / "cwd"))
    except OSError:  # gone meanwhile, or another user's (then its cwd is unreadable)
        return None
    if words == [""]:
        return 0
    if not any("snakemake" in w.lower() for w in words):
        return None
    named = False
    for w in words:
        if w and not w.startswith("-"):
            try:
                named = named or _is_under((cwd / w).resolve(), directory)
            except (OSError, RuntimeError):
                pass
    return int(entry.name) if _is_under(cwd, directory) or named else None


def remove_stale_lock(directory) -> tuple[str, list]:
    """Remove Snakemake's lock of ``directory`` if no Snakemake process works there.

    Returns
    -------
    outcome : str
        ``"unlocked"`` (lock files were there and nobody held them: removed), ``"free"`` (no lock),
        ``"held"`` (Snakemake processes work there: nothing removed) or ``"unknown"`` (this platform
        cannot tell: nothing removed).
    detail : list
        The removed files (``"unlocked"``) or the holders' process ids (``"held"``); else empty.

    Examples
    --------
    >>> import tempfile
    >>> remove_stale_lock(tempfile.mkdtemp())
    ('free', [])
    """
    files = lock_files(directory)
    if not files:
        return "free", []
    holders = snakemake_processes_in(directory)
    if holders is None:
        return "unknown", []
    if holders:
        return "held", holders
    removed = []
    for f in files:
        try:
            f.unlink()
            removed.append(f)
        except FileNotFoundError:  # Snakemake (or another wrapper) removed it meanwhile
            pass
    return "unlocked", removed
