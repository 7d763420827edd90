"""Read and validate a CSV of measured microsphere impacts.

The file format is documented in ``data/README.md``, section "Measured-impact CSV format".
:func:`read_impacts` checks the whole file at once and raises ONE :class:`ImpactDataError` that
lists every problem found, each located by file, data row, line and column.

Returned table
--------------
One row per impact, in file order, with these columns (always all of them, in this order; NaN or
missing where a value is neither given nor derivable). Uncertainties are standard uncertainties
(one standard deviation) in the unit of their quantity.

==========================================  =======  ==================================================
column                                      unit     meaning
==========================================  =======  ==================================================
``row``                                     [-]      1-based data row in the file (blank lines skipped)
``line``                                    [-]      1-based line of the file where the row starts
``id``, ``size_class``, ``material_pair``            text labels as written (missing: NA)
``radius``                                  [m]      sphere radius (``diameter`` / 2 if diameter given)
``speed``                                   [m/s]    incident speed magnitude
``incidence_deg``                           [deg]    incidence angle from the surface normal, [0, 90)
``normal_speed``                            [m/s]    incident normal speed magnitude, > 0
``rebound_normal_speed``                    [m/s]    rebound normal speed magnitude, >= 0
``e_n``                                     [1]      normal coefficient of restitution, [0, 1]
``rebound_tangential_speed``                [m/s]    rebound tangential speed of the centre, >= 0
``rebound_angle_deg``                       [deg]    rebound angle from the surface normal
``tangential_restitution``                  [1]      e_t = v_t,out / v_t,in (in the incidence plane)
``rebound_spin``                            [rad/s]  angular speed |omega| after the impact, >= 0
``spin``                                    [rad/s]  stated incident spin about t', + = top-spin
``<quantity>_uncertainty``                  as qty   for each quantity above from ``radius`` on
==========================================  =======  ==================================================

Angles are kept in degrees in columns whose names end in ``_deg``, the convention of
:func:`microimpact.model.kinematics.incident_velocity`; everything else is SI.

Derived columns (first-order propagation of standard uncertainties; a derived uncertainty is NaN
unless every input it needs has an uncertainty, except for the ratios below):

* The errors of the incident and the rebound speeds are taken as independent
  (:data:`SPEED_CORRELATION` = 0): they are measured on separate segments of a track (other frames,
  fitted apart), whose random errors do not share a cause. An error common to both -- the
  length scale of the camera's calibration -- is fully correlated and cancels in the ratios e_n
  and e_t; independence then over-states their uncertainty (conservative), never under-states it.
  :func:`ratio_uncertainty` takes a correlation for a laboratory that knows its own.
* The ratios e_n = v_r / v_n, e_t = v_t,out / v_t,in, the rebound angle atan(v_t / v_r) and the
  rebound tangential speed e_t v_t,in of a given e_t use every stated uncertainty: where only one of
  their two inputs has one, the other counts as exact (its term zero, not unknown), so that a stated
  uncertainty is never dropped.

* ``normal_speed = speed cos(incidence)`` when speed and incidence angle are given;
  ``speed = normal_speed / cos(incidence)`` when normal speed and incidence angle are given;
  speed and incidence angle are NaN when only the normal speed is given.
* ``e_n = rebound_normal_speed / normal_speed`` or ``rebound_normal_speed = e_n normal_speed``.
* ``rebound_angle = atan(rebound_tangential_speed / rebound_normal_speed)`` or
  ``rebound_tangential_speed = rebound_normal_speed tan(rebound_angle)``.
* ``tangential_restitution = rebound_tangential_speed / (speed sin(incidence))`` (NaN at normal
  incidence), or from a given ``tangential_restitution`` the (signed) rebound tangential speed and
  the rebound angle.

Possible but implausible values warn (:class:`ImpactDataWarning`, naming the rows): a tangential
restitution above 1 without a stated ``spin``; |e_t| above 1 by more than
:data:`MEASUREMENT_TOLERANCE_SIGMAS` stated uncertainties without a stated ``spin`` is impossible
and refused. ``df.attrs["measured"]`` lists the canonical
columns the file gave (not derived), so a fit uses what was measured.

Columns that are not part of the format (an operator, a batch, a note) are the analyst's own:
they are kept as text after the columns above, under their header name (``csv_<name>`` where that
name is one of the columns above), listed in ``df.attrs["kept_columns"]``, and carried with ``id``
through every per-row output (:func:`row_labels`). A header name close to a known column (a likely
typo) warns, naming the known column.

``df.attrs`` holds ``source`` (the path as given, str), ``sha256`` (of the file's bytes) and
``units`` (column -> unit string), so later flags and writers can point back to the file.
"""

from __future__ import annotations

import csv
import difflib
import hashlib
import io as _stdio
import math
import os
import re
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from microimpact.io.kinds import file_kind, is_binary
from microimpact.io.materials import read_materials
from microimpact.io.paths import DATA_README
from microimpact.io.units import INTERNAL_UNIT, UnitError, accepted_units, conversion_factor, parse_header_field

__all__ = [
    "read_impacts",
    "ratio_uncertainty",
    "SPEED_CORRELATION",
    "row_labels",
    "insert_row_labels",
    "label_variables",
    "labels_from_dataset",
    "material_pairs",
    "select_material_pair",
    "ImpactDataError",
    "ImpactDataWarning",
    "Problem",
    "CANONICAL_COLUMNS",
    "COLUMN_UNITS",
    "OBLIQUE_COLUMNS",
    "MAX_LISTED_PROBLEMS",
]

#: at most this many problems are written out in an ImpactDataError message (all are in .problems)
MAX_LISTED_PROBLEMS = 200

_MISSING = frozenset({"", "nan", "na", "n/a", "null", "none"})
_BOM = b"\xef\xbb\xbf"


@dataclass(frozen=True)
class _Quantity:
    """A numeric input column: its dimension, output column, scale and accepted range."""

    dimension: str
    canonical: str
    scale: float = 1.0  # applied after unit conversion (diameter -> radius)
    low: float = 0.0
    low_open: bool = True
    high: float = math.inf
    high_open: bool = True

    def range_text(self) -> str:
        unit = " deg" if self.dimension == "angle" else ""
        if math.isinf(self.high):
            return f"{'>' if self.low_open else '>='} {self.low:g}{unit}"
        lo = "(" if self.low_open else "["
        hi = ")" if self.high_open else "]"
        return f"in {lo}{self.low:g}, {self.high:g}{hi}{unit}"

    def ok(self, x: np.ndarray) -> np.ndarray:
        lo = x > self.low if self.low_open else x >= self.low
        hi = x < self.high if self.high_open else x <= self.high
        return lo & hi


_BASE: dict[str, _Quantity] = {
    "radius": _Quantity("length", "radius"),
    "diameter": _Quantity("length", "radius", scale=0.5),
    "speed": _Quantity("speed", "speed"),
    "incidence_angle": _Quantity("angle", "incidence_deg", low_open=False, high=90.0),
    "normal_speed": _Quantity("speed", "normal_speed"),
    "rebound_normal_speed": _Quantity("speed", "rebound_normal_speed", low_open=False),
    "e_n": _Quantity("dimensionless", "e_n", low_open=False, high=1.0, high_open=False),
    "rebound_tangential_speed": _Quantity("speed", "rebound_tangential_speed", low_open=False),
    "rebound_angle": _Quantity("angle", "rebound_angle_deg", low_open=False, high=90.0),
    # e_t = v_t,out / v_t,in: negative (reversed) or above 1 only with incident spin
    "tangential_restitution": _Quantity("dimensionless", "tangential_restitution", low=-math.inf),
    "rebound_spin": _Quantity("angular_speed", "rebound_spin", low_open=False),
    # stated incident spin about t' in the forward-rolling sense (+: top-spin, -: back-spin)
    "spin": _Quantity("angular_speed", "spin", low=-math.inf),
}
_QUANTITIES: dict[str, _Quantity] = dict(_BASE)
for _name, _q in _BASE.items():
    _QUANTITIES[f"{_name}_uncertainty"] = _Quantity(
        _q.dimension, f"{_q.canonical}_uncertainty", scale=_q.scale, low_open=False
    )
_LABELS = ("id", "size_class", "material_pair")

