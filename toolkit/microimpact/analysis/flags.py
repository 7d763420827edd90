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
* ``rotation_sensitive``: over spin, range(mu_t) or range(mu_t') > ``mu`` (default 0.05), or
  range(K_L) > ``K_L`` (default 0.05), or range(e_n) > the e_n limit (never, by the decoupling of
  the normal motion; kept so that the definition does not depend on it), or some spin samples are
  captured and others not.
* ``angle_sensitive``: over angle, range(e_n) > the e_n limit, or range(mu_t) or range(mu_t') >
  ``mu``, or range(K_L) > ``K_L``, or the outcome changes.
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

import numpy as np
import pandas as pd
import xarray as xr

from microimpact.solvers.impact import simulate_many
from microimpact.model.contact import Contact

__all__ = ["flag_measurements", "write_flags", "fibonacci_sphere", "DEFAULT_THRESHOLDS"]

#: default flag thresholds (see the module docstring)
DEFAULT_THRESHOLDS = {"mu": 0.05, "K_L": 0.05, "e_n": 0.02, "near_capture_ratio": 1.5}
_COEFS = ("e_n", "mu_t", "mu_tp", "K_L", "K_t")
_COEF_META = {
    "e_n": "normal coefficient of restitution, Eq. (21)",
    "mu_t": "tangential impulse ratio in t, Eq. (22)",
    "mu_tp": "tangential impulse ratio in t', Eq. (23)",
    "K_L": "translational kinetic energy loss ratio, Eq. (25)",
    "K_t": "total kinetic energy loss ratio, Eq. (24)",
}


def fibonacci_sphere(n: int) -> np.ndarray:
    """``n`` nearly uniformly spread unit vectors (Fibonacci lattice), shape (n, 3). [-]"""
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = math.pi * (1.0 + math.sqrt(5.0)) * i
    rho = np.sqrt(1.0 - z * z)
    return np.column_stack([z, rho * np.cos(phi), rho * np.sin(phi)])  # (n, t, t') components


def _contact_for(obj, radius: float) -> Contact:
    """Contact of this radius from a DampingFit / MaterialPair (``.contact(r)``) or a Contact."""
    if isinstance(obj, Contact):
        if obj.radius == radius:
            return obj
        return Contact.from_work_of_adhesion(
            radius, obj.density, obj.stiffness, obj.work_of_adhesion, zeta_hertz=obj.zeta_hertz,
            zeta_adhesion=obj.zeta_adhesion, friction=obj.friction,
            damping_reference_speed=obj.damping_reference_speed)
    if hasattr(obj, "contact"):
        return obj.contact(radius)
    raise ValueError(f"contact_or_fit must be a Contact, DampingFit or MaterialPair, got {type(obj).__name__}")


def _progress(enabled, message):
    if enabled:
        print(message, file=sys.stderr, flush=True)


def flag_measurements(table, contact_or_fit, *, spin_bound=None, angle_uncertainty_deg=None,
                      default_angle_uncertainty_deg: float = 2.0, n_spin: int = 12,
                      spin_fractions=(0.5, 1.0), angle_offsets=(-1.0, 0.0, 1.0), thresholds=None,
                      rtol: float = 1e-8, progress: bool = False) -> xr.Dataset:
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
    """
    from microimpact.dynamics.nonlinear import capture_velocity

    th = dict(DEFAULT_THRESHOLDS)
    if thresholds:
        unknown = set(thresholds) - set(th)
        if unknown:
            raise ValueError(f"unknown threshold(s) {sorted(unknown)}; known: {sorted(th)}")
        th.update({k: float(v) for k, v in thresholds.items()})
    df = table
    src = df.attrs.get("source", "impact table")
    n = len(df)
    if n == 0:
        raise ValueError(f"{src}: no impacts to flag")
    rows = df["row"].to_numpy(dtype=np.int64) if "row" in df.columns else np.arange(1, n + 1)
    radius = df["radius"].to_numpy(dtype=float)
    inc = df["incidence_deg"].to_numpy(dtype=float) if "incidence_deg" in df.columns else np.zeros(n)
    inc = np.where(np.isfinite(inc), inc, 0.0)
    speed = df["speed"].to_numpy(dtype=float) if "speed" in df.columns else np.full(n, np.nan)
    vn = df["normal_speed"].to_numpy(dtype=float)
    speed = np.where(np.isfinite(speed), speed, vn / np.cos(np.radians(inc)))
    for name, x in (("radius", radius), ("speed", speed)):
        bad = ~np.isfinite(x) | (x <= 0)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{src}: row {rows[i]}, column {name!r}: {x[i]!r} must be finite and > 0")
    vn = speed * np.cos(np.radians(inc))

    if angle_uncertainty_deg is not None:
        sig_a = np.full(n, float(angle_uncertainty_deg))
        angle_source = "argument"
    elif "incidence_deg_uncertainty" in df.columns and np.isfinite(df["incidence_deg_uncertainty"].to_numpy(dtype=float)).any():
        sig_a = df["incidence_deg_uncertainty"].to_numpy(dtype=float)
        sig_a = np.where(np.isfinite(sig_a), sig_a, default_angle_uncertainty_deg)
        angle_source = "table column incidence_angle_uncertainty (default where empty)"
    else:
        sig_a = np.full(n, float(default_angle_uncertainty_deg))
        angle_source = "default"
    if np.any(~np.isfinite(sig_a) | (sig_a < 0)):
        raise ValueError(f"angle uncertainty must be finite and >= 0 deg, got {angle_uncertainty_deg!r}")

    if spin_bound is None:
        bound = speed / radius
        spin_source = "rolling spin speed / radius per impact"
    else:
        bound = np.broadcast_to(np.asarray(spin_bound, dtype=float), (n,)).copy()
        spin_source = "argument"
        if np.any(~np.isfinite(bound) | (bound < 0)):
            raise ValueError(f"spin_bound must be finite and >= 0 rad/s, got {spin_bound!r}")

    # sample sets: spin index 0 is the zero spin; angle offset 0 is the nominal angle
    fr = np.asarray([f for f in spin_fractions if f != 0], dtype=float)
    dirs = fibonacci_sphere(n_spin)
    unit = np.vstack([np.zeros((1, 3)), np.repeat(dirs, fr.size, axis=0) * np.tile(fr, n_spin)[:, None]])
    offsets = np.unique(np.append(np.asarray(angle_offsets, dtype=float), 0.0))
    k0 = int(np.flatnonzero(offsets == 0.0)[0])

    th_en = df["e_n_uncertainty"].to_numpy(dtype=float) if "e_n_uncertainty" in df.columns else np.full(n, np.nan)
    en_limit = np.where(np.isfinite(th_en) & (th_en > 0), th_en, th["e_n"])

    out = {k: np.full(n, np.nan) for k in
           [f"{c}{s}" for c in _COEFS for s in ("", "_min_spin", "_max_spin", "_min_angle", "_max_angle", "_min", "_max")]}
    out["capture_velocity"] = np.full(n, np.nan)
    switch_spin = np.zeros(n, dtype=bool)
    switch_angle = np.zeros(n, dtype=bool)
    radii, inverse = np.unique(radius, return_inverse=True)
    t0 = time.perf_counter()
    for gi, r in enumerate(radii):
        idx = np.flatnonzero(inverse == gi)
        contact = _contact_for(contact_or_fit, float(r))
        vc = capture_velocity(contact)
        out["capture_velocity"][idx] = vc
        a = inc[idx, None] + offsets[None, :] * sig_a[idx, None]  # (impact, angle)
        alpha = xr.DataArray(np.minimum(np.abs(a), 89.9), dims=("impact", "angle_sample"))
        azim = xr.DataArray(np.where(a < 0, 180.0, 0.0), dims=("impact", "angle_sample"))
        w = bound[idx, None, None] * unit[None, :, :]  # (impact, spin, 3)
        omega = tuple(xr.DataArray(w[:, :, k], dims=("impact", "spin_sample")) for k in range(3))
        ds = simulate_many(contact, xr.DataArray(speed[idx], dims="impact"), alpha, azim, omega, rtol=rtol)
        ds = ds.transpose("impact", "spin_sample", "angle_sample")
        for c in _COEFS:
            x = ds[c].values
            with np.errstate(invalid="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN slices (captured samples)
                out[c][idx] = x[:, 0, k0]
                out[f"{c}_min_spin"][idx] = np.nanmin(x[:, :, k0], axis=1)
                out[f"{c}_max_spin"][idx] = np.nanmax(x[:, :, k0], axis=1)
                out[f"{c}_min_angle"][idx] = np.nanmin(x[:, 0, :], axis=1)
                out[f"{c}_max_angle"][idx] = np.nanmax(x[:, 0, :], axis=1)
                out[f"{c}_min"][idx] = np.nanmin(x, axis=(1, 2))
                out[f"{c}_max"][idx] = np.nanmax(x, axis=(1, 2))
        oc = ds["outcome"].values
        switch_spin[idx] = oc[:, :, k0].min(axis=1) != oc[:, :, k0].max(axis=1)
        switch_angle[idx] = oc[:, 0, :].min(axis=1) != oc[:, 0, :].max(axis=1)
        _progress(progress, f"flags: radius {r * 1e6:.4g} um ({gi + 1}/{radii.size}), {idx.size} impacts x "
                  f"{unit.shape[0]} spins x {offsets.size} angles, {time.perf_counter() - t0:.1f} s")

    def rng(c, s):
        return np.nan_to_num(out[f"{c}_max_{s}"] - out[f"{c}_min_{s}"], nan=0.0)

    rot = ((rng("mu_t", "spin") > th["mu"]) | (rng("mu_tp", "spin") > th["mu"]) | (rng("K_L", "spin") > th["K_L"])
           | (rng("e_n", "spin") > en_limit) | switch_spin)
    ang = ((rng("e_n", "angle") > en_limit) | (rng("mu_t", "angle") > th["mu"]) | (rng("mu_tp", "angle") > th["mu"])
           | (rng("K_L", "angle") > th["K_L"]) | switch_angle)
    ratio = vn / out["capture_velocity"]
    near = ratio < th["near_capture_ratio"]

    res = xr.Dataset(coords={"impact": ("impact", np.arange(n), {"long_name": "impact index in the table"}),
                             "row": ("impact", rows, {"long_name": "data row of the impact in the source CSV"})})
    for c in _COEFS:
        units = "1"
        res[c] = ("impact", out[c], {"units": units, "long_name": f"{_COEF_META[c]}, zero spin, nominal angle"})
        for s, what in (("spin", "over initial spin samples at the nominal angle"),
                        ("angle", "over incidence-angle samples at zero spin"), ("", "over all samples")):
            suffix = f"_{s}" if s else ""
            for mm in ("min", "max"):
                res[f"{c}_{mm}{suffix}"] = ("impact", out[f"{c}_{mm}{suffix}"], {
                    "units": units, "long_name": f"{mm}imum {_COEF_META[c]} {what}"})
    res["capture_velocity"] = ("impact", out["capture_velocity"], {"units": "m s-1", "long_name": "capture velocity of this radius"})
    res["capture_speed_ratio"] = ("impact", ratio, {"units": "1", "long_name": "incident normal speed / capture velocity"})
    res["spin_bound"] = ("impact", bound, {"units": "rad s-1", "long_name": f"largest initial spin sampled ({spin_source})"})
    res["angle_uncertainty_deg"] = ("impact", sig_a, {"units": "degree", "long_name": f"incidence-angle uncertainty used ({angle_source})"})
    res["e_n_limit"] = ("impact", en_limit, {"units": "1", "long_name": "e_n spread limit (e_n_uncertainty, else threshold_e_n)"})
    flag_attrs = {"flag_values": np.array([0, 1], dtype=np.int8)}
    res["rotation_sensitive"] = ("impact", rot.astype(np.int8), {**flag_attrs, "flag_meanings": "insensitive rotation_sensitive",
        "long_name": "range over spin of mu_t or mu_t' > threshold_mu, or of K_L > threshold_K_L, or of e_n > e_n_limit, or outcome changes"})
    res["angle_sensitive"] = ("impact", ang.astype(np.int8), {**flag_attrs, "flag_meanings": "insensitive angle_sensitive",
        "long_name": "range over angle of e_n > e_n_limit, or of mu_t or mu_t' > threshold_mu, or of K_L > threshold_K_L, or outcome changes"})
    res["near_capture"] = ("impact", near.astype(np.int8), {**flag_attrs, "flag_meanings": "far near_capture",
        "long_name": "capture_speed_ratio < threshold_near_capture_ratio"})
    res.attrs.update({f"threshold_{k}": v for k, v in th.items()})
    res.attrs.update({
        "title": "measurement flags: sensitivity to unmeasured spin and angle error, closeness to capture",
        "source": str(src), "n_spin_directions": int(n_spin), "spin_fractions": fr,
        "angle_offsets_sigma": offsets, "spin_samples": int(unit.shape[0]), "angle_samples": int(offsets.size),
        "spin_bound_source": spin_source, "angle_uncertainty_source": angle_source,
        "model": "Cheng, Brach & Dunn (2002); coefficients from microimpact.simulate_many",
        "Conventions": "CF-1.8",
    })
    if "sha256" in df.attrs:
        res.attrs["source_sha256"] = df.attrs["sha256"]
    return res


def write_flags(ds: xr.Dataset, csv_path, nc_path=None):
    """Write the flags as CSV (one row per impact, keyed by ``row``) and optionally NetCDF, atomically.

    Returns
    -------
    tuple of pathlib.Path
        The files written.
    """
    from microimpact.io import write_csv, write_netcdf

    table = ds.to_dataframe().reset_index(drop=True)
    cols = ["row"] + [c for c in table.columns if c not in ("row", "impact")]
    table = table[cols]
    written = [write_csv(table, csv_path, float_format="%.8g")]
    if nc_path is not None:
        written.append(write_netcdf(ds, nc_path))
    return tuple(written)
