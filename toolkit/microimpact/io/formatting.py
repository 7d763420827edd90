"""Text formatting of table cells and durations, shared by every writer of human-readable tables.

:func:`format_cell` is the one formatter of a table cell (the reproduction table's Markdown, the
PDF report's tables); :func:`format_number` and :func:`format_duration` write the numbers of the
benchmark summary.

Example
-------
>>> from microimpact.io.formatting import format_cell, format_duration
>>> format_cell(True), format_cell(float("nan")), format_cell("a | b", markdown=True)
('yes', '', 'a \\\\| b')
>>> format_duration(2.5e-6)
'2.5 us'
"""

from __future__ import annotations

import html
import math

import numpy as np

__all__ = ["format_cell", "format_number", "format_duration", "estimates_repr", "ReportHTML"]


def format_cell(value, *, markdown: bool = False, float_format: str = ".4g") -> str:
    """One table cell as text.

    Parameters
    ----------
    value : object
        ``None`` -> ``""``; booleans (Python or numpy) -> ``"yes"`` / ``"no"``; floats ->
        ``float_format`` (NaN -> ``""``); anything else -> ``str(value)``.
    markdown : bool, optional
        Escape ``|`` and replace line breaks by spaces, so the text fits in one cell of a
        Markdown pipe table.
    float_format : str, optional
        Format spec of floats (default 4 significant digits).

    Returns
    -------
    str

    Examples
    --------
    >>> format_cell(0.123456789)
    '0.1235'
    """
    if value is None:
        text = ""
    elif isinstance(value, (bool, np.bool_)):
        text = "yes" if value else "no"
    elif isinstance(value, (float, np.floating)):
        text = "" if math.isnan(value) else format(value, float_format)
    else:
        text = str(value)
    if markdown:
        text = text.replace("|", "\\|").replace("\n", " ")
    return text


def format_number(x, spec: str = ".2e") -> str:
    """``x`` formatted with ``spec``; ``"-"`` for None or NaN, ``"inf"`` for infinity.

    Examples
    --------
    >>> format_number(1234.5678, ".3g")
    '1.23e+03'
    """
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if isinstance(x, float) and math.isinf(x):
        return "inf"
    return format(x, spec)


def format_duration(seconds: float) -> str:
    """A duration [s] in us, ms or s to 3 significant digits; ``"-"`` for NaN, ``"> limit"`` for inf.

    Examples
    --------
    >>> format_duration(3725.0), format_duration(0.5)
    ('3.72e+03 s', '500 ms')
    """
    if not math.isfinite(seconds):
        return "-" if math.isnan(seconds) else "> limit"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} us"
    if seconds < 1:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


def estimates_repr(kind: str, values: dict, stderr: dict | None = None, varied=None, **extra) -> str:
    """A one-line repr of a fit-like result: each parameter with its standard error, fixed ones
    marked, then a few scalars (``extra``); no tables or arrays (a DampingFit's default repr
    printed its whole DataFrame).

    Examples
    --------
    >>> estimates_repr("DampingFit", {"zeta_hertz": 0.54241, "work_of_adhesion": 0.2158},
    ...                {"zeta_hertz": 0.1596}, varied=("zeta_hertz",), n_points=20)
    'DampingFit(zeta_hertz=0.5424 +/- 0.16, work_of_adhesion=0.2158 (fixed), n_points=20)'
    """
    stderr = stderr or {}
    parts = []
    for name, value in values.items():
        if varied is not None and name not in varied:
            parts.append(f"{name}={value:.4g} (fixed)")
        elif stderr.get(name) is not None and math.isfinite(stderr[name]):
            parts.append(f"{name}={value:.4g} +/- {stderr[name]:.2g}")
        else:
            parts.append(f"{name}={value:.4g}")
    parts += [f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v!r}" for k, v in extra.items()]
    return f"{kind}({', '.join(parts)})"


class ReportHTML:
    """Mixin: a result with a ``report()`` text shows that text in a notebook (``_repr_html_``)
    instead of its one-line repr.

    Examples
    --------
    >>> class Result(ReportHTML):
    ...     def report(self):
    ...         return "zeta_H = 0.5 < 1"
    >>> Result()._repr_html_()
    '<pre>zeta_H = 0.5 &lt; 1</pre>'
    """

    def _repr_html_(self) -> str:
        return f"<pre>{html.escape(self.report())}</pre>"
