"""Fit the Thornton & Ning (1998) elastic-plastic adhesive law to measured e_n(v_n).

The law (:mod:`microimpact.model.thornton_ning`) is rate-independent: its restitution at a normal
speed V_i follows from its energy account, (1/2) m V_r^2 = (1/2) m V_i^2 - W_p - H, (TN8)-(TN10),
with no time integration (:func:`~microimpact.model.thornton_ning.restitution_coefficient`,
vectorised over the speeds of one radius; the tests check it against the independent scipy
integration :func:`microimpact.solvers.plastic_reference.plastic_impact`). Two parameters are
fitted, jointly over the particle sizes, each row with its own radius and mass:

* the **yield velocity** V_y = 1.5605 sqrt(p_y^5 / (E*^4 rho)), (TN11) [m/s]. V_y rather than the
  yield pressure p_y because V_y is on the data's own axis (without adhesion e depends on V_y / V_i
  alone, (TN12): e = 1 below it) and, like p_y, it is one value for every size (it holds no
  radius). p_y is one-to-one with it at the material's E* and rho, so its profile interval is
  V_y's mapped (:func:`~microimpact.model.thornton_ning.yield_pressure`);
* the **work of adhesion** w_A [J/m^2], shared by every size (as in
  :func:`microimpact.analysis.fitting.fit_damping`).

The residuals are those of :func:`~microimpact.analysis.fitting.damping_residual`: (model e_n -
measured e_n) / sigma, model e_n = 0 where the law captures the sphere, weights as
:func:`~microimpact.analysis.fitting.fit_damping` takes them (``weights="auto"``: the stated e_n
uncertainties, with the effective variance of stated speed uncertainties, re-weighted twice).

The fit: chi-square on a log grid of (V_y, w_A), then trust-region least squares
(:func:`scipy.optimize.least_squares`) in log coordinates from its best point. Each parameter's
95 % interval is its profile-likelihood interval {x : P(x) - chi2_min <= 3.84}, P the chi-square
re-minimised over the other parameter (scaled by the reduced chi-square for an unweighted fit), as
:func:`~microimpact.analysis.fitting.damping_identifiability` makes them; an interval that reaches
an end of the range searched (:data:`PLASTIC_RANGES`) is a bound, not a number
(:func:`~microimpact.analysis.identifiability.status_from_interval`). The sticking (capture)
velocity of each size is a function of both parameters: its interval is its range over the
boundary of the joint region {chi2 - chi2_min <= 3.84} (rays from the best fit, whitened by the
Hessian, and the four ends of the profile intervals), which for a model linear near the optimum is
its profile-likelihood interval (Press et al. 2007, Sec. 15.6.5).

Where the yield pressure falls below the JKR centre pressure at first contact of a size
(:func:`~microimpact.model.thornton_ning.first_contact_pressure`), the paper's criterion yields the
contact as it forms, outside the law's domain; the model holds p_y at that limit there (e_n then no
longer depends on V_y, and a profile that reaches it ends as a bound). The law's own yield (TN2) is
where the JKR force per contact area reaches p_y (the model module says why).

References
----------
Thornton, C. and Ning, Z. (1998), A theoretical model for the stick/bounce behaviour of adhesive,
elastic-plastic spheres, Powder Technol. 99:154-162, doi:10.1016/S0032-5910(98)00099-0.
Venzon, D. J. and Moolgavkar, S. H. (1988), A method for computing profile-likelihood-based
confidence intervals, Appl. Stat. 37:87-94, doi:10.2307/2347496.
Press, W. H. et al. (2007), Numerical Recipes, 3rd ed., Cambridge University Press, Sec. 15.6.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import pandas as pd
import xarray as xr
from scipy import optimize

from microimpact.analysis.fit_result import FitResult
from microimpact.analysis.fitting import _sigma_e, _table_arrays
from microimpact.analysis.identifiability import DEFAULT_LEVEL, chi2_threshold, status_from_interval
from microimpact.analysis.verdict import Verdict, assess_residuals
from microimpact.io.files import CONVENTIONS, restore_label_coordinates
from microimpact.io.impacts import insert_row_labels, label_variables, labels_from_dataset, row_labels
from microimpact.io.statuses import status_from_variables, status_variables
from microimpact.model import thornton_ning as tn
from microimpact.solvers import Deadline

__all__ = ["PlasticFit", "PlasticProblem", "fit_thornton_ning", "PLASTIC_PARAMETERS", "PLASTIC_RANGES",
           "PLASTIC_UNITS", "PLASTIC_START_GRID", "STICKING_RAYS"]

#: the fitted parameters, in this order
PLASTIC_PARAMETERS = ("yield_velocity", "work_of_adhesion")
#: their units (CF)
PLASTIC_UNITS = {"yield_velocity": "m s-1", "work_of_adhesion": "J m-2", "yield_pressure": "Pa",
                 "sticking_velocity": "m s-1"}
#: the range each profile searches (log-spaced): V_y from 1 mm/s (a microsphere at 1 m/s is then
#: far above yield) to 1 km/s (no impact of a rebound experiment yields); w_A from 1e-6 J/m^2 (it
#: moves e_n of a 1-3 um sphere of the bundled material by < 1e-4 at 0.5-60 m/s, measured: no
#: adhesion, as far as rebound data can tell) to 10 J/m^2 (ten times a metallic bond)
PLASTIC_RANGES = {"yield_velocity": (1e-3, 1e3), "work_of_adhesion": (1e-6, 10.0)}
#: the start grid: V_y [m/s] and w_A as multiples of the material's w_A [-]
PLASTIC_START_GRID = (np.geomspace(0.03, 300.0, 9), np.geomspace(0.03, 30.0, 7))
#: rays traced from the best fit to the boundary of the joint region for the sticking velocities'
#: intervals: in whitened coordinates a linear function's extreme over 16 evenly spaced boundary
#: points is within cos(11.25 deg) = 0.98 of its extreme over the whole boundary (the four profile
#: ends are added, which catch it exactly where it lies along a parameter's axis)
STICKING_RAYS = 16
#: relative tolerance of the profile intervals' ends (in log of the parameter)
_PROFILE_XTOL = 1e-4
#: relative tolerance of the sticking velocities (a root of the rebound energy)
_STICKING_RTOL = 1e-9


# --------------------------------------------------------------------------- the model
@dataclass(frozen=True)
class PlasticProblem:
    """The data of a Thornton-Ning fit, grouped by radius, and the material.

    Attributes
    ----------
    radii : tuple of float
        Distinct sphere radii. [m]
    groups : tuple of numpy.ndarray
        For each radius, the indices of its rows.
    normal_speed : numpy.ndarray
        Incident normal speed of each row. [m/s]
    density, stiffness : float
        rho [kg/m^3] and K = (4/3) E* [Pa] of the material.

    Examples
    --------
    Below yield and without adhesion every impact is elastic; above it e_n is Thornton's (TN12):

    >>> p = PlasticProblem.from_arrays([1e-6, 1e-6, 2e-6], [0.5, 20.0, 20.0], 1350.0, 1.776e9)
    >>> e = p.restitution(2.0, 0.0)
    >>> [round(float(x), 6) for x in e], round(float(tn.thornton_restitution(0.1)), 6)
    ([1.0, 0.658558, 0.658558], 0.658558)
    """

    radii: tuple
    groups: tuple
    normal_speed: np.ndarray
    density: float
    stiffness: float

    @classmethod
    def from_arrays(cls, radius, normal_speed, density: float, stiffness: float) -> "PlasticProblem":
        """Group rows by radius [m]; normal speeds [m/s]; the material's rho [kg/m^3], K [Pa]."""
        radii, inverse = np.unique(np.asarray(radius, dtype=float), return_inverse=True)
        groups = tuple(np.flatnonzero(inverse == i) for i in range(radii.size))
        return cls(tuple(float(r) for r in radii), groups, np.asarray(normal_speed, dtype=float), float(density),
                   float(stiffness))

    def contact(self, radius: float, yield_velocity: float, work_of_adhesion: float) -> tn.PlasticContact:
        """The contact of a sphere of ``radius`` [m] at V_y [m/s] and w_A [J/m^2]: p_y from V_y by
        (TN11), held at the first-contact limit where it falls below it (module docstring)."""
        p_y = tn.yield_pressure(yield_velocity, self.stiffness, self.density)
        p_first = tn.first_contact_pressure(radius, 0.75 * self.stiffness, work_of_adhesion)
        mass = self.density * 4.0 / 3.0 * math.pi * radius**3
        return tn.PlasticContact(radius, mass, self.stiffness, float(work_of_adhesion),
                                 float(max(p_y, p_first * (1.0 + 1e-9))))

    def restitution(self, yield_velocity: float, work_of_adhesion: float, speed_factor: float = 1.0) -> np.ndarray:
        """Model e_n of every row (0 where captured), the rows of one radius at once. [-]"""
        out = np.empty(self.normal_speed.size)
        for r, idx in zip(self.radii, self.groups):
            pc = self.contact(r, yield_velocity, work_of_adhesion)
            out[idx] = tn.restitution_coefficient(pc, self.normal_speed[idx] * speed_factor)
        return out

    def sticking_velocities(self, yield_velocity: float, work_of_adhesion: float, near=None) -> np.ndarray:
        """The sticking (capture) velocity of each radius of :attr:`radii`; ``near``: values [m/s]
        they are expected within 30 % of (a first bracket). [m/s]"""
        near = [None] * len(self.radii) if near is None else near
        return np.array([tn.capture_velocity(self.contact(r, yield_velocity, work_of_adhesion), rtol=_STICKING_RTOL,
                                             bracket=None if v is None else (v / 1.3, v * 1.3))
                         for r, v in zip(self.radii, near)])


