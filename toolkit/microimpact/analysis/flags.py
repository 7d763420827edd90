"""Per-measurement flags: which measured impacts are sensitive to unmeasured spin, to the angle
error, or close to capture (Cheng, Brach & Dunn 2002, Figs. 7-14 and their discussion).

The paper's point: microsphere spin cannot be measured, yet an initial spin of the order of the
rolling spin v / r changes the tangential impulse ratios mu_t, mu_t' (Eqs. (22)-(23)) and the energy
loss K_L (Eq. (25)) a lot; near capture a small error in the incidence angle changes mu and e_n
(Fig. 8). :func:`flag_measurements` simulates every measured impact under a set of plausible
unmeasured conditions, all at once with :func:`microimpact.simulate_many`, and reports the spread.

Samples (per impact)
--------------------
* spin: the zero spin plus ``n_spin`` directions in 3-D (a Fibonacci sphere, so omega_n, omega_t and
  omega_t' all occur) times magnitudes ``spin_fractions`` x the spin bound. Default bound: the
  rolling spin speed / radius of that impact [rad/s];
* incidence angle: nominal + k sigma_alpha for k in ``angle_offsets`` (default -1, 0, +1), with
  sigma_alpha from the table's ``incidence_deg_uncertainty`` when given, else
  ``default_angle_uncertainty_deg`` (2 deg). A negative angle is the positive angle with the
  azimuth turned by 180 deg.

Every spin sample is combined with every angle sample (one broadcast). Ranges "over spin" are
taken at the nominal angle, ranges "over angle" at zero spin.

Flags (thresholds recorded as Dataset attributes ``threshold_*``)
-----------------------------------------------------------------
A flag is raised only where the unmeasured quantity can move a quantity the row MEASURED by more
than its stated uncertainty (mu_t, mu_t' and K_L are derived coefficients no row measured; their
spreads are reported, not flagged):

* ``rotation_sensitive``: over spin, range(e_n) > the e_n limit (never, by the decoupling of the
  normal motion: e_n-only rows are never R), or the row's oblique measurement moves by more than its
  uncertainty (``spin_moves_prediction`` of :mod:`microimpact.analysis.spin`), or some spin samples
  are captured and others not.
* ``angle_sensitive``: over +/- one angle uncertainty, range(e_n) > the e_n limit, or the row's
  oblique measurement moves by more than its uncertainty (``angle_moves_prediction``), or the
  outcome changes. ``e_n_shift_low_angle``/``_high_angle`` say by how much and in which direction.
  The e_n limit is the impact's ``e_n_uncertainty`` when the table gives one (a spread smaller
  than the measurement error cannot be seen), else ``e_n`` (default 0.02).
* ``near_capture``: normal speed / capture velocity < ``near_capture_ratio`` (default 1.5; e_n is
  then below about a third of its high-speed value and steep in v_n). The capture velocity of each
  radius is :func:`microimpact.dynamics.nonlinear.capture_velocity` (bisection on the engine outcome).
"""

from __future__ import annotations

import math
import sys
import time
import warnings
from dataclasses import dataclass

import numpy as np
import xarray as xr

from microimpact.analysis.spin import spin_explanation
from microimpact.dynamics.nonlinear import capture_velocity
from microimpact.io.files import CONVENTIONS, all_or_nothing, write_csv, write_netcdf
from microimpact.io.impacts import CSV_COLUMN_ATTR, label_variables, row_labels
from microimpact.io.materials import material_contact
from microimpact.io.variables import attributes
from microimpact.solvers import DEFAULT_RTOL, Deadline
from microimpact.solvers.impact import simulate_many

__all__ = ["flag_measurements", "write_flags", "fibonacci_sphere", "flag_summary", "DEFAULT_THRESHOLDS", "FLAG_LETTERS"]

