"""What the data determine about a fitted parameter, as a record and as CF NetCDF variables.

:class:`ParameterStatus` is the answer of :mod:`microimpact.analysis.identifiability` (a value with
its interval, a one-sided bound, or nothing); here it is stored and read back, so that everything
that only reads result files (the report) can state it without importing the analysis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr

__all__ = ["ParameterStatus", "STATUSES", "DEFAULT_LEVEL", "status_variables", "status_from_variables",
           "stderr_is_meaningful"]

#: the four answers, in the order of their NetCDF flag values 0-3
STATUSES = ("determined", "lower_bound", "upper_bound", "not_determined")
#: confidence level of every reported interval and bound
DEFAULT_LEVEL = 0.95



@dataclass(frozen=True)
class ParameterStatus:
    """What the data say about one fitted parameter.

    Attributes
    ----------
    name : str
        Parameter name (``friction``, ``zeta_hertz``, ...).
    status : str
        One of :data:`STATUSES`.
    value : float
        The estimate where ``determined``, else NaN. [unit of the parameter]
    lower, upper : float
        The ``level`` interval where ``determined``; the bound and the end of the allowed range for
        a one-sided bound (``lower_bound``: ``[bound, range max]``; ``upper_bound``:
        ``[range min, bound]``); the whole allowed range where ``not_determined``.
    level : float
        Confidence level of ``[lower, upper]``. [-]
    reason : str
        Why, in the terms of the data (empty for an ordinary determined parameter).
    method : str
        How the interval was found: ``profile`` or ``covariance``.

    Examples
    --------
    A parameter the data bound from below only is printed as a bound, never as a number:

    >>> s = ParameterStatus("friction", "lower_bound", math.nan, 0.27, 10.0,
    ...                     reason="every impact ends in rolling above it")
    >>> s.determined, s.contains(0.5), s.contains(0.1)
    (False, True, False)
    >>> s.describe()
    'friction >= 0.27 (95 % bound; no upper limit up to 10 from these data): every impact ends ...'
    >>> ParameterStatus("zeta_hertz", "determined", 0.5, 0.45, 0.56).describe()
    'zeta_hertz = 0.5, 95 % interval [0.45, 0.56]'
    """

    name: str
    status: str
    value: float
    lower: float
    upper: float
    level: float = DEFAULT_LEVEL
    reason: str = ""
    method: str = "covariance"

    def __post_init__(self):
        if self.status not in STATUSES:
            raise ValueError(f"status must be one of {', '.join(STATUSES)}, got {self.status!r}")

    @property
    def determined(self) -> bool:
        """True where the data determine a value with a finite two-sided interval."""
        return self.status == "determined"

    def contains(self, x: float) -> bool:
        """Whether ``x`` lies in ``[lower, upper]`` (the interval, bound or range reported)."""
        return bool(self.lower <= x <= self.upper)

    def to_record(self, stderr: float = math.nan) -> dict:
        """The status as JSON-ready numbers, by the rules of :meth:`describe`: a value, its
        interval and its standard error only where the data determine it (the standard error also
        only where :func:`stderr_is_meaningful`), else the bound or the searched range.

        Examples
        --------
        >>> ParameterStatus("friction", "lower_bound", math.nan, 0.27, 10.0).to_record()
        {'status': 'lower_bound', 'level': 0.95, 'lower_bound': 0.27, 'searched_up_to': 10.0}
        """
        rec = {"status": self.status, "level": self.level}
        if self.status == "determined":
            rec |= {"value": self.value, "interval": [self.lower, self.upper]}
            if stderr_is_meaningful(self.value, stderr):
                rec["stderr"] = float(stderr)
        elif self.status == "lower_bound":
            rec |= {"lower_bound": self.lower, "searched_up_to": self.upper}
        elif self.status == "upper_bound":
            rec |= {"upper_bound": self.upper, "searched_down_to": self.lower}
        else:
            rec |= {"searched_range": [self.lower, self.upper]}
        if self.reason:
            rec["reason"] = self.reason
        return rec

    def describe(self, unit: str = "", digits: int = 4) -> str:
        """One line for a report: the value and interval, or the bound, or 'not determined'.

        Examples
        --------
        >>> ParameterStatus("friction", "lower_bound", math.nan, 0.27, 10.0).describe()
        'friction >= 0.27 (95 % bound; no upper limit up to 10 from these data)'
        """
        u = f" {unit}" if unit and unit != "1" else ""
        pct = f"{100 * self.level:.0f} %"
        g = f".{digits}g"
        why = f": {self.reason}" if self.reason else ""
        if self.status == "determined":
            return f"{self.name} = {self.value:{g}}{u}, {pct} interval [{self.lower:{g}}, {self.upper:{g}}]{why}"
        if self.status == "lower_bound":
            return (f"{self.name} >= {self.lower:{g}}{u} ({pct} bound; no upper limit up to {self.upper:{g}} "
                    f"from these data){why}")
        if self.status == "upper_bound":
            return (f"{self.name} <= {self.upper:{g}}{u} ({pct} bound; no lower limit down to {self.lower:{g}} "
                    f"from these data){why}")
        return f"{self.name}: not determined by these data (anywhere in [{self.lower:{g}}, {self.upper:{g}}]){why}"


def stderr_is_meaningful(value: float, stderr: float) -> bool:
    """Whether a standard error may be printed as a number next to its value: finite, and at most
    100 % of a nonzero value. Above that, "value +/- stderr" spans zero and says nothing the
    interval or bound does not say better; every printed fit result applies this one rule.

    Examples
    --------
    >>> stderr_is_meaningful(0.5, 0.1), stderr_is_meaningful(0.5, 0.6), stderr_is_meaningful(0.0, 0.1)
    (True, False, False)
    """
    return bool(math.isfinite(stderr) and math.isfinite(value) and value != 0 and stderr <= abs(value))


def status_variables(status: ParameterStatus, units: str) -> dict:
    """CF variables of a :class:`ParameterStatus`: ``<name>_status`` (a flag), ``<name>_lower``, ``<name>_upper``.

    Parameters
    ----------
    status : ParameterStatus
    units : str
        CF units of the parameter.

    Returns
    -------
    dict of xarray.DataArray
        Scalar variables; the status carries ``flag_values``/``flag_meanings`` (CF 1.10 section 3.5),
        the reason, the level and the method as attributes.

    Examples
    --------
    >>> v = status_variables(ParameterStatus("friction", "lower_bound", math.nan, 0.27, 10.0), "1")
    >>> int(v["friction_status"]), v["friction_status"].attrs["flag_meanings"].split()[1]
    (1, 'lower_bound')
    """
    n = status.name
    what = {"determined": "interval", "lower_bound": "lower bound (upper: end of the range searched)",
            "upper_bound": "upper bound (lower: start of the range searched)",
            "not_determined": "range searched"}[status.status]
    return {
        f"{n}_status": xr.DataArray(np.int8(STATUSES.index(status.status)), attrs={
            "long_name": f"what the data determine about {n}", "flag_values": np.arange(len(STATUSES), dtype=np.int8),
            "flag_meanings": " ".join(STATUSES), "reason": status.reason or "determined", "level": status.level,
            "method": status.method}),
        f"{n}_lower": xr.DataArray(float(status.lower), attrs={
            "units": units, "long_name": f"lower end of the {100 * status.level:.0f} % {what} of {n}"}),
        f"{n}_upper": xr.DataArray(float(status.upper), attrs={
            "units": units, "long_name": f"upper end of the {100 * status.level:.0f} % {what} of {n}"}),
    }


def status_from_variables(ds, name: str, value: float) -> ParameterStatus | None:
    """Inverse of :func:`status_variables` (None where the file predates them).

    Parameters
    ----------
    ds : xarray.Dataset
    name : str
        Parameter name.
    value : float
        The stored estimate (used where the status is ``determined``).

    Examples
    --------
    A round trip through the file's variables:

    >>> import xarray as xr
    >>> s = ParameterStatus("friction", "lower_bound", math.nan, 0.27, 10.0,
    ...                     reason="all roll above it")
    >>> back = status_from_variables(xr.Dataset(status_variables(s, "1")), "friction", math.nan)
    >>> back.status, back.lower, back.upper, back.reason
    ('lower_bound', 0.27, 10.0, 'all roll above it')
    """
    if f"{name}_status" not in ds:
        return None
    v = ds[f"{name}_status"]
    status = STATUSES[int(v.values)]
    reason = str(v.attrs.get("reason", ""))
    return ParameterStatus(name, status, float(value) if status == "determined" else math.nan,
                           float(ds[f"{name}_lower"]), float(ds[f"{name}_upper"]), float(v.attrs.get("level", DEFAULT_LEVEL)),
                           "" if reason == "determined" else reason, str(v.attrs.get("method", "")))