class _Objective:
    """chi^2 in log coordinates x = (ln V_y, ln w_A), clipped to the ranges; counts and caches."""

    def __init__(self, problem, e_n, sigma, deadline):
        self.problem, self.e_n, self.sigma, self.deadline = problem, e_n, sigma, deadline
        self.lo = np.log([PLASTIC_RANGES[n][0] for n in PLASTIC_PARAMETERS])
        self.hi = np.log([PLASTIC_RANGES[n][1] for n in PLASTIC_PARAMETERS])
        self.nfev = 0
        self._cache = {}

    def reweight(self, sigma) -> None:
        """Use the uncertainties ``sigma`` from now on (the cache is of the old residuals)."""
        self.sigma = sigma
        self._cache.clear()

    def values(self, x) -> tuple[float, float]:
        v = np.exp(np.clip(np.asarray(x, dtype=float), self.lo, self.hi))
        return float(v[0]), float(v[1])

    def residual(self, x) -> np.ndarray:
        key = tuple(float(t) for t in x)
        if key not in self._cache:
            self.deadline.check(f"{self.nfev} evaluations of the Thornton-Ning law")
            self.nfev += 1
            self._cache[key] = (self.problem.restitution(*self.values(x)) - self.e_n) / self.sigma
            if len(self._cache) > 4096:  # bounded: the profiles revisit only recent points
                self._cache.pop(next(iter(self._cache)))
        return self._cache[key]

    def chisqr(self, x) -> float:
        r = self.residual(x)
        return float(r @ r)


