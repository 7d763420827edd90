"""Part A of the report: the analyst's material, every result made with the parameters of the fit.

Sections: the damping fit (Fig. 3 analogue, drawn from the ``fit_curves`` file), its posterior
(bands on e_n(v), corner plot, capture velocity with credible interval, bands on the sweeps), the
friction fit from the oblique columns (measured against fitted per angle), capture and critical
velocity of each measured size, the Table 2 sweeps at the measured sizes and the measurement flags
with the per-row spin ranges. Each section states the ``parameter_source`` of the files it shows.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import xarray as xr

from microimpact.io.statuses import status_from_variables
from microimpact.report import figures
from microimpact.report import posterior_figures as pfig
from microimpact.report.inputs import at_radius, parameter_source, per_radius
from microimpact.report.layout import Layout

__all__ = ["fit_section", "posterior_section", "oblique_section", "analyst_dynamics_section", "analyst_sweeps_section",
           "flags_section"]

_PARAMETERS = ("zeta_hertz", "zeta_adhesion", "work_of_adhesion")


# =============================================================================== fit
def fit_section(lay: Layout, fit: xr.Dataset, curves: xr.Dataset | None, data: pd.DataFrame | None,
                synthetic: bool) -> None:
    """The damping fit: method, Fig. 3 analogue, parameter table, fit statistics, data by size.

    Examples
    --------
    The section of a fit of six synthetic impacts names the data as synthetic:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> from microimpact.report.layout import Layout
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False).to_dataset()
    >>> lay = Layout("Report")
    >>> fit_section(lay, fit, None, table, synthetic=True)
    >>> text = " ".join(t.get_text() for t in lay.pages[0].figure.texts)
    >>> lay.contents, "SYNTHETIC data generated with known parameters" in " ".join(text.split())
    ([('1. Damping fit (analogue of Fig. 3)', 0)], True)
    """
    lay.section("Damping fit (analogue of Fig. 3)")
    a = fit.attrs
    src = a.get("fit_source", "the data")
    lay.paragraph(
        f"zeta_H and zeta_A of Eqs. (14)-(15) fitted by weighted least squares to the measured normal "
        f"restitution e_n(v_n) of {src}"
        + (" -- SYNTHETIC data generated with known parameters, not a measurement" if synthetic else "")
        + ", jointly over all sphere sizes with one work of adhesion w_A (f0 per radius from Eq. (7)). "
        f"Weighting: {a.get('weighting', '?')}."
        + (f" Data file sha256: {a['fit_sha256']}." if a.get("fit_sha256") else ""))
    lay.source(_fit_source(fit, curves))
    if curves is None:
        lay.paragraph("(No fit_curves file was given: the model is drawn at the data points.)", color="0.4")
    lay.plot(figures.plot_fit(fit, curves), max_height=3.8)
    lay.heading("Fitted parameters")
    lay.table(_parameter_rows(fit), {"parameter": 17, "units": 6, "value": 22, "stderr": 14, "ci95": 24, "method": 40},
              headers={"ci95": "95 % interval (profile)", "stderr": "std. error"}, size=7.2)
    lay.paragraph(_fit_statistics(fit))
    if data is not None and len(data):
        lay.heading("Data by sphere size (validated table, SI units)")
        lay.table(_data_by_size(data), {"diameter_um": 14, "n": 6, "v_min": 12, "v_max": 12, "e_min": 10, "e_max": 10},
                  headers={"diameter_um": "diameter [um]", "n": "impacts", "v_min": "min v_n [m/s]",
                           "v_max": "max v_n [m/s]", "e_min": "min e_n [-]", "e_max": "max e_n [-]"}, size=7.2)


def _fit_source(fit: xr.Dataset, curves: xr.Dataset | None) -> str:
    """What made the fit section: the fit's own ``parameter_source`` if it has one, else the data it fitted."""
    stamped = [ds for ds in (fit, curves) if ds is not None and "parameter_source" in ds.attrs]
    if stamped:
        return parameter_source(*stamped)
    a = fit.attrs
    return (f"fit: {a.get('fit_source', 'unknown data')} {a.get('fit_sha256', 'sha256 unknown')} (this fit; density "
            "and stiffness, and w_A unless fitted, from the materials config)")


