"""Which rows were probably spun, and by how much: flags that explain.

For every measured impact, :func:`spin_explanation` asks two questions of the model, over the
posterior (a set of posterior draws, or the point estimate when no posterior is given):

1. **Does an unmeasured spin or angle error move the prediction by more than the measurement
   uncertainty?** The prediction is of the quantity that row MEASURED: its oblique column
   (tangential restitution, rebound angle, rebound tangential speed or rebound spin) when it has
   one, else e_n. Spin: the largest change over top-/back-spins up to the spin bound (default the
   rolling spin v / r); angle: the change at +/- one angle uncertainty. ``*_probability`` is the
   fraction of posterior draws in which the change exceeds the measurement's standard uncertainty;
   the row is flagged (``spin_moves_prediction``, ``angle_moves_prediction``) when that fraction is
   at least one half. e_n never moves with spin (the normal motion decouples from the tangential
   one, model-notes section 4), so normal-only rows are never spin-flagged: spin cannot be seen in
   them.
2. **Which unmeasured spin is consistent with the measurement?** (the inverse problem) The spin
   about t' (top-spin +, back-spin -, in the incidence plane: the one that changes the in-plane
   rebound) is scanned over [-bound, +bound]; a spin is consistent when the posterior-median
   prediction lies within :data:`CONSISTENCY_SIGMAS` (3) sigma of the measured value, sigma^2 = (measurement uncertainty, with
   the effective variance of the speed and angle errors)^2 + (posterior spread of the prediction)^2.
   The row gets ``spin_low`` / ``spin_high`` (the consistent range, [rad/s]; the whole scan for a
   row that cannot constrain spin, NaN when no spin in the scan is consistent),
   ``probably_spun`` (zero spin is NOT consistent, some spin is) and ``spin_unexplained`` (the
   measured quantity depends on spin, yet no spin in the scan explains the row, ``closest_sigma``
   standard uncertainties away at best: look for another cause). A row whose prediction does not
   depend on spin (e_n) admits every spin and is never U.

Every prediction goes through :func:`microimpact.analysis.oblique.rebound_state`, i.e. one
:func:`microimpact.solvers.engine.solve_normal_many` batch per radius and draw plus the closed-form
tangential map.
"""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from microimpact.analysis.oblique import OBSERVABLE_UNITS, ObliqueProblem, _observables, rebound_state
from microimpact.analysis.posterior import _contact
from microimpact.analysis.verdict import sidak_threshold
from microimpact.solvers import engine_threads
from microimpact._runtime.progress import progress_bar
from microimpact.solvers import DEFAULT_RTOL, Deadline

__all__ = ["spin_explanation", "SPIN_VARIABLES"]

