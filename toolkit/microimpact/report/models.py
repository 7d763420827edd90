"""Report section: the normal contact models (the paper's ring force, JKR, DMT) fitted to the same data.

Reads the NetCDF of :func:`microimpact.analysis.model_comparison.compare_normal_models` (no model is
run here): a table of AIC and BIC side by side with the fitted parameters and the Tabor parameter,
and a figure of the data with each model's fitted curve.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from microimpact.report.figures import WIDTH, Plot, _colors, _figure, _rc
from scipy.special import chdtrc

from microimpact.report.inputs import VERDICT_LEVEL, parameter_source
from microimpact.report.layout import Layout

__all__ = ["model_comparison_section", "plot_model_comparison", "model_verdicts"]

_STYLES = {"ring": "-", "jkr": "--", "dmt": ":", "jkr_force": "-.", "thornton_ning": (0, (5, 1, 1, 1, 1, 1))}
_NAMES = {"ring": "ring force (paper)", "jkr": "JKR", "dmt": "DMT", "jkr_force": "JKR, force-controlled break",
          "thornton_ning": "Thornton-Ning (elastic-plastic)"}


@_rc
def plot_model_comparison(ds: xr.Dataset) -> Plot:
    """Measured e_n(v_n) per sphere size and the fitted curve of each normal model.

    Parameters
    ----------
    ds : xarray.Dataset
        :func:`~microimpact.analysis.model_comparison.compare_normal_models` output: ``data_*``
        along ``point``, ``e_n_curve`` (normal_model, radius, curve_speed [m/s]).

    Examples
    --------
    The ring force and JKR fitted to six synthetic impacts made with the ring force (a coarse start
    grid keeps the example short): one line style per model, and the caption's Delta AIC prefers the
    ring force:

    >>> from microimpact.analysis.model_comparison import compare_normal_models
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> ds = compare_normal_models(table, material, ("ring", "jkr"), curve_points=5,
    ...                            start_grid=([0.1, 1.0], [10.0, 100.0]))
    >>> plot = plot_model_comparison(ds)
    >>> lines = [line for line in plot.figure.axes[0].get_lines() if line.get_linestyle() != "None"]
    >>> [(line.get_label(), line.get_linestyle()) for line in lines]
    [('ring force (paper)', '-'), ('JKR', '--')]
    >>> plot.caption.split("Delta AIC: ")[1]
    'ring force (paper) 0.0, JKR 13.6.'
    """
    fig = _figure(WIDTH * 0.72, 3.3)
    ax = fig.subplots()
    radii = ds["radius"].values
    cols = _colors(radii.size)
    r_data = ds["data_radius"].values
    for k, (r, col) in enumerate(zip(radii, cols)):
        sel = np.isclose(r_data, r, rtol=1e-9, atol=0)
        sig = ds["data_e_n_uncertainty"].values[sel]
        ax.errorbar(ds["data_normal_speed"].values[sel], ds["data_e_n"].values[sel],
                    yerr=np.where(np.isfinite(sig), sig, 0.0), fmt="o", ms=3.0, color=col, ecolor=col,
                    elinewidth=0.6, capsize=1.2, alpha=0.8, lw=0, label=f"d = {2 * r * 1e6:.3g} µm")
        for m in ds["normal_model"].values:
            ax.plot(ds["curve_speed"].values, ds["e_n_curve"].sel(normal_model=m).isel(radius=k).values,
                    color=col, lw=1.1, ls=_STYLES.get(str(m), "-.") ,
                    label=_NAMES.get(str(m), str(m)) if k == 0 else None)
    ax.set_xscale("log")
    ax.set_xlabel(r"incident normal speed $v_n$ [m/s]")
    ax.set_ylabel(r"$e_n$ [-]")
    ax.set_ylim(bottom=0.0)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    aic = ", ".join(f"{_NAMES.get(str(m), m)} {float(ds['delta_aic'].sel(normal_model=m)):.1f}"
                    for m in ds["normal_model"].values)
    plastic = "thornton_ning" in [str(m) for m in ds["normal_model"].values]
    caption = ("Normal restitution e_n against incident normal speed [m/s]: the data (1-sigma error bars, colour "
               "per sphere diameter) and each normal model fitted to them with the same free parameters "
               "(zeta_H, zeta_A, w_A" + ("; the rate-independent Thornton-Ning law: V_y, w_A" if plastic else "")
               + "); line style per model (solid: the paper's ring force, dashed: JKR, "
               f"dotted: DMT{', dash-dotted-dotted: Thornton-Ning' if plastic else ''}). Delta AIC: {aic}.")
    return Plot(fig, caption)


def model_verdicts(ds: xr.Dataset) -> dict[str, str]:
    """Normal model -> "adequate", "inadequate" or "not tested": the file's ``verdict`` per model where
    it records one, else chi-square against N - k degrees of freedom (stated uncertainties only).

    Examples
    --------
    >>> import xarray as xr
    >>> ds = xr.Dataset({"chi_square": ("normal_model", [95.0, 400.0])}, coords={"normal_model": ["ring", "jkr"]},
    ...                 attrs={"number_of_points": 100, "varied_parameters": 3, "weighting": "stated e_n uncertainties"})
    >>> model_verdicts(ds)
    {'ring': 'adequate', 'jkr': 'inadequate'}
    """
    models = [str(m) for m in ds["normal_model"].values]
    if "verdict" in ds:
        return dict(zip(models, (str(v) for v in ds["verdict"].values)))
    a = ds.attrs
    dof = float(a.get("number_of_points", np.nan)) - float(a.get("varied_parameters", np.nan))
    stated = "stated" in str(a.get("weighting", "")) or "uncertaint" in str(a.get("weighting", ""))
    if not (stated and np.isfinite(dof) and dof > 0):
        return dict.fromkeys(models, "not tested")
    p = chdtrc(dof, np.asarray(ds["chi_square"].values, float))
    return {m: "inadequate" if q < VERDICT_LEVEL else "adequate" for m, q in zip(models, p)}


def _preference(ds: xr.Dataset, verdicts: dict[str, str]) -> str:
    """What the comparison says: the preferred adequate model, or, with all rejected, the least bad one."""
    order = sorted(verdicts, key=lambda m: float(ds["aic"].sel(normal_model=m)))
    best = order[0]
    if all(v == "inadequate" for v in verdicts.values()):
        return (f" All {len(order)} models are rejected by the data (chi-square too large for the stated "
                f"uncertainties): no model is preferred. Least bad (lowest AIC): {_NAMES.get(best, best)}; the AIC "
                "differences rank misfits, not adequate models.")
    adequate = [m for m in order if verdicts[m] != "inadequate"]
    rejected = [m for m in order if verdicts[m] == "inadequate"]
    return (f" Lowest AIC among the models the data do not reject: {_NAMES.get(adequate[0], adequate[0])}."
            + (f" Rejected by the data: {', '.join(_NAMES.get(m, m) for m in rejected)}." if rejected else ""))


def _table(ds: xr.Dataset, verdicts: dict[str, str] | None = None) -> pd.DataFrame:
    verdicts = verdicts or model_verdicts(ds)
    plastic = "yield_velocity" in ds and bool(ds["yield_velocity"].notnull().any())
    rows = []
    for m in ds["normal_model"].values:
        d = ds.sel(normal_model=m)
        mu = d["tabor_parameter"].values
        rows.append({"model": _NAMES.get(str(m), str(m)), "AIC": f"{float(d['aic']):.1f}",
                     "BIC": f"{float(d['bic']):.1f}", "dAIC": f"{float(d['delta_aic']):.1f}",
                     "dBIC": f"{float(d['delta_bic']):.1f}", "chi2": f"{float(d['chi_square']):.4g}",
                     "zeta_H": _cell(d, "zeta_hertz"), "zeta_A": _cell(d, "zeta_adhesion"),
                     "w_A": f"{float(d['work_of_adhesion']):.3g}", "mu_T": f"{mu.min():.3g}-{mu.max():.3g}",
                     "verdict": verdicts.get(str(m), "")} | ({"V_y": _cell(d, "yield_velocity")} if plastic else {}))
    return pd.DataFrame(rows)


def _cell(d: xr.Dataset, name: str) -> str:
    """A parameter's cell: its value, or "-" for a model without it (the zetas of a rate-independent law)."""
    if name not in d or not np.isfinite(float(d[name])):
        return "-"
    return f"{float(d[name]):.3g}"