def _least_squares(obj, x0, fixed=None):
    """(x, chi^2) of trust-region least squares from ``x0``; ``fixed`` = (index, value) holds one coordinate."""
    x0 = np.asarray(x0, dtype=float)
    free = [k for k in range(x0.size) if fixed is None or k != fixed[0]]

    def full(z):
        x = x0.copy()
        x[free] = z
        if fixed is not None:
            x[fixed[0]] = fixed[1]
        return x

    res = optimize.least_squares(lambda z: obj.residual(full(z)), np.clip(x0[free], obj.lo[free], obj.hi[free]),
                                 bounds=(obj.lo[free], obj.hi[free]), method="trf", x_scale=1.0, xtol=1e-10,
                                 ftol=1e-12, gtol=1e-12, diff_step=1e-6, max_nfev=200)
    x = full(res.x)
    return x, obj.chisqr(x)


# --------------------------------------------------------------------------- profiles and region
def _profile_end(obj, best, chi_min, scale, k, side, half):
    """The end of parameter k's profile interval on ``side`` (-1, +1), in log coordinates, and the
    other coordinates' optimum there: walked out from the best fit in doubling steps from the Wald
    half-width ``half``, the crossing of chi2_min + 3.84 (scaled) then located by Brent's method.

    Each point's profile value is kept once computed: the optimum at a point depends on where its
    search starts, and a point walked again from its own optimum can come out lower (on 100,000
    rows by enough to turn the sign that bracketed the crossing, and Brent's method then refused
    the bracket)."""
    level = chi_min / scale + chi2_threshold(DEFAULT_LEVEL)
    limit = obj.hi[k] if side > 0 else obj.lo[k]
    start, value = {0.0: best}, {}

    def excess(t):  # P(best_k + side t) - level, continuing from the nearest point already walked
        if t not in value:
            near = min(start, key=lambda s: abs(s - t))
            x, chi = _least_squares(obj, start[near], fixed=(k, best[k] + side * t))
            start[t], value[t] = x, chi / scale - level
        return value[t]

    t_in, t = 0.0, min(max(half, 1e-3), abs(limit - best[k]))
    while True:
        if excess(t) > 0.0:
            break
        if t >= abs(limit - best[k]):
            return float(limit), start[t]
        t_in, t = t, min(2.0 * t, abs(limit - best[k]))
    root = optimize.brentq(excess, t_in, t, xtol=_PROFILE_XTOL, rtol=_PROFILE_XTOL)
    excess(root)
    return float(best[k] + side * root), start[root]


