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
import contextvars
import errno
import glob
import os
import stat
import tempfile
from collections.abc import Iterator, Mapping
from datetime import datetime, timezone
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np

from microimpact._runtime.signals import deferred_signals
from microimpact.io.variables import VARIABLES, udunits

__all__ = ["atomic_path", "atomic_write", "all_or_nothing", "recorded_outputs", "write_netcdf", "write_netcdf_groups", "write_csv", "NETCDF_COMPRESSION",
           "CONVENTIONS", "read_netcdf_groups", "restore_label_coordinates", "LABEL_OF"]

#: encoding added to every numeric, non-scalar NetCDF variable
NETCDF_COMPRESSION = {"zlib": True, "complevel": 4}


def _remove_orphans(directory: Path, name: str) -> None:
    """Remove the temporary files of ``name`` left by writers that were killed (SIGKILL, a crash):
    each temporary file carries its writer's process id, and one whose process is gone is an
    orphan. A live writer's file (this process or another) is left alone."""
    for tmp in directory.glob(f".{glob.escape(name)}.*.tmp"):
        parts = tmp.name[len(name) + 2:].split(".")
        if not parts or not parts[0].isdigit():
            continue  # not one of ours (or written before the id was in the name)
        pid = int(parts[0])
        try:
            os.kill(pid, 0)
            continue  # alive (or another user's): not ours to remove
        except ProcessLookupError:
            pass
        except PermissionError:
            continue
        with contextlib.suppress(OSError):
            tmp.unlink()


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

    Examples
    --------
    The file appears only when the block ends normally; an interrupted write leaves nothing:

    >>> with atomic_path("a.txt") as tmp:
    ...     _ = tmp.write_text("done")
    >>> Path("a.txt").read_text()
    'done'
    >>> try:
    ...     with atomic_path("b.txt") as tmp:
    ...         _ = tmp.write_text("half")
    ...         raise KeyboardInterrupt
    ... except KeyboardInterrupt:
    ...     pass
    >>> sorted(p.name for p in Path(".").iterdir() if p.name.startswith("b"))
    []
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise FileNotFoundError(f"cannot write {path}: directory {directory} does not exist")
    mode = _target_mode(path)
    _remove_orphans(directory, path.name)
    fd, tmp_name = tempfile.mkstemp(dir=directory, prefix=f".{path.name}.{os.getpid()}.", suffix=".tmp")
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
        pending = _TRANSACTION.get()
        if pending is not None:  # inside all_or_nothing(): moved into place when the whole block succeeds
            pending.append((tmp, path, mode, directory))
            return
        _commit([(tmp, path, mode, directory)])
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise


#: the lists of :func:`recorded_outputs` blocks now running, each collecting the outputs moved into place
_RECORDINGS: list[list[Path]] = []


@contextlib.contextmanager
def recorded_outputs():
    """Collect the files moved into place inside the block, in order: yields the list they are
    appended to (it keeps its contents after the block).

    A command that is interrupted reports from it what it had written (a Ctrl-C that lands after
    its outputs were moved into place must not be answered with "nothing was written"). Only
    running blocks record: a long-lived process that writes many files keeps no list of them.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "a.txt"
    >>> with recorded_outputs() as written:
    ...     with atomic_write(target) as f:
    ...         _ = f.write("a")
    >>> written == [target]
    True
    """
    record: list[Path] = []
    _RECORDINGS.append(record)
    try:
        yield record
    finally:
        _RECORDINGS.remove(record)


def _commit(moves) -> None:
    """Move finished temporary files into place, with SIGINT and SIGTERM held until all are moved:
    a signal between two moves would leave the first output written and the second's temporary
    file behind (a Ctrl-C of ``flags`` during its commit would leave ``x.csv`` and
    ``.x.nc.*.tmp``). The held signal is raised once every file is in place."""
    with deferred_signals():
        for tmp, path, mode, directory in moves:
            os.chmod(tmp, mode)
            os.replace(tmp, path)
            for record in _RECORDINGS:
                record.append(path)
            _fsync_dir(directory)


#: the files written inside all_or_nothing(), waiting to be moved into place: (tmp, path, mode, directory)
_TRANSACTION: contextvars.ContextVar = contextvars.ContextVar("microimpact_files_transaction", default=None)


