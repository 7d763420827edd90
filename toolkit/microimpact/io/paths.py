"""Checks of a command's input and output paths, made before any work is done.

Nothing is lost: an output never replaces one of the inputs (by the same name, through a symbolic
link or a hard link), two outputs never share a path, and every output can be written before the
computation starts, so that a long fit does not end in an error about its output file. The
functions are pure (they only look at the file system) and raise :class:`PathError`, whose message
names the option at fault (``--out``, ``--nc``, ``data``, ...) and the path.

A trailing slash (``--out newdir/``) names a directory: an option that takes a file refuses it.
"""

from __future__ import annotations

import contextlib
import errno
import os
import sys
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path

__all__ = [
    "PathError",
    "print_before_writing",
    "check_input_file",
    "check_output_file",
    "check_output_dir",
    "check_outputs",
    "same_file",
    "reporting_os_errors",
    "DATA_README",
]

#: the data formats' documentation as installed with the package (a copy of the repository's
#: data/README.md, which an installed user does not have): help texts and errors name this path
DATA_README = Path(__file__).resolve().parents[1] / "data" / "README.md"

#: fall-backs when the file system does not say (POSIX minimum values are lower; these are Linux's)
_NAME_MAX = 255
_PATH_MAX = 4096


class PathError(ValueError):
    """A path that a command cannot use; ``option`` and ``path`` name the culprit.

    Subclass of ValueError: the command line reports it in one line with exit status 2.

    Examples
    --------
    The option and the path come first, so that a command line prints one line that names both:

    >>> check_input_file("--data", "missing.csv")
    Traceback (most recent call last):
    ...
    microimpact.io.paths.PathError: --data 'missing.csv': does not exist or is not a file
    >>> err = PathError("--out", "fit.nc", "is a directory")
    >>> str(err), err.option, err.path
    ("--out 'fit.nc': is a directory", '--out', 'fit.nc')
    """

    def __init__(self, option: str, path, reason: str):
        self.option = option
        self.path = str(path)
        self.reason = reason
        super().__init__(f"{option} {self.path!r}: {reason}")


def _directory_of(path: Path) -> Path:
    return path.parent if str(path.parent) else Path(".")


def _limit(directory: Path, name: str, fallback: int) -> int:
    try:
        return int(os.pathconf(directory, name))
    except (OSError, ValueError, AttributeError):
        return fallback


def _check_lengths(option: str, text: str, path: Path) -> None:
    directory = _directory_of(path)
    probe = directory if directory.is_dir() else Path(".")
    name_max = _limit(probe, "PC_NAME_MAX", _NAME_MAX)
    for part in path.parts:
        if len(os.fsencode(part)) > name_max:
            raise PathError(option, text, f"file name too long ({len(os.fsencode(part))} bytes; "
                                          f"this file system allows {name_max})")
    path_max = _limit(probe, "PC_PATH_MAX", _PATH_MAX)
    if len(os.fsencode(os.path.abspath(text))) >= path_max:
        raise PathError(option, text, f"path too long (this file system allows {path_max - 1} bytes)")


def _text(option: str, path) -> str:
    if path is None:
        raise PathError(option, "", "no path given")
    text = os.fspath(path)
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    if text == "":
        raise PathError(option, text, "empty path")
    if "\0" in text:
        raise PathError(option, text, "the path contains a NUL byte")
    return text


def check_input_file(option: str, path) -> Path:
    """``Path(path)`` if it is an existing, readable regular file; else :class:`PathError`.

    Parameters
    ----------
    option : str
        Name of the argument, for the message (``"data file"``, ``"--fit"``, ...).
    path : str or os.PathLike

    Examples
    --------
    >>> check_input_file("data file", "missing.csv")
    Traceback (most recent call last):
    ...
    microimpact.io.paths.PathError: data file 'missing.csv': does not exist or is not a file
    """
    text = _text(option, path)
    p = Path(text)
    _check_lengths(option, text, p)
    if not p.exists():
        raise PathError(option, text, "does not exist or is not a file")
    if p.is_dir():
        raise PathError(option, text, "is a directory, not a file")
    if not p.is_file():
        raise PathError(option, text, "does not exist or is not a file (not a regular file)")
    if not os.access(p, os.R_OK):
        raise PathError(option, text, "is not readable (permission denied)")
    return p


