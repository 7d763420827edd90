"""Comparison of the model's tangential/rotational rebound with the Kharaz et al. (2001) experiment.

Data: ``data/kharaz2001_oblique.csv`` (real measurements, digitized; provenance in data/README.md):
5 mm aluminium-oxide spheres on a thick soda-lime glass anvil at 3.9 m/s, angle of incidence from
the surface normal. Kharaz, Gorham & Salman (2001), Powder Technol. 120:281-291,
doi:10.1016/S0032-5910(01)00283-2.

Model conditions (those of the DEM verification cases that reproduce the experiment, stored as
the ``alumina_on_soda_lime_glass`` pair of the bundled materials config): density 4000 kg/m3,
E = 380 GPa, nu = 0.23 on E = 70 GPa, nu = 0.25 (Eqs. (3)-(4)), Coulomb friction 0.092, no adhesion
(f0 = 0: negligible for a 5 mm sphere). Damping: the data file holds no normal restitution, and the
rebound is nearly elastic (the measured rebound angles and tangential restitutions at 50-60 deg
imply e_n = tan(rebound angle) / tan(incidence) / (v_t,out / v_t,in) close to 1), so by default
zeta_H = zeta_A = 0 and e_n = 1, as in the DEM verification cases (restitution coefficient 1.0).
Pass ``normal_restitution`` to choose zeta_H so that the model e_n equals it instead.

Physics of the comparison
-------------------------
The model is tangentially rigid with Coulomb friction (Eqs. (16)-(20)): for a sphere without
initial spin, with tan(alpha) > (7/2) f (1 + e_n) it slides throughout the contact and
v_t,out / v_t,in = 1 - f (1 + e_n) / tan(alpha); below that angle sliding stops and it rolls out
with v_t,out / v_t,in = 5/7 (the "rolling limit"). Kharaz et al. state that beyond about 30 deg the
rebound follows rigid-body sliding theory; below it tangential compliance (elastic tangential
deformation, microslip, Maw et al.), which the model does not contain, shows: measured tangential
restitution ABOVE 5/7 at the smallest angles (the elastic tangential spring returns energy) and
BELOW 5/7 around 10-20 deg.

Two tangentially compliant models (:mod:`microimpact.model.tangential_compliance`) are compared
beside it: Mindlin stiffness 8 G* a with G* from the shear moduli of the materials config, micro-slip
and the same Coulomb friction 0.092, nothing fitted; "mindlin" (elastic micro-slip, no memory:
variables ``*_compliant``) and "mindlin_deresiewicz" (the loading/unloading hysteresis of
Mindlin & Deresiewicz 1953: ``*_hysteretic``). Only the hysteretic one loses energy to micro-slip
when the tangential force reverses, which is what the measured rebound below 10 deg shows.

Spin sign convention
--------------------
In the toolkit frame (:mod:`microimpact.model.kinematics`) the slip is u_t = v_t + r omega_t', so a
sphere rolling forward in +t has omega_t' = -v_t / r < 0: friction from an impact with v_t > 0
drives omega_t' negative ("forward" or top-spin rolling). The data give the angular SPEED; the
comparison uses |omega| (the model's omega_t' is reported too, negative).
"""

from __future__ import annotations

import functools
import math
from importlib.resources import files
from pathlib import Path

import lmfit
import numpy as np
import pandas as pd
import xarray as xr
from scipy.optimize import brentq

from microimpact.io.materials import default_materials_path, read_materials
from microimpact.io.files import CONVENTIONS
from microimpact.io.provenance import materials_parameter_source, stamp_parameters
from microimpact.io.variables import VARIABLES, attributes
from microimpact.model.tangential_compliance import MD_UNLOADING_EXPONENTS
from microimpact.solvers import engine
from microimpact.solvers.hysteretic_reference import hysteretic_reference
from microimpact.solvers.impact import simulate_many

__all__ = ["kharaz_comparison", "kharaz_summary", "kharaz_table", "default_kharaz_path", "read_kharaz",
           "KHARAZ_CONDITIONS", "UNLOADING_READINGS"]

#: experimental conditions of the Kharaz et al. (2001) data, SI units
KHARAZ_CONDITIONS = dict(
    radius=2.5e-3,  # [m], 5 mm diameter
    speed=3.9,  # [m/s]
    material_pair="alumina_on_soda_lime_glass",  # density 4000, E/nu, friction 0.092, no adhesion
)