def _wald_half_widths(obj, best, scale) -> tuple[np.ndarray, np.ndarray]:
    """(95 % Wald half-widths in log coordinates, the inverse covariance) from a central-difference
    Jacobian of the residuals at the best fit (1 where it is singular)."""
    h = 1e-5
    jac = np.column_stack([(obj.residual(best + h * e) - obj.residual(best - h * e)) / (2 * h) for e in np.eye(best.size)])
    info = jac.T @ jac / scale
    try:
        cov = np.linalg.inv(info)
        half = 1.96 * np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:
        half = np.ones(best.size)
    return np.where(np.isfinite(half) & (half > 0), half, 1.0), info


def _region_boundary(obj, best, chi_min, scale, info, rays) -> list[np.ndarray]:
    """Points where chi^2 / scale has risen by 3.84 along ``rays`` directions from the best fit,
    evenly spaced in coordinates whitened by ``info`` (the range's edge where it never does)."""
    threshold = chi2_threshold(DEFAULT_LEVEL)
    try:
        curvature, axes = np.linalg.eigh(info)
        basis = axes / np.sqrt(curvature) if np.all(curvature > 0) else np.eye(best.size)
    except np.linalg.LinAlgError:
        basis = np.eye(best.size)
    points = []
    for theta in 2.0 * np.pi * np.arange(rays) / rays:
        d = basis @ np.array([math.cos(theta), math.sin(theta)])
        with np.errstate(divide="ignore", invalid="ignore"):
            reach = np.where(d > 0, (obj.hi - best) / d, np.where(d < 0, (obj.lo - best) / d, np.inf))
        t_edge = float(np.min(reach))

        def rise(t, d=d):
            return (obj.chisqr(best + t * d) - chi_min) / scale - threshold

        t_in, t = 0.0, min(math.sqrt(threshold), t_edge)
        while rise(t) <= 0.0 and t < t_edge:
            t_in, t = t, min(2.0 * t, t_edge)
        if rise(t) > 0.0:
            t = optimize.brentq(rise, t_in, t, xtol=1e-4 * t)
        points.append(best + t * d)
    return points


