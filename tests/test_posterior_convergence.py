"""A posterior is converged or it is an error (issue 25, part 4).

The chain runs until the 50-tau rule, R-hat < 1.01 and a bulk ESS of 400 hold, or fails with one
line; R-hat and ESS are the definitions of Vehtari et al. (2021), checked here against ArviZ on the
same draws; a parameter the data only bound is reported by that bound, not by the prior's quantiles.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from microimpact.analysis.diagnostics import ess_bulk, split_rhat
from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.oblique import fit_friction
from microimpact.analysis.posterior import MIN_ACCEPTANCE, Posterior, PosteriorError, _raise_if_collapsed, sample_posterior
from microimpact.analysis.synthetic import make_synthetic_impacts, make_synthetic_oblique
from microimpact.cli import main
from microimpact.io import default_materials_path, read_impacts, read_materials
from microimpact.io.files import write_csv

PAIR = "ammonium_fluorescein_on_silicon"


@pytest.fixture(scope="module")
def pairs():
    return read_materials(default_materials_path())


@pytest.fixture(scope="module")
def small(tmp_path_factory, pairs):
    path = tmp_path_factory.mktemp("conv") / "small.csv"
    write_csv(make_synthetic_impacts(seed=5, radii=(1.29e-6, 3.45e-6), n_per_radius=12), path, float_format="%.6g")
    table = read_impacts(path)
    return path, table, fit_damping(table, pairs[PAIR], confidence_intervals=False)


def _ar1(phi, shape, seed):
    rng = np.random.default_rng(seed)
    e = rng.normal(size=shape)
    x = np.zeros(shape)
    for t in range(1, shape[1]):
        x[:, t] = phi * x[:, t - 1] + e[:, t]
    return x


@pytest.mark.parametrize("phi, offset", [(0.0, 0.0), (0.6, 0.0), (0.95, 0.5)])
def test_rhat_and_ess_are_arviz_s(phi, offset):
    az = pytest.importorskip("arviz")
    x = _ar1(phi, (8, 801), seed=3)
    x[2] += offset  # one chain shifted: R-hat must see it
    # the same definitions on the same draws: agreement to round-off (FFT autocovariances: 1e-12)
    assert split_rhat(x) == pytest.approx(float(az.rhat(x)), rel=1e-10)
    assert ess_bulk(x) == pytest.approx(float(az.ess(x, method="bulk")), rel=1e-8)
    if offset:
        assert split_rhat(x) > 1.01


def test_an_independent_sample_has_rhat_one_and_full_ess():
    x = np.random.default_rng(0).normal(size=(4, 2000))
    assert split_rhat(x) == pytest.approx(1.0, abs=0.01)
    # iid draws: the ESS is the number of draws, within its sampling error (about 10 %)
    assert ess_bulk(x) == pytest.approx(8000, rel=0.15)


@pytest.mark.slow  # 20 s or more: `pytest -m slow` (README, Tests), not the default run
def test_default_chain_converges_and_says_so(small):
    _, table, fit = small
    post = sample_posterior(table, fit, seed=11)
    assert post.converged
    n_post = post.chain.shape[0] - post.burn
    assert n_post > 50 * max(post.autocorr_time.values())
    assert max(post.info["rhat"].values()) < 1.01 and min(post.info["ess_bulk"].values()) >= 400
    assert post.info["priors"] == {"zeta_hertz": (0.0, 1e3), "zeta_adhesion": (0.0, 1e4)}
    text = post.report()
    assert "converged (50 tau" in text and "priors      : flat" in text
    # the least-squares value lies inside the converged 95 % interval
    for name in post.names:
        lo, hi = post.interval(name)
        assert lo < fit.values[name] < hi, name
    back = post.to_dataset()
    assert back["chain_zeta_hertz"].attrs["prior_max"] == 1e3
    assert back["chain_zeta_hertz"].attrs["rhat"] == pytest.approx(post.info["rhat"]["zeta_hertz"], abs=0)


def test_a_chain_out_of_budget_is_an_error(small):
    _, table, fit = small
    with pytest.raises(PosteriorError, match=r"has not converged after 100 steps of 16 walkers .* max_steps"):
        sample_posterior(table, fit, seed=11, max_steps=100)


@pytest.mark.parametrize("acceptance, dead, tau, what", [
    (np.full(16, 0.0), 0, np.array([5.0, 5.0]), "mean acceptance 0.000"),
    (np.full(16, 0.3), 3, np.array([5.0, 5.0]), "3 walker"),
    (np.full(16, 0.3), 0, np.array([5.0, np.nan]), "no autocorrelation time for b"),
])
def test_a_collapsed_chain_is_an_error(acceptance, dead, tau, what, small):
    _, _, fit = small
    diag = {"acceptance": acceptance, "dead": dead, "tau": tau, "n_post": 400}
    with pytest.raises(PosteriorError, match=what):
        _raise_if_collapsed(diag, ["a", "b"], fit, None, 600)
    healthy = diag | {"acceptance": np.full(16, 2 * MIN_ACCEPTANCE), "dead": 0, "tau": np.array([5.0, 5.0])}
    _raise_if_collapsed(healthy, ["a", "b"], fit, None, 600)  # no error


def test_cli_refuses_an_unconverged_posterior_and_writes_nothing(small, tmp_path, capsys):
    path, _, _ = small
    out, post = tmp_path / "fit.nc", tmp_path / "post.nc"
    status = main(["fit", str(path), "--out", str(out), "--posterior", str(post), "--max-steps", "100",
                   "--no-confidence-intervals"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2
    assert err[-1].startswith("microimpact: error: the posterior has not converged after 100 steps")
    assert not out.exists() and not post.exists()
    assert main(["fit", str(path), "--out", str(out), "--posterior", str(post), "--full-chain"]) == 2
    assert "--full-chain was removed" in capsys.readouterr().err


@pytest.mark.slow  # 20 s or more: `pytest -m slow` (README, Tests), not the default run
def test_a_parameter_the_data_only_bound_is_reported_by_its_bound(tmp_path, pairs):
    # every impact rolls for f above ~0.04: the posterior above that follows the flat prior, whose
    # end (10) is arbitrary; the report gives the fit's profile bound, which holds the truth (0.6)
    path = tmp_path / "roll.csv"
    write_csv(make_synthetic_oblique(radii=(3.45e-6,), speeds=(5.0, 10.0, 20.0), incidence_deg=(5.0, 10.0, 15.0),
                                     friction=0.6, seed=3), path, float_format="%.6g")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        table = read_impacts(path, materials=pairs)
    fit = fit_damping(table, pairs[PAIR], confidence_intervals=False)
    ff = fit_friction(table, fit)
    post = sample_posterior(table, fit, ff, seed=3)
    st = ff.identifiability["friction"]
    assert post.info["status"]["friction"] == "lower_bound"
    assert post.bound("friction").startswith(f">= {st.lower:.4g}") and st.lower <= 0.6
    line = next(x for x in post.report().splitlines() if x.strip().startswith("friction"))
    assert "profile-likelihood bound" in line and "95 % [" not in line
    back = Posterior.load(post.save(tmp_path / "p.nc"))
    assert back.bound("friction") == post.bound("friction")