#: A MEASURED rebound quantity outside its physical range by at most this many of its stated
#: standard uncertainties is kept as a measurement (noise puts a nearly elastic impact's e_n above 1,
#: a rolling sphere's rebound speed slightly below 0); beyond it, or without a stated uncertainty,
#: the value is refused. 4 sigma: a Gaussian error goes past it with probability 6e-5 (two-sided), so a
#: genuine measurement is essentially never refused, while a unit or sign error still is. The fits
#: read the same constant (microimpact.analysis.fitting).
MEASUREMENT_TOLERANCE_SIGMAS = 4.0
#: the measured rebound quantities to which :data:`MEASUREMENT_TOLERANCE_SIGMAS` applies (the incident
#: speed, angle and size define the experiment and keep their strict ranges)
MEASURED_QUANTITIES = ("e_n", "rebound_normal_speed", "rebound_tangential_speed", "rebound_angle", "rebound_spin")
_KNOWN = tuple(_QUANTITIES) + _LABELS

#: the columns of the returned DataFrame, in order
CANONICAL_COLUMNS: tuple[str, ...] = (
    "row",
    "line",
    *_LABELS,
    *(c for q in ("radius", "speed", "incidence_deg", "normal_speed", "rebound_normal_speed", "e_n",
                  "rebound_tangential_speed", "rebound_angle_deg", "tangential_restitution", "rebound_spin",
                  "spin") for c in (q, f"{q}_uncertainty")),
)
#: the oblique (tangential and rotational) measurement columns a friction fit can use
OBLIQUE_COLUMNS: tuple[str, ...] = ("tangential_restitution", "rebound_tangential_speed", "rebound_angle_deg",
                                    "rebound_spin")
#: unit of each numeric column of the returned DataFrame
COLUMN_UNITS: dict[str, str] = {"row": "1", "line": "1"} | {
    q.canonical: INTERNAL_UNIT[q.dimension] for q in _QUANTITIES.values()
}


@dataclass(frozen=True)
class Problem:
    """One problem found in an impact file.

    Attributes
    ----------
    message : str
        What is wrong and what is accepted.
    row : int or None
        1-based data row (blank lines not counted), None for problems of the file or header.
    line : int or None
        1-based line of the file.
    column : str or None
        Header field as written in the file.
    value : str or None
        The offending cell or header text as written.

    Examples
    --------
    >>> from pathlib import Path
    >>> _ = Path("k.csv").write_text("radius [m],normal_speed [m/s],e_n [1]\\n1e-6,-1.0,0.5\\n")
    >>> try:
    ...     read_impacts("k.csv")
    ... except ImpactDataError as err:
    ...     print(err.problems[0])
    Problem(message='must be > 0 (speeds are magnitudes)', row=1, line=2,
            column='normal_speed [m/s]', value='-1.0')
    """

    message: str
    row: int | None = None
    line: int | None = None
    column: str | None = None
    value: str | None = None

    def format(self, source: str) -> str:
        """The problem as one line, prefixed by the file name ``source``."""
        where = [source]
        if self.row is not None:
            where.append(f"row {self.row} (line {self.line})")
        elif self.line is not None:
            where.append(f"line {self.line}")
        if self.column is not None:
            where.append(f"column {self.column!r}")
        if self.value is not None:
            where.append(f"value {self.value!r}")
        return ", ".join(where) + ": " + self.message


class ImpactDataError(ValueError):
    """An impact file that cannot be used; the message lists every problem found.

    Attributes
    ----------
    source : str
        The file's name as given.
    problems : tuple of Problem
        All problems, in the order found (the message lists the first
        :data:`MAX_LISTED_PROBLEMS`).

    Examples
    --------
    Every problem is reported at once, each naming its line and column:

    >>> from pathlib import Path
    >>> _ = Path("i.csv").write_text("radius [m],normal_speed [m/s],e_n [1]\\n1e-6,1.0,abc\\n")
    >>> try:
    ...     read_impacts("i.csv")
    ... except ImpactDataError as err:
    ...     print(err.source); print(str(err).splitlines()[1])
    i.csv
      - i.csv, row 1 (line 2), column 'e_n [1]', value 'abc': is not a number; ...
    """

    def __init__(self, source: str, problems):
        self.source = str(source)
        self.problems = tuple(problems)
        n = len(self.problems)
        lines = [f"{n} problem{'s' if n != 1 else ''} in impact file {self.source}:"]
        name = Path(self.source).name
        lines += ["  - " + p.format(name) for p in self.problems[:MAX_LISTED_PROBLEMS]]
        if n > MAX_LISTED_PROBLEMS:
            lines.append(f"  ... and {n - MAX_LISTED_PROBLEMS} more (all are in ImpactDataError.problems)")
        lines.append(f"The format is described in {DATA_README}, section 'Measured-impact CSV format'.")
        super().__init__("\n".join(lines))


class ImpactDataWarning(UserWarning):
    """Something in an impact file that was ignored (e.g. an unknown column).

    Examples
    --------
    A measurement is data: e_n = 1.004 +/- 0.01 is kept as measured, with a warning naming its row:

    >>> import warnings
    >>> from pathlib import Path
    >>> _ = Path("w.csv").write_text("radius [m],normal_speed [m/s],e_n [1],e_n_uncertainty [1]\\n"
    ...                              "1e-6,1.0,1.004,0.01\\n1e-6,2.0,0.6,0.01\\n")
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     table = read_impacts("w.csv")
    >>> table["e_n"].tolist(), caught[0].category.__name__
    ([1.004, 0.6], 'ImpactDataWarning')
    >>> str(caught[0].message)
    'w.csv: 1 measurement(s) outside the physical range by no more than 4 stated standard
     uncertainties, kept as measured (e_n [1]: rows 1)'
    """


# --------------------------------------------------------------------------- bytes and text
def _decode(data: bytes) -> tuple[str, list[Problem]]:
    """UTF-8 text of ``data`` (BOM removed); every undecodable byte becomes a Problem."""
    offset0 = len(_BOM) if data.startswith(_BOM) else 0
    problems: list[Problem] = []
    pos = offset0
    while True:
        try:
            data[pos:].decode("utf-8")
            break
        except UnicodeDecodeError as e:
            bad = pos + e.start
            line = data.count(b"\n", 0, bad) + 1
            problems.append(
                Problem(
                    f"byte 0x{data[bad]:02X} at byte offset {bad} is not valid UTF-8; save the file "
                    "as UTF-8 (e.g. 'CSV UTF-8' in a spreadsheet program)",
                    line=line,
                )
            )
            pos += e.end
            if len(problems) >= MAX_LISTED_PROBLEMS:
                break
    return data[offset0:].decode("utf-8", errors="replace"), problems


@dataclass(frozen=True)
class _Column:
    index: int  # position in the header
    field: str  # header text as written
    name: str
    unit: str | None


# --------------------------------------------------------------------------- header
def _check_header(fields: list[str]) -> tuple[dict[str, _Column], dict[str, float], list[Problem], list[str]]:
    """Columns by name, unit factors, header problems and ignored fields."""
    columns, factors, problems, ignored, misplaced_unit = _header_columns(fields)
    problems += _header_combinations(columns, misplaced_unit)
    return columns, factors, problems, ignored


def _header_columns(fields: list[str]):
    """Each header field on its own: (columns by name, unit factors, problems, ignored fields, names
    written with a unit in round brackets)."""
    problems: list[Problem] = []
    ignored: list[str] = []
    columns: dict[str, _Column] = {}
    misplaced_unit: set[str] = set()  # 'radius (um)': reported once, not also as missing
    factors: dict[str, float] = {}
    for i, raw in enumerate(fields):
        name, unit = parse_header_field(raw)
        col = _Column(i, raw.strip(), name, unit)
        if name not in _KNOWN:
            m = re.fullmatch(r"(\w+)\s*\((.*)\)", name)
            if m and m.group(1) in _QUANTITIES:
                misplaced_unit.add(m.group(1))
                problems.append(Problem(
                    f"units go in square brackets: write '{m.group(1)} [{m.group(2).strip()}]'",
                    line=1, column=col.field))
            else:
                ignored.append(col.field)
            continue
        if name in columns:
            first = columns[name]
            how = "the same column appears" if first.field == col.field else f"{name!r} is given"
            problems.append(Problem(
                f"{how} twice (columns {first.index + 1} and {i + 1}, as {first.field!r} and "
                f"{col.field!r}); keep one", line=1, column=col.field))
            continue
        columns[name] = col
        if name in _LABELS:
            if unit is not None:
                problems.append(Problem(
                    f"{name!r} is a text label column and takes no unit; write the header as {name!r}",
                    line=1, column=col.field))
            continue
        dim = _QUANTITIES[name].dimension
        if unit is None:
            hint = " (units go in square brackets)" if "(" in col.field else ""
            example = accepted_units(dim)[0]
            problems.append(Problem(
                f"column has no unit{hint}; write it as '{name} [unit]', e.g. '{name} [{example}]'; "
                f"accepted units: {', '.join(accepted_units(dim))}", line=1, column=col.field))
            continue
        try:
            factors[name] = conversion_factor(unit, dim) * _QUANTITIES[name].scale
        except UnitError as e:
            problems.append(Problem(str(e), line=1, column=col.field))
    return columns, factors, problems, ignored, misplaced_unit