#: variables added to the flags by :func:`spin_explanation`: name -> (units, long_name)
SPIN_VARIABLES = {
    "predicted_quantity": (None, "measured quantity the prediction is compared with"),
    "spin_shift": ("1", "posterior-median largest change of the prediction over the spin scan, in measurement "
                        "standard uncertainties"),
    "angle_shift": ("1", "posterior-median change of the prediction at +/- one angle uncertainty, in measurement "
                         "standard uncertainties"),
    "spin_moves_probability": ("1", "fraction of posterior draws in which unmeasured spin moves the prediction by "
                                    "more than the measurement uncertainty"),
    "angle_moves_probability": ("1", "fraction of posterior draws in which the angle error moves the prediction by "
                                     "more than the measurement uncertainty"),
    "spin_low": ("rad s-1", "lowest incident top-spin (back-spin negative) consistent with the measurement"),
    "spin_high": ("rad s-1", "highest incident top-spin (back-spin negative) consistent with the measurement"),
    "spin_scan_bound": ("rad s-1", "largest spin magnitude scanned"),
    "spin_shift_low": (None, "most negative change of the prediction over the spin scan (posterior median), in the "
                             "unit of predicted_quantity"),
    "spin_shift_high": (None, "most positive change of the prediction over the spin scan (posterior median), in the "
                              "unit of predicted_quantity"),
    "angle_shift_low": (None, "most negative change of the prediction at +/- one angle uncertainty (posterior "
                              "median), in the unit of predicted_quantity"),
    "angle_shift_high": (None, "most positive change of the prediction at +/- one angle uncertainty (posterior "
                               "median), in the unit of predicted_quantity"),
    "measured_value": (None, "the row's measured predicted_quantity, in its unit"),
    "model_value": (None, "the fitted model's predicted_quantity at zero spin and the nominal angle (posterior median)"),
    "standardized_residual": ("1", "(model_value - measured_value) / its standard uncertainty (measurement, speed "
                                   "and angle errors, posterior spread)"),
    "closest_sigma": ("1", "smallest distance of the prediction from the measurement over the spin scan, in "
                           "standard uncertainties (measurement, speed and angle errors, posterior spread)"),
}
#: a spin is consistent with a row when the prediction lies within this many standard uncertainties
#: of the measurement: 3 keeps a clean row unflagged with probability 0.997, so that a flag on a
#: data set of tens of rows points at a real cause rather than at the noise
CONSISTENCY_SIGMAS = 3.0
_FLAGS = {
    "spin_moves_prediction": ("still moves", "spin_moves_probability >= 0.5"),
    "angle_moves_prediction": ("still moves", "angle_moves_probability >= 0.5"),
    "probably_spun": ("unspun_consistent probably_spun", "zero spin is outside the consistent spin range"),
    "spin_unexplained": ("explained unexplained", "no spin in the scan and no angle error brings the prediction within "
                                                  "the outlier threshold (Sidak over the rows, at least 3 sigma) of "
                                                  "the measurement (also a row whose quantity does not depend on spin)"),
}


def _row_quantities(table):
    """(quantity, measured, sigma) per table row: the first oblique column the row measured, else e_n."""
    n = len(table)
    quantity = np.full(n, "e_n", dtype=object)
    measured = table["e_n"].to_numpy(dtype=float).copy()
    sigma = (table["e_n_uncertainty"].to_numpy(dtype=float).copy() if "e_n_uncertainty" in table.columns
             else np.full(n, np.nan))
    try:
        ob = ObliqueProblem.from_table(table)
    except ValueError:
        return quantity, measured, sigma
    rows = table["row"].to_numpy(dtype=np.int64) if "row" in table.columns else np.arange(1, n + 1)
    pos = {int(r): i for i, r in enumerate(rows)}
    seen = set()
    for k in range(ob.size):
        i = pos[int(ob.rows[k])]
        if i in seen:
            continue
        seen.add(i)
        quantity[i], measured[i], sigma[i] = ob.quantity[k], ob.measured[k], ob.sigma_measured[k]
    return quantity, measured, sigma


def _predict(contact, speed, incidence_deg, spin, quantity):
    """Model value of ``quantity`` per entry (e_n or an oblique observable), NaN where captured."""
    st = rebound_state(contact, speed, np.clip(incidence_deg, 0.0, 89.9), spin)
    vn = speed * np.cos(np.radians(incidence_deg))
    out = _observables(st, speed, incidence_deg, quantity)
    out = np.where(quantity == "e_n", st["velocity_out_n"] / vn, out)
    return np.where(st["captured"] & (quantity != "e_n"), np.nan, out)