def _fit_parameters(fit: xr.Dataset) -> list[str]:
    if "parameter" in fit.coords:
        return [str(p) for p in fit["parameter"].values]
    return [p for p in _PARAMETERS if p in fit]


def _parameter_rows(fit: xr.Dataset) -> pd.DataFrame:
    """One row per fit parameter: value, standard error and 95 % interval where the data determine it,
    else the bound or 'not determined' (the fit's ``<name>_status`` variables); no standard error
    above 100 % of the value is printed as a number."""
    rows = []
    for name in _fit_parameters(fit):
        units = fit[name].attrs.get("units", "")
        v, se = float(fit[name]), float(fit[f"{name}_stderr"])
        if not bool(int(fit[name].attrs.get("varied", 1))):
            rows.append({"parameter": name, "units": units, "value": f"{v:.6g}", "stderr": "fixed", "ci95": "",
                         "method": "fixed (materials config)"})
            continue
        st = status_from_variables(fit, name, v)
        if st is not None and not st.determined:
            value = {"lower_bound": f">= {st.lower:.4g}", "upper_bound": f"<= {st.upper:.4g}"}.get(st.status,
                                                                                                "not determined")
            rows.append({"parameter": name, "units": units, "value": value, "stderr": "-", "ci95": "-",
                         "method": f"not determined by these data: {st.reason}"})
            continue
        meaningful = math.isfinite(se) and v and se <= abs(v)
        ci = (st.lower, st.upper) if st is not None else (v - 1.96 * se, v + 1.96 * se)
        rows.append({"parameter": name, "units": units, "value": f"{v:.6g}", "stderr": f"{se:.3g}" if meaningful else "-",
                     "ci95": f"[{ci[0]:.5g}, {ci[1]:.5g}]",
                     "method": "profile likelihood" if st is not None else "covariance: value +/- 1.96 stderr"})
    return pd.DataFrame(rows)


def _fit_statistics(fit: xr.Dataset) -> str:
    a = fit.attrs
    pairs = []
    if "correlation" in fit:
        corr = fit["correlation"]
        names = [str(n) for n in corr["parameter"].values]
        varied = str(a.get("varied", "")).split()
        pairs = [f"{p}/{q} {float(corr.sel(parameter=p, parameter_b=q)):+.3f}"
                 for i, p in enumerate(names) for q in names[i + 1:] if p in varied and q in varied]
    num = lambda key: float(a.get(key, math.nan))  # noqa: E731
    return (f"{int(a.get('n_points', 0))} points; chi-square {num('chisqr'):.4g}, reduced chi-square "
            f"{num('redchi'):.4g}; AIC {num('aic'):.4g}, BIC {num('bic'):.4g}; correlations: {', '.join(pairs) or 'n/a'}. "
            f"Material: density {num('density'):g} kg/m^3, K = {num('stiffness'):.4g} Pa, damping reference speed: "
            f"{a.get('damping_reference_speed', '?')}. {a.get('fit_ci_message', '')}")


def _data_by_size(t: pd.DataFrame) -> pd.DataFrame:
    summary = (t.assign(diameter_um=np.round(2e6 * t["radius"], 3))
               .groupby("diameter_um")
               .agg(n=("normal_speed", "size"), v_min=("normal_speed", "min"), v_max=("normal_speed", "max"),
                    e_min=("e_n", "min"), e_max=("e_n", "max"))
               .reset_index())
    for c in ("v_min", "v_max", "e_min", "e_max"):
        summary[c] = summary[c].map(lambda x: f"{x:.3g}")
    return summary