def check_output_file(option: str, path) -> Path:
    """``Path(path)`` if a file can be written there (atomically, through a temporary file next to it).

    Refused: a name with a trailing slash (a directory), an existing directory, a directory that
    does not exist or that this user cannot write, a name or path too long for the file system,
    an existing output that is not a regular file.

    Examples
    --------
    >>> check_output_file("--out", "out.nc")
    PosixPath('out.nc')
    """
    text = _text(option, path)
    if text.endswith(("/", os.sep)) or (os.altsep and text.endswith(os.altsep)):
        raise PathError(option, text, "ends with a slash, which names a directory; give a file name")
    p = Path(text)
    _check_lengths(option, text, p)
    if p.is_dir():
        raise PathError(option, text, "is an existing directory; give a file name")
    if p.exists() and not p.is_file():
        raise PathError(option, text, "exists and is not a regular file")
    directory = _directory_of(p)
    if not directory.exists():
        raise PathError(option, text, f"directory {str(directory)!r} does not exist")
    if not directory.is_dir():
        raise PathError(option, text, f"{str(directory)!r} is not a directory")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise PathError(option, text, f"directory {str(directory)!r} is not writable")
    _probe(option, text, directory, p.name)
    return p


def _probe(option: str, text: str, directory: Path, name: str, *, make_dir: bool = False) -> None:
    """Create (and remove) a temporary file, or directory, in ``directory``. os.access says yes to
    root everywhere, and a read-only or virtual file system (/sys, /proc, a read-only mount) refuses
    only when something is created: the refusal then comes before any work, not after it."""
    try:
        if make_dir:
            probe = tempfile.mkdtemp(dir=directory, prefix=f".{name}.", suffix=".tmp")
            os.rmdir(probe)
            return
        fd, probe = tempfile.mkstemp(dir=directory, prefix=f".{name}.", suffix=".tmp")
    except OSError as exc:
        raise PathError(option, text, f"cannot create {'a directory' if make_dir else 'a file'} in "
                                      f"{str(directory)!r}: {exc.strerror or exc}") from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)


def check_output_dir(option: str, path) -> Path:
    """``Path(path)`` if it is a writable directory or can be created (with its parents).

    Examples
    --------
    A directory that does not exist yet is accepted (and not created); a file in its place is not:

    >>> check_output_dir("--out", "results/run1"), Path("results").exists()
    (PosixPath('results/run1'), False)
    >>> _ = Path("data.csv").write_text("x")
    >>> check_output_dir("--out", "data.csv")
    Traceback (most recent call last):
    ...
    microimpact.io.paths.PathError: --out 'data.csv': exists and is not a directory
    """
    text = _text(option, path)
    p = Path(text)
    _check_lengths(option, text, p)
    if p.exists():
        if not p.is_dir():
            raise PathError(option, text, "exists and is not a directory")
        if not os.access(p, os.W_OK | os.X_OK):
            raise PathError(option, text, "directory is not writable")
        _probe(option, text, p, "output")
        return p
    ancestor = p.absolute().parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise PathError(option, text, f"{str(ancestor)!r} is not a directory")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise PathError(option, text, f"cannot create it: directory {str(ancestor)!r} is not writable")
    _probe(option, text, ancestor, p.name, make_dir=True)
    return p


