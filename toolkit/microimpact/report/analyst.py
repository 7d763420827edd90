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
from microimpact.report.inputs import FLAG_LETTERS, Verdict, at_radius, parameter_source, per_radius, read_verdict
from microimpact.report.layout import Layout

__all__ = ["summary_section", "fit_section", "posterior_section", "oblique_section", "analyst_dynamics_section", "analyst_sweeps_section",
           "flags_section", "verdict_title_lines"]

_PARAMETERS = ("zeta_hertz", "zeta_adhesion", "work_of_adhesion")


# =============================================================================== summary
#: colour of the verdict line: rejected, not tested, adequate
_VERDICT_COLOR = {"inadequate": "#b00000", "adequate": "#1a6e1a"}


def summary_section(lay: Layout, fit: xr.Dataset, verdict: Verdict | None = None) -> None:
    """The first page of the analyst's part: the verdict an analyst acts on.

    The adequacy of the model (chi-square, degrees of freedom, p), each fitted value with its one
    95 % interval or what the data leave undetermined and why, the rows named as outliers by their
    CSV id, the structure of the misfit, and the values that come from the materials config.

    Examples
    --------
    A fit file that records a rejection and two outliers: the page says so, names them, and lists the
    density as a value of the materials config:

    >>> import xarray as xr
    >>> from microimpact.report.layout import Layout
    >>> fit = xr.Dataset({"zeta_hertz": ((), 5.37, {"varied": 1}), "zeta_hertz_stderr": 0.07},
    ...                  attrs={"verdict": "inadequate", "verdict_text": "The model does not describe these data.",
    ...                         "chi_square": 535.1, "degrees_of_freedom": 58, "p_value": 2.2e-78,
    ...                         "outlier_ids": "s-07,s-31", "density": 1350.0, "varied": "zeta_hertz"})
    >>> lay = Layout("Report")
    >>> summary_section(lay, fit)
    >>> text = " ".join(" ".join(t.get_text() for t in p.figure.texts) for p in lay.pages)
    >>> "Verdict: inadequate (chi-square 535.1 for 58 degrees of freedom, p = 2.2e-78)" in text
    True
    >>> "s-07, s-31" in text, "density" in text
    (True, True)
    """
    verdict = verdict or read_verdict(fit)
    lay.section("Verdict", new_page=False)
    lay.paragraph(f"Verdict: {verdict.label}", size=11, color=_VERDICT_COLOR.get(verdict.verdict, "#7a5a00"))
    if not verdict.text.startswith(f"{verdict.verdict}: chi-square"):  # the fit's text is the label again
        lay.paragraph(verdict.text or ("The model is rejected by the data." if verdict.rejected else ""))
    if verdict.misfit_description:
        lay.paragraph(f"Where the model misses: {verdict.misfit_description}")
    if verdict.rejected:
        lay.paragraph("Every result of this part below (capture and critical velocities, sweeps, posterior bands, "
                      "flags) is computed with the parameters of this rejected fit, and each section says so.",
                      color=_VERDICT_COLOR["inadequate"])
    lay.heading("Fitted values (one 95 % interval each)")
    lay.table(_summary_rows(fit, verdict), {"parameter": 17, "units": 6, "value": 11, "ci95": 30, "from": 52},
              headers={"ci95": "95 % interval", "from": "how it is known"}, size=7.4)
    if verdict.rejected and math.isfinite(verdict.widening):
        lay.paragraph("Intervals: conditional on the rejected model; they do not include the misfit (counted as "
                      f"noise it would widen each by sqrt(reduced chi-square) = {verdict.widening:.3g}).")
    elif verdict.interval_note:
        lay.paragraph(f"Intervals: {verdict.interval_note}")
    elif verdict.rejected:
        lay.paragraph("Intervals: conditional on the rejected model; they do not include the misfit.")
    lay.heading("Outliers")
    if verdict.outlier_ids:
        lay.paragraph(f"{len(verdict.outlier_ids)} row(s) named by their CSV id: {', '.join(verdict.outlier_ids)}"
                      + (f" ({verdict.outlier_threshold_text})." if verdict.outlier_threshold_text else "."))
        refit = _without_outliers_rows(fit)
        if verdict.without_outliers or len(refit):
            lay.paragraph(f"Refit {_refit_phrase(verdict.without_outliers or 'see the table')}"
                          + (". These values are shown for comparison; the rest of this part uses the fit above."
                             if len(refit) else "."))
        if len(refit):
            lay.table(refit, {"parameter": 17, "value": 11, "ci95": 30}, headers={"ci95": "95 % interval"}, size=7.4)
    elif "residual" in fit or verdict.recorded:
        lay.paragraph("No row's residual is improbable given the number of rows"
                      + (f" ({verdict.outlier_threshold_text})." if verdict.outlier_threshold_text else "."))
    else:
        lay.paragraph("Not tested: the fit file holds no residuals.", color="0.4")
    fixed = _config_values(fit)
    if fixed:
        lay.heading("Values from the materials config (not fitted)")
        lay.paragraph("; ".join(fixed) + ".")