# =============================================================================== posterior
def posterior_section(lay: Layout, fit: xr.Dataset, post: xr.Dataset) -> None:
    """The posterior: summary table, e_n bands, corner plot, capture velocity interval, sweep bands.

    Examples
    --------
    A short chain (an illustration, not converged): a row per sampled parameter in the table, the
    band and corner figures, and the chain's own statement that it has not converged. A posterior
    file that was not computed gives one line instead:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.posterior import restitution_bands, sample_posterior
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> from microimpact.report.layout import Layout
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> lay = Layout("Report")
    >>> posterior_section(lay, fit.to_dataset(), post.to_dataset(restitution_bands(post, fit, [1.0, 2.0], n_draws=8)))
    >>> text = " ".join(" ".join(t.get_text() for t in p.figure.texts) for p in lay.pages)
    >>> [name in text for name in ("zeta_hertz", "zeta_adhesion", "NOT converged")]
    [True, True, True]
    >>> sum(len(p.figure.axes) for p in lay.pages)  # e_n bands and corner plot
    2
    >>> lay = Layout("Report")
    >>> posterior_section(lay, None, xr.Dataset(attrs={"comment": "posterior not computed"}))
    >>> lay.page.figure.texts[-1].get_text()
    '(No posterior: posterior not computed.)'
    """
    lay.section("Posterior of the fitted parameters", new_page=False)
    if "sampled" not in post.attrs:
        lay.paragraph(f"(No posterior: {post.attrs.get('comment', 'not computed')}.)", color="0.4")
        return
    lay.paragraph(
        "The fitted parameters sampled with emcee (ensemble sampler, differential-evolution moves), seeded "
        f"(seed {post.attrs.get('seed')}), walkers started around the least-squares fit, run until converged "
        "(50 autocorrelation times with a stable tau, rank-normalised split R-hat < 1.01, bulk effective sample "
        "size >= 400; an unconverged chain stops the pipeline instead of reaching this page). Speed errors: "
        + str(post.attrs.get("errors_in_variables", "")) + ". " + str(post.attrs.get("convergence", "")) + ".")
    lay.table(_posterior_rows(post), {"parameter": 17, "median": 11, "ci95": 40, "prior": 18, "rhat": 8, "ess": 7,
                                      "units": 7},
              headers={"ci95": "95 % credible interval (or bound)", "prior": "flat prior", "rhat": "R-hat",
                       "ess": "ESS"}, size=7.2)
    if "e_n_band" in post:
        lay.plot(pfig.plot_fit_bands(fit, post), max_height=3.6)
    lay.plot(pfig.plot_corner(post), max_height=4.6)
    if "capture_velocity_quantile" in post:
        lay.heading("Capture velocity with its credible interval")
        cv = post["capture_velocity_quantile"]
        if not np.any(np.asarray(cv.values, float) > 0):  # no adhesion (f0 = 0): nothing is captured
            lay.paragraph("No impact is captured at any speed in any posterior draw: the pair has no adhesion "
                          "(f0 = 0), so there is no capture velocity.")
            cv = None
    if "capture_velocity_quantile" in post and cv is not None:
        t = pd.DataFrame({"d": [f"{2e6 * r:.4g}" for r in cv["radius"].values],
                          "median": [f"{float(cv.sel(radius=r, quantile=0.5, method='nearest')):.4g}" for r in cv["radius"].values],
                          "ci": [f"[{float(cv.sel(radius=r, quantile=0.025, method='nearest')):.4g}, "
                                 f"{float(cv.sel(radius=r, quantile=0.975, method='nearest')):.4g}]" for r in cv["radius"].values]})
        lay.table(t, {"d": 12, "median": 16, "ci": 28}, headers={"d": "d [um]", "median": "v_capture [m/s]",
                                                                 "ci": "95 % credible interval [m/s]"}, size=7.2)
    if "sweep_e_n_band" in post:
        lay.plot(pfig.plot_sweep_bands(post), max_height=2.8)


