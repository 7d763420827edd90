"""SYNTHETIC microsphere e_n(v_n) data generated from stated parameters (not measurements).

No digitized copy of the Wall et al. (1990) e_n(v) data that Cheng, Brach & Dunn (2002) fit in
their Fig. 3 is public, so the bundled example data ``data/synthetic_microspheres.csv`` is made
here, by the model itself, from the material of Table 1 row 2 (ammonium fluorescein on polished
silicon, :data:`microimpact.model.parameters.TABLE1_ROW2`) at radii over the Table 1 row 1 range,
plus a stated noise model. It exists to exercise and test the fit; it is not evidence for
the model. Regenerate it with ``python workflow/scripts/make_synthetic_data.py``.

Noise model (defaults)
----------------------
For each radius r, ``n_per_radius`` nominal speeds v are log-spaced from ``start_factor`` times the
capture velocity v_c(r) to ``max_speed``. Per impact (one ``numpy.random.default_rng(seed)`` stream,
drawn in file order):

* true incidence angle alpha = |N(0, angle_sd_deg)| (recorded as 0 deg with uncertainty
  ``angle_sd_deg``); true normal speed v cos(alpha);
* recorded speed = v (1 + speed_rel_sd N(0,1)), ``speed_uncertainty`` = speed_rel_sd x recorded speed;
* recorded e_n = e_n,true (1 + e_n_rel_sd N(0,1)), clipped to [0, 1], with e_n,true the model at the
  true normal speed; ``e_n_uncertainty`` = e_n_rel_sd x e_n,true (the stated instrument precision).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd

from microimpact.dynamics.nonlinear import capture_velocity
from microimpact.io.files import write_csv
from microimpact.io.materials import material_contact
from microimpact.model.parameters import TABLE1, TABLE1_ROW2
from microimpact.solvers import engine
from microimpact.solvers.impact import simulate_many

__all__ = ["SYNTHETIC_DEFAULTS", "SYNTHETIC_OBLIQUE_DEFAULTS", "make_synthetic_impacts", "make_synthetic_oblique",
           "write_synthetic_impacts"]

#: generating parameters of data/synthetic_microspheres.csv; the material is Table 1 row 2
SYNTHETIC_DEFAULTS = dict(
    # [m]: the ends of the Table 1 row 1 range (1.29-3.45 um) and two sizes between them
    radii=(TABLE1["row1_small"].radius, 1.72e-6, 2.58e-6, TABLE1["row1_large"].radius),
    density=TABLE1_ROW2.density,  # [kg/m3]
    stiffness=TABLE1_ROW2.stiffness,  # [Pa]
    # [J/m2]: Table 1 row 2's w_A (f0 = 7.422 N/m at 3.45 um, Eq. (7)) to the 6 digits of the
    # bundled materials config, so that a fit with that config holds the generating w_A exactly
    work_of_adhesion=round(TABLE1_ROW2.work_of_adhesion, 6),
    zeta_hertz=TABLE1_ROW2.zeta_hertz,  # [-]
    zeta_adhesion=TABLE1_ROW2.zeta_adhesion,  # [-]
    friction=TABLE1_ROW2.friction,  # [-] (does not affect e_n)
    n_per_radius=25,
    start_factor=1.1,  # first speed = 1.1 v_c(r)
    max_speed=100.0,  # [m/s]
    e_n_rel_sd=0.03,
    speed_rel_sd=0.01,
    angle_sd_deg=1.0,
    seed=20020101,
    material_pair="ammonium_fluorescein_on_silicon",
)


def make_synthetic_impacts(**overrides) -> pd.DataFrame:
    """Make the synthetic e_n(v) table, in the measured-impact CSV format (units in the header).

    Parameters
    ----------
    **overrides
        Any key of :data:`SYNTHETIC_DEFAULTS`: ``radii`` [m], ``density`` [kg/m^3], ``stiffness``
        [Pa], ``work_of_adhesion`` [J/m^2], ``zeta_hertz``, ``zeta_adhesion``, ``friction`` [-],
        ``n_per_radius``, ``start_factor`` [-], ``max_speed`` [m/s], ``e_n_rel_sd``,
        ``speed_rel_sd`` [-], ``angle_sd_deg`` [deg], ``seed``, ``material_pair``. Zero noise
        levels give exact model values.

    Returns
    -------
    pandas.DataFrame
        Columns ``id, size_class, material_pair, radius [um], speed [m/s], incidence_angle [deg],
        e_n [1], speed_uncertainty [m/s], incidence_angle_uncertainty [deg], e_n_uncertainty [1]``
        (the angle uncertainty column only when ``angle_sd_deg`` > 0). ``attrs["generating"]``
        holds the parameters, ``attrs["true_e_n"]`` and ``attrs["true_normal_speed"]`` the
        noise-free values.

    References
    ----------
    Cheng, Brach & Dunn (2002), Table 1 row 2 (the material) and Eqs. (21), (27) (the model).

    Examples
    --------
    Five noise-free impacts of 3.45 um spheres, from just above the capture velocity to 100 m/s:
    e_n rises from capture and falls again where the Hertzian damping takes over:

    >>> raw = make_synthetic_impacts(radii=(3.45e-6,), n_per_radius=5, e_n_rel_sd=0.0, speed_rel_sd=0.0,
    ...                              angle_sd_deg=0.0)
    >>> print(raw[["speed [m/s]", "e_n [1]"]].round(4).to_string(index=False))
     speed [m/s]  e_n [1]
          1.5942   0.2592
          4.4864   0.6555
         12.6260   0.7241
         35.5331   0.7356
        100.0000   0.7164
    """
    unknown = set(overrides) - set(SYNTHETIC_DEFAULTS)
    if unknown:
        raise ValueError(f"unknown parameter(s) {sorted(unknown)}; known: {sorted(SYNTHETIC_DEFAULTS)}")
    p = {**SYNTHETIC_DEFAULTS, **overrides}
    rng = np.random.default_rng(p["seed"])
    rows = []
    true_e, true_vn = [], []
    material = SimpleNamespace(**p)
    for r in p["radii"]:
        c = material_contact(material, r)
        vc = capture_velocity(c, solver_rtol=1e-10)  # as when data/synthetic_microspheres.csv was made
        v = np.geomspace(p["start_factor"] * vc, p["max_speed"], p["n_per_radius"])
        alpha = np.abs(rng.normal(0.0, p["angle_sd_deg"], v.size)) if p["angle_sd_deg"] > 0 else np.zeros(v.size)
        vn = v * np.cos(np.radians(alpha))
        e = engine.solve_normal_many(c, vn, rtol=1e-10)["e_n"]
        speed = v * (1.0 + p["speed_rel_sd"] * rng.normal(size=v.size))
        e_rec = np.clip(e * (1.0 + p["e_n_rel_sd"] * rng.normal(size=v.size)), 0.0, 1.0)
        label = f"d{2 * r * 1e6:.2f}um"
        for i in range(v.size):
            row = {
                "id": f"syn-{label}-{i + 1:02d}",
                "size_class": label,
                "material_pair": p["material_pair"],
                "radius [um]": round(r * 1e6, 6),
                "speed [m/s]": float(f"{speed[i]:.6g}"),
                "incidence_angle [deg]": 0.0,
                "e_n [1]": float(f"{e_rec[i]:.6g}"),
                "speed_uncertainty [m/s]": float(f"{p['speed_rel_sd'] * speed[i]:.3g}"),
                "e_n_uncertainty [1]": float(f"{p['e_n_rel_sd'] * e[i]:.3g}"),
            }
            if p["angle_sd_deg"] > 0:
                row["incidence_angle_uncertainty [deg]"] = p["angle_sd_deg"]
            rows.append(row)
        true_e.append(e)
        true_vn.append(vn)
    df = pd.DataFrame(rows)
    if p["e_n_rel_sd"] == 0:
        df = df.drop(columns="e_n_uncertainty [1]")
    if p["speed_rel_sd"] == 0:
        df = df.drop(columns="speed_uncertainty [m/s]")
    df.attrs["generating"] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in p.items()}
    df.attrs["true_e_n"] = np.concatenate(true_e)
    df.attrs["true_normal_speed"] = np.concatenate(true_vn)
    return df


def write_synthetic_impacts(path, **overrides):
    """Make the synthetic table and write it atomically as CSV (:func:`microimpact.io.write_csv`).

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    Three impacts of one size, written as the CSV format the readers take:

    >>> path = write_synthetic_impacts("synthetic.csv", radii=(3.45e-6,), n_per_radius=3)
    >>> from microimpact.io import read_impacts
    >>> len(read_impacts(path))
    3
    """
    df = make_synthetic_impacts(**overrides)
    return write_csv(df, path, float_format="%.6g")


#: generating parameters of the synthetic OBLIQUE table (:func:`make_synthetic_oblique`); Table 1 row 2
SYNTHETIC_OBLIQUE_DEFAULTS = dict(
    radii=(1.72e-6, 3.45e-6),  # [m]
    density=TABLE1_ROW2.density,  # [kg/m3]
    stiffness=TABLE1_ROW2.stiffness,  # [Pa]
    work_of_adhesion=round(TABLE1_ROW2.work_of_adhesion, 6),  # [J/m2]
    zeta_hertz=TABLE1_ROW2.zeta_hertz,  # [-]
    zeta_adhesion=TABLE1_ROW2.zeta_adhesion,  # [-]
    friction=TABLE1_ROW2.friction,  # [-]
    speeds=(15.0, 30.0, 60.0, 100.0),  # [m/s]
    incidence_deg=(20.0, 35.0, 50.0, 60.0, 70.0),  # [deg]
    e_n_rel_sd=0.03,
    tangential_sd=0.02,  # [-] standard uncertainty of e_t (or of the column's quantity, scaled)
    speed_rel_sd=0.01,
    angle_sd_deg=0.5,  # [deg]
    tangential_column="tangential_restitution",  # or rebound_angle, rebound_spin
    seed=20020102,
    material_pair="ammonium_fluorescein_on_silicon",
)


def make_synthetic_oblique(**overrides) -> pd.DataFrame:
    """SYNTHETIC oblique impacts (not measurements): e_n and one tangential column per impact.

    Every radius x speed x incidence angle of :data:`SYNTHETIC_OBLIQUE_DEFAULTS` (overridable),
    without initial spin; captured impacts (no rebound) are left out. Per impact, one ``numpy.random.default_rng(seed)`` stream: the true speed
    and angle are the nominal ones; the RECORDED speed and angle carry Gaussian errors
    (``speed_rel_sd`` relative, ``angle_sd_deg``), stated as uncertainties; e_n gets relative noise
    ``e_n_rel_sd``; the tangential column (``tangential_column``: ``tangential_restitution`` [1],
    ``rebound_angle`` [deg] or ``rebound_spin`` [rad/s]) gets Gaussian noise of standard deviation
    ``tangential_sd`` x its scale (1 for e_t, 10 deg for the angle, v_t,in / r for the spin).

    Returns
    -------
    pandas.DataFrame
        In the measured-impact CSV format (units in the header); ``attrs["generating"]`` holds the
        parameters.

    Examples
    --------
    Two noise-free impacts at 30 m/s: at 20 deg the sphere ends rolling, and the tangential
    restitution is the rigid-body 5/7 (the 2/7 rule); at 60 deg it slides throughout:

    >>> df = make_synthetic_oblique(radii=(3.45e-6,), speeds=(30.0,), incidence_deg=(20.0, 60.0), e_n_rel_sd=0.0,
    ...                             tangential_sd=0.0, speed_rel_sd=0.0, angle_sd_deg=0.0)
    >>> e_t = df["tangential_restitution [1]"]
    >>> abs(float(e_t[0]) - 5 / 7) < 1e-6, bool(e_t[1] > 5 / 7)
    (True, True)
    """
    unknown = set(overrides) - set(SYNTHETIC_OBLIQUE_DEFAULTS)
    if unknown:
        raise ValueError(f"unknown parameter(s) {sorted(unknown)}; known: {sorted(SYNTHETIC_OBLIQUE_DEFAULTS)}")
    p = {**SYNTHETIC_OBLIQUE_DEFAULTS, **overrides}
    col = p["tangential_column"]
    if col not in ("tangential_restitution", "rebound_angle", "rebound_spin"):
        raise ValueError(f"tangential_column must be tangential_restitution, rebound_angle or rebound_spin, got {col!r}")
    rng = np.random.default_rng(p["seed"])
    material = SimpleNamespace(**p)
    rows = []
    for r in p["radii"]:
        c = material_contact(material, r)
        v, a = np.meshgrid(np.asarray(p["speeds"], float), np.asarray(p["incidence_deg"], float), indexing="ij")
        v, a = v.ravel(), a.ravel()
        ds = simulate_many(c, v, a, rtol=1e-10)
        vt_in = v * np.sin(np.radians(a))
        truth = {"tangential_restitution": (ds["velocity_out_t"].values / vt_in, 1.0, "1"),
                 "rebound_angle": (np.degrees(np.arctan2(ds["velocity_out_t"].values, ds["velocity_out_n"].values)),
                                   10.0, "deg"),
                 "rebound_spin": (np.sqrt(sum(ds[k].values ** 2 for k in ("omega_out_n", "omega_out_t", "omega_out_tp"))),
                                  vt_in / r, "rad/s")}[col]
        e = ds["e_n"].values
        for i in range(v.size):
            if ds["outcome"].values[i]:
                continue  # captured: no rebound to measure
            sd_t = p["tangential_sd"] * (truth[1] if np.isscalar(truth[1]) else truth[1][i])
            t_rec = truth[0][i] + sd_t * rng.normal()
            if col == "rebound_spin":
                t_rec = abs(t_rec)
            rows.append({
                "id": f"obl-r{r * 1e6:.2f}-{i + 1:02d}", "material_pair": p["material_pair"],
                "radius [um]": round(r * 1e6, 6),
                "speed [m/s]": float(f"{v[i] * (1.0 + p['speed_rel_sd'] * rng.normal()):.6g}"),
                "incidence_angle [deg]": float(f"{a[i] + p['angle_sd_deg'] * rng.normal():.5g}"),
                "e_n [1]": float(f"{np.clip(e[i] * (1.0 + p['e_n_rel_sd'] * rng.normal()), 0.0, 1.0):.6g}"),
                f"{col} [{truth[2]}]": float(f"{t_rec:.6g}"),
                "speed_uncertainty [m/s]": float(f"{p['speed_rel_sd'] * v[i]:.3g}"),
                "incidence_angle_uncertainty [deg]": p["angle_sd_deg"],
                "e_n_uncertainty [1]": float(f"{p['e_n_rel_sd'] * e[i]:.3g}"),
                f"{col}_uncertainty [{truth[2]}]": float(f"{sd_t:.3g}"),
            })
    df = pd.DataFrame(rows)
    df.attrs["generating"] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in p.items()}
    return df