@contextlib.contextmanager
def all_or_nothing() -> Iterator[None]:
    """Every file written inside the block (through :func:`atomic_path` and the writers built on it)
    appears when the block ends without an exception, and none does if it raises.

    A command with several outputs (a fit and its posterior; flags as CSV and NetCDF) thus never
    leaves the first written and the second missing: a failure on the second (an unwritable
    directory found only when writing) removes the first's temporary file too. Blocks nested in
    an outer one join it.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> try:
    ...     with all_or_nothing():
    ...         with atomic_write(d / "a.txt") as f:
    ...             _ = f.write("a")
    ...         raise OSError("the second output cannot be written")
    ... except OSError:
    ...     pass
    >>> sorted(p.name for p in d.iterdir())
    []
    """
    if _TRANSACTION.get() is not None:
        yield
        return
    pending: list = []
    token = _TRANSACTION.set(pending)
    try:
        yield
    except BaseException:
        with deferred_signals():  # a second Ctrl-C must not leave a temporary file behind
            for tmp, *_ in pending:
                with contextlib.suppress(FileNotFoundError):
                    tmp.unlink()
        raise
    finally:
        _TRANSACTION.reset(token)
    _commit(pending)


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


#: the CF version every NetCDF file of the toolkit follows (global attribute ``Conventions``)
CONVENTIONS = "CF-1.10"


def _history_line(path: Path) -> str:
    try:
        release = version("microimpact")
    except PackageNotFoundError:  # pragma: no cover - running from a bare source tree
        release = "0+unknown"
    now = datetime.now(timezone.utc).replace(microsecond=0).isoformat().replace("+00:00", "Z")
    return f"{now} microimpact {release} microimpact.io.files.write_netcdf: {path.name}"


def _conventions(existing) -> str:
    """``Conventions`` naming :data:`CONVENTIONS`; other conventions listed in ``existing`` are kept."""
    others = [c for c in str(existing or "").replace(",", " ").split() if not c.startswith("CF-")]
    return " ".join([CONVENTIONS, *others])


def _int32(value, what: str):
    """``value`` (an int64 array or scalar) as int32; a value int32 cannot hold is an error, not wrapped."""
    a = np.asarray(value)
    info = np.iinfo(np.int32)
    if a.size and (a.min() < info.min or a.max() > info.max):
        raise ValueError(f"{what}: values outside the int32 range cannot be written as CF integers")
    return a.astype(np.int32) if a.ndim else np.int32(a)


def _cf_attrs(attrs: Mapping, what: str) -> dict:
    """Attributes with units in the one UDUNITS style and int64 numbers as int32."""
    out = {}
    for key, value in attrs.items():
        if key == "units" or key.endswith("_units"):
            value = udunits(value) if isinstance(value, str) else value
        elif isinstance(value, (bool, np.bool_)):
            value = np.int8(value)
        elif isinstance(value, (int, np.integer)) or (isinstance(value, np.ndarray) and value.dtype.kind in "iu"
                                                       and value.dtype.itemsize > 4):
            value = _int32(value, f"{what} attribute {key}")
        out[key] = value
    return out


#: attribute of a text label variable written in place of a text coordinate variable: its dimension
LABEL_OF = "label_of_dimension"


def _labels_as_auxiliary_coordinates(ds):
    """Text coordinate variables (``parameter`` = zeta_hertz, zeta_adhesion, ...) as auxiliary
    coordinate variables ``<dim>_label`` along the same dimension (CF 6.1, labels).

    A CF coordinate variable is numeric and strictly monotonic (CF 5); compliance-checker's
    monotonicity check raised its own exception on text ones and exited 2. The dimension keeps its
    name (and the data variables along it); :func:`restore_label_coordinates` makes the label the
    index coordinate again when the file is read."""
    for name in [d for d in ds.dims if d in ds.variables and np.dtype(ds[d].dtype).kind in "OUS"]:
        coord = ds[name]
        attrs = dict(coord.attrs)
        if name in VARIABLES:
            attrs.setdefault("long_name", VARIABLES[name][1])
        attrs.setdefault("long_name", f"label of each {name}")
        ds = ds.drop_vars(name).assign_coords({f"{name}_label": (name, coord.values, attrs | {LABEL_OF: name})})
    return ds


def restore_label_coordinates(ds):
    """The inverse of the writer's label variables: each ``<dim>_label`` (marked with
    :data:`LABEL_OF`) becomes the index coordinate ``<dim>`` again, so ``.sel(parameter=...)``
    works on a file read back. Datasets without labels are returned as they are.

    Examples
    --------
    >>> import xarray as xr
    >>> ds = xr.Dataset({"x": ("p", [1.0, 2.0])}, coords={"p_label": ("p", ["a", "b"], {LABEL_OF: "p"})})
    >>> float(restore_label_coordinates(ds)["x"].sel(p="b"))
    2.0
    """
    for name in [n for n, v in ds.variables.items() if LABEL_OF in v.attrs]:
        var = ds[name]
        dim = var.attrs[LABEL_OF]
        attrs = {k: v for k, v in var.attrs.items() if k != LABEL_OF}
        ds = ds.drop_vars(name).assign_coords({dim: (dim, var.values, attrs)})
    return ds


