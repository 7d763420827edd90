"""Friction (and, later, tangential compliance) from the analyst's oblique columns.

The measured-impact CSV may carry, per oblique impact, one tangential rebound quantity --
``tangential_restitution`` e_t = v_t,out / v_t,in, ``rebound_angle`` or ``rebound_tangential_speed`` --
and/or ``rebound_spin`` |omega_out| (data/README.md), each with its standard uncertainty.
:func:`fit_friction` fits the Coulomb coefficient f of Eqs. (16)-(20) to them, with the normal
damping of a finished :class:`~microimpact.analysis.fit_result.DampingFit`.

After the normal fit, not jointly -- and why
--------------------------------------------
The normal motion does not depend on friction (the decoupling of model-notes section 4): e_n carries
no information on f. The tangential outcome depends on the normal damping only through the
friction impulse J = int |F_n| dt, which the e_n data already fix far better than a few tangential
rows could. So the friction fit runs second, with zeta_H, zeta_A (and w_A) at their fitted values,
and loses next to nothing against a joint fit, while a bad tangential row cannot pull the damping.
What the sequential fit would lose -- the uncertainty of the damping -- is put back twice:

* the standard error of f adds the damping covariance by the delta method,
  var(f) = var(f | zeta) + g^T Cov(zeta) g with g = d f_hat / d zeta from two refits per parameter;
* the posterior (:mod:`microimpact.analysis.posterior`) samples (zeta_H, zeta_A, f) jointly under
  both likelihoods, so its bands carry the correlation.

Measured quantity and errors in variables
-----------------------------------------
Each row is fitted in the quantity that was MEASURED (``df.attrs["measured"]``; a derived column
would inherit correlated errors). Its variance is the stated one plus the effective variance of the
incident speed and angle errors (Orear 1982, doi:10.1119/1.12972):
sigma^2 = sigma_q^2 + (dq/dv)^2 sigma_v^2 + (dq/dalpha)^2 sigma_alpha^2, slopes by central differences
of the model at the current f. Rows with a stated ``spin`` (top-spin +) start with that spin.

Hook for tangential compliance
------------------------------
:data:`TANGENTIAL_PARAMETERS` maps ``Contact.tangential_model`` to the Contact fields fitted from
the oblique data. The paper's rigid model has ``("friction",)``; a compliant model adds its
stiffness field there and the fit varies it too (start values and bounds in
:data:`PARAMETER_BOUNDS`) -- the model is always built with ``Contact.with_(**parameters)`` and solved
by :func:`microimpact.solvers.engine.solve_normal_many` plus the closed-form tangential map
(:func:`rebound_state`, the two halves of :func:`microimpact.simulate_many`).
"""

from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import xarray as xr

from microimpact.io.files import CONVENTIONS, write_netcdf
from microimpact.io.impacts import OBLIQUE_COLUMNS
from microimpact.io.progress import progress_bar
from microimpact.solvers import DEFAULT_RTOL, Deadline

__all__ = ["FrictionFit", "ObliqueProblem", "fit_friction", "oblique_model", "rebound_state", "effective_sigma", "TANGENTIAL_PARAMETERS",
           "PARAMETER_BOUNDS", "OBSERVABLE_UNITS"]

#: Contact.tangential_model -> the Contact fields fitted from oblique data (the compliance hook)
TANGENTIAL_PARAMETERS: dict[str, tuple[str, ...]] = {"rigid": ("friction",)}
#: fitted tangential parameter -> (start grid, lower bound, upper bound)
PARAMETER_BOUNDS: dict[str, tuple] = {"friction": (np.geomspace(0.01, 2.0, 12), 0.0, 10.0)}
#: the fitted observables and their units
OBSERVABLE_UNITS = {"tangential_restitution": "1", "rebound_tangential_speed": "m s-1", "rebound_angle_deg": "degree",
                    "rebound_spin": "rad s-1"}