#: the measured quantities: name -> (units, long_name) from :mod:`microimpact.io.variables`; the data
#: file states each value's unit, which must be this one
_QUANTITIES = {q: VARIABLES[q] for q in ("tangential_restitution", "rebound_spin", "rebound_angle")}


def default_kharaz_path() -> Path:
    """The copy bundled with the package, ``microimpact/data/kharaz2001_oblique.csv``.

    Read through :mod:`importlib.resources`, so it is found in an installed wheel as well as in a
    clone. It is byte-identical to the repository's ``data/kharaz2001_oblique.csv``, which the
    pipeline reads (``tests/test_packaging.py`` checks that the two copies agree).

    Examples
    --------
    >>> default_kharaz_path().name
    'kharaz2001_oblique.csv'
    """
    return Path(str(files("microimpact") / "data" / "kharaz2001_oblique.csv"))


def read_kharaz(path=None) -> pd.DataFrame:
    """Read the Kharaz et al. (2001) table (columns quantity, incidence_angle_deg, value, units).

    Parameters
    ----------
    path : str or Path, optional
        The CSV; default the bundled copy (:func:`default_kharaz_path`).

    Raises
    ------
    ValueError
        For an unknown quantity, a unit that is not the documented one, or a non-numeric value
        (names the file and line).

    References
    ----------
    Kharaz, A. H., Gorham, D. A. and Salman, A. D. (2001), An experimental study of the elastic
    rebound of spheres, Powder Technol. 120:281-291, doi:10.1016/S0032-5910(01)00283-2.

    Examples
    --------
    >>> t = read_kharaz()
    >>> sorted(t["quantity"].unique()), float(t.loc[0, "incidence_angle_deg"]), float(t.loc[0, "value"])
    (['rebound_angle', 'rebound_spin', 'tangential_restitution'], 1.84, 0.79344)
    """
    path = Path(path) if path is not None else default_kharaz_path()
    df = pd.read_csv(path, dtype={"quantity": str, "units": str})
    need = ["quantity", "incidence_angle_deg", "value", "units"]
    missing = [c for c in need if c not in df.columns]
    if missing:
        raise ValueError(f"{path}: missing column(s) {', '.join(missing)}; expected {', '.join(need)}")
    for i, r in df.iterrows():
        line = i + 2
        if r["quantity"] not in _QUANTITIES:
            raise ValueError(f"{path}, line {line}: unknown quantity {r['quantity']!r}; known: {', '.join(_QUANTITIES)}")
        if str(r["units"]).strip() != _QUANTITIES[r["quantity"]][0]:
            raise ValueError(f"{path}, line {line}, column 'units': {r['units']!r}; expected "
                             f"{_QUANTITIES[r['quantity']][0]!r} for {r['quantity']}")
        for c in ("incidence_angle_deg", "value"):
            if not np.isfinite(pd.to_numeric(r[c], errors="coerce")):
                raise ValueError(f"{path}, line {line}, column {c!r}: {r[c]!r} is not a finite number")
    df["incidence_angle_deg"] = df["incidence_angle_deg"].astype(float)
    df["value"] = df["value"].astype(float)
    return df


def _base_contact(normal_restitution):
    """The contact of the Kharaz conditions, zeta_H chosen for ``normal_restitution`` (None: e_n = 1)."""
    pair = read_materials(default_materials_path())[KHARAZ_CONDITIONS["material_pair"]]
    c = pair.contact(KHARAZ_CONDITIONS["radius"])
    if normal_restitution is None:
        return c.with_(zeta_hertz=0.0, zeta_adhesion=0.0)
    e = float(normal_restitution)
    if not 0.0 < e <= 1.0:
        raise ValueError(f"normal_restitution must lie in (0, 1], got {e!r}")
    if e == 1.0:
        return c.with_(zeta_hertz=0.0, zeta_adhesion=0.0)
    speeds = KHARAZ_CONDITIONS["speed"] * np.cos(np.radians([0.0]))

    def g(z):
        return engine.solve_normal_many(c.with_(zeta_hertz=z), speeds, rtol=1e-10)["e_n"][0] - e

    hi = 1.0
    while g(hi) > 0:
        hi *= 2.0
    # e_n at normal incidence; with Hertzian damping alone and the per-impact reference speed the
    # model e_n does not depend on the speed, so it holds at every angle
    return c.with_(zeta_hertz=brentq(g, 0.0, hi, xtol=1e-12), zeta_adhesion=0.0)


