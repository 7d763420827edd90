"""Fit the damping coefficients zeta_H and zeta_A (and optionally w_A) to measured e_n(v_n).

The paper's procedure (Cheng, Brach & Dunn 2002, section "Determination of the damping
coefficients", Fig. 3): least-squares regression of the normal coefficient of restitution e_n,
Eq. (21), against the incident normal speed v_n, with the normal contact law of Eq. (27) and the
damping forms of Eqs. (14)-(15). Here the fit is done with lmfit and

* JOINTLY over particle sizes: every radius r gets its own f0 from ONE shared work of adhesion
  w_A through Eq. (7), f0 = (9/(2 pi) K r w_A^2)^(1/3) (a fit per size would fit f0, which is not a
  material property; see notes/model-notes.md section 1);
* with the model e_n(v_n) from :func:`microimpact.solvers.engine.solve_normal_many`, one call per distinct
  radius per evaluation; a radius with thousands of rows takes e_n from the ring law's error-controlled
  table instead (:mod:`microimpact.solvers.emulator`, ``method="emulator"``, the default), where its
  tolerance cannot move an estimate by more than a tenth of a standard error
  (:func:`emulator_shift_bound`);
* from a coarse global start: chi-square on a log-spaced (zeta_H, zeta_A) grid, then
  Levenberg-Marquardt (``leastsq``) from the best grid point, with bounds zeta >= 0 (w_A > 0).

Residuals and capture
---------------------
Below the capture velocity the model predicts capture and e_n = 0. The model e_n is continuous and
tends to 0 at the capture velocity (roughly as the square root of the distance to it, see
:func:`microimpact.dynamics.nonlinear.capture_bracket`), so a measured rebound that the model predicts as
captured simply gets the residual (0 - e_n,measured) / sigma: no special case, no discontinuity
in chi-square. A measured capture (e_n = 0) is fitted the same way.

Weights
-------
``weights="auto"`` uses the ``e_n_uncertainty`` column (standard uncertainty) when every row has
one > 0, and, when every row also has a ``normal_speed_uncertainty``, adds the speed error through
the effective-variance method (Orear 1982, Am. J. Phys. 50:912, doi:10.1119/1.12972):

    sigma_eff^2 = sigma_e^2 + (d e_n / d v_n)^2 sigma_vn^2,

with the slope d e_n / d v_n of the model at the current best fit, updated twice (fit, re-weight,
fit again, re-weight, fit again). The speed term matters near the capture velocity, where e_n rises
steeply with v_n: at 1.1 v_c a 1 % speed error is a ~5 % error in e_n. Where the table gave the
rebound speed and e_n = v_r / v_n was derived from it (``attrs["measured"]``), the same speed error
is already in sigma_e (as e_n sigma_v / v_n) and moves the model too: the two are correlated, and
sigma_eff^2 = sigma_e^2 + (m'^2 + 2 m' e_n / v_n) sigma_vn^2 (:func:`_effective_sigma`).
With stated uncertainties the covariance is NOT rescaled by the reduced chi-square (lmfit
``scale_covar=False``); unweighted fits rescale it (the residual scatter estimates sigma).
"""

from __future__ import annotations

import functools
import math
import time
import warnings
from dataclasses import dataclass, field

import lmfit
import numba
import numpy as np
import pandas as pd
from scipy import integrate, stats
from scipy.optimize import brentq

from microimpact.analysis.fit_result import PARAMETER_NAMES, DampingFit, fit_parameter_table, format_fit
from microimpact.analysis.sampling_defaults import DEFAULT_FIT_METHOD, DEFAULT_LOSS, LOSSES, METHODS
from microimpact.analysis.verdict import p_value_text
from microimpact.analysis.identifiability import DEFAULT_LEVEL, chi2_threshold, status_from_interval
from microimpact.io.impacts import MEASUREMENT_TOLERANCE_SIGMAS, insert_row_labels, row_labels
from microimpact.io.materials import material_contact
from microimpact._runtime.progress import progress_bar
from microimpact.model import reduction
from microimpact.model.contact import Contact
from microimpact.solvers import DEFAULT_RTOL, Deadline, TimeBudgetExceeded, emulator, engine
from microimpact.solvers.family import FAMILY_MIN_SPEEDS, normal_restitution

# The engine (numba) is imported inside the two functions that solve, so that importing the fit
# costs no numba start-up. The result record, DampingFit, lives in fit_result (no lmfit import):
# what only reads a fit (studies, flags, the CLI's flags command) loads neither lmfit nor numba.

__all__ = [
    "DampingFit",
    "FitProblem",
    "fit_damping",
    "damping_residual",
    "model_restitution",
    "fit_parameter_table",
    "format_fit",
    "PARAMETER_NAMES",
    "DEFAULT_START_GRID",
    "LOSSES",
    "DEFAULT_LOSS",
    "robust_terms",
    "loss_description",
    "FIT_METHODS",
    "EMULATOR_TOLERANCE",
    "EMULATOR_MIN_ROWS",
    "EMULATOR_MAX_SHIFT",
    "emulator_shift_bound",
]

#: default start grid: log-spaced zeta_H and zeta_A values on which chi-square is evaluated
DEFAULT_START_GRID = (np.geomspace(0.01, 10.0, 13), np.geomspace(0.1, 1000.0, 13))
#: how a fit computes the model e_n: "emulator" (the default of :func:`fit_damping`) takes the e_n of a
#: radius with EMULATOR_MIN_ROWS rows or more from the ring law's error-controlled table
#: (:func:`microimpact.solvers.emulator.ring_emulator`), "solve" solves every evaluation
FIT_METHODS = METHODS
#: absolute e_n tolerance of the table in a fit: the posterior's (one shipped table serves both)
EMULATOR_TOLERANCE = 1e-6
#: the box of groups of that table (:data:`microimpact.solvers.emulator.WIDE_DOMAIN`, shipped)
EMULATOR_DOMAIN = emulator.WIDE_DOMAIN
#: a radius with this many rows or more takes its e_n from the table: from here on a solve builds a
#: restitution family on every evaluation (:data:`microimpact.solvers.family.FAMILY_MIN_SPEEDS`),
#: while fewer rows are solved directly at about the cost of a table lookup, to the fit's rtol
EMULATOR_MIN_ROWS = FAMILY_MIN_SPEEDS
#: the most, in standard errors, by which the table's tolerance may move an estimate
#: (:func:`emulator_shift_bound`); a fit whose bound is larger is made again by "solve"
EMULATOR_MAX_SHIFT = 0.1