def _posterior_rows(post: xr.Dataset) -> pd.DataFrame:
    """Median and 95 % interval where the data determine the parameter; its statement otherwise."""
    rows = []
    for n in pfig.posterior_names(post):
        q = post[f"{n}_quantile"]
        a = post[f"chain_{n}"].attrs
        at = lambda x: float(q.sel(quantile=x, method="nearest"))  # noqa: E731
        determined = a.get("status", "determined") == "determined"
        rows.append({"parameter": n, "median": f"{at(0.5):.5g}" if determined else "-",
                     "ci95": f"[{at(0.025):.5g}, {at(0.975):.5g}]" if determined else str(a.get("statement", "")),
                     "prior": f"[{a['prior_min']:.3g}, {a['prior_max']:.3g}]" if "prior_min" in a else "",
                     "rhat": f"{a['rhat']:.3f}" if "rhat" in a else "", "ess": f"{a['ess_bulk']:.0f}" if "ess_bulk" in a else "",
                     "units": q.attrs.get("units", "")})
    return pd.DataFrame(rows)


# =============================================================================== oblique
def oblique_section(lay: Layout, obl: xr.Dataset) -> None:
    """The friction fit from the oblique columns: measured against fitted per angle.

    Examples
    --------
    Eight synthetic oblique impacts made with f = 0.15 (friction fitted without propagating the
    damping covariance, to keep the example short): the section states the fitted f and its 95 %
    interval, which contains 0.15, and shows one figure. A table without oblique columns gets one
    line instead of a section:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.oblique import fit_friction
    >>> from microimpact.analysis.synthetic import make_synthetic_oblique
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials, write_csv
    >>> from microimpact.report.layout import Layout
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> data = make_synthetic_oblique(radii=(3.45e-6,), speeds=(15.0, 30.0), incidence_deg=(35.0, 50.0, 60.0, 70.0))
    >>> table = read_impacts(write_csv(data, "oblique.csv"))
    >>> friction = fit_friction(table, fit_damping(table, material, confidence_intervals=False), propagate_damping=False)
    >>> lay = Layout("Report")
    >>> oblique_section(lay, friction.to_dataset())
    >>> lay.contents, len(lay.page.figure.axes)
    ([('1. Friction from the oblique columns', 0)], 1)
    >>> print(lay.page.figure.texts[1].get_text().split("interval. ")[1])
    f = 0.15895, 95 % profile-likelihood interval [0.14417, 0.17382] (standard error 0.00757).
    >>> lay = Layout("Report")
    >>> oblique_section(lay, xr.Dataset(attrs={"comment": "the impact table has no oblique columns: no friction fit"}))
    >>> lay.contents, lay.page.figure.texts[-1].get_text()
    ([], 'Friction: the impact table has no oblique columns: no friction fit.')
    """
    if "friction" not in obl:
        # one line under the fit, not a section of its own (a heading and this line once filled a page)
        lay.paragraph(f"Friction: {obl.attrs.get('comment', 'no friction fit')}.", color="0.4")
        return
    lay.section("Friction from the oblique columns", new_page=False)
    lay.paragraph(
        f"Coulomb friction f fitted to the measured {', '.join(dict.fromkeys(str(q) for q in obl['quantity'].values))} "
        "with the paper's rigid tangential model (Eqs. (16)-(20)), AFTER the damping fit: the normal motion does not "
        "depend on f, and the tangential outcome depends on the damping only through the friction impulse, which the "
        "e_n data fix; the damping covariance is propagated into the interval. " + _friction_statement(obl))
    lay.plot(pfig.plot_oblique(obl), max_height=4.0)


def _friction_statement(obl: xr.Dataset) -> str:
    """What the oblique data say of f: its value and 95 % interval, a one-sided bound, or nothing."""
    st = status_from_variables(obl, "friction", float(obl["friction"]))
    if st is None:  # a file from before the identifiability
        return (f"f = {float(obl['friction']):.5g} +- {float(obl['friction_stderr']):.3g} "
                f"({float(obl['friction_stderr_conditional']):.3g} at fixed damping).")
    if st.determined:
        return (f"f = {st.value:.5g}, 95 % profile-likelihood interval [{st.lower:.5g}, {st.upper:.5g}] "
                f"(standard error {float(obl['friction_stderr']):.3g}).")
    return f"The data do not determine f: {st.describe()}."