def _cf_dataset(ds, *, root: bool, path: Path):
    """A copy of ``ds`` in the CF-1.10 form of the toolkit's files, and its per-variable encoding.

    - every variable has ``long_name`` (and ``units`` for a numeric quantity) from
      :data:`microimpact.io.variables.VARIABLES` where it has none of its own, units in one UDUNITS
      spelling (:func:`microimpact.io.variables.udunits`);
    - coordinate variables carry no ``_FillValue`` (CF 2.5.1: they must not have missing values);
    - 64-bit integers are written as int32 (values outside its range are an error), booleans as int8;
    - text is written as NetCDF strings (``NC_STRING``), not as character arrays;
    - numeric arrays are zlib-compressed; the rest of each variable's own encoding is kept;
    - the root group has ``Conventions`` = :data:`CONVENTIONS` and a ``history`` line for this write
      (appended to the history the Dataset already has).
    The values are not changed.
    """
    keep = {"dtype", "_FillValue", "scale_factor", "add_offset", "units", "calendar",
            "zlib", "complevel", "shuffle", "chunksizes", "fletcher32", "contiguous"}
    out = _labels_as_auxiliary_coordinates(ds.copy(deep=False))
    encoding = {}
    for name, var in out.variables.items():
        attrs = dict(var.attrs)
        if name in VARIABLES:
            units, long_name = VARIABLES[name]
            attrs.setdefault("long_name", long_name)
            if units is not None and var.dtype.kind in "biuf":
                attrs.setdefault("units", units)
        var.attrs = _cf_attrs(attrs, f"{path.name}: variable {name}")
        enc = {k: v for k, v in var.encoding.items() if k in keep}
        kind = np.dtype(var.dtype).kind
        if kind in "iu" and np.dtype(var.dtype).itemsize > 4 or enc.get("dtype") in ("int64", "uint64", np.int64):
            _int32(var.values, f"{path.name}: variable {name}")
            enc["dtype"] = "int32"
        elif kind == "b":
            enc["dtype"] = "int8"
        elif kind in "OUS":
            enc["dtype"] = str
            enc.pop("_FillValue", None)
        if name in out.dims:
            enc["_FillValue"] = None
        if var.ndim > 0 and kind in "biuf":
            enc.pop("contiguous", None)
            enc |= NETCDF_COMPRESSION
        encoding[name] = enc
    attrs = _cf_attrs(out.attrs, f"{path.name}: global")
    if root:
        attrs["Conventions"] = _conventions(attrs.get("Conventions"))
        previous = str(attrs.get("history", "")).rstrip("\n")
        attrs["history"] = (previous + "\n" if previous else "") + _history_line(path)
    out.attrs = attrs
    return out, encoding


def write_netcdf(ds, path) -> Path:
    """Write an xarray Dataset ``ds`` to a CF-1.10 NetCDF-4 file ``path`` atomically; return ``path``.

    The file follows CF-1.10 (see :func:`write_netcdf_groups` for what the writer adds); the values
    are written as they are. The same as ``write_netcdf_groups({None: ds}, path)``.

    Examples
    --------
    >>> import xarray as xr
    >>> path = write_netcdf(xr.Dataset({"e_n": ("speed", [0.5])}), "t.nc")
    >>> xr.open_dataset(path).attrs["Conventions"]
    'CF-1.10'
    """
    return write_netcdf_groups({None: ds}, path)


def write_netcdf_groups(groups: Mapping, path) -> Path:
    """Write several xarray Datasets to one CF-1.10 NetCDF-4 file atomically, one group each.

    Every file the toolkit writes goes through here, so the CF form is made in one place:
    ``Conventions`` = ``CF-1.10`` and a ``history`` line for this write on the root group (appended
    to the Dataset's own ``history``); ``long_name`` and ``units`` from
    :data:`microimpact.io.variables.VARIABLES` where a variable has none; units in one UDUNITS
    spelling; no ``_FillValue`` on coordinate variables; int32 instead of int64, int8 for booleans;
    text as NetCDF strings. Numeric variables are zlib-compressed and each variable's own encoding
    (dtype, fill value, units of times) is kept. The Datasets passed in are not modified.

    Parameters
    ----------
    groups : mapping of str or None to xarray.Dataset
        Group name (a path such as ``"a/b"`` makes nested groups) -> contents, written in this
        order; the key ``None`` (or ``"/"``) is the root group, written first wherever it stands
        in the mapping. Without a root entry the root group gets only the global attributes.
    path : str or os.PathLike
        Output file; replaced atomically.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    ValueError
        If no group is given, or an integer variable holds values outside the int32 range.
    OSError
        ENOSPC, naming ``path``, if the write failed on a file system without room for the file. The
        temporary file is removed, but the HDF5 library cannot close a file it failed to flush: its
        space comes back when the process ends.

    Examples
    --------
    >>> import numpy as np, xarray as xr, netCDF4
    >>> fit = xr.Dataset({"e_n": ("speed", np.array([0.5, 0.6]))}, coords={"speed": [1.0, 2.0]})
    >>> flags = xr.Dataset({"flag": ("row", np.array([True, False]))})
    >>> _ = write_netcdf_groups({None: fit, "flags": flags}, "r.nc")
    >>> with netCDF4.Dataset("r.nc") as nc:
    ...     print(nc.Conventions, list(nc.groups), nc["e_n"].units, nc["flags"]["flag"].dtype)
    CF-1.10 ['flags'] 1 int8
    """
    import xarray as xr

    items = sorted(groups.items(), key=lambda item: item[0] not in (None, "/"))  # stable: root first
    if not items:
        raise ValueError(f"nothing to write to {path}: no groups given")
    if items[0][0] not in (None, "/"):
        items.insert(0, (None, xr.Dataset()))
    path = Path(path)
    prepared = [(name, *_cf_dataset(ds, root=i == 0, path=path)) for i, (name, ds) in enumerate(items)]
    with atomic_path(path) as tmp, deferred_signals():  # a signal lands after the write: tmp is then removed
        try:
            for i, (name, ds, encoding) in enumerate(prepared):
                ds.to_netcdf(tmp, mode="w" if i == 0 else "a", group=None if name in (None, "/") else str(name),
                             engine="netcdf4", format="NETCDF4", encoding=encoding)
        except RuntimeError as exc:
            full = _no_room_for(prepared, tmp, path)
            if full is None:
                raise
            raise full from exc
    return path


