"""Figures: analogues of the figures of Cheng, Brach & Dunn (2002), doi:10.1080/02786820290092221.

Every function takes xarray Datasets produced by the toolkit, draws on a new
:class:`matplotlib.figure.Figure` (no pyplot state, no file I/O) and returns a :class:`Plot`: the
figure plus a caption that says what is drawn and how (units, what dotted lines and markers mean).
Save with ``plot.figure.savefig(path)`` (or through :func:`microimpact.io.files.atomic_path`).

Sizes are for an A4 page: full text width (7 in) and 8-9 pt text.

==================================== ========================= ======================================
function                             paper figure              input
==================================== ========================= ======================================
:func:`plot_fit`                     Fig. 3                    ``DampingFit.to_dataset()`` (+ curves)
:func:`plot_bifurcation_plane`       Fig. 4                    :func:`dynamics.bifurcation_plane`
:func:`plot_phase_portraits`         Fig. 5                    list of :func:`dynamics.phase_portrait`
:func:`plot_energy_loss`             Figs. 7, 9, 11            :func:`sweeps.run_sweep`
:func:`plot_restitution_and_impulse` Figs. 8, 10, 12, 13, 14   :func:`sweeps.run_sweep`
:func:`plot_size_dependence`         (none)                    sweep with a ``radius`` dimension
:func:`plot_work_precision`          (none)                    benchmark Dataset
:func:`plot_kharaz`                  (none)                    :func:`validation.kharaz_comparison`
:func:`plot_flags`                   (none)                    :func:`analysis.flags.flag_measurements`
==================================== ========================= ======================================
"""

from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass

import matplotlib
import matplotlib.ticker
import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import NullFormatter

from microimpact.io.statuses import status_from_variables
from microimpact.report.inputs import FLAG_LETTERS, read_verdict

__all__ = [
    "Plot",
    "TABLE2_FIGURES",
    "plot_energy_loss",
    "plot_restitution_and_impulse",
    "plot_size_dependence",
    "plot_phase_portraits",
    "plot_bifurcation_plane",
    "plot_fit",
    "plot_work_precision",
    "plot_kharaz",
    "plot_flags",
]

#: Table 2 case -> (energy-loss figure, e_n/mu figure) of the paper (case 2.4/2.5 only have the latter)
TABLE2_FIGURES = {"2.1": ("7", "8"), "2.2": ("9", "10"), "2.3": ("11", "12"), "2.4": (None, "13"), "2.5": (None, "14")}

WIDTH = 7.0  # in, A4 text width
STYLE = {
    "font.size": 8.5,
    "axes.titlesize": 9,
    "axes.labelsize": 8.5,
    "legend.fontsize": 7.5,
    "legend.title_fontsize": 8,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    "lines.linewidth": 1.3,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "grid.linewidth": 0.5,
}
CAPTURE_SHADE = "0.88"

# Symbols and units (as axis-label text) of sweep quantities
_SYMBOL = {
    "speed": (r"incident speed $v$", "m/s"),
    "incidence_deg": (r"$\alpha$", "deg"),
    "azimuth_deg": (r"$\theta$", "deg"),
    "omega_n": (r"$\omega_n$", "rad/s"),
    "omega_t": (r"$\omega_t$", "rad/s"),
    "omega_tp": (r"$\omega_{t'}$", "rad/s"),
    "friction": (r"$f$", "-"),
}


_HUE_TEXT = {
    "incidence_deg": "the incidence angle alpha [deg]",
    "azimuth_deg": "the azimuth theta [deg]",
    "omega_n": "omega_n [rad/s]",
    "omega_t": "omega_t [rad/s]",
    "omega_tp": "omega_t' [rad/s]",
    "friction": "the friction coefficient f",
}


@dataclass(frozen=True)
class Plot:
    """A figure and its caption.

    Attributes
    ----------
    figure : matplotlib.figure.Figure
    caption : str
        Plain-text caption (what is plotted, units, line styles, data provenance).
    paper_figure : str or None
        Number of the paper's figure this is an analogue of, e.g. "7".

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> p = Plot(Figure(), "An empty figure.")
    >>> len(p.figure.axes), p.caption, p.paper_figure
    (0, 'An empty figure.', None)
    """

    figure: Figure
    caption: str
    paper_figure: str | None = None

    def __post_init__(self):
        # every log axis of every figure gets the same readable tick labels (_LogLabels): plain
        # numbers where they are short, never the '2x10^0 3x10^0' labels that run into each other
        for ax in self.figure.axes:
            for axis, scale in ((ax.xaxis, ax.get_xscale()), (ax.yaxis, ax.get_yscale())):
                if scale == "log":
                    _plain_log_labels(axis)


def _figure(width: float, height: float) -> Figure:
    fig = Figure(figsize=(width, height), layout="constrained")
    return fig


