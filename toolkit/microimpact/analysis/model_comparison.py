"""Compare normal contact models on the same e_n(v_n) data: a fit of each, with AIC and BIC side by side.

Each normal model (the paper's adhesion ring force, "ring"; JKR; DMT; see
:mod:`microimpact.model.adhesion_models`) is fitted to the same measured normal restitution with
the residual convention of :func:`microimpact.analysis.fitting.damping_residual`:
(model e_n - measured e_n) / sigma, sigma the stated e_n uncertainty (or 1 when a row has none),
model e_n = 0 where the model predicts capture, jointly over the particle sizes with one work of
adhesion (f0 or the JKR/DMT scales per radius from it). Their free parameters are the same:
zeta_H, zeta_A (Eqs. (14)-(15)) and w_A. Each fit starts from the best point of a log grid of the
zetas at the material's w_A and ends with Levenberg-Marquardt (lmfit ``leastsq``).

The elastic-plastic adhesive law of Thornton & Ning (1998), ``"thornton_ning"``
(:mod:`microimpact.model.thornton_ning`), is rate-independent: it has no damping, and its free
parameters are the yield velocity V_y and w_A (:func:`microimpact.analysis.plastic_fit.fit_thornton_ning`,
with the same residuals); its row has ``yield_velocity`` where the others have the zetas (NaN
elsewhere), and ``n_parameters`` says each model's k.

Many rows: a radius with at least :data:`~microimpact.analysis.speed_curves.MIN_ROWS` rows is
fitted through a certified Chebyshev curve of e_n in ln v per evaluation (:func:`_fit_restitution`,
:func:`~microimpact.analysis.speed_curves.certified_curve`), within :data:`CURVE_TOLERANCE` of the
solver, so that a fit's cost barely grows with the rows; fewer rows are solved one by one.

Every model carries its verdict (:func:`microimpact.analysis.verdict.assess_residuals`), and the
comparison's sentence (:func:`comparison_verdict`) never prefers a rejected model.

Information criteria (lmfit's definitions, for Gaussian residuals):
AIC = N ln(chi^2 / N) + 2 k, BIC = N ln(chi^2 / N) + k ln N, N points, k the model's varied
parameters. Differences matter, not values: Delta AIC > ~10 is strong support for the lower
(Burnham & Anderson 2002).

References
----------
Akaike, H. (1974), A new look at the statistical model identification, IEEE Trans. Autom. Control
19:716-723, doi:10.1109/TAC.1974.1100705.
Schwarz, G. (1978), Estimating the dimension of a model, Ann. Stat. 6:461-464, doi:10.1214/aos/1176344136.
Burnham, K. P. and Anderson, D. R. (2002), Model Selection and Multimodel Inference, 2nd ed., Springer.
"""

from __future__ import annotations

import warnings

import lmfit
import numpy as np
import xarray as xr

from microimpact.analysis.verdict import ADEQUATE, NO_UNCERTAINTIES, assess_residuals
from microimpact.analysis.fitting import FitProblem
from microimpact.analysis.plastic_fit import PlasticProblem, fit_thornton_ning
from microimpact.analysis.speed_curves import MIN_ROWS, certified_curve
from microimpact.io.variables import attributes
from microimpact.model.adhesion_models import AdhesionRegimeWarning, tabor_parameter
from microimpact.model.laws import restitution_law, restitution_laws
from microimpact.solvers import DEFAULT_RTOL, engine, normal_models

__all__ = ["compare_normal_models", "comparison_verdict", "normal_model_restitution", "DEFAULT_MODELS", "DEFAULT_START_GRID"]

#: the models compared by default: the paper's ring force, JKR, DMT and the elastic-plastic Thornton-Ning law
DEFAULT_MODELS = ("ring", "jkr", "dmt", "thornton_ning")
#: the models fitted by their own module rather than with the damping (the registry's rate-independent laws)
PLASTIC_MODELS = tuple(n for n in restitution_laws() if restitution_law(n).rate_independent)
#: the parameters of a row of the comparison (NaN where a model does not have them)
_PARAMETERS = ("zeta_hertz", "zeta_adhesion", "work_of_adhesion", "yield_velocity")
#: start grid of every fit: log-spaced zeta_H and zeta_A at the material's w_A
DEFAULT_START_GRID = (np.geomspace(0.01, 10.0, 7), np.geomspace(0.1, 1000.0, 7))
#: absolute e_n tolerance of the speed curves of a fit's rows against the solver (:func:`_fit_restitution`):
#: far below the data's noise (sigma ~ 1e-2) and near the solver's own error at rtol = 1e-8 times the
#: integration's error growth, so that chi-square, AIC and the estimates move well within their
#: statistical errors (chi-square by at most 2 tol sqrt(W chi2) + tol^2 W, W = sum 1 / sigma^2)
CURVE_TOLERANCE = 1e-7


