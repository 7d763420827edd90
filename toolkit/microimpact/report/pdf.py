"""The PDF report of the pipeline, and the few pipeline products that no other module makes.

:func:`build_report` assembles ``reports/report.pdf`` from the NetCDF/CSV results of the Snakemake
workflow (``Snakefile``, ``workflow/``): a title page with provenance, the damping fit (Fig. 3
analogue), the nonlinear analysis (Figs. 4 and 5), the Table 2 sweeps (Figs. 7-14), the
measurement flags, the Kharaz et al. (2001) validation, the work-precision benchmark, the
seeded stress sweep of the engine (:mod:`microimpact.studies.stress`), the reproduction table of the
paper's claims and the configuration. Figures come from
:mod:`microimpact.report.figures` (one :class:`~microimpact.report.figures.Plot` per figure, with its caption); this
module only lays them out on A4 pages with matplotlib's PdfPages (figures are embedded as 160 dpi
images, captions and tables as text so the PDF is searchable).

Also defined here: :func:`is_synthetic`, :func:`git_commit`, :func:`provenance` - what the title
page states. :func:`phase_portraits`, :func:`save_phase_portraits`, :func:`load_phase_portraits`
and :func:`dynamics_summary` live in :mod:`microimpact.dynamics.nonlinear` and are re-exported here.

Paper: Cheng, Brach & Dunn (2002), Aerosol Sci. Technol. 36:1081-1093, doi:10.1080/02786820290092221.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import subprocess
import textwrap
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from microimpact.dynamics.nonlinear import dynamics_summary, load_phase_portraits, phase_portraits, save_phase_portraits
from microimpact.model.contact import PAPER_REFERENCE

__all__ = [
    "build_report",
    "phase_portraits",
    "save_phase_portraits",
    "load_phase_portraits",
    "dynamics_summary",
    "is_synthetic",
    "git_commit",
    "provenance",
    "PAGE_SIZE",
]


#: A4 portrait, inches
PAGE_SIZE = (8.27, 11.69)
_MARGIN_X = 0.65  # in
_TOP = 0.75  # in, below the top edge: running header
_BOTTOM = 0.75  # in, above the bottom edge: footer
_TEXT_WIDTH = PAGE_SIZE[0] - 2 * _MARGIN_X
_DPI = 160  # embedded figures
_BODY_PT = 8.5
_TABLE_PT = 6.6


# =============================================================================== provenance
def is_synthetic(data_path, flag="auto") -> bool:
    """Whether a data file is synthetic: ``flag`` if it is a bool; for "auto", True when the file
    name contains "synthetic" (the bundled data/synthetic_microspheres.csv does)."""
    if isinstance(flag, bool):
        return flag
    if flag != "auto":
        raise ValueError(f"data_synthetic must be true, false or 'auto', got {flag!r}")
    return "synthetic" in Path(os.fspath(data_path)).name.lower()


def git_commit(directory=".") -> str | None:
    """``<commit>`` (``+ uncommitted changes`` when the tree is dirty) of the git checkout at
    ``directory``, or None when git or the repository is not available. Read-only."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=directory, capture_output=True, text=True,
                              timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=directory,
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return head + (" + uncommitted changes" if dirty else "") if head else None


def provenance(config: Mapping | None = None, *, data_path=None, data_table=None) -> dict[str, str]:
    """The facts of the title page, as label -> text."""
    from microimpact import __version__

    config = dict(config or {})
    data_path = data_path or config.get("data")
    synthetic = is_synthetic(data_path or "", config.get("data_synthetic", "auto")) if data_path else False
    out = {
        "toolkit": f"microimpact {__version__}",
        "created": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "git commit": git_commit() or "not available (not a git checkout)",
        "python": f"{platform.python_version()} on {platform.system()} {platform.machine()}",
        "data": f"{data_path}" + ("  -- SYNTHETIC data (generated, not measured)" if synthetic else "  -- measured data"),
    }
    if data_table is not None and len(data_table):
        t = data_table
        radii = np.unique(np.round(t["radius"].to_numpy(float) * 1e6, 4))
        v = t["normal_speed"].to_numpy(float)
        out["data content"] = (f"{len(t)} impacts, {len(radii)} radii ({', '.join(f'{r:g}' for r in radii)} um), "
                               f"normal speed {np.nanmin(v):.3g}-{np.nanmax(v):.3g} m/s")
        sha = t.attrs.get("sha256") if hasattr(t, "attrs") else None
        if sha:
            out["data sha256"] = sha
    if config:
        out["materials"] = f"{config.get('materials')} (pair {config.get('material_pair')})"
        sim = config.get("simulation", {})
        out["simulation contact"] = ", ".join(f"{k} = {v:g}" for k, v in sim.items() if isinstance(v, (int, float)))
        fit = config.get("fit", {})
        out["fit options"] = ", ".join(f"{k} = {v}" for k, v in fit.items()) or "defaults"
        sweeps = config.get("sweeps", {})
        out["sweeps"] = (f"Table 2 cases {', '.join(sweeps)}; {config.get('sweep_chunks', 1)} chunk(s) per case"
                         if sweeps else "none")
        bench = config.get("benchmark", {})
        out["benchmark"] = ("on" + (" (quick)" if bench.get("quick", True) else " (full)")) if bench.get("enabled") else "off"
        stress = config.get("stress")
        if stress is not None:
            out["stress sweep"] = (f"on ({stress.get('cases', '?')} cases, seed {stress.get('seed', '?')}"
                                   + (f", reference solver on every {stress['reference_every']}-th case"
                                      if stress.get("reference_every") else "") + ")"
                                   if stress.get("enabled") else "off")
    return out


# =============================================================================== page layout
def _wrap(text: str, width: int) -> list[str]:
    lines: list[str] = []
    for para in str(text).split("\n"):
        lines.extend(textwrap.wrap(para, width=width, break_long_words=True, break_on_hyphens=False) or [""])
    return lines


@dataclass
class _Page:
    figure: object
    section: str
    y: float  # inches from the top edge to the next free line