def _model(contact, angles, friction):
    """Model quantities at these incidence angles [deg] and friction coefficient(s)."""
    v = KHARAZ_CONDITIONS["speed"]
    a = np.asarray(angles, dtype=float)
    ds = simulate_many(contact, v, np.clip(a, 0.0, 89.999), 0.0, friction=friction)
    out = _rebound_quantities(a, *(ds[f"velocity_out_{c}"].values for c in ("n", "t")),
                              *(ds[f"omega_out_{c}"].values for c in ("n", "t", "tp")))
    return out | {"omega_out_tp": ds["omega_out_tp"].values, "e_n": ds["e_n"].values}


def _rebound_quantities(angles, v_n, v_t, w_n, w_t, w_tp) -> dict:
    """Tangential restitution [-], rebound spin |omega| [rad/s] and rebound angle [deg] of rebounds
    at these incidence angles [deg] (velocities [m/s] and spins [rad/s] after the impact)."""
    vt_in = KHARAZ_CONDITIONS["speed"] * np.sin(np.radians(np.clip(np.asarray(angles, dtype=float), 0.0, 89.999)))
    with np.errstate(invalid="ignore", divide="ignore"):
        tr = v_t / vt_in
    return {"tangential_restitution": tr, "rebound_spin": np.sqrt(w_n**2 + w_t**2 + w_tp**2),
            "rebound_angle": np.degrees(np.arctan2(v_t, v_n))}