_H_SPEED = 1e-4  # relative step of the speed slope [-]
_H_ANGLE = 0.05  # step of the angle slope [deg]


@dataclass(frozen=True)
class ObliqueProblem:
    """The oblique rows of an impact table, one entry per (row, measured quantity).

    Attributes
    ----------
    rows : numpy.ndarray
        CSV data row of each entry.
    quantity : numpy.ndarray of str
        The measured quantity of each entry (a key of :data:`OBSERVABLE_UNITS`).
    radius, speed, incidence_deg, spin : numpy.ndarray
        [m], [m/s], [deg], stated incident top-spin [rad/s] (0 where not stated).
    measured, sigma_measured : numpy.ndarray
        The value and its stated standard uncertainty (NaN: not stated), in the quantity's unit.
    sigma_speed, sigma_angle : numpy.ndarray
        Incident speed [m/s] and angle [deg] uncertainties (0 where not stated).
    source : str
    """

    rows: np.ndarray
    quantity: np.ndarray
    radius: np.ndarray
    speed: np.ndarray
    incidence_deg: np.ndarray
    spin: np.ndarray
    measured: np.ndarray
    sigma_measured: np.ndarray
    sigma_speed: np.ndarray
    sigma_angle: np.ndarray
    source: str = "impact table"

    @classmethod
    def from_table(cls, table: pd.DataFrame) -> "ObliqueProblem":
        """The oblique entries of a table from :func:`microimpact.io.read_impacts`.

        Raises
        ------
        ValueError
            If the table has no oblique column with a value at a nonzero incidence angle (names
            the file and the columns looked for).
        """
        src = str(table.attrs.get("source", "impact table"))
        measured = table.attrs.get("measured")
        if measured is None:  # a table built in memory: the first oblique column with values (the
            # canonical table derives the others from it; fitting them too would count a row twice)
            measured = tuple(c for c in OBLIQUE_COLUMNS if c in table.columns
                             and np.isfinite(table[c].to_numpy(dtype=float)).any())[:1]
        names = [c for c in OBLIQUE_COLUMNS if c in measured and c in table.columns]
        n = len(table)

        def col(name, default=np.nan):
            return table[name].to_numpy(dtype=float) if name in table.columns else np.full(n, default)

        rows = table["row"].to_numpy(dtype=np.int64) if "row" in table.columns else np.arange(1, n + 1)
        inc = col("incidence_deg")
        speed = col("speed")
        parts = []
        for q in names:
            x = col(q)
            use = np.isfinite(x) & np.isfinite(inc) & (inc > 0) & np.isfinite(speed) & (col("e_n") > 0)
            idx = np.flatnonzero(use)
            parts.append((q, idx, x[idx], col(f"{q}_uncertainty")[idx]))
        if not any(p[1].size for p in parts):
            raise ValueError(f"{src}: no oblique measurement to fit friction from: give one of the columns "
                             "tangential_restitution, rebound_angle, rebound_tangential_speed or rebound_spin at a "
                             "nonzero incidence_angle with a rebound (data/README.md)")
        idx = np.concatenate([p[1] for p in parts])
        zero = np.nan_to_num
        return cls(rows=rows[idx], quantity=np.concatenate([np.full(p[1].size, p[0], dtype=object) for p in parts]),
                   radius=col("radius")[idx], speed=speed[idx], incidence_deg=inc[idx], spin=zero(col("spin")[idx]),
                   measured=np.concatenate([p[2] for p in parts]), sigma_measured=np.concatenate([p[3] for p in parts]),
                   sigma_speed=zero(col("speed_uncertainty")[idx]), sigma_angle=zero(col("incidence_deg_uncertainty")[idx]),
                   source=src)

    @property
    def size(self) -> int:
        """Number of entries."""
        return int(self.rows.size)