#: bytes a NetCDF-4 file needs beyond its values (HDF5's superblock, object headers, attributes): an
#: upper bound for the toolkit's files, whose metadata are tens of kilobytes
_NETCDF_OVERHEAD = 1 << 20


def _no_room_for(prepared, tmp: Path, path: Path) -> OSError | None:
    """The ENOSPC error of a NetCDF write that failed on a file system with less room than the file
    needs (its values uncompressed and :data:`_NETCDF_OVERHEAD`), else None.

    HDF5 reports a write the disk refused only as ``RuntimeError('NetCDF: HDF error')``, its errno
    lost in the library; a full disk, the one cause a user can act on, is told by the free space."""
    try:
        st = os.statvfs(tmp.parent)
    except (OSError, AttributeError):  # no statvfs (Windows): the library's own message
        return None
    needed = sum(int(ds.nbytes) for _, ds, _ in prepared) + _NETCDF_OVERHEAD
    if st.f_bavail * st.f_frsize >= needed:
        return None
    return OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))


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

    Examples
    --------
    >>> import pandas as pd
    >>> write_csv(pd.DataFrame({"e_n": [0.5]}), "t.csv")
    PosixPath('t.csv')
    >>> open("t.csv").read()
    'e_n\\n0.5\\n'
    """
    to_csv_kwargs.setdefault("index", False)
    with atomic_write(path, "w", newline="") as f:
        df.to_csv(f, **to_csv_kwargs)
    return Path(path)


def read_netcdf_groups(path) -> list:
    """Read every group of a NetCDF-4 file written by :func:`write_netcdf_groups`, in file order.

    Groups that hold no variables (the root of a file of phase portraits, which only carries
    attributes, or a group that only holds other groups) are left out; nested groups are read
    depth first. Each group is loaded into memory and the file is closed.

    Parameters
    ----------
    path : str or os.PathLike
        NetCDF-4 file.

    Returns
    -------
    list of xarray.Dataset
        One Dataset per group with variables (the root first if it has any), with its own
        coordinates and attributes.

    Examples
    --------
    A round trip (booleans come back as the int8 they are stored as):

    >>> import numpy as np, xarray as xr
    >>> fit = xr.Dataset({"e_n": ("speed", np.array([0.5, 0.6]))}, coords={"speed": [1.0, 2.0]})
    >>> flags = xr.Dataset({"flag": ("row", np.array([True, False]))})
    >>> root, group = read_netcdf_groups(write_netcdf_groups({None: fit, "flags": flags}, "r.nc"))
    >>> root["e_n"].values.tolist(), root["speed"].values.tolist(), group["flag"].values.tolist()
    ([0.5, 0.6], [1.0, 2.0], [1, 0])
    """
    # imported here: io.files serves every writer, also the CSV-only ones, which need neither
    import netCDF4
    import xarray as xr

    def walk(group, prefix):
        here = [prefix or None] if group.variables else []
        return here + [p for name, child in group.groups.items() for p in walk(child, f"{prefix}/{name}")]

    with netCDF4.Dataset(path, "r") as nc:
        names = walk(nc, "")
    out = []
    for name in names:
        with xr.open_dataset(path, group=name, engine="netcdf4", decode_timedelta=False) as ds:
            out.append(restore_label_coordinates(ds.load()))
    return out