def spin_explanation(table, fit, *, posterior=None, friction: float | None = None, n_draws: int = 8,
                     spin_bound=None, angle_uncertainty_deg=None, default_angle_uncertainty_deg: float = 2.0,
                     n_scan: int = 41, default_sigma: float = 0.02, rtol: float = DEFAULT_RTOL,
                     progress: bool = False, time_budget: float | None = None) -> xr.Dataset:
    """Posterior flags that explain, and the spin range consistent with each row (module docstring).

    Parameters
    ----------
    table : pandas.DataFrame
        Impacts from :func:`microimpact.io.read_impacts`.
    fit : DampingFit
        Material and point estimate (draws replace its zetas, w_A and friction).
    posterior : Posterior, optional
        Draws of the parameters; None uses the point estimate only.
    friction : float, optional
        Coulomb f when the posterior does not sample it; default the fit's material friction. [-]
    n_draws : int
        Posterior draws used.
    spin_bound : float or array_like, optional
        Largest |spin| scanned [rad/s]; default each row's speed / radius.
    angle_uncertainty_deg : float, optional
        Angle uncertainty [deg]; default the table's, else ``default_angle_uncertainty_deg``.
    default_angle_uncertainty_deg : float
        [deg]
    n_scan : int
        Spins in the scan (odd, so that 0 is one of them).
    default_sigma : float
        Measurement uncertainty where the row states none (in the quantity's unit).
    rtol : float
        Relative tolerance of the normal solves. [-]
    progress : bool
        Progress bar on stderr (a terminal only).
    time_budget : float or Deadline, optional
        Wall-clock budget, checked after each draw; None: no limit. [s]

    Returns
    -------
    xarray.Dataset
        Along ``impact``: the variables of :data:`SPIN_VARIABLES` and the 0/1 flags
        ``spin_moves_prediction``, ``angle_moves_prediction``, ``probably_spun``, ``spin_unexplained``.

    Examples
    --------
    Six normal-only synthetic impacts and the point estimate: e_n does not move with spin, so no row
    is spin-flagged and every scanned spin (up to the rolling spin v / r) is consistent:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> ds = spin_explanation(table, fit, n_scan=5)
    >>> set(ds["predicted_quantity"].values), ds["spin_shift"].values.tolist()
    ({'e_n'}, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    >>> bool((ds["spin_high"] == table["speed"].to_numpy() / table["radius"].to_numpy()).all())
    True
    >>> int(ds["spin_moves_prediction"].sum()), int(ds["probably_spun"].sum()), int(ds["spin_unexplained"].sum())
    (0, 0, 0)

    A scan without zero spin is refused:

    >>> spin_explanation(table, fit, n_scan=4)
    Traceback (most recent call last):
    ...
    ValueError: n_scan must be odd and >= 3 (so that zero spin is scanned), got 4
    """
    n = len(table)
    deadline = Deadline.start(time_budget, "spin explanation")
    if n_scan < 3 or n_scan % 2 == 0:
        raise ValueError(f"n_scan must be odd and >= 3 (so that zero spin is scanned), got {n_scan}")
    quantity, measured, sigma_m = _row_quantities(table)
    sigma_m = np.where(np.isfinite(sigma_m) & (sigma_m > 0), sigma_m, default_sigma)
    radius, inc, speed, sig_a, sig_v, bound = _row_inputs(table, spin_bound, angle_uncertainty_deg,
                                                          default_angle_uncertainty_deg)
    scan = np.linspace(-1.0, 1.0, n_scan)  # x bound
    k0 = n_scan // 2
    draws = _parameter_draws(fit, posterior, friction, n_draws)
    # per draw: predictions (impact, n_scan + 4): spins at the nominal angle, then angle -/+ sigma, speed -/+ sigma
    pred = np.empty((len(draws), n, n_scan + 4))

    with progress_bar(len(draws), "spin ranges", progress) as advance, engine_threads(1):
        advance = deadline.ticking(advance, len(draws), "posterior draws")
        for j, d in enumerate(draws):
            for r in np.unique(radius):
                idx = np.flatnonzero(radius == r)
                pred[j, idx] = _scan_predictions(_contact(fit, float(r), d), speed[idx], inc[idx], sig_v[idx],
                                                 sig_a[idx], bound[idx], scan, quantity[idx])
            advance(1)
    return _explain(pred, k0, n_scan, quantity, measured, sigma_m, bound, scan, table)