def normal_model_restitution(problem: FitProblem, normal_model: str, zeta_hertz, zeta_adhesion, work_of_adhesion,
                             *, rtol=DEFAULT_RTOL, normal_speed=None, radius=None) -> np.ndarray:
    """Model e_n of ``normal_model`` at the points of ``problem`` (or at given speeds and radii). [-]

    Parameters
    ----------
    problem : FitProblem
        Data grouped by radius and the material (density, stiffness, damping reference speed).
    normal_model : {"ring", "jkr", "dmt", "jkr_force"}
    zeta_hertz, zeta_adhesion : float
        Eqs. (14)-(15). [-]
    work_of_adhesion : float
        w_A shared by every radius. [J/m^2]
    rtol : float
        Relative tolerance of the normal solves. [-]
    normal_speed, radius : array_like, optional
        Evaluate at these (broadcast) instead of the data points. [m/s], [m]

    Examples
    --------
    Without damping the ring and DMT laws are conservative (e_n = 1 with adhesion too); JKR loses the
    energy of its hysteresis, less with LAMMPS's force criterion (contact breaks earlier, at F = -F_c):

    >>> from microimpact.analysis.fitting import FitProblem
    >>> from microimpact.io import default_materials_path, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> problem = FitProblem.from_arrays([3.45e-6] * 3, [0.5, 1.0, 2.0], material)
    >>> {m: normal_model_restitution(problem, m, 0.0, 0.0, 0.215834).round(4).tolist()
    ...  for m in ("ring", "dmt", "jkr", "jkr_force")}
    {'ring': [1.0, 1.0, 1.0], 'dmt': [1.0, 1.0, 1.0], 'jkr': [0.4277, 0.892, 0.9741], 'jkr_force': [0.7723, 0.9482, 0.9873]}
    """
    solver = engine if normal_model == "ring" else normal_models
    if normal_speed is None:
        radii, groups, speeds = problem.radii, problem.groups, problem.normal_speed
    else:
        sp, rr = np.broadcast_arrays(np.asarray(normal_speed, dtype=float), np.asarray(radius, dtype=float))
        speeds = sp.ravel()
        radii_arr, inverse = np.unique(rr.ravel(), return_inverse=True)
        radii = tuple(float(r) for r in radii_arr)
        groups = tuple(np.flatnonzero(inverse == i) for i in range(radii_arr.size))
    out = np.empty(speeds.size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AdhesionRegimeWarning)  # the regime is reported per fit instead
        for r, idx in zip(radii, groups):
            c = problem.contact(r, zeta_hertz, zeta_adhesion, work_of_adhesion).with_(normal_model=normal_model)
            out[idx] = solver.solve_normal_many(c, speeds[idx], rtol=rtol)["e_n"]
    return out if normal_speed is None else out.reshape(sp.shape)


def _fit_restitution(problem, model, zeta_hertz, zeta_adhesion, work_of_adhesion, rtol, tol=CURVE_TOLERANCE):
    """Model e_n at the rows of ``problem`` as in :func:`normal_model_restitution`, a radius with at
    least :data:`~microimpact.analysis.speed_curves.MIN_ROWS` rows by a certified speed curve.

    Such a radius's e_n(v) is one smooth curve per parameter set: the solver at the nodes of
    :func:`~microimpact.analysis.speed_curves.certified_curve` in z = ln v (Lobatto nodes of pieces
    of the rows' range) gives p_2n, checked against ``tol`` at the odd nodes; the rows of a piece
    that fails (capture inside it, e_n's root) take the solver row by row. A radius with fewer rows
    takes the solver at its rows, as :func:`normal_model_restitution` does (the same numbers). [-]
    """
    speeds = problem.normal_speed
    out = np.empty(speeds.size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AdhesionRegimeWarning)  # the regime is reported per fit instead
        for r, idx in zip(problem.radii, problem.groups):
            def solve(v):
                c = problem.contact(r, zeta_hertz, zeta_adhesion, work_of_adhesion).with_(normal_model=model)
                return (engine if model == "ring" else normal_models).solve_normal_many(c, v, rtol=rtol)["e_n"]
            if idx.size < MIN_ROWS:
                out[idx] = solve(speeds[idx])
                continue
            values, ok = certified_curve(lambda z: solve(np.exp(z)), np.log(speeds[idx]), tol)
            if not ok.all():
                values[~ok] = solve(speeds[idx][~ok])
            out[idx] = values
    return out