def _observables(out: dict, speed, incidence_deg, quantity) -> np.ndarray:
    """The model value of each entry's quantity from the rebound velocity and spin ``out``."""
    vt_in = speed * np.sin(np.radians(incidence_deg))
    vt, vn = out["velocity_out_t"], out["velocity_out_n"]
    with np.errstate(divide="ignore", invalid="ignore"):  # e_t is undefined at normal incidence
        e_t = np.where(vt_in > 0, vt / np.where(vt_in > 0, vt_in, 1.0), np.nan)
    values = {
        "tangential_restitution": e_t,
        "rebound_tangential_speed": vt,
        "rebound_angle_deg": np.degrees(np.arctan2(vt, vn)),
        "rebound_spin": np.sqrt(out["omega_out_n"] ** 2 + out["omega_out_t"] ** 2 + out["omega_out_tp"] ** 2),
    }
    res = np.full(speed.shape, np.nan)
    for q, v in values.items():
        m = quantity == q
        res[m] = v[m]
    return res


def rebound_state(contact, speed, incidence_deg, spin, rtol: float = DEFAULT_RTOL) -> dict:
    """Rebound velocity and spin of impacts in the incidence plane, as :func:`microimpact.simulate_many`.

    The fast path of the fits: one :func:`microimpact.solvers.engine.solve_normal_many` call (the
    impulses J, J_a) and the closed-form tangential map :func:`microimpact.model.tangential.tangential_outcome`
    -- the two halves of ``simulate_many`` without its Dataset (a test checks they agree).

    Parameters
    ----------
    contact : Contact
    speed, incidence_deg, spin : numpy.ndarray
        Incident speed [m/s], angle from the normal [deg] and top-spin (omega_t' = -spin) [rad/s].
    rtol : float
        Relative tolerance of the normal solves. [-]

    Returns
    -------
    dict of arrays: ``captured`` (bool), ``velocity_out_n``, ``velocity_out_t`` [m/s],
    ``omega_out_n``, ``omega_out_t``, ``omega_out_tp`` [rad/s].
    """
    from microimpact.model.tangential import tangential_outcome
    from microimpact.solvers import engine

    a = np.radians(incidence_deg)
    vn, vt = speed * np.cos(a), speed * np.sin(a)
    speeds, inverse = np.unique(vn, return_inverse=True)  # one solve per distinct normal speed
    sol = {k: v[inverse] for k, v in engine.solve_normal_many(contact, speeds, rtol=rtol).items()}
    zero = np.zeros_like(vn)
    tan = tangential_outcome(contact.mass, contact.moment_of_inertia, contact.radius, contact.friction,
                             (-vn, vt, zero), (zero, zero, -spin), sol["friction_impulse"], sol["twist_impulse"])
    return {"captured": sol["captured"], "velocity_out_n": np.where(sol["captured"], 0.0, sol["e_n"] * vn),
            "velocity_out_t": tan["v_t"], "omega_out_n": tan["omega_n"], "omega_out_t": tan["omega_t"],
            "omega_out_tp": tan["omega_tp"]}


def oblique_model(problem: ObliqueProblem, contact_of, parameters: dict, *, speed=None, incidence_deg=None,
                  rtol: float = DEFAULT_RTOL) -> np.ndarray:
    """Model value of every entry's measured quantity, one normal solve batch per radius.

    Parameters
    ----------
    problem : ObliqueProblem
    contact_of : callable
        radius [m] -> Contact with the normal parameters (e.g. ``DampingFit.contact``).
    parameters : dict
        Tangential Contact fields (``friction`` [-], ...), applied with ``Contact.with_``.
    speed, incidence_deg : numpy.ndarray, optional
        Incident speed [m/s] and angle [deg] replacing the problem's (for slopes).
    rtol : float
        Relative tolerance of the normal solves. [-]

    Returns
    -------
    numpy.ndarray
        In each entry's unit (:data:`OBSERVABLE_UNITS`); NaN where the model captures the sphere.
    """
    v = problem.speed if speed is None else speed
    a = problem.incidence_deg if incidence_deg is None else incidence_deg
    out = np.empty(problem.size)
    for r in np.unique(problem.radius):
        idx = np.flatnonzero(problem.radius == r)
        c = contact_of(float(r)).with_(**parameters)
        st = rebound_state(c, v[idx], np.clip(a[idx], 0.0, 89.9), problem.spin[idx], rtol=rtol)
        out[idx] = np.where(st["captured"], np.nan, _observables(st, v[idx], a[idx], problem.quantity[idx]))
    return out


