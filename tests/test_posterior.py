"""Posterior of the fitted parameters (issue 15, items 2, 3 and 8): emcee (run until converged), seeded,
with diagnostics; bands; errors in variables (their calibration: tests/test_calibration.py).

The data are the bundled SYNTHETIC microsphere file (data/README.md) and small synthetic sets.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from microimpact.analysis.fitting import FitProblem, fit_damping, model_restitution
from microimpact.analysis.posterior import (GAUSS_HERMITE_NODES, Posterior, PosteriorError, _Likelihood, capture_velocity_interval,
                                            restitution_bands, sample_posterior, sweep_bands)
from microimpact.analysis.synthetic import make_synthetic_impacts
from microimpact.io import default_materials_path, read_impacts, read_materials
from microimpact.io.files import write_csv, write_netcdf

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def pair():
    return read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]


@pytest.fixture(scope="module")
def small(tmp_path_factory, pair):
    """A 24-point synthetic data set, its fit and a short seeded chain."""
    path = tmp_path_factory.mktemp("post") / "small.csv"
    write_csv(make_synthetic_impacts(seed=5, radii=(1.29e-6, 3.45e-6), n_per_radius=12), path, float_format="%.6g")
    table = read_impacts(path)
    fit = fit_damping(table, pair, confidence_intervals=False)
    return table, fit, sample_posterior(table, fit, walkers=8, steps=120, seed=11, require_convergence=False)


def test_a_fit_outside_the_prior_is_refused_naming_the_parameter(small):
    # a calibration design's least squares put zeta_A at 1.8e5, beyond the prior's [0, 1e4]: the
    # walkers, clipped onto the edge, were not linearly independent and emcee raised a ValueError
    table, fit, _ = small
    beyond = dataclasses.replace(fit, values=dict(fit.values) | {"zeta_adhesion": 1.8e5})
    with pytest.raises(PosteriorError, match=r"zeta_adhesion = 180000 outside \[0, 10000\]"):
        sample_posterior(table, beyond, walkers=8, steps=20, seed=11, require_convergence=False)


def test_seeded_chain_is_reproducible(small):
    table, fit, post = small
    again = sample_posterior(table, fit, walkers=8, steps=120, seed=11, require_convergence=False)
    np.testing.assert_array_equal(post.chain, again.chain)  # same seed: bit-identical chain
    other = sample_posterior(table, fit, walkers=8, steps=20, seed=12, require_convergence=False)
    assert not np.array_equal(post.chain[:20], other.chain)


def test_diagnostics_are_present_and_sane(small):
    _, fit, post = small
    assert post.chain.shape == (120, 8, 2)
    assert post.names == ("zeta_hertz", "zeta_adhesion")
    # emcee's differential-evolution moves on a near-Gaussian 2-D posterior accept 0.2-0.9 of their
    # proposals; all accepted or all refused would mean a broken likelihood
    assert 0.2 < post.acceptance_fraction.mean() < 0.9
    for name in post.names:
        assert 1.0 <= post.autocorr_time[name] < 60.0, name
    # 80 post-burn-in steps of tau ~ 5-20 cannot pass the 50 tau rule: the record says so
    assert post.converged is False and "NOT converged" in post.info["convergence"]


def test_posterior_agrees_with_least_squares(small):
    # a near-linear model with flat priors: the posterior median is within 0.5 standard errors of
    # the least-squares value and the 95 % interval is 2 x 1.96 se within 30 % (a short chain)
    _, fit, post = small
    for name in post.names:
        lo, hi = post.interval(name)
        assert abs(post.median()[name] - fit.values[name]) < 0.5 * fit.stderr[name], name
        assert (hi - lo) == pytest.approx(2 * 1.96 * fit.stderr[name], rel=0.3), name


def test_dataset_is_cf_clean_and_round_trips(small, tmp_path):
    _, fit, post = small
    ds = post.to_dataset(restitution_bands(post, fit, n_draws=8), capture_velocity_interval(post, fit, n_draws=6),
                         sweep_bands(post, fit, cases=["2.1", "2.2"], n_draws=4, n_speeds=5))
    for name, var in ds.variables.items():
        if var.dtype.kind in "fiu" and name not in ("step", "walker", "point", "case"):
            assert "units" in var.attrs and "long_name" in var.attrs, name
    path = write_netcdf(ds, tmp_path / "posterior.nc")
    back = Posterior.load(path)
    np.testing.assert_array_equal(back.chain, post.chain)
    assert back.interval("zeta_adhesion") == post.interval("zeta_adhesion")


def test_bands_contain_the_best_fit_and_capture_interval_brackets_it(small):
    from microimpact.dynamics.nonlinear import capture_velocity

    _, fit, post = small
    bands = restitution_bands(post, fit, n_draws=16)
    r = fit.radii[-1]
    band = bands["e_n_band"].sel(radius=r)
    v = bands["band_speed"].values
    best = model_restitution(FitProblem.from_arrays(np.full(v.size, r), v, fit), fit.zeta_hertz, fit.zeta_adhesion,
                             fit.work_of_adhesion)
    lo, hi = band.sel(quantile=0.025).values, band.sel(quantile=0.975).values
    # the best fit lies inside the posterior band at 90 % of the speeds (16 draws: the band's edges are noisy)
    assert np.mean((best >= lo - 1e-9) & (best <= hi + 1e-9)) > 0.9
    cv = capture_velocity_interval(post, fit, n_draws=16)["capture_velocity_quantile"].sel(radius=r)
    v_best = capture_velocity(fit.contact(r))
    assert float(cv.sel(quantile=0.025)) <= v_best * 1.001 and v_best * 0.999 <= float(cv.sel(quantile=0.975))


def test_latent_speed_quadrature_equals_effective_variance_for_a_linear_model():
    # the latent-speed likelihood integrates N(e | m(u), s_e) N(u | v, s_v) du; for a model linear
    # in u this is exactly the effective-variance Gaussian N(e | m(v), sqrt(s_e^2 + (m' s_v)^2)):
    # Gauss-Hermite with 9 nodes integrates it to round-off
    x, w = np.polynomial.hermite.hermgauss(GAUSS_HERMITE_NODES)
    slope, v, sv, se, e = 0.02, 5.0, 0.3, 0.01, 0.115
    u = v + math.sqrt(2) * sv * x
    quad = np.sum(w / math.sqrt(math.pi) * np.exp(-0.5 * ((slope * u - e) / se) ** 2)) / (se * math.sqrt(2 * math.pi))
    s = math.hypot(se, slope * sv)
    exact = math.exp(-0.5 * ((slope * v - e) / s) ** 2) / (s * math.sqrt(2 * math.pi))
    assert quad == pytest.approx(exact, rel=1e-3)  # 9 nodes on a Gaussian of relative width 0.9: 1e-3


def test_auto_picks_latent_speeds_near_capture(pair, tmp_path):
    # large speed errors near the capture velocity: the tangent line misstates the likelihood there
    path = tmp_path / "near_capture.csv"
    write_csv(make_synthetic_impacts(seed=3, radii=(3.45e-6,), n_per_radius=10, start_factor=1.02, max_speed=20.0,
                                     speed_rel_sd=0.05), path, float_format="%.6g")
    table = read_impacts(path)
    fit = fit_damping(table, pair, confidence_intervals=False)
    like = _Likelihood(fit, table, None, "auto", 1e-8)
    assert like.latent[:2].all()  # the slowest rows: within 3 sigma_v of capture
    assert not like.latent[-1]  # the fastest: e_n flat, effective variance suffices
    assert not _Likelihood(fit, table, None, "effective", 1e-8).latent.any()
    assert _Likelihood(fit, table, None, "latent", 1e-8).latent.all()
    post = sample_posterior(table, fit, walkers=8, steps=30, seed=1, require_convergence=False)
    assert "latent true speed" in post.info["errors_in_variables"] and post.info["latent_rows"]