def _header_combinations(columns: Mapping[str, _Column], misplaced_unit: set[str]) -> list[Problem]:
    """The header's columns together: a quantity given twice, required columns missing, an
    uncertainty without its quantity. ``misplaced_unit`` names count as present (reported once)."""
    problems: list[Problem] = []

    def have(*names):
        return [n for n in names if n in columns]

    def mentioned(*names):
        return [n for n in names if n in columns or n in misplaced_unit]

    def fields_of(names):
        return " and ".join(repr(columns[n].field) for n in names)

    # the same quantity given twice
    for group, what in (
        (("radius", "diameter"), "the particle size"),
        (("radius_uncertainty", "diameter_uncertainty"), "the particle size uncertainty"),
        (("rebound_normal_speed", "e_n"), "the normal rebound"),
        (("rebound_tangential_speed", "rebound_angle", "tangential_restitution"), "the tangential rebound"),
    ):
        if len(have(*group)) > 1:
            both = "both" if len(have(*group)) == 2 else "all"
            problems.append(Problem(f"columns {fields_of(have(*group))} {both} give {what}; keep one", line=1))
    incident = set(have("speed", "incidence_angle", "normal_speed"))
    if incident == {"speed", "incidence_angle", "normal_speed"} or incident == {"speed", "normal_speed"}:
        problems.append(Problem(
            f"columns {fields_of(sorted(incident))} over-determine the incident velocity; give "
            "'speed' + 'incidence_angle', or 'normal_speed' (optionally with 'incidence_angle')", line=1))
    # missing required columns
    speed_units = ", ".join(accepted_units("speed"))
    if not mentioned("radius", "diameter"):
        problems.append(Problem(
            "no particle size column; add 'radius [unit]' or 'diameter [unit]' with a length unit "
            f"({', '.join(accepted_units('length'))})", line=1))
    if not incident and not mentioned("speed", "incidence_angle", "normal_speed"):
        problems.append(Problem(
            "no incident velocity columns; add 'speed [unit]' and 'incidence_angle [unit]', or "
            f"'normal_speed [unit]' (speed units: {speed_units}; angle units: "
            f"{', '.join(accepted_units('angle'))})", line=1))
    elif incident == {"speed"}:
        problems.append(Problem(
            f"column {fields_of(['speed'])} needs 'incidence_angle [deg]' next to it, or replace it "
            "by 'normal_speed [m/s]'", line=1))
    elif incident == {"incidence_angle"}:
        problems.append(Problem(
            f"column {fields_of(['incidence_angle'])} needs 'speed [m/s]' or 'normal_speed [m/s]' "
            "next to it", line=1))
    if not mentioned("rebound_normal_speed", "e_n"):
        problems.append(Problem(
            f"no rebound column; add 'rebound_normal_speed [unit]' ({speed_units}) or 'e_n [1]'", line=1))
    # uncertainty without its quantity
    for name in columns:
        if name.endswith("_uncertainty"):
            base = name[: -len("_uncertainty")]
            size_ok = base in ("radius", "diameter") and have("radius", "diameter")
            if base not in columns and not size_ok:
                problems.append(Problem(
                    f"uncertainty column without a {base!r} column; add '{base} [unit]' or drop it",
                    line=1, column=columns[name].field))
    return problems


def _required(columns: Mapping[str, _Column]) -> set[str]:
    req = {n for n in ("radius", "diameter", "normal_speed", "rebound_normal_speed", "e_n") if n in columns}
    if "speed" in columns:
        req |= {"speed", "incidence_angle"} & set(columns)
    return req


# --------------------------------------------------------------------------- propagation
#: correlation of the errors of a row's incident and rebound speeds: independent (module docstring)
SPEED_CORRELATION = 0.0


def ratio_uncertainty(numerator, numerator_uncertainty, denominator, denominator_uncertainty,
                      correlation: float = SPEED_CORRELATION):
    """Standard uncertainty of q = a / b from those of a and b and the correlation of their errors.

    sigma_q^2 = (sigma_a / b)^2 + (a sigma_b / b^2)^2 - 2 rho (sigma_a / b)(a sigma_b / b^2)
    (first order; the minus sign: q falls as b rises). An uncertainty given as NaN counts as zero
    (exact) where the other is given; NaN where neither is.

    Parameters
    ----------
    numerator, numerator_uncertainty : array_like
        a and sigma_a (e.g. the rebound normal speed [m/s]).
    denominator, denominator_uncertainty : array_like
        b and sigma_b (e.g. the incident normal speed [m/s]).
    correlation : float
        rho, the correlation coefficient of the errors of a and b, in [-1, 1]. [-]

    Returns
    -------
    numpy.ndarray
        sigma_q, in the unit of a / b.

    References
    ----------
    JCGM 100:2008 (GUM), Eq. (16): the law of propagation of uncertainty for correlated inputs.

    Examples
    --------
    e_n = 0.6 / 1.0 with 0.02 on each speed: independent, fully correlated (the ratio's relative
    uncertainty is then the difference of the relative ones), and the rebound alone:

    >>> [round(float(ratio_uncertainty(0.6, 0.02, 1.0, 0.02, rho)), 6) for rho in (0.0, 1.0)]
    [0.023324, 0.008]
    >>> float(ratio_uncertainty(0.6, 0.02, 1.0, float("nan")))
    0.02
    """
    if not -1.0 <= correlation <= 1.0:
        raise ValueError(f"correlation must lie in [-1, 1], got {correlation!r}")
    a, sa, b, sb = (np.asarray(x, dtype=float) for x in (numerator, numerator_uncertainty, denominator,
                                                          denominator_uncertainty))
    neither = np.isnan(sa) & np.isnan(sb)
    with np.errstate(invalid="ignore", divide="ignore"):
        ta, tb = np.nan_to_num(sa) / b, (a / b) * (np.nan_to_num(sb) / b)
        # hypot where independent: squares near the float limit would overflow
        out = np.hypot(ta, tb) if correlation == 0 else np.sqrt(np.maximum(ta * ta + tb * tb - 2 * correlation * ta * tb, 0.0))
    return np.where(neither, np.nan, out)


def _angle_uncertainty(t, st, r, sr):
    """Uncertainty of atan2(t, r) [rad] from independent errors of t and r; one unstated counts as exact."""
    h = np.hypot(r, t)  # divided before squaring: no overflow near the float limit
    neither = np.isnan(st) & np.isnan(sr)
    return np.where(neither, np.nan, np.hypot(r / h * np.nan_to_num(st), t / h * np.nan_to_num(sr)) / h)


def _unc(*terms):
    """sqrt(sum of squares) of the terms; NaN if any is NaN (first-order propagation).

    Summed with hypot, so that terms near the float limit do not overflow when squared."""
    terms = [np.asarray(t, dtype=float) for t in terms]
    out = np.zeros(np.broadcast(*terms).shape)
    any_nan = np.zeros(out.shape, dtype=bool)
    for t in terms:
        out = np.hypot(out, t)
        any_nan |= np.isnan(t)
    return np.where(any_nan, np.nan, out)