def effective_sigma(problem: ObliqueProblem, contact_of, parameters: dict, rtol: float = DEFAULT_RTOL) -> np.ndarray:
    """sqrt(sigma_q^2 + (dq/dv sigma_v)^2 + (dq/dalpha sigma_alpha)^2) of each entry (see the module docstring).

    NaN where the quantity's own uncertainty is not stated."""
    terms = [problem.sigma_measured ** 2]
    v, a = problem.speed, problem.incidence_deg
    if np.any(problem.sigma_speed > 0):
        up = oblique_model(problem, contact_of, parameters, speed=v * (1 + _H_SPEED), rtol=rtol)
        dn = oblique_model(problem, contact_of, parameters, speed=v * (1 - _H_SPEED), rtol=rtol)
        terms.append((np.nan_to_num((up - dn) / (2 * _H_SPEED * v)) * problem.sigma_speed) ** 2)
    if np.any(problem.sigma_angle > 0):
        up = oblique_model(problem, contact_of, parameters, incidence_deg=a + _H_ANGLE, rtol=rtol)
        dn = oblique_model(problem, contact_of, parameters, incidence_deg=np.maximum(a - _H_ANGLE, 0.0), rtol=rtol)
        step = a + _H_ANGLE - np.maximum(a - _H_ANGLE, 0.0)
        terms.append((np.nan_to_num((up - dn) / step) * problem.sigma_angle) ** 2)
    return np.sqrt(sum(terms))