def _fit_one(problem, model, e_n, sigma, w0, rtol, grid):
    """lmfit result of one normal model: grid start, then leastsq over zeta_H, zeta_A, w_A."""
    def residual(params):
        p = params.valuesdict()
        return (_fit_restitution(problem, model, p["zeta_hertz"], p["zeta_adhesion"],
                                 p["work_of_adhesion"], rtol) - e_n) / sigma

    best = (np.inf, 0.5, 30.0)
    for zh in grid[0]:
        for za in grid[1]:
            chi2 = float(np.sum(((_fit_restitution(problem, model, zh, za, w0, rtol) - e_n) / sigma) ** 2))
            if chi2 < best[0]:
                best = (chi2, zh, za)
    params = lmfit.Parameters()
    params.add("zeta_hertz", value=best[1], min=0.0)
    params.add("zeta_adhesion", value=best[2], min=0.0)
    params.add("work_of_adhesion", value=w0, min=1e-6 * w0)
    return lmfit.minimize(residual, params, method="leastsq", scale_covar=False)


def compare_normal_models(table, base, models=DEFAULT_MODELS, *, rtol: float = DEFAULT_RTOL,
                          curve_points: int = 60, start_grid=DEFAULT_START_GRID) -> xr.Dataset:
    """Fit each normal model to the same e_n(v_n) data; AIC, BIC and the fitted curves.

    Parameters
    ----------
    table : pandas.DataFrame
        Impacts as read by :func:`microimpact.io.read_impacts`: ``radius`` [m], ``normal_speed``
        [m/s], ``e_n`` [-], optionally ``e_n_uncertainty`` [-] (used as sigma when every row has
        one > 0; else unweighted).
    base : MaterialPair, Contact or DampingFit
        Density [kg/m^3], stiffness [Pa], the starting w_A [J/m^2] and the damping reference speed.
    models : sequence of {"ring", "jkr", "dmt", "jkr_force", "thornton_ning"}
    rtol : float
        Relative tolerance of the normal solves. [-]
    curve_points : int
        Speeds of the fitted curves, log-spaced over the data range. [-]
    start_grid : (array_like, array_like)
        zeta_H and zeta_A values whose best pair (chi-square at the material's w_A) starts each fit. [-]

    Returns
    -------
    xarray.Dataset
        Dimension ``normal_model``: ``aic``, ``bic``, ``chi_square``, ``delta_aic``, ``delta_bic``
        (to the best model), ``n_parameters``, the fitted ``zeta_hertz``, ``zeta_adhesion``,
        ``work_of_adhesion``, ``yield_velocity`` (NaN where a model has no such parameter) and their
        standard errors, ``verdict`` and ``p_value``, the ``tabor_parameter`` at each radius; curves
        ``e_n_curve`` (normal_model, radius, curve_speed); the data (``point``). Attributes: number
        of points, of varied parameters (one number where every model has the same), the
        weighting, the comparison's sentence.

    Examples
    --------
    Six synthetic impacts made with the ring force (a coarse start grid keeps the example short): the
    ring law is the better one by Delta AIC > 10 and recovers the zeta_A the data were made with:

    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> ds = compare_normal_models(table, material, ("ring", "jkr"), curve_points=5,
    ...                            start_grid=([0.1, 1.0], [10.0, 100.0]))
    >>> ds["delta_aic"].round(1).to_series().to_dict()
    {'ring': 0.0, 'jkr': 13.6}
    >>> ds["e_n_curve"].dims, ds["e_n_curve"].shape, ds.attrs["weighting"]
    (('normal_model', 'radius', 'curve_speed'), (2, 1, 5), 'stated e_n uncertainties')
    >>> ring = ds.sel(normal_model="ring")  # made with zeta_A = 29
    >>> bool(abs(ring["zeta_adhesion"] - 29.0) < 2 * ring["zeta_adhesion_stderr"])
    True
    """
    radius = table["radius"].to_numpy(float)
    speed = table["normal_speed"].to_numpy(float)
    e_n = table["e_n"].to_numpy(float)
    sig = table["e_n_uncertainty"].to_numpy(float) if "e_n_uncertainty" in table else np.full(e_n.size, np.nan)
    weighted = bool(np.all(np.isfinite(sig) & (sig > 0)))
    sigma = sig if weighted else np.ones_like(e_n)
    problem = FitProblem.from_arrays(radius, speed, base)
    radii = np.asarray(problem.radii)
    curve_speed = np.geomspace(speed.min() * 0.8, speed.max() * 1.2, curve_points)
    rows = {k: [] for k in ("aic", "bic", "chi_square", "n_parameters", *_PARAMETERS, *(f"{n}_stderr" for n in _PARAMETERS))}
    curves, tabor, verdicts = [], [], []
    for model in models:
        row, curve, verdict = (_plastic_row(table, base, sigma if weighted else "none", radii, curve_speed)
                               if model in PLASTIC_MODELS else
                               _damping_row(problem, model, e_n, sigma, weighted, rtol, start_grid, radii, curve_speed,
                                            speed, radius))
        for k in rows:
            rows[k].append(row.get(k, np.nan))
        curves.append(curve)
        verdicts.append(verdict)
        tabor.append(tabor_parameter(radii, base.stiffness, row["work_of_adhesion"]))
    ds = _comparison_dataset(models, rows, curves, tabor, radii, curve_speed, radius, speed, e_n, sig,
                             weighted, e_n.size, rows["n_parameters"])
    ds["verdict"] = xr.DataArray(np.array([v.verdict for v in verdicts], dtype=object), dims="normal_model",
                                 attrs={"long_name": "adequacy of each model (chi-square test of the stated uncertainties)"})
    ds["p_value"] = xr.DataArray(np.array([v.p_value for v in verdicts]), dims="normal_model",
                                 attrs={"units": "1", "long_name": "p-value of the chi-square test"})
    ds.attrs["comparison_verdict"] = comparison_verdict(list(models), verdicts, ds["aic"].values)
    return ds


