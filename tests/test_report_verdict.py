"""The report states the verdict an analyst acts on (issue 51, item 7).

A small fit file made here carries the verdict attributes the fit writes (verdict, verdict_text,
chi_square, degrees_of_freedom, p_value, outlier_ids, outlier_threshold_text, misfit_description,
interval_note): page 1 of Part A states them; every downstream section says it comes from a
rejected model; the model comparison prefers no rejected model; the flags page lists the flagged
rows only, by the CSV's id, with the letters of ``microimpact flags``. A file from before the
verdict is judged by the report from its chi-square (checked against scipy.stats.chi2), and a file
without one says "verdict not recorded". No solver runs here: every input is built by hand.
"""

import re

import numpy as np
import pandas as pd
import pytest
import xarray as xr
from scipy.stats import chi2, norm

from microimpact.analysis.flags import FLAG_LETTERS as CLI_LETTERS
from microimpact.io.statuses import ParameterStatus, status_variables
from microimpact.report import analyst, figures
from microimpact.report.inputs import FLAG_LETTERS, VERDICT_LEVEL, read_verdict
from microimpact.report.layout import Layout
from microimpact.report.models import model_verdicts
from microimpact.report.pdf import build_report

pypdf = pytest.importorskip("pypdf")

N = 40
IDS = [f"s-{k:02d}" for k in range(1, N + 1)]
VERDICT_ATTRS = {
    "verdict": "inadequate", "verdict_text": "The model does not describe these data.", "chi_square": 1310.0,
    "degrees_of_freedom": 38, "p_value": 2.7e-250, "outlier_ids": "s-07,s-31",  # chi2.sf(1310, 38) = 2.72e-250
    "outlier_threshold_text": "|z| > 3.23 (5 % false alarms on 40 rows)",
    "misfit_description": "too low at 3-8 m/s, too high above 20 m/s",
    "interval_note": "conditional on a rejected model; widened by the misfit: [17.9, 18.9]",
    "without_outliers_text": "without s-07, s-31: adequate: chi-square 31.2 for 36 degrees of freedom (p = 0.69)",
    "without_outliers_zeta_adhesion": 18.31, "without_outliers_zeta_adhesion_interval_low": 18.02,
    "without_outliers_zeta_adhesion_interval_high": 18.57,
}


def _fit(attrs: dict, residual=None) -> xr.Dataset:
    """A damping-fit file of 40 points at two sizes: zeta_H and zeta_A fitted, w_A from the config."""
    rng = np.random.default_rng(4)
    speed = np.geomspace(1.0, 40.0, N)
    radius = np.where(np.arange(N) % 2, 1.29e-6, 3.45e-6)
    sigma = np.full(N, 0.02)
    model = 0.8 - 0.5 / speed
    z = rng.normal(size=N) if residual is None else residual
    ds = xr.Dataset(
        {"zeta_hertz": ((), 0.52, {"units": "1", "varied": 1}), "zeta_hertz_stderr": 0.05,
         "zeta_adhesion": ((), 18.38, {"units": "1", "varied": 1}), "zeta_adhesion_stderr": 0.13,
         "work_of_adhesion": ((), 0.216, {"units": "J m-2", "varied": 0}), "work_of_adhesion_stderr": np.nan,
         **status_variables(ParameterStatus("zeta_hertz", "upper_bound", np.nan, 0.0, 0.057,
                                            reason="every row is adhesion-dominated"), "1"),
         **status_variables(ParameterStatus("zeta_adhesion", "determined", 18.38, 18.125, 18.623), "1"),
         "id": ("point", np.array(IDS)), "row": ("point", np.arange(1, N + 1)), "radius": ("point", radius),
         "normal_speed": ("point", speed), "e_n_measured": ("point", model - z * sigma), "sigma": ("point", sigma),
         "e_n_model": ("point", model), "residual": ("point", z)},
        attrs={"varied": "zeta_hertz zeta_adhesion", "n_points": N, "chisqr": float(np.sum(z ** 2)),
               "redchi": float(np.sum(z ** 2)) / (N - 2), "weighting": "e_n uncertainty", "density": 1350.0,
               "stiffness": 1.776e9, "friction": 0.15, "damping_reference_speed": "per-impact normal speed",
               "fit_source": "lab.csv", "parameter_source": "fit: lab.csv 0123", **attrs})
    return ds


