"""numba's ``njit`` for the compiled parts of microimpact, with an on-disk cache that cannot go stale.

numba's ``cache=True`` notices edits to the compiled function's own file only, so a solver kernel
that inlines a law of :mod:`microimpact.model.law` kept the old law after the law was edited. Every
kernel of the package is therefore cached under a directory named after a hash of the sources of
everything that is compiled (``model/``, ``solvers/`` and this file): a change to any of them
starts a new cache, and an old one is never read again.

Where the cache lives: ``$NUMBA_CACHE_DIR/microimpact-<hash>`` when the user sets
``NUMBA_CACHE_DIR``; otherwise ``__pycache__/numba-<hash>`` beside this file, or, where the package
directory cannot be written (a system-wide install), ``~/.cache/microimpact/numba-<hash>``. The
directory is set for the package's own functions only, at their decoration; other packages'
numba caches are not touched.

No kernel uses ``fastmath``: with it, the code numba runs right after compiling and the code it
later loads from its cache come from two separate passes of LLVM's back end and round differently,
so a first (compiling) run and a second (cached) run of the same computation gave different
numbers. Without it they are bitwise equal (``tests/test_compile_cache.py``), and the engine is
not slower (``microimpact benchmark`` compares such variants side by side).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import types
from pathlib import Path

try:
    import fcntl
except ImportError:  # not POSIX (Windows): no lock between processes, each compiles on its own
    fcntl = None

import numba
import numpy as np
from numba.core import config

__all__ = ["njit", "njit_batch", "cache_directory", "source_hash"]

_PACKAGE = Path(__file__).resolve().parent
#: the sources whose compiled code is cached: a change to any of them invalidates every kernel
_COMPILED_SOURCES = ("model", "solvers")


@functools.lru_cache(maxsize=1)
def source_hash() -> str:
    """First 16 hex digits of the sha256 of the compiled sources (``model/``, ``solvers/``, this file).

    Examples
    --------
    >>> len(source_hash())
    16
    """
    digest = hashlib.sha256()
    files = sorted(p for d in _COMPILED_SOURCES for p in (_PACKAGE / d).glob("*.py")) + [Path(__file__).resolve()]
    for path in files:
        digest.update(path.relative_to(_PACKAGE).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


@functools.lru_cache(maxsize=1)
def cache_directory() -> str:
    """The directory of this version's compiled kernels (module docstring).

    Examples
    --------
    >>> source_hash() in cache_directory()
    True
    """
    user = os.environ.get("NUMBA_CACHE_DIR")
    if user:
        return os.path.join(user, f"microimpact-{source_hash()}")
    local = _PACKAGE / "__pycache__"
    try:
        local.mkdir(exist_ok=True)
        if os.access(local, os.W_OK):
            return str(local / f"numba-{source_hash()}")
    except OSError:
        pass
    return os.path.join(os.path.expanduser("~"), ".cache", "microimpact", f"numba-{source_hash()}")


def njit(*args, **kwargs):
    """:func:`numba.njit`, with the package's cache directory for ``cache=True`` (module docstring).

    Used as ``@njit(cache=True, ...)`` or ``njit(inline="always", cache=True)(func)``.

    Examples
    --------
    A compiled function gives what its Python source gives; the package's cached kernels keep
    their compiled code under :func:`cache_directory`:

    >>> @njit
    ... def squared_norm(x, y):
    ...     return x * x + y * y
    >>> squared_norm(3.0, 4.0), squared_norm.py_func(3.0, 4.0)
    (25.0, 25.0)
    >>> from microimpact.solvers import engine
    >>> cache = getattr(engine._energy, "_cache", None)  # None interpreted: nothing is compiled
    >>> cache is None or cache.cache_path.startswith(cache_directory())
    True

    Interpreted (``NUMBA_DISABLE_JIT=1``) the function runs as Python and hands back what the
    compiled one would (:func:`_interpreted`), with ``py_func`` its Python source as compiled.
    """
    if len(args) == 1 and callable(args[0]) and not kwargs:  # bare @njit
        return _decorate(args[0], ())
    return lambda func: _decorate(func, args, **kwargs)


def _decorate(func, args, **kwargs):
    if config.DISABLE_JIT:
        return _interpreted(func)
    if not kwargs.get("cache"):
        return numba.njit(*args, **kwargs)(func)
    previous = config.CACHE_DIR
    config.CACHE_DIR = cache_directory()  # read when the dispatcher sets up its cache, i.e. now
    try:
        return numba.njit(*args, **kwargs)(func)
    finally:
        config.CACHE_DIR = previous


def _interpreted(func):
    """``func`` run as Python, its results boxed as numba boxes a compiled function's: a numpy scalar
    (interpreted, ``u[1]`` of an array is ``np.float64``) as the Python number it holds, also inside a
    tuple or named tuple; arrays as they are. So results, and what they print, do not depend on
    whether numba compiled the kernels, and code that builds records from them has nothing to convert.

    Examples
    --------
    >>> run = _interpreted(lambda x: (np.float64(x), np.True_, np.zeros(1)))
    >>> run(0.5)[:2], type(run(0.5)[2]).__name__, run.py_func(0.5)[0]
    ((0.5, True), 'ndarray', np.float64(0.5))
    """

    @functools.wraps(func)
    def run(*args, **kwargs):
        return _boxed(func(*args, **kwargs))

    run.py_func = func
    return run


def _boxed(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, tuple):
        items = [_boxed(v) for v in value]
        return type(value)(*items) if hasattr(value, "_fields") else tuple(items)
    return value


def njit_batch(func, *, cache: bool = True):
    """A loop over a batch (``for i in numba.prange(n)``), compiled for threads only when threads run it.

    Returns a callable that runs ``func`` compiled with ``parallel=True`` when numba has more than
    one thread (:func:`numba.get_num_threads`), and compiled as a plain loop otherwise. Both
    versions are compiled, and cached, on first use only: a process on one thread (every rule of
    the pipeline, the fits and the sampler) never compiles the parallel one, whose parfor passes
    are its costliest part. The impacts of a batch are independent, so both give the same numbers,
    bit for bit. ``cache`` as for :func:`numba.njit` (True for the package's kernels).

    Examples
    --------
    >>> import numpy as np
    >>> from numba import prange
    >>> def squares(x, out):
    ...     for i in prange(x.shape[0]):
    ...         out[i] = x[i] * x[i]
    >>> kernel = njit_batch(squares, cache=False)  # a doctest has no file to cache beside
    >>> out = np.empty(3)
    >>> kernel(np.arange(3.0), out)
    >>> out.tolist()
    [0.0, 1.0, 4.0]
    """
    return _BatchKernel(func, cache)


class _BatchKernel:
    """The two compiled versions of a batch loop (:func:`njit_batch`), each made on first use."""

    def __init__(self, func, cache):
        functools.update_wrapper(self, func)
        self.py_func = func
        self._caching = cache
        self._parallel = None
        self._serial = None

    @property
    def parallel(self):
        """The version compiled with ``parallel=True`` (prange over numba's threads)."""
        if self._parallel is None:
            self._parallel = _decorate(self.py_func, (), cache=self._caching, parallel=True)
        return self._parallel

    @property
    def serial(self):
        """The version compiled as a plain loop.

        numba's cache files are named after the function's qualified name and first line, not
        its compile options, so the serial version compiles a copy of the function under a name
        of its own: otherwise the two versions would overwrite each other's cache entries."""
        if self._serial is None:
            func = self.py_func
            copy = types.FunctionType(func.__code__, func.__globals__, func.__name__ + "_serial",
                                      func.__defaults__, func.__closure__)
            copy.__qualname__ = func.__qualname__ + "_serial"
            copy.__module__ = func.__module__
            self._serial = _decorate(copy, (), cache=self._caching)
        return self._serial

    def __call__(self, *args):
        kernel = self.parallel if numba.get_num_threads() > 1 else self.serial
        if self._caching and getattr(kernel, "overloads", None) == {}:  # this process's first call
            with _compile_lock(kernel):
                # compile() first looks in the cache, which a process that held the lock before
                # this one has just filled: a kernel is compiled once, not in every job at once
                kernel.compile(tuple(kernel.typeof_pyval(a) for a in args))
        return kernel(*args)


@contextlib.contextmanager
def _compile_lock(kernel):
    """Hold an exclusive lock, shared by every process that uses the same cache directory, on the
    first compile of one batch kernel.

    Two pipeline jobs that start at once (the fit and the benchmark) would otherwise both compile
    the engine's batch kernel, tens of seconds of CPU each; with the lock the second waits for the
    first to write the kernel to numba's cache and loads it from there. Without a lockable cache
    directory (read-only, or no ``fcntl``) each process compiles on its own, as numba does.
    """
    handle = None
    if fcntl is not None:
        func = kernel.py_func
        path = os.path.join(cache_directory(), f"{func.__module__}.{func.__qualname__}.lock")
        try:
            os.makedirs(os.path.dirname(path), exist_ok=True)
            handle = open(path, "a")
            fcntl.flock(handle, fcntl.LOCK_EX)
        except OSError:
            if handle is not None:
                handle.close()
            handle = None
    try:
        yield
    finally:
        if handle is not None:
            fcntl.flock(handle, fcntl.LOCK_UN)
            handle.close()
