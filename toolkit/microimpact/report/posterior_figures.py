"""Figures of the analyst's posterior and oblique fit, drawn from result files only (no model run).

* :func:`plot_fit_bands`: measured e_n(v_n) with the best fit and the posterior 95 % band per size;
* :func:`plot_corner`: the corner plot of the chain (matplotlib only: histograms on the diagonal,
  scatter of the post-burn-in samples below it);
* :func:`plot_sweep_bands`: posterior bands of e_n, mu_t and K_L along the Table 2 sweeps;
* :func:`plot_oblique`: measured against fitted tangential quantity per incidence angle.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from microimpact.report.figures import WIDTH, Plot, _colors, _figure, _rc

__all__ = ["plot_fit_bands", "plot_corner", "plot_sweep_bands", "plot_oblique", "posterior_names", "posterior_verdict_title"]

_LABEL = {"zeta_hertz": r"$\zeta_H$", "zeta_adhesion": r"$\zeta_A$", "work_of_adhesion": r"$w_A$ [J/m$^2$]",
          "friction": r"$f$"}


def posterior_names(post: xr.Dataset) -> list[str]:
    """The sampled parameters of a posterior file (attribute ``sampled``).

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.posterior import restitution_bands, sample_posterior
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> ds = post.to_dataset(restitution_bands(post, fit, [1.0, 2.0, 5.0], n_draws=8))
    >>> posterior_names(ds)
    ['zeta_hertz', 'zeta_adhesion']
    """
    return str(post.attrs.get("sampled", "")).split()


def _samples(post: xr.Dataset, name: str) -> np.ndarray:
    burn = int(post.attrs.get("burn_in", 0))
    return post[f"chain_{name}"].values[burn:].ravel()


def _q(post: xr.Dataset, var: str, q: float) -> xr.DataArray:
    return post[var].sel(quantile=q, method="nearest")


@_rc
def plot_fit_bands(fit: xr.Dataset, post: xr.Dataset) -> Plot:
    """Measured e_n with error bars, the best fit, and the posterior 95 % band of the model per size.

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.posterior import restitution_bands, sample_posterior
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> ds = post.to_dataset(restitution_bands(post, fit, [1.0, 2.0, 5.0], n_draws=8))
    >>> plot = plot_fit_bands(fit.to_dataset(), ds)
    >>> len(plot.figure.axes), plot.caption.startswith("Measured e_n (1-sigma error bars)")
    (1, True)
    """
    fig = _figure(WIDTH * 0.72, 3.3)
    ax = fig.subplots()
    radius = fit["radius"].values
    classes = np.unique(np.round(radius, 12))
    v_band = post["band_speed"].values
    for r, col in zip(classes, _colors(len(classes))):
        sel = np.isclose(radius, r, rtol=1e-9, atol=0)
        j = int(np.argmin(np.abs(post["radius"].values - r)))
        lo = _q(post, "e_n_band", 0.025).isel(radius=j).values
        hi = _q(post, "e_n_band", 0.975).isel(radius=j).values
        ax.fill_between(v_band, lo, hi, color=col, alpha=0.25, lw=0)
        ax.plot(v_band, _q(post, "e_n_band", 0.5).isel(radius=j).values, color=col, lw=1.1,
                label=f"d = {2 * r * 1e6:.3g} µm")
        ax.errorbar(fit["normal_speed"].values[sel], fit["e_n_measured"].values[sel], yerr=fit["sigma"].values[sel],
                    fmt="o", ms=2.8, color=col, elinewidth=0.6, capsize=1.2, lw=0)
    ax.set_xscale("log")
    ax.set_xlabel(r"incident normal speed $v_n$ [m/s]")
    ax.set_ylabel(r"$e_n$ [-]")
    ax.set_ylim(bottom=0.0)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    caption = ("Measured e_n (1-sigma error bars) against incident normal speed [m/s], with the posterior median of "
               "the model e_n (line) and its 95 % credible band (shaded: 2.5-97.5 % of the model over posterior draws, "
               f"without the measurement noise). {_convergence(post)}")
    return Plot(fig, caption, "3")


def _convergence(post: xr.Dataset) -> str:
    return f"Chain: {post.attrs.get('convergence', 'convergence not recorded')}."


@_rc
def plot_corner(post: xr.Dataset) -> Plot:
    """Corner plot of the post-burn-in samples: marginal histograms and pairwise scatter.

    Examples
    --------
    Two parameters: two histograms and one scatter panel (and an empty corner):

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.posterior import restitution_bands, sample_posterior
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> ds = post.to_dataset(restitution_bands(post, fit, [1.0, 2.0, 5.0], n_draws=8))
    >>> plot = plot_corner(ds)
    >>> len(plot.figure.axes), plot.caption.split(" (")[0]
    (4, 'Corner plot of the posterior')
    """
    names = posterior_names(post)
    k = len(names)
    fig = _figure(min(WIDTH * 0.75, 1.9 * k + 0.6), min(WIDTH * 0.75, 1.9 * k + 0.6))
    axes = np.atleast_2d(fig.subplots(k, k, squeeze=False))
    data = {n: _samples(post, n) for n in names}
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            ax = axes[i, j]
            if j > i:
                ax.set_visible(False)
                continue
            if i == j:
                ax.hist(data[a], bins=30, color="C0", histtype="stepfilled", alpha=0.6)
                lo, hi = np.quantile(data[a], [0.025, 0.975])
                for x in (lo, np.median(data[a]), hi):
                    ax.axvline(x, color="0.2", lw=0.7, ls="--" if x != np.median(data[a]) else "-")
                ax.set_yticks([])
            else:
                ax.plot(data[b], data[a], ",", color="C0", alpha=0.4)
            if i == k - 1:
                ax.set_xlabel(_LABEL.get(b, b))
            else:
                ax.set_xticklabels([])
            if j == 0 and i > 0:
                ax.set_ylabel(_LABEL.get(a, a))
            ax.tick_params(labelsize=6.5)
    tau = ", ".join(f"{n} {float(post[f'{n}_autocorr_time']):.1f}" for n in names)
    af = post["acceptance_fraction"].values
    caption = (f"Corner plot of the posterior ({post.sizes['walker']} walkers x {post.sizes['step']} steps, burn-in "
               f"{post.attrs.get('burn_in')}, seed {post.attrs.get('seed')}): marginal histograms with median (solid) "
               f"and 95 % interval (dashed), pairwise samples below. Autocorrelation times [steps]: {tau}; acceptance "
               f"fraction {af.mean():.2f} (walkers {af.min():.2f}-{af.max():.2f}). {_convergence(post)}")
    title = posterior_verdict_title(post)
    if title:
        fig.suptitle(title, fontsize=7, color="#b00000" if post.attrs.get("verdict") == "inadequate" else "0.2",
                     wrap=True)
        caption += f" {title[0].upper()}{title[1:]}."
    return Plot(fig, caption)


def posterior_verdict_title(post: xr.Dataset) -> str:
    """The title a posterior figure carries: its fit's verdict, "conditional on a rejected model"
    where the fit's model is rejected ("" for a file that records no verdict).

    Examples
    --------
    >>> post = xr.Dataset(attrs={"verdict": "inadequate", "verdict_text": "inadequate: chi-square 790 for 38 dof"})
    >>> posterior_verdict_title(post)
    'posterior conditional on a rejected model (inadequate: chi-square 790 for 38 dof)'
    >>> posterior_verdict_title(xr.Dataset())
    ''
    """
    verdict, text = str(post.attrs.get("verdict", "")), str(post.attrs.get("verdict_text", ""))
    if not verdict:
        return ""
    if verdict == "inadequate":
        return f"posterior conditional on a rejected model ({text})"
    return f"posterior of a fit judged {text}"


@_rc
def plot_sweep_bands(post: xr.Dataset) -> Plot:
    """Posterior bands (95 %) of e_n, mu_t and K_L along each Table 2 sweep of the analyst's material.

    Examples
    --------
    Case 2.1 for four draws of a short, not converged chain (an illustration): three panels (e_n,
    mu_t, K_L), the sweep's size in the caption:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.posterior import sample_posterior, sweep_bands
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> plot = plot_sweep_bands(sweep_bands(post, fit, cases=["2.1"], n_draws=4, n_speeds=5))
    >>> print(" | ".join(ax.get_ylabel() for ax in plot.figure.axes))
    $e_n$ [-] | $\\mu_t$ [-] | $K_L$ [-]
    >>> "at d = 6.9 µm" in plot.caption
    True
    """
    fig = _figure(WIDTH, 2.5)
    axes = fig.subplots(1, 3)
    v = post["sweep_speed"].values
    cases = [str(c) for c in post["case"].values]
    for q, ax, label in zip(("e_n", "mu_t", "K_L"), axes, (r"$e_n$", r"$\mu_t$", r"$K_L$")):
        for c, col in zip(cases, _colors(len(cases))):
            band = post[f"sweep_{q}_band"].sel(case=c)
            lo, mid, hi = (band.sel(quantile=x, method="nearest").values for x in (0.025, 0.5, 0.975))
            if not np.any(np.isfinite(mid)):
                continue
            ax.fill_between(v, lo, hi, color=col, alpha=0.25, lw=0)
            ax.plot(v, mid, color=col, lw=1.0, label=f"case {c}")
        ax.set_xscale("log")
        ax.set_xlabel(r"speed $v$ [m/s]")
        ax.set_ylabel(label + " [-]")
    axes[0].legend(fontsize=6.5, frameon=False)
    r = float(post.attrs.get("sweep_radius", math.nan))
    caption = (f"Posterior bands of the analyst's Table 2 sweeps at d = {2e6 * r:.3g} µm over the measured speeds "
               f"(median line, 95 % band over posterior draws), {post.attrs.get('sweep_conditions', '')}. "
               "mu_t is undefined (not drawn) where there is no tangential motion.")
    return Plot(fig, caption)


@_rc
def plot_oblique(obl: xr.Dataset) -> Plot:
    """Measured (with 1-sigma effective uncertainty) against fitted tangential quantity, per incidence angle.

    Examples
    --------
    Eight synthetic oblique impacts (friction fitted without propagating the damping covariance, to
    keep the example short): one panel of the measured column, the fitted f in the caption:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.oblique import fit_friction
    >>> from microimpact.analysis.synthetic import make_synthetic_oblique
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials, write_csv
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> data = make_synthetic_oblique(radii=(3.45e-6,), speeds=(15.0, 30.0), incidence_deg=(35.0, 50.0, 60.0, 70.0))
    >>> table = read_impacts(write_csv(data, "oblique.csv"))
    >>> friction = fit_friction(table, fit_damping(table, material, confidence_intervals=False), propagate_damping=False)
    >>> plot = plot_oblique(friction.to_dataset())
    >>> [ax.get_ylabel() for ax in plot.figure.axes], "fitted friction f = 0.1589" in plot.caption
    (['tangential_restitution [1]'], True)
    """
    quantities = list(dict.fromkeys(str(q) for q in obl["quantity"].values))
    fig = _figure(WIDTH * 0.75, 2.6 * len(quantities))
    axes = np.atleast_1d(fig.subplots(len(quantities), 1, squeeze=False)[:, 0])
    radii = np.unique(obl["radius"].values)
    for ax, q in zip(axes, quantities):
        sel = obl["quantity"].values == q
        units = str(obl["quantity_units"].values[sel][0])
        for r, col in zip(radii, _colors(len(radii))):
            s = sel & np.isclose(obl["radius"].values, r)
            a = obl["incidence_deg"].values[s]
            ax.errorbar(a, obl["oblique_measured"].values[s], yerr=obl["oblique_sigma"].values[s], fmt="o", ms=2.8,
                        color=col, elinewidth=0.6, capsize=1.2, lw=0, label=f"measured, d = {2e6 * r:.3g} µm")
            ax.plot(a, obl["oblique_model"].values[s], "x", color=col, ms=4, label=f"fitted, d = {2e6 * r:.3g} µm")
        ax.set_xlabel(r"incidence angle $\alpha$ [deg]")
        ax.set_ylabel(f"{q} [{units}]")
    axes[0].legend(fontsize=6.5, frameon=False, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    f, se = float(obl["friction"]), float(obl["friction_stderr"])
    caption = (f"Oblique impacts: measured tangential quantity (dots, effective 1-sigma: measurement plus incident "
               f"speed and angle errors) and the model at the fitted friction f = {f:.4g} +- {se:.2g} (crosses), "
               f"per incidence angle; {obl.attrs.get('tangential_model', 'rigid')} tangential model, fitted after "
               "the damping (reduced chi-square " f"{float(obl.attrs.get('redchi', math.nan)):.3g}).")
    return Plot(fig, caption)