def _comparison(chi_square) -> xr.Dataset:
    models = ["ring", "jkr", "dmt"][: len(chi_square)]
    k = len(models)
    speed = np.geomspace(1.0, 40.0, 5)
    aic = N * np.log(np.asarray(chi_square) / N) + 6
    return xr.Dataset(
        {"aic": ("normal_model", aic), "bic": ("normal_model", aic + 5), "delta_aic": ("normal_model", aic - aic.min()),
         "delta_bic": ("normal_model", aic - aic.min()), "chi_square": ("normal_model", np.asarray(chi_square, float)),
         **{p: ("normal_model", np.full(k, v)) for p, v in (("zeta_hertz", 0.5), ("zeta_adhesion", 18.0),
                                                            ("work_of_adhesion", 0.2))},
         "tabor_parameter": (("normal_model", "radius"), np.full((k, 2), 15.0)),
         "e_n_curve": (("normal_model", "radius", "curve_speed"), np.full((k, 2, 5), 0.5)),
         "data_radius": ("point", np.full(4, 1.29e-6)), "data_normal_speed": ("point", speed[:4]),
         "data_e_n": ("point", np.full(4, 0.5)), "data_e_n_uncertainty": ("point", np.full(4, 0.02))},
        coords={"normal_model": models, "radius": [1.29e-6, 3.45e-6], "curve_speed": speed},
        attrs={"number_of_points": N, "varied_parameters": 3, "weighting": "stated e_n uncertainties",
               "parameter_source": "materials: x"})


def _flags() -> pd.DataFrame:
    near = np.zeros(N, int)
    near[[0, 2]] = 1
    return pd.DataFrame({"row": np.arange(1, N + 1), "id": IDS, "e_n": 0.5, "e_n_min": 0.45, "e_n_max": 0.55,
                         "capture_speed_ratio": np.geomspace(1.1, 30.0, N), "rotation_sensitive": 0,
                         "angle_sensitive": 0, "near_capture": near})


def _dynamics() -> xr.Dataset:
    return xr.Dataset({"capture_velocity": ("radius", [2.1, 1.4]), "critical_velocity": ("radius", [7e-5, 4e-5])},
                      coords={"radius": [1.29e-6, 3.45e-6]}, attrs={"parameter_source": "fit: lab.csv 0123"})


@pytest.fixture(scope="module")
def rejected_report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("verdict")
    _fit(VERDICT_ATTRS).to_netcdf(tmp / "fit.nc")
    _flags().to_csv(tmp / "flags.csv", index=False)
    path = build_report(tmp / "report.pdf", {"fit": tmp / "fit.nc", "flags": tmp / "flags.csv",
                                             "model_comparison": _comparison([1310.0, 1500.0, 1420.0]),
                                             "analyst_dynamics": _dynamics()})
    pages = [" ".join((p.extract_text() or "").split()) for p in pypdf.PdfReader(path).pages]
    return tmp, pages


def _section(pages, title):
    return " ".join(p for p in pages if title in p)


def test_page_one_states_the_verdict_values_outliers_and_config(rejected_report):
    _, pages = rejected_report
    first = pages[1]  # the first page after the title page
    assert "Verdict: inadequate (chi-square 1310 for 38 degrees of freedom, p = 2.7e-250)" in first
    assert "too low at 3-8 m/s, too high above 20 m/s" in first
    assert "s-07, s-31" in first and "|z| > 3.23" in first
    # one 95 % interval for the determined parameter, a bound and the reason for the other
    assert "[18.125, 18.623]" in first and "<= 0.057" in first and "every row is adhesion-dominated" in first
    assert "widened by the misfit" in first
    # w_A was not varied: it is the materials config's, as are the density and stiffness
    assert re.search(r"work_of_adhesion J m-2 0\.216 - materials config", first)
    assert "density = 1350 kg/m^3" in first and "contact stiffness K = 1.776e+09 Pa" in first


def test_the_title_page_states_each_verdict_the_outliers_and_the_refit_without_them(rejected_report):
    """Issue 51: the PDF's first page (the title page) states the verdict; the outliers are named by
    id there and the refit without them is shown beside the fit on the verdict page."""
    _, pages = rejected_report
    title = pages[0]
    assert "Verdict, Part A: inadequate (chi-square 1310 for 38 degrees of freedom, p = 2.7e-250)" in title
    assert ("Outliers (by CSV id): s-07, s-31; refit without s-07, s-31: adequate: chi-square 31.2 for 36 "
            "degrees of freedom (p = 0.69)") in title
    verdict_page = pages[1]
    assert "Refit without s-07, s-31: adequate" in verdict_page
    assert re.search(r"zeta_adhesion 18\.31 \[18\.02, 18\.57\]", verdict_page), verdict_page
    # the fit's own text, when it is the verdict line again (as analysis.verdict writes it), is not repeated
    lay = Layout("Report")
    analyst.summary_section(lay, _fit(VERDICT_ATTRS | {
        "verdict_text": "inadequate: chi-square 1310 for 38 degrees of freedom (p = 2.7e-250)"}))
    text = " ".join(t.get_text() for p in lay.pages for t in p.figure.texts)
    assert text.count("chi-square 1310 for 38") == 1, text


def test_every_downstream_section_says_it_comes_from_a_rejected_model(rejected_report):
    _, pages = rejected_report
    for title in ("Capture and critical velocity of the measured sizes", "Measurement flags"):
        assert "FROM A REJECTED MODEL" in _section(pages, title), title