def kharaz_comparison(path=None, *, normal_restitution=None, friction=None, sliding_threshold_deg: float = 30.0,
                      fit_friction: bool = True, curve_incidence_deg=None, contact_models=None) -> xr.Dataset:
    """Compare the model's tangential restitution, rebound spin and rebound angle with Kharaz (2001).

    Parameters
    ----------
    path : str or os.PathLike, optional
        Data file; default the copy bundled with the package (:func:`default_kharaz_path`).
    normal_restitution : float, optional
        Choose zeta_H so that the model e_n equals this; default: no damping, e_n = 1 (see the
        module docstring). [-]
    friction : float, optional
        Coulomb friction of the nominal model; default 0.092, the source's value. [-]
    sliding_threshold_deg : float
        Angles above this are the "sliding" regime where rigid-body sliding theory should hold
        (Kharaz et al.: about 30 deg); the friction is fitted there. [deg]
    fit_friction : bool
        Also fit the friction coefficient (lmfit, leastsq) to the tangential restitution at
        angles above ``sliding_threshold_deg``.
    curve_incidence_deg : sequence of float, optional
        Incidence angles of the model curves. [deg] Default 0.25-85 deg in 0.25 deg steps.
    contact_models : dict, optional
        Sub-model selection of a "selected" model added beside the others (pipeline config key
        ``contact_models``): any of ``tangential_model``, ``friction_model``, ``rolling_friction``
        (:class:`~microimpact.model.contact.Contact` fields). Its variables and RMS attributes have
        the suffix ``_selected``; the attribute ``selected_contact_models`` records the choice.

    Returns
    -------
    xarray.Dataset
        For each quantity q in (tangential_restitution, rebound_spin, rebound_angle), along its own
        dimension ``q`` with coordinate ``q_incidence_deg``: ``q_measured``, ``q_model`` (nominal
        friction), ``q_difference`` (model - measured), ``q_sliding`` (1 above the threshold) and,
        with ``fit_friction``, ``q_model_fitted`` and ``q_difference_fitted``; ``omega_out_tp_model``
        (signed spin, see the module docstring). Model curves on the fine angle grid
        ``curve_incidence_deg``: ``q_curve`` (nominal friction) and, with ``fit_friction``,
        ``q_curve_fitted``. Scalars: ``friction``, ``fitted_friction``
        (+ ``fitted_friction_stderr``), ``e_n_model``, ``zeta_hertz``, ``rolling_limit`` (5/7) and
        ``transition_angle`` (model sliding/rolling boundary, tan = (7/2) f (1 + e_n)). RMS
        differences per quantity and regime are attributes ``rms_<q>_<sliding|below>[_fitted]``
        (see :func:`kharaz_summary`). The tangentially compliant models add their variables and
        RMS with the suffixes ``_compliant`` and ``_hysteretic``; without normal damping (the
        default), the other readings of a hysteretic turning point held by a falling load add
        theirs with the suffix ``_md_<reading>`` (:data:`UNLOADING_READINGS`).

    Examples
    --------
    The bundled measurements against the model with nothing fitted: below 30 deg the hysteretic
    law's tangential restitution is closer to the data than the rigid contact's 5/7:

    >>> ds = kharaz_comparison()
    >>> rigid = ds.attrs["rms_tangential_restitution_below"]
    >>> hysteretic = ds.attrs["rms_tangential_restitution_below_hysteretic"]
    >>> bool(hysteretic < rigid), round(float(ds.attrs["rms_tangential_restitution_all_hysteretic"]), 3)
    (True, 0.027)
    """
    data = read_kharaz(path)
    contact = _base_contact(normal_restitution)
    f_nom = contact.friction if friction is None else float(friction)
    if not (math.isfinite(f_nom) and f_nom >= 0):
        raise ValueError(f"friction must be finite and >= 0, got {friction!r}")
    contact = contact.with_(friction=f_nom)
    src = str(path if path is not None else default_kharaz_path())
    f_fit, f_err = (_fit_friction(contact, data, sliding_threshold_deg, src) if fit_friction
                    else (math.nan, math.nan))
    e_n = float(engine.solve_normal_many(contact, np.array([KHARAZ_CONDITIONS["speed"]]), rtol=1e-10)["e_n"][0])

    grid = (np.arange(0.25, 85.0001, 0.25) if curve_incidence_deg is None
            else np.asarray(curve_incidence_deg, dtype=float).reshape(-1))
    ds = xr.Dataset(coords={"curve_incidence_deg": ("curve_incidence_deg", grid, attributes(
        "incidence_deg", long_name="incidence angle from the surface normal (model curves)"))})
    curves = {"": (_model(contact, grid, f_nom), f"friction {f_nom:g}")}
    if fit_friction:
        curves["_fitted"] = (_model(contact, grid, f_fit), f"fitted friction {f_fit:.4g}")
    for q in _QUANTITIES:
        _compare_quantity(ds, q, data[data["quantity"] == q], contact, curves,
                          {"": f_nom, "_fitted": f_fit} if fit_friction else {"": f_nom}, sliding_threshold_deg)
    _scalars(ds, contact, f_nom, f_fit, f_err, e_n, sliding_threshold_deg)
    for suffix in COMPLIANT_MODELS:
        _compare_compliant(ds, data, contact, grid, f_nom, sliding_threshold_deg, suffix)
    if contact.zeta_hertz == 0.0:  # the readings' integration covers the elastic Hertz contact only
        _compare_readings(ds, data, contact.with_(tangential_model="mindlin_deresiewicz"), sliding_threshold_deg)
    if contact_models:
        _compare_selected(ds, data, contact, contact_models, grid, f_nom, sliding_threshold_deg)
    ds.attrs.update(_comparison_attrs(src, contact, e_n, sliding_threshold_deg))
    return stamp_parameters(ds, contact, materials_parameter_source(KHARAZ_CONDITIONS["material_pair"]))


def _compare_selected(ds, data, contact, contact_models: dict, grid, f_nom, sliding_threshold_deg) -> None:
    """Add to ``ds`` the comparison of the sub-models ``contact_models`` (suffix ``_selected``) and
    the attribute ``selected_contact_models``; ValueError for a key that is not a sub-model field."""
    allowed = {"tangential_model", "friction_model", "rolling_friction"}
    unknown = set(contact_models) - allowed
    if unknown:
        raise ValueError(f"contact_models: unknown key(s) {', '.join(sorted(unknown))}; accepted: {', '.join(sorted(allowed))}")
    _compare_compliant(ds, data, contact.with_(**contact_models), grid, f_nom, sliding_threshold_deg, "_selected")
    ds.attrs["selected_contact_models"] = ", ".join(f"{k}={v}" for k, v in sorted(contact_models.items()))