def robust_terms(z, loss: str = DEFAULT_LOSS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(rho(z^2), its first and its second derivative in z) of each standardized residual z.

    The objective of the damping fit is sum_i rho(z_i^2), with scipy.optimize.least_squares's
    losses at ``f_scale`` = 1 (one stated standard uncertainty): ``linear`` rho(s) = s (chi-square),
    ``soft_l1`` rho(s) = 2 (sqrt(1 + s) - 1), ``huber`` rho(s) = s for s <= 1, else 2 sqrt(s) - 1.
    A residual far beyond 1 counts as |z| (``huber``, ``soft_l1``) rather than z^2: a gross outlier
    pulls the fit by a bounded amount.

    Parameters
    ----------
    z : array_like
        Standardized residuals (model - measured) / sigma. [1]
    loss : {"linear", "soft_l1", "huber"}

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray)
        rho(z^2), psi = d rho(z^2) / dz, d psi / dz. [1]

    References
    ----------
    Huber, P. J. (1964). Robust estimation of a location parameter. Ann. Math. Statist. 35(1),
    73-101. doi:10.1214/aoms/1177703732; scipy.optimize.least_squares (its ``loss`` argument).

    Examples
    --------
    Small residuals count as in least squares; a residual of 20 counts about 2 x 20 = 40, not 400:

    >>> [round(float(robust_terms([x], "soft_l1")[0][0]), 3) for x in (0.01, 20.0)]
    [0.0, 38.05]
    >>> robust_terms([3.0], "huber")[0].tolist(), robust_terms([3.0], "linear")[0].tolist()
    ([5.0], [9.0])
    """
    z = np.asarray(z, dtype=float)
    s = z * z
    if loss == "linear":
        return s, 2 * z, np.full_like(z, 2.0)
    if loss == "soft_l1":
        root = np.sqrt(1 + s)
        return 2 * (root - 1), 2 * z / root, 2 / root**3
    if loss == "huber":
        big = s > 1
        a = np.abs(z)
        return (np.where(big, 2 * a - 1, s), np.where(big, 2 * np.sign(z), 2 * z), np.where(big, 0.0, 2.0))
    raise ValueError(f"loss must be one of {', '.join(LOSSES)}, got {loss!r}")


def _objective(residual, loss: str) -> float:
    """sum rho(z^2) of standardized residuals: chi-square for the linear loss."""
    r = np.asarray(residual, dtype=float)
    return float(r @ r) if loss == "linear" else float(np.sum(robust_terms(r, loss)[0]))


# --------------------------------------------------------------------------- the model
@dataclass(frozen=True)
class FitProblem:
    """The data of a damping fit arranged for fast model evaluation (one engine call per radius).

    Attributes
    ----------
    radii : tuple of float
        Distinct particle radii. [m]
    groups : tuple of numpy.ndarray
        For each radius, the indices of its points in the data order.
    normal_speed : numpy.ndarray
        Incident normal speed of each point. [m/s]
    material : MaterialPair, Contact or DampingFit
        The material: density [kg/m^3], stiffness K [Pa], friction [-] (not used by e_n; kept for
        the fitted contact) and damping reference speed [m/s] (None: each impact's own normal
        speed). Its zetas and w_A are replaced by the trial values.
    method : {"solve", "emulator"}
        How :func:`model_restitution` computes e_n (:data:`FIT_METHODS`): "emulator" takes the e_n
        of a radius with at least :data:`EMULATOR_MIN_ROWS` points from the ring law's table.

    Examples
    --------
    Three impacts of two radii; the points of each radius are solved together:

    >>> from microimpact.io import default_materials_path, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> problem = FitProblem.from_arrays([2e-6, 2e-6, 4e-6], [1.0, 3.0, 2.0], material)
    >>> problem.radii, [g.tolist() for g in problem.groups]
    ((2e-06, 4e-06), [[0, 1], [2]])
    """

    radii: tuple
    groups: tuple
    normal_speed: np.ndarray
    material: object
    method: str = "solve"
    _groups: dict = field(default_factory=dict, compare=False, repr=False)  # the table's groups, per w_A
    _memo: dict = field(default_factory=dict, compare=False, repr=False)  # recent model e_n, by parameters

    @classmethod
    def from_arrays(cls, radius, normal_speed, base, method: str = "solve") -> "FitProblem":
        """Group points by radius [m] and normal speed [m/s]; ``base`` is the material; ``method``
        one of :data:`FIT_METHODS` (how :func:`model_restitution` computes e_n)."""
        if method not in FIT_METHODS:
            raise ValueError(f"method must be one of {', '.join(FIT_METHODS)}, got {method!r}")
        radius = np.asarray(radius, dtype=float)
        v = np.asarray(normal_speed, dtype=float)
        radii, inverse = np.unique(radius, return_inverse=True)
        groups = tuple(np.flatnonzero(inverse == i) for i in range(radii.size))
        return cls(tuple(float(r) for r in radii), groups, v, base, method)

    def subset(self, rows) -> "FitProblem":
        """The problem restricted to the points ``rows`` (indices in the data order)."""
        radius = np.empty(self.normal_speed.size)
        for r, idx in zip(self.radii, self.groups):
            radius[idx] = r
        return FitProblem.from_arrays(radius[rows], self.normal_speed[rows], self.material, self.method)

    def emulated_rows(self) -> np.ndarray:
        """Whether each point's e_n comes from the table (``method`` "emulator", a radius with at least
        :data:`EMULATOR_MIN_ROWS` points); the table may still hand single points to the solver."""
        out = np.zeros(self.normal_speed.size, dtype=bool)
        if self.method == "emulator":
            for idx in self.groups:
                out[idx] = idx.size >= EMULATOR_MIN_ROWS
        return out

    def table_groups(self, radius, idx, work_of_adhesion, speed_factor):
        """(y0, C1 / zeta_H = C2 / zeta_A) of the points ``idx`` of one radius [m] at w_A [J/m^2] and the
        speeds times ``speed_factor``, or None where the radius's law is not the ring law. The groups
        are linear in the zetas (Eqs. (14)-(15), :func:`microimpact.model.reduction.ring_groups`):
        computed once per w_A, an evaluation is one table lookup."""
        key = (float(radius), float(work_of_adhesion), float(speed_factor))
        if key not in self._groups:
            if any(k[1] != key[1] for k in self._groups):  # one w_A at a time: a fitted w_A moves every call
                self._groups.clear()
            c = self.contact(radius, 1.0, 1.0, work_of_adhesion)
            if reduction.law_of(c) != "ring":
                self._groups[key] = None
            else:
                y0, per, _ = reduction.ring_groups([c], (self.normal_speed[idx] * speed_factor)[None, :])
                self._groups[key] = (np.ascontiguousarray(y0[0]), np.ascontiguousarray(per[0]))
        return self._groups[key]

    def contact(self, radius, zeta_hertz, zeta_adhesion, work_of_adhesion) -> Contact:
        """The Contact of one radius [m] at trial zetas [-] and w_A [J/m^2], f0 from Eq. (7)."""
        return material_contact(self.material, radius, zeta_hertz=zeta_hertz, zeta_adhesion=zeta_adhesion,
                                work_of_adhesion=work_of_adhesion)


def model_restitution(problem: FitProblem, zeta_hertz, zeta_adhesion, work_of_adhesion, *, rtol=DEFAULT_RTOL,
                      speed_factor=1.0) -> np.ndarray:
    """Model e_n of every point, Eqs. (21), (27): one engine call per distinct radius (a
    restitution family of the normal speed when a radius has thousands of distinct speeds,
    :func:`microimpact.solvers.family.normal_restitution`), or, for a problem of ``method``
    "emulator", one table lookup for each radius with at least :data:`EMULATOR_MIN_ROWS` points
    (the solver where the table does not meet :data:`EMULATOR_TOLERANCE`).

    Parameters
    ----------
    problem : FitProblem
    zeta_hertz, zeta_adhesion : float
        Damping coefficients, Eqs. (14)-(15). [-]
    work_of_adhesion : float
        w_A shared by all radii; f0 per radius from Eq. (7). [J/m^2]
    rtol : float
        Relative tolerance of the normal solves. [-]
    speed_factor : float
        Multiply every normal speed by this (for finite-difference slopes). [-]

    Returns
    -------
    numpy.ndarray
        e_n in the data order; 0 where the model predicts capture. [-]

    Examples
    --------
    Without damping and adhesion the Hertz contact is elastic, e_n = 1; with the material's Table 1
    values the 2 um sphere at 1 m/s is captured:

    >>> from microimpact.io import default_materials_path, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> problem = FitProblem.from_arrays([2e-6, 2e-6, 4e-6], [1.0, 3.0, 2.0], material)
    >>> model_restitution(problem, 0.0, 0.0, 0.0).tolist()
    [1.0, 1.0, 1.0]
    >>> model_restitution(problem, 0.5, 29.0, 0.215834).round(4).tolist()
    [0.0, 0.049, 0.5437]
    """
    emulated = problem.method == "emulator" and any(idx.size >= EMULATOR_MIN_ROWS for idx in problem.groups)
    key = (float(zeta_hertz), float(zeta_adhesion), float(work_of_adhesion), float(rtol), float(speed_factor))
    if emulated and key in problem._memo:
        return problem._memo[key].copy()
    out = np.empty(problem.normal_speed.size)
    for r, idx in zip(problem.radii, problem.groups):
        g = None
        if problem.method == "emulator" and idx.size >= EMULATOR_MIN_ROWS:
            g = problem.table_groups(r, idx, work_of_adhesion, speed_factor)
        if g is None:
            c = problem.contact(r, zeta_hertz, zeta_adhesion, work_of_adhesion)
            out[idx] = normal_restitution(c, problem.normal_speed[idx] * speed_factor, rtol=rtol)
        else:
            out[idx] = _emulated(problem, r, idx, g, zeta_hertz, zeta_adhesion, work_of_adhesion, speed_factor)
    if emulated:  # lmfit evaluates many points twice (a minimisation's start, its result, a re-fit's start)
        if len(problem._memo) >= MEMO_SIZE:
            problem._memo.pop(next(iter(problem._memo)))
        problem._memo[key] = out.copy()
    return out


#: model evaluations of a large fit kept for repeated parameters (:func:`model_restitution`)
MEMO_SIZE = 64


def _emulated(problem, radius, idx, groups, zeta_hertz, zeta_adhesion, work_of_adhesion, speed_factor):
    """e_n of the points ``idx`` of one radius by the table where it meets EMULATOR_TOLERANCE, by the
    emulator's fallback solves (to the same absolute tolerance) where it does not. [-]"""
    y0, per = groups
    table = _table()
    e, _, solve = table.evaluate(y0, zeta_hertz * per, zeta_adhesion * per, EMULATOR_TOLERANCE)
    e = np.array(e, dtype=float)
    if solve.any():
        c = problem.contact(radius, zeta_hertz, zeta_adhesion, work_of_adhesion)
        e[solve] = emulator.fallback_restitution(c, problem.normal_speed[idx][solve] * speed_factor, EMULATOR_TOLERANCE)
    return e