def test_the_comparison_prefers_no_rejected_model(rejected_report):
    _, pages = rejected_report
    text = _section(pages, "Normal contact models compared on the data")
    assert "All 3 models are rejected by the data" in text and "no model is preferred" in text
    assert "Least bad (lowest AIC): ring force (paper)" in text
    assert "strongly preferred." not in text.replace("(a rejected model is never preferred)", "")
    assert model_verdicts(_comparison([1310.0, 1500.0, 1420.0])) == dict.fromkeys(["ring", "jkr", "dmt"],
                                                                                  "inadequate")


def test_comparison_with_one_adequate_model_names_it():
    # chi-square 30 for 37 degrees of freedom is adequate (p = 0.78), 400 is not
    ds = _comparison([30.0, 400.0])
    assert model_verdicts(ds) == {"ring": "adequate", "jkr": "inadequate"}
    lay = Layout("Report")
    from microimpact.report.models import model_comparison_section
    model_comparison_section(lay, ds)
    text = " ".join(" ".join(t.get_text().split()) for p in lay.pages for t in p.figure.texts)
    assert "Lowest AIC among the models the data do not reject: ring force (paper)" in text
    assert "Rejected by the data: JKR" in text


def test_flags_page_lists_the_flagged_rows_only_by_id(rejected_report):
    tmp, pages = rejected_report
    text = _section(pages, "Measurement flags")
    table = text.split("Flagged rows (4 of 40)")[1]
    listed = re.findall(r"\bs-\d\d\b", table)
    # rows 1 and 3 are near capture (N), s-07 and s-31 are outliers of the fit
    assert listed == ["s-01", "s-03", "s-07", "s-31"]
    assert "s-01 " in table and " N " in table and "yes" in table
    # the page names the flags file the report read, which exists
    assert f"every row and column is in {tmp / 'flags.csv'}" in text.replace("- ", "-") or str(tmp / "flags.csv") in text
    assert (tmp / "flags.csv").exists()
    assert "C = near capture" not in text and "N = near capture" in text


def test_report_letters_are_the_cli_letters():
    assert FLAG_LETTERS == CLI_LETTERS


def test_flags_figure_draws_the_measured_points_and_the_outliers():
    t = _flags()
    ds = xr.Dataset({k: ("impact", t[k].to_numpy()) for k in t.columns if k != "id"})
    ds["id"] = ("impact", t["id"].to_numpy())
    ds["e_n_measured"] = ("impact", np.linspace(0.3, 0.7, N))
    plot = figures.plot_flags(ds, outliers=["s-07", "s-31"])
    ax = plot.figure.axes[0]
    labels = [line.get_label() for line in ax.get_lines()]
    assert "outlier of the fit" in labels
    measured = [c for c in ax.containers if getattr(c, "get_label", lambda: "")() == "measured e_n ± 1σ"]
    assert measured and np.allclose(measured[0].lines[0].get_ydata(), ds["e_n_measured"].values)
    assert [a.get_text() for a in ax.texts] == ["s-07", "s-31"]
    assert "N near capture" in plot.caption and "C near capture" not in plot.caption
    from test_report_figures import legend_overlaps
    assert legend_overlaps(plot.figure) == []


def test_a_file_without_the_verdict_is_judged_from_its_chi_square():
    z = np.zeros(N)
    z[[6, 30]] = (24.0, -24.0)  # two gross outliers among 40 rows
    v = read_verdict(_fit({}, residual=z))
    assert v.verdict == "inadequate" and not v.recorded
    assert v.p_value == pytest.approx(chi2.sf(2 * 24.0 ** 2, N - 2), rel=1e-9, abs=0)
    assert v.outlier_ids == ("s-07", "s-31")
    # the threshold has a 5 % false-alarm rate over 40 rows (Bonferroni, two-sided)
    assert f"{norm.isf(VERDICT_LEVEL / (2 * N)):.3g}" in v.outlier_threshold_text
    clean = read_verdict(_fit({}, residual=np.where(np.arange(N) % 2, 1.0, -1.0)))
    assert clean.verdict == "adequate" and clean.outlier_ids == ()
    bare = xr.Dataset({"zeta_hertz": 0.5})
    assert read_verdict(bare).verdict == "verdict not recorded"
    unweighted = _fit({}, residual=z).assign_attrs(weighting="unweighted")
    assert read_verdict(unweighted).verdict == "no stated uncertainties"


def test_summary_of_an_adequate_fit_has_no_rejection_note():
    lay = Layout("Report")
    analyst.summary_section(lay, _fit({**VERDICT_ATTRS, "verdict": "adequate", "outlier_ids": "",
                                       "misfit_description": "", "interval_note": ""}))
    text = " ".join(" ".join(t.get_text().split()) for p in lay.pages for t in p.figure.texts)
    assert "Verdict: adequate" in text and "rejected" not in text.lower()
    assert "No row's residual is improbable" in text