def verdict_title_lines(verdict: Verdict, part: str) -> list[tuple[str, str]]:
    """The title page's lines of one analyst part's verdict, as (text, colour): the verdict with its
    chi-square, the outliers by id and the verdict of the refit without them.

    Examples
    --------
    >>> v = Verdict("inadequate", "", 817.9, 38, 4.2e-147, ("d-12", "d-24"), without_outliers="without d-12, d-24: adequate")
    >>> [text for text, _ in verdict_title_lines(v, "Part A")]
    ['Verdict, Part A: inadequate (chi-square 817.9 for 38 degrees of freedom, p = 4.2e-147)', 'Outliers (by CSV id): d-12, d-24; refit without d-12, d-24: adequate']
    """
    color = _VERDICT_COLOR.get(verdict.verdict, "#7a5a00")
    lines = [(f"Verdict, {part}: {verdict.label}", color)]
    if verdict.outlier_ids:
        lines.append((f"Outliers (by CSV id): {', '.join(verdict.outlier_ids)}"
                      + (f"; refit {_refit_phrase(verdict.without_outliers)}" if verdict.without_outliers else ""), color))
    return lines


def _refit_phrase(text: str) -> str:
    """'without A, B: adequate ...' as the fit states it, or 'without them: <text>'."""
    return text if text.startswith("without ") else f"without them: {text}"


def _summary_rows(fit: xr.Dataset, verdict: Verdict) -> pd.DataFrame:
    """One row per fit parameter: the value and its one 95 % interval, the bound, or 'not determined'
    with the data's reason, or the materials config for a parameter that was not varied."""
    rows = []
    conditional = " (conditional on the rejected model)" if verdict.rejected else ""
    for name in _fit_parameters(fit):
        units = fit[name].attrs.get("units", "")
        v = float(fit[name])
        if not _varied(fit, name):
            rows.append({"parameter": name, "units": units, "value": f"{v:.4g}", "ci95": "-",
                         "from": "materials config (not fitted)"})
            continue
        st = status_from_variables(fit, name, v)
        if st is not None and not st.determined:
            value = {"lower_bound": f">= {st.lower:.4g}", "upper_bound": f"<= {st.upper:.4g}"}.get(st.status, "-")
            rows.append({"parameter": name, "units": units, "value": value, "ci95": "-",
                         "from": f"not determined by these data: {st.reason or st.status}"})
            continue
        if st is not None:
            lo, hi, how = st.lower, st.upper, "fitted; profile likelihood"
        else:
            se = float(fit[f"{name}_stderr"]) if f"{name}_stderr" in fit else math.nan
            lo, hi, how = v - 1.96 * se, v + 1.96 * se, "fitted; covariance, value +/- 1.96 std. error"
        ci = f"[{lo:.5g}, {hi:.5g}]" if math.isfinite(lo) and math.isfinite(hi) else "not computed"
        rows.append({"parameter": name, "units": units, "value": f"{v:.5g}", "ci95": ci, "from": how + conditional})
    return pd.DataFrame(rows, columns=["parameter", "units", "value", "ci95", "from"])