def _row_inputs(table, spin_bound, angle_uncertainty_deg, default_angle_uncertainty_deg) -> tuple:
    """(radius [m], incidence [deg], speed [m/s], angle uncertainty [deg], speed uncertainty [m/s],
    spin bound [rad/s]) of each row of :func:`spin_explanation`: the speed is the normal speed where
    no speed is given, the angle uncertainty ``angle_uncertainty_deg``, else the table's, else the
    default, and the spin bound ``spin_bound``, else speed / radius."""
    n = len(table)
    radius = table["radius"].to_numpy(dtype=float)
    inc = np.nan_to_num(table["incidence_deg"].to_numpy(dtype=float))
    speed = table["speed"].to_numpy(dtype=float)
    speed = np.where(np.isfinite(speed), speed, table["normal_speed"].to_numpy(dtype=float))
    if angle_uncertainty_deg is not None:
        sig_a = np.full(n, float(angle_uncertainty_deg))
    else:
        col = table["incidence_deg_uncertainty"].to_numpy(dtype=float) if "incidence_deg_uncertainty" in table.columns else np.full(n, np.nan)
        sig_a = np.where(np.isfinite(col), col, default_angle_uncertainty_deg)
    sig_v = np.nan_to_num(table["speed_uncertainty"].to_numpy(dtype=float)) if "speed_uncertainty" in table.columns else np.zeros(n)
    bound = speed / radius if spin_bound is None else np.broadcast_to(np.asarray(spin_bound, dtype=float), (n,)).copy()
    return radius, inc, speed, sig_a, sig_v, bound


def _parameter_draws(fit, posterior, friction, n_draws) -> list[dict]:
    """The parameter sets of :func:`spin_explanation`: the fit's point estimate, or ``n_draws``
    posterior draws, each with the friction ``friction`` (default the fit's) where it has none."""
    if posterior is None:
        return [dict(fit.values) | {"friction": fit.friction if friction is None else friction}]
    draws = posterior.draws(n_draws)
    for d in draws:
        d.setdefault("friction", fit.friction if friction is None else friction)
    return draws


def _scan_predictions(c, speed, inc, sig_v, sig_a, bound, scan, quantity) -> np.ndarray:
    """Predictions (row, len(scan) + 4) of each row's measured ``quantity`` with contact ``c``: at
    the spins ``bound`` x ``scan`` and the nominal angle, then at the angle -/+ ``sig_a`` [deg] and
    the speed -/+ ``sig_v`` [m/s] without spin."""
    n_scan, m = scan.size, speed.size
    sp = np.concatenate([np.repeat(speed[:, None], n_scan + 2, 1),
                         speed[:, None] + sig_v[:, None] * np.array([-1.0, 1.0])], axis=1)
    an = np.concatenate([np.repeat(inc[:, None], n_scan, 1),
                         inc[:, None] + sig_a[:, None] * np.array([-1.0, 1.0]),
                         np.repeat(inc[:, None], 2, 1)], axis=1)
    an = np.abs(an)
    w = np.concatenate([bound[:, None] * scan[None, :], np.zeros((m, 4))], axis=1)
    q = np.repeat(quantity[:, None], n_scan + 4, 1)
    return _predict(c, sp.ravel(), an.ravel(), w.ravel(), q.ravel()).reshape(m, n_scan + 4)