@dataclass
class _Layout:
    """Flows headings, figures, paragraphs and tables onto A4 pages (all figures kept until the end)."""

    title: str
    pages: list = field(default_factory=list)
    contents: list = field(default_factory=list)  # (section, page index)

    # ------------------------------------------------------------------ pages
    def new_page(self, section: str) -> _Page:
        from matplotlib.figure import Figure

        fig = Figure(figsize=PAGE_SIZE)
        page = _Page(fig, section, _TOP + 0.15)
        self.pages.append(page)
        return page

    @property
    def page(self) -> _Page:
        return self.pages[-1]

    def _room(self, height: float) -> bool:
        return self.page.y + height <= PAGE_SIZE[1] - _BOTTOM

    def ensure(self, height: float) -> _Page:
        if not self.pages or not self._room(height):
            self.new_page(self.pages[-1].section if self.pages else "")
        return self.page

    def _text(self, x_in: float, y_in: float, text: str, **kw):
        return self.page.figure.text(x_in / PAGE_SIZE[0], 1.0 - y_in / PAGE_SIZE[1], text, va="top", **kw)

    # ------------------------------------------------------------------ blocks
    def section(self, title: str, *, new_page: bool = True) -> None:
        if new_page or not self.pages:
            self.new_page(title)
        else:
            self.ensure(0.8)
            self.page.section = title
        self.contents.append((title, len(self.pages) - 1))
        self._text(_MARGIN_X, self.page.y, title, fontsize=13, fontweight="bold")
        self.page.y += 0.38

    def heading(self, text: str) -> None:
        self.ensure(0.9)
        self._text(_MARGIN_X, self.page.y, text, fontsize=10, fontweight="bold")
        self.page.y += 0.26

    def paragraph(self, text: str, *, size: float = _BODY_PT, mono: bool = False, gap: float = 0.1,
                  color: str = "black") -> None:
        chars = int(_TEXT_WIDTH * 72 / (size * (0.61 if mono else 0.53)))
        line_h = size * 1.32 / 72
        lines = _wrap(text, chars)
        while lines:
            self.ensure(line_h * min(len(lines), 2))
            fit = max(1, int((PAGE_SIZE[1] - _BOTTOM - self.page.y) / line_h))
            chunk, lines = lines[:fit], lines[fit:]
            self._text(_MARGIN_X, self.page.y, "\n".join(chunk), fontsize=size, linespacing=1.32,
                       family="monospace" if mono else "sans-serif", color=color)
            self.page.y += line_h * len(chunk)
        self.page.y += gap

    def plot(self, plot, *, max_height: float = 5.2) -> None:
        """A :class:`microimpact.report.figures.Plot`: the figure as an image, its caption below."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        fig = plot.figure
        w, h = fig.get_size_inches()
        scale = min(1.0, _TEXT_WIDTH / w, max_height / h)
        ww, hh = w * scale, h * scale
        cap_lines = len(_wrap(plot.caption, int(_TEXT_WIDTH * 72 / (_BODY_PT * 0.53))))
        self.ensure(hh + 0.1 + cap_lines * _BODY_PT * 1.32 / 72)
        canvas = FigureCanvasAgg(fig)
        fig.set_dpi(_DPI)
        canvas.draw()
        img = np.asarray(canvas.buffer_rgba())
        x0 = _MARGIN_X + (_TEXT_WIDTH - ww) / 2
        ax = self.page.figure.add_axes([x0 / PAGE_SIZE[0], 1.0 - (self.page.y + hh) / PAGE_SIZE[1],
                                        ww / PAGE_SIZE[0], hh / PAGE_SIZE[1]])
        ax.imshow(img, interpolation="none", aspect="auto")
        ax.set_axis_off()
        self.page.y += hh + 0.08
        label = f"Figure (analogue of the paper's Fig. {plot.paper_figure}). " if plot.paper_figure else "Figure. "
        self.paragraph(label + plot.caption, gap=0.22)

    def table(self, df: pd.DataFrame, widths: Mapping[str, int], *, headers: Mapping[str, str] | None = None,
              size: float = _TABLE_PT, caption: str | None = None) -> None:
        """A table as monospaced text with wrapped cells, paginated with the header repeated.

        ``widths`` gives the columns to show and their width in characters.
        """
        headers = dict(headers or {})
        cols = [c for c in widths if c in df.columns]
        line_h = size * 1.3 / 72
        char_w = size * 0.602 / 72  # DejaVu Sans Mono advance width
        total = sum(widths[c] for c in cols) + 2 * (len(cols) - 1)
        scale_size = size if total * char_w <= _TEXT_WIDTH else size * _TEXT_WIDTH / (total * char_w)
        line_h = scale_size * 1.3 / 72

        def fmt_row(cells: list[list[str]]) -> list[str]:
            n = max(len(c) for c in cells)
            return ["  ".join((c[i] if i < len(c) else "").ljust(widths[col]) for c, col in zip(cells, cols)).rstrip()
                    for i in range(n)]

        head = fmt_row([_wrap(headers.get(c, c), widths[c]) for c in cols])
        rule = "-" * total
        rows = []
        for _, r in df.iterrows():
            rows.append(fmt_row([_wrap(_cell(r[c]), widths[c]) for c in cols]))
        if caption:
            self.paragraph(caption)
        i = 0
        while i < len(rows):
            self.ensure(line_h * (len(head) + 1 + len(rows[i])))
            avail = PAGE_SIZE[1] - _BOTTOM - self.page.y
            block = head + [rule]
            while i < len(rows) and (len(block) + len(rows[i])) * line_h <= avail:
                block += rows[i]
                i += 1
            if len(block) == len(head) + 1:  # a single row taller than a page: cut it
                block += rows[i][: max(1, int(avail / line_h) - len(block))]
                i += 1
            self._text(_MARGIN_X, self.page.y, "\n".join(block), fontsize=scale_size, family="monospace",
                       linespacing=1.3)
            self.page.y += line_h * len(block) + 0.15
            if i < len(rows):
                self.new_page(self.page.section)
                self._text(_MARGIN_X, self.page.y, f"{self.page.section} (continued)", fontsize=10, fontweight="bold")
                self.page.y += 0.26

    # ------------------------------------------------------------------ output
    def save(self, path, metadata: Mapping[str, str]) -> None:
        from matplotlib.backends.backend_pdf import PdfPages

        from microimpact.io.files import atomic_path

        n = len(self.pages)
        with atomic_path(path) as tmp:
            with PdfPages(tmp, metadata=dict(metadata)) as pdf:
                for k, page in enumerate(self.pages, start=1):
                    fig = page.figure
                    if k == 1:  # the title page carries no running header
                        fig.text(0.5, 0.4 / PAGE_SIZE[1], f"page {k} of {n}", fontsize=7, color="0.4", ha="center")
                        pdf.savefig(fig)
                        continue
                    fig.text(_MARGIN_X / PAGE_SIZE[0], 1.0 - 0.45 / PAGE_SIZE[1], self.title, fontsize=7, color="0.4",
                             va="bottom")
                    fig.text(1.0 - _MARGIN_X / PAGE_SIZE[0], 1.0 - 0.45 / PAGE_SIZE[1], page.section, fontsize=7,
                             color="0.4", va="bottom", ha="right")
                    fig.add_artist(_hline(fig, 1.0 - 0.5 / PAGE_SIZE[1]))
                    fig.text(0.5, 0.4 / PAGE_SIZE[1], f"page {k} of {n}", fontsize=7, color="0.4", ha="center")
                    pdf.savefig(fig)


def _hline(fig, y):
    from matplotlib.lines import Line2D

    x0, x1 = _MARGIN_X / PAGE_SIZE[0], 1 - _MARGIN_X / PAGE_SIZE[0]
    return Line2D([x0, x1], [y, y], transform=fig.transFigure, color="0.6", lw=0.5)


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (float, np.floating)):
        return "" if math.isnan(value) else f"{value:.4g}"
    return str(value)


# =============================================================================== inputs
def _dataset(obj) -> xr.Dataset:
    if isinstance(obj, xr.Dataset):
        return obj
    with xr.open_dataset(obj, engine="netcdf4", decode_timedelta=False) as ds:
        return ds.load()


def _frame(obj) -> pd.DataFrame:
    return obj if isinstance(obj, pd.DataFrame) else pd.read_csv(obj, keep_default_na=False, na_values=[""])


def _json(obj) -> dict:
    if isinstance(obj, Mapping):
        return dict(obj)
    with open(obj, encoding="utf-8") as f:
        return json.load(f)


def _as_list(obj) -> list:
    if obj is None:
        return []
    if isinstance(obj, (str, os.PathLike, xr.Dataset)):
        return [obj]
    return list(obj)


# =============================================================================== sections
def _fit_section(lay: _Layout, fit_ds: xr.Dataset, data_table: pd.DataFrame | None, synthetic: bool) -> None:
    from microimpact.report import figures as plots
    from microimpact.analysis.fitting import PARAMETER_NAMES

    lay.section("1. Damping fit (analogue of Fig. 3)")
    src = fit_ds.attrs.get("fit_source", "the data")
    lay.paragraph(
        f"zeta_H and zeta_A of Eqs. (14)-(15) fitted by weighted least squares to the measured normal "
        f"restitution e_n(v_n) of {src}"
        + (" -- SYNTHETIC data generated with known parameters, not a measurement" if synthetic else "")
        + ", jointly over all sphere sizes with one work of adhesion w_A (f0 per radius from Eq. (7)). "
        f"Weighting: {fit_ds.attrs.get('weighting', '?')}.")
    curves = None
    try:
        from microimpact.studies.sweeps import restitution_curves

        curves = restitution_curves(fit_ds)
    except (ImportError, ValueError) as exc:  # pragma: no cover - drawn at the data points instead
        lay.paragraph(f"(model curves not available: {exc}; the model is drawn at the data points)", color="0.4")
    lay.plot(plots.plot_fit(fit_ds, curves), max_height=4.0)

    rows = []
    for name in PARAMETER_NAMES:
        units = fit_ds[name].attrs.get("units", "")
        v = float(fit_ds[name])
        se = float(fit_ds[f"{name}_stderr"])
        varied = bool(int(fit_ds[name].attrs.get("varied", 1)))
        lim = fit_ds[f"{name}_confidence_limit"]
        levels = [int(s) for s in lim["sigma_level"].values]
        prof = dict(zip(levels, (float(x) for x in lim.values)))
        if not varied:
            rows.append({"parameter": name, "units": units, "value": f"{v:.6g}", "stderr": "fixed",
                         "ci1": "", "ci2": "", "method": "fixed (materials config)"})
            continue
        if all(math.isfinite(prof.get(k, math.nan)) for k in (-1, 1, -2, 2)):
            ci1, ci2, method = (prof[-1], prof[1]), (prof[-2], prof[2]), "profile likelihood (lmfit.conf_interval)"
        else:
            ci1, ci2, method = (v - se, v + se), (v - 2 * se, v + 2 * se), "covariance: value +/- k stderr"
        rows.append({"parameter": name, "units": units, "value": f"{v:.6g}", "stderr": f"{se:.3g}",
                     "ci1": f"[{ci1[0]:.5g}, {ci1[1]:.5g}]", "ci2": f"[{ci2[0]:.5g}, {ci2[1]:.5g}]", "method": method})
    lay.heading("Fitted parameters")
    lay.table(pd.DataFrame(rows), {"parameter": 17, "units": 6, "value": 10, "stderr": 9, "ci1": 20, "ci2": 20,
                                   "method": 34},
              headers={"ci1": "1-sigma interval", "ci2": "2-sigma interval", "stderr": "std. error"}, size=7.2)
    a = fit_ds.attrs
    corr = fit_ds["correlation"]
    names = [str(n) for n in corr["parameter"].values]
    varied = str(a.get("varied", "")).split()
    pairs = [f"{p}/{q} {float(corr.sel(parameter=p, parameter_b=q)):+.3f}"
             for i, p in enumerate(names) for q in names[i + 1:] if p in varied and q in varied]
    lay.paragraph(
        f"{int(a.get('n_points', 0))} points; chi-square {float(a.get('chisqr', math.nan)):.4g}, reduced chi-square "
        f"{float(a.get('redchi', math.nan)):.4g}; AIC {float(a.get('aic', math.nan)):.4g}, BIC {float(a.get('bic', math.nan)):.4g}; "
        f"correlations: {', '.join(pairs) or 'n/a'}. Material: density {float(a.get('density', math.nan)):g} kg/m^3, "
        f"K = {float(a.get('stiffness', math.nan)):.4g} Pa, damping reference speed: {a.get('damping_reference_speed', '?')}. "
        f"{a.get('fit_ci_message', '')}")
    if data_table is not None and len(data_table):
        t = data_table
        summary = (t.assign(diameter_um=np.round(2e6 * t["radius"], 3))
                   .groupby("diameter_um")
                   .agg(n=("normal_speed", "size"), v_min=("normal_speed", "min"), v_max=("normal_speed", "max"),
                        e_min=("e_n", "min"), e_max=("e_n", "max"))
                   .reset_index())
        for c in ("v_min", "v_max", "e_min", "e_max"):
            summary[c] = summary[c].map(lambda x: f"{x:.3g}")
        lay.heading("Data by sphere size (validated table, SI units)")
        lay.table(summary, {"diameter_um": 14, "n": 6, "v_min": 12, "v_max": 12, "e_min": 10, "e_max": 10},
                  headers={"diameter_um": "diameter [um]", "n": "impacts", "v_min": "min v_n [m/s]",
                           "v_max": "max v_n [m/s]", "e_min": "min e_n [-]", "e_max": "max e_n [-]"}, size=7.2)


def _dynamics_section(lay: _Layout, bif: xr.Dataset, portraits: list[xr.Dataset], dyn: xr.Dataset | None) -> None:
    from microimpact.report import figures as plots

    lay.section("2. Nonlinear dynamics of the normal contact (Figs. 4, 5)")
    if dyn is not None:
        lay.paragraph(
            f"Simulation contact: r = {dyn.attrs.get('contact_radius', math.nan) * 1e6:.3g} um, "
            f"f0 = {dyn.attrs.get('contact_adhesion_line_force', math.nan):.4g} N/m, "
            f"zeta_H = {dyn.attrs.get('contact_zeta_hertz', math.nan):.3g}, zeta_A = {dyn.attrs.get('contact_zeta_adhesion', math.nan):.3g}; "
            f"m = {float(dyn['mass']):.4g} kg, X = {float(dyn['length_scale']):.4g} m, T = {float(dyn['time_scale']):.4g} s. "
            f"Critical velocity v_c (C = 2, Eq. (38)) = {float(dyn['critical_velocity']):.4g} m/s; "
            f"normal capture velocity = {float(dyn['capture_velocity']):.4g} m/s.")
    lay.plot(plots.plot_bifurcation_plane(bif), max_height=4.2)
    if dyn is not None:
        df = pd.DataFrame({
            "speed": [f"{v:.3g}" for v in dyn["speed"].values],
            "C1": [f"{x:.4g}" for x in dyn["C1"].values],
            "C2": [f"{x:.4g}" for x in dyn["C2"].values],
            "C": [f"{x:.4g}" for x in dyn["C"].values],
            "type": [str(x) for x in dyn["equilibrium_type"].values],
            "omega_f": [f"{x:.4g}" if math.isfinite(x) and c < 2 else "none (C >= 2)"
                        for x, c in zip(dyn["asymptotic_frequency"].values, dyn["C"].values)],
        })
        lay.heading("Damping and equilibrium at the phase-portrait speeds")
        lay.table(df, {"speed": 14, "C1": 10, "C2": 10, "C": 10, "type": 14, "omega_f": 22},
                  headers={"speed": "v_n [m/s]", "C1": "C1 [-]", "C2": "C2 [-]", "C": "C [-]",
                           "type": "equilibrium", "omega_f": "omega_f [rad/s]"}, size=7.2)
    lay.section("3. Phase portraits (analogue of Fig. 5)")
    # at most two panels per figure: four side by side on a page width leave unreadable axes
    groups = [portraits] if len(portraits) <= 2 else [portraits[i:i + 2] for i in range(0, len(portraits), 2)]
    for group in groups:
        lay.plot(plots.plot_phase_portraits(group), max_height=4.0)


def _sweep_section(lay: _Layout, sweeps: list[xr.Dataset], number: int) -> None:
    from microimpact.report import figures as plots

    for k, ds in enumerate(sorted(sweeps, key=lambda d: str(d.attrs.get("case", "")))):
        case = str(ds.attrs.get("case", "?"))
        figs = plots.TABLE2_FIGURES.get(case, (None, None))
        nums = ", ".join(f for f in figs if f)
        lay.section(f"{number}.{k + 1} Table 2 case {case}" + (f" (Fig{'s' if ',' in nums else ''}. {nums})" if nums else ""),
                    new_page=k > 0)
        if ds.attrs.get("case_description"):
            lay.paragraph(str(ds.attrs["case_description"]) + ".")
        if figs[0] is not None:
            lay.plot(plots.plot_energy_loss(ds), max_height=3.6)
        lay.plot(plots.plot_restitution_and_impulse(ds), max_height=4.2)


def _flags_section(lay: _Layout, flags: pd.DataFrame, data: pd.DataFrame | None, number: int) -> None:
    lay.section(f"{number}. Measurement flags")
    if flags.empty:
        lay.paragraph("No impacts in the flags table.")
        return
    n = len(flags)
    count = {k: int(flags[k].sum()) if k in flags else 0 for k in ("rotation_sensitive", "angle_sensitive", "near_capture")}
    lay.paragraph(
        "Each measured impact simulated under the fitted model with plausible unmeasured initial spin (up to the "
        "rolling spin v/r, 3-D directions) and with the incidence angle moved by its uncertainty "
        "(microimpact.analysis.flags.flag_measurements). Flags: R = rotation-sensitive (an unmeasured spin changes "
        "mu or K_L by more than the threshold), A = angle-sensitive (the angle error changes e_n, mu or the "
        "outcome), C = near capture (normal speed below 1.5 x the capture velocity, where e_n is steep). "
        f"Of {n} impacts: {count['rotation_sensitive']} R, {count['angle_sensitive']} A, {count['near_capture']} C. "
        "Spreads are max - min over the samples; all columns are in results/flags.csv (and .nc).")

    def spread(q, over):
        lo, hi = f"{q}_min_{over}", f"{q}_max_{over}"
        return (flags[hi] - flags[lo]) if lo in flags and hi in flags else pd.Series(np.nan, index=flags.index)

    t = pd.DataFrame({"row": flags["row"]})
    if data is not None and "row" in data:
        d = data.set_index("row")
        t["d"] = flags["row"].map(2e6 * d["radius"]).map(lambda x: f"{x:.3g}")
        t["v_n"] = flags["row"].map(d["normal_speed"]).map(lambda x: f"{x:.3g}")
        t["alpha"] = flags["row"].map(d["incidence_deg"]).map(lambda x: f"{x:.3g}")
        t["e_meas"] = flags["row"].map(d["e_n"]).map(lambda x: f"{x:.3f}")
    t["e_n"] = flags.get("e_n", np.nan)
    t["ratio"] = flags.get("capture_speed_ratio", np.nan)
    t["mu_spin"] = np.fmax(spread("mu_t", "spin"), spread("mu_tp", "spin"))
    t["KL_spin"] = spread("K_L", "spin")
    t["e_angle"] = spread("e_n", "angle")
    t["mu_angle"] = np.fmax(spread("mu_t", "angle"), spread("mu_tp", "angle"))
    t["flags"] = ["".join(c for c, k in (("R", "rotation_sensitive"), ("A", "angle_sensitive"), ("C", "near_capture"))
                          if k in flags and int(r[k])) or "-" for _, r in flags.iterrows()]
    for c in ("e_n", "ratio", "mu_spin", "KL_spin", "e_angle", "mu_angle"):
        t[c] = t[c].map(lambda x: "" if not np.isfinite(x) else f"{x:.3g}")
    lay.table(t, {"row": 5, "d": 9, "v_n": 9, "alpha": 9, "e_meas": 9, "e_n": 9, "ratio": 9, "mu_spin": 9,
                  "KL_spin": 9, "e_angle": 9, "mu_angle": 9, "flags": 5},
              headers={"d": "d [um]", "v_n": "v_n [m/s]", "alpha": "alpha [deg]", "e_meas": "e_n meas.",
                       "e_n": "e_n model", "ratio": "v_n/v_cap", "mu_spin": "d mu spin", "KL_spin": "d K_L spin",
                       "e_angle": "d e_n angle", "mu_angle": "d mu angle"}, size=7.0)


def _kharaz_section(lay: _Layout, kh: xr.Dataset, number: int) -> None:
    from microimpact.report import figures as plots

    lay.section(f"{number}. Validation: oblique impacts of Kharaz et al. (2001)")
    lay.paragraph(
        "Real measurements (digitized): 5 mm alumina spheres on soda-lime glass at 3.9 m/s. They test the "
        "tangential/rotational part of the model in its non-adhesive limit; microsphere data with rotation "
        f"are not publicly available. {kh.attrs.get('conditions', '')}")
    lay.plot(plots.plot_kharaz(kh), max_height=3.2)
    if "friction" in kh and "fitted_friction" in kh:
        lay.paragraph(
            f"Friction: nominal {float(kh['friction']):.4g}; fitted to the tangential restitution above "
            f"{kh.attrs.get('sliding_threshold_deg', 30):g} deg: {float(kh['fitted_friction']):.4g} +/- "
            f"{float(kh.get('fitted_friction_stderr', np.nan)):.2g}. Model sliding/rolling transition at "
            f"{float(kh['transition_angle']):.3g} deg.")
    from microimpact.analysis.kharaz import kharaz_summary

    lay.heading("RMS model - measured")
    lay.table(kharaz_summary(kh), {"quantity": 24, "units": 8, "regime": 12, "rms_nominal_friction": 16,
                                 "rms_fitted_friction": 16},
              headers={"rms_nominal_friction": "nominal friction", "rms_fitted_friction": "fitted friction"},
              size=7.2)


def _benchmark_section(lay: _Layout, wp: xr.Dataset | None, number: int) -> None:
    from microimpact.report import figures as plots

    lay.section(f"{number}. Work-precision benchmark", new_page=True)
    if wp is None:
        lay.paragraph("The work-precision benchmark was switched off in the configuration (benchmark.enabled: "
                      "false); run with --config 'benchmark={enabled: true}' to include it.")
        return
    a = wp.attrs
    quick = str(a.get("quick", "")).lower() in ("1", "true")
    lay.paragraph(
        f"{str(a.get('title', 'Work-precision benchmark')).capitalize()} (microimpact.studies.benchmark"
        f"{', quick mode: small test set, few settings' if quick else ', full study'}) on the Table 1 row 2 contact: "
        f"{a.get('n_normal_speeds', '?')} normal impacts from just above the capture speed "
        f"({float(a.get('capture_speed', math.nan)):.4g} m/s) to 100 m/s and {a.get('n_oblique_cases', '?')} oblique "
        f"impacts. Reference: {a.get('reference', '?')}. Machine: {a.get('machine_processor', '?')}, "
        f"{a.get('machine_cpu_count', '?')} cores (1-min load average at start {float(a.get('machine_load_average_1min_at_start', math.nan)):.2g}); "
        f"the benchmark took {float(a.get('total_seconds', math.nan)):.3g} s.")
    lay.plot(plots.plot_work_precision(wp), max_height=3.6)
    rows = []
    for i, m in enumerate(wp["method"].values):
        err = np.asarray(wp["max_error_e_n"].isel(method=i).values, float)
        t = np.asarray(wp["time_per_impact"].isel(method=i).values, float)
        ok = np.isfinite(err) & np.isfinite(t)
        if not ok.any():
            continue
        j = int(np.argmin(np.where(ok, err, np.inf)))
        rows.append({"method": str(m), "err": f"{err[j]:.3g}", "time": f"{t[j]:.3g}",
                     "fast": f"{np.nanmin(np.where(ok, t, np.nan)):.3g}",
                     "timing": str(wp["timing_mode"].values[i]) if "timing_mode" in wp else ""})
    if rows:
        lay.heading("Most accurate setting of each method")
        lay.table(pd.DataFrame(rows), {"method": 13, "err": 12, "time": 14, "fast": 14, "timing": 60},
                  headers={"err": "max |e_n err|", "time": "time/impact [s]", "fast": "fastest [s]",
                           "timing": "how timed"}, size=7.0)
    ratio = a.get("ratio_dop853_to_engine_single")
    if ratio is not None:
        lay.paragraph(
            f"At the target error {float(a.get('target_error_e_n', math.nan)):.0e} in e_n: DOP853 / engine time ratio "
            f"{float(ratio):.3g} (single calls), {float(a.get('ratio_dop853_to_engine_batch', math.nan)):.3g} (batch); "
            f"target {float(a.get('target_ratio', math.nan)):g}. {a.get('target_ratio_note', '')}")


#: units and distribution of each input of the stress sweep (microimpact.studies.stress.draw_cases)
_STRESS_INPUTS = {
    "radius": ("r", "m", "log-uniform"),
    "speed": ("|v_i|", "m/s", "log-uniform"),
    "density": ("rho", "kg/m^3", "log-uniform"),
    "stiffness": ("K", "Pa", "log-uniform"),
    "work_of_adhesion": ("w_A", "J/m^2", "log-uniform, or exactly 0"),
    "zeta_hertz": ("zeta_H", "-", "log-uniform, or exactly 0"),
    "zeta_adhesion": ("zeta_A", "-", "log-uniform, or exactly 0"),
    "friction": ("f", "-", "uniform, or exactly 0"),
    "incidence_deg": ("alpha", "deg", "uniform, or exactly 0"),
    "azimuth_deg": ("theta", "deg", "uniform"),
    "spin_ratio": ("r omega_i / v", "-", "each component uniform in +/- max, or no spin"),
}

#: failed cases listed in the report (all of them are in results/stress_summary.json)
_STRESS_MAX_LISTED = 30


def _stress_section(lay: _Layout, s: Mapping | None, number: int, settings: Mapping | None) -> None:
    lay.section(f"{number}. Numerical stability (stress sweep)", new_page=True)
    settings = dict(settings or {})
    if s is None:
        if settings and not settings.get("enabled", True):
            lay.paragraph("The stress sweep was switched off in the configuration (stress.enabled: false); run "
                          "with --config 'stress={enabled: true}' to include it.")
        else:
            lay.paragraph("No stress-sweep summary was given to the report (results/stress_summary.json).")
        return
    from microimpact.studies.stress import ZERO_PROBABILITY

    n = int(s.get("cases_run", 0))
    tol = dict(s.get("tolerances", {}))
    by_kind = {k: int(v) for k, v in dict(s.get("failures_by_kind", {})).items()}
    n_ref = int(s.get("reference_cases", 0))
    every = settings.get("reference_every")
    limit = settings.get("case_time_limit")
    if n_ref:
        ref_text = (f"; {n_ref} cases" + (f" (every {every}-th)" if every else "")
                    + " also against the full 3-D reference solver (DOP853)")
    else:
        ref_text = "; the 3-D reference solver was not run (stress.reference_every: 0)"
    lay.paragraph(
        f"Seeded random stress sweep of the impact engine (microimpact.studies.stress.stress_sweep): {n} impacts drawn with "
        f"seed {s.get('seed', '?')} over the input ranges below, log-uniformly over decades where the range spans "
        f"several, with exact zeros (probability {ZERO_PROBABILITY:g}) where zero is allowed. Each impact is "
        "simulated at rtol 1e-10 and 1e-8 and checked: no exception (the engine's step limit is its time box), "
        "finite results, 0 <= e_n <= 1 (e_n = 0 for a capture), the energy balance KE_in = KE_out + contact "
        "energy + dissipated energy, and agreement of the two tolerances" + ref_text + ". Errors are relative to "
        "the case's energy scale max(KE_in, depth of the contact well), velocities to the matching speed scale "
        f"(microimpact.studies.stress docstring). {int(s.get('captures', 0))} of the {n} impacts were captured. The sweep took "
        f"{float(s.get('seconds', math.nan)):.3g} s (slowest case {float(s.get('slowest_case_seconds', math.nan)):.3g} s). "
        "Per-case inputs and results: results/stress.nc; summary with full-precision inputs: "
        "results/stress_summary.json; microimpact.studies.stress.draw_cases(n, seed) redraws the same cases.")
    n_failed = int(s.get("cases_failed", 0))
    if n_failed:
        kinds = ", ".join(f"{k} {v}" for k, v in by_kind.items() if v)
        lay.paragraph(f"Result: {n_failed} of {n} cases failed a check ({100 * n_failed / max(n, 1):.2g} %): {kinds}. "
                      "The failed cases are listed below; failures are reported, not hidden.", color="#b00000")
    else:
        lay.paragraph(f"Result: all {n} cases passed every check.")

    def worst(key):
        w = dict(s.get(key) or {})
        v = w.get("value")
        case = (w.get("case") or {}).get("case")
        return ("" if v is None else f"{float(v):.3g}"), ("" if case is None else str(case))

    def tol_text(key):
        return f"<= {float(tol[key]):.0e}" if key in tol else ""

    rows = [
        {"check": "exception raised (incl. step limit)", "tol": "none", "kind": "exception"},
        {"check": "non-finite result", "tol": "none", "kind": "nonfinite"},
        {"check": "e_n outside [0, 1], or != 0 for a capture", "tol": "none", "kind": "restitution"},
        {"check": "energy balance", "tol": tol_text("energy"), "key": "worst_energy_error", "kind": "energy"},
        {"check": "convergence: rtol 1e-8 vs 1e-10", "tol": tol_text("convergence"), "key": "worst_convergence_error",
         "kind": "convergence"},
        {"check": f"engine vs reference solver ({n_ref} cases)", "tol": tol_text("reference"),
         "key": "worst_reference_error", "kind": "reference"},
        {"check": "time per case [s]", "tol": f"<= {float(limit):g}" if limit is not None else "",
         "kind": "timeout"},
    ]
    for r in rows:
        r["worst"], r["case"] = worst(r["key"]) if "key" in r else ("", "")
        if r["kind"] == "timeout":
            r["worst"] = f"{float(s.get('slowest_case_seconds', math.nan)):.3g}"
        if r["kind"] == "reference" and not n_ref:
            r["worst"] = "not run"
        r["failed"] = str(by_kind.get(r["kind"], 0)) if (r["kind"] != "reference" or n_ref) else "-"
    lay.heading("Checks: worst value over all cases and number of failed cases")
    lay.table(pd.DataFrame(rows), {"check": 42, "tol": 12, "worst": 12, "case": 8, "failed": 8},
              headers={"tol": "tolerance", "worst": "worst", "case": "at case", "failed": "failed"}, size=7.2)

    ranges = dict(s.get("input_ranges", {}))
    if ranges:
        t = pd.DataFrame([{"input": name, "symbol": _STRESS_INPUTS.get(name, ("", "", ""))[0],
                           "units": _STRESS_INPUTS.get(name, ("", "", ""))[1],
                           "min": f"{float(lo):.3g}", "max": f"{float(hi):.3g}",
                           "drawn": _STRESS_INPUTS.get(name, ("", "", ""))[2]} for name, (lo, hi) in ranges.items()])
        lay.heading("Input ranges (SI units; angles in degrees)")
        lay.table(t, {"input": 18, "symbol": 14, "units": 8, "min": 9, "max": 9, "drawn": 46}, size=7.2)

    failed = list(s.get("failed_cases", []))
    if failed:
        shown = failed[:_STRESS_MAX_LISTED]
        cols = {"case": 6, "checks": 11, "radius": 8, "speed": 8, "incidence_deg": 6, "azimuth_deg": 6, "density": 8,
                "stiffness": 8, "work_of_adhesion": 8, "zeta_hertz": 8, "zeta_adhesion": 8, "friction": 6,
                "omega_n": 9, "omega_t": 9, "omega_tp": 9}
        t = []
        for item in shown:
            inputs = dict(item.get("inputs", {}))
            row = {"case": str(inputs.get("case", "")),
                   "checks": ", ".join(dict.fromkeys(f.get("kind", "?") for f in item.get("failures", [])))}
            for c in cols:
                if c not in row:
                    v = inputs.get(c)
                    row[c] = "" if v is None else f"{float(v) + 0.0:.3g}"  # + 0.0: no "-0"
            t.append(row)
        lay.heading(f"Failed cases ({len(failed)}" + (f", first {len(shown)} listed" if len(shown) < len(failed) else "")
                    + "): inputs, SI units")
        lay.table(pd.DataFrame(t), cols,
                  headers={"radius": "r [m]", "speed": "v [m/s]", "incidence_deg": "alpha", "azimuth_deg": "theta",
                           "density": "rho", "stiffness": "K [Pa]", "work_of_adhesion": "w_A", "zeta_hertz": "zeta_H",
                           "zeta_adhesion": "zeta_A", "friction": "f", "omega_n": "omega_n",
                           "omega_t": "omega_t", "omega_tp": "omega_t'"}, size=7.0)
        details = [f"case {dict(item.get('inputs', {})).get('case', '?')}: {f.get('kind', '?')}: {f.get('detail', '')}"
                   for item in shown for f in item.get("failures", [])]
        lay.paragraph("\n".join(details), mono=True, size=6.5)


def _reproduction_section(lay: _Layout, repro: pd.DataFrame, number: int) -> None:
    lay.section(f"{number}. Reproduction of the paper's numbers and statements")
    agree = repro["agree"].astype(str).str.lower()
    n_yes = int(agree.isin(["true", "yes"]).sum())
    n_no = int(agree.isin(["false", "no"]).sum())
    lay.paragraph(
        f"Every toolkit value is computed when the pipeline runs (microimpact.studies.reproduction). {len(repro)} rows: "
        f"{n_yes} agree, {n_no} disagree, {len(repro) - n_yes - n_no} not checkable (the paper's figures are "
        "missing from the available text). Disagreements are reported, not tuned away; see the notes.")
    df = repro.copy()
    df["agree"] = agree.map({"true": "yes", "false": "NO", "yes": "yes", "no": "NO"}).fillna(agree)
    lay.table(df, {"id": 12, "claim": 28, "source": 12, "paper_value": 18, "toolkit_value": 18, "agree": 5,
                   "note": 30},
              headers={"paper_value": "paper", "toolkit_value": "toolkit"})


def _title_page(lay: _Layout, title: str, prov: Mapping[str, str], contents: list[tuple[str, int]]) -> object:
    from matplotlib.figure import Figure

    fig = Figure(figsize=PAGE_SIZE)
    W, H = PAGE_SIZE

    def text(x, y, s, **kw):
        fig.text(x / W, 1 - y / H, s, va="top", **kw)

    text(_MARGIN_X, 1.3, "\n".join(textwrap.wrap(title, 48)), fontsize=20, fontweight="bold", linespacing=1.25)
    text(_MARGIN_X, 2.35, "\n".join(textwrap.wrap(
        "Microsphere impact model of " + PAPER_REFERENCE + ": fit of the damping coefficients, 3-D impact simulations, "
        "nonlinear dynamics, Table 2 sensitivity sweeps and validation.", 95)), fontsize=9, linespacing=1.35)
    if "SYNTHETIC" in prov.get("data", ""):
        text(_MARGIN_X, 3.25, "DATA: SYNTHETIC (generated with known parameters; not a measurement)", fontsize=11,
             fontweight="bold", color="#b00000")
    y = 3.7
    text(_MARGIN_X, y, "Provenance", fontsize=12, fontweight="bold")
    y += 0.3
    for key, value in prov.items():
        lines = _wrap(value, 88)
        text(_MARGIN_X, y, key, fontsize=8.5, fontweight="bold")
        text(_MARGIN_X + 1.45, y, "\n".join(lines), fontsize=8.5, linespacing=1.3)
        y += 0.17 * len(lines) + 0.06
    y += 0.25
    text(_MARGIN_X, y, "Contents", fontsize=12, fontweight="bold")
    y += 0.3
    for name, page in contents:
        text(_MARGIN_X, y, name, fontsize=9)
        text(W - _MARGIN_X, y, f"page {page + 2}", fontsize=9, ha="right")
        y += 0.2
    text(_MARGIN_X, H - 0.9, "\n".join(textwrap.wrap(
        "Generated by the microimpact Snakemake pipeline (Snakefile, workflow/); every number and figure is computed "
        "from the files under results/. Units are SI unless stated; angles in degrees.", 110)), fontsize=7.5,
        color="0.35")
    return fig


# =============================================================================== entry point
def build_report(path, *, fit, phase_portraits, bifurcation, sweeps=(), reproduction=None, flags=None,
                 kharaz=None, work_precision=None, stress=None, dynamics=None, data_table=None, config=None,
                 title: str | None = None) -> Path:
    """Build the PDF report from the pipeline's results.

    Parameters
    ----------
    path : str or os.PathLike
        PDF to write (atomically).
    fit : path or xarray.Dataset
        ``DampingFit.save`` output (results/fit.nc).
    phase_portraits : path or list of xarray.Dataset
        :func:`save_phase_portraits` file or the trajectories.
    bifurcation : path or xarray.Dataset
        :func:`microimpact.dynamics.nonlinear.bifurcation_plane` output.
    sweeps : sequence of paths or Datasets
        :func:`microimpact.studies.sweeps.run_sweep` outputs, one per Table 2 case (any order).
    reproduction : path or DataFrame, optional
        :func:`microimpact.studies.reproduction.reproduction_table` (CSV).
    flags : path or DataFrame, optional
        The measurement-flags table (CSV).
    kharaz : path or xarray.Dataset, optional
        :func:`microimpact.analysis.kharaz.kharaz_comparison` output.
    work_precision : path or xarray.Dataset, optional
        Benchmark Dataset; None: the page says the benchmark was switched off.
    stress : path or mapping, optional
        :func:`microimpact.studies.stress.stress_sweep` summary (results/stress_summary.json or the
        ``StressReport.summary`` dict); None: the page says the stress sweep was not run.
    dynamics : path or xarray.Dataset, optional
        :func:`dynamics_summary` output.
    data_table : path or DataFrame, optional
        The validated impact table (SI units) for the data summary.
    config : mapping, optional
        The pipeline configuration (title page and appendix).
    title : str, optional
        Report title; default ``config["report_title"]`` or a generic one.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    from microimpact import __version__

    config = dict(config or {})
    title = title or config.get("report_title") or "Microsphere contact/impact report"
    data = _frame(data_table) if data_table is not None else None
    prov = provenance(config, data_table=data)
    synthetic = "SYNTHETIC" in prov.get("data", "")

    lay = _Layout(title)
    _fit_section(lay, _dataset(fit), data, synthetic)
    portraits = load_phase_portraits(phase_portraits) if isinstance(phase_portraits, (str, os.PathLike)) \
        else list(phase_portraits)
    _dynamics_section(lay, _dataset(bifurcation), portraits, _dataset(dynamics) if dynamics is not None else None)
    number = 4
    sweep_ds = [_dataset(s) for s in _as_list(sweeps)]
    if sweep_ds:
        lay.section(f"{number}. Sensitivity to the initial conditions (Table 2, Figs. 7-14)", new_page=True)
        lay.paragraph(
            "Each Table 2 case is swept over the incident speed and one curve-family parameter with the fast "
            "engine (one normal solve per distinct normal speed, closed-form tangential map). Curves: rebound "
            "solid, captured dotted; grey bands mark capture. Contact: the configured simulation parameters.")
        _sweep_section(lay, sweep_ds, number)
        number += 1
    if flags is not None:
        _flags_section(lay, _frame(flags), data, number)
        number += 1
    if kharaz is not None:
        _kharaz_section(lay, _dataset(kharaz), number)
        number += 1
    _benchmark_section(lay, _dataset(work_precision) if work_precision is not None else None, number)
    number += 1
    _stress_section(lay, _json(stress) if stress is not None else None, number, config.get("stress"))
    number += 1
    if reproduction is not None:
        _reproduction_section(lay, _frame(reproduction), number)
        number += 1
    if config:
        import yaml

        from microimpact.studies.sweeps import _plain

        lay.section(f"{number}. Appendix: configuration")
        lay.paragraph("The configuration this report was made with (workflow/config/config.yaml merged with "
                      "command-line overrides), validated against workflow/config/config.schema.yaml.")
        lay.paragraph(yaml.safe_dump(_plain(config, unknown=str), sort_keys=False, width=110), mono=True, size=7)

    title_fig = _title_page(lay, title, prov, lay.contents)
    lay.pages.insert(0, _Page(title_fig, "title", 0.0))
    path = Path(path)
    lay.save(path, {"Title": title, "Author": f"microimpact {__version__}",
                    "Subject": "Microsphere impact model of Cheng, Brach & Dunn (2002)",
                    "Keywords": "synthetic data" if synthetic else "measured data"})
    return path