# --------------------------------------------------------------------------- the fit
def fit_thornton_ning(table, base, *, weights="auto", time_budget: float | None = None,
                      start_grid=PLASTIC_START_GRID) -> "PlasticFit":
    """Fit the Thornton & Ning (1998) law (yield velocity V_y and work of adhesion w_A) to e_n(v_n).

    Parameters
    ----------
    table : pandas.DataFrame
        Impacts as :func:`microimpact.io.read_impacts` returns them: ``radius`` [m],
        ``normal_speed`` [m/s], ``e_n`` [-], optional ``e_n_uncertainty`` [-],
        ``normal_speed_uncertainty`` [m/s], ``row``, ``id``, ``material_pair`` (one pair only).
    base : MaterialPair, Contact or DampingFit
        The material: density [kg/m^3], stiffness K [Pa] and the w_A [J/m^2] the start grid is
        centred on.
    weights : {"auto", "e_n", "none"} or array_like
        As :func:`microimpact.analysis.fitting.fit_damping`. [-]
    time_budget : float, optional
        Wall-clock budget; :class:`~microimpact.solvers.TimeBudgetExceeded` past it. [s]
    start_grid : (array_like, array_like)
        V_y values [m/s] and w_A multiples of the material's [-] of the start grid.

    Returns
    -------
    PlasticFit

    Raises
    ------
    ValueError
        A table that cannot be fitted (names the row and column), or too few rows.

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162; Venzon & Moolgavkar (1988), Appl. Stat. 37:87-94.

    Examples
    --------
    Twenty noise-free rebounds of two sizes made by the law (V_y = 5 m/s, w_A = 0.1 J/m^2) give
    them back:

    >>> from microimpact.io import read_materials
    >>> m = read_materials()["ammonium_fluorescein_on_silicon"]
    >>> p = PlasticProblem.from_arrays(np.repeat([1e-6, 3e-6], 10), np.tile(np.geomspace(2.0, 40.0, 10), 2),
    ...                                m.density, m.stiffness)
    >>> t = pd.DataFrame({"radius": np.repeat([1e-6, 3e-6], 10), "normal_speed": p.normal_speed,
    ...                   "e_n": p.restitution(5.0, 0.1), "e_n_uncertainty": 0.01})
    >>> fit = fit_thornton_ning(t, m)
    >>> round(fit.values["yield_velocity"], 5), round(fit.values["work_of_adhesion"], 6), fit.verdict.verdict
    (5.0, 0.1, 'adequate')
    """
    t0 = time.perf_counter()
    deadline = Deadline.start(time_budget, "Thornton-Ning fit")
    density, stiffness, w0 = float(base.density), float(base.stiffness), float(base.work_of_adhesion)
    df, rows, arr, src = _table_arrays(table)
    sigma_e, effective, weighting = _sigma_e(weights, arr, rows, src)
    e_n = arr["e_n"]
    if e_n.size <= len(PLASTIC_PARAMETERS):
        raise ValueError(f"{src}: {e_n.size} point(s) cannot determine {len(PLASTIC_PARAMETERS)} parameters")
    problem = PlasticProblem.from_arrays(arr["radius"], arr["normal_speed"], density, stiffness)
    sigma = np.ones_like(e_n) if sigma_e is None else sigma_e
    obj = _Objective(problem, e_n, sigma, deadline)
    grid = [np.log([v, w]) for v in start_grid[0] for w in (w0 if w0 > 0 else 0.1) * np.asarray(start_grid[1])]
    best, chi_min = _least_squares(obj, min(grid, key=obj.chisqr))
    if effective:  # the effective variance of the speed uncertainties, re-weighted twice (Orear 1982)
        for _ in range(2):
            h = 1e-4
            slope = (problem.restitution(*obj.values(best), 1 + h) - problem.restitution(*obj.values(best), 1 - h)) \
                / (2 * h * problem.normal_speed)
            sigma = np.sqrt(sigma_e**2 + (slope * arr["normal_speed_uncertainty"]) ** 2)
            obj.reweight(sigma)
            best, chi_min = _least_squares(obj, best)
    dof = e_n.size - len(PLASTIC_PARAMETERS)
    scale = max(chi_min / dof, 1e-300) if sigma_e is None else 1.0
    identifiability, tips = _profiles(obj, best, chi_min, scale)
    values = dict(zip(PLASTIC_PARAMETERS, obj.values(best)))
    sticking = _sticking_intervals(obj, problem, best, chi_min, scale, tips)
    model = problem.restitution(*obj.values(best))
    data = pd.DataFrame({"row": rows, "radius": arr["radius"], "normal_speed": arr["normal_speed"], "e_n": e_n,
                         "sigma": sigma if sigma_e is not None else np.full_like(e_n, np.nan), "model": model,
                         "residual": (model - e_n) / sigma})
    data = insert_row_labels(data, row_labels(df))
    labels = df["material_pair"].dropna().unique() if "material_pair" in df.columns else ()
    n = e_n.size
    aic = n * math.log(max(chi_min, 1e-300) / n) + 2 * len(PLASTIC_PARAMETERS)  # lmfit's definitions
    bic = n * math.log(max(chi_min, 1e-300) / n) + len(PLASTIC_PARAMETERS) * math.log(n)
    info = {"nfev": int(obj.nfev), "method": "log grid + scipy least_squares (trf); profile likelihood",
            "elapsed_s": time.perf_counter() - t0, "source": df.attrs.get("source"), "sha256": df.attrs.get("sha256"),
            "material_pair": str(labels[0]) if len(labels) == 1 else None,
            "outside_physical_range": int(arr["outside"])}
    return PlasticFit(values=values, identifiability=identifiability, sticking=sticking, chisqr=float(chi_min),
                      aic=float(aic), bic=float(bic), n_points=int(n), data=data, density=density, stiffness=stiffness,
                      weighting=weighting, scale_covar=sigma_e is None, info=info)