@functools.lru_cache(maxsize=1)
def _table():
    """The fit's emulator table, looked up once per process (the lookup hashes the physics' source)."""
    return emulator.ring_emulator(emulator.table_tolerance(EMULATOR_TOLERANCE), EMULATOR_DOMAIN)


def emulator_shift_bound(problem: FitProblem, sigma, scale: float = 1.0) -> float:
    """The most, in standard errors, by which the table's tolerance can move an estimate of the fit. [-]

    The table's e_n is within EMULATOR_TOLERANCE = tol of the law's (its verified bound; where it
    is not, the solver runs). Linearised about the fit, an error de of the model moves the estimate
    by d theta = (J^T J)^-1 J^T dz (dz = de / sigma, J = dz / d theta), and by Cauchy-Schwarz
    |d theta_j| <= sqrt(((J^T J)^-1)_jj) ||dz||: the standard error (times sqrt(scale) where the
    covariance is scaled by the reduced chi-square ``scale``) times ||dz|| <= tol sqrt(sum 1 /
    sigma_i^2) over the rows the table serves. The same bound holds for the ends of a profile interval
    where the profile is quadratic.

    Parameters
    ----------
    problem : FitProblem
    sigma : numpy.ndarray or None
        The uncertainties the fit used (None: unweighted, 1). [-]
    scale : float
        Factor of the covariance (the reduced chi-square of an unweighted fit, else 1). [-]

    Returns
    -------
    float
        The bound; 0 where no row is served by the table. [-]

    Examples
    --------
    2,000 rows of sigma 0.01 each served by the table: 1e-6 sqrt(2000 / 0.01^2) = 0.0045 standard errors:

    >>> from microimpact.io import default_materials_path, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> problem = FitProblem.from_arrays(np.full(2000, 2e-6), np.geomspace(2.0, 50.0, 2000), material, "emulator")
    >>> round(emulator_shift_bound(problem, np.full(2000, 0.01)), 4)
    0.0045
    """
    rows = problem.emulated_rows()
    if not rows.any():
        return 0.0
    s = np.ones(rows.size) if sigma is None else np.broadcast_to(np.asarray(sigma, dtype=float), rows.shape)
    return float(EMULATOR_TOLERANCE * math.sqrt(np.sum(1.0 / s[rows] ** 2) / max(float(scale), 1e-300)))


def damping_residual(params, problem: FitProblem, e_n=None, sigma=None, *, rtol=DEFAULT_RTOL):
    """lmfit objective: (model - e_n) / sigma, or the model e_n itself when ``e_n`` is None.

    Parameters
    ----------
    params : lmfit.Parameters or mapping
        ``zeta_hertz``, ``zeta_adhesion``, ``work_of_adhesion``. [-], [-], [J/m^2]
    problem : FitProblem
    e_n : array_like, optional
        Measured restitution coefficients in the data order. [-]
    sigma : array_like, optional
        Their standard uncertainties; None means unweighted. [-]
    rtol : float
        Relative tolerance of the normal solves. [-]

    Returns
    -------
    numpy.ndarray
        Model e_n (``e_n`` None), else the (weighted) residuals. Plain residuals are used for
        points the model predicts as captured (model e_n = 0 is continuous at the capture
        velocity).

    Examples
    --------
    Residuals of data 0.01 above the model, weighted by sigma = 0.02:

    >>> from microimpact.io import default_materials_path, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> problem = FitProblem.from_arrays([2e-6, 4e-6], [3.0, 2.0], material)
    >>> params = {"zeta_hertz": 0.5, "zeta_adhesion": 29.0, "work_of_adhesion": 0.215834}
    >>> model = damping_residual(params, problem)
    >>> damping_residual(params, problem, e_n=model + 0.01, sigma=0.02).round(12).tolist()
    [-0.5, -0.5]
    """
    p = params.valuesdict() if hasattr(params, "valuesdict") else dict(params)
    model = model_restitution(problem, p["zeta_hertz"], p["zeta_adhesion"], p["work_of_adhesion"], rtol=rtol)
    if e_n is None:
        return model
    res = model - np.asarray(e_n, dtype=float)
    return res if sigma is None else res / np.asarray(sigma, dtype=float)


# --------------------------------------------------------------------------- fit
def _material(base):
    """density, stiffness, w_A, friction, reference speed from a MaterialPair, Contact or DampingFit."""
    try:
        return (float(base.density), float(base.stiffness), float(base.work_of_adhesion),
                float(getattr(base, "friction", 0.0) or 0.0), getattr(base, "damping_reference_speed", None))
    except AttributeError:
        raise ValueError("base must give density, stiffness and work_of_adhesion (a MaterialPair, "
                         f"Contact or DampingFit), got {type(base).__name__}") from None


def _table_arrays(table):
    """Columns needed by the fit, checked; errors name the data row and column."""
    if isinstance(table, pd.DataFrame):
        df = table
    else:
        df = pd.DataFrame(table)
    missing = [c for c in ("radius", "normal_speed", "e_n") if c not in df.columns]
    if missing:
        raise ValueError(f"the impact table lacks column(s) {', '.join(missing)}; read it with microimpact.io.read_impacts")
    rows = df["row"].to_numpy(dtype=np.int64) if "row" in df.columns else np.arange(1, len(df) + 1)
    src = df.attrs.get("source", "impact table")
    if len(df) == 0:
        raise ValueError(f"{src}: no impacts to fit")
    if "material_pair" in df.columns:
        pairs = sorted({str(p) for p in df["material_pair"].dropna().unique()})
        if len(pairs) > 1:
            raise ValueError(f"{src}: the table mixes material pairs ({', '.join(pairs)}); fit one pair at a time "
                             "(e.g. microimpact fit --material-pair NAME)")
    out = {}
    for col in ("e_n_uncertainty", "normal_speed_uncertainty"):
        out[col] = df[col].to_numpy(dtype=float) if col in df.columns else np.full(len(df), np.nan)
    # a measured e_n outside [0, 1] by no more than the reader's tolerance of its stated uncertainty
    # is a measurement and is fitted as measured (the model side stays in [0, 1])
    allowance = MEASUREMENT_TOLERANCE_SIGMAS * np.nan_to_num(out["e_n_uncertainty"], nan=0.0).clip(min=0.0)
    for col in ("radius", "normal_speed", "e_n"):
        x = df[col].to_numpy(dtype=float)
        bad = ~np.isfinite(x) | ((x <= 0) if col != "e_n" else (x < -allowance) | (x > 1 + allowance))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            rule = ("must be finite and > 0" if col != "e_n" else
                    f"e_n must lie in [0, 1], or outside it by at most {MEASUREMENT_TOLERANCE_SIGMAS:g} stated standard "
                    f"uncertainties (here {allowance[i] / MEASUREMENT_TOLERANCE_SIGMAS:.3g})")
            raise ValueError(f"{src}: row {rows[i]}, column {col!r}: value {x[i]!r} cannot be fitted ({rule})")
        out[col] = x
    out["outside"] = int(np.count_nonzero((out["e_n"] < 0) | (out["e_n"] > 1)))
    return df, rows, out, src


def _derived_ratio(df, arrays):
    """e_n / v_n [s/m] of each row where the reader derived e_n from the rebound and incident normal
    speeds (``attrs["measured"]``: the rebound speed and not e_n), else None."""
    measured = set(df.attrs.get("measured", ()))
    if "rebound_normal_speed" in measured and "e_n" not in measured:
        return arrays["e_n"] / arrays["normal_speed"]
    return None


def _sigma_e(weights, arrays, rows, src):
    """(sigma_e or None, use_effective_variance, label)."""
    n = arrays["e_n"].size
    if weights is None or (isinstance(weights, str) and weights == "none"):
        return None, False, "none"
    if isinstance(weights, str):
        if weights not in ("auto", "e_n"):
            raise ValueError(f"weights must be 'auto', 'e_n', 'none' or an array of uncertainties, got {weights!r}")
        s = arrays["e_n_uncertainty"]
        given = np.isfinite(s)
        if weights == "auto" and not given.any():
            return None, False, "none"
        bad = ~given | (s <= 0)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{src}: row {rows[i]}, column 'e_n_uncertainty': value {s[i]!r}; weighting by "
                             "e_n uncertainties needs a value > 0 in every row (or use weights='none')")
        sv = arrays["normal_speed_uncertainty"]
        eff = weights == "auto" and bool(np.all(np.isfinite(sv)))
        return s, eff, "e_n uncertainty + effective variance" if eff else "e_n uncertainty"
    s = np.asarray(weights, dtype=float)
    if s.shape != (n,) or not np.all(np.isfinite(s) & (s > 0)):
        raise ValueError(f"weights given as an array must be {n} finite uncertainties > 0")
    return s, False, "given"