# =============================================================================== dynamics per size
def analyst_dynamics_section(lay: Layout, dyn: xr.Dataset) -> None:
    """Capture and critical velocity and the fitted contact of each measured sphere size.

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> from microimpact.report.layout import Layout
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False).to_dataset()
    >>> from microimpact.studies.material import material_dynamics
    >>> lay = Layout("Report")
    >>> analyst_dynamics_section(lay, material_dynamics(fit))
    >>> lay.contents
    [('1. Capture and critical velocity of the measured sizes', 0)]
    """
    lay.section("Capture and critical velocity of the measured sizes", new_page=False)
    lay.paragraph(
        "For each measured sphere radius, the contact built from the fitted zeta_H, zeta_A and w_A (f0 from "
        "Eq. (7)): the normal capture velocity (largest captured normal speed, by bisection) and the critical "
        "velocity v_c of Eq. (38), at which the total damping C = C1 + C2 equals 2.")
    lay.source(parameter_source(dyn))
    t = pd.DataFrame({
        "d": 2e6 * dyn["radius"].values,
        "f0": per_radius(dyn, "contact_adhesion_line_force"),
        "zh": per_radius(dyn, "contact_zeta_hertz"),
        "za": per_radius(dyn, "contact_zeta_adhesion"),
        "v_cap": dyn["capture_velocity"].values,
        "v_c": dyn["critical_velocity"].values if "critical_velocity" in dyn else np.nan,
    }).map(lambda x: f"{float(x):.4g}")
    lay.table(t, {"d": 12, "f0": 12, "zh": 10, "za": 10, "v_cap": 16, "v_c": 16},
              headers={"d": "d [um]", "f0": "f0 [N/m]", "zh": "zeta_H [-]", "za": "zeta_A [-]",
                       "v_cap": "v_capture [m/s]", "v_c": "v_c, Eq. (38) [m/s]"}, size=7.2)


# =============================================================================== sweeps at the measured sizes
def analyst_sweeps_section(lay: Layout, sweeps: list[xr.Dataset], dyn: xr.Dataset | None) -> None:
    """The Table 2 cases with the fitted contact: all sizes in one figure, each case at the median size.

    Examples
    --------
    Case 2.1 of a fit of six impacts of one size (three speeds, two angles): the size-dependence
    figure and the case's two figures (analogues of Figs. 7 and 8), at the median size d = 6.9 um:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> from microimpact.report.layout import Layout
    >>> from microimpact.studies.material import material_sweep
    >>> from microimpact.studies.sweeps import case_spec
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False).to_dataset()
    >>> spec = case_spec("2.1", {"speed": {"start": 1, "stop": 2, "num": 3}, "incidence_deg": [0.0, 30.0]})
    >>> lay = Layout("Report")
    >>> analyst_sweeps_section(lay, [material_sweep(fit, spec, case="2.1")], None)
    >>> text = " ".join(" ".join(t.get_text() for t in p.figure.texts) for p in lay.pages)
    >>> sum(len(p.figure.axes) for p in lay.pages), "Table 2 case 2.1 at d = 6.9 um" in text
    (3, True)
    """
    sweeps = sorted(sweeps, key=lambda d: str(d.attrs.get("case", "")))
    radii = sweeps[0]["radius"].values
    k = len(radii) // 2
    lay.section("Sensitivity sweeps of the measured material (Table 2 cases)", new_page=False)
    lay.paragraph(
        "The initial conditions of the paper's Table 2 cases, simulated with the fitted contact of each measured "
        "sphere size, over the measured speed range. The first figure compares the sizes; the figures of each "
        f"case show the median size, d = {2e6 * radii[k]:.3g} um (all sizes are in the sweep files).")
    lay.source(parameter_source(*sweeps))
    lay.plot(figures.plot_size_dependence(sweeps[0], dyn), max_height=3.0)
    for ds in sweeps:
        one = at_radius(ds, k)
        case = str(ds.attrs.get("case", "?"))
        plots = [figures.plot_restitution_and_impulse(one)]
        if figures.TABLE2_FIGURES.get(case, (None, None))[0] is not None:
            plots.insert(0, figures.plot_energy_loss(one))
        for i, plot in enumerate(plots):
            lay.plot(plot, max_height=2.8, heading=None if i else f"Table 2 case {case} at d = {2e6 * radii[k]:.3g} um")