def _without_outliers_rows(fit: xr.Dataset) -> pd.DataFrame:
    """The refit without the outliers (the ``without_outliers_<name>`` attributes): one row per parameter."""
    a, rows = fit.attrs, []
    for name in _fit_parameters(fit):
        if f"without_outliers_{name}" not in a:
            continue
        lo, hi = (float(a.get(f"without_outliers_{name}_interval_{end}", math.nan)) for end in ("low", "high"))
        ci = f"[{lo:.5g}, {hi:.5g}]" if math.isfinite(lo) and math.isfinite(hi) else "not determined"
        rows.append({"parameter": name, "value": f"{float(a[f'without_outliers_{name}']):.5g}", "ci95": ci})
    return pd.DataFrame(rows, columns=["parameter", "value", "ci95"])


def _varied(fit: xr.Dataset, name: str) -> bool:
    """Whether the fit varied ``name``: the variable's ``varied`` attribute, else the file's ``varied`` list."""
    if name in fit and "varied" in fit[name].attrs:
        return bool(int(fit[name].attrs["varied"]))
    if "varied" in fit.attrs:
        return name in str(fit.attrs["varied"]).split()
    # a file that records neither: a fixed parameter has no standard error
    return f"{name}_stderr" in fit and math.isfinite(float(fit[f"{name}_stderr"]))


def _config_values(fit: xr.Dataset) -> list[str]:
    """The material values the fit took from the materials config, as 'name = value units'."""
    a = fit.attrs
    out = [f"{label} = {float(a[key]):.4g} {units}".rstrip() for key, label, units in
           (("density", "density", "kg/m^3"), ("stiffness", "contact stiffness K", "Pa"),
            ("friction", "friction f", "")) if key in a]
    if a.get("damping_reference_speed"):
        out.append(f"damping reference speed: {a['damping_reference_speed']}")
    return out


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
        # the standard error the text report and --json print: the 95 % interval's (fit.nc's interval_stderr)
        v, se = float(fit[name]), float(fit[name].attrs.get("interval_stderr", fit[f"{name}_stderr"]))
        if not _varied(fit, name):
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
    pairs = [p for p in pairs if "nan" not in p]  # a correlation lmfit did not estimate is left out, not printed as nan
    num = lambda key: float(a.get(key, math.nan))  # noqa: E731
    return (f"{int(a.get('n_points', 0))} points; chi-square {num('chisqr'):.4g}, reduced chi-square "
            f"{num('redchi'):.4g}; AIC {num('aic'):.4g}, BIC {num('bic'):.4g}; correlations: {', '.join(pairs) or 'n/a'}. "
            f"Material: density {num('density'):g} kg/m^3, K = {num('stiffness'):.4g} Pa, damping reference speed: "
            f"{a.get('damping_reference_speed', '?')}."
            # the message of lmfit's intervals contradicts the profile intervals printed above it
            + ("" if any(f"{n}_status" in fit for n in _fit_parameters(fit)) else f" {a.get('fit_ci_message', '')}"))


def _rejected(lay: Layout, note: str) -> None:
    """The line of a section whose results come from a rejected model ("" writes nothing)."""
    if note:
        lay.paragraph(note, color=_VERDICT_COLOR["inadequate"])


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
def posterior_section(lay: Layout, fit: xr.Dataset, post: xr.Dataset, note: str = "") -> None:
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
    _rejected(lay, note)
    if "sampled" not in post.attrs:
        lay.paragraph(f"(No posterior: {post.attrs.get('comment', 'not computed')}.)", color="0.4")
        return
    lay.paragraph(
        "The fitted parameters sampled with emcee (ensemble sampler, differential-evolution moves), seeded "
        f"(seed {post.attrs.get('seed')}), walkers started around the least-squares fit, run until converged "
        "(50 autocorrelation times with a stable tau, rank-normalised split R-hat < 1.01, bulk effective sample "
        "size >= 400; an unconverged chain stops the pipeline instead of reaching this page). Speed errors: "
        + str(post.attrs.get("errors_in_variables", "")) + ". " + _likelihood_method(post)
        + str(post.attrs.get("convergence", "")) + ".")
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


