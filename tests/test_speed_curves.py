"""The posterior's speed curves (microimpact.analysis.speed_curves) against the per-row model.

The unit tests use an analytic model of the groups (no emulator, milliseconds); the likelihood tests
force the curves onto the bundled 100-row data (``MIN_ROWS = 0``; by default a radius needs 400 rows)
and compare them with the per-row path of the same likelihood."""

from __future__ import annotations

import numpy as np
import pytest

from microimpact.analysis import posterior, speed_curves
from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.speed_curves import SpeedCurves, chebyshev_matrices
from microimpact.io import default_materials_path, read_impacts, read_materials
from pathlib import Path

BUNDLED = Path(__file__).resolve().parents[1] / "data" / "synthetic_microspheres.csv"


def _model(zh, za, y0, per):
    """An analytic e_n of the groups with the ring law's shape: a root at y0 = 1 + C2 (capture)."""
    yc = 1.0 + za[:, None] * per
    return np.sqrt(np.clip(1.0 - yc / y0, 0.0, None)) * np.exp(-zh[:, None] * per * np.log(y0))


def _curves(n_rows=2000, seed=1, tol=1e-9, evaluate=_model, slowest=1.65):
    """Curves of one radius over rows with speeds ``slowest`` to 100 (groups y0 = v, per = v^-1/5)."""
    rng = np.random.default_rng(seed)
    v = np.geomspace(slowest, 100.0, n_rows)
    ref = (0.2, 0.5)
    sigma = rng.uniform(0.003, 0.02, n_rows)
    e = _model(np.array([ref[0]]), np.array([ref[1]]), v[None, :], v[None, :] ** -0.2)[0] + sigma * rng.standard_normal(n_rows)
    pole = 1.0 + ref[1] * 1.5 ** -0.2  # about the capture speed at the reference (v = 1.5)
    return SpeedCurves([1.0], [np.arange(n_rows)], v, e, sigma, [pole], lambda i, s: (s, s ** -0.2), evaluate, ref,
                       tol), v, e, sigma


def test_nested_pair_is_exact_for_polynomials_and_measures_the_error_of_the_coarse_one():
    x, M, D = chebyshev_matrices(6)
    p = np.polynomial.chebyshev.Chebyshev([0.3, -1.0, 0.5, 0.25, 0.1, -0.2, 0.05])  # degree 6 = n
    assert np.abs(D @ p(x)).max() < 1e-13  # p_n reproduces a degree-n polynomial: no difference
    assert np.allclose(M @ p(x), np.pad(p.coef, (0, 6)), atol=1e-13)  # and p_2n its coefficients
    f = np.exp(3 * x)
    coarse = np.polynomial.chebyshev.chebfit(x[0::2], f[0::2], 6)  # p_6 by least squares on its own nodes
    assert np.allclose(D @ f, np.polynomial.chebyshev.chebval(x[1::2], coarse) - f[1::2], atol=1e-12)


def test_sum_of_squares_from_moments_is_the_sum_over_the_rows():
    curves, v, e, sigma = _curves()
    zh, za = np.array([0.2, 0.21, 0.18]), np.array([0.5, 0.49, 0.52])
    c, ok = curves.coefficients(zh, za)
    assert ok.all()
    rows, vals = curves.values(c)[0]
    direct = np.sum(((vals - e[rows]) / sigma[rows]) ** 2, axis=1)
    # equal to the rounding of sums of ~2000 terms of ~1e3 (chi-square ~ 2000 at the reference)
    assert np.allclose(curves.sum_of_squares(c)[:, 0], direct, rtol=1e-10, atol=1e-8)
    exact = _model(zh, za, v[rows][None, :], v[rows][None, :] ** -0.2)
    assert np.abs(vals - exact).max() <= curves.tol  # the interpolant meets its stated tolerance


def test_a_curve_that_misses_its_tolerance_is_refused():
    curves, v, *_ = _curves()
    # a walker whose capture speed lies above the slowest rows: its nodes there are captured
    _, ok = curves.coefficients(np.array([0.2, 0.2]), np.array([0.5, 0.9]))
    assert ok.tolist() == [[True], [False]]
    kinked = lambda zh, za, y0, per: _model(zh, za, y0, per) + 1e-6 * (y0 > 20.0)  # noqa: E731  a 1e-6 step
    assert _curves(evaluate=kinked)[0].n_curves == 0  # no piece meets 1e-9 across a step: no curve


