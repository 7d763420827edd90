"""What to measure next: the impacts that most narrow the intervals of named damping parameters.

From a damping fit (:class:`~microimpact.analysis.fit_result.DampingFit`, the ``fit.nc`` of
``microimpact fit --out``) or from prior ranges with a material, and the space a laboratory can
measure (a speed range, incidence angles, size classes, the noise of e_n), :func:`design_impacts`
picks the next N impacts one at a time (greedy sequential design over a candidate grid).

Criterion: Fisher information (linearised, nearly linear problem)
-----------------------------------------------------------------
The expected covariance of the parameters theta after adding impacts c_1 ... c_k is the inverse of
the Fisher information

    M = M_0 + sum_k g(c_k) g(c_k)^T / sigma_eff(c_k)^2,    g(c) = d e_n(c) / d theta,

with M_0 the information of the data already fitted (at the fit's estimate) or of the prior, and
sigma_eff^2 = sigma_e^2 + (d e_n / d v_n)^2 sigma_vn^2 the effective variance of the fit (Orear
1982). This is the linearised (Gauss-Newton) covariance: it is the expected posterior covariance
only where e_n is nearly linear in theta over the interval, which the profile intervals of the fit
may contradict near capture; the output says so (``criterion``). Each step adds the candidate that
most reduces the A-criterion (sum of the named parameters' relative variances) or the D-criterion
(log-determinant of their block of the covariance); the expected 95 % interval width of a
parameter is 2 z_0.975 sqrt(C_jj).

The sensitivities g are central differences of the solver's e_n (:func:`model_restitution`) with
relative step h = rtol^(1/3): the truncation error of a central difference is O(h^2), the solver's
error O(rtol / h), and h = rtol^(1/3) balances them (Press et al. 2007, Numerical Recipes 3rd ed.,
section 5.7).

Identifiability first
---------------------
A parameter that the current data do not determine (the fit's
:mod:`~microimpact.analysis.identifiability` status) gets a sentence saying where e_n responds to
it. A candidate whose e_n does not respond to a named parameter (sensitivity below
:data:`SENSITIVITY_FLOOR` of the largest over the grid, e.g. every captured impact, where e_n = 0
whatever the damping) is never recommended. Friction: e_n does not depend on it (the normal motion
is decoupled from the tangential, Cheng, Brach & Dunn 2002, Eqs. (16)-(20)); the output names the
impacts of the grid that slide throughout the contact (f < f* = 2 m |u_0| / (7 J), J the friction
impulse of the normal solve), where a rebound angle or tangential restitution measures f.

References
----------
* Fedorov, V. V. (1972). Theory of Optimal Experiments. Academic Press (A- and D-optimal designs).
* Atkinson, A. C., Donev, A. N. & Tobias, R. D. (2007). Optimum Experimental Designs, with SAS.
  Oxford University Press, ch. 10-11 (sequential construction, D_s-optimality).
* Orear, J. (1982). Least squares when both variables have uncertainties. Am. J. Phys. 50, 912.
  doi:10.1119/1.12972
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy import stats

from microimpact.analysis.design_defaults import (DEFAULT_E_T_SIGMA, DEFAULT_NEW_IMPACTS, DEFAULT_NEW_OBLIQUE,
                                                  DEFAULT_OBLIQUE_QUANTITY, DEFAULT_PARAMETERS, DEFAULT_REBOUND_ANGLE_SIGMA,
                                                  DEFAULT_REBOUND_SPIN_SIGMA, OBLIQUE_QUANTITIES)
from microimpact.analysis.fit_result import PARAMETER_NAMES
from microimpact.analysis.fitting import FitProblem, model_restitution
from microimpact.analysis.oblique import _observables, normal_impulses, rebound_from_impulses
from microimpact.io.materials import material_contact
from microimpact.io.statuses import DEFAULT_LEVEL
from microimpact.solvers import DEFAULT_RTOL

__all__ = ["DesignSpace", "ExperimentDesign", "design_impacts", "fisher_widths", "uniform_design",
           "restitution_sensitivities", "design_template", "DESIGN_CRITERIA", "SENSITIVITY_FLOOR",
           "TEMPLATE_COLUMNS", "MAX_NEW_IMPACTS", "MAX_CANDIDATE_SPEEDS", "design_friction", "uniform_oblique_design", "design_record", "design_next_impacts",
           "fit_design_space",
           "tangential_sensitivities", "FRICTION_RANGE", "OBLIQUE_ANGLES_DEG"]

#: the design criteria of :func:`design_impacts`
DESIGN_CRITERIA = ("A", "D")
#: a candidate whose |d e_n / d ln theta| / sigma is below this fraction of the largest over the grid
#: has "no effect" on theta and is never recommended for it (captured impacts have exactly 0)
SENSITIVITY_FLOOR = 1e-2
#: most new impacts of one design (a measurement campaign, not a simulation study)
MAX_NEW_IMPACTS = 1000
#: most candidate speeds of a design space (the greedy step costs candidates x parameters^3)
MAX_CANDIDATE_SPEEDS = 2000
#: prior standard deviation, relative to the estimate, of a parameter the data leave free: a weak
#: regulariser that keeps the information matrix invertible (its widths then say "not determined")
WEAK_PRIOR_RELATIVE_SD = 10.0
#: columns of the CSV template (the measured-impact format, data/README.md) with the tangential
#: restitution as the oblique quantity; e_n, the oblique quantity and e_n's uncertainty are left
#: empty or stated for the laboratory to fill in (:func:`design_template`)
TEMPLATE_COLUMNS = ("id", "radius [um]", "speed [m/s]", "incidence_angle [deg]", "e_n [1]", "e_n_uncertainty [1]",
                    "tangential_restitution [1]", "tangential_restitution_uncertainty [1]", "reason")
#: Coulomb coefficients a friction design must determine when nothing else is known: the prior range
#: the design averages its criterion over (log-uniform). [-]
FRICTION_RANGE = (0.05, 1.0)
#: incidence angles of a friction design when the design space gives none but normal incidence:
#: an impact slides throughout only for f < f* ~ 2 tan(alpha) / (7 (1 + e_n)), so f up to 1
#: needs alpha near 80 deg (Cheng, Brach & Dunn 2002, Eqs. (16)-(20)). [deg]
OBLIQUE_ANGLES_DEG = (20.0, 30.0, 40.0, 50.0, 60.0, 65.0, 70.0, 75.0, 80.0, 85.0)
#: log-spaced friction values the friction design averages its criterion over
FRICTION_GRID_POINTS = 25


@dataclass(frozen=True)
class DesignSpace:
    """What the laboratory can measure.

    Attributes
    ----------
    radii : tuple of float
        Size classes (sphere radii). [m]
    speed_range : (float, float)
        Incident speeds that can be set. [m/s]
    incidence_deg : tuple of float
        Incidence angles from the normal that can be set. [deg]
    e_n_sigma : float
        Standard uncertainty of a measured e_n. [-]
    speed_sigma : float
        Relative standard uncertainty of the incident speed (0: none). [-] The default, 1 %, is
        that of the bundled synthetic data; it matters near capture, where e_n rises steeply with
        v_n and a point would otherwise look far more informative than a measurement there is.
    n_speeds : int
        Log-spaced candidate speeds over ``speed_range``.
    e_t_sigma : float
        Standard uncertainty of a measured tangential restitution e_t = v_t,out / v_t,in (the
        friction design). [-]
    oblique_quantity : str
        What is measured of an oblique impact besides e_n, a key of
        :data:`~microimpact.analysis.design_defaults.OBLIQUE_QUANTITIES`:
        ``tangential_restitution`` (uncertainty ``e_t_sigma``), ``rebound_angle`` (from the normal,
        ``rebound_angle_sigma``), ``rebound_spin`` (|omega| after the impact, ``rebound_spin_sigma``)
        or ``none`` (e_n only: friction cannot be designed for).
    rebound_angle_sigma : float
        Standard uncertainty of a measured rebound angle. [deg]
    rebound_spin_sigma : float
        Standard uncertainty of a measured rebound spin. [rad/s]

    Examples
    --------
    >>> DesignSpace(radii=(3.45e-6,), speed_range=(0.5, 20.0)).candidates().shape
    (60, 4)
    """

    radii: tuple
    speed_range: tuple = (0.5, 20.0)
    incidence_deg: tuple = (0.0,)
    e_n_sigma: float = 0.02
    speed_sigma: float = 0.01
    n_speeds: int = 60
    e_t_sigma: float = DEFAULT_E_T_SIGMA
    oblique_quantity: str = DEFAULT_OBLIQUE_QUANTITY
    rebound_angle_sigma: float = DEFAULT_REBOUND_ANGLE_SIGMA
    rebound_spin_sigma: float = DEFAULT_REBOUND_SPIN_SIGMA

    def __post_init__(self):
        lo, hi = (float(x) for x in self.speed_range)
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
            raise ValueError(f"speed_range must be two speeds 0 < min < max [m/s], got {self.speed_range!r}")
        if not self.radii or not all(math.isfinite(r) and r > 0 for r in self.radii):
            raise ValueError(f"radii must be one or more finite radii > 0 [m], got {self.radii!r}")
        if not self.incidence_deg or not all(0 <= a < 90 for a in self.incidence_deg):
            raise ValueError(f"incidence angles must lie in [0, 90) deg, got {self.incidence_deg!r}")
        if not (math.isfinite(self.e_n_sigma) and self.e_n_sigma > 0):
            raise ValueError(f"e_n_sigma must be a finite standard uncertainty > 0, got {self.e_n_sigma!r}")
        if not (math.isfinite(self.speed_sigma) and 0 <= self.speed_sigma < 0.5):
            raise ValueError(f"speed_sigma must be a relative uncertainty in [0, 0.5), got {self.speed_sigma!r}")
        if not (math.isfinite(self.e_t_sigma) and self.e_t_sigma > 0):
            raise ValueError(f"e_t_sigma must be a finite standard uncertainty > 0, got {self.e_t_sigma!r}")
        if not 2 <= int(self.n_speeds) <= MAX_CANDIDATE_SPEEDS:
            raise ValueError(f"n_speeds must be in [2, {MAX_CANDIDATE_SPEEDS}], got {self.n_speeds!r}")
        if self.oblique_quantity not in OBLIQUE_QUANTITIES:
            raise ValueError(f"oblique_quantity must be one of {', '.join(OBLIQUE_QUANTITIES)}, got "
                             f"{self.oblique_quantity!r}")
        for name in ("rebound_angle_sigma", "rebound_spin_sigma"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite standard uncertainty > 0, got {value!r}")

    @property
    def oblique_sigma(self) -> float:
        """Standard uncertainty of the measured oblique quantity, in its unit
        (:data:`~microimpact.analysis.design_defaults.OBLIQUE_QUANTITIES`);
        NaN for ``none``."""
        return {"tangential_restitution": self.e_t_sigma, "rebound_angle": self.rebound_angle_sigma,
                "rebound_spin": self.rebound_spin_sigma}.get(self.oblique_quantity, math.nan)

    def candidates(self) -> pd.DataFrame:
        """The candidate grid: radius [m], speed [m/s], incidence_deg [deg], normal_speed [m/s]."""
        speeds = np.geomspace(self.speed_range[0], self.speed_range[1], int(self.n_speeds))
        r, v, a = (x.ravel() for x in np.meshgrid(np.asarray(self.radii, float), speeds,
                                                  np.asarray(self.incidence_deg, float), indexing="ij"))
        return pd.DataFrame({"radius": r, "speed": v, "incidence_deg": a, "normal_speed": v * np.cos(np.radians(a))})


@dataclass(frozen=True)
class ExperimentDesign:
    """Result of :func:`design_impacts`.

    Attributes
    ----------
    rows : pandas.DataFrame
        The recommended impacts in the order chosen: ``id``, ``radius`` [m], ``speed`` [m/s],
        ``incidence_deg`` [deg], ``normal_speed`` [m/s], ``e_n_expected`` [-], ``reason`` (one line).
    widths : pandas.DataFrame
        Expected 95 % interval width of each named parameter after 0 ... N new impacts, for the
        recommended design (``design``) and for N impacts spread uniformly over the same space
        (``uniform``): columns ``n_new``, ``parameter``, ``design``, ``uniform`` [unit of the parameter].
    parameters : tuple of str
        The parameters the design narrows.
    values : dict
        The parameter values the sensitivities are taken at: the fit's estimates, or, for a parameter
        the data do not determine, a point inside what they allow (:func:`_reference_value`); the
        prior's geometric centres. [-], [-], [J/m^2]
    criterion : str
        What was optimised, in words (Fisher information, linearised).
    notes : dict
        ``{parameter: sentence}``: identifiability of each named parameter (and friction) and what
        would determine it.
    """

    rows: pd.DataFrame
    widths: pd.DataFrame
    parameters: tuple
    values: dict
    criterion: str
    notes: dict = field(default_factory=dict)

    def width(self, parameter: str, n_new: int | None = None, which: str = "design") -> float:
        """Expected 95 % width of ``parameter`` after ``n_new`` (default all) new impacts."""
        w = self.widths[self.widths["parameter"] == parameter]
        n = int(w["n_new"].max()) if n_new is None else n_new
        return float(w.loc[w["n_new"] == n, which].iloc[0])

    def summary(self) -> str:
        """Lines for a terminal: the criterion, the notes, the widths before and after."""
        lines = [f"criterion: {self.criterion}"]
        lines += [f"{k}: {v}" for k, v in self.notes.items()]
        for p in self.parameters:
            n = int(self.widths.loc[self.widths["parameter"] == p, "n_new"].max())
            lines.append(f"{p}: expected 95 % width {self.width(p, 0):.4g} now, {self.width(p):.4g} after "
                         f"{n} recommended impacts ({self.width(p, which='uniform'):.4g} if uniform)")
        return "\n".join(lines)


def restitution_sensitivities(material, radius, normal_speed, values: dict, parameters, *, rtol=DEFAULT_RTOL):
    """e_n and its derivatives by the relative parameters and by the normal speed.

    Parameters
    ----------
    material : MaterialPair, Contact or DampingFit
    radius, normal_speed : array_like
        Of each impact. [m], [m/s]
    values : dict
        ``zeta_hertz`` [-], ``zeta_adhesion`` [-], ``work_of_adhesion`` [J/m^2].
    parameters : sequence of str
        Names among :data:`PARAMETER_NAMES` to differentiate by.
    rtol : float
        Relative tolerance of the normal solves; the relative step is rtol^(1/3). [-]

    Returns
    -------
    (e_n, gradient, slope)
        e_n [-]; gradient[i, j] = d e_n,i / d ln theta_j (a change of e_n per 100 % change of
        theta_j) [-]; slope = d e_n / d v_n [s/m].

    Examples
    --------
    A captured impact (1 m/s at 2 um, Table 1) does not respond to the damping:

    >>> from microimpact.io import default_materials_path, read_materials
    >>> m = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> vals = {"zeta_hertz": 0.5, "zeta_adhesion": 29.0, "work_of_adhesion": 0.215834}
    >>> e, g, s = restitution_sensitivities(m, [2e-6, 2e-6], [1.0, 10.0], vals, ("zeta_hertz",))
    >>> float(e[0]), float(g[0, 0]), bool(g[1, 0] < 0)
    (0.0, 0.0, True)
    """
    problem = FitProblem.from_arrays(radius, normal_speed, material)
    h = float(rtol) ** (1.0 / 3.0)
    base = {k: float(values[k]) for k in PARAMETER_NAMES}

    def e_at(**changes):
        p = {**base, **changes}
        return model_restitution(problem, p["zeta_hertz"], p["zeta_adhesion"], p["work_of_adhesion"], rtol=rtol)

    e = e_at()
    grad = np.empty((e.size, len(parameters)))
    for j, name in enumerate(parameters):
        x = base[name]
        step = h * x if x > 0 else h
        up, dn = e_at(**{name: x + step}), e_at(**{name: max(x - step, 0.0)})
        grad[:, j] = (up - dn) / ((x + step) - max(x - step, 0.0)) * (x if x > 0 else 1.0)
    up = model_restitution(problem, base["zeta_hertz"], base["zeta_adhesion"], base["work_of_adhesion"], rtol=rtol,
                           speed_factor=1 + h)
    dn = model_restitution(problem, base["zeta_hertz"], base["zeta_adhesion"], base["work_of_adhesion"], rtol=rtol,
                           speed_factor=1 - h)
    slope = (up - dn) / (2 * h * problem.normal_speed)
    return e, grad, slope


def fisher_widths(information, values: dict, parameters, level: float = DEFAULT_LEVEL) -> dict:
    """Expected ``level`` interval widths 2 z sqrt(C_jj) theta_j from a relative information matrix.

    Parameters
    ----------
    information : numpy.ndarray
        Fisher information of the relative parameters ln theta (inverse of their covariance). [-]
    values : dict
        theta_j, the scale of each relative parameter. [unit of each parameter]
    parameters : sequence of str
        The rows and columns of ``information``, in order.
    level : float
        Confidence level; z is the normal quantile of (1 + level) / 2. [-]

    Returns
    -------
    dict
        ``{name: width}``. [unit of each parameter]

    Examples
    --------
    Information 100 in ln theta is a relative standard error of 0.1: at theta = 0.5 the 95 % width
    is 2 x 1.96 x 0.05:

    >>> round(fisher_widths(np.diag([100.0]), {"zeta_hertz": 0.5}, ("zeta_hertz",))["zeta_hertz"], 4)
    0.196
    """
    cov = np.linalg.inv(information)
    z = float(stats.norm.ppf(0.5 + level / 2))
    return {p: 2 * z * math.sqrt(max(cov[j, j], 0.0)) * abs(values[p]) for j, p in enumerate(parameters)}


def _criterion(information, named, kind):
    """The scalars to minimise, one per matrix of the stack ``information`` (k, p, p): A (sum of the
    named relative variances) or D (log det of their covariance block)."""
    cov = np.linalg.inv(information)[:, named][:, :, named]
    return np.trace(cov, axis1=1, axis2=2) if kind == "A" else np.linalg.slogdet(cov)[1]


def uniform_design(space: DesignSpace, n: int) -> pd.DataFrame:
    """``n`` impacts spread evenly: log-spaced speeds over the range, size classes and angles cycled.

    Examples
    --------
    >>> uniform_design(DesignSpace(radii=(1e-6, 2e-6)), 4)["radius"].tolist()
    [1e-06, 2e-06, 1e-06, 2e-06]
    """
    k = np.arange(n)
    speeds = np.geomspace(space.speed_range[0], space.speed_range[1], max(n, 1))[:n]
    radii = np.asarray(space.radii, float)[k % len(space.radii)]
    angles = np.asarray(space.incidence_deg, float)[(k // len(space.radii)) % len(space.incidence_deg)]
    return pd.DataFrame({"radius": radii, "speed": speeds, "incidence_deg": angles,
                         "normal_speed": speeds * np.cos(np.radians(angles))})


def uniform_oblique_design(space: DesignSpace, n: int) -> pd.DataFrame:
    """``n`` oblique impacts spread evenly: angles evenly over the space's oblique range (that of
    :data:`OBLIQUE_ANGLES_DEG` if it has none), speeds log-spaced, size classes cycled.

    Examples
    --------
    >>> uniform_oblique_design(DesignSpace(radii=(1e-6,), incidence_deg=(0.0, 20.0, 80.0)), 4)["incidence_deg"].tolist()
    [20.0, 40.0, 60.0, 80.0]
    """
    angles = tuple(a for a in space.incidence_deg if a > 0) or OBLIQUE_ANGLES_DEG
    rows = uniform_design(space, n)
    a = np.linspace(min(angles), max(angles), n) if n > 1 else np.array([max(angles)])
    return rows.assign(incidence_deg=a, normal_speed=rows["speed"] * np.cos(np.radians(a)))


def _start(source, prior, material, parameters):
    """(material, values, all parameters modelled, prior information M_0, notes) of a fit or a prior."""
    if source is not None:
        varied = tuple(n for n in PARAMETER_NAMES if n in source.varied or n in parameters)
        values = {**source.values, **{p: _reference_value(source, p) for p in varied}}
        d = source.data
        sigma = d["sigma"].to_numpy(float) if "sigma" in d.columns else np.full(len(d), np.nan)
        if not np.all(np.isfinite(sigma) & (sigma > 0)) or source.weighting == "none":
            sigma = np.full(len(d), math.sqrt(max(source.redchi, 1e-12)))  # unweighted: the scatter estimates sigma
        return source, values, varied, (d["radius"].to_numpy(float), d["normal_speed"].to_numpy(float), sigma)
    if material is None or not prior:
        raise ValueError("give a fit, or prior ranges with a material")
    values = {"zeta_hertz": math.nan, "zeta_adhesion": math.nan, "work_of_adhesion": float(material.work_of_adhesion)}
    for name, (lo, hi) in prior.items():
        if name not in PARAMETER_NAMES or not (0 < lo < hi and math.isfinite(hi)):
            raise ValueError(f"prior range of {name!r}: give a parameter of {PARAMETER_NAMES} and 0 < min < max")
        values[name] = math.sqrt(lo * hi)  # the range's geometric centre
    missing = [n for n in ("zeta_hertz", "zeta_adhesion") if not math.isfinite(values[n])]
    if missing:
        raise ValueError(f"the prior needs a range for {', '.join(missing)}")
    varied = tuple(n for n in PARAMETER_NAMES if n in prior or n in parameters)
    return material, values, varied, None


def _reference_value(fit, name) -> float:
    """Where to linearise a fitted parameter: its estimate where the data determine it, else a point
    inside what the data allow (half the upper bound, twice the lower bound): an estimate at the
    range's end (zeta_H = 0 when the data prefer no Hertz damping) has no relative scale, and its
    widths would say nothing."""
    value = float(fit.values[name])
    st = fit.identifiability.get(name)
    if st is None or st.determined:
        if not value > 0:
            raise ValueError(f"the fit's {name} is {value!r}: the relative sensitivities need a value > 0")
        return value
    if st.status == "upper_bound" and st.upper > 0 and math.isfinite(st.upper):
        return 0.5 * float(st.upper)
    if st.status == "lower_bound" and st.lower > 0 and math.isfinite(st.lower):
        return 2.0 * float(st.lower)
    return value if value > 0 else 1.0


def _posterior_information(posterior, values, varied):
    """(values at the posterior medians, information = inverse sample covariance of ln theta) for the
    parameters ``varied``; a parameter the posterior did not sample gets the weak prior."""
    names = [p for p in varied if p in posterior.names]
    if not names:
        raise ValueError(f"the posterior samples none of {list(varied)!r}")
    x = posterior.samples[:, [posterior.names.index(p) for p in names]]
    if not np.all(x > 0):
        raise ValueError("the posterior has samples <= 0 of " + ", ".join(names) + ": the relative (ln) design "
                         "needs positive values")
    med = posterior.median()
    values = {**values, **{p: float(med[p]) for p in names}}
    cov = np.atleast_2d(np.cov(np.log(x), rowvar=False))
    info = np.diag(np.full(len(varied), 1.0 / WEAK_PRIOR_RELATIVE_SD ** 2))
    idx = [varied.index(p) for p in names]
    info[np.ix_(idx, idx)] = np.linalg.inv(cov)
    return values, info


def _prior_information(varied, prior, values, z):
    """Information of the prior: a range [lo, hi] is a +/- z interval in ln theta; a weak prior elsewhere."""
    sd = []
    for p in varied:
        if prior and p in prior:
            lo, hi = prior[p]
            sd.append(math.log(hi / lo) / (2 * z))
        else:
            sd.append(WEAK_PRIOR_RELATIVE_SD)
    return np.diag(1.0 / np.square(sd))


def design_impacts(fit=None, space: DesignSpace | None = None, n: int = DEFAULT_NEW_IMPACTS, *,
                   parameters=DEFAULT_PARAMETERS, prior: dict | None = None, material=None, criterion: str = "A",
                   rtol: float = DEFAULT_RTOL, friction_range: tuple = FRICTION_RANGE, posterior=None) -> ExperimentDesign:
    """The next ``n`` impacts that most reduce the expected 95 % intervals of ``parameters``.

    Parameters
    ----------
    fit : DampingFit, optional
        The current fit (:meth:`DampingFit.load` of a ``fit.nc``); its data's information is M_0.
    space : DesignSpace
        What can be measured.
    n : int
        Number of new impacts.
    parameters : sequence of str
        The parameters to narrow, among :data:`PARAMETER_NAMES`; ``"friction"`` gets a note only
        (e_n does not depend on it).
    prior : dict, optional
        ``{name: (min, max)}`` without a fit: each range is read as a 95 % interval of ln theta.
    material : MaterialPair, optional
        The material, without a fit (density, stiffness, w_A).
    criterion : {"A", "D"}
        A-optimal (sum of relative variances) or D_s-optimal (log det of their covariance block).
    rtol : float
        Relative tolerance of the normal solves (and of the finite-difference step). [-]
    friction_range : (float, float)
        Coulomb coefficients for the friction note. [-]
    posterior : Posterior, optional
        An MCMC sample of the fit's parameters (``microimpact fit --posterior``): M_0 is then the
        inverse of its sample covariance of ln theta (the data's information, without the
        linearisation of the fit) and the sensitivities are taken at its medians.

    Returns
    -------
    ExperimentDesign

    Examples
    --------
    From a prior on the damping of Table 1's material, 4 impacts that narrow zeta_H: none is captured:

    >>> from microimpact.io import default_materials_path, read_materials
    >>> m = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> space = DesignSpace(radii=(3.45e-6,), speed_range=(0.5, 20.0), n_speeds=20)
    >>> d = design_impacts(None, space, 4, prior={"zeta_hertz": (0.1, 2.0), "zeta_adhesion": (10.0, 80.0)},
    ...                    material=m)
    >>> bool((d.rows["e_n_expected"] > 0).all()), d.width("zeta_hertz") < d.width("zeta_hertz", which="uniform")
    (True, True)
    """
    if space is None:
        raise ValueError("give the design space (DesignSpace)")
    if criterion not in DESIGN_CRITERIA:
        raise ValueError(f"criterion must be one of {DESIGN_CRITERIA}, got {criterion!r}")
    if not 1 <= int(n) <= MAX_NEW_IMPACTS:
        raise ValueError(f"the number of new impacts must be in [1, {MAX_NEW_IMPACTS}], got {n!r}")
    wanted = tuple(parameters)
    unknown = [p for p in wanted if p not in PARAMETER_NAMES + ("friction",)]
    if unknown or not wanted:
        raise ValueError(f"parameters must be among {PARAMETER_NAMES + ('friction',)}, got {list(wanted)!r}")
    damping = tuple(p for p in wanted if p != "friction")
    base, values, varied, existing = _start(fit, prior, material, damping)
    z = float(stats.norm.ppf(0.5 + DEFAULT_LEVEL / 2))
    info0 = _prior_information(varied, prior if fit is None else None, values, z)
    if posterior is not None:
        if fit is None:
            raise ValueError("a posterior needs its damping fit (the material and the data's radii)")
        values, info0 = _posterior_information(posterior, values, varied)
        existing = None  # the posterior already holds the data's information
    if existing is not None:
        _, g0, s0 = restitution_sensitivities(base, existing[0], existing[1], values, varied, rtol=rtol)
        info0 = info0 + (g0 / existing[2][:, None]).T @ (g0 / existing[2][:, None])
    cand = space.candidates()
    e, g, slope = restitution_sensitivities(base, cand["radius"], cand["normal_speed"], values, varied, rtol=rtol)
    sigma = np.sqrt(space.e_n_sigma ** 2 + (slope * space.speed_sigma * cand["normal_speed"].to_numpy()) ** 2)
    notes = _notes(fit, damping, varied, g, sigma, cand, space)
    if "friction" in wanted:
        notes["friction"] = _friction_note(base, values, cand, friction_range, rtol) + (
            "; this design space measures e_n only, so no impact of it determines friction" if
            space.oblique_quantity == "none" else "")
    if not damping:
        empty = pd.DataFrame(columns=["n_new", "parameter", "design", "uniform"])
        return ExperimentDesign(_rows(cand.iloc[[]], e[:0], []), empty, wanted, values, _CRITERION_TEXT[criterion], notes)
    named = [varied.index(p) for p in damping]
    chosen, reasons, info_path = _greedy(info0, g / sigma[:, None], named, _admissible(g, sigma, named), n, criterion,
                                         cand, e, varied, values)
    uni = uniform_design(space, int(n))
    _, gu, su = restitution_sensitivities(base, uni["radius"], uni["normal_speed"], values, varied, rtol=rtol)
    su = np.sqrt(space.e_n_sigma ** 2 + (su * space.speed_sigma * uni["normal_speed"].to_numpy()) ** 2)
    widths = _width_table(info0, info_path, gu / su[:, None], values, varied, damping)
    return ExperimentDesign(_rows(cand.iloc[chosen], e[chosen], reasons), widths, damping, values,
                            _CRITERION_TEXT[criterion], notes)


_CRITERION_TEXT = {k: f"Fisher information (linearised covariance, valid where e_n is nearly linear in the parameters "
                      f"over their intervals); greedy sequential {k}-optimal selection over the candidate grid"
                   for k in DESIGN_CRITERIA}


def _admissible(g, sigma, named):
    """Candidates where e_n responds to every named parameter (above SENSITIVITY_FLOOR of the grid's largest)."""
    s = np.abs(g[:, named]) / sigma[:, None]
    top = s.max(axis=0)
    return np.all((s > SENSITIVITY_FLOOR * top) & (top > 0), axis=1)


def _greedy(info0, gw, named, admissible, n, kind, cand, e, varied, values):
    """Indices chosen one at a time, each the admissible candidate of least criterion; reasons; M after each."""
    if not admissible.any():
        raise ValueError("no candidate impact of the design space responds to the named parameters "
                         "(all captured, or below the sensitivity floor): widen the speed range or the sizes")
    info, chosen, reasons, path = info0.copy(), [], [], []
    for _ in range(int(n)):
        options = np.flatnonzero(admissible)
        scores = _criterion(info[None] + gw[options, :, None] * gw[options, None, :], named, kind)
        best = int(options[np.argmin(scores)])
        before = fisher_widths(info, values, varied)
        info = info + np.outer(gw[best], gw[best])
        after = fisher_widths(info, values, varied)
        lead = max(named, key=lambda j: abs(gw[best, j]))
        size = f"d = {2e6 * cand['radius'].iloc[best]:.3g} um, " if cand["radius"].nunique() > 1 else ""
        reasons.append(f"{size}v_n = {cand['normal_speed'].iloc[best]:.3g} m/s, e_n ~ {e[best]:.3f}: "
                       + ", ".join(f"{varied[j]} width {before[varied[j]]:.3g} -> {after[varied[j]]:.3g}" for j in named)
                       + f"; e_n moves {abs(gw[best, lead]):.2g} sigma per 100 % of {varied[lead]}")
        chosen.append(best)
        path.append(info.copy())
    return chosen, reasons, path


def _width_table(info0, path, gu, values, varied, damping):
    """Widths after 0 ... N new impacts, recommended and uniform (the first k of the uniform N)."""
    rows = []
    uni = info0.copy()
    for k in range(len(path) + 1):
        design = fisher_widths(info0 if k == 0 else path[k - 1], values, varied)
        if k > 0:
            uni = uni + np.outer(gu[k - 1], gu[k - 1])
        uniform = fisher_widths(uni, values, varied)
        rows += [{"n_new": k, "parameter": p, "design": design[p], "uniform": uniform[p]} for p in damping]
    return pd.DataFrame(rows)


def _rows(chosen, e, reasons):
    return pd.DataFrame({"id": [f"design-{k + 1:03d}" for k in range(len(chosen))],
                         "radius": chosen["radius"].to_numpy(), "speed": chosen["speed"].to_numpy(),
                         "incidence_deg": chosen["incidence_deg"].to_numpy(),
                         "normal_speed": chosen["normal_speed"].to_numpy(), "e_n_expected": np.asarray(e),
                         "reason": list(reasons)})


def _notes(fit, damping, varied, g, sigma, cand, space):
    """One sentence per named parameter: its status now and the speeds where e_n responds to it most."""
    notes = {}
    for p in damping:
        j = varied.index(p)
        s = np.abs(g[:, j]) / sigma
        where = s >= 0.5 * s.max() if s.max() > 0 else np.zeros(s.size, bool)
        st = fit.identifiability.get(p) if fit is not None else None
        now = ("not fitted" if st is None else st.describe() if st.determined else
               f"{st.status.replace('_', ' ')} by the current data ({st.reason})")
        if not where.any():
            notes[p] = f"{now}; e_n does not respond to it anywhere in the design space: widen the speed range"
            continue
        vn = cand["normal_speed"].to_numpy()[where]
        radii = sorted({float(r) for r in cand["radius"].to_numpy()[where]})
        notes[p] = (f"{now}; e_n responds to it most (>= half the largest, up to {s.max():.2g} sigma per 100 % change) "
                    f"at v_n {vn.min():.3g}-{vn.max():.3g} m/s, radius {', '.join(f'{r * 1e6:.3g} um' for r in radii)};"
                    f" no impact is recommended where it has no effect (captured: e_n = 0 whatever the damping)")
    return notes


def _friction_note(base, values, cand, friction_range, rtol):
    """Where the grid's impacts slide throughout the contact, f < f* = 2 m |u_0| / (7 J) (no incident spin)."""
    fstar = np.zeros(len(cand))
    for r in np.unique(cand["radius"]):
        idx = np.flatnonzero(cand["radius"].to_numpy() == r)
        c = material_contact(base, float(r), zeta_hertz=values["zeta_hertz"], zeta_adhesion=values["zeta_adhesion"],
                             work_of_adhesion=values["work_of_adhesion"])
        imp = normal_impulses(c, cand["speed"].to_numpy()[idx], cand["incidence_deg"].to_numpy()[idx], rtol)
        j = imp["friction_impulse"]
        with np.errstate(divide="ignore", invalid="ignore"):
            fstar[idx] = np.where(j > 0, 2.0 * c.mass * np.abs(imp["velocity_in_t"]) / (7.0 * j), 0.0)
    text = ("e_n does not depend on friction (normal motion decoupled from the tangential, Eqs. (16)-(20)): no e_n "
            "impact determines it; measure the rebound angle or tangential restitution of impacts that slide "
            "(design_friction recommends them)")
    f_ref = float(getattr(base, "friction", 0.0) or 0.0)
    f_ref = f_ref if friction_range[0] <= f_ref <= friction_range[1] else math.sqrt(friction_range[0] * friction_range[1])
    slides = fstar > f_ref
    if not slides.any():
        return text + f"; no impact of this space slides for f = {f_ref:.2g} (add larger incidence angles)"
    a, v = cand["incidence_deg"].to_numpy()[slides], cand["speed"].to_numpy()[slides]
    return text + (f": for f = {f_ref:.2g}, the impacts of this space at {a.min():.3g}-{a.max():.3g} deg and "
                   f"{v.min():.3g}-{v.max():.3g} m/s slide throughout (f < f* = 2 m |u_0| / (7 J)); the most "
                   f"slippery of them slides for f up to {min(float(fstar[slides].max()), friction_range[1]):.2g}")


def design_template(design: ExperimentDesign, space: DesignSpace) -> pd.DataFrame:
    """The recommended rows as a measured-impact CSV table, e_n and the oblique quantity left empty.

    Columns: :data:`TEMPLATE_COLUMNS`, with the oblique pair named after the space's
    ``oblique_quantity`` (``rebound_angle [deg]``, ``rebound_spin [rad/s]``; none for ``none``).
    The oblique rows (incidence > 0) state :attr:`DesignSpace.oblique_sigma` as the oblique
    quantity's uncertainty (empty at normal incidence); ``e_n_sigma`` [-] is the uncertainty of
    every row's e_n.

    Examples
    --------
    >>> rows = pd.DataFrame({"id": ["design-001"], "radius": [3.45e-6], "speed": [2.0], "incidence_deg": [0.0],
    ...                      "normal_speed": [2.0], "e_n_expected": [0.5], "reason": ["why"]})
    >>> d = ExperimentDesign(rows, pd.DataFrame(), ("zeta_hertz",), {}, "Fisher")
    >>> t = design_template(d, DesignSpace(radii=(3.45e-6,)))
    >>> list(t.columns) == list(TEMPLATE_COLUMNS), round(float(t["radius [um]"].iloc[0]), 6), t["e_n [1]"].iloc[0]
    (True, 3.45, '')
    >>> list(design_template(d, DesignSpace(radii=(3.45e-6,), oblique_quantity="rebound_angle")).columns[6:8])
    ['rebound_angle [deg]', 'rebound_angle_uncertainty [deg]']
    """
    r = design.rows
    oblique = r["incidence_deg"].to_numpy(float) > 0
    table = {TEMPLATE_COLUMNS[0]: r["id"], TEMPLATE_COLUMNS[1]: r["radius"] * 1e6,
             TEMPLATE_COLUMNS[2]: r["speed"], TEMPLATE_COLUMNS[3]: r["incidence_deg"],
             TEMPLATE_COLUMNS[4]: "", TEMPLATE_COLUMNS[5]: float(space.e_n_sigma)}
    q = space.oblique_quantity
    if q != "none":
        unit = OBLIQUE_QUANTITIES[q]
        table[f"{q} [{unit}]"] = ""
        table[f"{q}_uncertainty [{unit}]"] = np.where(oblique, f"{space.oblique_sigma:.6g}", "")
    return pd.DataFrame({**table, TEMPLATE_COLUMNS[8]: r["reason"]})


def tangential_sensitivities(contact, speed, incidence_deg, frictions, rtol=DEFAULT_RTOL,
                             quantity: str = "tangential_restitution"):
    """e_n, and an oblique quantity q (e_t by default) and d q / d ln f of impacts at several frictions.

    The normal solve does not depend on f (model-notes section 4), so each impact is solved once
    (:func:`~microimpact.analysis.oblique.normal_impulses`) and e_t follows from the closed-form map
    of Eqs. (16)-(20) (:func:`~microimpact.analysis.oblique.rebound_from_impulses`) at each f. The
    derivative is a central difference in ln f with step 1e-4: e_t is linear in f while the sphere
    slides throughout (v_t,out = v_t,in - f J / m) and constant once it ends rolling, so the only
    error is at the kink f = f*, where the difference is a one-sided mean. The rebound angle
    atan(v_t,out / v_n,out) and the rebound spin (5 f J / (2 m R) while sliding, v_t,out / R once
    rolling) are smooth functions of e_t, computed by the friction fit's own observables.

    Parameters
    ----------
    contact : Contact
        The normal parameters (damping, f0) at the impacts' radius.
    speed, incidence_deg : array_like
        Incident speed [m/s] and angle from the normal [deg] (> 0).
    frictions : array_like
        Coulomb coefficients. [-]
    rtol : float
        Relative tolerance of the normal solves. [-]
    quantity : str
        ``tangential_restitution`` [-], ``rebound_angle`` [deg] or ``rebound_spin`` [rad/s].

    Returns
    -------
    (e_n, q, gradient)
        e_n [-] per impact; q and gradient[i, k] = d q_i / d ln f_k [unit of q], shape
        (impacts, frictions); NaN and 0 where the impact is captured, 0 where it ends in rolling
        at f_k.

    Examples
    --------
    At 60 deg and 10 m/s the sphere slides throughout for f = 0.1 (e_t responds) and ends rolling
    for f = 1 (e_t = 5/7 whatever f):

    >>> from microimpact.io import default_materials_path, read_materials
    >>> from microimpact.io.materials import material_contact
    >>> m = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> c = material_contact(m, 3.45e-6, zeta_hertz=0.5, zeta_adhesion=29.0)
    >>> e_n, e_t, g = tangential_sensitivities(c, [10.0], [60.0], [0.1, 1.0])
    >>> bool(g[0, 0] < -0.01), round(float(e_t[0, 1]), 4), float(g[0, 1])
    (True, 0.7143, 0.0)

    The rebound spin responds where e_t does, in rad/s:

    >>> _, w, gw = tangential_sensitivities(c, [10.0], [60.0], [0.1, 1.0], quantity="rebound_spin")
    >>> bool(gw[0, 0] > 1e4), float(gw[0, 1])
    (True, 0.0)
    """
    if quantity not in OBLIQUE_QUANTITIES or quantity == "none":
        raise ValueError(f"quantity must be one of tangential_restitution, rebound_angle, rebound_spin, got {quantity!r}")
    speed, angle = np.asarray(speed, float), np.asarray(incidence_deg, float)
    imp = normal_impulses(contact, speed, angle, rtol)
    zero = np.zeros_like(speed)
    names = np.full(speed.shape, "rebound_angle_deg" if quantity == "rebound_angle" else quantity, dtype=object)
    h = 1e-4
    q, grad = np.empty((speed.size, len(frictions))), np.empty((speed.size, len(frictions)))
    undefined = imp["captured"] | (imp["velocity_in_t"] <= 0)

    def q_at(f):
        out = rebound_from_impulses(contact, imp, zero, friction=f)
        return np.where(undefined, np.nan, _observables(out, speed, angle, names))

    for k, f in enumerate(np.asarray(frictions, float)):
        q[:, k] = q_at(f)
        d = np.nan_to_num((q_at(f * math.exp(h)) - q_at(f * math.exp(-h))) / (2 * h))
        # a rolling impact's q differs only by rounding (~1e-16 |q| / h = 1e-12 |q|): that is no response
        grad[:, k] = np.where(np.abs(d) > 1e-8 * np.maximum(1.0, np.nan_to_num(np.abs(q[:, k]))), d, 0.0)
    return imp["e_n"], q, grad


def _friction_candidates(space: DesignSpace) -> pd.DataFrame:
    """The oblique candidates: the space's nonzero angles, else :data:`OBLIQUE_ANGLES_DEG`."""
    angles = tuple(a for a in space.incidence_deg if a > 0) or OBLIQUE_ANGLES_DEG
    return replace(space, incidence_deg=angles).candidates()


def design_friction(fit=None, space: DesignSpace | None = None, n: int = DEFAULT_NEW_OBLIQUE, *, material=None, values=None,
                    existing=None, friction_range: tuple = FRICTION_RANGE, rtol: float = DEFAULT_RTOL) -> ExperimentDesign:
    """The next ``n`` oblique impacts (angle, speed, size) that most narrow the Coulomb coefficient f.

    e_n does not depend on f; a measured tangential restitution e_t (or rebound angle, or rebound
    spin: the space's ``oblique_quantity``) does, but only while the sphere slides throughout the contact (f < f*_i = 2 m |u_0| / (7 J_i)); an impact that ends
    rolling gives e_t = 5/7 whatever f and only bounds it (the ``lower_bound`` / ``not_determined``
    statuses of :func:`~microimpact.analysis.oblique.fit_friction`). Because where an impact slides
    depends on the unknown f itself, the criterion is averaged over ``friction_range``
    (log-uniform, :data:`FRICTION_GRID_POINTS` values): each greedy step adds the candidate that
    most reduces the mean over f of the relative variance 1 / I(f) of ln f, with
    I(f) = I_0(f) + sum_k (d q_k / d ln f)^2 / sigma_q^2, q the measured oblique quantity and
    sigma_q its uncertainty (:attr:`DesignSpace.oblique_sigma`) (a Bayesian A-criterion; Chaloner &
    Verdinelli 1995). A candidate that is captured or ends rolling for every f of the range is never
    recommended.

    Parameters
    ----------
    fit : DampingFit, optional
        The damping fit whose contact the impacts are solved with (else ``material`` and ``values``).
    space : DesignSpace
        Its nonzero ``incidence_deg`` are the candidate angles (:data:`OBLIQUE_ANGLES_DEG` if none);
        its ``oblique_quantity`` is what is measured (``none`` is refused: e_n alone does not
        determine f).
    n : int
        Number of new oblique impacts.
    material : MaterialPair, optional
        Without a fit.
    values : dict, optional
        ``zeta_hertz``, ``zeta_adhesion`` [-] (and ``work_of_adhesion`` [J/m^2]) without a fit.
    existing : pandas.DataFrame, optional
        Oblique impacts already measured (``radius`` [m], ``speed`` [m/s], ``incidence_deg`` [deg]):
        their information is I_0.
    friction_range : (float, float)
        The range f is believed to lie in. [-]
    rtol : float
        Relative tolerance of the normal solves. [-]

    Returns
    -------
    ExperimentDesign
        ``widths``: the expected 95 % width of f at the range's geometric centre.

    References
    ----------
    Chaloner, K. & Verdinelli, I. (1995). Bayesian experimental design: a review. Statistical
    Science 10(3), 273-304. doi:10.1214/ss/1177009939

    Examples
    --------
    With candidate angles 10-80 deg, the design never picks an angle where every f of 0.05-1 rolls:

    >>> from microimpact.io import default_materials_path, read_materials
    >>> m = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> space = DesignSpace(radii=(3.45e-6,), speed_range=(2.0, 20.0), incidence_deg=(10.0, 45.0, 80.0), n_speeds=4)
    >>> d = design_friction(None, space, 3, material=m, values={"zeta_hertz": 0.5, "zeta_adhesion": 29.0})
    >>> sorted(set(d.rows["incidence_deg"].tolist())) != [10.0], d.parameters
    (True, ('friction',))
    """
    lo, hi = _checked_friction_request(space, n, friction_range)
    base, vals = _friction_design_base(fit, material, values)
    grid = np.geomspace(lo, hi, FRICTION_GRID_POINTS)
    cand = _friction_candidates(space)
    q, sigma = space.oblique_quantity, space.oblique_sigma
    e_n, e_t, g = _oblique_sensitivities(base, vals, cand, grid, rtol, q)
    info0 = np.full(grid.size, 1.0 / WEAK_PRIOR_RELATIVE_SD ** 2)
    if existing is not None and len(existing):
        # the impacts already measured: their own quantity is not known here, so e_t with e_t_sigma
        _, _, g0 = _oblique_sensitivities(base, vals, existing, grid, rtol)
        info0 = info0 + np.sum(np.square(g0 / space.e_t_sigma), axis=0)
    gw2 = np.square(g / sigma)
    admissible = (e_n > 0) & np.any(gw2 > 0, axis=1)
    if not admissible.any():
        raise ValueError("no oblique candidate of the design space slides for any f of the friction range (all "
                         "captured or rolling): add steeper incidence angles or higher speeds")
    chosen, reasons, path = _greedy_friction(info0, gw2, admissible, int(n), cand, e_n, q, grid)
    uni = uniform_oblique_design(space, int(n))
    _, _, gu = _oblique_sensitivities(base, vals, uni, grid, rtol, q)
    centre = int(np.argmin(np.abs(np.log(grid) - 0.5 * math.log(lo * hi))))
    widths = _friction_width_table(info0, path, np.square(gu / sigma), grid, centre)
    rows = _rows(cand.iloc[chosen], e_n[chosen], reasons)
    notes = {"friction": _friction_design_note(cand, g, e_n, grid, chosen)}
    return ExperimentDesign(rows, widths, ("friction",), {**vals, "friction": float(grid[centre])},
                            f"Fisher information of the {q.replace('_', ' ')} in ln f averaged over the friction range "
                            "(Bayesian A-criterion, log-uniform prior); greedy sequential selection over the oblique "
                            "candidates", notes)



def _checked_friction_request(space, n, friction_range) -> tuple[float, float]:
    """The ends of ``friction_range`` of :func:`design_friction`, its design ``space`` and ``n``
    checked (ValueError: no space, ``n`` outside [1, MAX_NEW_IMPACTS], a range not 0 < min < max,
    a space that measures e_n only)."""
    if space is None:
        raise ValueError("give the design space (DesignSpace)")
    if not 1 <= int(n) <= MAX_NEW_IMPACTS:
        raise ValueError(f"the number of new impacts must be in [1, {MAX_NEW_IMPACTS}], got {n!r}")
    lo, hi = (float(x) for x in friction_range)
    if not 0 < lo < hi:
        raise ValueError(f"friction_range must be 0 < min < max, got {friction_range!r}")
    if space.oblique_quantity == "none":
        raise ValueError("friction: the design space measures e_n only, and e_n does not depend on friction "
                         "(Eqs. (16)-(20)); measure the tangential restitution, rebound angle or rebound spin of "
                         "oblique impacts")
    return lo, hi


def _friction_design_base(fit, material, values) -> tuple:
    """(base, values) the impacts of :func:`design_friction` are solved with: the damping ``fit`` and
    its values, else ``material`` with its work of adhesion and ``values`` (ValueError without)."""
    if fit is not None:
        return fit, dict(fit.values)
    if material is not None and values:
        return material, {"work_of_adhesion": float(material.work_of_adhesion), **{k: float(v) for k, v in values.items()}}
    raise ValueError("give a damping fit, or a material with the damping values")

def _oblique_sensitivities(base, vals, table, grid, rtol, quantity="tangential_restitution"):
    """:func:`tangential_sensitivities` of the rows of ``table`` (radius, speed, incidence_deg), one contact per radius."""
    e_n = np.zeros(len(table))
    e_t, g = np.full((len(table), grid.size), np.nan), np.zeros((len(table), grid.size))
    radius = np.asarray(table["radius"], float)
    for r in np.unique(radius):
        idx = np.flatnonzero(radius == r)
        c = material_contact(base, float(r), zeta_hertz=vals["zeta_hertz"], zeta_adhesion=vals["zeta_adhesion"],
                             work_of_adhesion=vals["work_of_adhesion"])
        e_n[idx], e_t[idx], g[idx] = tangential_sensitivities(c, np.asarray(table["speed"], float)[idx],
                                                              np.asarray(table["incidence_deg"], float)[idx], grid, rtol,
                                                              quantity)
    return e_n, e_t, g


def _greedy_friction(info0, gw2, admissible, n, cand, e_n, quantity, grid):
    """Candidates chosen one at a time, each of least mean relative variance of ln f over the grid."""
    info, chosen, reasons, path = info0.copy(), [], [], []
    options = np.flatnonzero(admissible)
    for _ in range(n):
        scores = np.mean(1.0 / (info[None, :] + gw2[options]), axis=1)
        best = int(options[np.argmin(scores)])
        info = info + gw2[best]
        slides = grid[gw2[best] > 0]
        size = f"d = {2e6 * cand['radius'].iloc[best]:.3g} um, " if cand["radius"].nunique() > 1 else ""
        reasons.append(f"{size}{cand['incidence_deg'].iloc[best]:.3g} deg, {cand['speed'].iloc[best]:.3g} m/s, "
                       f"e_n ~ {e_n[best]:.3f}: slides throughout for f up to {slides.max():.2g} (its "
                       f"{quantity.replace('_', ' ')} responds to f there, up to {math.sqrt(gw2[best].max()):.2g} "
                       f"sigma per 100 % of f)")
        chosen.append(best)
        path.append(info.copy())
    return chosen, reasons, path


def _friction_width_table(info0, path, gu2, grid, centre):
    """Expected 95 % widths of f at the grid's centre after 0 ... N impacts, recommended and uniform."""
    z = float(stats.norm.ppf(0.5 + DEFAULT_LEVEL / 2))
    uni = info0.copy()
    rows = []
    for k in range(len(path) + 1):
        rec = info0 if k == 0 else path[k - 1]
        if k > 0:
            uni = uni + gu2[k - 1]
        rows.append({"n_new": k, "parameter": "friction", "design": 2 * z * grid[centre] / math.sqrt(rec[centre]),
                     "uniform": 2 * z * grid[centre] / math.sqrt(uni[centre])})
    return pd.DataFrame(rows)


def _friction_design_note(cand, g, e_n, grid, chosen):
    """What determines f: the angles and speeds that slide for the upper half of the range, and the design's reach."""
    top = grid[grid >= np.sqrt(grid[0] * grid[-1])]
    reach = (g[:, grid >= top[0]] != 0).any(axis=1) & (e_n > 0)
    text = ("e_n does not depend on friction (Eqs. (16)-(20)); a measured tangential restitution (or rebound angle) "
            "determines f only from impacts that slide throughout (f < f* = 2 m |u_0| / (7 J))")
    if reach.any():
        a, v = cand["incidence_deg"].to_numpy()[reach], cand["speed"].to_numpy()[reach]
        text += (f"; impacts at {a.min():.3g}-{a.max():.3g} deg and {v.min():.3g}-{v.max():.3g} m/s slide for "
                 f"f >= {top[0]:.2g}")
    covered = grid[(g[chosen] != 0).any(axis=0)]
    return text + (f"; the recommended impacts slide for f up to {covered.max():.2g} of the range "
                   f"{grid[0]:.2g}-{grid[-1]:.2g}" if covered.size else "; none of them slides")


def design_record(design: ExperimentDesign, space: DesignSpace, source: str = "") -> dict:
    """The design as JSON-ready data (the pipeline's ``design.json``, the report page's input).

    Parameters
    ----------
    design : ExperimentDesign
    space : DesignSpace
        The space it was chosen from (recorded with it).
    source : str
        Where the fit came from (a file name).

    Returns
    -------
    dict
        ``criterion``, ``parameters``, ``values``, ``notes``, ``space`` (radii [m], speed_range
        [m/s], incidence_deg and the friction design's oblique_deg [deg], e_n_sigma, e_t_sigma,
        speed_sigma [-], n_speeds, oblique_quantity and its oblique_sigma [its unit]), ``rows``
        (records of :attr:`ExperimentDesign.rows`), ``widths`` (records of
        :attr:`ExperimentDesign.widths`), ``source``.

    Examples
    --------
    >>> rows = pd.DataFrame({"id": ["design-001"], "radius": [3.45e-6], "speed": [2.0], "incidence_deg": [0.0],
    ...                      "normal_speed": [2.0], "e_n_expected": [0.5], "reason": ["why"]})
    >>> widths = pd.DataFrame({"n_new": [0, 1], "parameter": "zeta_hertz", "design": [1.0, 0.5], "uniform": [1.0, 0.8]})
    >>> rec = design_record(ExperimentDesign(rows, widths, ("zeta_hertz",), {"zeta_hertz": 0.5}, "Fisher"),
    ...                     DesignSpace(radii=(3.45e-6,)))
    >>> rec["rows"][0]["reason"], rec["widths"][1]["uniform"], rec["space"]["speed_range"]
    ('why', 0.8, [0.5, 20.0])
    """
    return {"criterion": design.criterion, "parameters": list(design.parameters),
            "values": {k: float(v) for k, v in design.values.items()}, "notes": dict(design.notes),
            "space": {"radii": [float(r) for r in space.radii], "speed_range": [float(x) for x in space.speed_range],
                      "incidence_deg": [float(a) for a in space.incidence_deg], "e_n_sigma": float(space.e_n_sigma),
                      "oblique_deg": sorted({float(a) for a in _friction_candidates(space)["incidence_deg"]}),
                      "e_t_sigma": float(space.e_t_sigma), "speed_sigma": float(space.speed_sigma),
                      "oblique_quantity": space.oblique_quantity, "oblique_sigma": float(space.oblique_sigma),
                      "n_speeds": int(space.n_speeds)},
            "rows": design.rows.to_dict("records"), "widths": design.widths.to_dict("records"), "source": str(source)}


def fit_design_space(fit, **changes) -> DesignSpace:
    """The design space of a fit: its radii and speed range, e_n uncertainty its median stated one
    (the scatter, sqrt(reduced chi-square), when unweighted); ``changes`` replace any field.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> fit = SimpleNamespace(radii=[3.45e-6], speed_range=(1.0, 10.0), weighting="none", redchi=0.0004,
    ...                       data=pd.DataFrame({"e_n": [0.5]}))
    >>> s = fit_design_space(fit, n_speeds=10)
    >>> s.speed_range, round(s.e_n_sigma, 6), s.n_speeds
    ((1.0, 10.0), 0.02, 10)
    """
    d = fit.data
    s = d["sigma"].to_numpy(float) if "sigma" in d.columns else np.array([np.nan])
    sigma = float(np.nanmedian(s)) if fit.weighting != "none" and np.isfinite(s).any() else math.sqrt(fit.redchi)
    lo, hi = fit.speed_range
    base = {"radii": tuple(float(r) for r in fit.radii), "speed_range": (float(lo), float(hi)), "e_n_sigma": sigma}
    return DesignSpace(**{**base, **changes})


def design_next_impacts(fit, space: DesignSpace, n: int = DEFAULT_NEW_IMPACTS, parameters=DEFAULT_PARAMETERS, *,
                        n_friction: int = DEFAULT_NEW_OBLIQUE,
                        criterion: str = "A", rtol: float = DEFAULT_RTOL, posterior=None) -> ExperimentDesign:
    """The e_n design of the damping parameters named and, with ``"friction"`` named, the oblique
    design of :func:`design_friction` after it, as one :class:`ExperimentDesign` (ids renumbered).

    Parameters
    ----------
    fit : DampingFit
    space : DesignSpace
    n : int
        New e_n impacts for the damping parameters.
    parameters : sequence of str
        Among :data:`PARAMETER_NAMES` and ``"friction"``.
    n_friction : int
        New oblique impacts for friction.
    criterion : {"A", "D"}
        Of the damping design.
    rtol : float
        Relative tolerance of the normal solves. [-]
    posterior : Posterior, optional
        Of the fit: the damping design's M_0 (:func:`design_impacts`).

    Returns
    -------
    ExperimentDesign

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.io import default_materials_path, read_materials
    >>> m = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = pd.DataFrame({"radius": 3.45e-6, "normal_speed": [2.0, 4.0, 8.0, 16.0], "e_n": [0.3, 0.55, 0.68, 0.7],
    ...                       "e_n_uncertainty": 0.02})
    >>> fit = fit_damping(table, m, confidence_intervals=False)
    >>> d = design_next_impacts(fit, fit_design_space(fit, n_speeds=8), 2, ("zeta_hertz", "friction"), n_friction=2)
    >>> d.rows["id"].tolist(), d.parameters
    (['design-001', 'design-002', 'design-003', 'design-004'], ('zeta_hertz', 'friction'))
    """
    damping = tuple(p for p in parameters if p != "friction")
    parts = []
    if damping:
        parts.append(design_impacts(fit, space, n, parameters=damping, criterion=criterion, rtol=rtol,
                                    posterior=posterior))
    if "friction" in parameters:
        parts.append(design_friction(fit, space, n_friction, rtol=rtol))
    if not parts:
        raise ValueError(f"parameters must be among {PARAMETER_NAMES + ('friction',)}, got {list(parameters)!r}")
    if len(parts) == 1:
        return parts[0]
    rows = pd.concat([p.rows for p in parts], ignore_index=True)
    rows["id"] = [f"design-{k + 1:03d}" for k in range(len(rows))]
    return ExperimentDesign(rows, pd.concat([p.widths for p in parts], ignore_index=True),
                            parts[0].parameters + parts[1].parameters, {**parts[0].values, **parts[1].values},
                            "; ".join(p.criterion for p in parts), {**parts[0].notes, **parts[1].notes})