# =============================================================================== flags
def flags_section(lay: Layout, flags: pd.DataFrame, data: pd.DataFrame | None) -> None:
    """Which measured impacts are sensitive to unmeasured spin, to the angle error, or near capture.

    Examples
    --------
    An empty flags table says so:

    >>> import pandas as pd
    >>> from microimpact.report.layout import Layout
    >>> lay = Layout("Report")
    >>> flags_section(lay, pd.DataFrame(), None)
    >>> lay.page.figure.texts[-1].get_text()
    'No impacts in the flags table.'
    """
    lay.section("Measurement flags")
    if flags.empty:
        lay.paragraph("No impacts in the flags table.")
        return
    count = {k: int(flags[k].sum()) if k in flags else 0 for k in ("rotation_sensitive", "angle_sensitive", "near_capture")}
    lay.paragraph(
        "Each measured impact simulated under the fitted model with plausible unmeasured initial spin (up to the "
        "rolling spin v/r, 3-D directions) and with the incidence angle moved by its uncertainty "
        "(microimpact.analysis.flags.flag_measurements). Flags: R = rotation-sensitive (an unmeasured spin changes "
        "mu or K_L by more than the threshold), A = angle-sensitive (the angle error changes e_n, mu or the "
        "outcome), C = near capture (normal speed below 1.5 x the capture velocity, where e_n is steep). "
        f"Of {len(flags)} impacts: {count['rotation_sensitive']} R, {count['angle_sensitive']} A, "
        f"{count['near_capture']} C. Spreads are max - min over the samples; all columns are in results/flags.csv.")
    if "parameter_source" in flags:
        lay.source("; ".join(dict.fromkeys(str(s) for s in flags["parameter_source"])))
    else:
        lay.source("the fit (the flags are computed from results/fit.nc)")
    lay.table(_flags_table(flags, data), {"row": 5, "d": 9, "v_n": 9, "alpha": 9, "e_meas": 9, "e_n": 9, "ratio": 9,
                                          "mu_spin": 9, "KL_spin": 9, "e_angle": 9, "mu_angle": 9, "flags": 5},
              headers={"d": "d [um]", "v_n": "v_n [m/s]", "alpha": "alpha [deg]", "e_meas": "e_n meas.",
                       "e_n": "e_n model", "ratio": "v_n/v_cap", "mu_spin": "d mu spin", "KL_spin": "d K_L spin",
                       "e_angle": "d e_n angle", "mu_angle": "d mu angle"}, size=7.0)
    if "spin_low" in flags:
        _spin_ranges(lay, flags)