@dataclass(frozen=True)
class _SpeedErrors:
    """The incident normal speeds' uncertainties ``sigma`` [m/s] and ``ratio``: e_n / v_n [s/m] of each
    row where e_n was derived as v_r / v_n (its uncertainty then holds the term e_n sigma_v / v_n of
    the same speed error that moves the model; :func:`_effective_sigma`), else None."""

    sigma: np.ndarray
    ratio: np.ndarray | None = None


def _effective_sigma(problem, p, sigma_e, sigma_v, rtol, h=1e-4):
    """The effective sigma of each row, with the model slope m' = de/dv by central differences.

    Where e_n was measured: sqrt(sigma_e^2 + (m' sigma_v)^2) (Orear 1982). Where it was derived as
    e_n = v_r / v_n (``sigma_v.ratio`` = e_n / v_n), one speed error dv moves both the measured e_n
    (by -e_n dv / v_n, already in sigma_e) and the model (by m' dv): the residual's variance is
    sigma_r^2 / v_n^2 + (m' + e_n / v_n)^2 sigma_v^2 = sigma_e^2 + (m'^2 + 2 m' e_n / v_n) sigma_v^2
    (the incident and rebound speed errors independent, :data:`microimpact.io.impacts.SPEED_CORRELATION`).
    Near capture, where m' > 0, the cross term adds to the variance; at high speed, where m' < 0, the
    two movements partly cancel."""
    up = model_restitution(problem, p["zeta_hertz"], p["zeta_adhesion"], p["work_of_adhesion"], rtol=rtol, speed_factor=1 + h)
    dn = model_restitution(problem, p["zeta_hertz"], p["zeta_adhesion"], p["work_of_adhesion"], rtol=rtol, speed_factor=1 - h)
    slope = (up - dn) / (2 * h * problem.normal_speed)
    sv, ratio = np.asarray(sigma_v.sigma, dtype=float), sigma_v.ratio
    cross = 0.0 if ratio is None else 2 * slope * ratio * sv**2
    return np.sqrt(np.maximum(sigma_e**2 + (slope * sv) ** 2 + cross, 0.0))


def fit_damping(table, base, *, fit_work_of_adhesion: bool = False, weights="auto", start_grid=DEFAULT_START_GRID,
                rtol: float = DEFAULT_RTOL, confidence_intervals: bool = True, scale_covar: bool | None = None,
                threads: int | None = 1, progress: bool = False, time_budget: float | None = None,
                loss: str = DEFAULT_LOSS, method: str = DEFAULT_FIT_METHOD) -> DampingFit:
    """Fit zeta_H, zeta_A (and optionally w_A) to measured e_n(v_n), jointly over particle sizes.

    Parameters
    ----------
    table : pandas.DataFrame
        Impacts as returned by :func:`microimpact.io.read_impacts`: columns ``radius`` [m],
        ``normal_speed`` [m/s], ``e_n`` [-], optional ``e_n_uncertainty`` [-],
        ``normal_speed_uncertainty`` [m/s], ``row``, ``material_pair`` (one pair only).
    base : MaterialPair, Contact or DampingFit
        The material: density [kg/m^3], stiffness K [Pa], work of adhesion w_A [J/m^2] (a
        Contact's :attr:`~microimpact.Contact.work_of_adhesion`; the start value when
        ``fit_work_of_adhesion``), friction [-] and damping reference speed [m/s].
    fit_work_of_adhesion : bool
        Also fit w_A (shared by all radii, f0 per radius from Eq. (7)).
    weights : {"auto", "e_n", "none"} or array_like
        "auto": e_n uncertainties if the table has them (plus the effective variance of the
        speed uncertainty when every row has a ``normal_speed_uncertainty``), else unweighted;
        "e_n": e_n uncertainties only; "none": unweighted; an array: the uncertainties. [-]
    start_grid : (array_like, array_like)
        zeta_H and zeta_A values [-] on which chi-square is evaluated; the fit starts from the
        best grid point (w_A at its base value).
    rtol : float
        Relative tolerance of the engine's normal solves. [-]
    confidence_intervals : bool
        Compute 1- and 2-sigma :func:`lmfit.conf_interval` limits (a profile fit per limit).
    scale_covar : bool, optional
        Scale the covariance by the reduced chi-square; default: only for unweighted fits.
    threads : int or None
        Engine threads during the fit (restored afterwards); None keeps the current setting. Default
        1: for hundreds of small engine calls, thread start-up costs more than a second core gains.
    progress : bool
        A progress bar on stderr (a terminal only): the start grid, then each least-squares round.
    time_budget : float or Deadline, optional
        Wall-clock budget of the fit (checked at every evaluation); None: no limit. [s]
    loss : {"linear", "soft_l1", "huber"}
        The objective sum rho(z^2) of the standardized residuals z (:func:`robust_terms`): least
        squares, or robust (scipy's loss at ``f_scale`` = 1 stated uncertainty, which it needs) for
        gross outliers, its 95 % intervals the robust profile scaled by the sandwich (Huber 1967).
        The verdict's chi-square stays the plain sum of z^2 at the fitted values.
    method : {"emulator", "solve"}
        How the model e_n is computed (:data:`FIT_METHODS`, the module docstring): "emulator" takes
        the e_n of radii with :data:`EMULATOR_MIN_ROWS` rows from the ring law's table unless its
        tolerance could move an estimate by :data:`EMULATOR_MAX_SHIFT` standard errors
        (:func:`emulator_shift_bound`); "solve" and a robust loss solve every radius at ``rtol``.
        ``info["model_evaluation"]`` says which was used.

    Raises
    ------
    ValueError
        For a table that cannot be fitted (names the row and column), mixed material pairs, or
        bad arguments (``time_budget`` <= 0 or not a number).
    TimeBudgetExceeded
        The fit ran past ``time_budget``; the message says how far it got. No result is returned
        (lmfit's own abort would give a half-finished one).

    Notes
    -----
    Model: e_n(v_n) of Eq. (21) from the normal contact law Eq. (27) with
    C = zeta (r^3 K sqrt(v_n) / m)^(-2/5), Eqs. (14)-(15), and f0(r) = (9/(2 pi) K r w_A^2)^(1/3),
    Eq. (7). The model e_n is 0 below the capture velocity and continuous there, so plain
    residuals are used for every point (see the module docstring).

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (7), (14)-(15), (21), (27); Newville, M. et al., LMFIT:
    Non-Linear Least-Squares Minimization and Curve-Fitting for Python, doi:10.5281/zenodo.11813.

    Examples
    --------
    Twelve noise-free rebounds of 3.45 um spheres made with zeta_H = 0.5, zeta_A = 29 (the
    synthetic data set's values) give them back:

    >>> from microimpact.analysis.synthetic import make_synthetic_impacts
    >>> from microimpact.io import read_materials
    >>> raw = make_synthetic_impacts(e_n_rel_sd=0.0, speed_rel_sd=0.0, angle_sd_deg=0.0, radii=(3.45e-6,),
    ...                              n_per_radius=12)
    >>> table = pd.DataFrame({"radius": raw["radius [um]"] * 1e-6, "normal_speed": raw.attrs["true_normal_speed"],
    ...                       "e_n": raw.attrs["true_e_n"]})
    >>> fit = fit_damping(table, read_materials()["ammonium_fluorescein_on_silicon"], confidence_intervals=False)
    >>> round(fit.values["zeta_hertz"], 6), round(fit.values["zeta_adhesion"], 5)
    (0.5, 29.0)
    """
    deadline = Deadline.start(time_budget, "fit")
    if method not in FIT_METHODS:
        raise ValueError(f"method must be one of {', '.join(FIT_METHODS)}, got {method!r}")
    if threads is None:
        return _fit_damping(table, base, fit_work_of_adhesion, weights, start_grid, rtol, confidence_intervals,
                            scale_covar, progress, deadline, loss, method)

    previous = numba.get_num_threads()
    engine.set_threads(threads)
    try:
        return _fit_damping(table, base, fit_work_of_adhesion, weights, start_grid, rtol, confidence_intervals,
                            scale_covar, progress, deadline, loss, method)
    finally:
        engine.set_threads(previous)


