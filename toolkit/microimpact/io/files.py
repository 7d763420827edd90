"""Atomic file output: every writer in the toolkit goes through these.

A file is written to a temporary file in the same directory, flushed and fsync'ed, then moved over
the target with :func:`os.replace` (atomic on POSIX and Windows for a same-filesystem move). An
exception, a kill or a crash therefore leaves either the old file or the complete new one, never a
half-written file; on an exception the temporary file is removed. (After SIGKILL or a power loss a
hidden ``.<name>.*.tmp`` file may remain next to the target; it is never mistaken for the output.)

The new file gets the permissions a plain ``open(path, "w")`` would give it (0666 minus the umask),
or keeps those of the file it replaces.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from collections.abc import Iterator, Mapping
from pathlib import Path

import numpy as np

__all__ = ["atomic_path", "atomic_write", "write_netcdf", "write_netcdf_groups", "write_csv", "NETCDF_COMPRESSION"]

#: encoding added to every numeric, non-scalar NetCDF variable
NETCDF_COMPRESSION = {"zlib": True, "complevel": 4}


def _target_mode(path: Path) -> int:
    try:
        return stat.S_IMODE(path.stat().st_mode)
    except FileNotFoundError:
        umask = os.umask(0)  # reading the umask means setting it; restore at once
        os.umask(umask)
        return 0o666 & ~umask


def _fsync_dir(directory: Path) -> None:
    if os.name != "posix":
        return
    fd = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_path(path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; on success move it over ``path`` atomically.

    For writers that need a file name rather than a file object (NetCDF, matplotlib, PDF).
    Whatever is at the temporary path when the ``with`` block ends without an exception is
    fsync'ed and replaces ``path``; on an exception it is removed and ``path`` is untouched.

    Parameters
    ----------
    path : str or os.PathLike
        Final file. Its directory must exist.

    Raises
    ------
    FileNotFoundError
        If the directory of ``path`` does not exist, or the block created no file.
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise FileNotFoundError(f"cannot write {path}: directory {directory} does not exist")
    mode = _target_mode(path)
    fd, tmp_name = tempfile.mkstemp(dir=directory, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        if not tmp.exists():
            raise FileNotFoundError(f"nothing was written to the temporary file for {path}")
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.chmod(tmp, mode)
        os.replace(tmp, path)
        _fsync_dir(directory)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise


@contextlib.contextmanager
def atomic_write(path, mode: str = "w", *, encoding: str | None = "utf-8", newline: str | None = None):
    """Open ``path`` for writing so that it is replaced atomically when the block succeeds.

    Parameters
    ----------
    path : str or os.PathLike
        Final file. Its directory must exist.
    mode : {"w", "wt", "wb"}
        Text or binary write mode.
    encoding : str or None
        Text encoding (text modes only).
    newline : str or None
        As for :func:`open` (text modes only); use ``""`` for the :mod:`csv` module.

    Yields
    ------
    file object
        Open on a temporary file in the same directory. Its contents replace ``path`` when the
        ``with`` block exits normally; on an exception the temporary file is removed and ``path``
        is left as it was.

    Examples
    --------
    >>> with atomic_write("out.txt") as f:  # doctest: +SKIP
    ...     f.write("all or nothing\\n")
    """
    if mode not in ("w", "wt", "wb"):
        raise ValueError(f"atomic_write mode must be 'w', 'wt' or 'wb', got {mode!r}")
    binary = "b" in mode
    with atomic_path(path) as tmp:
        with open(tmp, mode, **({} if binary else {"encoding": encoding, "newline": newline})) as f:
            yield f
            f.flush()
            os.fsync(f.fileno())


def _netcdf_encoding(ds) -> dict[str, dict]:
    """Per-variable encoding: the variable's own (valid) encoding plus zlib for numeric arrays."""
    keep = {"dtype", "_FillValue", "scale_factor", "add_offset", "units", "calendar",
            "zlib", "complevel", "shuffle", "chunksizes", "fletcher32", "contiguous"}
    encoding = {}
    for name, var in ds.variables.items():
        enc = {k: v for k, v in var.encoding.items() if k in keep}
        if var.ndim > 0 and np.dtype(var.dtype).kind in "biuf":
            enc.pop("contiguous", None)
            enc |= NETCDF_COMPRESSION
        encoding[name] = enc
    return encoding


def write_netcdf(ds, path) -> Path:
    """Write an xarray Dataset ``ds`` to NetCDF-4 file ``path`` atomically; return ``path``.

    Numeric variables are zlib-compressed; each variable's own encoding (dtype, fill value, units
    of times) is kept. The same as ``write_netcdf_groups({None: ds}, path)``.
    """
    return write_netcdf_groups({None: ds}, path)


def write_netcdf_groups(groups: Mapping, path) -> Path:
    """Write several xarray Datasets to one NetCDF-4 file atomically, one group each.

    Numeric variables are zlib-compressed and each variable's own encoding is kept, as in
    :func:`write_netcdf`.

    Parameters
    ----------
    groups : mapping of str or None to xarray.Dataset
        Group name -> contents, written in this order; the key ``None`` (or ``"/"``) is the root
        group, written first wherever it stands in the mapping.
    path : str or os.PathLike
        Output file; replaced atomically.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    items = sorted(groups.items(), key=lambda item: item[0] not in (None, "/"))  # stable: root first
    if not items:
        raise ValueError(f"nothing to write to {path}: no groups given")
    path = Path(path)
    with atomic_path(path) as tmp:
        for i, (name, ds) in enumerate(items):
            ds.to_netcdf(tmp, mode="w" if i == 0 else "a", group=None if name in (None, "/") else str(name),
                         engine="netcdf4", format="NETCDF4", encoding=_netcdf_encoding(ds))
    return path


def write_csv(df, path, **to_csv_kwargs) -> Path:
    """Write a pandas DataFrame to CSV atomically (UTF-8, no index unless asked).

    Parameters
    ----------
    df : pandas.DataFrame
        Table to write.
    path : str or os.PathLike
        Output file; replaced atomically.
    **to_csv_kwargs
        Passed to :meth:`pandas.DataFrame.to_csv` (default ``index=False``).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    to_csv_kwargs.setdefault("index", False)
    with atomic_write(path, "w", newline="") as f:
        df.to_csv(f, **to_csv_kwargs)
    return Path(path)


def read_netcdf_groups(path) -> list:
    """Read every group of a NetCDF-4 file written by :func:`write_netcdf_groups`, in file order.

    The root group is left out when it holds no variables (it then only carries attributes, as in
    a file of phase portraits); each group is loaded into memory and the file is closed.

    Parameters
    ----------
    path : str or os.PathLike
        NetCDF-4 file.

    Returns
    -------
    list of xarray.Dataset
        One Dataset per group (the root first if it has variables), with its own coordinates and
        attributes.
    """
    # imported here: io.files serves every writer, also the CSV-only ones, which need neither
    import netCDF4
    import xarray as xr

    with netCDF4.Dataset(path, "r") as nc:
        names = ([None] if nc.variables else []) + list(nc.groups)
    out = []
    for name in names:
        with xr.open_dataset(path, group=name, engine="netcdf4", decode_timedelta=False) as ds:
            out.append(ds.load())
    return out