def _profiles(obj, best, chi_min, scale) -> tuple[dict, list]:
    """({name: ParameterStatus} of each parameter's profile interval, the four profile ends as points)."""
    half, _ = _wald_half_widths(obj, best, scale)
    out, tips = {}, []
    for k, name in enumerate(PLASTIC_PARAMETERS):
        ends = []
        for side in (-1, 1):
            x_end, point = _profile_end(obj, best, chi_min, scale, k, side, half[k])
            ends.append(math.exp(x_end))
            tips.append(point)
        lo, hi = PLASTIC_RANGES[name]
        reasons = {"not_determined": f"chi-square changes by less than the 95 % threshold over {name} in [{lo:g}, {hi:g}]",
                   "lower_bound": f"the e_n data are as well explained by any larger {name}, up to {hi:g}",
                   "upper_bound": f"the e_n data are as well explained by any smaller {name}, down to {lo:g}"}
        out[name] = status_from_interval(name, obj.values(best)[k], ends[0], ends[1], lo, hi, method="profile",
                                         reasons=reasons, atol=1e-9 * hi)
    return out, tips


def _sticking_intervals(obj, problem, best, chi_min, scale, tips) -> pd.DataFrame:
    """Per radius: the sticking velocity at the best fit and its range over the joint region's boundary."""
    _, info = _wald_half_widths(obj, best, scale)
    points = _region_boundary(obj, best, chi_min, scale, info, STICKING_RAYS) + list(tips)
    at_best = problem.sticking_velocities(*obj.values(best))
    at = np.array([at_best] + [problem.sticking_velocities(*obj.values(x), near=at_best) for x in points])
    return pd.DataFrame({"radius": np.asarray(problem.radii), "sticking_velocity": at[0],
                         "sticking_velocity_lower": at.min(axis=0), "sticking_velocity_upper": at.max(axis=0)})