def _fit_damping(table, base, fit_work_of_adhesion, weights, start_grid, rtol, confidence_intervals, scale_covar,
                 progress=False, deadline=Deadline.start(None, "fit"), loss=DEFAULT_LOSS, method="solve"):
    """The fit of :func:`fit_damping`: check, start on the grid, least squares, collect the result."""
    t0 = time.perf_counter()
    density, stiffness, w_a0, friction, vref = _material(base)
    df, rows, arr, src = _table_arrays(table)
    sigma_e, effective, weighting = _sigma_e(weights, arr, rows, src)
    _check_loss(loss, sigma_e, src)
    # the table's bound on the estimates (emulator_shift_bound) is that of least squares
    problem = FitProblem.from_arrays(arr["radius"], arr["normal_speed"], base, method if loss == "linear" else "solve")
    e_n = arr["e_n"]
    n_var = 3 if fit_work_of_adhesion else 2
    if e_n.size <= n_var:
        raise ValueError(f"{src}: {e_n.size} point(s) cannot determine {n_var} parameters")
    if fit_work_of_adhesion and not w_a0 > 0:
        raise ValueError("fitting w_A needs a start value > 0 (base.work_of_adhesion)")
    if scale_covar is None:
        scale_covar = sigma_e is None

    n_grid = np.size(start_grid[0]) * np.size(start_grid[1])
    rounds = 3 if effective else 1
    steps = n_grid + rounds + int(bool(confidence_intervals))
    with progress_bar(steps, f"fit of {e_n.size} impacts", progress) as advance:
        advance = deadline.ticking(advance, steps, f"steps ({n_grid} start-grid points, {rounds} least-squares "
                                                   f"round(s){', confidence intervals' if confidence_intervals else ''})")
        starts, nfev = _grid_start(problem, e_n, sigma_e, w_a0, start_grid, rtol, advance, loss)
        if fit_work_of_adhesion:  # w_A too: from the best grid point with w_A halved and doubled as well
            starts += [(starts[0][0], starts[0][1], w_a0 * k) for k in (0.5, 2.0)]
        sigma_v = _SpeedErrors(arr["normal_speed_uncertainty"], _derived_ratio(df, arr)) if effective else None
        if sigma_v is not None and sigma_v.ratio is not None:
            weighting += " (e_n = v_r / v_n: one incident-speed error moves ratio and model, counted as correlated)"
        fit_args = (problem, e_n, sigma_e, sigma_v, rtol, scale_covar, fit_work_of_adhesion, deadline, loss)
        best, n_runs = _multistart(starts, *fit_args)
        nfev += n_runs
        if _implausible(best[1], sigma_e):  # the start grid missed the valley: a denser, wider one
            dense, n_grid2 = _grid_start(problem, e_n, sigma_e, w_a0, DENSE_START_GRID, rtol, loss=loss)
            again, n_runs = _multistart(dense, *fit_args)
            nfev += n_grid2 + n_runs
            if _objective(again[1].residual, loss) < _objective(best[1].residual, loss):
                best, starts = again, dense
        advance(rounds)
        mini, result, sigma, n = best
        shift = emulator_shift_bound(problem, sigma, result.redchi if scale_covar else 1.0)
        if shift > EMULATOR_MAX_SHIFT:  # the data are too precise for the table's tolerance
            return _fit_damping(table, base, fit_work_of_adhesion, weights, start_grid, rtol, confidence_intervals,
                                scale_covar, progress, deadline, loss, "solve")
        mini.iter_cb = deadline.iter_cb("the confidence intervals")
        cis, ci_message = _confidence_intervals(mini, result, confidence_intervals and loss == "linear")
        if confidence_intervals and loss != "linear":
            ci_message = f"lmfit's 1- and 2-sigma limits (conf_interval) not used with the {loss} loss (it tests chi-square)"
        advance(1)

    outside = arr["outside"]
    p = result.params.valuesdict()
    model = damping_residual(p, problem, rtol=rtol)
    sig_used = np.ones_like(e_n) if sigma is None else np.asarray(sigma, dtype=float)
    data = pd.DataFrame({"row": rows, "radius": arr["radius"], "normal_speed": arr["normal_speed"],
                         "e_n": e_n, "sigma": sig_used if sigma is not None else np.full_like(e_n, np.nan),
                         "model": model, "residual": (model - e_n) / sig_used})
    data = insert_row_labels(data, row_labels(df))
    labels = df["material_pair"].dropna().unique() if "material_pair" in df.columns else ()
    info = {"nfev": int(nfev + n), "success": bool(result.success), "message": str(result.message),
            "method": "coarse log grid + lmfit " + ("leastsq" if loss == "linear" else f"least_squares (loss {loss})"),
            "rtol": float(rtol), "loss": loss, "loss_description": loss_description(loss),
            "elapsed_s": time.perf_counter() - t0, "source": df.attrs.get("source"),
            "sha256": df.attrs.get("sha256"), "material_pair": str(labels[0]) if len(labels) == 1 else None,
            "ci_message": ci_message or None, "model_evaluation": _model_evaluation(problem, rtol, shift)}
    varied = tuple(n for n in PARAMETER_NAMES if result.params[n].vary)
    grid = starts.grid if e_n.size <= GRID_START_POINTS else None  # a subsampled grid is another chi-square
    identifiability = damping_identifiability(problem, e_n, sigma, result, rtol, scale_covar, deadline, w_a0, grid,
                                              loss)
    info["elapsed_s"] = time.perf_counter() - t0
    info["success"] = bool(result.success) and all(st.determined for st in identifiability.values())
    if _implausible(result, sigma_e):
        info["success"] = False
        info["goodness_of_fit"] = (f"chi-square {result.chisqr:.4g} for {result.nfree} degrees of freedom ("
                                   f"{p_value_text(stats.chi2.sf(result.chisqr, result.nfree))}): the model does not describe these "
                                   "data within their stated uncertainties at the best fit found")
    undetermined = [n for n, st in identifiability.items() if not st.determined]
    if not info["success"] and result.success:
        info["message"] = ("least squares converged, but the data do not determine " + ", ".join(undetermined)
                           if undetermined else "least squares converged, but the model does not describe the data "
                           "(see the verdict)")
    info["outside_physical_range"] = outside
    return DampingFit(values={n: float(result.params[n].value) for n in PARAMETER_NAMES},
                      stderr={n: _stderr(result.params[n]) for n in PARAMETER_NAMES}, varied=varied,
                      correlation=_correlation(result.params, varied), confidence_intervals=cis,
                      chisqr=float(result.chisqr), redchi=float(result.redchi), aic=float(result.aic),
                      bic=float(result.bic), n_points=int(e_n.size), data=data, density=density,
                      stiffness=stiffness, friction=friction, damping_reference_speed=vref,
                      weighting=weighting, scale_covar=bool(scale_covar), info=info,
                      identifiability=identifiability)


def _model_evaluation(problem, rtol, shift) -> str:
    """How the fit computed the model e_n, in words (``info["model_evaluation"]``)."""
    rows = problem.emulated_rows()
    solved = f"the solver at rtol {rtol:g}"
    if not rows.any():
        return solved
    rest = int((~rows).sum())
    return (f"the ring-law emulator (absolute tolerance {EMULATOR_TOLERANCE:g}; the solver where the table does not "
            f"meet it) for the {int(rows.sum())} rows of radii with at least {EMULATOR_MIN_ROWS} rows, which moves an "
            f"estimate by at most {shift:.2g} standard errors" + (f"; {solved} for the other {rest}" if rest else ""))


#: allowed range of each damping parameter, searched by its profile (w_A relative to its fitted
#: value): zeta_H of 1e3 or zeta_A of 1e4 damp every impact of the model to capture, so a profile
#: flat up to there is flat for good
DAMPING_RANGES = {"zeta_hertz": (0.0, 1e3), "zeta_adhesion": (0.0, 1e4), "work_of_adhesion": (1e-3, 1e2)}
#: relative tolerance of the profile interval's ends (brentq on the profile)
PROFILE_XTOL = 1e-3
#: where PROFILE_XTOL relative would be coarser than this many standard errors, the profile is walked
#: and its ends located in standard errors (:meth:`_Profile.crossing`); a quarter leaves the fit of the
#: bundled data (100 rows) as it was
PROFILE_PRECISE = 0.25
#: tolerance of the profile interval's ends in standard errors, where they are located in them
PROFILE_SE_XTOL = 0.01