def _comparison_attrs(src: str, contact, e_n: float, sliding_threshold_deg) -> dict:
    """The global attributes of :func:`kharaz_comparison`: the data's source and reference, the
    impact's conditions with the model's e_n and zeta_H, the threshold and the spin convention."""
    return {
        "title": "microimpact model vs Kharaz, Gorham & Salman (2001) oblique impacts",
        "source": src,
        "reference": "Kharaz, Gorham & Salman (2001), Powder Technol. 120:281-291, doi:10.1016/S0032-5910(01)00283-2",
        "conditions": "5 mm alumina sphere on soda-lime glass, 3.9 m/s, no adhesion, "
                      f"e_n = {e_n:.4g} (zeta_H = {contact.zeta_hertz:.4g})",
        "sliding_threshold_deg": float(sliding_threshold_deg),
        "impact_speed": float(KHARAZ_CONDITIONS["speed"]),
        "impact_speed_units": "m s-1",
        "spin_convention": "omega_t' < 0 is forward rolling for v_t > 0 (slip u_t = v_t + r omega_t'); compared as |omega|",
        "Conventions": CONVENTIONS,
    }


def _fit_friction(contact, data, sliding_threshold_deg, src) -> tuple[float, float]:
    """(friction, its standard error) fitted (lmfit, leastsq) to the tangential restitution above
    ``sliding_threshold_deg`` [deg]. [-]"""
    tr = data[data["quantity"] == "tangential_restitution"]
    sl = tr[tr["incidence_angle_deg"] > sliding_threshold_deg]
    if len(sl) < 2:
        raise ValueError(f"{src}: fewer than 2 tangential_restitution points above {sliding_threshold_deg} deg")

    def residual(params, angles, data=None):
        m = _model(contact, angles, params["friction"].value)["tangential_restitution"]
        return m if data is None else m - data

    params = lmfit.Parameters()
    params.add("friction", value=contact.friction if contact.friction > 0 else 0.1, min=0.0)
    res = lmfit.minimize(residual, params, args=(sl["incidence_angle_deg"].to_numpy(),),
                         kws={"data": sl["value"].to_numpy()}, method="leastsq")
    err = res.params["friction"].stderr
    return float(res.params["friction"].value), float(err) if err is not None else math.nan


def _compare_quantity(ds, q, sub, contact, curves, frictions, sliding_threshold_deg) -> None:
    """Add quantity ``q``'s measured values, model values, differences, curves and RMS to ``ds``.

    ``frictions`` maps the suffix "" (nominal) and, when fitted, "_fitted" to a friction [-]."""
    units, long_name = _QUANTITIES[q]
    a = sub["incidence_angle_deg"].to_numpy()
    meas = sub["value"].to_numpy()
    sliding = (a > sliding_threshold_deg).astype(np.int8)
    for suffix, (curve, label) in curves.items():
        ds[f"{q}_curve{suffix}"] = ("curve_incidence_deg", curve[q], {
            "units": units, "long_name": f"model {long_name}, {label}"})
    ds.coords[f"{q}_incidence_deg"] = ((q,), a, attributes("incidence_deg", long_name="incidence angle from the surface normal"))
    ds[f"{q}_measured"] = ((q,), meas, {"units": units, "long_name": f"measured {long_name} (Kharaz et al. 2001)"})
    ds[f"{q}_sliding"] = ((q,), sliding, {"units": "1", "long_name": f"1 if incidence > {sliding_threshold_deg:g} deg",
                                          "flag_values": np.array([0, 1], dtype=np.int8),
                                          "flag_meanings": "below_threshold sliding_regime"})
    for suffix, f in frictions.items():
        mod = _model(contact, a, f)
        label = f"friction {f:g}" if suffix == "" else "fitted friction"
        ds[f"{q}_model{suffix}"] = ((q,), mod[q], {"units": units, "long_name": f"model {long_name}, {label}"})
        ds[f"{q}_difference{suffix}"] = ((q,), mod[q] - meas, {
            "units": units, "long_name": "model - measured" if suffix == "" else "model (fitted friction) - measured"})
        if q == "rebound_spin" and suffix == "":
            ds["omega_out_tp_model"] = ((q,), mod["omega_out_tp"], attributes(
                "omega_out_tp", long_name="model spin about t' after impact (negative: forward rolling, see notes)"))
        for regime, mask in (("sliding", sliding == 1), ("below", sliding == 0)):
            d = ds[f"{q}_difference{suffix}"].values
            ds.attrs[f"rms_{q}_{regime}{suffix}"] = float(np.sqrt(np.mean(d[mask] ** 2))) if mask.any() else math.nan