def _likelihood_method(post) -> str:
    """How the likelihood computed the model e_n, as a sentence (files before the method was recorded: none)."""
    method = str(post.attrs.get("likelihood_method", ""))
    if method.startswith("emulator"):
        return (f"Model e_n: the ring law's certified table ({method}; the solver where the table's error "
                "estimate exceeds the tolerance). ")
    return "Model e_n: the solver at every evaluation. " if method else ""


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
def oblique_section(lay: Layout, obl: xr.Dataset, note: str = "") -> None:
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
    _rejected(lay, note)
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
def analyst_dynamics_section(lay: Layout, dyn: xr.Dataset, note: str = "") -> None:
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
    _rejected(lay, note)
    lay.paragraph(
        "For each measured sphere size (diameter d), the contact built from the fitted zeta_H, zeta_A and w_A (f0 "
        "from Eq. (7)): the normal capture velocity v_capture (largest captured normal speed, by bisection) and the "
        "critical velocity v_c of Eq. (38), at which the total damping C = C1 + C2 equals 2 (a property of the "
        "settling motion, not a speed below which spheres stick).")
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
def analyst_sweeps_section(lay: Layout, sweeps: list[xr.Dataset], dyn: xr.Dataset | None, note: str = "") -> None:
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
    _rejected(lay, note)
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
#: flag column -> what its letter (FLAG_LETTERS, the letters of ``microimpact flags``) means
_FLAG_MEANING = {
    "rotation_sensitive": "rotation-sensitive (an unmeasured spin moves a measured quantity by more than its "
                          "uncertainty, or changes the outcome)",
    "angle_sensitive": "angle-sensitive (the incidence-angle error moves a measured quantity by more than its "
                       "uncertainty, or changes the outcome)",
    "near_capture": "near capture (normal speed below 1.5 x the capture velocity, where e_n is steep)",
    "probably_spun": "probably spun (zero spin lies outside the spin range consistent with the measurement)",
    "spin_unexplained": "unexplained (no spin and no angle error within the scan explains the row)",
}


def _letters(row) -> str:
    return "".join(letter for name, letter in FLAG_LETTERS.items() if name in row and _raised(row[name])) or "-"


def _raised(x) -> bool:
    try:
        return bool(int(float(x)))
    except (TypeError, ValueError):
        return False


def _by_row(flags: pd.DataFrame, table, column: str) -> pd.Series:
    """``column`` of ``table`` (the data table or the fit's points, keyed by ``row``) for each flags row."""
    if table is None or "row" not in table or column not in table:
        return pd.Series(np.nan, index=flags.index)
    values = pd.Series(np.asarray(table[column]), index=np.asarray(table["row"]).astype(int))
    values = values[~values.index.duplicated()]
    return flags["row"].astype(int).map(values)


def _flags_with_fit(flags: pd.DataFrame, data: pd.DataFrame | None, fit: xr.Dataset | None) -> pd.DataFrame:
    """The flags table with the measured e_n, its uncertainty and the standardized residual of each row:
    the flags file's own columns where it has them, else the data table's and the fit's."""
    out = flags.copy()
    points = None if fit is None or "row" not in fit else {
        k: fit[k].values for k in ("row", "residual", "id", "e_n_measured", "sigma", "normal_speed", "radius") if k in fit}
    # (column, [(table, its column), ...]): the first source that has it; the data table, then the fit's points
    fills = {"e_n_measured": [(data, "e_n"), (points, "e_n_measured")],
             "e_n_uncertainty": [(data, "e_n_uncertainty"), (points, "sigma")],
             "standardized_residual": [(points, "residual")], "id": [(data, "id"), (points, "id")],
             "normal_speed": [(data, "normal_speed"), (points, "normal_speed")],
             "radius": [(data, "radius"), (points, "radius")]}
    for column, sources in fills.items():
        if column not in out:
            out[column] = pd.Series(np.nan, index=out.index, dtype=object if column == "id" else float)
            for table, source in sources:
                missing = out[column].isna()
                if missing.any():
                    out.loc[missing, column] = _by_row(out, table, source)[missing]
    out["diameter_um"] = 2e6 * pd.to_numeric(out["radius"], errors="coerce")
    # the CSV's id where the file or the table has one, else the row number
    out["id"] = [i if isinstance(i, str) and i else str(int(r)) for i, r in zip(out["id"], out["row"])]
    return out