def damping_identifiability(problem, e_n, sigma, result, rtol, scale_covar, deadline=Deadline.start(None, "fit"),
                            work_of_adhesion_start: float | None = None, grid=None, loss: str = DEFAULT_LOSS) -> dict:
    """What the data determine about each varied damping parameter (:mod:`microimpact.analysis.identifiability`).

    The 95 % interval of every varied parameter is its profile-likelihood interval, {x : P(x) -
    chi2_min <= 3.84} with P(x) the chi-square re-minimised over the other varied parameters at x
    (scaled by the reduced chi-square for an unweighted fit). The profile is walked outward from
    the estimate in growing steps, each re-fit starting from the previous point's optimum
    (continuation), until it rises past the threshold or reaches the end of the parameter's range
    (:data:`DAMPING_RANGES`); the crossing is then located by brentq to :data:`PROFILE_XTOL`. An
    interval that reaches an end of the range is a one-sided bound (or, both ends, nothing): see
    :func:`~microimpact.analysis.identifiability.status_from_interval`. The covariance interval
    value +/- 1.96 stderr under-covers where e_n is far from linear in the parameter (a
    calibration study over random designs found 91 % for zeta_H; docs/calibration.md).

    Parameters
    ----------
    problem : FitProblem
    e_n : numpy.ndarray
        Measured e_n. [-]
    sigma : numpy.ndarray or None
        Uncertainties used by the fit (None: unweighted). [-]
    result : lmfit.minimizer.MinimizerResult
        The least-squares fit.
    rtol : float
        Relative tolerance of the normal solves. [-]
    scale_covar : bool
        Whether chi-square is scaled by the reduced chi-square (unweighted fits).
    deadline : Deadline
    work_of_adhesion_start : float, optional
        The material's w_A the fit started from: w_A's range is relative to it. [J/m^2]
    grid : (array, array, array), optional
        The start grid (zeta_H values, zeta_A values, chi-square): a grid point outside the walked
        interval whose chi-square is within the threshold marks a second valley of the profile
        (zeta_H and zeta_A can trade places over a narrow speed range); the interval then extends
        over it, to where the profile walked outward from that point crosses the threshold.
    loss : {"linear", "soft_l1", "huber"}
        The fit's loss: a robust one profiles its objective sum rho(z^2) (:func:`robust_terms`)
        divided by :func:`_sandwich_scale`, so that the interval has the M-estimator's width.

    Returns
    -------
    dict
        ``{name: ParameterStatus}`` for each varied parameter.
    """
    out = {}
    varied = [n for n in PARAMETER_NAMES if result.params[n].vary]
    dof = max(e_n.size - len(varied), 1)
    scales = dict.fromkeys(varied, _sandwich_scale(loss) if loss != "linear" else
                           max(result.chisqr / dof, 1e-300) if scale_covar else 1.0)
    best = _objective(result.residual, loss)
    for name in varied:
        scale = scales[name]
        level = best / scale + chi2_threshold(DEFAULT_LEVEL)
        value = float(result.params[name].value)
        lo, hi = DAMPING_RANGES[name]
        if name == "work_of_adhesion":  # relative to the material's value the fit started from
            ref = work_of_adhesion_start or value
            lo, hi = lo * ref, hi * ref
        profile = _Profile(problem, e_n, sigma, result.params, name, rtol, scale, deadline, level, loss)
        lower = profile.crossing(value, lo, level)
        upper = profile.crossing(value, hi, level)
        for x, other in _grid_valleys(grid, name, best, lower, upper):
            start = result.params.copy()
            for n, v in other.items():
                start[n].set(value=v)
            if profile(x, start)[0] <= level:  # confirmed by a re-fit: a second valley
                lower = min(lower, profile.crossing(x, lo, level, start))
                upper = max(upper, profile.crossing(x, hi, level, start))
        reasons = {"not_determined": f"chi-square changes by less than the 95 % threshold over {name} in [{lo:.3g}, {hi:.3g}]",
                   "lower_bound": f"the e_n data are as well explained by any larger {name}, up to {hi:.3g}",
                   "upper_bound": f"the e_n data are as well explained by any smaller {name}, down to {lo:.3g}"}
        out[name] = status_from_interval(name, value, lower, upper, lo, hi, method="profile", reasons=reasons,
                                         atol=1e-12 * max(abs(hi), 1.0))
    return out


def _grid_valleys(grid, name, chisqr, lower, upper):
    """[(x, {other parameter: value})]: candidates for a second valley of the profile of ``name``, start-grid
    points outside [lower, upper] whose chi-square (minimised over the other grid parameter) lies within
    twice the 95 % threshold of the grid's least, the threshold scaled by how much larger the grid's
    chi-square is than the fit's (the grid uses the stated e_n uncertainties, the fit may add the
    speed errors). Each candidate is confirmed by a re-fit before it counts."""
    if grid is None or name not in ("zeta_hertz", "zeta_adhesion"):
        return []
    gh, ga, chi2 = grid
    least = float(np.min(chi2))
    level = least + 2 * chi2_threshold() * max(least / max(chisqr, 1e-300), 1.0)
    values, axis, other_name, other_values = (gh, 1, "zeta_adhesion", ga) if name == "zeta_hertz" else (ga, 0, "zeta_hertz", gh)
    best_other = np.argmin(chi2, axis=axis)
    prof = np.min(chi2, axis=axis)
    return [(float(values[k]), {other_name: float(other_values[best_other[k]])}) for k in range(values.size)
            if prof[k] <= level and not lower <= values[k] <= upper]