@dataclass(frozen=True, eq=False)
class FrictionFit:
    """Result of :func:`fit_friction`.

    Attributes
    ----------
    values : dict
        Fitted tangential parameters (``friction`` [-]).
    stderr : dict
        Standard errors including the propagated damping covariance, same units.
    stderr_conditional : dict
        Standard errors with the damping held at its fitted values.
    tangential_model : str
        ``Contact.tangential_model`` the parameters belong to.
    chisqr, redchi : float
        Chi-square and reduced chi-square of the tangential residuals.
    n_points : int
    weighted : bool
        Whether stated uncertainties weighted the fit (else the covariance is scaled by redchi).
    data : pandas.DataFrame
        ``row``, ``quantity``, ``radius`` [m], ``speed`` [m/s], ``incidence_deg`` [deg], ``measured``,
        ``sigma`` (effective), ``model``, ``residual`` ((model - measured)/sigma).
    info : dict
        ``nfev``, ``elapsed_s``, ``source``, ``method``, ``damping_gradient``.
    """

    values: dict
    stderr: dict
    stderr_conditional: dict
    tangential_model: str
    chisqr: float
    redchi: float
    n_points: int
    weighted: bool
    data: pd.DataFrame
    info: dict = field(default_factory=dict)

    @property
    def friction(self) -> float:
        """Fitted Coulomb coefficient f. [-]"""
        return self.values["friction"]

    def report(self) -> str:
        """Plain-text summary."""
        lines = [f"Friction fit ({self.tangential_model} tangential model, Eqs. (16)-(20)), after the damping fit"]
        for k, v in self.values.items():
            lines.append(f"  {k:<17}= {v:.6g} +/- {self.stderr[k]:.3g} (with the damping uncertainty; "
                         f"{self.stderr_conditional[k]:.3g} at fixed damping)")
        qs = ", ".join(f"{q} ({int((self.data['quantity'] == q).sum())})" for q in dict.fromkeys(self.data["quantity"]))
        lines.append(f"  data        : {self.n_points} entries: {qs}; "
                     f"{'stated uncertainties + effective variance' if self.weighted else 'unweighted'}")
        lines.append(f"  chi-square  : {self.chisqr:.4g}, reduced {self.redchi:.4g}")
        return "\n".join(lines)

    def to_dataset(self) -> xr.Dataset:
        """CF form: scalar ``friction`` (+ ``friction_stderr``) and the entries along ``entry``."""
        d = self.data
        ds = xr.Dataset(coords={"entry": ("entry", np.arange(len(d)), {"long_name": "index of the fitted oblique entry"})})
        for k, v in self.values.items():
            ds[k] = xr.DataArray(v, attrs={"units": "1", "long_name": f"fitted {k} ({self.tangential_model} tangential model)"})
            ds[f"{k}_stderr"] = xr.DataArray(self.stderr[k], attrs={
                "units": "1", "long_name": f"standard error of {k}, damping uncertainty propagated"})
            ds[f"{k}_stderr_conditional"] = xr.DataArray(self.stderr_conditional[k], attrs={
                "units": "1", "long_name": f"standard error of {k} at the fitted damping"})
        ds["row"] = ("entry", d["row"].to_numpy(dtype=np.int64), {"units": "1", "long_name": "data row in the impact CSV"})
        ds["quantity"] = ("entry", d["quantity"].to_numpy(dtype=str).astype(object), {"long_name": "measured quantity"})
        for c, ln in (("radius", ("m", "sphere radius")), ("speed", ("m s-1", "incident speed")),
                      ("incidence_deg", ("degree", "incidence angle from the surface normal"))):
            ds[c] = ("entry", d[c].to_numpy(dtype=float), {"units": ln[0], "long_name": ln[1]})
        for c, ln in (("measured", "measured value"), ("sigma", "effective standard uncertainty"),
                      ("model", "model value at the fitted parameters")):
            ds[f"oblique_{c}"] = ("entry", d[c].to_numpy(dtype=float), {
                "units": "1", "long_name": f"{ln} of the entry's quantity (unit of the quantity: see quantity_units)"})
        ds["quantity_units"] = ("entry", np.array([OBSERVABLE_UNITS[q] for q in d["quantity"]], dtype=object),
                                {"long_name": "unit of the entry's quantity"})
        ds.attrs.update({"title": "friction fit from oblique impacts", "Conventions": CONVENTIONS,
                         "tangential_model": self.tangential_model, "chisqr": self.chisqr, "redchi": self.redchi,
                         "n_points": self.n_points, "weighted": int(self.weighted),
                         "source": str(self.info.get("source", ""))})
        return ds

    def save(self, path):
        """Write :meth:`to_dataset` atomically."""
        return write_netcdf(self.to_dataset(), path)


@contextlib.contextmanager
def engine_threads(threads: int | None = 1):
    """Run the engine on ``threads`` threads inside the block (None: unchanged), restored after.

    One thread for the fits and the sampler: they make thousands of small engine calls, for which
    thread start-up and, on a shared machine, waiting for the second thread cost more than the
    second core gains (measured on the 2-core machine under load: 4 ms per posterior evaluation on
    one thread against 50 ms on two; see also :func:`microimpact.analysis.fitting.fit_damping`).
    """
    if threads is None:
        yield
        return
    import numba

    from microimpact.solvers import engine

    previous = numba.get_num_threads()
    engine.set_threads(threads)
    try:
        yield
    finally:
        engine.set_threads(previous)