#: default flag thresholds (see the module docstring)
DEFAULT_THRESHOLDS = {"mu": 0.05, "K_L": 0.05, "e_n": 0.02, "near_capture_ratio": 1.5}
_COEFS = ("e_n", "mu_t", "mu_tp", "K_L", "K_t")
#: suffix -> what the extreme is taken over ("" is the nominal value: zero spin, nominal angle)
_SPREADS = {"_spin": "over initial spin samples at the nominal angle",
            "_angle": "over incidence-angle samples at zero spin", "": "over all samples"}


def fibonacci_sphere(n: int) -> np.ndarray:
    """``n`` nearly uniformly spread unit vectors (Fibonacci lattice), shape (n, 3). [-]

    Points at heights z_i = 1 - (2 i + 1) / n, turned by the golden angle from one to the next:
    equal areas in z, no clustering at the poles (the spin directions sampled by
    :func:`flag_measurements`).

    References
    ----------
    Gonzalez, A. (2010), Measurement of areas on a sphere using Fibonacci and latitude-longitude
    lattices, Math. Geosci. 42:49-64, doi:10.1007/s11004-009-9257-x.

    Examples
    --------
    Unit vectors, and their mean tends to the centre as n grows:

    >>> v = fibonacci_sphere(100)
    >>> v.shape, bool(np.allclose(np.linalg.norm(v, axis=1), 1.0)), bool(np.abs(v.mean(axis=0)).max() < 1e-3)
    ((100, 3), True, True)
    """
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = math.pi * (1.0 + math.sqrt(5.0)) * i
    rho = np.sqrt(1.0 - z * z)
    return np.column_stack([z, rho * np.cos(phi), rho * np.sin(phi)])  # (n, t, t') components


def _contact_for(obj, radius: float):
    """Contact of this radius from a DampingFit, MaterialPair or Contact (f0 from Eq. (7))."""
    try:
        return material_contact(obj, radius)
    except ValueError:
        raise ValueError("contact_or_fit must be a Contact, DampingFit or MaterialPair, "
                         f"got {type(obj).__name__}") from None


def _progress(enabled, message):
    if enabled:
        print(message, file=sys.stderr, flush=True)


@dataclass(frozen=True)
class _Impacts:
    """The measured impacts to flag, checked, with the uncertainties and spin bounds to sample."""

    source: str
    rows: np.ndarray
    radius: np.ndarray  # [m]
    incidence_deg: np.ndarray  # [deg]
    speed: np.ndarray  # [m/s]
    normal_speed: np.ndarray  # [m/s]
    angle_uncertainty_deg: np.ndarray  # [deg]
    angle_source: str
    spin_bound: np.ndarray  # [rad/s]
    spin_source: str
    e_n_uncertainty: np.ndarray  # [-], NaN where not given


def _impacts(df, spin_bound, angle_uncertainty_deg, default_angle_uncertainty_deg) -> _Impacts:
    """Columns of the impact table, checked; errors name the data row and column."""
    src = df.attrs.get("source", "impact table")
    n = len(df)
    if n == 0:
        raise ValueError(f"{src}: no impacts to flag")

    def column(name, default):
        return df[name].to_numpy(dtype=float) if name in df.columns else np.full(n, default)

    rows = df["row"].to_numpy(dtype=np.int64) if "row" in df.columns else np.arange(1, n + 1)
    radius = df["radius"].to_numpy(dtype=float)
    inc = column("incidence_deg", 0.0)
    inc = np.where(np.isfinite(inc), inc, 0.0)
    speed = column("speed", np.nan)
    speed = np.where(np.isfinite(speed), speed, df["normal_speed"].to_numpy(dtype=float) / np.cos(np.radians(inc)))
    for name, x in (("radius", radius), ("speed", speed)):
        bad = ~np.isfinite(x) | (x <= 0)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{src}: row {rows[i]}, column {name!r}: {x[i]!r} must be finite and > 0")

    if angle_uncertainty_deg is not None:
        sig_a, angle_source = np.full(n, float(angle_uncertainty_deg)), "argument"
    elif np.isfinite(column("incidence_deg_uncertainty", np.nan)).any():
        sig_a = column("incidence_deg_uncertainty", np.nan)
        sig_a = np.where(np.isfinite(sig_a), sig_a, default_angle_uncertainty_deg)
        angle_source = "table column incidence_angle_uncertainty (default where empty)"
    else:
        sig_a, angle_source = np.full(n, float(default_angle_uncertainty_deg)), "default"
    if np.any(~np.isfinite(sig_a) | (sig_a < 0)):
        raise ValueError(f"angle uncertainty must be finite and >= 0 deg, got {angle_uncertainty_deg!r}")

    if spin_bound is None:
        bound, spin_source = speed / radius, "rolling spin speed / radius per impact"
    else:
        bound, spin_source = np.broadcast_to(np.asarray(spin_bound, dtype=float), (n,)).copy(), "argument"
        if np.any(~np.isfinite(bound) | (bound < 0)):
            raise ValueError(f"spin_bound must be finite and >= 0 rad/s, got {spin_bound!r}")
    return _Impacts(str(src), rows, radius, inc, speed, speed * np.cos(np.radians(inc)), sig_a, angle_source,
                    bound, spin_source, column("e_n_uncertainty", np.nan))


