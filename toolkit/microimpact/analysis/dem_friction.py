"""The Coulomb coefficient mu of a DEM tangential law (LAMMPS GRANULAR) fitted to oblique rebounds.

:func:`fit_dem_friction` fits mu of ``linear_history`` or a ``mindlin`` variant
(:mod:`microimpact.model.dem_tangential`) with the rest of the contact given, e.g. the normal law of
:func:`microimpact.analysis.dem_fit.fit_dem_law`; the held tangential stiffness is reported (how far
mu moves with it) or, with its uncertainty, profiled out. :func:`rank_dem_tangential_laws` ranks the
laws by AIC and :func:`dem_friction_coverage` measures the coverage of mu's interval over random
designs. Every DEM law is solved in full for each trial mu, so the profile, its interval and its
status come from :mod:`microimpact.analysis.oblique` (the rigid law's fit), with a costlier objective.

The held tangential stiffness
-----------------------------
The data of a fit rarely determine the tangential stiffness alone, and mu depends on it where the
contact sticks (low incidence): :func:`fit_dem_friction` refits mu at the stiffness 10 % below and
above the given one, and the report states both. Without ``stiffness_uncertainty`` the interval
holds at the given stiffness only: on four noisy rebounds at 10-70 deg (LAMMPS's Mindlin law,
mu = 0.25) half and twice the true G* gave mu = 0.36 and a lower bound of 9.9, far outside the
interval [0.234, 0.264] at the true G*. With it (u), the stiffness is a nuisance parameter with a
Gaussian prior, (1 + u z) times the given one, z standard normal, profiled out
(:class:`_StiffnessProfile`): the interval is mu's profile likelihood over mu and z jointly, so
rebounds that constrain the stiffness narrow it and a valley of e_t(mu) that moves with the
stiffness is followed. The normal law's shift is measured at the given stiffness and widens this
interval as it widens the held one (:func:`fit_dem_friction`, Notes). Measured calibration: :data:`STIFFNESS_COVERAGE`.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import lmfit
import numpy as np
import pandas as pd
from scipy.optimize import minimize_scalar

from microimpact.analysis.dem_fit import (REGION_RAYS, DemLawFit, dem_law_contact, fit_dem_law, information_criteria,
                                          ranked_by_aic)
from microimpact.analysis.identifiability import DEFAULT_LEVEL
from microimpact.analysis.oblique import (PARAMETER_BOUNDS, _H_ANGLE, _H_SPEED, FrictionFit, ObliqueProblem,
                                          _friction_result, _friction_status, _FrictionObjective, _observables,
                                          _profile_fit, _profile_scale)
from microimpact._runtime.progress import progress_bar
from microimpact.model.dem_damping import RESTITUTION_DAMPING_MODELS, critical_damping_coefficient
from microimpact.model.dem_tangential import DEM_TANGENTIAL_MODELS
from microimpact.solvers import DEFAULT_RTOL, Deadline
from microimpact.solvers.dem_tangential import uses_dem_tangential
from microimpact.solvers.impact import simulate_impact

__all__ = ["fit_dem_friction", "rank_dem_tangential_laws", "dem_friction_coverage"]


#: points of the friction profile of a DEM tangential law (each point solves every entry), and the
#: points added where it lies near its minimum (the interval's ends)
DEM_PROFILE_POINTS = 48
DEM_REFINE_POINTS = 32
#: relative change of the held tangential stiffness at which :func:`fit_dem_friction` refits mu to
#: show how much mu depends on it (the data of a DEM law's fit do not determine the stiffness)
STIFFNESS_STEP = 0.1


def fit_dem_friction(table, contact_of, *, normal_fit=None, stiffness_uncertainty: float | None = None,
                     rtol: float = DEFAULT_RTOL, progress: bool = False,
                     time_budget: float | None = None) -> FrictionFit:
    """Fit the Coulomb coefficient mu of a DEM tangential law (LAMMPS's ``linear_history`` or a
    ``mindlin`` variant, :mod:`microimpact.model.dem_tangential`) to the oblique columns.

    The rest of the contact (normal law, damping, tangential stiffness and damping) is given, e.g.
    by :func:`microimpact.analysis.dem_fit.fit_dem_law` for the normal law and the material's G*.

    Parameters
    ----------
    table : pandas.DataFrame
        Impacts from :func:`microimpact.io.read_impacts` with an oblique column.
    contact_of : callable
        radius [m] -> Contact with a DEM ``tangential_model`` (one of
        :data:`~microimpact.model.dem_tangential.DEM_TANGENTIAL_MODELS`; its ``friction`` is
        replaced by each trial mu).
    normal_fit : DemLawFit, optional
        The fit of the normal law that ``contact_of`` holds (:func:`~microimpact.analysis.dem_fit.fit_dem_law`):
        its uncertainty is propagated into mu (Notes). None: mu at the given normal law, nothing
        propagated.
    stiffness_uncertainty : float, optional
        Relative standard uncertainty of the held tangential stiffness (``tangential_stiffness`` of
        ``linear_history``, ``shear_modulus`` of the mindlin laws), in [0, 0.5): the stiffness is
        profiled out of mu's interval with a Gaussian prior of this width (Notes). None or 0: mu at
        the given stiffness. [-]
    rtol : float
        Relative tolerance of the solves. [-]
    progress : bool
        Progress bar on stderr (a terminal only).
    time_budget : float or Deadline, optional
        Wall-clock budget; None: no limit. [s]

    Returns
    -------
    FrictionFit
        As :func:`fit_friction` (``info["damping_gradient"]``: d mu / d normal parameter), its
        ``tangential_model`` the DEM law's; where mu is determined, ``info["stiffness_sensitivity"]``:
        the held stiffness (``field``, ``value``) and mu refitted at :data:`STIFFNESS_STEP` below and
        above it (``friction_low``, ``friction_high``); with ``stiffness_uncertainty`` also
        ``profiled_factor`` (the best stiffness over the given one) and ``friction_at_given`` (mu's
        fit at the given stiffness; NaN where not determined there).

    Raises
    ------
    ValueError
        No oblique data, no DEM tangential law, or a ``normal_fit`` of another law or with a
        parameter not determined (each named).
    TimeBudgetExceeded
        The fit ran past ``time_budget``.

    Notes
    -----
    Every trial mu solves every entry (:func:`microimpact.solvers.dem_tangential.solve_dem_tangential`):
    the profile has :data:`DEM_PROFILE_POINTS` log-spaced points over ``PARAMETER_BOUNDS["friction"]``,
    refined and polished as in :func:`fit_friction`; the interval is the profile-likelihood interval.
    With stated speed or angle uncertainties the effective variance is evaluated once, at a first fit
    with the stated uncertainties alone, and held for the second (it depends on mu only through the
    model's slopes). With ``normal_fit``, mu is refitted over the boundary of the normal law's 95 %
    confidence region (:meth:`~microimpact.analysis.dem_fit.DemLawFit.confidence_region`) and each
    end of its 95 % interval widened in quadrature by how far the refits move it that way
    (:func:`_normal_law_shift`). How the held tangential stiffness is reported or, with
    ``stiffness_uncertainty``, profiled out: the module docstring (The held tangential stiffness).

    References
    ----------
    LAMMPS documentation, ``pair_style granular``, https://docs.lammps.org/pair_granular.html.

    Examples
    --------
    Four noise-free rebounds of LAMMPS's Mindlin law with mu = 0.25 give mu back:

    >>> import numpy as np, pandas as pd
    >>> from microimpact import Contact, simulate_impact
    >>> c = Contact(1e-6, 2000.0, 1e9, 0.0, friction=0.25, tangential_model="lammps_mindlin", shear_modulus=3e8)
    >>> angles = np.linspace(10.0, 70.0, 4)
    >>> e_t = [simulate_impact(c, 1.0, a).velocity_out[1] / np.sin(np.radians(a)) for a in angles]
    >>> table = pd.DataFrame({"radius": 1e-6, "speed": 1.0, "incidence_deg": angles, "e_n": 1.0,
    ...                       "tangential_restitution": e_t, "tangential_restitution_uncertainty": 0.01})
    >>> fit = fit_dem_friction(table, lambda r: c)
    >>> fit.identifiability["friction"].determined, round(fit.friction, 6)
    (True, 0.25)
    """
    t0 = time.perf_counter()
    deadline = Deadline.start(time_budget, "friction fit")
    problem = ObliqueProblem.from_table(table, warn=True)
    contact = _dem_contact(contact_of, problem)
    ends = _normal_fit_ends(normal_fit, contact_of, problem) if normal_fit is not None else {}
    u = _stiffness_uncertainty(stiffness_uncertainty)
    weighted = bool(np.all(np.isfinite(problem.sigma_measured) & (problem.sigma_measured > 0)))
    with progress_bar(_fit_evaluations(u, ends), "friction fit", progress) as advance:
        objective = _DemFrictionObjective(problem, contact_of, weighted, rtol, advance)
        held, fitted, best = _profiled_friction(objective, contact, contact_of, u, deadline)
        shift, gradient, sensitivity = _friction_sensitivities(objective, fitted, contact_of, normal_fit, ends,
                                                               held, best, u, deadline)
    fit = _friction_result(problem, fitted, best, 0.0, {"friction": gradient} if gradient else {}, weighted,
                           contact.tangential_model, t0, shift=shift)
    return replace(fit, info=fit.info | {"normal_propagated": ", ".join(gradient), "stiffness_sensitivity": sensitivity,
                                         "stiffness_uncertainty": u if sensitivity else None})


def _dem_contact(contact_of, problem):
    """The contact of the first entry's radius, checked to hold a DEM tangential law (ValueError)."""
    contact = contact_of(float(problem.radius[0]))
    if not uses_dem_tangential(contact):
        raise ValueError(f"fit_dem_friction fits a DEM tangential law ({', '.join(map(repr, DEM_TANGENTIAL_MODELS))}); the "
                         f"contact has tangential_model={contact.tangential_model!r} (use fit_friction)")
    return contact


def _fit_evaluations(u, ends) -> int:
    """The progress bar's total of :func:`fit_dem_friction`: its profiles (three more with a
    stiffness uncertainty ``u``) and the refits over the normal law's interval ``ends``."""
    profile = 2 * (DEM_PROFILE_POINTS + DEM_REFINE_POINTS + 20)
    return profile * (1 + 2 * bool(u)) + (_region_refits(ends) + 2) * _REFIT_EVALUATIONS


def _profiled_friction(objective, contact, contact_of, u, deadline):
    """(held, fitted, best): mu's profile fit at the given stiffness (``held``, the effective variance
    held at a first fit where speeds or angles carry uncertainties), the objective of the final fit
    (``objective``, or the :class:`_StiffnessProfile` over the stiffness with relative uncertainty
    ``u``) and that fit (``best``)."""
    problem = objective.problem
    best = _profile_fit(objective, lmfit, deadline, DEM_PROFILE_POINTS, DEM_REFINE_POINTS)
    if objective.weighted and (np.any(problem.sigma_speed > 0) or np.any(problem.sigma_angle > 0)):
        objective.hold_effective_sigma(best.value)
        best = _profile_fit(objective, lmfit, deadline, DEM_PROFILE_POINTS, DEM_REFINE_POINTS)
    held, fitted = best, objective
    if u and getattr(contact, _stiffness_field(contact.tangential_model)):
        weight = _profile_scale(objective, best.chisqr, max(problem.size - 1, 1))
        fitted = _StiffnessProfile(objective, contact_of, u, weight)
        best = _profile_fit(fitted, lmfit, deadline, DEM_PROFILE_POINTS, DEM_REFINE_POINTS)
    return held, fitted, best


def _friction_sensitivities(objective, fitted, contact_of, normal_fit, ends, held, best, u, deadline):
    """(shift, gradient, sensitivity) of a determined mu (else (None, {}, {})): the normal law's
    shift and gradient (:func:`_normal_law_shift`, with interval ``ends``; measured at the given
    stiffness, about its own fit ``held``, and applied to the profiled interval) and
    :func:`_stiffness_sensitivity`, with ``u`` also the profiled stiffness factor and mu at the
    given stiffness."""
    shift, gradient, sensitivity = None, {}, {}
    if _friction_status(best, fitted, 0.0).determined:
        if ends:
            shift, gradient = _normal_law_shift(objective, contact_of, normal_fit, held, deadline)
        sensitivity = _stiffness_sensitivity(objective, contact_of, held, deadline)
        if u and sensitivity:
            z = fitted.stiffness_z(best.value)
            sensitivity |= {"uncertainty": u, "profiled_factor": 1.0 + u * z,
                            "friction_at_given": held.value if _friction_status(held, objective, 0.0).determined
                            else math.nan}
    return shift, gradient, sensitivity


def _refit(deviance, brackets, width, lo_lim, hi_lim) -> float:
    """The minimiser of ``deviance`` over mu: bounded Brent in each bracket in turn until its minimum
    lies inside; else (the normal law moved mu further) from the best point of a grid over the whole
    range [lo_lim, hi_lim], an end of which is returned when the minimum lies there (mu moves at
    least that far, and the widened interval reaches the range's end)."""
    for a, b in brackets:
        res = minimize_scalar(deviance, bounds=(a, b), method="bounded",
                              options={"xatol": 1e-4 * width, "maxiter": _REFIT_EVALUATIONS})
        if res.success and min(res.x - a, b - res.x) > 1e-3 * width:
            return float(res.x)
    grid = np.concatenate([[lo_lim], np.geomspace(max(lo_lim, 1e-3), hi_lim, 41)])
    values = [deviance(x) for x in grid]
    i = int(np.argmin(values))
    if i in (0, grid.size - 1):
        return float(grid[i])
    res = minimize_scalar(deviance, bounds=(grid[i - 1], grid[i + 1]), method="bounded",
                          options={"xatol": 1e-4 * width, "maxiter": _REFIT_EVALUATIONS})
    return float(res.x) if res.fun <= values[i] else float(grid[i])


def _region_refits(ends) -> int:
    """How many refits :func:`_normal_law_shift` makes for a normal fit with these interval ends."""
    return {0: 0, 1: 2}.get(len(ends), REGION_RAYS)


#: most objective evaluations of one refit of :func:`_normal_law_shift`
_REFIT_EVALUATIONS = 60


def _normal_fit_ends(normal_fit, contact_of, problem) -> dict:
    """The 95 % interval ends of the normal fit's parameters, checked: its law must be the one
    ``contact_of`` holds, and every end finite (ValueError naming what differs)."""
    if not isinstance(normal_fit, DemLawFit):
        raise TypeError(f"normal_fit must be the DemLawFit of fit_dem_law, not {type(normal_fit).__name__}")
    r = float(problem.radius[0])
    given, fitted = contact_of(r), normal_fit.contact(r)
    for name in ("normal_model", "damping_model", "damping_coefficient", "adhesion_line_force", "stiffness", "density"):
        a, b = getattr(given, name), getattr(fitted, name)
        if a != b and not (isinstance(a, float) and math.isclose(a, b, rel_tol=1e-12)):
            raise ValueError(f"normal_fit: contact_of({r:g}) has {name}={a!r}, the fitted law ({normal_fit.law}) "
                             f"{b!r}; build contact_of from normal_fit.contact")
    ends = normal_fit.interval_ends()
    statuses = {"coefficient": normal_fit.status, "work_of_adhesion": normal_fit.adhesion_status}
    for name, (lo, hi) in ends.items():
        if statuses[name] in ("not determined", "inadequate"):
            raise ValueError(f"normal_fit: the {normal_fit.law} fit's {name} is {statuses[name]} ("
                             f"{normal_fit.describe()}): mu cannot carry its uncertainty; fit mu at a given normal "
                             "law (normal_fit=None) or measure what determines it")
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ValueError(f"normal_fit: the {normal_fit.law} fit's {name} has no finite 95 % interval "
                             f"({lo:.6g} to {hi:.6g}, status {normal_fit.status!r}): its uncertainty cannot be propagated")
    return ends


def _refits(objective, contacts_of, best, deadline, what: str) -> np.ndarray:
    """mu refitted by :func:`_refit`, at the effective variance held at the estimate's, with each of
    ``contacts_of`` (radius -> Contact) in place of the fit's contact; ``what`` names them for the
    deadline's message.

    Each refit is a bounded Brent search over +-10 conditional standard errors about the estimate,
    to 1e-3 of one; a minimum at an end of that bracket is searched again over [mu / 2, 2 mu], then
    over the whole range."""
    _, lo_lim, hi_lim = PARAMETER_BOUNDS["friction"]
    f = best.value
    width = 10.0 * best.stderr if math.isfinite(best.stderr) and best.stderr > 0 else 0.5 * f
    brackets = [(max(lo_lim, f - width), min(hi_lim, f + width)), (max(lo_lim, 0.5 * f), min(hi_lim, 2.0 * f))]
    out = []
    for contact_of in contacts_of:
        moved = _DemFrictionObjective(objective.problem, contact_of, objective.weighted, objective.rtol, objective.advance)
        moved._sigma = objective.sigma(f)
        out.append(_refit(moved.deviance, brackets, width, lo_lim, hi_lim))
        deadline.check(what)
    return np.array(out)


def _stiffness_field(tangential_model: str) -> str:
    """The Contact field of a DEM tangential law's stiffness (linear_history: k_t [N/m]; the
    mindlin laws: G* [Pa], their k_t being 8 G* a)."""
    return "tangential_stiffness" if tangential_model == "linear_history" else "shear_modulus"


def _stiffness_uncertainty(uncertainty) -> float | None:
    """The relative standard uncertainty of the held stiffness, checked (ValueError outside
    [0, 0.5)); None or 0: none (the stiffness held)."""
    if uncertainty is None:
        return None
    u = float(uncertainty)
    if not (0.0 <= u < 0.5):
        raise ValueError(f"stiffness_uncertainty must be a relative standard uncertainty in [0, 0.5), got {uncertainty!r}")
    return u or None


def _scaled_stiffness(contact_of, name: str, factor: float):
    """radius -> ``contact_of(radius)`` with its stiffness field ``name`` times ``factor``."""
    def contact(r):
        c = contact_of(r)
        return c.with_(**{name: factor * getattr(c, name)})
    return contact



def _stiffness_sensitivity(objective, contact_of, best, deadline) -> dict:
    """The held tangential stiffness's field and value, and mu refitted with it
    :data:`STIFFNESS_STEP` lower and higher (``friction_low``, ``friction_high``); {} where the law
    has no stiffness."""
    first = contact_of(float(objective.problem.radius[0]))
    name = _stiffness_field(first.tangential_model)
    value = getattr(first, name)
    if not value:
        return {}

    refits = _refits(objective, [_scaled_stiffness(contact_of, name, 1.0 + s * STIFFNESS_STEP) for s in (-1, 1)],
                     best, deadline,
                     "the refits of mu at the changed tangential stiffness")
    return {"field": name, "value": float(value), "step": STIFFNESS_STEP,
            "friction_low": float(refits[0]), "friction_high": float(refits[1])}


def _normal_law_shift(objective, contact_of, normal_fit, best, deadline) -> tuple[tuple[float, float], dict]:
    """((down, up), {parameter: d mu / d parameter}): how far mu moves over the normal law's 95 %
    confidence region.

    mu is refitted (at the held effective variance) at every point of
    :meth:`~microimpact.analysis.dem_fit.DemLawFit.confidence_region` (the two ends of the
    damping's 95 % interval, or 12 points around the joint region of the damping and a fitted work
    of adhesion); ``down`` and ``up`` are how far the lowest and highest refit lie below and above
    the estimate. For a linear model this is 1.96 sqrt(g^T C g) both ways (the delta method with
    the normal fit's covariance C, correlation included); beyond it the refits follow the model:
    a work of adhesion whose interval is wide in log10 w_A moves mu further one way than the other.
    :func:`_friction_status` widens each end of the 95 % profile interval in quadrature by its
    side's shift. The gradient is the slope of the least-squares plane through the refits
    (:func:`_refits`)."""
    f = best.value
    points = normal_fit.confidence_region(DEFAULT_LEVEL)

    def shifted(keywords):
        def contact(r):
            law = normal_fit.contact(r, **keywords)
            return contact_of(r).with_(damping_coefficient=law.damping_coefficient,
                                       adhesion_line_force=law.adhesion_line_force)
        return contact

    refits = _refits(objective, [shifted(k) for k in points], best, deadline,
                     "the refits of mu over the normal law's confidence region")
    names = list(points[0])
    best_point = {"coefficient": normal_fit.best, "work_of_adhesion": normal_fit.material.get("work_of_adhesion", 0.0)}
    design = np.array([[1.0, *(p[k] - best_point[k] for k in names)] for p in points])
    slope = np.linalg.lstsq(design, refits, rcond=None)[0][1:]  # a plane through the refits (two: the secant)
    shift = (max(0.0, f - float(refits.min())), max(0.0, float(refits.max()) - f))
    return shift, dict(zip(names, map(float, slope)))


def rank_dem_tangential_laws(table, contacts_of, *, normal_fit=None, stiffness_uncertainty: float | None = None,
                             rtol: float = DEFAULT_RTOL, progress: bool = False, time_budget: float | None = None):
    """Fit mu of each DEM tangential law to the same oblique columns and rank the laws by AIC.

    Parameters
    ----------
    table : pandas.DataFrame
        As :func:`fit_dem_friction`.
    contacts_of : mapping
        tangential_model -> (radius [m] -> Contact with that law), the rest of the contact given.
    normal_fit, stiffness_uncertainty, rtol, progress
        As :func:`fit_dem_friction` (the normal fit's and the stiffness's uncertainty propagated into
        every law's mu).
    time_budget : float or Deadline, optional
        Wall-clock budget of all the fits; None: no limit. [s]

    Returns
    -------
    (pandas.DataFrame, dict)
        One row per law, best first: law, status (:class:`~microimpact.analysis.identifiability.ParameterStatus`),
        friction (NaN unless determined) and its 95 % profile interval (or a one-sided bound and
        the end of the range; NaN where not determined), chi^2, AIC, BIC (one
        parameter each), dAIC and the Akaike weight; and ``{law: FrictionFit}``. Laws within a
        dAIC of 2 are not told apart by the data (Burnham & Anderson 2002, Sec. 2.6).

    References
    ----------
    Burnham, K. P. and Anderson, D. R. (2002), Model Selection and Multimodel Inference, Springer.

    Examples
    --------
    Rebounds of LAMMPS's ``mindlin/force`` law at 3-12 deg, where the contact sticks while it
    unloads and the variants differ, rank it first:

    >>> import numpy as np, pandas as pd
    >>> from microimpact import Contact, simulate_impact
    >>> base = Contact(1e-6, 2000.0, 1e9, 0.0, friction=0.2, shear_modulus=3e8)
    >>> laws = ["lammps_mindlin", "lammps_mindlin_force"]
    >>> angles = np.linspace(3.0, 12.0, 4)
    >>> truth = base.with_(tangential_model="lammps_mindlin_force")
    >>> e_t = [simulate_impact(truth, 1.0, a).velocity_out[1] / np.sin(np.radians(a)) for a in angles]
    >>> table = pd.DataFrame({"radius": 1e-6, "speed": 1.0, "incidence_deg": angles, "e_n": 1.0,
    ...                       "tangential_restitution": e_t, "tangential_restitution_uncertainty": 0.01})
    >>> ranked, fits = rank_dem_tangential_laws(table, {m: (lambda r, m=m: base.with_(tangential_model=m)) for m in laws})
    >>> ranked["law"][0], bool(ranked["delta_aic"][1] > 10)
    ('lammps_mindlin_force', True)
    """
    deadline = Deadline.start(time_budget, "tangential laws fitted")
    fits, rows = {}, []
    for law, contact_of in contacts_of.items():
        fit = fit_dem_friction(table, contact_of, normal_fit=normal_fit, stiffness_uncertainty=stiffness_uncertainty,
                               rtol=rtol, progress=progress, time_budget=deadline)
        if fit.tangential_model != law:
            raise ValueError(f"contacts_of[{law!r}] gives tangential_model={fit.tangential_model!r}")
        fits[law] = fit
        status = fit.identifiability["friction"]
        aic, bic = information_criteria(fit.chisqr, fit.n_points, fit.weighted)
        shown = status.status != "not_determined"  # an interval, or a one-sided bound and the range's end
        rows.append({"law": law, "status": status.status, "friction": fit.friction if status.determined else math.nan,
                     "interval_low": status.lower if shown else math.nan,
                     "interval_high": status.upper if shown else math.nan,
                     "chisqr": fit.chisqr, "aic": aic, "bic": bic})
    return ranked_by_aic(pd.DataFrame(rows)), fits


class _DemFrictionObjective(_FrictionObjective):
    """Chi-square of a DEM tangential law's mu: every entry solved at every trial mu (cached)."""

    def __init__(self, problem, contact_of, weighted, rtol, advance=lambda n=1: None):
        self.problem, self.weighted, self.rtol, self.advance = problem, weighted, rtol, advance
        self.contacts = {float(r): contact_of(float(r)) for r in np.unique(problem.radius)}
        self.nfev = 0
        self._cache = {}
        self._sigma = None

    def model(self, f, state="nominal") -> np.ndarray:
        key = (float(f), state)
        if key not in self._cache:
            self.nfev += 1
            self.advance(1)
            p = self.problem
            v, a = p.speed.copy(), p.incidence_deg.copy()
            if state == "v+":
                v = v * (1 + _H_SPEED)
            elif state == "v-":
                v = v * (1 - _H_SPEED)
            elif state == "a+":
                a = a + _H_ANGLE
            elif state == "a-":
                a = np.maximum(a - _H_ANGLE, 0.0)
            self._cache[key] = self._solve_all(float(f), v, np.clip(a, 0.0, 89.9))
        return self._cache[key]

    def _solve_all(self, f, v, a) -> np.ndarray:
        p = self.problem
        names = ("velocity_out_n", "velocity_out_t", "omega_out_n", "omega_out_t", "omega_out_tp")
        out = {k: np.empty(p.size) for k in names}
        captured = np.zeros(p.size, dtype=bool)
        for i in range(p.size):
            c = self.contacts[float(p.radius[i])].with_(friction=f)
            r = simulate_impact(c, float(v[i]), float(a[i]), omega=(0.0, 0.0, -float(p.spin[i])), rtol=self.rtol)
            captured[i] = r.outcome == "capture"
            vals = (abs(r.velocity_out[0]), r.velocity_out[1], *r.omega_out)
            for k, x in zip(names, vals):
                out[k][i] = x
        return np.where(captured, np.nan, _observables(out, v, a, p.quantity))

    def hold_effective_sigma(self, f) -> None:
        """Evaluate the effective variance at ``f`` and hold it for every trial mu."""
        p = self.problem
        self._sigma = self._effective_sigma(f, bool(np.any(p.sigma_speed > 0)), bool(np.any(p.sigma_angle > 0)))

    def sigma(self, f) -> np.ndarray:
        if self._sigma is not None:
            return self._sigma
        return self.problem.sigma_measured if self.weighted else np.ones(self.problem.size)

    def rolling_thresholds(self) -> np.ndarray:
        """No closed-form threshold: the profile's grid alone."""
        return np.full(self.problem.size, np.inf)



#: the held stiffness's standardised error z = (k / k_given - 1) / u over which
#: :class:`_StiffnessProfile` profiles it: a prior penalty of 16 at the ends, four times the 95 %
#: threshold of the profile (3.84)
STIFFNESS_PRIOR_RANGE = 4.0


#: most parabolic steps of :meth:`_StiffnessProfile.stiffness_z` after its three starting points
_STIFFNESS_STEPS = 10


class _StiffnessProfile:
    """The deviance of mu with the held tangential stiffness profiled out under a Gaussian prior.

    The stiffness is k = (1 + u z) k_given with z standard normal a priori; at each trial mu the
    deviance is minimised over z of the data's deviance at (mu, z) plus ``weight`` z^2 (the prior's
    -2 log density; ``weight`` is 1 with stated uncertainties, else the reduced chi-square of the
    fit at the given stiffness, which the profile is divided by), z within
    +-:data:`STIFFNESS_PRIOR_RANGE` and k above a tenth of k_given. The interval of mu from this
    profile is the profile-likelihood interval of mu with the stiffness a nuisance parameter
    (Pawitan 2001, Sec. 3.4): where the data say nothing about the stiffness the prior alone bounds
    it, where they do (sticking contacts at small incidence) they narrow it, and a change of
    e_t(mu)'s valley with the stiffness is followed, not linearised.

    The minimum over z: the penalised deviance at z = -2, 0, 2, then successive parabolic
    interpolation, each step at the vertex of the parabola through the best point so far and its
    two neighbours (clipped to the range), until a vertex falls within 1e-3 of a point already
    solved (or after :data:`_STIFFNESS_STEPS` steps); the least value found. Rebounds at small
    incidence can pin the stiffness tightly (the deviance rises by hundreds over 2 z), so a single
    parabola is not enough. The effective variance is that of the given stiffness (held)."""

    def __init__(self, held: _DemFrictionObjective, contact_of, uncertainty: float, weight: float = 1.0):
        self.held, self.problem, self.weighted, self.rtol = held, held.problem, held.weighted, held.rtol
        self.advance = held.advance
        self.uncertainty, self.weight = float(uncertainty), float(weight)
        self._contact_of = contact_of
        self.field = _stiffness_field(held.contacts[float(self.problem.radius[0])].tangential_model)
        self.z_range = (max(-STIFFNESS_PRIOR_RANGE, -0.9 / self.uncertainty), STIFFNESS_PRIOR_RANGE)
        self._at = {0.0: held}
        self._best = {}

    @property
    def nfev(self) -> int:
        return sum(o.nfev for o in self._at.values())

    def at(self, z: float) -> _DemFrictionObjective:
        """The objective with the stiffness at (1 + u z) times the given one."""
        z = float(z)
        if z not in self._at:
            moved = _DemFrictionObjective(
                self.problem, _scaled_stiffness(self._contact_of, self.field, 1.0 + self.uncertainty * z),
                self.weighted, self.rtol, self.advance)
            moved._sigma = self.held._sigma
            self._at[z] = moved
        return self._at[z]

    def penalised(self, f, z) -> float:
        """The data's deviance at (mu, z) plus the prior's ``weight`` z^2. [-]"""
        return self.at(z).deviance(f) + self.weight * float(z) ** 2

    def stiffness_z(self, f) -> float:
        """z of the least penalised deviance at mu = f (see the class)."""
        f = float(f)
        if f not in self._best:
            lo, hi = self.z_range
            tried = {z: self.penalised(f, z) for z in (max(lo, -2.0), 0.0, min(hi, 2.0))}
            for _ in range(_STIFFNESS_STEPS):
                zs = sorted(tried)
                k = int(np.argmin([tried[z] for z in zs]))
                k = min(max(k, 1), len(zs) - 2)
                vertex = _parabola_vertex(zs[k - 1:k + 2], [tried[z] for z in zs[k - 1:k + 2]], lo, hi)
                if min(abs(vertex - z) for z in zs) < 1e-3:
                    break
                tried[vertex] = self.penalised(f, vertex)
            self._best[f] = min(tried, key=tried.get)
        return self._best[f]

    def deviance(self, f) -> float:
        """The profiled deviance at mu = f. [-]"""
        return self.penalised(f, self.stiffness_z(f))

    def model(self, f, state="nominal") -> np.ndarray:
        return self.at(self.stiffness_z(f)).model(f, state)

    def sigma(self, f) -> np.ndarray:
        return self.held.sigma(f)

    def residual(self, f, sigma=None) -> np.ndarray:
        """The data's residuals at (mu, z(mu)) and the prior's, sqrt(weight) z. [-]"""
        z = self.stiffness_z(f)
        return np.append(self.at(z).residual(f, sigma), math.sqrt(self.weight) * z)

    def chi2(self, f) -> float:
        """The data's chi-square at (mu, z(mu)) (the prior's term left out). [-]"""
        r = self.at(self.stiffness_z(f)).residual(f)
        return float(r @ r)

    def rolling_thresholds(self) -> np.ndarray:
        return self.held.rolling_thresholds()


def _parabola_vertex(x, y, lo, hi) -> float:
    """The abscissa of the least value of the parabola through three points, within [lo, hi] (an
    end where it opens downwards or is flat: the end on the side of the lower outer point)."""
    (x0, x1, x2), (y0, y1, y2) = x, y
    den = (x0 - x1) * (x0 - x2) * (x1 - x2)
    a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den
    if not a > 0:
        return float(lo if y0 <= y2 else hi)
    b = (x2 ** 2 * (y0 - y1) + x1 ** 2 * (y2 - y0) + x0 ** 2 * (y1 - y2)) / den
    return float(min(max(-b / (2 * a), lo), hi))


#: the tangential laws and the normal laws :func:`dem_friction_coverage` draws from
_COVERAGE_TANGENTIAL = ("linear_history", "lammps_mindlin", "lammps_mindlin_rescale", "lammps_mindlin_force",
                        "lammps_mindlin_rescale_force")
_COVERAGE_NORMAL = (("hertz", "coeff_restitution"), ("hertz", "viscoelastic"), ("jkr_force", "viscoelastic"),
                    ("dmt", "mass_velocity"))


def dem_friction_coverage(trials: int = 60, seed: int = 11, propagate: bool = True, fit_adhesion: bool = False,
                          stiffness_uncertainty: float = 0.0, rtol: float = DEFAULT_RTOL):
    """Coverage of the 95 % interval of mu of a LAMMPS tangential law fitted after its normal law,
    both from the same noisy data, over random experiment designs.

    Each trial draws a tangential law (any of LAMMPS's five, a random k_t 10^0.5-10^3 N/m or G*
    10^8-10^8.8 Pa), a normal law (Hertz + ``coeff_restitution`` with e uniform 0.3-0.95; Hertz or
    JKR + ``viscoelastic``, DMT + ``mass_velocity``, with eta_n0 log-uniform 0.01-0.2 critical
    dampings at 1 m/s and w_A log-uniform 1e-3-3e-2 J/m^2), mu log-uniform 0.05-1 and a design of
    4-13 impacts of a 1 um sphere (2000 kg/m^3, 1 GPa) at 0.1-10 m/s over a random angle range in
    0-85 deg, with stated Gaussian noise 0.005-0.05 on e_n and on e_t. Captures are left out (a
    design with fewer than three rebounds is skipped); the normal law is fitted by
    :func:`fit_dem_law`, then mu by :func:`fit_dem_friction` at the
    fitted normal law, its uncertainty propagated or not.

    Parameters
    ----------
    trials : int
        Designs drawn.
    seed : int
        Seed of the generator (the same seed draws the same designs with and without ``propagate``).
    propagate : bool
        Pass the normal fit as ``normal_fit`` (its uncertainty in mu's interval).
    fit_adhesion : bool
        Draw the adhesive normal laws only (JKR, DMT) and fit the work of adhesion with the damping
        (two normal parameters propagated).
    stiffness_uncertainty : float
        > 0: the fit of mu is given the true tangential stiffness times (1 + u z), z standard normal
        (from a generator of its own, so the designs are those of the same seed without it), and
        ``stiffness_uncertainty=u``. 0: the true stiffness. [-]
    rtol : float
        Solver tolerance. [-]

    Returns
    -------
    pandas.DataFrame
        One row per design fitted: normal and tangential law, true and fitted damping coefficient
        (and work of adhesion), the normal fit's status, true mu, n, the noises, mu's status, value
        and interval, and ``covered`` (designs whose normal fit is not determined: no mu); with
        ``stiffness_uncertainty``, ``stiffness_given``: the given stiffness over the true one.

    References
    ----------
    LAMMPS documentation, ``pair_style granular``, https://docs.lammps.org/pair_granular.html.

    Examples
    --------
    One design (a Hertz law with LAMMPS's ``mindlin_rescale/force``), whose rebounds bound mu from
    below only; the bound holds the true mu:

    >>> d = dem_friction_coverage(trials=1, seed=3, rtol=1e-6)
    >>> d[["normal_law", "tangential_model", "status", "covered"]].values.tolist()
    [['hertz+coeff_restitution', 'lammps_mindlin_rescale_force', 'lower_bound', True]]
    """
    rng = np.random.default_rng(seed)
    errors = np.random.default_rng([seed, 1])  # the stiffness errors: the designs stay those of the seed
    rows = []
    normal_laws = _COVERAGE_NORMAL[2:] if fit_adhesion else _COVERAGE_NORMAL
    for _ in range(trials):
        law, normal, damping, mat, coef, mu, stiffness, speeds, angles, noise_n, noise_t = _coverage_design(
            rng, normal_laws)
        tangential = {"friction": mu, "tangential_model": law, **stiffness}
        truth = dem_law_contact(mat, 1e-6, normal, damping, coef).with_(**tangential)
        table = _measured_rebounds(truth, speeds, angles, noise_n, noise_t, rng, rtol)
        if len(table) < 3:
            continue
        n = len(table)
        normal_fit = fit_dem_law(table, mat, normal, damping, fit_adhesion=fit_adhesion, rtol=rtol)
        row = {"normal_law": f"{normal}+{damping}", "tangential_model": law, "coefficient": coef,
               "coefficient_fitted": normal_fit.best, "normal_status": normal_fit.status, "mu": mu, "n": n,
               "noise_e_n": noise_n, "noise_e_t": noise_t}
        if fit_adhesion:
            row |= {"work_of_adhesion": mat["work_of_adhesion"], "work_of_adhesion_fitted": normal_fit.material["work_of_adhesion"],
                    "adhesion_status": normal_fit.adhesion_status}
        if stiffness_uncertainty > 0:
            given = 1.0 + stiffness_uncertainty * float(errors.standard_normal())
            (name, value), = stiffness.items()
            tangential = tangential | {name: given * value}
            row["stiffness_given"] = given
        if normal_fit.determined:
            fit = fit_dem_friction(table, lambda r, f=normal_fit, t=tangential: f.contact(r).with_(**t),
                                   normal_fit=normal_fit if propagate else None,
                                   stiffness_uncertainty=stiffness_uncertainty or None, rtol=rtol)
            st = fit.identifiability["friction"]
            row |= {"status": st.status, "value": fit.friction, "lower": st.lower, "upper": st.upper,
                    "covered": bool(st.lower <= mu <= st.upper)}
        rows.append(row)
    return pd.DataFrame(rows)



def _coverage_design(rng, normal_laws) -> tuple:
    """One random design of :func:`dem_friction_coverage`, drawn from ``rng``: (tangential law,
    normal law, damping law, material, damping coefficient, mu, {stiffness field: value}, speeds
    [m/s], angles [deg], e_n noise, e_t noise), the normal and damping laws from ``normal_laws``."""
    law = str(rng.choice(_COVERAGE_TANGENTIAL))
    normal, damping = normal_laws[int(rng.integers(0, len(normal_laws)))]
    mat = {"density": 2000.0, "stiffness": 1e9,
           "work_of_adhesion": 0.0 if normal == "hertz" else float(10 ** rng.uniform(-3, -1.5))}
    if damping in RESTITUTION_DAMPING_MODELS:
        coef = float(rng.uniform(0.3, 0.95))
    else:
        unit = critical_damping_coefficient(dem_law_contact(mat, 1e-6, normal, damping, 1.0), 1.0)
        coef = float(10 ** rng.uniform(-2, -0.7)) * unit
    mu = float(10 ** rng.uniform(-1.3, 0))
    stiffness = ({"tangential_stiffness": float(10 ** rng.uniform(0.5, 3))} if law == "linear_history"
                 else {"shear_modulus": float(1e9 * 10 ** rng.uniform(-1, -0.2))})
    n = int(rng.integers(4, 14))
    lo = rng.uniform(0, 70)
    hi = min(lo + rng.uniform(5, 60), 85)
    angles, speeds = rng.uniform(lo, hi, n), 10 ** rng.uniform(-1, 1, n)
    noise_t, noise_n = float(10 ** rng.uniform(-2.3, -1.3)), float(10 ** rng.uniform(-2.3, -1.3))
    return law, normal, damping, mat, coef, mu, stiffness, speeds, angles, noise_n, noise_t

def _measured_rebounds(truth, speeds, angles, noise_n, noise_t, rng, rtol):
    """The rebounds of ``truth`` as an impact table with Gaussian noise of the stated sigma on e_n
    and e_t (captures left out: nothing rebounds to be measured)."""
    results = [simulate_impact(truth, v, a, rtol=rtol) for v, a in zip(speeds, angles)]
    keep = np.array([r.outcome == "rebound" for r in results])
    results = [r for r, k in zip(results, keep) if k]
    speeds, angles, n = speeds[keep], angles[keep], int(keep.sum())
    vn = speeds * np.cos(np.radians(angles))
    e_n = np.array([abs(r.velocity_out[0]) for r in results]) / vn
    e_t = np.array([r.velocity_out[1] for r in results]) / (speeds * np.sin(np.radians(angles)))
    if n < 3:  # no noise drawn: the caller skips the design (as the study always has)
        return pd.DataFrame({"speed": speeds})
    return pd.DataFrame({"radius": truth.radius, "speed": speeds, "incidence_deg": angles, "normal_speed": vn,
                         "e_n": e_n + rng.normal(0, noise_n, n), "e_n_uncertainty": noise_n,
                         "tangential_restitution": e_t + rng.normal(0, noise_t, n),
                         "tangential_restitution_uncertainty": noise_t})