def _damping_row(problem, model, e_n, sigma, weighted, rtol, grid, radii, curve_speed, speed, radius):
    """(row of the comparison, fitted curves (radius, curve_speed), verdict) of a damped normal model."""
    res = _fit_one(problem, model, e_n, sigma, float(problem.material.work_of_adhesion), rtol, grid)
    p = res.params
    row = {"aic": res.aic, "bic": res.bic, "chi_square": res.chisqr, "n_parameters": res.nvarys}
    for name in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion"):
        row[name] = p[name].value
        row[f"{name}_stderr"] = np.nan if p[name].stderr is None else p[name].stderr
    curve = normal_model_restitution(problem, model, p["zeta_hertz"].value, p["zeta_adhesion"].value,
                                     p["work_of_adhesion"].value, rtol=rtol, normal_speed=curve_speed[None, :],
                                     radius=radii[:, None])
    verdict = assess_residuals(res.residual, res.nvarys, stated=weighted, speed=speed, radius=radius,
                               what=f"{model} law")
    return row, curve, verdict


def _plastic_row(table, base, weights, radii, curve_speed):
    """(row, curves, verdict) of the Thornton-Ning law: :func:`~microimpact.analysis.plastic_fit.fit_thornton_ning`
    with the comparison's sigma (the stated e_n uncertainties, or none), its stderr the one its 95 %
    profile interval implies (width / 3.92)."""
    fit = fit_thornton_ning(table, base, weights=weights)
    row = {"aic": fit.aic, "bic": fit.bic, "chi_square": fit.chisqr, "n_parameters": len(fit.varied)}
    for name in fit.varied:
        st = fit.identifiability[name]
        row[name] = fit.values[name]
        row[f"{name}_stderr"] = (st.upper - st.lower) / 3.92 if st.determined else np.nan
    problem = PlasticProblem.from_arrays(np.repeat(radii, curve_speed.size), np.tile(curve_speed, radii.size),
                                         fit.density, fit.stiffness)
    curve = problem.restitution(fit.values["yield_velocity"], fit.values["work_of_adhesion"])
    return row, curve.reshape(radii.size, curve_speed.size), fit.verdict


def comparison_verdict(models, verdicts, aic) -> str:
    """The comparison in one sentence: never a rejected model "preferred".

    All rejected: "all rejected; least bad: X (its verdict), largest misfit where ..."; else the
    lowest AIC among the adequate models; without stated uncertainties, the lowest AIC against the
    scatter (no model can be rejected).

    Examples
    --------
    >>> from microimpact.analysis.verdict import Verdict
    >>> bad = [Verdict("inadequate", c, 58.0, 1e-30, misfit_description="model too low at 3-8 m/s") for c in (600.0, 500.0)]
    >>> comparison_verdict(["jkr", "dmt"], bad, np.array([20.0, 8.0]))
    'all rejected; least bad: dmt (inadequate: chi-square 500 for 58 degrees of freedom (p = 1e-30)); largest misfit where model too low at 3-8 m/s'
    """
    aic = np.asarray(aic, dtype=float)
    if all(v.verdict == NO_UNCERTAINTIES for v in verdicts):
        k = int(np.argmin(aic))
        return f"no stated uncertainties: no model can be rejected; lowest AIC against the scatter: {models[k]}"
    adequate = [i for i, v in enumerate(verdicts) if v.verdict == ADEQUATE]
    if not adequate:
        k = int(np.argmin([v.chi_square for v in verdicts]))
        v = verdicts[k]
        where = f"; largest misfit where {v.misfit_description}" if v.misfit_description else ""
        return f"all rejected; least bad: {models[k]} ({v.text()}){where}"
    k = min(adequate, key=lambda i: aic[i])
    others = [models[i] for i in adequate if i != k]
    rejected = [models[i] for i in range(len(models)) if i not in adequate]
    return (f"adequate: {', '.join(models[i] for i in adequate)}; lowest AIC among them: {models[k]}"
            + (f" (by {min(aic[i] for i in adequate if i != k) - aic[k]:.3g} over {', '.join(others)})" if others else "")
            + (f"; rejected: {', '.join(rejected)}" if rejected else ""))