def fit_friction(table, damping_fit, *, tangential_model: str | None = None, rtol: float = DEFAULT_RTOL,
                 propagate_damping: bool = True, progress: bool = False, time_budget: float | None = None) -> FrictionFit:
    """Fit the tangential parameters (friction f) to the oblique columns, after the damping fit.

    Parameters
    ----------
    table : pandas.DataFrame
        Impacts from :func:`microimpact.io.read_impacts` with an oblique column (module docstring).
    damping_fit : DampingFit
        The normal fit; its contact (f0 per radius from Eq. (7)) is used at every radius.
    tangential_model : str, optional
        Key of :data:`TANGENTIAL_PARAMETERS`; default the fitted contact's ``tangential_model``.
    rtol : float
        Relative tolerance of the normal solves. [-]
    propagate_damping : bool
        Add the damping covariance to the standard error (two refits per damping parameter).
    progress : bool
        Progress bar on stderr (a terminal only).
    time_budget : float or Deadline, optional
        Wall-clock budget; None: no limit. Checked after every model evaluation. [s]

    Returns
    -------
    FrictionFit

    Raises
    ------
    ValueError
        No oblique data (names the file), an unknown tangential model (names the hook to extend),
        a ``time_budget`` that is not a number > 0.
    TimeBudgetExceeded
        The fit ran past ``time_budget``; the message says how far it got.
    """
    import lmfit  # only when fitting

    t0 = time.perf_counter()
    deadline = Deadline.start(time_budget, "friction fit")
    problem = ObliqueProblem.from_table(table)
    contact_of = damping_fit.contact
    model_name = tangential_model or contact_of(float(problem.radius[0])).tangential_model
    if model_name not in TANGENTIAL_PARAMETERS:
        raise ValueError(f"tangential_model {model_name!r} has no fitted parameters registered; add them to "
                         f"microimpact.analysis.oblique.TANGENTIAL_PARAMETERS (known: {', '.join(TANGENTIAL_PARAMETERS)})")
    names = TANGENTIAL_PARAMETERS[model_name]
    weighted = bool(np.all(np.isfinite(problem.sigma_measured) & (problem.sigma_measured > 0)))
    n_var = len(damping_fit.varied) if propagate_damping else 0
    with progress_bar(3 + 2 * n_var, "friction fit", progress) as advance, engine_threads(1):
        best, sigma, nfev = _fit_tangential(problem, contact_of, names, weighted, rtol, lmfit, deadline=deadline)
        advance(3)
        gradient = {}
        cond = {k: best.params[k].stderr if best.params[k].stderr is not None else math.nan for k in names}
        var = {k: cond[k] ** 2 for k in names}
        if propagate_damping:
            gradient = _damping_gradient(problem, damping_fit, names, best, sigma, rtol, lmfit, advance, deadline)
            cov = _damping_covariance(damping_fit)
            for k in names:
                g = np.array([gradient[k][p] for p in damping_fit.varied])
                var[k] += float(g @ cov @ g)
    p = {k: float(best.params[k].value) for k in names}
    model = oblique_model(problem, contact_of, p, rtol=rtol)
    data = pd.DataFrame({"row": problem.rows, "quantity": problem.quantity.astype(str), "radius": problem.radius,
                         "speed": problem.speed, "incidence_deg": problem.incidence_deg, "measured": problem.measured,
                         "sigma": sigma, "model": model, "residual": (model - problem.measured) / sigma})
    return FrictionFit(values=p, stderr={k: math.sqrt(var[k]) for k in names}, stderr_conditional=cond,
                       tangential_model=model_name, chisqr=float(best.chisqr), redchi=float(best.redchi),
                       n_points=problem.size, weighted=weighted, data=data,
                       info={"nfev": nfev, "elapsed_s": time.perf_counter() - t0, "source": problem.source,
                             "method": "grid start + lmfit leastsq, effective variance re-weighted twice",
                             "damping_gradient": gradient})


def _residual(params, problem, contact_of, names, measured, sigma, rtol):
    p = {k: params[k].value for k in names}
    model = oblique_model(problem, contact_of, p, rtol=rtol)
    return np.nan_to_num((model - measured) / sigma, nan=1e3)  # a captured model: far from any rebound