def _derive(v: dict[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
    """Fill the derived columns of the internal table ``v`` (canonical names, NaN = not given)."""
    nan = np.full(n, np.nan)
    out = {k: v.get(k, nan) for k in COLUMN_UNITS if k not in ("row", "line")}
    rad = math.pi / 180.0
    # incident
    a, sa = out["incidence_deg"] * rad, out["incidence_deg_uncertainty"] * rad
    if "speed" in v:
        sp, ssp = out["speed"], out["speed_uncertainty"]
        out["normal_speed"] = sp * np.cos(a)
        out["normal_speed_uncertainty"] = _unc(np.cos(a) * ssp, sp * np.sin(a) * sa)
    elif "normal_speed" in v and "incidence_deg" in v:
        vn, svn = out["normal_speed"], out["normal_speed_uncertainty"]
        out["speed"] = vn / np.cos(a)
        out["speed_uncertainty"] = _unc(svn / np.cos(a), (vn / np.cos(a)) * np.tan(a) * sa)
    vn, svn = out["normal_speed"], out["normal_speed_uncertainty"]
    # normal rebound
    if "rebound_normal_speed" in v:
        r, sr = out["rebound_normal_speed"], out["rebound_normal_speed_uncertainty"]
        out["e_n"] = r / vn
        # every stated uncertainty used: a rebound one without an incident one (the incident speed then
        # counts as exact: its term is zero, not unknown), and the other way round
        out["e_n_uncertainty"] = ratio_uncertainty(r, sr, vn, svn)
    else:
        e, se = out["e_n"], out["e_n_uncertainty"]
        out["rebound_normal_speed"] = e * vn
        out["rebound_normal_speed_uncertainty"] = _unc(vn * se, e * svn)
    r, sr = out["rebound_normal_speed"], out["rebound_normal_speed_uncertainty"]
    # tangential rebound
    if "rebound_tangential_speed" in v:
        t, st = out["rebound_tangential_speed"], out["rebound_tangential_speed_uncertainty"]
        with np.errstate(invalid="ignore", divide="ignore"):
            out["rebound_angle_deg"] = np.degrees(np.arctan2(t, r))
            out["rebound_angle_deg_uncertainty"] = np.degrees(_angle_uncertainty(t, st, r, sr))
    elif "rebound_angle_deg" in v:
        b, sb = out["rebound_angle_deg"] * rad, out["rebound_angle_deg_uncertainty"] * rad
        out["rebound_tangential_speed"] = r * np.tan(b)
        out["rebound_tangential_speed_uncertainty"] = _unc(np.tan(b) * sr, (r / np.cos(b)) * (sb / np.cos(b)))
    _derive_tangential_restitution(v, out, a, sa)
    return out


def _derive_tangential_restitution(v: dict, out: dict, a, sa) -> None:
    """e_t = v_t,out / v_t,in with v_t,in = speed sin(incidence), or the rebound tangential speed
    (signed: negative when the rebound reverses) and angle from a given e_t. [1], [m/s], [deg]"""
    sp, ssp = out["speed"], out["speed_uncertainty"]
    vt_in = sp * np.sin(a)
    s_vt_in = _unc(np.sin(a) * ssp, sp * np.cos(a) * sa)
    with np.errstate(invalid="ignore", divide="ignore"):
        if "tangential_restitution" in v:
            e, se = out["tangential_restitution"], out["tangential_restitution_uncertainty"]
            t = e * vt_in
            out["rebound_tangential_speed"] = t
            # e_t's stated uncertainty used without the incident speed's (that then counts as exact)
            out["rebound_tangential_speed_uncertainty"] = np.where(
                np.isnan(se) & np.isnan(s_vt_in), np.nan, np.hypot(vt_in * np.nan_to_num(se), e * np.nan_to_num(s_vt_in)))
            r, sr = out["rebound_normal_speed"], out["rebound_normal_speed_uncertainty"]
            out["rebound_angle_deg"] = np.degrees(np.arctan2(t, r))
            out["rebound_angle_deg_uncertainty"] = np.degrees(
                _angle_uncertainty(t, out["rebound_tangential_speed_uncertainty"], r, sr))
        elif np.any(np.isfinite(out["rebound_tangential_speed"])):
            t, st = out["rebound_tangential_speed"], out["rebound_tangential_speed_uncertainty"]
            ok = vt_in > 0
            out["tangential_restitution"] = np.where(ok, t / vt_in, np.nan)
            out["tangential_restitution_uncertainty"] = np.where(ok, ratio_uncertainty(t, st, vt_in, s_vt_in), np.nan)


#: inputs (canonical names) that each derived column can be computed from
_INCIDENT = ("normal_speed", "speed", "incidence_deg")
_DEPENDS: dict[str, tuple[str, ...]] = {
    "normal_speed": ("speed", "incidence_deg"),
    "speed": ("normal_speed", "incidence_deg"),
    "e_n": ("rebound_normal_speed", *_INCIDENT),
    "rebound_normal_speed": ("e_n", *_INCIDENT),
    "rebound_angle_deg": ("rebound_tangential_speed", "rebound_normal_speed", "e_n", *_INCIDENT),
    "rebound_tangential_speed": ("rebound_angle_deg", "rebound_normal_speed", "e_n", "tangential_restitution",
                                 *_INCIDENT),
    "tangential_restitution": ("rebound_tangential_speed", "rebound_angle_deg", "rebound_normal_speed", "e_n",
                               *_INCIDENT),
}
for _k, _deps in list(_DEPENDS.items()):
    _DEPENDS[f"{_k}_uncertainty"] = (_k, *_deps, *(f"{d}_uncertainty" for d in (_k, *_deps)))


def _check_overflow(cells: _Cells, columns, values: dict, out: dict, problems: list[Problem]) -> None:
    """A problem for every derived value that overflowed to infinity, naming the row and the
    input column it came from (the given value of the most extreme magnitude; all inputs are
    listed in the message). Given values were checked finite already."""
    by_canonical = {_QUANTITIES[n].canonical: c for n, c in columns.items() if n in _QUANTITIES}
    for k in CANONICAL_COLUMNS:
        if k in values or k not in out:
            continue
        for i in np.flatnonzero(np.isinf(out[k])):
            given = [d for d in _DEPENDS.get(k, ()) if d in values and np.isfinite(values[d][i])]
            if not given:
                continue
            col = by_canonical[max(given, key=lambda d: abs(math.log10(abs(values[d][i]) or 1.0)))]
            fields = ", ".join(repr(by_canonical[d].field) for d in given)
            problems.append(Problem(
                f"the derived {k} [{COLUMN_UNITS[k]}] overflows to infinity (computed from {fields} of this "
                "row); a value is too large or too small to compute with: check it and its unit",
                int(cells.rows[i]), int(cells.lines[i]), col.field, cells.text[col.name][i]))


def _check_contacts(cells: _Cells, columns, out: dict, materials, pairs, problems: list[Problem]) -> None:
    """A problem for every row whose sphere size gives no valid contact with its material pair
    (e.g. f0 of Eq. (7) overflowing to infinity for an absurd radius). ``pairs``: the pair of
    each row (None: unknown, not checked)."""
    size = columns.get("radius") or columns.get("diameter")
    if size is None:
        return
    radius = out["radius"]
    verdict: dict = {}
    for i in range(cells.n):
        key = (pairs[i], float(radius[i]))
        if key[0] is None or not hasattr(materials.get(key[0]), "contact") or not np.isfinite(key[1]):
            continue  # no pair, an unknown one (reported) or a mapping of names only
        if key not in verdict:
            try:
                with np.errstate(all="ignore"):
                    materials[key[0]].contact(key[1])
                verdict[key] = None
            except (ValueError, OverflowError, ArithmeticError) as e:
                verdict[key] = str(e)
        if verdict[key] is not None:
            problems += cells.problems(np.arange(cells.n) == i, size, (
                f"radius {key[1]:.6g} m gives no usable contact for material pair {key[0]!r}: {verdict[key]} "
                "(f0 = (9/(2 pi) K r w_A^2)^(1/3), Eq. (7)); check the value and its unit"))


# --------------------------------------------------------------------------- main entry
def _refuse_binary(source: str) -> None:
    """ImpactDataError with one problem saying what the file is, for a NetCDF file, a workbook, a
    PDF, ... (not thousands of "invalid UTF-8" problems, one per line of binary bytes)."""
    if is_binary(source):
        raise ImpactDataError(source, [Problem(
            f"the file is {file_kind(source)}, not a CSV of measured impacts (text, UTF-8); export or save "
            "the measurements as CSV", line=1)])


def read_impacts(path, *, materials=None, material_pair=None) -> pd.DataFrame:
    """Read and validate a CSV of measured impacts; return it in canonical columns and units.

    Parameters
    ----------
    path : str or os.PathLike
        CSV file in the format of data/README.md, "Measured-impact CSV format". Read only; the
        file is never modified.
    materials : mapping of str to MaterialPair, str or os.PathLike, optional
        Materials config (as returned by :func:`microimpact.io.read_materials`, or its path).
        When given, every non-empty ``material_pair`` cell must name one of its pairs. When None,
        ``material_pair`` labels are not checked. When given, the size of every row whose pair
        is known (its ``material_pair`` cell, else ``material_pair``) must give a valid contact
        with that pair (e.g. f0 of Eq. (7) finite).
    material_pair : str, optional
        Pair of the rows without a ``material_pair`` cell, for the check above; a key of
        ``materials``.

    Returns
    -------
    pandas.DataFrame
        One row per impact with the columns :data:`CANONICAL_COLUMNS` (described in the module
        docstring), SI units with angles in [deg]. ``attrs``: ``source``, ``sha256``, ``units``.

    Raises
    ------
    ValueError
        If ``material_pair`` is given without ``materials`` or is not one of its pairs.
    ImpactDataError
        If anything is wrong. The message lists every problem (up to
        :data:`MAX_LISTED_PROBLEMS`; all are in ``.problems``), each with file name, data row, line
        of the file, column as written, the bad value and what is accepted.
    FileNotFoundError
        If ``path`` does not exist.

    Warns
    -----
    ImpactDataWarning
        For a column that is not part of the format but whose name is close to one that is (a
        likely typo); it is kept as text like every other column of the analyst's own.

    References
    ----------
    The format: data/README.md, "Measured-impact CSV format" (units in the header, as in the CF
    conventions' ``units`` attribute, https://cfconventions.org).

    Examples
    --------
    Two impacts, radius in micrometres: SI units come back, with the normal speed v cos(theta):

    >>> import pathlib, tempfile
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "impacts.csv"
    >>> _ = path.write_text("radius [um],speed [m/s],incidence_angle [deg],e_n [1]\\n3.45,2.0,0,0.61\\n3.45,4.0,30,0.72\\n")
    >>> t = read_impacts(path)
    >>> [float(x) for x in t["radius"]], [round(float(x), 6) for x in t["normal_speed"]], list(t["row"])
    ([3.45e-06, 3.45e-06], [2.0, 3.464102], [1, 2])
    """
    source = os.fspath(path)
    materials = _checked_materials(materials, material_pair)
    data = Path(source).read_bytes()
    sha256 = hashlib.sha256(data).hexdigest()
    _refuse_binary(source)
    header, header_line, records, problems = _read_records(source, data)
    columns, factors, header_problems, ignored = _check_header(header)
    if header_line != 1:
        header_problems = [Problem(p.message, p.row, header_line, p.column, p.value) for p in header_problems]
    problems += header_problems
    kept_columns = _kept_columns(header, ignored)
    _warn_ignored(Path(source).name, ignored)
    if not records:
        if not any(p.row is not None for p in problems):
            problems.append(Problem(
                "the file has a header but no data rows; add one row per impact", line=header_line))
        raise ImpactDataError(source, _sorted(problems))

    # rows with the wrong number of fields are reported and left out of the value checks
    records, ragged = _drop_ragged(records, len(header))
    problems += ragged
    cells = _Cells(columns, records)
    values = _numeric_values(cells, columns, factors, problems)
    labels = _labels(cells, columns, materials, problems)
    if any(p.row is None for p in problems):
        raise ImpactDataError(source, _sorted(problems))  # header broken: derived checks are moot

    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        out = _derive(values, cells.n)
    _check_derived(cells, columns, values, out, labels, materials, material_pair, problems)
    if problems:
        raise ImpactDataError(source, _sorted(problems))

    _warn_implausible(Path(source).name, cells, columns, out)
    kept = _warn_kept_outside(Path(source).name, cells, columns)
    df = _impact_frame(cells, records, columns, labels, out, kept_columns)
    df.attrs["source"] = source
    df.attrs["sha256"] = sha256
    df.attrs["units"] = dict(COLUMN_UNITS)
    df.attrs["measured"] = tuple(_QUANTITIES[n].canonical for n in columns if n in _QUANTITIES)
    df.attrs["outside_physical_range"] = kept
    return df


def _checked_materials(materials, material_pair):
    """The materials config of :func:`read_impacts` (read where a path is given), checked to hold
    ``material_pair`` where one is given (ValueError)."""
    if materials is not None and not isinstance(materials, Mapping):
        materials = read_materials(materials)
    if material_pair is not None and (materials is None or material_pair not in materials):
        known = f"known pairs: {', '.join(sorted(materials))}" if materials is not None else "materials= is not given"
        raise ValueError(f"material_pair {material_pair!r} is not a pair of the materials config; {known}")
    return materials


def _check_derived(cells: _Cells, columns, values: dict, out: dict, labels: dict, materials, material_pair,
                   problems: list[Problem]) -> None:
    """Add to ``problems`` those of the derived columns ``out``: overflow, a rebound faster than the
    impact, a tangential ratio out of bounds and, with ``materials``, each row's contact (its pair
    the row's ``material_pair`` label, else ``material_pair``)."""
    _check_overflow(cells, columns, values, out, problems)
    if "rebound_normal_speed" in values:
        _check_rebound(cells, columns["rebound_normal_speed"], out, problems)
    _check_tangential_bound(cells, columns, out, problems)
    if materials is not None:
        pairs = labels.get("material_pair", np.full(cells.n, None, dtype=object))
        pairs = np.array([p if p is not None else material_pair for p in pairs], dtype=object)
        _check_contacts(cells, columns, out, materials, pairs, problems)


def _impact_frame(cells: _Cells, records: list[_Record], columns, labels: dict, out: dict,
                  kept_columns: dict[str, int]) -> pd.DataFrame:
    """The table of :func:`read_impacts`: row and line, the labels as strings, the canonical columns
    of ``out`` and the analyst's own ``kept_columns`` as text (``attrs["kept_columns"]`` names them)."""
    frame = {"row": cells.rows, "line": cells.lines}
    for cname in _LABELS:
        frame[cname] = pd.array(labels.get(cname, [None] * cells.n), dtype="string")
    frame |= {k: out[k] for k in CANONICAL_COLUMNS if k in out}
    for cname, index in kept_columns.items():
        frame[cname] = pd.array([r.fields[index].strip() or None for r in records], dtype="string")
    df = pd.DataFrame(frame, columns=[*CANONICAL_COLUMNS, *kept_columns])
    df.attrs["kept_columns"] = tuple(kept_columns)
    return df


def _warn_kept_outside(name: str, cells: _Cells, columns) -> dict:
    """One :class:`ImpactDataWarning` naming the measurements kept outside their physical range
    (within :data:`MEASUREMENT_TOLERANCE_SIGMAS` of their stated uncertainty); returns
    {canonical column: [data rows]}."""
    kept = {_QUANTITIES[c].canonical: [int(r) for r in cells.rows[m]] for c, m in cells.kept_outside.items() if m.any()}
    if kept:
        listed = "; ".join(f"{columns[c].field if c in columns else c}: rows {', '.join(map(str, rows[:20]))}"
                           f"{f' and {len(rows) - 20} more' if len(rows) > 20 else ''}"
                           for c, rows in ((c, [int(r) for r in cells.rows[m]]) for c, m in cells.kept_outside.items()
                                           if m.any()))
        warnings.warn(f"{name}: {sum(map(len, kept.values()))} measurement(s) outside the physical range by no more "
                      f"than {MEASUREMENT_TOLERANCE_SIGMAS:g} stated standard uncertainties, kept as measured ({listed})",
                      ImpactDataWarning, stacklevel=3)
    return kept


def _warn_implausible(name: str, cells: _Cells, columns, out: dict) -> None:
    """One :class:`ImpactDataWarning` naming the rows whose values are possible but implausible.

    A tangential restitution above 1 (the rebound faster along the surface than the incidence)
    needs an incident top-spin; without a stated ``spin`` it is more likely noise or a sign
    error, so the row is kept and named."""
    e = out["tangential_restitution"]
    spin = out["spin"]
    with np.errstate(invalid="ignore"):
        bad = (e > 1.0) & ~np.isfinite(spin)
    if not bad.any():
        return
    col = columns.get("tangential_restitution") or columns.get("rebound_tangential_speed") or columns.get("rebound_angle")
    field = col.field if col is not None else "tangential_restitution"
    listed = ", ".join(f"row {int(cells.rows[i])} (line {int(cells.lines[i])}, e_t = {e[i]:.4g})"
                       for i in np.flatnonzero(bad)[:20])
    more = f" and {int(bad.sum()) - 20} more" if bad.sum() > 20 else ""
    warnings.warn(
        f"{name}: column {field!r}: tangential restitution above 1 without a stated 'spin' in {listed}{more}; "
        "possible only with incident top-spin, so it may be noise (the rows are kept; state the spin in a "
        "'spin [rad/s]' column if it was measured)", ImpactDataWarning, stacklevel=3)


@dataclass(frozen=True)
class _Record:
    """One non-blank CSV record: its fields, 1-based data row and the file line where it starts."""

    fields: list
    row: int
    line: int
    bad: frozenset = frozenset()  # indices of fields already reported (control characters)


def _read_records(source: str, data: bytes) -> tuple[list[str], int, list[_Record], list[Problem]]:
    """(header fields, header line, data records, problems so far) of the file's bytes.

    Leading ``# comment`` lines and Excel's ``sep=,`` first line are skipped (they count as lines).
    Problems found here: control characters (named by row and column), a quote that is not closed
    (named by the row where it opens; that record is left out). Raises :class:`ImpactDataError` for
    a blank file, text that is not CSV, or a delimiter other than the comma."""
    if not data.strip(_BOM + b" \t\r\n"):
        what = "empty (0 bytes)" if not data else "blank (only whitespace)"
        raise ImpactDataError(source, [Problem(
            f"the file is {what}; expected a header line such as "
            "'radius [um],speed [m/s],incidence_angle [deg],e_n [1]' followed by one row per impact")])
    text, problems = _decode(data)
    text, skipped = _skip_preamble(source, text, problems)
    reader = csv.reader(_stdio.StringIO(text, newline=""))
    header: list[str] | None = None
    header_line = 1
    records: list[_Record] = []
    prev = 0
    try:
        for rec in reader:
            start, prev = prev + 1, reader.line_num
            if not "".join(rec).strip():
                continue  # blank line or a line of empty fields
            if header is None:
                header, header_line = rec, start + skipped
                continue
            records.append(_Record(rec, len(records) + 1, start + skipped))
    except csv.Error as e:
        problems.append(Problem(f"cannot be parsed as CSV: {e}", line=reader.line_num + skipped))
        raise ImpactDataError(source, problems) from None
    if header is None:
        problems.append(Problem(
            "the file has only comment lines; expected a header line such as "
            "'radius [um],speed [m/s],incidence_angle [deg],e_n [1]' followed by one row per impact",
            line=skipped))
        raise ImpactDataError(source, problems)
    if len(header) == 1:
        for delim, label in ((";", "';' (semicolon)"), ("\t", "tabs")):
            if delim in header[0]:
                problems.append(Problem(
                    f"the file uses {label} to separate columns; ',' (comma) is required, with '.' "
                    "as the decimal point; re-export it as comma-separated CSV", line=header_line))
                raise ImpactDataError(source, problems)
    bad = next((f for f in header if "\n" in f or "\r" in f), None)
    if bad is not None:
        first = bad.splitlines()[0] if bad.splitlines() else ""
        problems.append(Problem(
            'a quote (") opens a header field here and is not closed on this line, so the following '
            "lines were read as part of the header; remove the stray quote or close it",
            line=header_line, value=first[:60] + ("..." if len(first) > 60 else "")))
        raise ImpactDataError(source, problems)
    problems += _control_characters(header, header_line, records)
    records, quote_problems = _drop_unclosed_quotes(header, header_line, records)
    problems += quote_problems
    return header, header_line, records, problems


def _skip_preamble(source: str, text: str, problems: list[Problem]) -> tuple[str, int]:
    """(text after the leading comment and ``sep=`` lines, number of lines skipped).

    Skipped: Excel's delimiter hint ``sep=,`` as the first line, and lines whose first non-blank
    character is ``#`` above the header (blank lines between them too). A ``sep=`` line naming
    another delimiter is refused (raises)."""
    lines = text.splitlines(keepends=True)
    n = 0
    for i, line in enumerate(lines):
        s = line.strip()
        m = re.fullmatch(r'"?sep=(.?)"?,*', s, flags=re.IGNORECASE)
        if i == 0 and m:
            if m.group(1) != ",":
                label = {";": "';' (semicolon)", "\t": "tabs", "": "nothing"}.get(m.group(1), repr(m.group(1)))
                problems.append(Problem(
                    f"Excel's delimiter line {s!r} says the columns are separated by {label}; ',' (comma) "
                    "is required, with '.' as the decimal point; re-export it as comma-separated CSV", line=1))
                raise ImpactDataError(source, problems)
            n = i + 1
            continue
        if s.startswith("#"):
            n = i + 1
            continue
        if s:
            break
    return "".join(lines[n:]), n


_CONTROL = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f]")
_CONTROL_NAMES = {0: "NUL", 7: "BEL", 8: "BS", 11: "VT", 12: "FF", 26: "SUB", 27: "ESC", 127: "DEL"}


def _field_name(header: list[str], i: int) -> str:
    return header[i].strip() if i < len(header) else f"(field {i + 1}, beyond the header)"


def _control_characters(header, header_line: int, records: list[_Record]) -> list[Problem]:
    """A problem for every header field or cell that holds a control character (tab, CR and LF
    are allowed: they are whitespace or line ends). Such a cell is also marked bad in its record
    so that it is not reported a second time (e.g. as "not a number")."""
    problems = []

    def check(fields, row, line):
        bad = set()
        for i, f in enumerate(fields):
            m = _CONTROL.search(f)
            if m:
                code = ord(m.group())
                name = _CONTROL_NAMES.get(code, "control character")
                count = len(_CONTROL.findall(f))
                more = f" (and {count - 1} more)" if count > 1 else ""
                problems.append(Problem(
                    f"contains the control character U+{code:04X} ({name}) at character {m.start() + 1}{more}; "
                    "remove it: a text CSV holds none (NUL bytes often mean a UTF-16 or binary file, or a "
                    "damaged copy), and dropping it silently could change a number",
                    row, line, _field_name(header, i), f))
                bad.add(i)
        return bad

    check(header, None, header_line)
    for k, rec in enumerate(records):
        bad = check(rec.fields, rec.row, rec.line)
        if bad:
            records[k] = _Record(rec.fields, rec.row, rec.line, frozenset(bad))
    return problems


def _drop_unclosed_quotes(header, header_line: int, records: list[_Record]):
    """(records without those where a quoted cell runs over a line end, a problem for each).

    A cell of this format never holds a line break, so a quoted cell that does means a quote
    that is not closed where it should be: the problem names the row, line and column where the
    quote opens, and how far the cell ran (to the end of the file when the quote never closes)."""
    problems, kept = [], []
    for k, rec in enumerate(records):
        i = next((i for i, f in enumerate(rec.fields) if "\n" in f or "\r" in f), None)
        if i is None:
            kept.append(rec)
            continue
        cell = rec.fields[i]
        body = cell.rstrip("\r\n")
        spans = body.count("\n") + body.count("\r") - body.count("\r\n")
        last = k == len(records) - 1 and i == len(rec.fields) - 1
        how = ("is never closed, so the rest of the file (lines "
               f"{rec.line}-{rec.line + spans}) was read as one cell" if last else
               f"is closed only {spans} line(s) later, on line {rec.line + spans}, so those lines were "
               "read as one cell")
        first = cell.splitlines()[0] if cell.splitlines() else ""
        problems.append(Problem(
            f'a quote (") opens a cell here and {how}; remove the stray quote or close it on this line '
            "(a cell cannot contain a line break)",
            rec.row, rec.line, _field_name(header, i), first[:60] + ("..." if len(first) > 60 else "")))
    return kept, problems


def _kept_columns(header: list[str], ignored: list[str]) -> dict[str, int]:
    """The analyst's own columns: DataFrame name -> field index. Unnamed columns (a trailing
    comma) are dropped; a name that is also a column of the returned table gets ``csv_`` in front,
    and a repeated name ``_2``, ``_3``, ... behind."""
    out: dict[str, int] = {}
    wanted = set(ignored)
    for i, raw in enumerate(header):
        field = raw.strip()
        if not field or field not in wanted:
            continue
        name = f"csv_{field}" if field in CANONICAL_COLUMNS else field
        base, k = name, 2
        while name in out:
            name, k = f"{base}_{k}", k + 1
        out[name] = i
    return out


def _warn_ignored(name: str, ignored: list[str]) -> None:
    """One :class:`ImpactDataWarning` naming the columns that are not part of the format but close
    to a known name (likely typos; they are kept as text like the analyst's other columns)."""
    hints = []
    for f in ignored:
        close = difflib.get_close_matches(parse_header_field(f)[0], _KNOWN, n=1)
        if close:
            hints.append(f"{f!r} (did you mean {close[0]!r}?)")
    if hints:
        warnings.warn(
            f"{name}: columns that are not part of the impact format, kept as text labels: {', '.join(hints)}",
            ImpactDataWarning, stacklevel=3)


def _drop_ragged(records: list[_Record], width: int) -> tuple[list[_Record], list[Problem]]:
    """(records with ``width`` fields, a problem for each other record)."""
    problems = []
    for rec in records:
        if len(rec.fields) != width:
            hint = " (a decimal comma? use '.' as the decimal point)" if len(rec.fields) > width else ""
            problems.append(Problem(f"has {len(rec.fields)} fields but the header has {width} columns{hint}",
                                    row=rec.row, line=rec.line, value=",".join(rec.fields)))
    return [rec for rec in records if len(rec.fields) == width], problems


class _Cells:
    """The cells of the known columns (stripped text) with the data row and line of each record."""

    def __init__(self, columns: Mapping[str, _Column], records: list[_Record]):
        self.n = len(records)
        self.rows = np.asarray([r.row for r in records], dtype=np.int64)
        self.lines = np.asarray([r.line for r in records], dtype=np.int64)
        self.text = {c.name: np.array([r.fields[c.index].strip() for r in records], dtype=object)
                     for c in columns.values()}
        # cells already reported (control characters): no second problem for them
        self.reported = {c.name: np.array([c.index in r.bad for r in records], dtype=bool)
                         for c in columns.values()}
        # measured values kept outside their physical range (within their stated error): column -> mask
        self.kept_outside: dict[str, np.ndarray] = {}

    def problems(self, mask, col: _Column, message: str) -> list[Problem]:
        """A problem of column ``col`` for every record where ``mask`` is true (cells already
        reported left out)."""
        mask = np.asarray(mask, dtype=bool) & ~self.reported[col.name]
        return [Problem(message, int(self.rows[i]), int(self.lines[i]), col.field, self.text[col.name][i])
                for i in np.flatnonzero(mask)]


def _parse_numbers(raw) -> np.ndarray:
    """Cells as floats, NaN where not a number. pandas decides what is a number; Python's float()
    then reads each one correctly rounded (pandas' fast parser before 2.2 can be a few ulp off, so a
    value written with repr() would not read back exactly)."""
    num = pd.to_numeric(pd.Series(raw), errors="coerce").to_numpy(dtype=float)
    for i in np.flatnonzero(np.isfinite(num)):
        try:
            num[i] = float(raw[i])
        except ValueError:  # a form pandas reads and Python does not: keep pandas' value
            pass
    return num


def _numeric_values(cells: _Cells, columns, factors, problems: list[Problem]) -> dict[str, np.ndarray]:
    """Numeric columns in internal units under their canonical names (NaN where not a valid
    number); appends a problem for every cell that is not a number, empty where required, not
    finite or out of range."""
    required = _required(columns)
    values: dict[str, np.ndarray] = {}
    for cname, col in columns.items():
        if cname in _LABELS:
            continue
        q = _QUANTITIES[cname]
        raw = cells.text[cname]
        num = _parse_numbers(raw)
        missing = np.zeros(cells.n, dtype=bool)
        nan_idx = np.flatnonzero(np.isnan(num))
        missing[nan_idx] = [raw[i].lower() in _MISSING for i in nan_idx]
        unit = col.unit if cname in factors else INTERNAL_UNIT[q.dimension]
        in_unit = " (unitless)" if q.dimension == "dimensionless" else f" in {unit}"
        problems += cells.problems(np.isnan(num) & ~missing, col, f"is not a number; expected a number{in_unit}")
        if cname in required:
            problems += cells.problems(missing, col, f"empty or NaN cell in a required column; give a number{in_unit}")
        problems += cells.problems(np.isinf(num), col, f"is not finite; expected a finite number{in_unit}")
        if cname not in factors:
            continue  # unit unknown: range checks would be meaningless
        x = num * factors[cname]
        with np.errstate(invalid="ignore"):
            out_of_range = np.isfinite(x) & ~q.ok(x / q.scale)
        if cname in MEASURED_QUANTITIES and out_of_range.any():
            kept = out_of_range & _within_stated_error(cells, columns, factors, cname, q, x)
            out_of_range &= ~kept
            cells.kept_outside[cname] = kept
        what = "uncertainty must be" if cname.endswith("_uncertainty") else "must be"
        if q.dimension == "angle" and unit not in ("deg", "degree", "degrees", "\u00b0"):
            for i in np.flatnonzero(out_of_range):
                problems.append(Problem(f"is {x[i]:.6g} deg; {what} {q.range_text()}",
                                        int(cells.rows[i]), int(cells.lines[i]), col.field, raw[i]))
        else:
            qualifier = " (speeds are magnitudes)" if q.dimension == "speed" and q.low == 0 else ""
            if cname in MEASURED_QUANTITIES:
                qualifier += (f", or outside it by at most {MEASUREMENT_TOLERANCE_SIGMAS:g} of the stated standard "
                              f"uncertainty (column {cname}_uncertainty)")
            problems += cells.problems(out_of_range, col, f"{what} {q.range_text()}{qualifier}")
        values[q.canonical] = np.where(np.isfinite(x), x, np.nan)
    return values


def _within_stated_error(cells: _Cells, columns, factors, cname: str, q: _Quantity, x: np.ndarray) -> np.ndarray:
    """Whether each value of a measured column lies within MEASUREMENT_TOLERANCE_SIGMAS of its stated
    uncertainty (column ``<name>_uncertainty``, same unit handling) of the accepted range."""
    unc = f"{cname}_uncertainty"
    if unc not in columns or unc not in factors:
        return np.zeros(cells.n, dtype=bool)
    s = _parse_numbers(cells.text[unc]) * factors[unc]
    below = np.where(x < q.low, q.low - x, 0.0)
    above = np.where(x > q.high, x - q.high, 0.0)
    with np.errstate(invalid="ignore"):
        return np.isfinite(s) & (s > 0) & (np.maximum(below, above) <= MEASUREMENT_TOLERANCE_SIGMAS * s)


def _labels(cells: _Cells, columns, materials, problems: list[Problem]) -> dict[str, np.ndarray]:
    """Text label columns (None where empty); appends problems for repeated ids and for material
    pairs that are not in ``materials`` (a mapping or the path of a materials config)."""
    labels = {c: np.where(cells.text[c] == "", None, cells.text[c]) for c in _LABELS if c in columns}
    if "id" in labels:
        ids = pd.Series(labels["id"])
        dup = ids.notna() & ids.duplicated(keep="first")
        for i in np.flatnonzero(dup.to_numpy()):
            first = int(cells.rows[np.flatnonzero((ids == ids.iloc[i]).to_numpy())[0]])
            problems.append(Problem(
                f"id is not unique (first on row {first}); give each impact its own id",
                int(cells.rows[i]), int(cells.lines[i]), columns["id"].field, labels["id"][i]))
    if materials is not None and "material_pair" in labels:
        if not isinstance(materials, Mapping):
            materials = read_materials(materials)
        bad = np.array([m is not None and m not in materials for m in labels["material_pair"]], dtype=bool)
        problems += cells.problems(bad, columns["material_pair"],
                                   f"is not a pair in the materials config; known pairs: {', '.join(sorted(materials))}")
    return labels


def _check_rebound(cells: _Cells, col: _Column, out: dict, problems: list[Problem]) -> None:
    """Append a problem for every rebound normal speed larger than the incident one (e_n > 1)."""
    vn, r = out["normal_speed"], out["rebound_normal_speed"]
    sr, svn = out["rebound_normal_speed_uncertainty"], out["normal_speed_uncertainty"]
    with np.errstate(invalid="ignore"):
        # a rebound faster than the incidence by no more than the stated errors allow is a measurement
        s = np.hypot(np.nan_to_num(sr), np.nan_to_num(svn))
        kept = (r > vn) & (s > 0) & (r - vn <= MEASUREMENT_TOLERANCE_SIGMAS * s)
        too_fast = (r > vn) & ~kept
    if kept.any():
        prev = cells.kept_outside.get("rebound_normal_speed", np.zeros(cells.n, dtype=bool))
        cells.kept_outside["rebound_normal_speed"] = prev | kept
    for i in np.flatnonzero(too_fast):
        problems.append(Problem(
            f"is larger than the incident normal speed ({vn[i]:.6g} m/s), so e_n = "
            f"{r[i] / vn[i]:.4g} > 1; e_n must be in [0, 1], or above 1 by no more than "
            f"{MEASUREMENT_TOLERANCE_SIGMAS:g} stated standard uncertainties",
            int(cells.rows[i]), int(cells.lines[i]), col.field, cells.text["rebound_normal_speed"][i]))


def _check_tangential_bound(cells: _Cells, columns, out: dict, problems: list[Problem]) -> None:
    """Append a problem for every row without a stated ``spin`` whose |e_t| exceeds 1 by more than
    :data:`MEASUREMENT_TOLERANCE_SIGMAS` of its stated uncertainty.

    Without incident spin the friction and tangential-compliance impulses only take tangential and
    rotational kinetic energy, m (v_t'^2 + k r^2 omega'^2) / 2 <= m v_t^2 / 2 (Maw, Barber & Fawcett
    1976, Wear 38:101-114: the tangential work is dissipated or stored and returned), so |v_t,out| <= v_t,in: |e_t| <= 1. A row above it within its errors
    is a measurement (kept, warned by :func:`_warn_implausible`); without a stated uncertainty the
    row is kept and warned as before (it may have had an unstated top-spin); with one, an excess
    the errors cannot explain is refused: every fit reads the table, so each refuses it alike."""
    e, se = out["tangential_restitution"], out["tangential_restitution_uncertainty"]
    with np.errstate(invalid="ignore"):
        impossible = (np.abs(e) > 1.0) & ~np.isfinite(out["spin"]) & np.isfinite(se) \
            & (np.abs(e) - 1.0 > MEASUREMENT_TOLERANCE_SIGMAS * se)
    name = next((n for n in ("tangential_restitution", "rebound_tangential_speed", "rebound_angle") if n in columns), None)
    if name is None:
        return
    for i in np.flatnonzero(impossible):
        problems.append(Problem(
            f"gives e_t = {e[i]:.4g} +- {se[i]:.2g}, so |e_t| > 1 by more than {MEASUREMENT_TOLERANCE_SIGMAS:g} "
            "standard uncertainties: without incident spin the rebound cannot be faster along the surface than "
            "the incidence; correct the value or its uncertainty, or state the incident spin in a 'spin [rad/s]' column",
            int(cells.rows[i]), int(cells.lines[i]), columns[name].field, cells.text[name][i]))


def _sorted(problems: list[Problem]) -> list[Problem]:
    """File/header problems first, then by row, keeping the order within a row."""
    return sorted(problems, key=lambda p: (p.row is not None, p.row or 0, p.line or 0))


# --------------------------------------------------------------------------- material pairs
def material_pairs(table: pd.DataFrame, default: str | None = None) -> list[str]:
    """The material pairs of an impact table, sorted: its ``material_pair`` labels, and ``default``
    when some row has no label (those rows belong to it).

    Parameters
    ----------
    table : pandas.DataFrame
        As returned by :func:`read_impacts`.
    default : str, optional
        Pair of the rows without a ``material_pair`` cell (the pipeline's config key
        ``material_pair``, the CLI's ``--material-pair``).

    Returns
    -------
    list of str

    Examples
    --------
    >>> t = pd.DataFrame({"material_pair": ["b", None, "a", "b"]})
    >>> material_pairs(t, default="c")
    ['a', 'b', 'c']
    >>> material_pairs(t.iloc[[0, 2]])
    ['a', 'b']
    """
    labels = table["material_pair"] if "material_pair" in table.columns else pd.Series([None] * len(table), dtype=object)
    pairs = {str(p) for p in labels.dropna().unique()}
    if default is not None and bool(labels.isna().any()):
        pairs.add(default)
    return sorted(pairs)


def select_material_pair(table: pd.DataFrame, pair: str, *, default: str | None = None) -> pd.DataFrame:
    """The rows of one material pair: those labelled ``pair``, and the unlabelled ones when ``pair``
    is the ``default`` pair. Row numbers (``row``), ids and ``attrs`` are kept; the label column is
    filled with ``pair`` and ``attrs["material_pair"]`` set, so every per-row output names the pair.

    Parameters
    ----------
    table : pandas.DataFrame
        As returned by :func:`read_impacts`.
    pair : str
        The material pair.
    default : str, optional
        Pair of the rows without a ``material_pair`` cell.

    Returns
    -------
    pandas.DataFrame
        The pair's rows in file order (index from 0).

    Raises
    ------
    ValueError
        If no row belongs to ``pair`` (the message names the pairs that do occur).

    Examples
    --------
    >>> t = pd.DataFrame({"row": [1, 2, 3], "material_pair": pd.array(["a", None, "b"], dtype="string")})
    >>> select_material_pair(t, "a", default="a")["row"].tolist()
    [1, 2]
    >>> select_material_pair(t, "b", default="a")["material_pair"].tolist()
    ['b']
    """
    labels = table["material_pair"] if "material_pair" in table.columns else pd.Series([None] * len(table), dtype=object)
    missing = labels.isna().to_numpy(dtype=bool)
    keep = np.array([not m and str(x) == pair for x, m in zip(labels, missing)], dtype=bool)
    if pair == default:
        keep |= missing
    if not keep.any():
        src = table.attrs.get("source", "impact table")
        raise ValueError(f"{src}: no impacts of material pair {pair!r} (pairs in the file: "
                         f"{', '.join(material_pairs(table, default)) or 'none'})")
    sub = table[keep].reset_index(drop=True)
    sub["material_pair"] = pair
    sub.attrs = {**table.attrs, "material_pair": pair}
    return sub


# --------------------------------------------------------------------------- the analyst's row labels
#: attribute of a NetCDF variable that holds one of the analyst's own CSV columns (its name)
CSV_COLUMN_ATTR = "csv_column"


def row_labels(table: pd.DataFrame) -> pd.DataFrame:
    """The analyst's own labels of each row of an impact table: ``id`` and every kept column.

    Parameters
    ----------
    table : pandas.DataFrame
        A table of :func:`read_impacts` (or rows of one).

    Returns
    -------
    pandas.DataFrame
        One text column per label ('' where the cell was empty), in the table's row order, index
        0..n-1; no columns when the file had neither an ``id`` nor columns of its own.

    Examples
    --------
    >>> t = pd.DataFrame({"id": pd.array(["a", None], dtype="string"), "radius": [1e-6, 2e-6],
    ...                   "operator": pd.array(["kim", "lee"], dtype="string")})
    >>> t.attrs["kept_columns"] = ("operator",)
    >>> row_labels(t).to_dict("list")
    {'id': ['a', ''], 'operator': ['kim', 'lee']}
    """
    names = (["id"] if "id" in table.columns else []) + [c for c in table.attrs.get("kept_columns", ())
                                                          if c in table.columns]
    return pd.DataFrame({c: table[c].astype("string").fillna("").to_numpy(dtype=object).astype(str).astype(object)
                         for c in names}, index=pd.RangeIndex(len(table)))


def insert_row_labels(data: pd.DataFrame, labels: pd.DataFrame, at: int = 1) -> pd.DataFrame:
    """``data`` (one row per labelled row, same order) with the label columns inserted at ``at``;
    a label whose name ``data`` already uses gets ``csv_`` in front. Returns a new DataFrame.

    Examples
    --------
    >>> d = pd.DataFrame({"row": [1, 2], "model": [0.5, 0.6]})
    >>> list(insert_row_labels(d, pd.DataFrame({"id": ["a", "b"], "model": ["x", "y"]})).columns)
    ['row', 'id', 'csv_model', 'model']
    """
    out = data.copy()
    for k, c in enumerate(labels.columns):
        name = c if c not in out.columns else f"csv_{c}"
        out.insert(min(at + k, out.shape[1]), name, labels[c].to_numpy(dtype=object))
    return out


def label_variables(labels: pd.DataFrame, dim: str) -> dict:
    """The labels as NetCDF-ready text variables along ``dim``: ``id`` as ``id``, each kept column
    as ``csv_<name>`` (ASCII letters, digits and ``_``) with its name in the attribute
    :data:`CSV_COLUMN_ATTR`; :func:`labels_from_dataset` reads them back.

    Examples
    --------
    >>> v = label_variables(pd.DataFrame({"id": ["a"], "batch no.": ["7"]}), "point")
    >>> sorted(v), v["csv_batch_no"].attrs["csv_column"]
    (['csv_batch_no', 'id'], 'batch no.')
    """
    out = {}
    for c in labels.columns:
        values = labels[c].to_numpy(dtype=object).astype(str).astype(object)
        if c == "id":
            out["id"] = xr.DataArray(values, dims=(dim,), attrs={"long_name": "the id column of the impact CSV"})
            continue
        stem = re.sub(r"[^A-Za-z0-9_]+", "_", c).strip("_") or "column"
        base = stem if stem.startswith("csv_") else f"csv_{stem}"
        name, k = base, 2
        while name in out:
            name, k = f"{base}_{k}", k + 1
        out[name] = xr.DataArray(values, dims=(dim,), attrs={
            "long_name": f"column {c!r} of the impact CSV (the analyst's own, kept as text)", CSV_COLUMN_ATTR: c})
    return out


def labels_from_dataset(ds, dim: str) -> pd.DataFrame:
    """The labels :func:`label_variables` wrote along ``dim``, as :func:`row_labels` gives them.

    Examples
    --------
    The inverse of :func:`label_variables`:

    >>> import xarray as xr
    >>> t = pd.DataFrame({"id": ["a", "b"], "batch no.": ["7", "8"]})
    >>> ds = xr.Dataset(label_variables(t, "point"))
    >>> labels_from_dataset(ds, "point").to_dict("list")
    {'id': ['a', 'b'], 'batch no.': ['7', '8']}
    """
    cols = {}
    for name, var in ds.data_vars.items():
        if var.dims == (dim,) and (name == "id" or CSV_COLUMN_ATTR in var.attrs):
            cols["id" if name == "id" else str(var.attrs[CSV_COLUMN_ATTR])] = var.values.astype(str).astype(object)
    return pd.DataFrame(cols, index=pd.RangeIndex(ds.sizes[dim]) if dim in ds.sizes else None)