def _comparison_dataset(models, rows, curves, tabor, radii, curve_speed, radius, speed, e_n, sig, weighted,
                        ndata, nvarys) -> xr.Dataset:
    """The Dataset of :func:`compare_normal_models` with units and long names."""
    units = {"aic": ("1", "Akaike information criterion"), "bic": ("1", "Bayesian information criterion"),
             "chi_square": ("1", "weighted sum of squared residuals"),
             "delta_aic": ("1", "AIC minus the lowest AIC of the compared models"),
             "delta_bic": ("1", "BIC minus the lowest BIC of the compared models"),
             "zeta_hertz_stderr": ("1", "standard error of zeta_H"),
             "zeta_adhesion_stderr": ("1", "standard error of zeta_A"),
             "work_of_adhesion_stderr": ("J m-2", "standard error of w_A"),
             "yield_velocity": ("m s-1", "yield velocity V_y of the Thornton-Ning law, (TN11)"),
             "yield_velocity_stderr": ("m s-1", "standard error of V_y (its 95 % profile interval's width / 3.92)"),
             "n_parameters": ("1", "number of varied parameters of the model"),
             "tabor_parameter": ("1", "Tabor parameter (R w^2 / (E*^2 z0^3))^(1/3), z0 = 0.4 nm"),
             "e_n_curve": ("1", "fitted model normal coefficient of restitution")}

    def attrs(name):
        if name in units:
            return {"units": units[name][0], "long_name": units[name][1]}
        return attributes(name)

    ds = xr.Dataset(coords={"normal_model": list(models), "radius": ("radius", radii, attributes("radius")),
                            "curve_speed": ("curve_speed", curve_speed, {"units": "m s-1", "long_name": "normal speed of the curves"})})
    for name, vals in rows.items():
        ds[name] = xr.DataArray(np.asarray(vals, dtype=float), dims="normal_model", attrs=attrs(name))
    for name in ("aic", "bic"):
        ds[f"delta_{name}"] = xr.DataArray(ds[name].values - ds[name].values.min(), dims="normal_model", attrs=attrs(f"delta_{name}"))
    ds["tabor_parameter"] = xr.DataArray(np.asarray(tabor), dims=("normal_model", "radius"), attrs=attrs("tabor_parameter"))
    ds["e_n_curve"] = xr.DataArray(np.asarray(curves), dims=("normal_model", "radius", "curve_speed"), attrs=attrs("e_n_curve"))
    ds["data_radius"] = xr.DataArray(radius, dims="point", attrs={"units": "m", "long_name": "sphere radius of the measurement"})
    ds["data_normal_speed"] = xr.DataArray(speed, dims="point", attrs={"units": "m s-1", "long_name": "measured incident normal speed"})
    ds["data_e_n"] = xr.DataArray(e_n, dims="point", attrs={"units": "1", "long_name": "measured normal coefficient of restitution"})
    ds["data_e_n_uncertainty"] = xr.DataArray(sig, dims="point", attrs={"units": "1", "long_name": "stated standard uncertainty of e_n"})
    ds.attrs.update(title="Normal contact models fitted to the same e_n(v_n) data",
                    parameter_source="each normal model fitted to the analyst's data (zeta_H, zeta_A, w_A; V_y, w_A of thornton_ning)",
                    number_of_points=int(ndata),
                    varied_parameters=int(nvarys[0]) if len(set(nvarys)) == 1 else "per model (n_parameters)",
                    weighting="stated e_n uncertainties" if weighted else "none (sigma = 1)",
                    free_parameters=" ".join(n for n in _PARAMETERS if np.any(np.isfinite(ds[n].values))))
    return ds