def _spin_samples(n_spin, spin_fractions) -> tuple[np.ndarray, np.ndarray]:
    """(nonzero fractions [-], unit spin samples (n, 3) [-]); sample 0 is the zero spin."""
    fr = np.asarray([f for f in spin_fractions if f != 0], dtype=float)
    dirs = fibonacci_sphere(n_spin)
    return fr, np.vstack([np.zeros((1, 3)), np.repeat(dirs, fr.size, axis=0) * np.tile(fr, n_spin)[:, None]])


def _spread(imp: _Impacts, contact_or_fit, unit, offsets, rtol, progress, deadline) -> dict:
    """Coefficients over the samples, per radius: nominal, min/max over spin, angle and all, the
    capture velocity [m/s] and whether the outcome switches over spin or over angle. The deadline
    is checked after each radius (one simulate_many each: a compiled call that cannot stop)."""
    n = imp.rows.size
    k0 = int(np.flatnonzero(offsets == 0.0)[0])
    out = {f"{c}{mm}{s}": np.full(n, np.nan) for c in _COEFS for s in _SPREADS for mm in ("", "_min", "_max")
           if mm or not s}
    out |= {"capture_velocity": np.full(n, np.nan), "switch_spin": np.zeros(n, bool), "switch_angle": np.zeros(n, bool)}
    radii, inverse = np.unique(imp.radius, return_inverse=True)
    t0 = time.perf_counter()
    for gi, r in enumerate(radii):
        idx = np.flatnonzero(inverse == gi)
        contact = _contact_for(contact_or_fit, float(r))
        out["capture_velocity"][idx] = capture_velocity(contact)
        a = imp.incidence_deg[idx, None] + offsets[None, :] * imp.angle_uncertainty_deg[idx, None]  # (impact, angle)
        alpha = xr.DataArray(np.minimum(np.abs(a), 89.9), dims=("impact", "angle_sample"))
        azim = xr.DataArray(np.where(a < 0, 180.0, 0.0), dims=("impact", "angle_sample"))
        w = imp.spin_bound[idx, None, None] * unit[None, :, :]  # (impact, spin, 3)
        omega = tuple(xr.DataArray(w[:, :, k], dims=("impact", "spin_sample")) for k in range(3))
        ds = simulate_many(contact, xr.DataArray(imp.speed[idx], dims="impact"), alpha, azim, omega, rtol=rtol)
        ds = ds.transpose("impact", "spin_sample", "angle_sample")
        for c in _COEFS:
            x = ds[c].values
            with np.errstate(invalid="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN slices (captured samples)
                out[c][idx] = x[:, 0, k0]
                for s, sub, axis in (("_spin", x[:, :, k0], 1), ("_angle", x[:, 0, :], 1), ("", x, (1, 2))):
                    out[f"{c}_min{s}"][idx] = np.nanmin(sub, axis=axis)
                    out[f"{c}_max{s}"][idx] = np.nanmax(sub, axis=axis)
        oc = ds["outcome"].values
        out["switch_spin"][idx] = oc[:, :, k0].min(axis=1) != oc[:, :, k0].max(axis=1)
        out["switch_angle"][idx] = oc[:, 0, :].min(axis=1) != oc[:, 0, :].max(axis=1)
        _progress(progress, f"flags: radius {r * 1e6:.4g} um ({gi + 1}/{radii.size}), {idx.size} impacts x "
                  f"{unit.shape[0]} spins x {offsets.size} angles, {time.perf_counter() - t0:.1f} s")
        deadline.check(f"{gi + 1} of {radii.size} radii")
    return out


def flag_measurements(table, contact_or_fit, *, spin_bound=None, angle_uncertainty_deg=None,
                      default_angle_uncertainty_deg: float = 2.0, n_spin: int = 12,
                      spin_fractions=(0.5, 1.0), angle_offsets=(-1.0, 0.0, 1.0), thresholds=None,
                      rtol: float = DEFAULT_RTOL, progress: bool = False, posterior=None, friction=None,
                      n_draws: int = 8, explain: bool = True, time_budget: float | None = None) -> xr.Dataset:
    """Spread of the impact coefficients over unmeasured spin and angle error, and flags.

    Parameters
    ----------
    table : pandas.DataFrame
        Measured impacts from :func:`microimpact.io.read_impacts` (``row``, ``radius`` [m],
        ``speed`` [m/s], ``incidence_deg`` [deg], ``normal_speed`` [m/s], optional
        ``incidence_deg_uncertainty`` [deg], ``e_n_uncertainty`` [-]). Rows with only a normal
        speed are taken as normal impacts.
    contact_or_fit : DampingFit, MaterialPair or Contact
        Model parameters; f0 follows each impact's radius through Eq. (7).
    spin_bound : float or array_like, optional
        Largest initial spin magnitude sampled [rad/s]; default each impact's rolling spin
        speed / radius.
    angle_uncertainty_deg : float, optional
        Incidence-angle standard uncertainty for every impact [deg]; default the table's
        ``incidence_deg_uncertainty`` per row, else ``default_angle_uncertainty_deg``.
    default_angle_uncertainty_deg : float
        Used where neither is given. [deg]
    n_spin : int
        Number of spin directions (Fibonacci sphere).
    spin_fractions : sequence of float
        Spin magnitudes as fractions of the bound (the zero spin is always included). [-]
    angle_offsets : sequence of float
        Angle samples in units of the angle uncertainty (0 is always included). [-]
    thresholds : dict, optional
        Overrides of :data:`DEFAULT_THRESHOLDS` (``mu``, ``K_L``, ``e_n``, ``near_capture_ratio``).
    rtol : float
        Engine tolerance. [-]
    progress : bool
        Print progress to stderr.
    posterior : Posterior, optional
        Posterior draws for the flags that explain (:func:`microimpact.analysis.spin.spin_explanation`);
        None: the point estimate of ``contact_or_fit``.
    friction : float, optional
        Coulomb f of the explanation when the posterior does not sample it (e.g. a friction fit's). [-]
    n_draws : int
        Posterior draws of the explanation.
    explain : bool
        Add the explanation (needs a DampingFit or MaterialPair as ``contact_or_fit``): per-row
        ``spin_low``/``spin_high`` (the unmeasured spin consistent with the measurement),
        ``spin_moves_prediction``, ``angle_moves_prediction``, ``probably_spun``, ``spin_unexplained``.
    time_budget : float or Deadline, optional
        Wall-clock budget of the flags and the explanation; None: no limit. Checked after each
        radius's batch and each posterior draw of the explanation; past it, TimeBudgetExceeded
        says how far the flags got. [s]

    Returns
    -------
    xarray.Dataset
        Along dimension ``impact`` (coordinate ``row``: the CSV data row): the nominal
        coefficients ``<c>`` (zero spin, nominal angle), ``<c>_min_spin``/``<c>_max_spin``,
        ``<c>_min_angle``/``<c>_max_angle`` and ``<c>_min``/``<c>_max`` over all samples for c in
        e_n, mu_t, mu_tp, K_L, K_t; ``capture_velocity`` [m/s], ``capture_speed_ratio`` [-],
        ``spin_bound`` [rad/s], ``angle_uncertainty_deg`` [deg]; flags ``rotation_sensitive``,
        ``angle_sensitive``, ``near_capture`` (int8 0/1). Thresholds and sample counts are
        attributes. ``ds.to_dataframe()`` gives one row per impact.

    Examples
    --------
    Two normal impacts of synthetic data (no spin in them): an unmeasured spin or an angle error of
    the stated size moves the predicted e_n by less than the e_n threshold, so neither is flagged:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> flags = flag_measurements(table.head(2), fit, n_spin=4, spin_fractions=(1.0,))
    >>> spread = (flags["e_n_max"] - flags["e_n_min"]).values
    >>> bool((spread < flags.attrs["threshold_e_n"]).all()), flags["probably_spun"].values.tolist()
    (True, [0, 0])
    """
    deadline = Deadline.start(time_budget, "flags")
    th = _thresholds(thresholds)
    imp = _impacts(table, spin_bound, angle_uncertainty_deg, default_angle_uncertainty_deg)
    fr, unit = _spin_samples(n_spin, spin_fractions)
    offsets = np.unique(np.append(np.asarray(angle_offsets, dtype=float), 0.0))  # 0: the nominal angle
    out = _spread(imp, contact_or_fit, unit, offsets, rtol, progress, deadline)

    en_limit, ratio, flags = _sensitivity_flags(imp, out, th)
    res = _flags_dataset(imp, out, ratio, en_limit, flags)
    _add_flag_attributes(res, th, imp, n_spin, fr, offsets, unit, table)
    if explain and hasattr(contact_or_fit, "varied"):
        res = _with_explanation(res, table, contact_or_fit, posterior=posterior, friction=friction, n_draws=n_draws,
                                spin_bound=spin_bound, angle_uncertainty_deg=angle_uncertainty_deg,
                                default_angle_uncertainty_deg=default_angle_uncertainty_deg, rtol=rtol,
                                progress=progress, time_budget=deadline)
    return _with_ids(res, table)


def _sensitivity_flags(imp: _Impacts, out: dict, th: dict) -> tuple[np.ndarray, np.ndarray, dict]:
    """(en_limit, ratio, flags) of :func:`flag_measurements`: the e_n spread that flags a row (its
    stated e_n uncertainty, else the threshold), the normal speed over the capture velocity and the
    flags ``rotation_sensitive``, ``angle_sensitive`` and ``near_capture`` from the spreads ``out``."""
    en_limit = np.where(np.isfinite(imp.e_n_uncertainty) & (imp.e_n_uncertainty > 0), imp.e_n_uncertainty, th["e_n"])

    def rng(c, s):
        return np.nan_to_num(out[f"{c}_max_{s}"] - out[f"{c}_min_{s}"], nan=0.0)

    # only what the row MEASURED counts: e_n here (the oblique quantity below, from the explanation);
    # mu_t, mu_t' and K_L are derived coefficients no row measured, so their spread flags nothing
    rot = (rng("e_n", "spin") > en_limit) | out["switch_spin"]
    ang = (rng("e_n", "angle") > en_limit) | out["switch_angle"]
    ratio = imp.normal_speed / out["capture_velocity"]
    return en_limit, ratio, {"rotation_sensitive": rot, "angle_sensitive": ang,
                             "near_capture": ratio < th["near_capture_ratio"]}


def _add_flag_attributes(res: xr.Dataset, th: dict, imp: _Impacts, n_spin: int, fr, offsets, unit, table) -> None:
    """Record on ``res`` the thresholds ``th``, the samples (``n_spin`` directions, spin fractions
    ``fr``, angle ``offsets``, the spin samples ``unit``), where the bounds came from, the model
    and the table's source and checksum."""
    res.attrs.update({f"threshold_{k}": v for k, v in th.items()})
    res.attrs.update({
        "title": "measurement flags: sensitivity to unmeasured spin and angle error, closeness to capture",
        "source": imp.source, "n_spin_directions": int(n_spin), "spin_fractions": fr,
        "angle_offsets_sigma": offsets, "spin_samples": int(unit.shape[0]), "angle_samples": int(offsets.size),
        "spin_bound_source": imp.spin_source, "angle_uncertainty_source": imp.angle_source,
        "model": "Cheng, Brach & Dunn (2002); coefficients from microimpact.simulate_many",
        "Conventions": CONVENTIONS,
    })
    if "sha256" in table.attrs:
        res.attrs["source_sha256"] = table.attrs["sha256"]


def _with_ids(res: xr.Dataset, table) -> xr.Dataset:
    """The analyst's labels of each row (``id`` and the CSV's own columns) as text variables along
    ``impact`` (:func:`microimpact.io.label_variables`)."""
    return res.assign(label_variables(row_labels(table), "impact"))


def flag_summary(ds: xr.Dataset) -> str:
    """One line naming every flag kind found, with its count (kinds with none are left out).

    Examples
    --------
    >>> import xarray as xr, numpy as np
    >>> ds = xr.Dataset({"near_capture": ("impact", np.array([1, 0], dtype=np.int8))})
    >>> flag_summary(ds)
    '2 impacts: 1 near_capture (N)'
    """
    kinds = [(name, letter) for name, letter in FLAG_LETTERS.items() if name in ds]
    found = [f"{int(ds[name].sum())} {name} ({letter})" for name, letter in kinds if int(ds[name].sum())]
    return f"{ds.sizes['impact']} impacts: " + (", ".join(found) if found else "no flags")


def _thresholds(overrides) -> dict:
    """:data:`DEFAULT_THRESHOLDS` with ``overrides``; ValueError names an unknown one."""
    th = dict(DEFAULT_THRESHOLDS)
    unknown = set(overrides or {}) - set(th)
    if unknown:
        raise ValueError(f"unknown threshold(s) {sorted(unknown)}; known: {sorted(th)}")
    return th | {k: float(v) for k, v in (overrides or {}).items()}


def _with_explanation(res: xr.Dataset, table, fit, *, posterior, **options) -> xr.Dataset:
    """The flags with the explanation of :func:`microimpact.analysis.spin.spin_explanation` merged in."""
    extra = spin_explanation(table, fit, posterior=posterior, **options)
    res = res.merge(extra.drop_vars("spin_scan_bound"), combine_attrs="no_conflicts")
    res.attrs["explanation_draws"] = "posterior draws" if posterior is not None else "point estimate"
    # a row's oblique measurement that spin (the angle error) moves by more than its uncertainty
    oblique = res["predicted_quantity"].values != "e_n"
    res["rotation_sensitive"].values |= (oblique & (res["spin_moves_prediction"].values == 1)).astype(np.int8)
    res["angle_sensitive"].values |= (oblique & (res["angle_moves_prediction"].values == 1)).astype(np.int8)
    return res


#: flag -> the letter the report and the summary use
FLAG_LETTERS = {"rotation_sensitive": "R", "angle_sensitive": "A", "near_capture": "N", "probably_spun": "S",
                "spin_unexplained": "U"}
#: flag name -> (flag_meanings, long_name)
_FLAGS = {
    "rotation_sensitive": ("insensitive rotation_sensitive", "unmeasured spin moves a measured quantity by more than "
                           "its uncertainty: e_n over spin > e_n_limit (never: the normal motion decouples), or the "
                           "row's oblique measurement (spin_moves_prediction), or the outcome changes"),
    "angle_sensitive": ("insensitive angle_sensitive", "the angle error moves a measured quantity by more than its "
                        "uncertainty: e_n at +/- one angle uncertainty > e_n_limit, or the row's oblique measurement "
                        "(angle_moves_prediction), or the outcome changes"),
    "near_capture": ("far near_capture", "capture_speed_ratio < threshold_near_capture_ratio"),
}


def _flags_dataset(imp: _Impacts, out: dict, ratio, en_limit, flags: dict) -> xr.Dataset:
    """The Dataset of :func:`flag_measurements` along ``impact``, units and long names from
    :mod:`microimpact.io.variables`."""
    res = xr.Dataset(coords={"impact": ("impact", np.arange(imp.rows.size), {"long_name": "impact index in the table"}),
                             "row": ("impact", imp.rows, attributes("row"))})
    for c in _COEFS:
        units, long_name = attributes(c)["units"], attributes(c)["long_name"]
        res[c] = ("impact", out[c], attributes(c, long_name=f"{long_name}, zero spin, nominal angle"))
        for s, what in _SPREADS.items():
            for mm in ("min", "max"):
                res[f"{c}_{mm}{s}"] = ("impact", out[f"{c}_{mm}{s}"], {
                    "units": units, "long_name": f"{mm}imum {long_name} {what}"})
    res["capture_velocity"] = ("impact", out["capture_velocity"],
                               attributes("capture_normal_speed", long_name="capture velocity of this radius"))
    res["capture_speed_ratio"] = ("impact", ratio, attributes("capture_speed_ratio"))
    res["spin_bound"] = ("impact", imp.spin_bound, attributes(
        "spin_bound", long_name=f"{attributes('spin_bound')['long_name']} ({imp.spin_source})"))
    res["angle_uncertainty_deg"] = ("impact", imp.angle_uncertainty_deg, attributes(
        "angle_uncertainty_deg", long_name=f"{attributes('angle_uncertainty_deg')['long_name']} ({imp.angle_source})"))
    res["e_n_limit"] = ("impact", en_limit, attributes("e_n_limit"))
    for side, mm in (("low", "min"), ("high", "max")):
        res[f"e_n_shift_{side}_angle"] = ("impact", np.nan_to_num(out[f"e_n_{mm}_angle"] - out["e_n"]), {
            "units": "1", "long_name": f"{'most negative' if side == 'low' else 'most positive'} change of the model "
                                      "e_n at +/- one angle uncertainty (zero spin)"})
    for name, (meanings, long_name) in _FLAGS.items():
        res[name] = ("impact", flags[name].astype(np.int8), {
            "flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": meanings, "long_name": long_name})
    return res


def write_flags(ds: xr.Dataset, csv_path, nc_path=None):
    """Write the flags as CSV (one row per impact, keyed by ``row``) and optionally NetCDF, atomically.

    Returns
    -------
    tuple of pathlib.Path
        The files written.

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> flags = flag_measurements(table.head(2), fit, n_spin=4, spin_fractions=(1.0,))
    >>> csv_path, nc_path = write_flags(flags, "flags.csv", "flags.nc")
    >>> import pandas as pd
    >>> pd.read_csv(csv_path)["row"].tolist(), nc_path.name
    ([1, 2], 'flags.nc')
    """
    table = ds.to_dataframe().reset_index(drop=True)
    # the row, then the analyst's labels (their own columns under the names of the CSV), then the flags
    labels = [n for n, v in ds.data_vars.items() if n == "id" or CSV_COLUMN_ATTR in v.attrs]
    cols = ["row", *labels] + [c for c in table.columns if c not in ("row", "impact", *labels)]
    table = table[cols].rename(columns={n: str(v.attrs[CSV_COLUMN_ATTR]) for n, v in ds.data_vars.items()
                                        if CSV_COLUMN_ATTR in v.attrs and str(v.attrs[CSV_COLUMN_ATTR]) not in cols})

    with all_or_nothing():  # both files or neither
        written = [write_csv(table, csv_path, float_format="%.8g")]
        if nc_path is not None:
            written.append(write_netcdf(ds, nc_path))
    return tuple(written)