def _add_model_quantity(ds, q, suffix, curve, mod, sub, label, difference_label, sliding_threshold_deg) -> None:
    """Add a model's curve ``q_curve<suffix>`` (``curve``: its dimension and values), its values
    ``q_model<suffix>`` and differences ``q_difference<suffix>`` at the measured angles of ``sub``,
    and the attributes ``rms_<q>_<sliding|below|all><suffix>``."""
    units, long_name = _QUANTITIES[q]
    a = sub["incidence_angle_deg"].to_numpy()
    ds[f"{q}_curve{suffix}"] = (curve[0], curve[1], {"units": units, "long_name": f"model {long_name}, {label}"})
    ds[f"{q}_model{suffix}"] = ((q,), mod, {"units": units, "long_name": f"model {long_name}, {label}"})
    d = mod - sub["value"].to_numpy()
    ds[f"{q}_difference{suffix}"] = ((q,), d, {"units": units, "long_name": difference_label})
    sliding = a > sliding_threshold_deg
    for regime, mask in (("sliding", sliding), ("below", ~sliding), ("all", np.ones_like(sliding))):
        ds.attrs[f"rms_{q}_{regime}{suffix}"] = float(np.sqrt(np.mean(d[mask] ** 2))) if mask.any() else math.nan


#: the tangentially compliant models compared: suffix of their variables -> (tangential_model, label)
COMPLIANT_MODELS = {
    "_compliant": ("mindlin", "tangentially compliant, elastic micro-slip (Mindlin)"),
    "_hysteretic": ("mindlin_deresiewicz", "tangentially compliant, hysteretic (Mindlin-Deresiewicz)"),
}


def _compare_compliant(ds, data, compliant, grid, friction, sliding_threshold_deg, suffix="_compliant") -> None:
    """Add a tangentially compliant model (Mindlin stiffness 8 G* a with micro-slip, G* from the
    materials config, the source's friction: nothing fitted) beside the rigid one.

    Variables ``q_model<suffix>``, ``q_difference<suffix>`` (per measured angle) and
    ``q_curve<suffix>`` (on the curve grid); attributes ``rms_<q>_<sliding|below|all><suffix>``
    and, for the rigid model with the nominal friction, ``rms_<q>_all``. ``suffix`` is a key of
    :data:`COMPLIANT_MODELS`: "_compliant" (elastic micro-slip, "mindlin") or "_hysteretic"
    ("mindlin_deresiewicz"), whose tangential model it sets; or "_selected", ``compliant`` as given.
    """
    if suffix in COMPLIANT_MODELS:
        compliant = compliant.with_(tangential_model=COMPLIANT_MODELS[suffix][0])
        what = COMPLIANT_MODELS[suffix][1]
    else:
        what = (f"selected sub-models ({compliant.tangential_model}, {compliant.friction_model}, "
                f"mu_r = {compliant.rolling_friction:g})")
    curve = _model(compliant, grid, friction)
    for q in _QUANTITIES:
        sub = data[data["quantity"] == q]
        mod = _model(compliant, sub["incidence_angle_deg"].to_numpy(), friction)[q]
        label = f"{what} (G* = {compliant.shear_modulus / 1e9:.4g} GPa), friction {friction:g}"
        _add_model_quantity(ds, q, suffix, ("curve_incidence_deg", curve[q]), mod, sub, label,
                            f"{what} model - measured", sliding_threshold_deg)
        rigid = ds[f"{q}_difference"].values
        ds.attrs[f"rms_{q}_all"] = float(np.sqrt(np.mean(rigid**2)))
    ds["effective_shear_modulus"] = ((), compliant.shear_modulus, {
        "units": "Pa", "long_name": "effective shear modulus G* of the compliant model (materials config)"})


#: the readings of a hysteretic turning point held by a falling load compared beside the solvers'
#: ("limit", the ``_hysteretic`` variables): suffix ``_md_<reading>`` -> what the held force does
UNLOADING_READINGS = {
    "rescaled_displacement": "falls as a^2 (displacement scaled with the contact radius, LAMMPS mindlin_rescale)",
    "displacement": "falls as a (displacement kept, LAMMPS mindlin)",
    "force": "kept (Thornton's law read literally at theta = 1, LAMMPS mindlin/force)",
}


#: incidence angles of the readings' curves [deg]: beyond the model's sliding/rolling boundary
#: (32.8 deg at f = 0.092, e_n = 1) the contact slides throughout, has no turning point, and every
#: reading is the "limit" curve (``_hysteretic``)
READING_CURVE_DEG = np.arange(1.0, 35.0001, 1.0)