class _Profile:
    """P(x): chi-square with one parameter held at x and the other varied ones re-fitted (continuation)."""

    def __init__(self, problem, e_n, sigma, best, name, rtol, scale, deadline, level=math.inf, loss=DEFAULT_LOSS):
        self.problem, self.e_n, self.sigma, self.best, self.name = problem, e_n, sigma, best, name
        self.rtol, self.scale, self.deadline, self.level, self.loss = rtol, scale, deadline, level, loss
        self.local = None  # (estimate, its stderr, {other: d other / d x}) while walked in standard errors
        self.minimum = level - chi2_threshold(DEFAULT_LEVEL)  # the scaled objective at the estimate

    def __call__(self, x, start=None) -> tuple[float, object]:
        """(P(x), the re-fitted parameters): the re-fit starts from the previous point's optimum and,
        where that differs, from the best fit too (the lower wins: a continuation alone can follow a
        valley of the other parameters that the best fit's basin leaves). Where both end above the
        threshold, the re-fit is tried once more from the best rescaled start (:meth:`_rescue`)."""
        if self.local is not None:
            return self._local_call(x, start)
        results = [self._refit(x, s) for s in ([start, self.best] if start is not None else [self.best])]
        best = min(results, key=lambda r: r[0])
        if best[0] > self.level:
            best = min(best, self._rescue(x, [s for s in (start, self.best) if s is not None]), key=lambda r: r[0])
        return best

    def _local_call(self, x, start) -> tuple[float, object]:
        """P(x) within a few standard errors of the estimate (:meth:`_crossing_in_stderr`): the same
        starts as :meth:`__call__`, tried in turn while P is above the threshold, so that whether P(x)
        is above it is decided as by all of them (a lower minimum found by a later start cannot move a
        point from below the threshold to above). The first start is the covariance's prediction of
        the other parameters at x (in a quadratic bowl, the profile's optimum), so that the re-fit
        takes a few evaluations. The rescue from a plateau (:meth:`_rescue`) runs only where P rose
        by more than twice what the covariance predicts, ((x - estimate) / stderr)^2: a re-fit stuck
        on a plateau is far above the bowl, one on the bowl is not."""
        value, se, slopes = self.local
        predicted = self.best.copy()
        for n, b in slopes.items():
            predicted[n].set(value=min(max(self.best[n].value + b * (x - value), predicted[n].min), predicted[n].max))
        best = self._refit(x, predicted)
        for s in ([start] if start is not None else []) + [self.best]:
            if best[0] <= self.level:
                return best
            best = min(best, self._refit(x, s), key=lambda r: r[0])
        rise = best[0] - self.minimum
        if best[0] > self.level and rise > 2.0 * ((x - value) / se) ** 2:
            best = min(best, self._rescue(x, [s for s in (start, self.best) if s is not None]), key=lambda r: r[0])
        return best

    def _rescue(self, x, starts) -> tuple[float, object]:
        """A re-fit from the lowest of the starts with one other varied parameter scaled by 1/8 ... 8.

        With zeta_A (or zeta_H) held far from the estimate, the previous optimum's w_A can leave
        every impact captured: e_n = 0 at every row, a plateau on which Levenberg-Marquardt has no
        gradient and stops (the calibration study's designs 1017, 1240, 1254: the profile ended on
        the plateau at chi-square 240236, 4439, 22183 and reported zeta_A <= 1.8, 4.3, 3.6, while
        from a start with a smaller w_A it stays within 0.1 of its minimum up to the range end). A
        few residual evaluations find a start off the plateau.

        The candidates only pick the start, so a large data set is represented by GRID_START_POINTS
        rows spread evenly over it, as on the start grid (:func:`_grid_start`); the re-fit uses all."""
        others = [n for n in PARAMETER_NAMES if n != self.name and self.best[n].vary]
        problem, e_n, sigma = _represented(self.problem, self.e_n, self.sigma)
        candidates = []
        for s in starts:
            for n in others:
                for factor in (0.125, 0.25, 0.5, 2.0, 4.0, 8.0):
                    p = s.copy()
                    p[self.name].set(value=x)
                    p[n].set(value=max(p[n].value, 1e-12) * factor)
                    r = damping_residual(p, problem, e_n, sigma, rtol=self.rtol)
                    candidates.append((_objective(r, self.loss), p))
        if not candidates:
            return math.inf, starts[0]
        return self._refit(x, min(candidates, key=lambda c: c[0])[1])

    def _refit(self, x, start) -> tuple[float, object]:
        params = start.copy()
        params[self.name].set(value=x, vary=False)
        if not any(params[n].vary for n in PARAMETER_NAMES):
            r = damping_residual(params, self.problem, self.e_n, self.sigma, rtol=self.rtol)
            return _objective(r, self.loss) / self.scale, params
        mini = lmfit.Minimizer(damping_residual, params, fcn_args=(self.problem,),
                               fcn_kws={"e_n": self.e_n, "sigma": self.sigma, "rtol": self.rtol},
                               iter_cb=self.deadline.iter_cb(f"the profile of {self.name}"))
        res = mini.minimize(**_method(self.loss, self.rtol, profile=True), max_nfev=400)
        return _objective(res.residual, self.loss) / self.scale, res.params

    def crossing(self, value, limit, level, start=None) -> float:
        """Where P rises to ``level`` between ``value`` and ``limit`` (``limit`` if it never does).

        The walk grows by factors of ``value`` and the crossing is located to PROFILE_XTOL relative;
        where that tolerance would exceed PROFILE_PRECISE standard errors (a parameter the data
        determine to better than ~0.1 %, as 100,000 rows do), both are in standard errors instead
        (:meth:`_crossing_in_stderr`): the relative tolerance could otherwise swallow the interval."""
        if limit == value:
            return limit
        se = self.best[self.name].stderr
        if se is not None and math.isfinite(se) and se > 0 and PROFILE_XTOL * 1.1 * abs(value) > PROFILE_PRECISE * se:
            return self._crossing_in_stderr(value, limit, level, start, float(se))
        up = limit > value
        x_in = value
        for k in range(200):
            factor = 1.2 if k < 8 else 2.0 ** min(k - 6, 6)  # growing steps: a flat profile is walked fast
            if up:
                x = min(x_in * factor if x_in > 0 else max(1e-6, 1e-3 * limit), limit)
            else:
                x = x_in / factor if x_in / factor > max(limit, 1e-6 * value) else limit
            px, params = self(x, start)
            if px > level:
                try:
                    return float(brentq(lambda t: self(t, start)[0] - level, x_in, x,
                                        xtol=PROFILE_XTOL * max(abs(x_in), abs(x)) * 1e-1 + 1e-300, rtol=PROFILE_XTOL))
                except ValueError:  # P not above the level at x_in (a re-fit found a lower minimum): bracket edge
                    return float(x)
            if x == limit:
                return float(limit)
            x_in, start = x, params
        return float(limit)

    def _crossing_in_stderr(self, value, limit, level, start, se) -> float:
        """:meth:`crossing` with steps of 1, 2, 4, ... standard errors ``se`` from ``value`` and the
        crossing located to PROFILE_SE_XTOL standard errors (a quadratic profile crosses the 95 %
        level at 1.96 of them: the second step brackets it)."""
        up = limit > value
        x_in, step = value, se
        estimate = self.best[self.name]
        slopes = {n: (estimate.correl or {}).get(n, 0.0) * self.best[n].stderr / se for n in PARAMETER_NAMES
                  if n != self.name and self.best[n].vary and self.best[n].stderr}
        self.local = (float(estimate.value), se, slopes)
        try:
            return self._walk_in_stderr(value, limit, level, start, se, up, x_in, step)
        finally:
            self.local = None

    def _walk_in_stderr(self, value, limit, level, start, se, up, x_in, step) -> float:
        for _ in range(200):
            x = min(value + step, limit) if up else max(value - step, limit)
            px, params = self(x, start)
            if px > level:
                try:
                    return float(brentq(lambda t: self(t, start)[0] - level, x_in, x, xtol=PROFILE_SE_XTOL * se,
                                        rtol=4 * np.finfo(float).eps))
                except ValueError:  # P not above the level at x_in (a re-fit found a lower minimum): bracket edge
                    return float(x)
            if x == limit:
                return float(limit)
            x_in, start, step = x, params, 2.0 * step
        return float(limit)


#: points of a large data set that represent it on the start grid (:func:`_grid_start`)
GRID_START_POINTS = 400


def _represented(problem, e_n, sigma):
    """(problem, e_n, sigma) restricted to GRID_START_POINTS rows spread evenly over the data, or as
    they are when there are no more rows than that: what picks a start, not the fit."""
    if e_n.size <= GRID_START_POINTS:
        return problem, e_n, sigma
    rows = np.unique(np.linspace(0, e_n.size - 1, GRID_START_POINTS).round().astype(int))
    return problem.subset(rows), e_n[rows], (sigma[rows] if np.ndim(sigma) else sigma)


#: least-squares runs started from the best local minima of the start grid
GRID_STARTS = 3
#: the start grid used when the first fit is implausible (chi-square p-value below IMPLAUSIBLE_P with
#: stated uncertainties): 4x denser and a decade wider in each coefficient
DENSE_START_GRID = (np.geomspace(1e-3, 100.0, 41), np.geomspace(1e-2, 1e4, 41))
#: p-value of chi-square below which a weighted fit counts as not describing the data
IMPLAUSIBLE_P = 1e-3


def _implausible(result, sigma_e) -> bool:
    """A weighted fit whose chi-square is improbable for its degrees of freedom (p < IMPLAUSIBLE_P)."""
    if sigma_e is None or result.nfree < 1:
        return False
    return bool(stats.chi2.sf(result.chisqr, result.nfree) < IMPLAUSIBLE_P)


def _multistart(starts, problem, e_n, sigma_e, sigma_v, rtol, scale_covar, fit_work_of_adhesion, deadline,
                loss=DEFAULT_LOSS):
    """(the least-chi-square run of _least_squares over ``starts``, evaluations): e_n trades zeta_H
    against zeta_A along curved valleys, so one start can end in the wrong one."""
    best, nfev = None, 0
    for zh0, za0, wa in starts:
        params = lmfit.Parameters()
        params.add("zeta_hertz", value=zh0, min=0.0)
        params.add("zeta_adhesion", value=za0, min=0.0)
        params.add("work_of_adhesion", value=wa, min=1e-12 if fit_work_of_adhesion else 0.0, vary=fit_work_of_adhesion)
        run = _least_squares(problem, e_n, params, sigma_e, sigma_v, rtol, scale_covar, lambda n=1: None, deadline,
                             loss)
        nfev += run[3]
        if best is None or _objective(run[1].residual, loss) < _objective(best[1].residual, loss) * (1 - 1e-9):
            best = run
    return best, nfev