def _spin_ranges(lay: Layout, flags: pd.DataFrame) -> None:
    """Per-row spin consistent with the measurement (the inverse problem) and the flags that explain."""
    lay.heading("Which rows were probably spun, and by how much")
    n = {k: int(flags[k].sum()) for k in ("spin_moves_prediction", "angle_moves_prediction", "probably_spun",
                                          "spin_unexplained") if k in flags}
    oblique = flags["predicted_quantity"].astype(str) != "e_n"
    lay.paragraph(
        "For each row, the prediction of the quantity it measured (its oblique column, else e_n) under the "
        f"posterior ({flags.get('explanation_draws', pd.Series(['posterior draws'])).iloc[0] if 'explanation_draws' in flags else 'posterior draws or the point estimate'}): "
        "S = an unmeasured top-/back-spin up to the rolling spin v/r moves it by more than the measurement "
        "uncertainty in at least half the draws, A = the angle error does; the spin range is the incident top-spin "
        "(back-spin negative) [rad/s] whose prediction lies within 2 sigma of the measurement (measurement, speed "
        "and angle errors and posterior spread). P = zero spin is outside that range (probably spun), U = no spin "
        f"explains the row. Of {len(flags)} rows: {n.get('spin_moves_prediction', 0)} S, "
        f"{n.get('angle_moves_prediction', 0)} A, {n.get('probably_spun', 0)} P, {n.get('spin_unexplained', 0)} U; "
        f"{int(oblique.sum())} rows have an oblique measurement. e_n does not depend on spin (the normal motion "
        "decouples), so a row that measured only e_n admits every spin scanned.")
    show = flags[oblique | (flags["probably_spun"] == 1) | (flags["spin_unexplained"] == 1)]
    if show.empty:
        lay.paragraph("No row constrains the spin (no oblique measurements) and none is unexplained.", color="0.4")
        return

    def fmt(x):
        return "" if not np.isfinite(x) else f"{x:.3g}"

    t = pd.DataFrame({
        "row": show["row"].astype(int).astype(str), "quantity": show["predicted_quantity"].astype(str),
        "low": show["spin_low"].map(fmt), "high": show["spin_high"].map(fmt),
        "s_spin": show["spin_shift"].map(lambda x: f"{x:.2g}"), "s_angle": show["angle_shift"].map(lambda x: f"{x:.2g}"),
        "flags": ["".join(c for c, k in (("S", "spin_moves_prediction"), ("A", "angle_moves_prediction"),
                                         ("P", "probably_spun"), ("U", "spin_unexplained")) if int(r[k])) or "-"
                  for _, r in show.iterrows()]})
    lay.table(t, {"row": 5, "quantity": 24, "low": 12, "high": 12, "s_spin": 10, "s_angle": 10, "flags": 6},
              headers={"low": "spin low [rad/s]", "high": "spin high [rad/s]", "s_spin": "spin shift [sigma]",
                       "s_angle": "angle shift [sigma]"}, size=7.0)


def _flags_table(flags: pd.DataFrame, data: pd.DataFrame | None) -> pd.DataFrame:
    def spread(q, over):
        lo, hi = f"{q}_min_{over}", f"{q}_max_{over}"
        return (flags[hi] - flags[lo]) if lo in flags and hi in flags else pd.Series(np.nan, index=flags.index)

    def fmt(series, spec=".3g"):
        return series.map(lambda x: "" if not np.isfinite(x) else format(x, spec))

    t = pd.DataFrame({"row": flags["row"]})
    if data is not None and "row" in data:
        d = data.set_index("row")
        t["d"] = fmt(flags["row"].map(2e6 * d["radius"]))
        t["v_n"] = fmt(flags["row"].map(d["normal_speed"]))
        t["alpha"] = fmt(flags["row"].map(d["incidence_deg"]))
        t["e_meas"] = fmt(flags["row"].map(d["e_n"]), ".3f")
    nan = pd.Series(np.nan, index=flags.index)
    t["e_n"] = fmt(flags.get("e_n", nan))
    t["ratio"] = fmt(flags.get("capture_speed_ratio", nan))
    t["mu_spin"] = fmt(np.fmax(spread("mu_t", "spin"), spread("mu_tp", "spin")))
    t["KL_spin"] = fmt(spread("K_L", "spin"))
    t["e_angle"] = fmt(spread("e_n", "angle"))
    t["mu_angle"] = fmt(np.fmax(spread("mu_t", "angle"), spread("mu_tp", "angle")))
    t["flags"] = ["".join(c for c, k in (("R", "rotation_sensitive"), ("A", "angle_sensitive"), ("C", "near_capture"))
                          if k in flags and int(r[k])) or "-" for _, r in flags.iterrows()]
    return t