def _fit_tangential(problem, contact_of, names, weighted, rtol, lmfit, start=None, deadline=Deadline.start(None, "")):
    """(lmfit result, effective sigma, evaluations): grid start (first parameter), leastsq, two re-weightings."""
    sig0 = problem.sigma_measured if weighted else np.ones(problem.size)
    nfev = 0
    if start is None:
        grid, _, _ = PARAMETER_BOUNDS[names[0]]
        chi = []
        for g in grid:
            r = _residual({names[0]: _Value(g)}, problem, contact_of, names[:1], problem.measured, sig0, rtol)
            chi.append(float(r @ r))
            deadline.check(f"{len(chi)} of {len(grid)} start-grid points")
        nfev += len(grid)
        start = {names[0]: float(grid[int(np.argmin(chi))])}
    params = lmfit.Parameters()
    for k in names:
        _, lo, hi = PARAMETER_BOUNDS[k]
        params.add(k, value=start[k], min=lo, max=hi)
    sigma = sig0
    for it in range(3):
        mini = lmfit.Minimizer(_residual, params, fcn_args=(problem, contact_of, names, problem.measured, sigma, rtol),
                               scale_covar=not weighted, iter_cb=deadline.iter_cb(f"least-squares round {it + 1}"))
        res = mini.minimize(method="leastsq")
        nfev += res.nfev
        if not weighted or it == 2:
            break
        sigma = effective_sigma(problem, contact_of, {k: res.params[k].value for k in names}, rtol)
        params = res.params
    return res, sigma, nfev


@dataclass(frozen=True)
class _Value:
    value: float


def _damping_gradient(problem, damping_fit, names, best, sigma, rtol, lmfit, advance,
                      deadline=Deadline.start(None, "")) -> dict:
    """d(fitted tangential parameter)/d(damping parameter) by central refits at +/- one standard error."""
    grad = {k: {} for k in names}
    start = {k: best.params[k].value for k in names}
    for p in damping_fit.varied:
        h = damping_fit.stderr[p] if math.isfinite(damping_fit.stderr[p]) and damping_fit.stderr[p] > 0 \
            else 1e-3 * abs(damping_fit.values[p])
        fitted = []
        for s in (+1, -1):
            values = dict(damping_fit.values) | {p: damping_fit.values[p] + s * h}

            def contact_of(r, values=values):
                return damping_fit.contact(r).with_(**_contact_fields(damping_fit, r, values))
            mini = lmfit.Minimizer(_residual, _params(lmfit, names, start),
                                   fcn_args=(problem, contact_of, names, problem.measured, sigma, rtol),
                                   iter_cb=deadline.iter_cb(f"the refit at {p} {'+-'[s < 0]} its standard error"))
            fitted.append(mini.minimize(method="leastsq").params)
            advance(1)
        for k in names:
            grad[k][p] = (fitted[0][k].value - fitted[1][k].value) / (2 * h)
    return grad


def _params(lmfit, names, start):
    params = lmfit.Parameters()
    for k in names:
        _, lo, hi = PARAMETER_BOUNDS[k]
        params.add(k, value=start[k], min=lo, max=hi)
    return params


def _contact_fields(damping_fit, radius, values) -> dict:
    """Contact fields of one radius for damping parameters ``values`` (f0 from Eq. (7) when w_A moves)."""
    from microimpact.io.materials import material_contact

    c = material_contact(damping_fit, radius, zeta_hertz=values["zeta_hertz"], zeta_adhesion=values["zeta_adhesion"],
                         work_of_adhesion=values["work_of_adhesion"])
    return {"zeta_hertz": c.zeta_hertz, "zeta_adhesion": c.zeta_adhesion, "adhesion_line_force": c.adhesion_line_force}


def _damping_covariance(damping_fit) -> np.ndarray:
    """Covariance of the varied damping parameters from the fit's standard errors and correlation."""
    from microimpact.analysis.fit_result import PARAMETER_NAMES

    idx = [PARAMETER_NAMES.index(p) for p in damping_fit.varied]
    se = np.array([damping_fit.stderr[p] for p in damping_fit.varied])
    corr = np.nan_to_num(damping_fit.correlation[np.ix_(idx, idx)])
    return corr * np.outer(se, se)