def _explain(pred, k0, n_scan, quantity, measured, sigma_m, bound, scan, table) -> xr.Dataset:
    """The flags and spin ranges from the predictions (draw, impact, sample)."""
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN slices: captured samples
        p0 = pred[:, :, k0]
        spin_change = np.nanmax(np.abs(pred[:, :, :n_scan] - p0[:, :, None]), axis=2)
        angle_change = np.nanmax(np.abs(pred[:, :, n_scan:n_scan + 2] - p0[:, :, None]), axis=2)
        speed_change = np.nanmax(np.abs(pred[:, :, n_scan + 2:] - p0[:, :, None]), axis=2)
        # the measurement's effective sigma: stated + speed and angle errors (half the +/- change)
        sigma_eff = np.sqrt(sigma_m ** 2 + np.nanmedian(speed_change, axis=0) ** 2 + np.nanmedian(angle_change, axis=0) ** 2)
        med = np.nanmedian(pred[:, :, :n_scan], axis=0)
        spread = np.nanstd(pred[:, :, :n_scan], axis=0)
        signed = np.nanmedian(pred - p0[:, :, None], axis=0)  # (impact, sample): median change from zero spin
        spin_lo, spin_hi = np.nanmin(signed[:, :n_scan], axis=1), np.nanmax(signed[:, :n_scan], axis=1)
        angle_lo = np.nanmin(signed[:, n_scan:n_scan + 2], axis=1)
        angle_hi = np.nanmax(signed[:, n_scan:n_scan + 2], axis=1)
        distance = np.abs(med - measured[:, None]) / np.sqrt(sigma_eff[:, None] ** 2 + spread ** 2)
    spin_p = np.mean(np.nan_to_num(spin_change) > sigma_m[None, :], axis=0)
    angle_p = np.mean(np.nan_to_num(angle_change) > sigma_m[None, :], axis=0)
    ok = np.isfinite(distance) & (distance <= CONSISTENCY_SIGMAS)
    spins = bound[:, None] * scan[None, :]
    # a row whose prediction does not move with spin (e_n, by the decoupling of the normal motion)
    # admits every spin: whether it fits the model is not a question about spin
    blind = np.nanmax(np.nan_to_num(spin_change), axis=0) <= 1e-9 * np.maximum(np.abs(np.nan_to_num(p0)).max(axis=0), 1e-300)
    # the same test the fit's verdict names outliers by (Sidak over the rows, never below 3 sigma):
    # a row that no spin and no angle error brings near the model is unexplained, whether or not
    # its quantity depends on spin (a blind e_n row 20 sigma off is unexplained, as its residual says)
    threshold = max(CONSISTENCY_SIGMAS, sidak_threshold(len(table)))
    explained = (np.isfinite(distance) & (distance <= threshold)).any(axis=1)
    ok |= blind[:, None] & explained[:, None]
    any_ok = ok.any(axis=1)
    low = np.where(any_ok, np.min(np.where(ok, spins, np.inf), axis=1), np.nan)
    high = np.where(any_ok, np.max(np.where(ok, spins, -np.inf), axis=1), np.nan)
    rows = table["row"].to_numpy(dtype=np.int64) if "row" in table.columns else np.arange(1, len(table) + 1)
    ds = xr.Dataset(coords={"impact": ("impact", np.arange(rows.size), {"long_name": "impact index in the table"})})
    values = {"predicted_quantity": quantity.astype(str).astype(object),
              "spin_shift": np.nan_to_num(np.median(spin_change, axis=0)) / sigma_m,
              "angle_shift": np.nan_to_num(np.median(angle_change, axis=0)) / sigma_m,
              "spin_moves_probability": spin_p, "angle_moves_probability": angle_p,
              "spin_low": low, "spin_high": high, "spin_scan_bound": bound,
              "spin_shift_low": np.nan_to_num(spin_lo), "spin_shift_high": np.nan_to_num(spin_hi),
              "angle_shift_low": np.nan_to_num(angle_lo), "angle_shift_high": np.nan_to_num(angle_hi),
              "closest_sigma": np.nanmin(np.where(np.isfinite(distance), distance, np.inf), axis=1),
              "measured_value": measured, "model_value": med[:, k0],
              "standardized_residual": (med[:, k0] - measured) / np.sqrt(sigma_eff ** 2 + spread[:, k0] ** 2)}
    for name, v in values.items():
        units, long_name = SPIN_VARIABLES[name]
        ds[name] = ("impact", v, {"long_name": long_name} | ({"units": units} if units else {}))
    flags = {"spin_moves_prediction": spin_p >= 0.5, "angle_moves_prediction": angle_p >= 0.5,
             "probably_spun": any_ok & ~ok[:, k0], "spin_unexplained": ~explained}
    for name, (meanings, long_name) in _FLAGS.items():
        ds[name] = ("impact", flags[name].astype(np.int8), {"flag_values": np.array([0, 1], dtype=np.int8),
                                                            "flag_meanings": meanings, "long_name": long_name})
    ds.attrs["spin_explanation"] = (
        f"spin about t' (top-spin +) scanned over +/- spin_scan_bound in {n_scan} steps; consistent: posterior-median "
        f"prediction within {CONSISTENCY_SIGMAS:g} sigma of the measurement (measurement, speed and angle errors and "
        "posterior spread); a row whose prediction does not depend on spin (e_n) admits every spin")
    ds.attrs["spin_quantity_units"] = "; ".join(f"{k}: {v}" for k, v in (OBSERVABLE_UNITS | {"e_n": "1"}).items())
    return ds
