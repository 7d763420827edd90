"""The DEM law fits' one interval (95 % profile likelihood, its standard error width / 3.92) and
their verdict (microimpact.analysis.verdict), against closed forms.

LAMMPS's ``coeff_restitution`` with Hertz gives e_n = e at every speed (to the solver's rtol 1e-8,
hence abs=5e-8 below), so chi^2(e) = sum ((e_i - e) / sigma)^2: its minimum is the mean, and its
95 % profile interval is the mean +- 1.959964 sigma / sqrt(n) (stated sigma) or +- t s / sqrt(n)
with the Student quantile t of n - 1 degrees of freedom and s the sample standard deviation (scatter
estimated). A 68 % interval, or the normal z in place of t, fails these.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from microimpact.analysis.dem_fit import INTERVAL_LEVEL, fit_dem_law, rank_dem_laws

HERTZ = {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0}
Z95 = 1.959963984540054  # the two-sided 95 % standard normal quantile


def _table(e, sigma=0.01, ids=None, speed=None):
    e = np.asarray(e, float)
    speed = np.geomspace(0.5, 8.0, e.size) if speed is None else np.asarray(speed, float)
    t = pd.DataFrame({"radius": 3e-6, "normal_speed": speed, "e_n": e})
    if sigma is not None:
        t["e_n_uncertainty"] = sigma
    if ids is not None:
        t["id"] = ids
    return t


def test_the_interval_is_the_95_percent_profile_and_the_stderr_its_width_over_3_92():
    e = np.array([0.611, 0.624, 0.598, 0.613, 0.604, 0.617])
    f = fit_dem_law(_table(e), HERTZ, "hertz", "coeff_restitution")
    half = Z95 * 0.01 / math.sqrt(e.size)
    assert INTERVAL_LEVEL == 0.95
    assert f.status == "determined" and f.value == pytest.approx(e.mean(), abs=5e-8)
    assert f.interval == pytest.approx((e.mean() - half, e.mean() + half), abs=5e-8)
    assert f.stderr == pytest.approx(0.01 / math.sqrt(e.size), abs=5e-8)  # width / 3.92: sigma / sqrt(n)
    assert "(standard error 0.00408; 95% interval" in f.describe()
    ds = f.to_dataset()
    assert float(ds["damping_coefficient_stderr"]) == f.stderr and ds.attrs["interval_level"] == 0.95
    assert ds.attrs["verdict"] == "adequate"


def test_with_the_scatter_estimated_the_interval_uses_the_student_quantile():
    e = np.array([0.61, 0.64, 0.58, 0.63, 0.60])
    f = fit_dem_law(_table(e, sigma=None), HERTZ, "hertz", "coeff_restitution", weights="none")
    half = stats.t.ppf(0.975, e.size - 1) * e.std(ddof=1) / math.sqrt(e.size)
    assert f.interval == pytest.approx((e.mean() - half, e.mean() + half), abs=5e-8)
    assert f.stderr == pytest.approx(half / Z95, abs=5e-8)
    v = f.verdict
    assert v.verdict == "no stated uncertainties" and "judged against the scatter" in v.text()


def test_every_dem_fit_carries_its_verdict_with_chi_square_dof_and_p():
    """Adequate: the chi-square test's numbers are scipy's; rejected: e_n rising with speed against a
    constant e (p < 1e-3), no value printed, p stated; an outlier is named by the CSV's id."""
    e = np.array([0.611, 0.624, 0.598, 0.613, 0.604, 0.617])
    f = fit_dem_law(_table(e), HERTZ, "hertz", "coeff_restitution")
    chi2 = float(np.sum(((e - e.mean()) / 0.01) ** 2))
    v = f.verdict
    assert (v.verdict, v.degrees_of_freedom) == ("adequate", 5.0)
    assert v.chi_square == pytest.approx(chi2, rel=1e-6, abs=0)
    assert v.p_value == pytest.approx(stats.chi2.sf(chi2, 5), rel=1e-5, abs=0)
    assert f.record()["verdict"]["verdict"] == "adequate"
    rising = np.array([0.2, 0.4, 0.6, 0.7, 0.8])
    g = fit_dem_law(_table(rising), HERTZ, "hertz", "coeff_restitution")
    chi2 = float(np.sum(((rising - rising.mean()) / 0.01) ** 2))
    assert g.status == "inadequate" and g.verdict.rejected and math.isnan(g.value)
    assert g.verdict.degrees_of_freedom == 4 and g.verdict.chi_square == pytest.approx(chi2, rel=1e-6, abs=0)
    assert f"chi^2/dof = {chi2 / 4:.4g}" in g.describe() and ("p = " in g.describe() or "p < 1e-300" in g.describe())
    assert g.verdict.misfit_description.startswith("systematic: 5 rows beyond the outlier threshold")  # all off
    assert g.to_dataset().attrs["verdict"] == "inadequate"
    ranked, _ = rank_dem_laws(_table(rising), HERTZ, [("hertz", "coeff_restitution")])
    assert ranked["verdict"].iloc[0] == "inadequate" and ranked["chisqr_per_dof"].iloc[0] == pytest.approx(chi2 / 4, rel=1e-6, abs=0)
    outlier = np.array([0.611, 0.624, 0.598, 0.613, 0.604, 0.617, 0.611, 0.72, 0.604, 0.617])
    h = fit_dem_law(_table(outlier, ids=[f"m{i}" for i in range(10)]), HERTZ, "hertz", "coeff_restitution")
    assert h.verdict.outlier_ids == ("m7",)


def test_a_rejected_law_is_described_as_the_closest_with_its_largest_errors_per_radius():
    """The closest-law text of a rejected constant e: the least chi^2 at the mean, the interval
    widened by sqrt(chi^2 / dof) and, per radius, the largest model - measured e_n error."""
    e = np.array([0.2, 0.4, 0.6, 0.7, 0.8, 0.3, 0.62, 0.79])
    t = pd.DataFrame({"radius": [2e-6] * 5 + [4e-6] * 3, "normal_speed": [0.5, 1, 2, 4, 8, 0.5, 2, 8], "e_n": e,
                      "e_n_uncertainty": 0.01})
    g = fit_dem_law(t, HERTZ, "hertz", "coeff_restitution")
    mean = e.mean()
    chi2 = float(np.sum(((e - mean) / 0.01) ** 2))
    w = math.sqrt(chi2 / 7)
    half = Z95 * 0.01 / math.sqrt(8)
    assert g.widened_interval() == pytest.approx((mean - w * half, mean + w * half), abs=1e-6)
    small, large = g.misfit_by_size()
    assert (small["radius"], small["impacts"], small["speed_min"], small["speed_max"]) == (2e-6, 5, 0.5, 8.0)
    assert small["largest_error"] == pytest.approx(mean - 0.2, abs=1e-7) and small["speed"] == 0.5
    assert large["largest_error"] == pytest.approx(mean - 0.3, abs=1e-7) and large["speed"] == 0.5
    text = g.report()
    assert "least chi^2 : damping_coefficient" in text and "radius 2 um: 5 impacts at 0.5-8 m/s" in text