def flags_section(lay: Layout, flags: pd.DataFrame, data: pd.DataFrame | None, *, fit: xr.Dataset | None = None,
                  verdict: Verdict | None = None, path=None) -> None:
    """The measurement flags: a figure of every row (measured and model e_n) and a table of the flagged rows only.

    The flag letters are those of ``microimpact flags`` (:data:`~microimpact.report.inputs.FLAG_LETTERS`);
    the full table (every row, every column) stays in the flags CSV, whose path the section names.

    Examples
    --------
    An empty flags table says so; a table of two rows, one near capture, lists that row alone, by its id:

    >>> import pandas as pd
    >>> from microimpact.report.layout import Layout
    >>> lay = Layout("Report")
    >>> flags_section(lay, pd.DataFrame(), None)
    >>> lay.page.figure.texts[-1].get_text()
    'No impacts in the flags table.'
    >>> flags = pd.DataFrame({"row": [1, 2], "id": ["a-1", "a-2"], "e_n": [0.2, 0.6], "e_n_min": [0.1, 0.6],
    ...                       "e_n_max": [0.3, 0.6], "capture_speed_ratio": [1.1, 5.0], "rotation_sensitive": 0,
    ...                       "angle_sensitive": 0, "near_capture": [1, 0]})
    >>> lay = Layout("Report")
    >>> flags_section(lay, flags, None, path="results/analyst/x/flags.csv")
    >>> table = next(t.get_text() for t in lay.page.figure.texts if t.get_text().startswith("id"))
    >>> [line.split()[0] for line in table.splitlines() if line.startswith("a-")]
    ['a-1']
    """
    lay.section("Measurement flags")
    if flags.empty:
        lay.paragraph("No impacts in the flags table.")
        return
    verdict = verdict or (read_verdict(fit) if fit is not None else None)
    outliers = set(verdict.outlier_ids) if verdict is not None else set()
    t = _flags_with_fit(flags, data, fit)
    kinds = [name for name in FLAG_LETTERS if name in t]
    counts = ", ".join(f"{int(t[k].map(_raised).sum())} {FLAG_LETTERS[k]}" for k in kinds)
    where = str(path) if path is not None else "the flags CSV of this material pair"
    lay.paragraph(
        "Each measured impact simulated under the fitted model with plausible unmeasured initial spin (up to the "
        "rolling spin v/r, 3-D directions) and with the incidence angle moved by its uncertainty "
        "(microimpact.analysis.flags.flag_measurements). Flags, the letters of 'microimpact flags': "
        + "; ".join(f"{FLAG_LETTERS[k]} = {_FLAG_MEANING[k]}" for k in kinds)
        + f". Of {len(t)} impacts: {counts}"
        + (f"; outliers of the fit (by id): {', '.join(sorted(outliers))}" if outliers else "")
        + f". The table lists the flagged rows only; every row and column is in {where}.")
    if verdict is not None:
        _rejected(lay, verdict.rejected_note("the model e_n and the flags"))
    if "parameter_source" in t:
        lay.source("; ".join(dict.fromkeys(str(s) for s in t["parameter_source"])))
    else:
        lay.source("the fit of this part (the flags are computed from its fit file)")
    if all(k in t for k in ("e_n", "e_n_min", "e_n_max", "capture_speed_ratio")):
        ds = xr.Dataset({k: ("impact", t[k].to_numpy()) for k in
                         ("e_n", "e_n_min", "e_n_max", "capture_speed_ratio", "e_n_measured", "e_n_uncertainty",
                          *kinds)})
        ds["id"] = ("impact", t["id"].astype(str).to_numpy())
        lay.plot(figures.plot_flags(ds, outliers=sorted(outliers)), max_height=3.4)
    _flagged_rows(lay, t, outliers)
    if "spin_low" in t:
        _spin_ranges(lay, t)