def same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` name the same file: equal after resolving symbolic links and
    ``..``, or (both existing) the same inode, as for a hard link.

    Examples
    --------
    >>> import os
    >>> _ = open("a.csv", "w").write("x\\n")
    >>> os.symlink("a.csv", "b.csv")
    >>> same_file("a.csv", "b.csv"), same_file("a.csv", "c.csv")
    (True, False)
    """
    pa, pb = Path(a), Path(b)
    with contextlib.suppress(OSError):
        if pa.exists() and pb.exists() and os.path.samefile(pa, pb):
            return True
    try:
        return pa.resolve(strict=False) == pb.resolve(strict=False)
    except (OSError, RuntimeError):  # a symbolic-link loop
        return os.path.abspath(pa) == os.path.abspath(pb)


def check_outputs(outputs: Mapping[str, object], inputs: Mapping[str, object] | None = None) -> dict[str, Path]:
    """Check a command's output files against each other and against its inputs, before any work.

    Parameters
    ----------
    outputs : mapping of option name -> path or None
        The files the command will write (None: not asked for). Each must pass
        :func:`check_output_file`.
    inputs : mapping of option name -> path or None
        The files the command reads. No output may be, or resolve or link to, one of them.

    Returns
    -------
    dict of option name -> pathlib.Path
        The outputs that were given.

    Raises
    ------
    PathError
        Naming the output option, and the input option it collides with.

    Examples
    --------
    >>> _ = Path("impacts.csv").write_text("x")
    >>> check_outputs({"--out": "fit.nc", "--report": None}, {"DATA": "impacts.csv"})
    {'--out': PosixPath('fit.nc')}
    >>> check_outputs({"--out": "impacts.csv"}, {"DATA": "impacts.csv"})
    Traceback (most recent call last):
    ...
    microimpact.io.paths.PathError: --out 'impacts.csv': is the input DATA ('impacts.csv');
    an output never replaces an input: ...
    """
    given = {k: v for k, v in outputs.items() if v is not None}
    checked = {k: check_output_file(k, v) for k, v in given.items()}
    for name, path in checked.items():
        for in_name, in_path in (inputs or {}).items():
            if in_path is not None and same_file(path, in_path):
                raise PathError(name, given[name], f"is the input {in_name} ({str(in_path)!r}); "
                                                   "an output never replaces an input: choose another name")
    names = list(checked)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if same_file(checked[a], checked[b]):
                raise PathError(name_pair(a, b), given[a], "two outputs on one path; give each its own file")
    return checked


def name_pair(a: str, b: str) -> str:
    return f"{a} and {b}"


def _reason(exc: OSError) -> str:
    if exc.errno == errno.ENAMETOOLONG:
        return "file name too long"
    return exc.strerror or str(exc)


def _culprit(outputs: Mapping[str, object], filename) -> tuple[str, object]:
    """The output (option, path) that an OSError's file name belongs to: the file itself, or the
    hidden temporary ``.<name>.*.tmp`` written next to it; else the first output."""
    items = [(k, v) for k, v in outputs.items() if v is not None]
    if filename is not None:
        name = Path(os.fsdecode(filename)).name
        for option, path in items:
            p = Path(path)
            if name == p.name or name.startswith(f".{p.name}.") or Path(os.fsdecode(filename)) == p:
                return option, path
            if p.is_dir() or not p.suffix:  # an output directory: a file inside it
                with contextlib.suppress(ValueError):
                    Path(os.fsdecode(filename)).absolute().relative_to(p.absolute())
                    return option, path
    return items[0] if items else ("output", filename or "")


@contextlib.contextmanager
def reporting_os_errors(outputs: Mapping[str, object]) -> Iterator[None]:
    """Turn an OSError raised inside the block (writing ``outputs``: option name -> path) into a
    :class:`PathError` that names the option and the path it was writing.

    Examples
    --------
    >>> with reporting_os_errors({"--out": "missing/dir/fit.nc"}):
    ...     _ = open("missing/dir/fit.nc", "w")
    Traceback (most recent call last):
    ...
    microimpact.io.paths.PathError: --out 'missing/dir/fit.nc': cannot write:
    No such file or directory
    """
    try:
        yield
    except PathError:
        raise
    except OSError as exc:
        option, path = _culprit(outputs, exc.filename)
        detail = f" ({os.fsdecode(exc.filename)})" if exc.filename and Path(os.fsdecode(exc.filename)).name != Path(str(path)).name else ""
        raise PathError(option, path, f"cannot write: {_reason(exc)}{detail}") from exc


def print_before_writing(text: str) -> None:
    """Print a command's report on stdout, and make sure it is out, before the command writes its files.

    All or nothing: a report that cannot be printed (stdout on a full disk, ``> /dev/full``) is an
    error, status 2, before any output file exists; printed after the files, the same error left
    them in place under a status that says nothing was done. A reader that stopped reading
    (``| head``) is no failure of the command: its files are still written and it ends with 141.

    Raises
    ------
    PathError
        Naming stdout and the system's reason.
    """
    try:
        print(text)
        sys.stdout.flush()
    except BrokenPipeError:
        pass  # the command line's final flush raises it again, after the files: status 141
    except OSError as exc:
        try:  # the unprinted rest is dropped, or the interpreter's exit would fail on it again
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        raise PathError("stdout", "-", f"cannot be written ({exc.strerror or exc}); nothing written") from None
