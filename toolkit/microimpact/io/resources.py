"""Memory a request needs, checked against the machine before the work starts.

A command whose memory grows with its arguments (posterior walkers x steps, a raster figure's
dots) estimates what it needs from them and refuses what cannot fit, naming the option and the
estimate, instead of growing until the kernel kills it (``fit --posterior --walkers 1000000000``
grew to 23 GB).
"""

from __future__ import annotations

import os

__all__ = ["available_memory", "check_memory", "MEMORY_FRACTION"]

#: a request may use at most this fraction of the memory available when it starts
MEMORY_FRACTION = 0.5


def available_memory() -> int | None:
    """Memory available to a new allocation [bytes]: ``MemAvailable`` of /proc/meminfo (Linux), else
    the free physical pages; None where neither is known.

    Examples
    --------
    >>> m = available_memory()
    >>> m is None or m > 0
    True
    """
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def _size(n: float) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n:.0f} B"


def check_memory(what: str, needed: float, available: int | None = None) -> None:
    """Raise ValueError if ``needed`` bytes exceed :data:`MEMORY_FRACTION` of the available memory.

    Parameters
    ----------
    what : str
        The request in the user's terms, naming its options (e.g. ``"--walkers 1e9 x --max-steps
        20000"``); first words of the message.
    needed : float
        Estimated bytes.
    available : int, optional
        Bytes available (default :func:`available_memory`); unknown: no check.

    Examples
    --------
    >>> check_memory("--dpi 200", 5e6, available=8_000_000_000)
    >>> check_memory("--dpi 1e6", 3e15, available=8_000_000_000)
    Traceback (most recent call last):
    ...
    ValueError: --dpi 1e6 needs about 3e+03 TB of memory; this machine has 8 GB available (at most half of it may be used)
    """
    available = available_memory() if available is None else available
    if available is not None and needed > MEMORY_FRACTION * available:
        raise ValueError(f"{what} needs about {_size(needed)} of memory; this machine has {_size(available)} "
                         f"available (at most half of it may be used)")