def model_comparison_section(lay: Layout, ds: xr.Dataset, synthetic: bool = False) -> None:
    """The models side by side: method, AIC/BIC table, figure, and how to read them.

    Examples
    --------
    The same comparison as a section: the table puts the ring force first with Delta AIC 0 and JKR
    13.6 above it, and the synthetic data are said to have been made with the ring model:

    >>> from microimpact.analysis.model_comparison import compare_normal_models
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> ds = compare_normal_models(table, material, ("ring", "jkr"), curve_points=5,
    ...                            start_grid=([0.1, 1.0], [10.0, 100.0]))
    >>> import re
    >>> from microimpact.report.layout import Layout
    >>> lay = Layout("Report")
    >>> model_comparison_section(lay, ds, synthetic=True)
    >>> texts = [t.get_text() for t in lay.page.figure.texts]
    >>> [re.split(r"\\s{2,}", row)[:4] for row in texts[3].splitlines()[2:]]  # model, AIC, BIC, Delta AIC
    [['ring force (paper)', '-5.4', '-6.0', '0.0'], ['JKR', '8.2', '7.5', '13.6']]
    >>> "generated with the paper's ring model" in " ".join(texts[1].split())
    True
    """
    lay.section("Normal contact models compared on the data")
    a = ds.attrs
    verdicts = model_verdicts(ds)
    lay.paragraph(
        "The paper's adhesion ring force and the JKR and DMT adhesion models (README, 'Contact models beyond the "
        "paper') are each fitted by weighted least squares to the same measured e_n(v_n), with the same three free "
        f"parameters (zeta_H, zeta_A, w_A) and the same residuals ({a.get('weighting', '?')}; "
        f"N = {a.get('number_of_points', '?')} points, k = {a.get('varied_parameters', '?')})"
        + (". The elastic-plastic adhesive law of Thornton & Ning (1998) is rate-independent: it is fitted with its "
           "yield velocity V_y and w_A (k = 2) and the same residuals" if "yield_velocity" in ds else "")
        + ". AIC = N ln(chi^2/N) "
        "+ 2k and BIC = N ln(chi^2/N) + k ln N; among models the data do not reject, one lower by more than about "
        "10 is strongly preferred (a rejected model is never preferred). "
        "mu_T is the Tabor parameter at the measured sizes with the fitted w_A (z0 = 0.4 nm): JKR applies above "
        "about 5, DMT below about 0.1."
        + (" The data are SYNTHETIC, generated with the paper's ring model: the comparison is expected to prefer "
           "it, and shows that the data can tell the models apart." if synthetic else "")
        + _preference(ds, verdicts))
    lay.source(parameter_source(ds))
    lay.table(_table(ds, verdicts), {"model": 18, "AIC": 8, "BIC": 8, "dAIC": 7, "dBIC": 7, "chi2": 9, "zeta_H": 7,
                                     "zeta_A": 7, "w_A": 7, "V_y": 7, "mu_T": 10, "verdict": 10}, size=7.0)
    lay.plot(plot_model_comparison(ds), max_height=3.4)