@functools.lru_cache(maxsize=4096)
def _reading_run(contact, angle, unloading):
    """:func:`~microimpact.solvers.hysteretic_reference.hysteretic_reference` of the Kharaz impact
    at this angle [deg] with this reading, at rtol 1e-8 (within 3e-8 of the compiled solver for
    "limit"); cached, since every comparison of one session integrates the same impacts."""
    return hysteretic_reference(contact, KHARAZ_CONDITIONS["speed"], angle, unloading=unloading, rtol=1e-8)


def _reading_runs(contact, angles, unloading) -> list:
    """:func:`_reading_run` at these angles [deg]. Where the "limit" run had no turning point the
    reading is never consulted, and that run is reused."""
    out = []
    for a in np.clip(np.asarray(angles, dtype=float), 0.0, 89.999):
        run = _reading_run(contact, float(a), "limit")
        out.append(_reading_run(contact, float(a), unloading) if run.slip_ended else run)
    return out


def _reading_quantities(runs, angles) -> dict:
    """Tangential restitution, rebound spin and rebound angle of these runs."""
    vel = np.array([r.velocity_out for r in runs]).reshape(-1, 3)
    omega = np.array([r.omega_out for r in runs]).reshape(-1, 3)
    return _rebound_quantities(angles, vel[:, 0], vel[:, 1], *omega.T)


def _compare_readings(ds, data, contact, sliding_threshold_deg) -> None:
    """Add the hysteretic law's other readings of a turning point held by a falling load
    (:data:`UNLOADING_READINGS`) beside the solvers' ("limit"), from the independent scipy
    integration: ``q_model_md_<reading>``, ``q_difference_md_<reading>``, ``q_curve_md_<reading>``
    (on ``reading_incidence_deg``, :data:`READING_CURVE_DEG`) and
    ``rms_<q>_<regime>_md_<reading>``; ``hysteretic_reference_difference``, the largest
    |tangential restitution| difference between that integration with the "limit" reading and the
    compiled solver at the measured angles."""
    q0 = "tangential_restitution"
    a0 = data[data["quantity"] == q0]["incidence_angle_deg"].to_numpy()
    limit = _reading_quantities(_reading_runs(contact, a0, "limit"), a0)[q0]
    diff = np.abs(limit - ds[f"{q0}_model_hysteretic"].values)
    ds.attrs["hysteretic_reference_difference"] = float(np.max(diff)) if diff.size else math.nan
    ds.coords["reading_incidence_deg"] = ("reading_incidence_deg", READING_CURVE_DEG, attributes(
        "incidence_deg", long_name="incidence angle from the surface normal (curves of the hysteretic readings)"))
    for reading, what in UNLOADING_READINGS.items():
        label = f"hysteretic, held turning point's force {what}, friction {contact.friction:g} (scipy integration)"
        suffix = f"_md_{reading}"
        curve = _reading_quantities(_reading_runs(contact, READING_CURVE_DEG, reading), READING_CURVE_DEG)
        for q in _QUANTITIES:
            sub = data[data["quantity"] == q]
            a = sub["incidence_angle_deg"].to_numpy()
            mod = _reading_quantities(_reading_runs(contact, a, reading), a)[q]
            _add_model_quantity(ds, q, suffix, ("reading_incidence_deg", curve[q]), mod, sub, label,
                                f"{label}: model - measured", sliding_threshold_deg)
    ds.attrs["unloading_readings"] = "; ".join(
        ["limit (k = 1, _hysteretic): the held force keeps its ratio to the Coulomb limit (the solvers' law)"]
        + [f"{r} (k = {MD_UNLOADING_EXPONENTS[r]:.3g}, _md_{r}): the held force {w}" for r, w in UNLOADING_READINGS.items()])