def _grid_start(problem, e_n, sigma, work_of_adhesion, start_grid, rtol, advance=lambda n=1: None,
                loss=DEFAULT_LOSS):
    """([(zeta_H, zeta_A, w_A)] at the GRID_STARTS best local minima of chi-square on the start grid,
    best first; number of evaluations).

    The grid only picks the basins the least-squares fits start in, so a large data set is
    represented by GRID_START_POINTS points spread evenly over it (a 100,000-row fit would
    otherwise spend most of its time here)."""
    gh, ga = (np.asarray(g, dtype=float).ravel() for g in start_grid)
    if gh.size == 0 or ga.size == 0 or np.any(gh < 0) or np.any(ga < 0):
        raise ValueError("start_grid must be two non-empty arrays of zeta values >= 0")
    problem, e_n, sigma = _represented(problem, e_n, sigma)
    chi2 = np.full((gh.size, ga.size), math.inf)
    for i, zh in enumerate(gh):
        for j, za in enumerate(ga):
            r = damping_residual({"zeta_hertz": zh, "zeta_adhesion": za, "work_of_adhesion": work_of_adhesion},
                                 problem, e_n, sigma, rtol=rtol)
            chi2[i, j] = _objective(r, loss)
            advance(1)
    padded = np.pad(chi2, 1, constant_values=math.inf)
    neighbours = np.stack([padded[:-2, 1:-1], padded[2:, 1:-1], padded[1:-1, :-2], padded[1:-1, 2:]])
    minima = np.argwhere(chi2 <= neighbours.min(axis=0))
    order = sorted(minima.tolist(), key=lambda ij: chi2[ij[0], ij[1]])[:GRID_STARTS]
    starts = [(float(gh[i]), float(ga[j]), float(work_of_adhesion)) for i, j in order]
    return _GridStarts(starts, (gh, ga, chi2)), gh.size * ga.size


class _GridStarts(list):
    """The start points, with the grid's chi-square (zeta_H values, zeta_A values, chi2[i, j]) kept
    for the identifiability (a second valley of the profile that a walk from the estimate cannot see)."""

    def __init__(self, starts, grid):
        super().__init__(starts)
        self.grid = grid


def _least_squares(problem, e_n, params, sigma_e, sigma_v, rtol, scale_covar, advance=lambda n=1: None,
                   deadline=Deadline.start(None, "fit"), loss=DEFAULT_LOSS):
    """Levenberg-Marquardt from ``params``; with speed uncertainties ``sigma_v`` [m/s] re-weighted
    twice by the effective variance. Returns (minimizer, result, sigma used, evaluations)."""
    rounds = 1 if sigma_v is None else 3

    def run(params, sigma, k):
        mini = lmfit.Minimizer(damping_residual, params, fcn_args=(problem,),
                               fcn_kws={"e_n": e_n, "sigma": sigma, "rtol": rtol}, scale_covar=scale_covar,
                               iter_cb=deadline.iter_cb(f"least-squares round {k} of {rounds}"))
        return mini, mini.minimize(**_method(loss, rtol))

    sigma = sigma_e
    mini, result = run(params, sigma, 1)
    advance(1)
    nfev = result.nfev
    if sigma_v is not None:
        for k in (2, 3):  # re-weight with the slope at the current best fit, refit
            sigma = _effective_sigma(problem, result.params.valuesdict(), sigma_e, sigma_v, rtol)
            mini, result = run(result.params, sigma, k)
            advance(1)
            nfev += result.nfev + 2 * len(problem.radii)
    return mini, result, sigma, nfev


def _method(loss: str, rtol: float, profile: bool = False) -> dict:
    """lmfit's minimize arguments of a loss: ``leastsq`` for least squares; ``least_squares`` with
    scipy's robust loss at f_scale 1 (one stated uncertainty) and a finite-difference step of
    sqrt(rtol), the step that balances truncation against the solver's relative error rtol.

    The profile's re-fits (``profile``) take that step with leastsq too: MINPACK's default,
    sqrt(machine epsilon) ~ 1.5e-8, differences noise, and a re-fit can stop short of its minimum
    (on four oblique rows the profile of zeta_A ended at 30.7 at rtol 1e-8 and at 24.6 at rtol 1e-10;
    with the step, at 24.55 at both). The main least-squares fit keeps MINPACK's default step: its
    value is converged to xtol either way, and its covariance is not what is printed (the interval's
    standard error is)."""
    if loss == "linear":  # MINPACK's forward-difference step is sqrt(epsfcn) relative
        return {"method": "leastsq", "epsfcn": rtol} if profile else {"method": "leastsq"}
    return {"method": "least_squares", "loss": loss, "f_scale": 1.0, "diff_step": math.sqrt(rtol)}


def loss_description(loss: str) -> str:
    """What a loss of the damping fit means, in words, for the report.

    Examples
    --------
    >>> loss_description("linear")
    'linear (least squares)'
    >>> print(loss_description("huber"))
    huber (robust: lmfit least_squares, scipy's loss at f_scale = 1 stated uncertainty; 95 % intervals from the profile of its objective, divided by the sandwich factor 0.756); the verdict's chi-square is the plain one, sum z^2 at the fitted values
    """
    if loss == "linear":
        return "linear (least squares)"
    return (f"{loss} (robust: lmfit least_squares, scipy's loss at f_scale = 1 stated uncertainty; 95 % intervals "
            f"from the profile of its objective, divided by the sandwich factor {_sandwich_scale(loss):.3g}); "
            "the verdict's chi-square is the plain one, sum z^2 at the fitted values")


def _check_loss(loss, sigma_e, src) -> None:
    """ValueError for an unknown loss, or a robust one without stated uncertainties (its scale)."""
    if loss not in LOSSES:
        raise ValueError(f"loss must be one of {', '.join(LOSSES)}, got {loss!r}")
    if loss != "linear" and sigma_e is None:
        raise ValueError(f"{src}: the {loss} loss needs stated e_n uncertainties (its scale is one stated standard "
                         "uncertainty); the table has none, or weights='none' was given")


@functools.lru_cache(maxsize=None)
def _sandwich_scale(loss: str) -> float:
    """c: the factor by which the profile of a robust objective sum rho(z^2) is divided so that its
    95 % interval has the M-estimator's width where the rows other than the outliers scatter by their
    stated uncertainties (z ~ N(0, 1)), as the least-squares profile assumes too.

    Near the fit, sum rho(z^2) rises by (x - x_hat)^2 / (2 (M^-1)_jj) with M = sum rho''(z) g g^T
    (g = dz/dtheta), while the estimator's variance is the sandwich M^-1 V M^-1 with
    V = sum psi(z)^2 g g^T (Huber 1967). With the expectations over z ~ N(0, 1) in place of each
    row's value, M = E[rho''] G and V = E[psi^2] G (G = sum g g^T), so for every parameter
    c = E[psi^2] / (2 E[rho'']): 1 for least squares, 0.610 for soft_l1, 0.756 for huber.
    A gross outlier enters neither expectation: its pull on the fit is bounded (|psi| <= 2).

    References
    ----------
    Huber, P. J. (1967). The behavior of maximum likelihood estimates under nonstandard conditions.
    Proc. Fifth Berkeley Symp. Math. Statist. Prob. 1, 221-233.
    """
    def mean(f):
        return integrate.quad(lambda z: f(np.array([z]))[0] * stats.norm.pdf(z), -40, 40, points=[-1, 0, 1])[0]
    psi2 = mean(lambda z: robust_terms(z, loss)[1] ** 2)
    second = mean(lambda z: robust_terms(z, loss)[2])
    return float(psi2 / (2 * second))


def _stderr(param) -> float:
    """Standard error of a varied lmfit parameter, NaN if fixed or not estimated."""
    return float(param.stderr) if param.vary and param.stderr is not None else math.nan


def _correlation(params, varied) -> np.ndarray:
    """Correlation matrix of :data:`PARAMETER_NAMES`, NaN rows and columns for fixed parameters."""
    corr = np.full((3, 3), np.nan)
    for i, a in enumerate(PARAMETER_NAMES):
        if a in varied:
            corr[i, i] = 1.0
            for j, b in enumerate(PARAMETER_NAMES):
                cb = (params[a].correl or {}).get(b)
                if cb is not None:
                    corr[i, j] = cb
    return corr


def _confidence_intervals(mini, result, wanted: bool) -> tuple[dict, str]:
    """({name: {sigma level: limit}} from lmfit.conf_interval, message why not when they are missing)."""
    if not wanted:
        return {}, "lmfit's 1- and 2-sigma limits (conf_interval) not requested"
    if not result.errorbars:
        return {}, "lmfit's 1- and 2-sigma limits (conf_interval) not computed: lmfit could not estimate the covariance"
    varied = [n for n in PARAMETER_NAMES if result.params[n].vary]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            raw = lmfit.conf_interval(mini, result, p_names=varied, sigmas=[1, 2])
    except TimeBudgetExceeded:  # the caller's budget, not a failure of the intervals
        raise
    except Exception as exc:  # noqa: BLE001 - report, do not fail the fit
        return {}, f"lmfit's 1- and 2-sigma limits (conf_interval) not computed: {exc}"
    # rows are (probability, value) for -2, -1, 0, +1, +2 sigma
    return {name: dict(zip((-2, -1, 1, 2), (float(rows[k][1]) for k in (0, 1, 3, 4))))
            for name, rows in raw.items()}, ""