def test_rows_near_capture_and_small_radii_keep_the_per_row_model(monkeypatch):
    pole = 1.0 + 0.5 * 1.5 ** -0.2
    curves, v, *_ = _curves(slowest=1.001 * pole)
    near = v < (1 + speed_curves.NEAR_CAPTURE) * pole
    assert near.sum() > 0 and curves.curve_rows.size == int(np.sum(~near))
    assert _curves(n_rows=speed_curves.MIN_ROWS - 1)[0].n_curves == 0


@pytest.fixture(scope="module")
def bundled():
    material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    table = read_impacts(BUNDLED, materials=default_materials_path())
    return table, fit_damping(table, material, confidence_intervals=False)


def _likelihoods(table, fit, monkeypatch, **kw):
    monkeypatch.setattr(speed_curves, "MIN_ROWS", 0)
    fast = posterior._Likelihood(fit, table, None, "auto", 1e-8, method="emulator", **kw)
    rowwise = posterior._Likelihood(fit, table, None, "auto", 1e-8, method="emulator", **kw)
    rowwise._speed_curves = None
    return fast, rowwise


@pytest.mark.parametrize("likelihood", ["normal", "student-t"])
def test_curve_likelihood_is_the_per_row_one_on_the_bundled_data(bundled, monkeypatch, likelihood):
    table, fit = bundled
    fast, rowwise = _likelihoods(table, fit, monkeypatch, likelihood=likelihood)
    assert fast._curves().n_curves == 4  # every radius of the bundled data on a curve
    rng = np.random.default_rng(3)
    v = fit.values
    p = {"zeta_hertz": v["zeta_hertz"] * (1 + 0.02 * rng.standard_normal(16)),
         "zeta_adhesion": v["zeta_adhesion"] * (1 + 0.02 * rng.standard_normal(16)),
         "work_of_adhesion": np.full(16, v["work_of_adhesion"])}
    # 100 rows, model errors <= 5e-8 and residuals <= a few sigma ~ 1e-2: |dlogL| <~ 100 x 5e-8 x 3 / 1e-2
    assert np.abs(fast.many(p) - rowwise.many(p)).max() < 2e-3


def test_curves_cost_does_not_grow_with_the_rows(bundled, monkeypatch):
    table, fit = bundled
    fast, _ = _likelihoods(table, fit, monkeypatch)
    curves = fast._curves()
    seen = []
    emulated = fast._emulated
    monkeypatch.setattr(fast, "_emulated", lambda zh, za, wa, y0, per: seen.append(y0.size) or emulated(zh, za, wa, y0, per))
    v = fit.values
    fast.many({n: np.full(8, v[n]) for n in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion")})
    nodes = sum(b.shape[0] for b in curves.pieces) * (2 * speed_curves.HALF_DEGREE + 1)
    # the nodes of every walker, and the rows on no curve (here: none below the capture margin)
    assert sum(seen) == 8 * (nodes + fast._rowwise.size)


@pytest.mark.extended
def test_chains_with_the_same_seed_take_the_same_decisions(bundled, monkeypatch):
    table, fit = bundled
    monkeypatch.setattr(speed_curves, "MIN_ROWS", 0)
    a = posterior.sample_posterior(table, fit, steps=300, require_convergence=False)
    monkeypatch.setattr(speed_curves, "MIN_ROWS", 10**9)
    b = posterior.sample_posterior(table, fit, steps=300, require_convergence=False)
    assert np.array_equal(a.chain, b.chain)  # positions follow from the seed and the accept decisions only
    assert np.abs(a.log_probability - b.log_probability).max() < 2e-3


def test_certified_curve_meets_its_tolerance_and_refuses_a_kink():
    """Smooth: every point certified and within tol; a capture-like root (0 below z = 1.1, sqrt
    above) is not smooth: the points of the piece holding it are refused, the others still meet
    tol, the wholly captured ones exactly 0 (a wrong estimate, split or piece lookup breaks one)."""
    z = np.linspace(0.0, 4.0, 5000)
    smooth = lambda t: 0.9 - 0.3 * np.exp(-t) + 0.01 * np.sin(3.0 * t)  # noqa: E731
    v, ok = speed_curves.certified_curve(smooth, z, 1e-9)
    assert ok.all() and np.abs(v - smooth(z)).max() <= 1e-9
    root = lambda t: np.sqrt(np.clip(t - 1.1, 0.0, None))  # noqa: E731
    z = np.sort(np.append(z, 1.1 + 1e-5))  # a point just above the root
    v, ok = speed_curves.certified_curve(root, z, 1e-7)
    assert not ok[z == 1.1 + 1e-5].any()  # the kink's piece (halved around it) is refused
    assert ok.mean() > 0.99 and ok[z < 1.0].all()  # ... and only it; captured pieces pass
    assert np.abs(v[ok] - root(z[ok])).max() <= 1e-7
