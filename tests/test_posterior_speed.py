"""The posterior's emulated likelihood (method="emulator") against the solver's (method="solve").

The fixture (a fit of six impacts and a small table, ~7 s) puts the tests that use it in the extended stage;
the method as an option of the fit and the CLI is tested in the default run."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from microimpact.analysis.analyst_fit import _posterior_options
from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.posterior import DEFAULT_METHOD, _Likelihood, sample_posterior
from microimpact.cli import main
from microimpact.analysis.synthetic import write_synthetic_impacts
from microimpact.io import default_materials_path, read_impacts, read_materials
from microimpact.model import reduction
from microimpact.solvers import emulator as em
from microimpact.solvers import ring_groups_batch

#: a small box of groups about the six impacts' (C1 2e-3 to 4e-3, C2 0.09 to 0.2): a table that builds
#: in seconds; the impacts outside it go to the fallback solves, which the test covers as well
BOX = {"hertz_damping": (2e-3, 4e-3), "adhesion_damping": (0.1, 0.2), "incident_speed": (1e-2, 1e2)}
#: the table's absolute e_n tolerance in these tests
TOL = 1e-3


@pytest.fixture(scope="module")
def six(tmp_path_factory, private_emulator_cache):
    material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    path = write_synthetic_impacts(tmp_path_factory.mktemp("d") / "six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    table = read_impacts(path)
    fit = fit_damping(table, material, confidence_intervals=False)
    em.ring_emulator(TOL, BOX)
    like = _Likelihood(fit, table, None, "auto", 1e-10, method="emulator", tol=TOL)
    like.domain = BOX
    like.model(dict(fit.values))  # the table's kernels loaded before the tests
    return table, fit


def _pair(table, fit):
    solve = _Likelihood(fit, table, None, "auto", 1e-10, method="solve")
    emulated = _Likelihood(fit, table, None, "auto", 1e-10, method="emulator", tol=TOL)
    emulated.domain = BOX
    return solve, emulated


@pytest.mark.extended
def test_emulated_model_meets_its_tolerance_at_random_points(six):
    table, fit = six
    solve, emulated = _pair(table, fit)
    rng = np.random.default_rng(5)
    base = dict(fit.values)
    decided = 0
    for z_h, z_a in zip(rng.uniform(0.3, 0.7, 6), rng.uniform(27.0, 31.0, 6)):
        p = base | {"zeta_hertz": float(z_h), "zeta_adhesion": float(z_a)}
        a, b = solve.model(p), emulated.model(p)
        # the table's error estimate is below TOL; the solves at rtol 1e-10 are exact on that scale
        assert np.max(np.abs(a - b)) <= TOL
        # log-likelihoods: every row moves by at most |z| TOL / sigma + (TOL / sigma)^2 / 2
        z = (a - solve.e) / solve.sig_eff
        bound = float(np.sum(np.abs(z) * TOL / solve.sig_eff + 0.5 * (TOL / solve.sig_eff) ** 2))
        assert abs(solve(p) - emulated(p)) <= bound
        decided += int(np.sum(np.abs(a - b) > 0))
    assert decided > 0  # some points came from the table, not all from the fallback


@pytest.mark.extended
def test_emulated_model_is_the_solver_where_it_falls_back(six):
    table, fit = six
    solve, emulated = _pair(table, fit)
    emulated.domain = {"hertz_damping": (1e-1, 2e-1), "adhesion_damping": (5.0, 10.0), "incident_speed": (1e-2, 1e2)}
    p = dict(fit.values)
    with pytest.MonkeyPatch.context() as mp:  # a box that holds no impact: no table is needed, every point is solved
        mp.setattr(em.RingEmulator, "evaluate", lambda self, y0, c1, c2, tol: (np.zeros(y0.shape), np.zeros(y0.shape, bool),
                                                                                 np.ones(y0.shape, bool)))
        mp.setattr(em, "ring_emulator", lambda tol, domain=None: em.RingEmulator.__new__(em.RingEmulator))
        b = emulated.model(p)
    # the fallback solves at rtol tol / 100 and the reference at 1e-10: they differ by ~1e-5 at most
    assert np.max(np.abs(solve.model(p) - b)) <= 10 * TOL * em.FALLBACK_RTOL


@pytest.mark.extended
def test_groups_of_many_work_of_adhesion_values_are_the_contacts_own(six):
    # the walkers' groups come from the fit's by powers of w_A (_speed_groups_many); built from a
    # contact at each w_A they must agree to rounding (a few ulps: the powers and the scales differ
    # in the order of their products)
    table, fit = six
    like = _Likelihood(fit, table, None, "auto", 1e-10, method="emulator", tol=TOL)
    w = fit.values["work_of_adhesion"] * np.array([0.2, 1.0, 1.3, 4.0])
    y0, per = like._speed_groups_many(w)
    pr = like.problem
    for k, wk in enumerate(w):
        for r, idx in zip(pr.radii, pr.groups):
            y, c1, c2 = reduction.ring_groups([pr.contact(r, 1.0, 2.0, float(wk))], pr.normal_speed[idx][None, :])
            np.testing.assert_allclose(y0[k, idx], y[0], rtol=1e-13)
            np.testing.assert_allclose(per[k, idx], c1[0], rtol=1e-13)
            np.testing.assert_allclose(2.0 * per[k, idx], c2[0], rtol=1e-13)
    assert like._speed_groups_many(np.array([0.0])) is None  # no adhesion: not the ring law, the solver


@pytest.mark.extended
def test_the_likelihood_of_many_walkers_is_each_walkers_own(six):
    # emcee's vectorized call (one table lookup for all walkers) against one call per walker: the
    # same numbers, bit for bit where w_A is the fit's, to rounding of the groups elsewhere
    table, fit = six
    like = _Likelihood(fit, table, None, "auto", 1e-10, method="emulator", tol=TOL)
    like.domain = BOX
    rng = np.random.default_rng(8)
    p = {"zeta_hertz": rng.uniform(0.3, 0.7, 5), "zeta_adhesion": rng.uniform(27.0, 31.0, 5),
         "work_of_adhesion": np.full(5, fit.values["work_of_adhesion"]), "friction": np.full(5, 0.3)}
    many = like.many(p)
    one = [like({n: v[k] for n, v in p.items()}) for k in range(5)]
    np.testing.assert_array_equal(many, one)
    p["work_of_adhesion"] = p["work_of_adhesion"] * rng.uniform(0.9, 1.1, 5)
    np.testing.assert_allclose(like.many(p), [like({n: v[k] for n, v in p.items()}) for k in range(5)], rtol=1e-12)


def test_fallback_of_many_contacts_is_each_contacts_own():
    # the posterior's fallback for all walkers at once (one engine call over their groups) against
    # emulator.fallback_restitution of each contact: both solve to e_n within tol (rtol tol / 100,
    # tighter near capture), so they differ by far less than tol; captures (e_n = 0) agree exactly
    from microimpact.model.parameters import TABLE1_ROW2
    rng = np.random.default_rng(3)
    contacts = [TABLE1_ROW2.with_(zeta_hertz=float(zh), zeta_adhesion=float(za), radius=float(r))
                for zh, za, r in zip(rng.uniform(0.0, 2.0, 6), rng.uniform(3.0, 100.0, 6), rng.uniform(0.5e-6, 1e-5, 6))]
    speeds = np.geomspace(0.05, 100.0, 7)
    y0, c1, c2 = reduction.ring_groups(contacts, np.tile(speeds, (len(contacts), 1)))
    tol = 1e-6
    got = ring_groups_batch.fallback_of_groups(y0, c1, c2, tol)
    want = np.array([em.fallback_restitution(c, speeds, tol) for c in contacts])
    assert (got == 0.0).any() and (got > 0.0).any()  # captures and rebounds both checked
    np.testing.assert_array_equal(got == 0.0, want == 0.0)
    assert np.max(np.abs(got - want)) <= 0.5 * tol
    with pytest.raises(ValueError, match="y0 must lie in"):
        ring_groups_batch.restitution_of_groups([0.0], [1e-3], [0.1])


@pytest.mark.extended
def test_oblique_model_of_many_walkers_is_each_walkers_own(tmp_path):
    # the oblique part of the likelihood for all walkers at once (one engine call over their
    # groups, the closed-form tangential map) against oblique_model per walker: the same kernel and
    # rtol, groups to rounding, so agreement to 1e-12 relative; captures (NaN) at the same entries
    from microimpact.analysis.oblique import fit_friction, oblique_model
    from microimpact.analysis.posterior import PARAMETER_NAMES, _contact
    from microimpact.analysis.synthetic import make_synthetic_oblique
    from microimpact.io import write_csv
    material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    data = make_synthetic_oblique(radii=(3.45e-6,), speeds=(2.0, 15.0), incidence_deg=(20.0, 50.0, 70.0))
    table = read_impacts(write_csv(data, tmp_path / "oblique.csv"))
    fit = fit_damping(table, material, fit_work_of_adhesion=True, confidence_intervals=False)
    ff = fit_friction(table, fit)
    like = _Likelihood(fit, table, ff, "auto", 1e-8, method="emulator")
    rng = np.random.default_rng(4)
    p = {n: fit.values[n] * rng.uniform(0.7, 1.4, 6) for n in PARAMETER_NAMES} | {"friction": rng.uniform(0.05, 1.0, 6)}
    p["zeta_adhesion"][0] = 500.0  # a walker whose slow impacts are captured
    many = like._oblique_many(p)
    one = np.array([oblique_model(like.oblique, lambda r, j=j: _contact(fit, r, {n: p[n][j] for n in PARAMETER_NAMES}),
                                  {"friction": p["friction"][j]}) for j in range(6)])
    np.testing.assert_array_equal(np.isnan(many), np.isnan(one))
    assert np.isnan(one[0]).any() and np.isfinite(one).sum() >= 12
    np.testing.assert_allclose(many[np.isfinite(one)], one[np.isfinite(one)], rtol=1e-12)


def test_method_is_checked():
    with pytest.raises(ValueError, match="method must be one of emulator, solve"):
        _Likelihood(None, None, None, "auto", 1e-8, method="table")


@pytest.mark.extended
def test_posterior_medians_agree_between_methods(six):
    table, fit = six
    a = sample_posterior(table, fit, walkers=8, steps=40, require_convergence=False, method="solve")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(_Likelihood, "__init__", _boxed(_Likelihood.__init__))
        b = sample_posterior(table, fit, walkers=8, steps=40, require_convergence=False, method="emulator",
                             emulator_tol=TOL)
    assert b.info["method"] == f"emulator (tol {TOL:g})" and a.info["method"] == "solve"
    for name in a.names:
        # same seed, likelihoods within ~0.01 of each other: the chains' medians within a tenth of the spread
        spread = np.std(a.samples[:, a.names.index(name)])
        assert abs(a.median()[name] - b.median()[name]) <= 0.1 * spread


def _boxed(init):
    def wrapped(self, *args, **kwargs):
        init(self, *args, **kwargs)
        self.domain = BOX
    return wrapped


# ------------------------------------------------------------------ the method as an option of the fit and the CLI
def test_the_analyst_fit_takes_the_method_and_checks_it():
    assert _posterior_options(True)["method"] == DEFAULT_METHOD == "emulator"
    assert _posterior_options({"method": "solve", "walkers": 8})["method"] == "solve"
    assert _posterior_options({"method": None})["method"] == DEFAULT_METHOD
    with pytest.raises(ValueError, match="method must be one of emulator, solve, got 'table'"):  # the sampler's check
        _Likelihood(None, None, None, "auto", 1e-8, method=_posterior_options({"method": "table"})["method"])


def test_posterior_method_without_posterior_is_refused(tmp_path, capsys):
    path = write_synthetic_impacts(tmp_path / "six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    out = tmp_path / "fit.nc"
    assert main(["fit", str(path), "--out", str(out), "--posterior-method", "solve"]) == 2
    assert "--posterior-method" in capsys.readouterr().err and not out.exists()
    assert main(["fit", str(path), "--out", str(out), "--posterior", str(tmp_path / "p.nc"),
                 "--posterior-method", "table"]) == 2
    assert "--posterior-method: invalid choice: 'table'" in capsys.readouterr().err and not out.exists()


@pytest.mark.extended
def test_cli_posterior_uses_the_shipped_table_and_records_it(tmp_path, capsys):
    """The default chain run to convergence on six impacts through the CLI, the likelihood emulated
    from the shipped table: the JSON summary and the posterior file say so."""
    path = write_synthetic_impacts(tmp_path / "six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    out, post = tmp_path / "fit.nc", tmp_path / "post.nc"
    assert main(["fit", str(path), "--out", str(out), "--posterior", str(post), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["posterior"]["converged"] is True
    assert summary["posterior"]["method"] == "emulator (tol 1e-06)"
    with xr.open_dataset(post) as ds:
        assert ds.attrs["likelihood_method"] == "emulator (tol 1e-06)"