def _scalars(ds, contact, f_nom, f_fit, f_err, e_n, sliding_threshold_deg) -> None:
    """Add the scalar results (frictions, e_n, zeta_H, rolling limit, transition angle) to ``ds``."""
    ds["friction"] = ((), f_nom, attributes("friction", long_name="Coulomb friction coefficient of the nominal model (source value)"))
    ds["fitted_friction"] = ((), f_fit, attributes(
        "friction", long_name=f"friction fitted to tangential restitution above {sliding_threshold_deg:g} deg"))
    ds["fitted_friction_stderr"] = ((), f_err, attributes("friction", long_name="standard error of fitted_friction"))
    ds["e_n_model"] = ((), e_n, attributes("e_n", long_name="model normal restitution at 3.9 m/s"))
    ds["zeta_hertz"] = ((), contact.zeta_hertz, attributes("zeta_hertz", long_name="Hertzian damping coefficient used"))
    ds["rolling_limit"] = ((), 5.0 / 7.0, attributes(
        "tangential_restitution", long_name="tangential restitution of a sphere that ends rolling, no initial spin"))
    ds["transition_angle"] = ((), math.degrees(math.atan(3.5 * f_nom * (1 + e_n))), attributes(
        "incidence_deg", long_name="model sliding/rolling boundary, tan(alpha) = (7/2) f (1 + e_n), nominal friction"))


def kharaz_summary(ds: xr.Dataset) -> pd.DataFrame:
    """RMS model - measured per quantity and regime as a table: the rigid model with the nominal
    and the fitted friction, and the tangentially compliant models, elastic micro-slip
    ("compliant") and hysteretic ("hysteretic"), with the nominal friction; ``rms_md_<reading>``
    the hysteretic law's other readings of a turning point held by a falling load
    (:data:`UNLOADING_READINGS`, NaN when the comparison has normal damping).

    Examples
    --------
    One row per quantity and regime; the RMS of each model side by side:

    >>> summary = kharaz_summary(kharaz_comparison())
    >>> row = summary[(summary["quantity"] == "tangential_restitution") & (summary["regime"] == "all")].iloc[0]
    >>> round(float(row["rms_hysteretic"]), 3), round(float(row["rms_md_force"]), 3)
    (0.027, 0.064)
    """
    rows = []
    th = ds.attrs["sliding_threshold_deg"]
    for q, (units, _) in _QUANTITIES.items():
        for regime in ("sliding", "below", "all"):
            rows.append({"quantity": q, "units": units,
                         "regime": {"sliding": f"> {th:g} deg", "below": f"<= {th:g} deg", "all": "all"}[regime],
                         "rms_nominal_friction": ds.attrs.get(f"rms_{q}_{regime}", math.nan),
                         "rms_fitted_friction": ds.attrs.get(f"rms_{q}_{regime}_fitted", math.nan),
                         "rms_compliant": ds.attrs.get(f"rms_{q}_{regime}_compliant", math.nan),
                         "rms_hysteretic": ds.attrs.get(f"rms_{q}_{regime}_hysteretic", math.nan),
                         **{f"rms_md_{r}": ds.attrs.get(f"rms_{q}_{regime}_md_{r}", math.nan)
                            for r in UNLOADING_READINGS}})
    return pd.DataFrame(rows)


def kharaz_table(ds: xr.Dataset) -> pd.DataFrame:
    """Per-angle long table: quantity, incidence, measured, model, difference (and fitted).

    Examples
    --------
    The rigid model's tangential restitution at the smallest angle is the 2/7 rule's 5/7:

    >>> table = kharaz_table(kharaz_comparison())
    >>> sorted(table["quantity"].unique())
    ['rebound_angle', 'rebound_spin', 'tangential_restitution']
    >>> first = table[table["quantity"] == "tangential_restitution"].iloc[0]
    >>> abs(float(first["model"]) - 5 / 7) < 1e-6
    True
    """
    out = []
    for q, (units, _) in _QUANTITIES.items():
        t = pd.DataFrame({"quantity": q, "units": units,
                          "incidence_deg": ds[f"{q}_incidence_deg"].values,
                          "measured": ds[f"{q}_measured"].values,
                          "model": ds[f"{q}_model"].values,
                          "difference": ds[f"{q}_difference"].values})
        if f"{q}_model_fitted" in ds:
            t["model_fitted"] = ds[f"{q}_model_fitted"].values
            t["difference_fitted"] = ds[f"{q}_difference_fitted"].values
        for suffix in COMPLIANT_MODELS:
            if f"{q}_model{suffix}" in ds:
                t[f"model{suffix}"] = ds[f"{q}_model{suffix}"].values
                t[f"difference{suffix}"] = ds[f"{q}_difference{suffix}"].values
        out.append(t)
    return pd.concat(out, ignore_index=True)
