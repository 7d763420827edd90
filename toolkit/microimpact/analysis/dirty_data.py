"""Measured-impact tables of the kinds real laboratories produce, for testing the fit's verdict.

Three kinds (issue 51), each made by a function from parameters chosen here, in the CSV format the
readers take:

* :func:`make_outlier_impacts`: the damping law of the toolkit with a few gross outliers
  (mis-tracked rebounds, tens of standard deviations off);
* :func:`make_thornton_impacts`: a law outside the toolkit's family: Thornton's (1997) closed form
  for the elastic-plastic impact of a sphere, e(V_y / V), times the adhesive
  energy loss of a capture speed v_c, e = e_T sqrt(1 - (v_c/V)^2) (an energy balance: the work
  lost to adhesion is that of an impact at v_c);
* :func:`make_rebound_only_impacts`: the toolkit's law, given as incident and rebound normal
  speeds with an uncertainty on the rebound speed only.

References
----------
* Thornton, C. (1997). Coefficient of restitution for collinear collisions of elastic-perfectly
  plastic spheres. J. Appl. Mech. 64(2), 383-386. doi:10.1115/1.2787319
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from microimpact.analysis.synthetic import make_synthetic_impacts
from microimpact.model import thornton_ning

__all__ = ["thornton_restitution", "make_outlier_impacts", "make_thornton_impacts", "make_rebound_only_impacts",
           "DIRTY_MATERIAL_PAIR"]

#: the materials-config pair the tables name (its density, stiffness and w_A are the fits' base)
DIRTY_MATERIAL_PAIR = "ammonium_fluorescein_on_silicon"


def thornton_restitution(speed, yield_speed):
    """Thornton's (1997) coefficient of restitution of an elastic-perfectly plastic sphere. [-]

    e = sqrt(6 sqrt(3) / 5) sqrt(1 - (V_y/V)^2 / 6) [ (V_y/V) / ((V_y/V) + 2 sqrt(6/5 - (V_y/V)^2 / 5)) ]^(1/4)
    for V > V_y, and 1 (elastic) for V <= V_y: the closed form (TN12) of
    :func:`microimpact.model.thornton_ning.thornton_restitution`, as a function of the speed.

    Parameters
    ----------
    speed : array_like
        Impact speed V. [m/s]
    yield_speed : float
        Speed V_y at which plastic yield begins. [m/s]

    Returns
    -------
    numpy.ndarray

    References
    ----------
    Thornton (1997), doi:10.1115/1.2787319 (its closed-form coefficient of restitution).

    Examples
    --------
    Continuous at V_y (e = 1) and falling as V^(-1/4) far above it:

    >>> round(float(thornton_restitution(1.0, 1.0)), 6)
    1.0
    >>> e = thornton_restitution(np.array([100.0, 1600.0]), 1.0)
    >>> round(float(e[0] / e[1]), 2)  # 16^(1/4)
    2.0
    """
    v = np.asarray(speed, dtype=float)
    return np.where(v <= yield_speed, 1.0, thornton_ning.thornton_restitution(yield_speed / v))


def _table(radius, speed, e_n, sigma, prefix, seed_note) -> pd.DataFrame:
    n = len(speed)
    df = pd.DataFrame({
        "id": [f"{prefix}-{i + 1:03d}" for i in range(n)], "material_pair": DIRTY_MATERIAL_PAIR,
        "radius [um]": np.round(np.asarray(radius) * 1e6, 6), "speed [m/s]": [float(f"{x:.6g}") for x in speed],
        "incidence_angle [deg]": 0.0, "e_n [1]": [float(f"{x:.6g}") for x in e_n],
        "e_n_uncertainty [1]": [float(f"{x:.3g}") for x in sigma]})
    df.attrs["generating"] = seed_note
    return df


def make_outlier_impacts(n_outliers: int = 3, *, seed: int = 51, zeta_hertz: float = 0.8, zeta_adhesion: float = 22.0,
                         offset_sigmas: float = 20.0) -> pd.DataFrame:
    """The toolkit's damping law on 40 rows (2 sizes x 20 speeds, 3 % noise stated) with
    ``n_outliers`` rows moved by +/- ``offset_sigmas`` stated uncertainties (clipped to [0, 1]).

    Returns
    -------
    pandas.DataFrame
        The CSV columns; ``attrs["outlier_ids"]`` the moved rows' ids, ``attrs["truth"]`` the
        generating zeta_H and zeta_A.

    Examples
    --------
    >>> df = make_outlier_impacts(2)
    >>> len(df), df.attrs["outlier_ids"]
    (40, ['dirty-025', 'dirty-036'])
    """
    df = make_synthetic_impacts(radii=(1.5e-6, 3.0e-6), n_per_radius=20, zeta_hertz=zeta_hertz,
                                zeta_adhesion=zeta_adhesion, speed_rel_sd=0.0, angle_sd_deg=0.0, seed=seed)
    rng = np.random.default_rng(seed + 1)
    rows = np.sort(rng.choice(np.arange(2, len(df) - 2), size=n_outliers, replace=False))
    e, s = df["e_n [1]"].to_numpy(float).copy(), df["e_n_uncertainty [1]"].to_numpy(float)
    for k in rows:  # away from the nearer bound of [0, 1], so the clip never undoes the move
        sign = -1.0 if e[k] > 0.5 else 1.0
        e[k] = float(np.clip(e[k] + sign * offset_sigmas * s[k], 0.0, 1.0))
    df["e_n [1]"] = [float(f"{x:.6g}") for x in e]
    df["id"] = [f"dirty-{i + 1:03d}" for i in range(len(df))]
    df.attrs["outlier_ids"] = [str(df["id"].iloc[k]) for k in rows]
    df.attrs["truth"] = {"zeta_hertz": zeta_hertz, "zeta_adhesion": zeta_adhesion}
    return df


def make_thornton_impacts(*, seed: int = 1997, radii=(1.2e-6, 2.4e-6, 4.0e-6), n_per_radius: int = 18,
                          yield_speed: float = 1.4, capture_speed_at_1um: float = 1.6, noise: float = 0.015,
                          max_speed: float = 40.0) -> pd.DataFrame:
    """e_n(v) of :func:`thornton_restitution` with adhesive capture, noise ``noise`` (stated).

    The capture speed scales as r^(-5/6) with radius (as the JKR capture speed does, Thornton &
    Ning 1998): v_c(r) = ``capture_speed_at_1um`` (r / 1 um)^(-5/6). Speeds are log-spaced from
    1.15 v_c to ``max_speed``.

    Examples
    --------
    >>> df = make_thornton_impacts()
    >>> len(df), bool(df["e_n [1]"].max() < 1)
    (54, True)
    """
    rng = np.random.default_rng(seed)
    rad, speed, e_n = [], [], []
    for r in radii:
        vc = capture_speed_at_1um * (r / 1e-6) ** (-5 / 6)
        v = np.geomspace(1.15 * vc, max_speed, n_per_radius)
        e = thornton_restitution(v, yield_speed) * np.sqrt(1 - (vc / v) ** 2)
        rad += [r] * v.size
        speed += list(v)
        e_n += list(np.clip(e + noise * rng.normal(size=v.size), 0.0, 1.0))
    return _table(rad, speed, e_n, [noise] * len(speed), "thornton",
                  {"yield_speed": yield_speed, "capture_speed_at_1um": capture_speed_at_1um, "noise": noise,
                   "seed": seed})


def make_rebound_only_impacts(*, seed: int = 4, zeta_hertz: float = 0.35, zeta_adhesion: float = 35.0,
                              rebound_rel_sd: float = 0.03) -> pd.DataFrame:
    """The toolkit's law as incident and rebound normal speeds, the rebound speed's uncertainty
    stated and the incident speed's not (30 rows, 2 sizes).

    Examples
    --------
    >>> list(make_rebound_only_impacts().columns)[-3:]
    ['normal_speed [m/s]', 'rebound_normal_speed [m/s]', 'rebound_normal_speed_uncertainty [m/s]']
    """
    src = make_synthetic_impacts(radii=(2.0e-6, 3.2e-6), n_per_radius=15, zeta_hertz=zeta_hertz,
                                 zeta_adhesion=zeta_adhesion, speed_rel_sd=0.0, angle_sd_deg=0.0, e_n_rel_sd=0.0,
                                 seed=seed)
    rng = np.random.default_rng(seed)
    v = src["speed [m/s]"].to_numpy(float)
    rebound = src["e_n [1]"].to_numpy(float) * v
    measured = rebound * (1 + rebound_rel_sd * rng.normal(size=v.size))
    return pd.DataFrame({"id": [f"rebound-{i + 1:02d}" for i in range(v.size)], "material_pair": DIRTY_MATERIAL_PAIR,
                         "radius [um]": src["radius [um]"], "normal_speed [m/s]": v,
                         "rebound_normal_speed [m/s]": [float(f"{x:.6g}") for x in measured],
                         "rebound_normal_speed_uncertainty [m/s]": [float(f"{x:.3g}") for x in rebound_rel_sd * rebound]})