def _rc(func):
    """Run a figure function under the toolkit style (matplotlib.rc_context, no global change)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with matplotlib.rc_context(STYLE):
            return func(*args, **kwargs)

    return wrapper


def _panel_label(ax, text: str) -> None:
    ax.set_title(text, loc="left", fontweight="bold")


def _fmt_value(x: float) -> str:
    """Compact legend number: 0, 5, 0.1, 6e4 -> '6×10⁴'."""
    if x == 0:
        return "0"
    exp = int(math.floor(math.log10(abs(x))))
    if -2 <= exp <= 3:
        return f"{x:g}"
    mant = x / 10**exp
    return (f"{mant:.3g}" + r"$\times10^{" + str(exp) + "}$") if abs(mant - 1) > 1e-12 else r"$10^{" + str(exp) + "}$"


def _colors(n: int):
    cmap = colormaps["viridis"]
    return [cmap(0.85 * i / max(n - 1, 1)) for i in range(n)]


def _contact_text(ds: xr.Dataset) -> str:
    a = ds.attrs
    if "contact_radius" not in a:
        return ""
    ref = a.get("contact_damping_reference_speed")
    ref = "per-impact v_n" if isinstance(ref, str) else f"{float(ref):g} m/s"
    return (
        f"r = {a['contact_radius'] * 1e6:.3g} um, density {a['contact_density']:g} kg/m^3, "
        f"K = {a['contact_stiffness']:.4g} Pa, f0 = {a['contact_adhesion_line_force']:g} N/m, "
        f"zeta_H = {a['contact_zeta_hertz']:g}, zeta_A = {a['contact_zeta_adhesion']:g} "
        f"(reference speed {ref})"
    )


def _hue_dim(ds: xr.Dataset, hue: str | None) -> str | None:
    others = [d for d in ds["e_n"].dims if d != "speed"]
    if "speed" not in ds["e_n"].dims:
        raise ValueError(f"the dataset has no 'speed' dimension (dims {dict(ds.sizes)}); sweep the speed")
    if hue is None:
        multi = [d for d in others if ds.sizes[d] > 1]
        if len(multi) > 1:
            raise ValueError(
                f"the sweep has several dimensions besides speed ({multi}); select one curve family with "
                "ds.sel(...) / ds.isel(...) or pass hue= and select the others"
            )
        hue = multi[0] if multi else (others[0] if others else None)
    if hue is not None:
        if hue not in others:
            raise ValueError(f"hue {hue!r} is not a dimension of the sweep besides speed ({others})")
        rest = [d for d in others if d != hue and ds.sizes[d] > 1]
        if rest:
            raise ValueError(f"select a single value of {rest} first (ds.sel / ds.isel)")
    return hue


def _curves(ds: xr.Dataset, hue: str | None):
    """[(label, value, sub-dataset along speed)] for each curve."""
    squeeze = [d for d in ds["e_n"].dims if d not in ("speed", hue)]
    ds = ds.isel({d: 0 for d in squeeze}) if squeeze else ds
    if hue is None:
        return [(None, None, ds)]
    return [(_fmt_value(float(v)), float(v), ds.isel({hue: i})) for i, v in enumerate(ds[hue].values)]


def _fixed_text(ds: xr.Dataset, hue: str | None) -> str:
    parts = []
    for key, (sym, units) in _SYMBOL.items():
        if key in ("speed", hue) or key not in ds.variables:
            continue
        if ds[key].ndim == 0:
            sym_txt = {"incidence_deg": "alpha", "azimuth_deg": "theta", "omega_n": "omega_n", "omega_t": "omega_t",
                       "omega_tp": "omega_t'", "friction": "f"}[key]
            unit_txt = "" if units == "-" else f" {units}"
            parts.append(f"{sym_txt} = {float(ds[key]):.3g}{unit_txt}")
    return ", ".join(parts)


def _capture_speeds(ds: xr.Dataset, curves) -> list[float]:
    """Incident speed below which each curve is captured: v_capture / cos(alpha) from ``capture_normal_speed``
    if present, else the midpoint between the last captured and first rebounding grid speed."""
    out = []
    for _, _, c in curves:
        if "capture_normal_speed" in ds and float(ds["capture_normal_speed"]) > 0:
            alpha = float(c["incidence_deg"]) if "incidence_deg" in c.variables and c["incidence_deg"].ndim == 0 else 0.0
            out.append(float(ds["capture_normal_speed"]) / math.cos(math.radians(alpha)))
            continue
        v = c["speed"].values
        cap = c["outcome"].values.astype(bool)
        if cap.any() and (~cap).any():
            out.append(0.5 * (v[cap].max() + v[~cap].min()))
        else:
            out.append(math.nan)
    return out


#: speeds spanning more than this ratio are drawn on a log axis (the analyst's sweeps run over the
#: measured speeds, often 1-100 m/s: a linear axis squeezes the capture region against its start)
LOG_SPEED_SPAN = 10.0


def _speed_axis(ax, ds: xr.Dataset) -> None:
    """Linear speed axis from 0 (the paper's figures), or a log axis where the speeds span decades."""
    v = np.asarray(ds["speed"].values, dtype=float)
    v = v[np.isfinite(v) & (v > 0)]
    if v.size and v.max() > LOG_SPEED_SPAN * v.min():
        ax.set_xscale("log")
        ax.set_xlim(v.min() / 1.05, v.max() * 1.05)
        _plain_log_labels(ax.xaxis)
    else:
        ax.set_xlim(0.0, float(v.max()) * 1.02 if v.size else 1.0)


class _LogLabels(matplotlib.ticker.Formatter):
    """Labels of a log axis that do not run into each other: plain numbers (0.5, 2, 10) between
    0.01 and 1000, powers of ten outside; the minor ticks (2 and 5 of each decade) labelled only
    while the axis spans at most a decade and a half (a 7-decade axis labelled at 1, 2 and 5 of
    each decade had its labels overlap)."""

    def __init__(self, minor: bool):
        self.minor = minor

    def __call__(self, x, pos=None):
        if not (x > 0 and math.isfinite(x)):
            return ""
        if self.minor:
            lo, hi = sorted(self.axis.get_view_interval())
            if not (lo > 0 and math.log10(hi / lo) <= 1.5):
                return ""
        if 1e-2 <= x < 1e3:
            return f"{x:g}"
        exponent = math.floor(math.log10(x) + 1e-9)
        mantissa = x / 10.0**exponent
        return (f"$10^{{{exponent}}}$" if abs(mantissa - 1.0) < 1e-6
                else f"${mantissa:g}\\times10^{{{exponent}}}$")


def _plain_log_labels(axis) -> None:
    """Readable labels on a log axis (:class:`_LogLabels`): the default 'm x 10^n' labels of an
    axis spanning less than a decade run into each other, and so do minor labels over many decades."""
    axis.set_major_formatter(_LogLabels(minor=False))
    axis.set_minor_locator(matplotlib.ticker.LogLocator(subs=(2.0, 5.0)))
    axis.set_minor_formatter(_LogLabels(minor=True))


def _mark_capture(ax, v_caps, colors) -> None:
    finite = [v for v in v_caps if math.isfinite(v)]
    if not finite:
        return
    lo, hi = min(finite), max(finite)
    x0 = ax.get_xlim()[0]
    ax.axvspan(x0, lo, color=CAPTURE_SHADE, zorder=0, lw=0)
    if hi > lo * (1 + 1e-6):  # capture speed differs between curves (alpha): one tick per curve
        ax.axvspan(lo, hi, color=CAPTURE_SHADE, alpha=0.45, zorder=0, lw=0)
        for v, col in zip(v_caps, colors):
            if math.isfinite(v):
                ax.plot([v], [1.0], marker="v", ms=4.5, color=col, mec="k", mew=0.3,
                        transform=ax.get_xaxis_transform(), clip_on=False, zorder=5, ls="none")
    ax.axvline(lo, color="0.45", lw=0.8, ls="--", zorder=1)
    ax.set_xlim(left=x0)


def _caption_capture(ds: xr.Dataset, v_caps) -> str:
    finite = sorted({round(v, 6) for v in v_caps if math.isfinite(v)})
    if not finite:
        return "No impact in the sweep is captured. "
    if "capture_normal_speed" in ds:
        txt = (f"Grey: captured (normal capture velocity v_capture = {float(ds['capture_normal_speed']):.4g} m/s, "
               "dashed line")
        if len(finite) > 1:
            txt += f"; light grey and triangles: v_capture / cos(alpha) = {finite[0]:.3g}-{finite[-1]:.3g} m/s per curve"
        return txt + "). "
    return f"Grey: captured (capture speed estimated from the grid: {finite[0]:.3g} m/s). "


def _legend(fig, ax, handles, hue, extra=()):
    if hue is None and not extra:
        return
    sym, units = _SYMBOL.get(hue, (hue, "")) if hue else ("", "")
    title = f"{sym} [{units}]" if hue else None
    ax.legend(handles=list(handles) + list(extra), title=title, loc="upper left", bbox_to_anchor=(1.02, 1.0),
              frameon=False, borderaxespad=0.0)


def _title(ds: xr.Dataset, what: str, fig_no: str | None) -> str:
    case = ds.attrs.get("case", "")
    t = what + (f" for Table 2 case {case}" if case else "")
    return t + (f" (analogue of Fig. {fig_no})" if fig_no else "")


# ----------------------------------------------------------------------------- Figs. 7, 9, 11
@_rc
def plot_energy_loss(ds: xr.Dataset, *, hue: str | None = None) -> Plot:
    """Energy-loss ratios K_L, K_t and K_L - K_t against the incident speed (Figs. 7, 9, 11).

    Parameters
    ----------
    ds : xarray.Dataset
        A sweep from :func:`microimpact.studies.sweeps.run_sweep` with a ``speed`` dimension and at most one
        other dimension of size > 1 (the curve family: incidence angle, spin or friction).
    hue : str, optional
        The curve-family dimension; default the only non-speed dimension.

    Returns
    -------
    Plot
        Three panels: (a) K_L, Eq. (25); (b) K_t, Eq. (24); (c) K_L - K_t. Solid: rebound; dotted:
        captured (ratios of the final state of a captured sphere, which may roll on); grey band:
        speeds at which the sphere is captured.

    Examples
    --------
    Three panels, one curve per incidence angle:

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.studies.sweeps import run_sweep
    >>> ds = run_sweep(WALL_1990, {"speed": [2.0, 4.0, 8.0], "incidence_deg": [0.0, 30.0]})
    >>> plot = plot_energy_loss(ds, hue="incidence_deg")
    >>> len(plot.figure.axes), plot.caption.split(".")[0]
    (3, 'Kinetic energy loss ratios')
    """
    hue = _hue_dim(ds, hue)
    curves = _curves(ds, hue)
    colors = _colors(len(curves))
    fig = _figure(WIDTH, 2.6)
    axes = fig.subplots(1, 3, sharex=True)
    quantities = [
        (ds["K_L"], r"$K_L$ [-]", "(a) translational, Eq. (25)"),
        (ds["K_t"], r"$K_t$ [-]", "(b) total, Eq. (24)"),
        (ds["K_L"] - ds["K_t"], r"$K_L - K_t$ [-]", r"(c) $K_L - K_t$"),
    ]
    handles = []
    v_caps = _capture_speeds(ds, curves)
    clipped = False
    for ax, (var, ylabel, title) in zip(axes, quantities):
        sq = [d for d in var.dims if d not in ("speed", hue)]
        var = var.isel({d: 0 for d in sq}) if sq else var
        rebound = np.asarray(_curves_values(var, curves, hue, captured=False))
        captured = np.asarray(_curves_values(var, curves, hue, captured=True))
        if np.isfinite(rebound).any():  # scale to the rebounds; captured values may be far off (spin)
            lo, hi = np.nanmin(rebound), np.nanmax(rebound)
            if np.isfinite(captured).any():
                near = captured[np.abs(captured - 0.5 * (lo + hi)) <= 1.0 * max(hi - lo, 0.05)]
                if near.size:
                    lo, hi = min(lo, near.min()), max(hi, near.max())
                clipped |= bool(np.any((captured < lo) | (captured > hi)))
            pad = 0.06 * max(hi - lo, 1e-3)
            ax.set_ylim(lo - pad, hi + pad)
        for i, ((label, _, c), col) in enumerate(zip(curves, colors)):
            y = var.isel({hue: i}).values if hue else var.values
            cap = c["outcome"].values.astype(bool)
            v = c["speed"].values
            (ln,) = ax.plot(v, np.where(cap, np.nan, y), color=col, label=label)
            ax.plot(v, np.where(cap, y, np.nan), color=col, ls=":", lw=1.0)
            if ax is axes[0]:
                handles.append(ln)
        ax.set_xlabel(r"incident speed $v$ [m/s]")
        ax.set_ylabel(ylabel)
        _panel_label(ax, title)
        _speed_axis(ax, ds)
        _mark_capture(ax, v_caps, colors)
    extra = [Line2D([], [], color="0.3", ls=":", lw=1.0, label="captured\n(final state)"),
             Patch(color=CAPTURE_SHADE, label="capture range")]
    _legend(fig, axes[2], handles if hue else [], hue, extra)
    fig_no = TABLE2_FIGURES.get(ds.attrs.get("case", ""), (None, None))[0]
    fixed = _fixed_text(ds, hue)
    caption = (
        f"{_title(ds, 'Kinetic energy loss ratios', fig_no)}. (a) K_L, Eq. (25), (b) K_t, Eq. (24), "
        f"(c) K_L - K_t, against the incident speed v [m/s]"
        + (f", one curve per value of {_HUE_TEXT.get(hue, hue)}" if hue else "")
        + (f"; {fixed}" if fixed else "") + ". Solid: rebound. Dotted: captured impacts, ratios of the final "
        "state (a captured sphere may roll on; the model has no rolling resistance). "
        + ("Some captured values lie outside the plotted range (a captured spinning sphere can end "
           "with more translational energy than it came with, K_L < 0). " if clipped else "")
        + _caption_capture(ds, v_caps) + (f"Contact: {_contact_text(ds)}." if _contact_text(ds) else "")
    )
    return Plot(fig, caption.strip(), fig_no)


def _curves_values(var, curves, hue, *, captured: bool):
    out = []
    for i, (_, _, c) in enumerate(curves):
        y = var.isel({hue: i}).values if hue else var.values
        cap = c["outcome"].values.astype(bool)
        out.append(np.where(cap == captured, y, np.nan))
    return out


# ----------------------------------------------------------------------------- Figs. 8, 10, 12-14
@_rc
def plot_restitution_and_impulse(ds: xr.Dataset, *, hue: str | None = None, panels: str | tuple = "auto") -> Plot:
    """Restitution e_n and impulse ratios mu_t, mu_t' against the incident speed (Figs. 8, 10, 12-14).

    Parameters
    ----------
    ds : xarray.Dataset
        A sweep from :func:`microimpact.studies.sweeps.run_sweep` (see :func:`plot_energy_loss`).
    hue : str, optional
        The curve-family dimension; default the only non-speed dimension.
    panels : "auto" or tuple of {"e_n", "mu_t", "mu_tp"}
        "auto" drops an impulse-ratio panel that is zero (or undefined) everywhere, e.g. mu_t'
        for an in-plane impact.

    Returns
    -------
    Plot
        e_n, Eq. (21) (0 when captured); mu_t, mu_t', Eqs. (22)-(23), left undefined (gaps) for
        captured impacts, as in the paper.

    Examples
    --------
    e_n and mu_t (no spin, so mu_t' = 0 is left out):

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.studies.sweeps import run_sweep
    >>> ds = run_sweep(WALL_1990, {"speed": [2.0, 4.0, 8.0], "incidence_deg": [0.0, 30.0]})
    >>> plot = plot_restitution_and_impulse(ds, hue="incidence_deg")
    >>> len(plot.figure.axes), plot.caption.split(".")[0]
    (2, 'Restitution coefficient and tangential impulse ratios')
    """
    hue = _hue_dim(ds, hue)
    curves = _curves(ds, hue)
    colors = _colors(len(curves))
    meta = {
        "e_n": (r"$e_n$ [-]", "Eq. (21)"),
        "mu_t": (r"$\mu_t$ [-]", "Eq. (22)"),
        "mu_tp": (r"$\mu_{t'}$ [-]", "Eq. (23)"),
    }
    if panels == "auto":
        panels = ["e_n"] + [k for k in ("mu_t", "mu_tp") if np.nanmax(np.abs(ds[k].values), initial=0.0) > 1e-12]
    panels = list(panels)
    unknown = [p for p in panels if p not in meta]
    if unknown:
        raise ValueError(f"panels must be among {list(meta)}, got {unknown}")
    fig = _figure(WIDTH if len(panels) == 3 else WIDTH * 0.78 if len(panels) == 2 else WIDTH * 0.5, 2.6)
    axes = np.atleast_1d(fig.subplots(1, len(panels), sharex=True))
    v_caps = _capture_speeds(ds, curves)
    handles = []
    for k, (ax, name) in enumerate(zip(axes, panels)):
        for (label, _, c), col in zip(curves, colors):
            (ln,) = ax.plot(c["speed"].values, c[name].values, color=col, label=label)
            if k == 0:
                handles.append(ln)
        ax.set_xlabel(r"incident speed $v$ [m/s]")
        ax.set_ylabel(meta[name][0])
        _panel_label(ax, f"({'abc'[k]}) " + meta[name][0].split(" ")[0] + ", " + meta[name][1])
        _speed_axis(ax, ds)
        _mark_capture(ax, v_caps, colors)
        if name == "e_n":
            ax.set_ylim(bottom=0.0)
    extra = [Patch(color=CAPTURE_SHADE, label="capture range")]
    _legend(fig, axes[-1], handles if hue else [], hue, extra)
    case = ds.attrs.get("case", "")
    fig_no = TABLE2_FIGURES.get(case, (None, None))[1]
    fixed = _fixed_text(ds, hue)
    names = {"e_n": "e_n, Eq. (21)", "mu_t": "mu_t, Eq. (22)", "mu_tp": "mu_t', Eq. (23)"}
    dropped = [names[k] for k in ("mu_t", "mu_tp") if k not in panels]
    caption = (
        f"{_title(ds, 'Restitution coefficient and tangential impulse ratios', fig_no)}. "
        + ", ".join(f"({'abc'[i]}) {names[p]}" for i, p in enumerate(panels))
        + " against the incident speed v [m/s]"
        + (f", one curve per value of {_HUE_TEXT.get(hue, hue)}" if hue else "")
        + (f"; {fixed}" if fixed else "") + ". e_n = 0 for a captured sphere; the impulse ratios are "
        "undefined there (no rebound) and are left out (gaps), as in the paper. "
        + (f"{' and '.join(dropped)} is zero throughout and not shown. " if dropped and len(panels) < 3 else "")
        + _caption_capture(ds, v_caps) + (f"Contact: {_contact_text(ds)}." if _contact_text(ds) else "")
    )
    return Plot(fig, caption.strip(), fig_no)


# ----------------------------------------------------------------------------- sizes of a measured material
def _normal_incidence(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` at the grid value closest to 0 of every dimension besides radius and speed."""
    sel = {d: int(np.argmin(np.abs(np.asarray(ds[d].values, float)))) for d in ds["e_n"].dims
           if d not in ("radius", "speed")}
    return ds.isel(sel)


@_rc
def plot_size_dependence(sweep: xr.Dataset, dynamics: xr.Dataset | None = None) -> Plot:
    """e_n against the incident speed for each sphere size, and the capture velocity against the size.

    Parameters
    ----------
    sweep : xarray.Dataset
        A sweep with a leading ``radius`` dimension [m] (one fitted contact per radius), a
        ``speed`` dimension [m/s] and ``e_n``, ``outcome``; other dimensions are taken at their grid
        value closest to 0 (normal incidence, no spin).
    dynamics : xarray.Dataset, optional
        ``capture_velocity`` and ``critical_velocity`` [m/s] on ``radius`` [m]; without it panel (b)
        shows the sweep's ``capture_normal_speed`` if it has one per radius.

    Returns
    -------
    Plot
        (a) e_n(v), one curve per diameter, captured impacts (e_n = 0) dotted; (b) normal capture
        velocity (and the critical velocity of Eq. (38)) against the diameter, log-log.

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("two.csv", radii=(1.72e-6, 3.45e-6), n_per_radius=4, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False).to_dataset()
    >>> from microimpact.studies.material import material_dynamics, material_sweep
    >>> from microimpact.studies.sweeps import case_spec
    >>> spec = case_spec("2.1", {"speed": {"start": 1, "stop": 2, "num": 3}, "incidence_deg": [0.0]})
    >>> plot = plot_size_dependence(material_sweep(fit, spec, case="2.1"), material_dynamics(fit))
    >>> len(plot.figure.axes), plot.caption.split(".")[0]
    (2, 'The measured material at each measured sphere size, with the contact fitted to the data')
    """
    ds = _normal_incidence(sweep)
    radii = np.asarray(ds["radius"].values, float)
    colors = _colors(radii.size)
    fig = _figure(WIDTH, 2.6)
    ax_e, ax_v = fig.subplots(1, 2)
    for i, (r, col) in enumerate(zip(radii, colors)):
        c = ds.isel(radius=i)
        cap = c["outcome"].values.astype(bool)
        y = c["e_n"].values
        ax_e.plot(c["speed"].values, np.where(cap, np.nan, y), color=col, label=f"{2e6 * r:.3g}")
        ax_e.plot(c["speed"].values, np.where(cap, y, np.nan), color=col, ls=":", lw=1.0)
    ax_e.set_xscale("log")
    ax_e.set_xlabel(r"incident speed $v$ [m/s]")
    ax_e.set_ylabel(r"$e_n$ [-]")
    ax_e.set_ylim(bottom=0.0)
    _panel_label(ax_e, "(a) $e_n$, Eq. (21)")
    ax_e.legend(title="d [µm]", frameon=False, loc="lower right")
    fixed = ", ".join(f"{d} = {float(ds[d]):g}" for d in sweep["e_n"].dims if d not in ("radius", "speed"))
    lines = []
    if dynamics is not None:
        lines = [(dynamics[k], label, m) for k, label, m in (("capture_velocity", "capture $v_{capture}$", "o"),
                                                             ("critical_velocity", "critical $v_c$, Eq. (38)", "s"))
                 if k in dynamics]
    elif "capture_normal_speed" in sweep and "radius" in sweep["capture_normal_speed"].dims:
        lines = [(sweep["capture_normal_speed"], "capture velocity", "o")]
    # a non-adhesive pair (f0 = 0) captures nothing: its capture velocity is 0 and v_c undefined,
    # which a log axis cannot show; the panel says so instead of staying empty
    lines = [(var, label, m) for var, label, m in lines if np.any(np.asarray(var.values, float) > 0)]
    for var, label, marker in lines:
        v = np.asarray(var.values, float)
        ax_v.plot(2e6 * np.asarray(var["radius"].values, float), np.where(v > 0, v, np.nan), marker=marker, ms=4,
                  label=label)
    ax_v.set_xscale("log")
    if lines:
        ax_v.set_yscale("log")
    else:
        ax_v.set_xlim(2e6 * radii.min() / 1.5, 2e6 * radii.max() * 1.5)
        ax_v.set_yticks([])
        ax_v.text(0.5, 0.5, "no capture at any speed\n(no adhesion: f0 = 0)" if dynamics is not None
                  else "no capture velocity\nin the input", transform=ax_v.transAxes, ha="center", va="center")
    for axis in (ax_v.xaxis, ax_v.yaxis, ax_e.xaxis) if lines else (ax_v.xaxis, ax_e.xaxis):
        _plain_log_labels(axis)
    ax_v.set_xlabel(r"sphere diameter $d$ [µm]")
    ax_v.set_ylabel(r"normal speed [m/s]")
    _panel_label(ax_v, "(b) capture velocity")
    if lines:
        ax_v.legend(frameon=False)
    case = sweep.attrs.get("case", "")
    caption = (
        "The measured material at each measured sphere size, with the contact fitted to the data. "
        f"(a) Normal restitution e_n against the incident speed v [m/s]{f' (Table 2 case {case}' if case else ' ('}"
        f"{', ' + fixed if fixed else ''}), one curve per diameter; dotted: captured (e_n = 0). "
        "(b) Normal capture velocity v_capture [m/s] (below it the sphere adheres)"
        + (" and critical velocity v_c of Eq. (38) (C = 2)" if dynamics is not None and "critical_velocity" in dynamics
           else "") + " against the diameter [um]."
        + ("" if lines else " No capture velocity to draw: every impact rebounds." if dynamics is not None
           else " (No capture velocities in the input.)")
    )
    return Plot(fig, caption, None)


# ----------------------------------------------------------------------------- Fig. 5
@_rc
def plot_phase_portraits(portraits) -> Plot:
    """Phase portraits of normal impacts (Fig. 5), one panel per trajectory.

    Parameters
    ----------
    portraits : sequence of xarray.Dataset
        From :func:`microimpact.dynamics.nonlinear.phase_portrait`: coordinate ``time`` [s], variables
        ``penetration`` x = -n [m] and ``penetration_rate`` dx/dt [m/s]; attributes
        ``normal_speed`` [m/s], ``outcome``, ``motion_type`` and, if present, ``length_scale`` X
        (the equilibrium penetration) [m], ``asymptotic_frequency`` [rad/s].

    Returns
    -------
    Plot
        Penetration rate against penetration, in the paper's sign convention n = -x (n < 0 in
        contact, dn/dt < 0 on approach). Circle: start; square: end; cross: equilibrium n_e = -X.

    Examples
    --------
    >>> from microimpact.dynamics.nonlinear import phase_portraits
    >>> from microimpact.presets import WALL_1990
    >>> plot = plot_phase_portraits(phase_portraits(WALL_1990, [1.0, 2.0]))
    >>> len(plot.figure.axes), plot.caption.split(":")[0]
    (2, 'Phase portraits of normal impacts (analogue of Fig. 5)')
    """
    portraits = list(portraits)
    if not portraits:
        raise ValueError("plot_phase_portraits: no portraits given")
    n = len(portraits)
    fig = _figure(min(WIDTH, 2.45 * n + 0.3), 2.9)
    axes = np.atleast_1d(fig.subplots(1, n))
    parts = []
    for k, (ax, p) in enumerate(zip(axes, portraits)):
        for name in ("penetration", "penetration_rate"):
            if name not in p:
                raise ValueError(f"portrait {k} lacks variable {name!r} (expected dynamics.phase_portrait output)")
        x = np.asarray(p["penetration"].values, float)
        xd = np.asarray(p["penetration_rate"].values, float)
        n_nm = -x * 1e9
        v0 = float(p.attrs.get("normal_speed", abs(xd[0]) if xd.size else math.nan))
        rate_scale, rate_unit = (1.0, "m/s") if np.nanmax(np.abs(xd)) >= 1e-2 else (1e6, r"$\mu$m/s")
        nd = -xd * rate_scale
        ax.plot(n_nm, nd, color="C0", lw=0.9)
        ax.plot(n_nm[:1], nd[:1], "o", color="C2", ms=4, label="start")
        ax.plot(n_nm[-1:], nd[-1:], "s", color="C3", ms=4, label="end")
        if "length_scale" in p.attrs:
            ax.plot([-float(p.attrs["length_scale"]) * 1e9], [0.0], "x", color="k", ms=6, mew=1.3,
                    label="equilibrium $n_e$")
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.axvline(0.0, color="0.6", lw=0.6)
        ax.set_xlabel(r"normal displacement $n$ [nm]")
        ax.set_ylabel(rf"normal velocity $\dot n$ [{rate_unit}]")
        motion = str(p.attrs.get("motion_type", p.attrs.get("outcome", "")))
        _panel_label(ax, f"({'abcdefgh'[k % 8]}) " + rf"$v_n(0)$ = {_fmt_value(v0)} m/s")
        ax.text(0.97, 0.04, motion, transform=ax.transAxes, ha="right", va="bottom", fontsize=7.5,
                bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="0.7", lw=0.5))
        freq = p.attrs.get("asymptotic_frequency")
        txt = f"({'abcdefgh'[k % 8]}) v_n(0) = {v0:g} m/s: {motion}"
        if freq is not None and float(freq) > 0 and p.attrs.get("outcome") == "capture":
            txt += f", asymptotic angular frequency {float(freq):.3g} rad/s"
        parts.append(txt)
    handles, texts = axes[0].get_legend_handles_labels()  # below the panels: inside, it covered the trajectory
    fig.legend(handles, texts, loc="outside lower center", ncol=len(texts), frameon=False, fontsize=7)
    caption = (
        "Phase portraits of normal impacts (analogue of Fig. 5): normal velocity dn/dt against normal "
        "displacement n = -x of the sphere centre (n < 0 in contact), from first contact until the "
        "sphere leaves or settles. " + "; ".join(parts) + ". Cross: static equilibrium n_e = -X."
    )
    return Plot(fig, caption, "5")


# ----------------------------------------------------------------------------- Fig. 4
@_rc
def plot_bifurcation_plane(ds: xr.Dataset, *, label_points: bool = True) -> Plot:
    """The (C1, C2) parameter plane with the bifurcation line C = 2 (Fig. 4).

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`microimpact.dynamics.nonlinear.bifurcation_plane`: coordinates ``C1``, ``C2``; variables
        ``region`` (C1, C2) with 0 spiral sink / 1 critical / 2 sink, ``critical_line_C2`` (C1)
        and, per ``case`` (label coordinate), ``case_C1``, ``case_C2``, ``case_speed`` [m/s].
    label_points : bool
        Number the points and list the labels in the legend.

    Examples
    --------
    >>> from microimpact.dynamics.nonlinear import bifurcation_plane
    >>> plot = plot_bifurcation_plane(bifurcation_plane(n_c1=21, n_c2=21))
    >>> plot.caption.startswith("Bifurcation on the (C1, C2) parameter plane (analogue of Fig. 4)")
    True
    """
    c1 = np.asarray(ds["C1"].values, float)
    c2 = np.asarray(ds["C2"].values, float)
    fig = _figure(WIDTH * 0.8, 3.5)
    ax = fig.subplots()
    # C1 on a log axis: the paper's points sit at C1 ~ 1e-3 - 1e-1, which a linear axis to C1 = 6
    # piles against C1 = 0. The regions follow from C = C1 + C2 alone, drawn on either side of the
    # exact line C2 = 2 - C1 (the grid's cells would show as a staircase)
    pts = np.asarray(ds["case_C1"].values, float) if "case_C1" in ds else np.array([])
    positive = np.concatenate([c1[c1 > 0], pts[pts > 0]])
    lo = 10.0 ** math.floor(math.log10(positive.min() / 2.0)) if positive.size else 1e-3
    hi = max(float(c1.max()), 2.5)
    x = np.geomspace(lo, hi, 400)
    top = max(float(c2.max()), 2.5)
    line = np.clip(2.0 - x, 0.0, top)
    ax.fill_between(x, 0.0, line, color="#dbe9f6", lw=0, zorder=0)
    ax.fill_between(x, line, top, color="#fbe3c9", lw=0, zorder=0)
    ok = x < 2.0
    ax.plot(x[ok], line[ok], color="k", lw=1.5)
    ax.set_xscale("log")
    ax.text(0.55, 0.3, "C < 2: spiral sink", transform=ax.transAxes, ha="center", va="center", fontsize=7)
    ax.text(0.97, 0.94, "C > 2: sink (no oscillation)", transform=ax.transAxes, ha="right", va="top", fontsize=7)
    handles = []
    if "case" in ds.dims:
        speeds = ds["case_speed"].values if "case_speed" in ds else np.full(ds.sizes["case"], np.nan)
        labels = [str(x) for x in ds["case"].values]
        uniq = sorted(set(np.round(speeds, 12)))
        cols = dict(zip(uniq, _colors(len(uniq))))
        markers = "ovsD^<>p*h"
        groups = {}
        for i, lab in enumerate(labels):
            groups.setdefault(lab.split(", v=")[0], []).append(i)
        for g_idx, (group, idx) in enumerate(groups.items()):
            for i in idx:
                ax.plot(ds["case_C1"].values[i], ds["case_C2"].values[i], marker=markers[g_idx % len(markers)],
                        ls="none", color=cols[np.round(speeds[i], 12)], mec="k", mew=0.5, ms=6, zorder=4)
            handles.append(Line2D([], [], marker=markers[g_idx % len(markers)], ls="none", color="0.7",
                                  mec="k", mew=0.5, label=group))
        for v, col in cols.items():
            handles.append(Line2D([], [], marker="o", ls="none", color=col, mec="k", mew=0.5,
                                  label=f"v_n = {_fmt_value(v)} m/s"))
    ax.set_xlabel(r"$C_1 = C_H X/T$, Eq. (31) [-]")
    ax.set_ylabel(r"$C_2 = C_A X/T$, Eq. (32) [-]")
    ax.set_xlim(lo, hi)
    ax.set_ylim(0.0, top)
    ax.grid(False)
    ax.legend(handles=[Line2D([], [], color="k", lw=1.5, label="C = 2")] + handles, loc="upper left",
              bbox_to_anchor=(1.02, 1.0), frameon=False, fontsize=7)
    caption = (
        "Bifurcation on the (C1, C2) parameter plane (analogue of Fig. 4). The equilibrium (1, 0) of Eq. (33) "
        "is a spiral sink for C = C1 + C2 < 2 (blue) and a sink for C > 2 (orange); the line C = 2 is critical. "
        "C1 on a log axis (the parameter sets have C1 << C2). "
        "Points: parameter sets (marker) at normal impact speeds (colour); C1, C2 vary as v_n^(-1/5) when "
        "the damping reference speed is each impact's own normal speed, Eqs. (14)-(15)."
    )
    return Plot(fig, caption, "4")


# ----------------------------------------------------------------------------- Fig. 3
@_rc
def plot_fit(fit: xr.Dataset, curves: xr.Dataset | None = None) -> Plot:
    """Measured e_n with error bars per sphere size and the fitted model (Fig. 3).

    Parameters
    ----------
    fit : xarray.Dataset
        :meth:`microimpact.analysis.fitting.DampingFit.to_dataset`: along ``point``, ``radius`` [m],
        ``normal_speed`` [m/s], ``e_n_measured``, ``sigma`` (1-sigma, drawn as error bars) and
        ``e_n_model``; scalar ``zeta_hertz``, ``zeta_adhesion``, ``work_of_adhesion`` [J/m^2].
    curves : xarray.Dataset, optional
        Smooth model lines from :func:`microimpact.studies.sweeps.restitution_curves` (``e_n`` on
        ``radius`` x ``speed``). Without it the model is drawn at the data points, joined.

    Examples
    --------
    A fit of eight synthetic impacts of two sizes, with its model curves:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("two.csv", radii=(1.72e-6, 3.45e-6), n_per_radius=4, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False).to_dataset()
    >>> from microimpact.studies.sweeps import restitution_curves
    >>> plot = plot_fit(fit, restitution_curves(fit, [1.0, 2.0, 5.0]))
    >>> len(plot.figure.axes), plot.caption.split(" (")[0]
    (2, 'Normal restitution coefficient e_n against incident normal speed [m/s]')
    """
    fig = _figure(WIDTH * 0.72, 4.2)
    ax, res_ax = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": (3, 1)})
    radius = fit["radius"].values
    classes = np.unique(np.round(radius, 12))
    cols = _colors(len(classes))
    handles = []
    for r, col in zip(classes, cols):
        sel = np.isclose(radius, r, rtol=1e-9, atol=0)
        v = fit["normal_speed"].values[sel]
        ax.errorbar(v, fit["e_n_measured"].values[sel], yerr=fit["sigma"].values[sel], fmt="o", ms=3.2, color=col,
                    ecolor=col, elinewidth=0.7, capsize=1.5, alpha=0.85, lw=0)
        if curves is not None:
            j = int(np.argmin(np.abs(curves["radius"].values - r)))
            ax.plot(curves["speed"].values, curves["e_n"].isel(radius=j).values, color=col, lw=1.3)
        else:
            order = np.argsort(v)
            ax.plot(v[order], fit["e_n_model"].values[sel][order], color=col, lw=1.3)
        handles.append(Line2D([], [], color=col, marker="o", ms=3.2, label=f"d = {2 * r * 1e6:.3g} µm"))
        if "residual" in fit:
            res_ax.plot(v, fit["residual"].values[sel], "o", ms=2.6, color=col, alpha=0.85)
    ax.set_xscale("log")
    ax.set_xlabel(r"incident normal speed $v_n$ [m/s]", fontsize=7)
    res_ax.axhspan(-2.0, 2.0, color="0.92", zorder=0)
    res_ax.axhline(0.0, color="0.4", lw=0.8)
    res_ax.set_xlabel(r"incident normal speed $v_n$ [m/s]")
    res_ax.set_ylabel("(model - data)/σ [-]", fontsize=7)
    ax.set_ylabel(r"$e_n$ [-]")
    ax.set_ylim(bottom=0.0)
    handles += [Line2D([], [], color="0.3", marker="o", ls="none", ms=3.2, label="data $\\pm 1\\sigma$"),
                Line2D([], [], color="0.3", label="model, best fit")]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)

    def par(name, fmt):
        val = float(fit[name])
        err = float(fit[f"{name}_stderr"]) if f"{name}_stderr" in fit else math.nan
        st = status_from_variables(fit, name, val)
        if st is not None and not st.determined:  # no number for what the data do not determine
            return {"lower_bound": f">= {st.lower:{fmt}}", "upper_bound": f"<= {st.upper:{fmt}}"}.get(
                st.status, "not determined") + f" (curve drawn at {val:{fmt}})"
        varied = (bool(int(fit[name].attrs["varied"])) if "varied" in fit[name].attrs
                  else name in str(fit.attrs["varied"]).split() if "varied" in fit.attrs else None)
        if varied is False:  # read from the file, never guessed from a missing standard error
            return f"{val:{fmt}} (fixed, materials config)"
        if varied is None and not math.isfinite(err):
            return f"{val:{fmt}} (the file does not record whether it was fitted)"
        if st is not None and math.isfinite(st.lower) and math.isfinite(st.upper):
            return f"{val:{fmt}}, 95 % [{st.lower:{fmt}}, {st.upper:{fmt}}]"
        return f"{val:{fmt}} (fitted)"

    verdict = read_verdict(fit)
    ax.set_title(f"model {verdict.label}", fontsize=7, loc="left",
                 color="#b00000" if verdict.rejected else "0.2", wrap=True)
    source = str(fit.attrs.get("fit_source", "")) or "the data set"
    synthetic = "synthetic" in json.dumps({k: str(v) for k, v in fit.attrs.items()}).lower()
    caption = (
        "Normal restitution coefficient e_n against incident normal speed [m/s] (analogue of Fig. 3): "
        f"measured points with 1-sigma error bars ({source}{', SYNTHETIC data' if synthetic else ''}) "
        "per sphere diameter, and the model at the best fit"
        f" (zeta_H = {par('zeta_hertz', '.3g')}, zeta_A = {par('zeta_adhesion', '.3g')}, "
        f"w_A = {par('work_of_adhesion', '.3g')} J/m^2; reduced chi-square {float(fit.attrs.get('redchi', math.nan)):.3g}). "
        "Lower panel: residuals (model - measured) / sigma per point, the grey band +/- 2. "
        f"Verdict: {verdict.label}."
        + (f" Outliers (by id): {', '.join(verdict.outlier_ids)}." if verdict.outlier_ids else "")
    )
    return Plot(fig, caption, "3")


# ----------------------------------------------------------------------------- benchmark
@_rc
def plot_work_precision(ds: xr.Dataset) -> Plot:
    """Work-precision diagram: maximum error against computing time per impact, one line per method.

    Parameters
    ----------
    ds : xarray.Dataset
        Dimensions ``method`` (labels) and ``setting`` (e.g. tolerance levels); variables
        ``time_per_impact`` [s], ``max_error_e_n`` [-] and ``max_error_mu`` [-] on (method, setting).
        Non-positive or missing values are left out (log axes).

    Examples
    --------
    Two error variables give two panels with log axes.

    >>> import xarray as xr
    >>> ds = xr.Dataset(
    ...     {k: (("method", "setting"), [[1e-3, 1e-2], [2e-3, 2e-2]])
    ...      for k in ("time_per_impact", "max_error_e_n", "max_error_mu")},
    ...     coords={"method": ["a", "b"], "setting": [1e-6, 1e-8]})
    >>> p = plot_work_precision(ds)
    >>> len(p.figure.axes), p.figure.axes[0].get_xlabel(), p.figure.axes[0].get_yscale()
    (2, 'time per impact [s]', 'log')
    """
    errors = [k for k in ("max_error_e_n", "max_error_mu") if k in ds]
    if "time_per_impact" not in ds or not errors:
        raise ValueError("plot_work_precision needs time_per_impact and max_error_e_n and/or max_error_mu")
    fig = _figure(WIDTH if len(errors) == 2 else WIDTH * 0.6, 2.8)
    axes = np.atleast_1d(fig.subplots(1, len(errors), sharey=False))
    methods = [str(m) for m in ds["method"].values]
    markers = "osD^v<>ph*"
    colors = [colormaps["tab10"](i % 10) for i in range(len(methods))]
    ylabels = {"max_error_e_n": r"max. error of $e_n$ [-]", "max_error_mu": r"max. error of $\mu$ [-]"}
    for k, (ax, name) in enumerate(zip(axes, errors)):
        for i, m in enumerate(methods):
            t = np.asarray(ds["time_per_impact"].isel(method=i).values, float).ravel()
            e = np.asarray(ds[name].isel(method=i).values, float).ravel()
            ok = np.isfinite(t) & np.isfinite(e) & (t > 0) & (e > 0)
            order = np.argsort(t[ok])
            ax.plot(t[ok][order], e[ok][order], marker=markers[i % len(markers)], ms=4, color=colors[i], label=m)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("time per impact [s]")
        ax.set_ylabel(ylabels[name])
        _panel_label(ax, f"({'ab'[k]}) " + ylabels[name].split(" [")[0])
    axes[-1].legend(title="method", loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    caption = (
        "Work-precision diagram: largest error against computing time per impact [s], log-log, one line per "
        "method, points along the solver settings (" + ", ".join(str(s) for s in ds["setting"].values) + "). "
        "Lower left is better."
    )
    return Plot(fig, caption, None)


# ----------------------------------------------------------------------------- Kharaz et al. (2001)
#: the other readings of the hysteretic law drawn in the Kharaz figure (tangential restitution
#: panel): reading -> (line style, legend text); the table in the report has all of them
_KHARAZ_READINGS = {"rescaled_displacement": (":", "k = 2/3"), "force": ("-.", "k = 0 (force kept)")}


@_rc
def plot_kharaz(ds: xr.Dataset) -> Plot:
    """Model against the oblique-impact measurements of Kharaz et al. (2001).

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`microimpact.analysis.kharaz.kharaz_comparison`: model curves ``<q>_curve`` (and
        ``<q>_curve_fitted``, fitted friction, drawn dashed when present; ``<q>_curve_compliant``, the
        tangentially compliant model, drawn green, and ``<q>_curve_hysteretic``, the hysteretic one,
        drawn orange, when present) on ``curve_incidence_deg``; ``tangential_restitution_curve_md_<reading>``
        (other readings of the hysteretic law, thin orange, when present) on ``reading_incidence_deg``
        for q = ``tangential_restitution`` [1], ``rebound_spin`` [rad/s], ``rebound_angle`` [deg];
        measured ``<q>_measured`` at the angles ``<q>_incidence_deg``.

    Examples
    --------
    >>> from microimpact.analysis.kharaz import kharaz_comparison
    >>> plot = plot_kharaz(kharaz_comparison())
    >>> len(plot.figure.axes), plot.caption.split(":")[0]
    (3, 'Oblique impact of 5 mm alumina spheres on glass at 3.9 m/s')
    """
    names = [n for n in ("tangential_restitution", "rebound_spin", "rebound_angle") if f"{n}_curve" in ds]
    labels = {
        "tangential_restitution": r"$v_{t,out} / v_{t,in}$ [-]",
        "rebound_spin": r"rebound spin $|\omega|$ [rad/s]",
        "rebound_angle": r"rebound angle [deg]",
    }
    angles = ds["curve_incidence_deg"].values
    lim = float(np.max(angles))
    f = float(ds["friction"]) if "friction" in ds else None
    f_fit = float(ds["fitted_friction"]) if "fitted_friction" in ds else math.nan
    fig = _figure(WIDTH, 3.1)
    axes = np.atleast_1d(fig.subplots(1, len(names)))
    readings = []  # the other readings' lines, added to the legend
    for k, (ax, name) in enumerate(zip(axes, names)):
        ax.plot(angles, ds[f"{name}_curve"].values, color="C0",
                label="model" + (f", f = {f:.3g}" if f is not None else ""))
        if f"{name}_curve_fitted" in ds and math.isfinite(f_fit):
            ax.plot(angles, ds[f"{name}_curve_fitted"].values, color="C0", ls="--", lw=0.9,
                    label=f"model, fitted f = {f_fit:.3g}")
        if f"{name}_curve_compliant" in ds:
            ax.plot(angles, ds[f"{name}_curve_compliant"].values, color="C2", lw=1.1,
                    label="compliant (Mindlin)" + (f", f = {f:.3g}" if f is not None else ""))
        if f"{name}_curve_hysteretic" in ds:
            ax.plot(angles, ds[f"{name}_curve_hysteretic"].values, color="C1", lw=1.1,
                    label="hysteretic (Mindlin-Deresiewicz)" + (f", f = {f:.3g}" if f is not None else ""))
        readings += [ax.plot(ds["reading_incidence_deg"].values, ds[f"{name}_curve_md_{reading}"].values,
                            color="C1", lw=0.8, ls=style, label=f"hysteretic, {text}")[0]
                    for reading, (style, text) in _KHARAZ_READINGS.items()
                    if name == "tangential_restitution" and f"{name}_curve_md_{reading}" in ds]
        if f"{name}_measured" in ds:
            ax.plot(ds[f"{name}_incidence_deg"].values, ds[f"{name}_measured"].values, "o", ms=4,
                    color="C3", mfc="none", mew=1.0, label="Kharaz et al. (2001)")
        if name == "rebound_angle":
            ax.plot([0, lim], [0, lim], color="0.6", lw=0.7, ls="--", label="specular")
        ax.set_xlabel(r"incidence angle $\alpha$ [deg]")
        ax.set_ylabel(labels[name])
        _panel_label(ax, f"({'abc'[k]}) " + name.replace("_", " "))
        ax.set_xlim(0, lim)
    target = axes[names.index("rebound_angle") if "rebound_angle" in names else 0]
    handles, texts = target.get_legend_handles_labels()
    # one legend below the panels: inside a panel it covered the measured points
    fig.legend(handles + readings, texts + [line.get_label() for line in readings], frameon=False,
               loc="outside lower center", ncol=3)
    speed = ds.attrs.get("impact_speed")
    zeta = float(ds["zeta_hertz"]) if "zeta_hertz" in ds else None
    e_n = float(ds["e_n_model"]) if "e_n_model" in ds else None
    damping = ("" if zeta is None else ", no damping" if zeta == 0.0
               else f", e_n = {e_n:.3g}" if e_n is not None else "")
    caption = (
        "Oblique impact of 5 mm alumina spheres on glass"
        + (f" at {float(speed):g} m/s" if speed is not None else "")
        + ": tangential restitution, rebound spin and rebound angle against the incidence angle. Circles: "
        "measurements of Kharaz, Gorham & Salman (2001), doi:10.1016/S0032-5910(01)00283-2 (digitized); "
        "solid line: the model in its non-adhesive, tangentially rigid limit"
        + (f" (f = {f:g}{damping})" if f is not None else "")
        + ("; dashed: the same with the friction fitted above "
           f"{float(ds.attrs.get('sliding_threshold_deg', 30.0)):g} deg (f = {f_fit:.4g})"
           if any(f"{n}_curve_fitted" in ds for n in names) and math.isfinite(f_fit) else "")
        + ". Below about 30 deg the measurements show effects of tangential compliance that a rigid "
        "Coulomb contact does not have."
        + (" Thin orange lines: other readings of the hysteretic law at a turning point held by a falling "
           "load, T ~ F_lim^k (the solvers' law: k = 1)."
           if any(f"tangential_restitution_curve_md_{r}" in ds for r in _KHARAZ_READINGS) else "")
    )
    return Plot(fig, caption, None)


# ----------------------------------------------------------------------------- measurement flags
#: flag variable -> (marker colour, legend text); the letters are those of ``microimpact flags``
_FLAG_STYLE = {
    "rotation_sensitive": ("tab:red", "rotation-sensitive"),
    "angle_sensitive": ("tab:orange", "angle-sensitive"),
    "near_capture": ("tab:blue", "near capture"),
    "probably_spun": ("tab:purple", "probably spun"),
    "spin_unexplained": ("k", "unexplained"),
}
_FLAGS_REQUIRED = ("rotation_sensitive", "angle_sensitive", "near_capture")


@_rc
def plot_flags(ds: xr.Dataset, *, outliers=()) -> Plot:
    """The measured and the model e_n of each impact, with the model's range under unmeasured spin and angle error.

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`microimpact.analysis.flags.flag_measurements`: along ``impact``, ``e_n`` [1],
        ``e_n_min``, ``e_n_max`` [1] (range over spin and angle), ``capture_speed_ratio`` [1]
        (normal speed over the capture velocity) and the 0/1 flags ``rotation_sensitive``,
        ``angle_sensitive``, ``near_capture`` (``probably_spun``, ``spin_unexplained`` when present);
        the measured ``e_n_measured`` with ``e_n_uncertainty`` [1] and the row's ``id`` when present.
    outliers : sequence of str
        The ids of the rows the fit names as outliers, marked with a cross.

    Returns
    -------
    Plot
        e_n against the speed ratio (log axis): measured points with 1-sigma bars, the model's value
        and its range (grey bar), rings in the colour of each flag raised, labelled with the
        letters of ``microimpact flags``.

    Examples
    --------
    Six synthetic impacts, the first made at 1.1 times the capture velocity: it alone is flagged near
    capture (speed ratio below 1.5); a dataset without the flags variables is refused, naming them:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.flags import flag_measurements
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> flags = flag_measurements(table, fit_damping(table, material, confidence_intervals=False))
    >>> flags["near_capture"].values.tolist(), round(float(flags["capture_speed_ratio"][0]), 2)
    ([1, 0, 0, 0, 0, 0], 1.09)
    >>> plot = plot_flags(flags.assign(e_n_measured=("impact", table["e_n"].to_numpy())))
    >>> plot.caption.split("flags raised (")[1].split(";")[0]
    '0 R rotation-sensitive, 0 A angle-sensitive, 1 N near capture, 0 S probably spun, 0 U unexplained'
    >>> "measured e_n" in plot.caption
    True
    >>> plot_flags(flags.drop_vars(["e_n_min", "near_capture"]))
    Traceback (most recent call last):
    ...
    ValueError: plot_flags needs the variables e_n_min, near_capture of a flags file
    """
    missing = [k for k in ("e_n", "e_n_min", "e_n_max", "capture_speed_ratio", *_FLAGS_REQUIRED) if k not in ds]
    if missing:
        raise ValueError(f"plot_flags needs the variables {', '.join(missing)} of a flags file")
    fig = _figure(WIDTH * 0.8, 3.0)
    ax = fig.subplots()
    x = np.asarray(ds["capture_speed_ratio"].values, float)
    e = np.asarray(ds["e_n"].values, float)
    ax.vlines(x, ds["e_n_min"].values, ds["e_n_max"].values, color="0.6", lw=0.9)
    ax.plot(x, e, "_", ms=7.0, mew=1.3, color="0.25", label="model e_n (bar: range over\nspin and angle)")
    measured = "e_n_measured" in ds and np.isfinite(np.asarray(ds["e_n_measured"].values, float)).any()
    if measured:
        sig = np.asarray(ds["e_n_uncertainty"].values, float) if "e_n_uncertainty" in ds else np.zeros_like(x)
        ax.errorbar(x, ds["e_n_measured"].values, yerr=np.where(np.isfinite(sig), sig, 0.0), fmt="o", ms=2.8,
                    color="C0", ecolor="C0", elinewidth=0.6, capsize=1.2, lw=0, label="measured e_n ± 1σ")
    counts = []
    for k, (name, (color, text)) in enumerate((n, v) for n, v in _FLAG_STYLE.items() if n in ds):
        raised = np.asarray(ds[name].values, float) > 0
        letter = FLAG_LETTERS[name]
        counts.append(f"{int(raised.sum())} {letter} {text}")
        ax.plot(x[raised], e[raised], "o", ms=6.0 + 2.5 * k, mfc="none", mec=color, mew=1.0,
                label=f"{letter}: {text}")
    ids = [str(i) for i in ds["id"].values] if "id" in ds else []
    out = np.array([i in set(outliers) for i in ids], bool) if ids else np.zeros(x.size, bool)
    if out.any():
        y_out = np.asarray(ds["e_n_measured"].values, float)[out] if measured else e[out]
        ax.plot(x[out], y_out, "x", ms=7, mew=1.4, color="#b00000", label="outlier of the fit")
        for xi, yi, name in zip(x[out], y_out, np.asarray(ids)[out]):
            ax.annotate(name, (xi, yi), xytext=(4, 4), textcoords="offset points", fontsize=6.5, color="#b00000")
    ax.set_xscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())  # a short log range: label the decades only
    ax.set_xlabel(r"normal speed / capture velocity $v_n / v_{capture}$ [-]")
    ax.set_ylabel(r"$e_n$ [-]")
    ax.set_ylim(bottom=0.0)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    caption = (
        f"Measurement flags of {ds.sizes.get('impact', len(e))} impacts ({str(ds.attrs.get('source', '')) or 'the data'}): "
        + ("the measured e_n (dots, 1-sigma bars) and " if measured else "")
        + "the model's e_n at each measured impact against its normal speed over the capture velocity, with a bar "
        "from the lowest to the highest model e_n under unmeasured spin and the incidence-angle uncertainty; rings "
        f"mark the flags raised ({', '.join(counts)}; thresholds in the file's attributes)"
        + (f"; crosses: the {int(out.sum())} outlier(s) of the fit, labelled by id" if out.any() else "") + "."
    )
    return Plot(fig, caption)
