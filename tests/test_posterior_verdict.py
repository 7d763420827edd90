"""The posterior carries the verdict of its fit (issue 51 item 1): ``verdict``, ``verdict_text`` and
``p_value`` in post.nc, and "conditional on a rejected model" where the fit's model is rejected."""

from __future__ import annotations

import dataclasses

import pytest
import xarray as xr

from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.posterior import CONDITIONAL_ON_REJECTED, Posterior, sample_posterior
from microimpact.analysis.synthetic import write_synthetic_impacts
from microimpact.analysis.verdict import ADEQUATE, INADEQUATE
from microimpact.io import default_materials_path, read_impacts, read_materials


@pytest.fixture(scope="module")
def six(tmp_path_factory):
    material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    path = write_synthetic_impacts(tmp_path_factory.mktemp("pv") / "six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    table = read_impacts(path)
    return table, fit_damping(table, material, confidence_intervals=False)


def _rejected(fit):
    """The fit with its residuals 20 times larger: the chi-square test rejects it (the likelihood
    reads the data and uncertainties, not the residuals, so the chain is the same)."""
    d = fit.data.copy()
    d["residual"] = 20 * d["residual"]
    return dataclasses.replace(fit, data=d)


def _chain(table, fit):  # short and not converged: only what the posterior says of itself is tested
    return sample_posterior(table, fit, walkers=8, steps=40, require_convergence=False)


def test_posterior_of_an_adequate_fit_carries_its_verdict(six, tmp_path):
    table, fit = six
    assert fit.verdict.verdict == ADEQUATE  # else this test tests nothing
    post = _chain(table, fit)
    path = post.save(tmp_path / "post.nc")
    with xr.open_dataset(path) as ds:
        assert ds.attrs["verdict"] == ADEQUATE
        assert ds.attrs["verdict_text"] == fit.verdict.text()
        assert ds.attrs["p_value"] == pytest.approx(fit.verdict.p_value, rel=1e-12)
        assert CONDITIONAL_ON_REJECTED not in str(ds.attrs.get("comment", ""))
    back = Posterior.load(path)
    assert not back.rejected and CONDITIONAL_ON_REJECTED not in back.report()
    assert f"verdict     : the fit's: {fit.verdict.text()}" in back.report()


def test_posterior_of_a_rejected_fit_says_it_is_conditional(six, tmp_path):
    table, fit = six
    bad = _rejected(fit)
    assert bad.verdict.verdict == INADEQUATE
    post = _chain(table, bad)
    path = post.save(tmp_path / "post.nc")
    with xr.open_dataset(path) as ds:
        assert ds.attrs["verdict"] == INADEQUATE
        assert ds.attrs["p_value"] == pytest.approx(bad.verdict.p_value, rel=1e-12) and ds.attrs["p_value"] < 1e-3
        assert CONDITIONAL_ON_REJECTED in ds.attrs["comment"]
    back = Posterior.load(path)
    assert back.rejected and CONDITIONAL_ON_REJECTED in back.report()
    assert bad.verdict.text() in back.report()


def test_posterior_states_its_likelihood(six):
    table, fit = six
    post = sample_posterior(table, fit, walkers=8, steps=40, require_convergence=False, likelihood="student-t", nu=3)
    ds = post.to_dataset()
    assert ds.attrs["likelihood"].startswith("student-t (nu = 3,") and ds.attrs["student_t_nu"] == 3.0
    assert "likelihood  : student-t (nu = 3," in post.report()
    assert _chain(table, fit).to_dataset().attrs["likelihood"] == "normal"
    with pytest.raises(ValueError, match="likelihood must be one of normal, student-t"):
        sample_posterior(table, fit, walkers=8, steps=40, likelihood="cauchy")
    with pytest.raises(ValueError, match="nu .* must be a finite number > 0"):
        sample_posterior(table, fit, walkers=8, steps=40, likelihood="student-t", nu=0.0)