def _flagged_rows(lay: Layout, t: pd.DataFrame, outliers: set) -> None:
    """The table of the rows with a flag raised or named as outliers: id, measured, model, standardized residual."""
    letters = [_letters(r) for _, r in t.iterrows()]
    show = [i for i, (letter, name) in enumerate(zip(letters, t["id"])) if letter != "-" or name in outliers]
    if not show:
        lay.paragraph("No row is flagged and none is an outlier of the fit.", color="0.4")
        return

    def fmt(x, spec=".3g"):
        return "" if not np.isfinite(float(x)) else format(float(x), spec)

    sub = t.iloc[show]
    table = pd.DataFrame({
        "id": sub["id"].astype(str),
        "d": [fmt(x) for x in _by_row_or(sub, "diameter_um")],
        "v_n": [fmt(x) for x in _by_row_or(sub, "normal_speed")],
        "meas": [fmt(x, ".4f") for x in sub["e_n_measured"]],
        "model": [fmt(x, ".4f") for x in sub["e_n"]],
        "z": [fmt(x, "+.2f") for x in sub["standardized_residual"]],
        "ratio": [fmt(x) for x in sub["capture_speed_ratio"]] if "capture_speed_ratio" in sub else "",
        "flags": [letters[i] for i in show],
        "outlier": ["yes" if name in outliers else "" for name in sub["id"]],
    })
    lay.heading(f"Flagged rows ({len(show)} of {len(t)})")
    lay.table(table, {"id": 18, "d": 8, "v_n": 9, "meas": 10, "model": 10, "z": 10, "ratio": 9, "flags": 6,
                      "outlier": 7},
              headers={"d": "d [um]", "v_n": "v_n [m/s]", "meas": "e_n measured", "model": "e_n model",
                       "z": "(model - meas.) / sigma", "ratio": "v_n / v_capture"}, size=7.2)


def _by_row_or(t: pd.DataFrame, column: str) -> pd.Series:
    """A per-row quantity of the flags table, NaN where it is not there."""
    return t[column] if column in t else pd.Series(np.nan, index=t.index)


def _spin_ranges(lay: Layout, flags: pd.DataFrame) -> None:
    """Per-row spin consistent with the measurement (the inverse problem), for the rows flagged S or U."""
    lay.heading("Which rows were probably spun, and by how much")
    n = {k: int(flags[k].map(_raised).sum()) for k in ("spin_moves_prediction", "angle_moves_prediction",
                                                      "probably_spun", "spin_unexplained") if k in flags}
    oblique = flags["predicted_quantity"].astype(str) != "e_n"
    draws = flags["explanation_draws"].iloc[0] if "explanation_draws" in flags else "posterior draws or the point estimate"
    lay.paragraph(
        "For each row, the prediction of the quantity it measured (its oblique column, else e_n) under the "
        f"posterior ({draws}); the spin range is the incident top-spin (back-spin negative) [rad/s] whose prediction "
        "lies within 2 sigma of the measurement (measurement, speed and angle errors and posterior spread). "
        f"{FLAG_LETTERS['probably_spun']} = zero spin is outside that range, {FLAG_LETTERS['spin_unexplained']} = no "
        f"spin explains the row. Of {len(flags)} rows: an unmeasured spin moves the prediction by more than the "
        f"measurement uncertainty in {n.get('spin_moves_prediction', 0)}, the angle error in "
        f"{n.get('angle_moves_prediction', 0)}; {n.get('probably_spun', 0)} {FLAG_LETTERS['probably_spun']}, "
        f"{n.get('spin_unexplained', 0)} {FLAG_LETTERS['spin_unexplained']}; {int(oblique.sum())} rows have an "
        "oblique measurement. e_n does not depend on spin (the normal motion decouples), so a row that measured "
        "only e_n admits every spin scanned.")
    show = flags[flags["probably_spun"].map(_raised) | flags["spin_unexplained"].map(_raised)]
    if show.empty:
        lay.paragraph(f"No row is flagged {FLAG_LETTERS['probably_spun']} or {FLAG_LETTERS['spin_unexplained']}.",
                      color="0.4")
        return

    def fmt(x):
        return "" if not np.isfinite(x) else f"{x:.3g}"

    t = pd.DataFrame({
        "id": show["id"].astype(str), "quantity": show["predicted_quantity"].astype(str),
        "low": show["spin_low"].map(fmt), "high": show["spin_high"].map(fmt),
        "s_spin": show["spin_shift"].map(lambda x: f"{x:.2g}"), "s_angle": show["angle_shift"].map(lambda x: f"{x:.2g}"),
        "flags": [_letters(r) for _, r in show.iterrows()]})
    lay.table(t, {"id": 18, "quantity": 24, "low": 12, "high": 12, "s_spin": 10, "s_angle": 10, "flags": 6},
              headers={"low": "spin low [rad/s]", "high": "spin high [rad/s]", "s_spin": "spin shift [sigma]",
                       "s_angle": "angle shift [sigma]"}, size=7.0)