# --------------------------------------------------------------------------- result
@dataclass(frozen=True, eq=False)
class PlasticFit(FitResult):
    """The Thornton & Ning law fitted to e_n(v_n) (:func:`fit_thornton_ning`).

    Attributes
    ----------
    values : dict
        Best-fit ``yield_velocity`` [m/s] and ``work_of_adhesion`` [J/m^2].
    identifiability : dict
        ``{name: ParameterStatus}``: each parameter's 95 % profile-likelihood interval, or a bound.
    sticking : pandas.DataFrame
        Per radius [m]: ``sticking_velocity`` at the best fit and ``sticking_velocity_lower``,
        ``sticking_velocity_upper``, its range over the 95 % joint region's boundary. [m/s]
    chisqr, aic, bic : float
        Least chi-square (weighted by the uncertainties used, else unweighted) and lmfit's AIC, BIC.
    n_points : int
    data : pandas.DataFrame
        ``row``, the CSV's labels, ``radius`` [m], ``normal_speed`` [m/s], ``e_n``, ``sigma`` (NaN
        unweighted), ``model``, ``residual`` ((model - e_n) / sigma).
    density, stiffness : float
        [kg/m^3], [Pa].
    weighting : str
    scale_covar : bool
        Whether the profile threshold is scaled by the reduced chi-square (unweighted fits).
    info : dict
        nfev, method, elapsed_s, source, sha256, material_pair, outside_physical_range, and
        excluded_ids (the rows ``fit --exclude`` left out, comma-separated) where some were.

    Examples
    --------
    The fit of :func:`fit_thornton_ning`'s example survives its file:

    >>> from microimpact.io import read_materials
    >>> m = read_materials()["ammonium_fluorescein_on_silicon"]
    >>> p = PlasticProblem.from_arrays([2e-6] * 8, np.geomspace(2.0, 40.0, 8), m.density, m.stiffness)
    >>> t = pd.DataFrame({"radius": [2e-6] * 8, "normal_speed": p.normal_speed, "e_n": p.restitution(5.0, 0.1),
    ...                   "e_n_uncertainty": 0.01})
    >>> fit = fit_thornton_ning(t, m)
    >>> back = PlasticFit.load(fit.save("tn_fit.nc"))
    >>> back.values == fit.values, back.verdict.verdict
    (True, 'adequate')
    """

    TITLE: ClassVar[str] = "Thornton-Ning elastic-plastic adhesive law fitted to measured e_n"
    KIND: ClassVar[str] = "Thornton-Ning fit"
    WRITTEN_BY: ClassVar[str] = "microimpact fit --law thornton_ning --out"
    LAW: ClassVar[str] = "thornton_ning"

    values: dict
    identifiability: dict
    sticking: pd.DataFrame
    chisqr: float
    aic: float
    bic: float
    n_points: int
    data: pd.DataFrame
    density: float
    stiffness: float
    weighting: str = "none"
    scale_covar: bool = True
    info: dict = field(default_factory=dict)

    @property
    def varied(self) -> tuple:
        """The fitted parameters."""
        return PLASTIC_PARAMETERS

    @property
    def determined(self) -> bool:
        """True where the data determine both parameters."""
        return all(st.determined for st in self.identifiability.values())

    @property
    def yield_pressure(self) -> float:
        """p_y of the best fit, from V_y by (TN11). [Pa]"""
        return tn.yield_pressure(self.values["yield_velocity"], self.stiffness, self.density)

    @property
    def yield_pressure_interval(self) -> tuple[float, float]:
        """p_y at the ends of V_y's interval or bound (p_y is increasing in V_y). [Pa]"""
        st = self.identifiability["yield_velocity"]
        return tuple(tn.yield_pressure(v, self.stiffness, self.density) for v in (st.lower, st.upper))

    @property
    def row_ids(self) -> tuple:
        """The CSV's id of each fitted row (its row number where the file has no ``id``)."""
        d = self.data
        if "id" in d.columns:
            return tuple(str(i) if str(i) else f"row {r}" for i, r in zip(d["id"], d["row"]))
        return tuple(f"row {r}" for r in d["row"])

    @property
    def verdict(self) -> Verdict:
        """Whether the law describes the data (:func:`~microimpact.analysis.verdict.assess_residuals`)."""
        d = self.data
        v = assess_residuals(d["residual"].to_numpy(float), len(PLASTIC_PARAMETERS), stated=self.weighting != "none",
                             ids=self.row_ids, speed=d["normal_speed"].to_numpy(float),
                             radius=d["radius"].to_numpy(float), what="Thornton-Ning law")
        # the rows the analyst left out (``fit --exclude``), as the damping fit records them
        return dataclasses.replace(v, excluded=tuple(x for x in str(self.info.get("excluded_ids") or "").split(",") if x))

    def contact(self, radius: float) -> tn.PlasticContact:
        """The fitted law's contact for a sphere of ``radius``. [m]"""
        problem = PlasticProblem.from_arrays([radius], [1.0], self.density, self.stiffness)
        return problem.contact(radius, self.values["yield_velocity"], self.values["work_of_adhesion"])

    def report(self) -> str:
        """The text report: data, verdict, parameters with their intervals, sticking velocities."""
        units = {"yield_velocity": "m/s", "work_of_adhesion": "J/m^2"}
        src, pair = self.info.get("source"), self.info.get("material_pair")
        radii = self.sticking["radius"].to_numpy()
        lines = ["Thornton-Ning elastic-plastic adhesive law (Thornton & Ning 1998; (TN1)-(TN12) of "
                 "microimpact.model.thornton_ning)"]
        if src:
            lines.append(f"  data        : {src}" + (f"  [{pair}]" if pair else ""))
        lines.append(f"  points      : {self.n_points} over {radii.size} radii "
                     f"({', '.join(f'{r * 1e6:.3g}' for r in radii)} um)")
        lines.append(f"  weighting   : {self.weighting}")
        lines.append(f"  material    : density {self.density:g} kg/m3, K {self.stiffness:.4g} Pa")
        lines += self.verdict.lines()
        lines.append("  parameters  :")
        for name in PLASTIC_PARAMETERS:
            st = self.identifiability[name]
            lines.append(f"    {st.describe(units[name], 5)} (profile likelihood)")
        lo, hi = self.yield_pressure_interval
        lines.append(f"    yield_pressure = {self.yield_pressure:.5g} Pa (from V_y by (TN11); V_y's interval maps to "
                     f"[{lo:.5g}, {hi:.5g}] Pa)")
        lines.append("  sticking    :")
        for _, r in self.sticking.iterrows():
            lines.append(f"    radius {r['radius'] * 1e6:.3g} um: v_stick = {r['sticking_velocity']:.5g} m/s, 95 % "
                         f"[{r['sticking_velocity_lower']:.5g}, {r['sticking_velocity_upper']:.5g}] (joint region)")
        lines.append(f"  chi-square  : {self.chisqr:.4g} ({self.n_points - len(PLASTIC_PARAMETERS)} degrees of freedom)")
        lines.append(f"  AIC, BIC    : {self.aic:.4g}, {self.bic:.4g}")
        lines.append(f"  evaluations : {self.info.get('nfev', '?')} ({self.info.get('elapsed_s', math.nan):.2f} s)")
        return "\n".join(lines)

    def __str__(self) -> str:  # pragma: no cover - convenience
        return self.report()

    def to_dataset(self) -> xr.Dataset:
        """CF form: ``yield_velocity``, ``work_of_adhesion``, ``yield_pressure`` (scalars, with the
        status variables of each parameter's interval), the sticking velocities along ``radius``
        and the fitted rows along ``point``; statistics, material and verdict as attributes."""
        ds = xr.Dataset(coords={"point": ("point", np.arange(len(self.data)), {"long_name": "index of the fitted point"}),
                                "radius": ("radius", self.sticking["radius"].to_numpy(float),
                                           {"units": "m", "long_name": "sphere radius"})})
        names = {"yield_velocity": "yield velocity V_y of the Thornton-Ning law, (TN11)",
                 "work_of_adhesion": "work of adhesion w_A shared by every size"}
        for name, what in names.items():
            ds[name] = xr.DataArray(float(self.values[name]), attrs={"units": PLASTIC_UNITS[name], "long_name": what,
                                                                     "varied": 1})
            ds.update(status_variables(self.identifiability[name], PLASTIC_UNITS[name]))
        ds["yield_pressure"] = xr.DataArray(self.yield_pressure, attrs={
            "units": "Pa", "long_name": "yield pressure p_y from V_y by (TN11)"})
        for col in ("sticking_velocity", "sticking_velocity_lower", "sticking_velocity_upper"):
            ds[col] = xr.DataArray(self.sticking[col].to_numpy(float), dims=("radius",), attrs={
                "units": "m s-1", "long_name": col.replace("_", " ") + " (95 % joint region)"})
        d = self.data
        ds.update(label_variables(d[[c for c in d.columns if c not in _POINT_COLUMNS]], "point"))
        for col in _POINT_COLUMNS:
            name = {"e_n": "e_n_measured", "model": "e_n_model", "radius": "point_radius"}.get(col, col)
            ds[name] = xr.DataArray(d[col].to_numpy(dtype=np.int64 if col == "row" else float), dims=("point",),
                                    attrs={"units": "m" if col == "radius" else "m s-1" if col == "normal_speed" else "1",
                                           "long_name": f"{col} of each fitted row"})
        ds.attrs.update({"title": self.TITLE, "Conventions": CONVENTIONS, "law": self.LAW, "chisqr": self.chisqr,
                         "aic": self.aic, "bic": self.bic, "n_points": self.n_points, "density": self.density,
                         "stiffness": self.stiffness, "weighting": self.weighting, "scale_covar": int(self.scale_covar),
                         "varied": " ".join(PLASTIC_PARAMETERS)})
        ds.attrs.update(self.verdict.to_attrs())
        ds.attrs.update({f"fit_{k}": v for k, v in self.info.items() if isinstance(v, (int, float, str))})
        return ds

    @classmethod
    def from_dataset(cls, ds: xr.Dataset) -> "PlasticFit":
        """Inverse of :meth:`to_dataset` (also of the Dataset read back from its file)."""
        ds = restore_label_coordinates(ds)
        a = ds.attrs
        values = {n: float(ds[n]) for n in PLASTIC_PARAMETERS}
        ident = {n: status_from_variables(ds, n, values[n]) for n in PLASTIC_PARAMETERS}
        sticking = pd.DataFrame({"radius": ds["radius"].values.astype(float),
                                 **{c: ds[c].values.astype(float) for c in ("sticking_velocity", "sticking_velocity_lower",
                                                                           "sticking_velocity_upper")}})
        data = pd.DataFrame({col: ds[{"e_n": "e_n_measured", "model": "e_n_model", "radius": "point_radius"}.get(col, col)]
                             .values for col in _POINT_COLUMNS})
        data["row"] = data["row"].astype(np.int64)
        data = insert_row_labels(data, labels_from_dataset(ds, "point"))
        info = {k.removeprefix("fit_"): (v.item() if hasattr(v, "item") else v) for k, v in a.items() if k.startswith("fit_")}
        return cls(values=values, identifiability=ident, sticking=sticking, chisqr=float(a["chisqr"]),
                   aic=float(a["aic"]), bic=float(a["bic"]), n_points=int(a["n_points"]), data=data,
                   density=float(a["density"]), stiffness=float(a["stiffness"]), weighting=str(a["weighting"]),
                   scale_covar=bool(int(a["scale_covar"])), info=info)


#: the columns of PlasticFit.data that the fit computes (the others are the analyst's row labels)
_POINT_COLUMNS = ("row", "radius", "normal_speed", "e_n", "sigma", "model", "residual")
