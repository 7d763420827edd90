"""What a file is, in words, for the message that refuses it where another kind was expected.

A NetCDF file given as the CSV of measured impacts produced 4277 "invalid UTF-8" problems, an Excel
workbook 316, and a posterior given as ``--fit`` a message about a missing ``zeta_hertz``
variable. Each reader asks :func:`file_kind` once it has failed, and the message says what the file
is: "a NetCDF file titled 'posterior of ...'", "an Excel workbook (.xlsx)", "CSV text", ...
The file's first bytes decide (the formats' signatures), and for NetCDF its ``title`` attribute,
which every file microimpact writes carries.
"""

from __future__ import annotations

import linecache
import re
import zipfile
from pathlib import Path

import netCDF4

__all__ = ["file_kind", "is_binary", "unreadable_content"]

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
    name = exc.args[0] if isinstance(exc, KeyError) and exc.args and str(exc.args[0]) in names | {exc.args[0]} else None
    tb, frames = exc.__traceback__, []
    while tb is not None:
        frames.append(tb.tb_frame)
        tb = tb.tb_next
    if name is None:
        try:
            name = _name_being_read(frames, ds, names)
        except Exception:  # noqa: BLE001 - best effort: the message is then less precise, never wrong
            name = None
    reason = (str(exc).splitlines() or [""])[0] or type(exc).__name__
    if name is None:
        return f"{path}: a variable or attribute does not read: {reason} ({type(exc).__name__})"
    if isinstance(exc, KeyError):
        return f"{path}: no variable or attribute {name!r} (the file is incomplete or not this kind)"
    if name in ds.variables:
        v = ds.variables[name]
        return (f"{path}: variable {name!r} (shape {tuple(v.shape)}, {v.dtype}) does not read: {reason} "
                f"({type(exc).__name__})")
    return f"{path}: attribute {name!r} = {str(ds.attrs[name])[:40]!r} does not read: {reason} ({type(exc).__name__})"


#: ``ds[...]`` and ``a[...]`` (the attributes) in a reader's source line
_SUBSCRIPT = re.compile(r"\b(?:ds|a|attrs)\[([^\[\]]+)\]")


def _name_being_read(frames, ds, names) -> str | None:
    """The variable or attribute a reader's frame was reading when it failed: the names its source
    line subscripts (``ds[n]``, ``ds[f"{n}_stderr"]``, evaluated with the frame's own names; the
    reader's code, never the file's), the odd one (not a numeric scalar) first; else a string
    local of the frame that names one."""
    for frame in reversed(frames):
        line = linecache.getline(frame.f_code.co_filename, frame.f_lineno)
        found = []
        for expression in _SUBSCRIPT.findall(line):
            try:
                value = eval(expression, frame.f_globals, dict(frame.f_locals))  # noqa: S307 - our own source
            except Exception:  # noqa: BLE001 - a subscript that needs names of another frame
                continue
            if isinstance(value, str) and value in names:
                found.append(value)
        # a variable held in a local (v = ds[...]; int(v.values)) names itself
        found += [str(v.name) for v in frame.f_locals.values()
                  if type(v).__module__.startswith("xarray") and type(v).__name__ == "DataArray" and str(v.name) in names]
        found += [v for k, v in frame.f_locals.items() if isinstance(v, str) and v in names and k != "path"]
        if found:
            odd = [n for n in found if n in ds.variables and (ds.variables[n].ndim > 0
                                                              or ds.variables[n].dtype.kind not in "biuf")]
            return (odd or found)[0]
    return None
