"""What a file is, in words, for the message that refuses it where another kind was expected.

A NetCDF file given as the CSV of measured impacts produced 4277 "invalid UTF-8" problems, an Excel
workbook 316, and a posterior given as ``--fit`` a message about a missing ``zeta_hertz``
variable. Each reader asks :func:`file_kind` once it has failed, and the message says what the file
is: "a NetCDF file titled 'posterior of ...'", "an Excel workbook (.xlsx)", "CSV text", ...
The file's first bytes decide (the formats' signatures), and for NetCDF its ``title`` attribute,
which every file microimpact writes carries.
"""

from __future__ import annotations

import contextlib
import linecache
import re
import zipfile
from pathlib import Path

import netCDF4
import numpy as np

__all__ = ["file_kind", "is_binary", "layout_mismatch", "unreadable_content"]

#: leading bytes -> what the file is
_SIGNATURES = (
    (b"\x89HDF\r\n\x1a\n", "netcdf"),
    (b"CDF\x01", "netcdf"),
    (b"CDF\x02", "netcdf"),
    (b"CDF\x05", "netcdf"),
    (b"PK\x03\x04", "zip"),
    (b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1", "an old-format Microsoft Office file (e.g. an Excel .xls workbook)"),
    (b"%PDF", "a PDF document"),
    (b"\x89PNG", "a PNG image"),
    (b"\xff\xd8\xff", "a JPEG image"),
    (b"\x1f\x8b", "a gzip-compressed file"),
)


def _netcdf_kind(path: Path) -> str:
    try:
        with netCDF4.Dataset(path) as nc:
            title = str(getattr(nc, "title", "")).strip()
    except Exception:  # noqa: BLE001 - a damaged file is still a NetCDF file by its signature
        return "a NetCDF file that cannot be read (damaged or truncated)"
    return f"a NetCDF file titled {title!r}" if title else "a NetCDF file without a title (not written by microimpact)"


def _zip_kind(path: Path) -> str:
    try:
        with zipfile.ZipFile(path) as z:
            names = z.namelist()
    except (zipfile.BadZipFile, OSError):
        return "a damaged zip archive"
    if any(n.startswith("xl/") for n in names):
        return "an Excel workbook (.xlsx)"
    if any(n.startswith("content.xml") for n in names):
        return "an OpenDocument file (e.g. a LibreOffice .ods spreadsheet)"
    return "a zip archive"


def file_kind(path) -> str:
    """What the file at ``path`` is, as words that follow "is" in a message.

    Parameters
    ----------
    path : str or os.PathLike
        An existing file.

    Returns
    -------
    str
        e.g. ``"a NetCDF file titled 'damping fit of ...'"``, ``"an Excel workbook (.xlsx)"``,
        ``"an empty file"``, ``"binary data"``, ``"a text file"``.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "impacts.csv"
    >>> _ = p.write_text("radius [um],speed [m/s]\\n1.0,2.0\\n")
    >>> file_kind(p)
    'a text file'
    >>> _ = p.write_bytes(b"PK\\x03\\x04 not really a zip")
    >>> file_kind(p)
    'a damaged zip archive'
    """
    path = Path(path)
    try:
        with open(path, "rb") as f:
            head = f.read(4096)
    except OSError as exc:
        return f"unreadable ({exc.strerror or exc})"
    if not head:
        return "an empty file"
    for signature, kind in _SIGNATURES:
        if head.startswith(signature):
            if kind == "netcdf":
                return _netcdf_kind(path)
            if kind == "zip":
                return _zip_kind(path)
            return kind
    if b"\0" in head:
        return "binary data"
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(head) - 4:  # not merely a character cut at the 4096-byte boundary
            return "a text file that is not UTF-8, or binary data"
    return "a text file"


def is_binary(path) -> bool:
    """True when the file is of a known binary format or holds NUL bytes: not a text file, even a
    badly encoded one (whose lines the CSV reader reports one by one).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "x.csv"
    >>> _ = p.write_bytes(b"CDF\\x01\\x00\\x00")
    >>> is_binary(p)
    True
    """
    kind = file_kind(path)
    return not (kind.startswith("a text file") or kind in ("an empty file", "binary data") or kind.startswith("unreadable"))


def unreadable_content(path, ds, exc: BaseException) -> str:
    """One line for a result file whose content a reader could not take: the file, the variable or
    attribute it was reading, that variable's shape and type, and what went wrong.

    The reader (``from_dataset`` of a result class) failed with ``exc`` on the Dataset ``ds`` read
    from ``path``. The variable is the name it was reading when it failed: a missing one is the
    KeyError's, else the innermost frame of the reader that holds a string naming a variable or
    an attribute of ``ds`` (the loop variable of ``{n: float(ds[n]) for n in ...}``).

    Examples
    --------
    >>> import xarray as xr
    >>> ds = xr.Dataset({"zeta_hertz": ("x", [0.5, 0.6])})
    >>> try:
    ...     {n: float(ds[n]) for n in ["zeta_hertz"]}
    ... except TypeError as exc:
    ...     print(unreadable_content("fit.nc", ds, exc))
    fit.nc: variable 'zeta_hertz' (shape (2,), float64) does not read: only 0-dimensional arrays can be converted to Python scalars (TypeError)
    """
    names = set(map(str, ds.variables)) | set(map(str, ds.attrs))
    missing = isinstance(exc, KeyError) and bool(exc.args) and str(exc.args[0]) not in names
    # a KeyError for a name the file lacks is a missing variable; one for a value the file holds
    # (a label read as a key: 'x') is a variable that does not read
    if missing and isinstance(exc.args[0], str):
        missing = not any(v.dtype.kind in "OUS" and exc.args[0] in set(map(str, np.asarray(v.values).ravel()[:1000]))
                          for v in ds.variables.values())
    name = exc.args[0] if missing else None
    tb, frames = exc.__traceback__, []
    while tb is not None:
        frames.append((tb.tb_frame, tb.tb_lasti))
        tb = tb.tb_next
    if name is None:
        certain, possible = _best_effort(_misfits, ds, exc) or ([], [])
        read = _best_effort(_names_being_read, frames, ds, names)
        # several possible ones (a label column is text too): the one the reader was reading, if it is one
        name = next(iter(certain), None) or next((n for n in read if n in possible), None) \
            or next(iter(possible + read), None)
    reason = (str(exc).splitlines() or [""])[0] or type(exc).__name__
    if name is None:
        return f"{path}: a variable or attribute does not read: {reason} ({type(exc).__name__})"
    if isinstance(exc, KeyError) and name not in names:
        return f"{path}: no variable or attribute {name!r} (the file is incomplete or not this kind)"
    if name in ds.variables:
        v = ds.variables[name]
        return (f"{path}: variable {name!r} (shape {tuple(v.shape)}, {v.dtype}) does not read: {reason} "
                f"({type(exc).__name__})")
    return f"{path}: attribute {name!r} = {str(ds.attrs[name])[:40]!r} does not read: {reason} ({type(exc).__name__})"


#: ``ds[...]`` and ``a[...]`` (the attributes) in a reader's source line
_SUBSCRIPT = re.compile(r"\b(?:ds|a|attrs)\[([^\[\]]+)\]")


def _best_effort(find, *args) -> list[str]:
    """``find(*args)``, or [] where it fails: the message is then less precise, never wrong."""
    try:
        return find(*args)
    except Exception:  # noqa: BLE001 - best effort
        return []


#: a quoted value in an exception's message ("could not convert string to float: 'x'")
_QUOTED = re.compile(r"""(?:np\.str_\()?'([^']*)'""")


def _misfits(ds, exc: BaseException) -> tuple[list[str], list[str]]:
    """Variables of ``ds`` that do not fit the file itself, whatever the reader: (certain, possible).
    Certain: one with a dimension that no other variable and no coordinate has (a parameter given an
    extra axis), or one that holds the text value the exception quotes (a number column holding
    "x"). Possible: a text variable beside numbers of its dimensions, where the reader failed on text."""
    users = {}
    for name, v in ds.variables.items():
        for d in v.dims:
            users.setdefault(d, []).append(str(name))
    lone = [u[0] for d, u in users.items() if len(u) == 1 and d not in ds.variables and u[0] in ds.data_vars]
    quoted = set(_QUOTED.findall(str(exc)))
    holding = [str(n) for n, v in ds.variables.items() if quoted and v.dtype.kind in "OUS"
               and quoted & set(map(str, np.asarray(v.values).ravel()[:1000]))]
    # a text variable beside variables of its dimensions that hold numbers (a chain made text),
    # where the reader failed on text ("unsupported operand type(s) for -: 'str' and 'str'")
    odd_text = []
    if "str" in str(exc) or isinstance(exc, KeyError):  # noqa: SIM102
        for name, v in ds.data_vars.items():
            siblings = [w for n, w in ds.data_vars.items() if n != name and w.dims == v.dims]
            if v.dtype.kind in "OUS" and any(w.dtype.kind in "biuf" for w in siblings):
                odd_text.append(str(name))
    # microimpact's own text (labels, units) reads back as fixed-width strings; variable-length
    # ones (object arrays) first
    odd_text.sort(key=lambda n: ds[n].dtype.kind != "O")
    return list(dict.fromkeys(lone + holding)), odd_text


def _statement(frame, lasti: int) -> str:
    """The source of what ``frame`` was running at instruction ``lasti``: every line of the
    expression (a ``pd.DataFrame({...})`` spans several), not only its first."""
    first = last = frame.f_lineno
    with contextlib.suppress(Exception):  # co_positions: Python 3.11+; else the one line
        positions = list(frame.f_code.co_positions())[lasti // 2]
        first, last = positions[0] or first, positions[1] or last
    return "".join(linecache.getline(frame.f_code.co_filename, n) for n in range(first, last + 1))


def _odd_ones(found: list[str], ds) -> list[str]:
    """Of the variables ``found`` on the failing statement, those unlike the others: text where the
    rest are numbers, else a shape that is not the most common one (the column of a table that is
    two-dimensional, the chain of another length), else the non-scalars (a parameter read with
    float())."""
    found = [n for n in dict.fromkeys(found) if n in ds.variables]
    text = [n for n in found if ds.variables[n].dtype.kind not in "biuf"]
    if text:
        return text
    shapes = [ds.variables[n].shape for n in found]
    if len(set(shapes)) > 1:
        common = max(set(shapes), key=shapes.count)
        if shapes.count(common) > 1:
            return [n for n, shape in zip(found, shapes) if shape != common]
    return [n for n in found if ds.variables[n].ndim > 0]


def _names_being_read(frames, ds, names) -> list[str]:
    """The variables or attributes a reader's frame was reading when it failed: the names its source
    statement subscripts (``ds[n]``, ``ds[f"{n}_stderr"]``, evaluated with the frame's own names; the
    reader's code, never the file's), the odd one (:func:`_odd_ones`) first; else a string or array
    local of the frame that names one; [] when no frame names one."""
    for frame, lasti in reversed(frames):
        found = []
        for expression in _SUBSCRIPT.findall(_statement(frame, lasti)):
            try:
                value = eval(expression, frame.f_globals, dict(frame.f_locals))  # noqa: S307 - our own source
            except Exception:  # noqa: BLE001 - a subscript that needs names of another frame
                continue
            if isinstance(value, str) and value in names:
                found.append(value)
        # a variable held in a local (v = ds[...]; int(v.values)) names itself
        found += [str(v.name) for v in frame.f_locals.values()
                  if type(v).__module__.startswith("xarray") and type(v).__name__ == "DataArray" and str(v.name) in names]
        # ... and so does its array (lim = ds[f"{n}_confidence_limit"].values; np.isfinite(lim)), which
        # the string local n would otherwise misname
        found += _variables_of_arrays(frame.f_locals.values(), ds)
        found += [v for k, v in frame.f_locals.items() if isinstance(v, str) and v in names and k != "path"]
        if found:
            odd = _odd_ones(found, ds)
            return list(dict.fromkeys(odd + found))
    return []


def _variables_of_arrays(values, ds) -> list[str]:
    """The variables of ``ds`` whose data are one of the NumPy arrays among ``values`` (a reader's
    locals): ``ds[name].values`` hands out the variable's own array, so identity (or shared
    memory, for a view) names it."""
    values = [*values]
    values += [x for v in values if isinstance(v, (list, tuple)) for x in v]  # np.stack([...]) of a comprehension
    arrays = [v for v in values if isinstance(v, np.ndarray) and v.size]
    found = []
    for name, variable in ds.variables.items():
        data = variable.values
        if any(a is data or (a.dtype == data.dtype and np.shares_memory(a, data)) for a in arrays):
            found.append(str(name))
    return found


def layout_mismatch(path, ds, written, kind: str) -> str | None:
    """One line naming the first variable of ``ds`` (read from ``path``) whose dimensions or type
    (numbers or text) are not those of ``written``, the Dataset the result read from it writes
    again; None when every shared variable matches.

    A reader that takes text or an extra dimension where its kind holds numbers (a column of
    strings read into a table) fails later, far from the file; the round trip names it at once.

    Examples
    --------
    >>> import xarray as xr
    >>> written = xr.Dataset({"radius": ("point", [1e-6, 2e-6])})
    >>> layout_mismatch("fit.nc", xr.Dataset({"radius": ("point", ["x", "y"])}), written, "damping fit")
    "fit.nc: variable 'radius' (dimensions ('point',), <U1) is not what a damping fit holds (dimensions ('point',), numbers)"
    >>> layout_mismatch("fit.nc", written, written, "damping fit") is None
    True
    """
    for name in written.variables:
        if name not in ds.variables:
            continue
        have, want = ds.variables[name], written.variables[name]
        numeric_have, numeric_want = have.dtype.kind in "biufc", want.dtype.kind in "biufc"
        if have.dims != want.dims or numeric_have != numeric_want:
            return (f"{path}: variable {str(name)!r} (dimensions {have.dims}, {have.dtype}) is not what a {kind} holds "
                    f"(dimensions {want.dims}, {'numbers' if numeric_want else 'text'})")
    return None
