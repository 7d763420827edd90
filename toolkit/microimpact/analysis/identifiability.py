"""What a data set can tell about a fitted parameter: a number, a one-sided bound, or nothing.

A least-squares fit always stops somewhere and lmfit always returns a value; whether the data
*determine* that value is a separate question. A model that does not respond to a parameter (a zero
Jacobian column), a chi-square profile that stays within the confidence threshold up to a limit of
the allowed range, or a covariance that cannot be estimated all mean that a value with a standard
error would be meaningless. The typical case is the Coulomb coefficient of the paper's rigid
tangential model (Eqs. (16)-(20)): an impact whose friction impulse suffices to stop the slip ends
in rolling, and above that friction its rebound no longer depends on f. A design in which every
impact rolls for every f above some f_r says only ``f >= f_r``.

The decision (:func:`parameter_status`) works on the 100 ``level`` % interval of a parameter:

* the profile-likelihood interval {p : chi2(p) - chi2_min <= chi2_1(level)} where a profile over
  the whole allowed range is available (Wilks' theorem; 3.84 for 95 %), otherwise the Wald
  interval value +/- z sigma from the covariance;
* an interval inside the allowed range is ``determined`` (the value and its interval);
* one that reaches the upper limit of the range is a ``lower_bound`` (the data exclude only small
  values), one that reaches the lower limit an ``upper_bound``, one that reaches both is
  ``not_determined``;
* a standard error that is not finite, or larger than the value itself (a relative uncertainty above
  100 %), never yields a number: the status then comes from the profile, or is ``not_determined``.

References
----------
* Wilks, S. S. (1938). The large-sample distribution of the likelihood ratio for testing
  composite hypotheses. Ann. Math. Statist. 9, 60-62. doi:10.1214/aoms/1177732360
* Raue, A. et al. (2009). Structural and practical identifiability analysis of partially
  observed dynamical models by exploiting the profile likelihood. Bioinformatics 25, 1923-1929.
  doi:10.1093/bioinformatics/btp358
"""

from __future__ import annotations

import math

import numpy as np
from scipy import stats

from microimpact.io.statuses import (DEFAULT_LEVEL, STATUSES, ParameterStatus, status_from_variables,  # noqa: F401
                                    status_variables)

__all__ = ["ParameterStatus", "STATUSES", "parameter_status", "profile_interval", "chi2_threshold",
           "status_variables", "status_from_variables",
           "status_from_interval", "DEFAULT_LEVEL"]

#: a standard error above this fraction of the value is not reported as a number
MAX_RELATIVE_UNCERTAINTY = 1.0


def chi2_threshold(level: float = DEFAULT_LEVEL, dof: int = 1) -> float:
    """Rise of chi-square above its minimum that bounds a ``level`` profile interval. [-]

    Parameters
    ----------
    level : float
        Confidence level, in (0, 1). [-]
    dof : int
        Number of parameters of interest (1 for a profile of one parameter).

    Returns
    -------
    float
        The ``level`` quantile of the chi-square distribution with ``dof`` degrees of freedom.

    References
    ----------
    Wilks (1938), doi:10.1214/aoms/1177732360.

    Examples
    --------
    >>> round(chi2_threshold(0.95), 3)
    3.841
    """
    return float(stats.chi2.ppf(level, dof))


def profile_interval(grid, chi2, threshold: float) -> tuple[float, float, float, float]:
    """The hull of the grid points within ``threshold`` of the least chi-square, refined linearly.

    Parameters
    ----------
    grid : array_like
        Parameter values, ascending, spanning the whole allowed range (first and last points are
        the range limits).
    chi2 : array_like
        Chi-square (minimised over any other parameters) at each grid value. [-]
    threshold : float
        Allowed rise above the minimum, e.g. :func:`chi2_threshold`. [-]

    Returns
    -------
    (best, lower, upper, chi2_min)
        The grid value of least chi-square, the interval's ends (equal to the range limits where the
        profile stays within the threshold up to them) and the least chi-square.

    Examples
    --------
    >>> g = np.linspace(0.0, 2.0, 201)
    >>> best, lo, hi, _ = profile_interval(g, (g - 1.0) ** 2 / 0.1 ** 2, 3.84)
    >>> round(best, 3), round(lo, 3), round(hi, 3)
    (1.0, 0.804, 1.196)
    """
    x = np.asarray(grid, dtype=float)
    c = np.asarray(chi2, dtype=float)
    c = np.where(np.isfinite(c), c, np.inf)
    k = int(np.argmin(c))
    cmin = float(c[k])
    inside = np.flatnonzero(c <= cmin + threshold)
    i, j = int(inside[0]), int(inside[-1])
    level = cmin + threshold

    def cross(a, b):  # linear interpolation of the crossing between grid points a (inside) and b
        if not math.isfinite(c[b]):
            return float(x[a])
        return float(x[a] + (x[b] - x[a]) * (level - c[a]) / (c[b] - c[a]))

    lower = float(x[0]) if i == 0 else cross(i, i - 1)
    upper = float(x[-1]) if j == x.size - 1 else cross(j, j + 1)
    return float(x[k]), lower, upper, cmin


def status_from_interval(name: str, value: float, lower: float, upper: float, range_min: float, range_max: float, *,
                         level: float = DEFAULT_LEVEL, method: str = "profile", reasons: dict | None = None,
                         atol: float = 0.0) -> ParameterStatus:
    """Classify an interval against the allowed range (see the module docstring).

    Parameters
    ----------
    name : str
    value : float
        The estimate. [unit of the parameter]
    lower, upper : float
        The ``level`` interval. [unit]
    range_min, range_max : float
        The allowed range searched. [unit]
    level : float
    method : str
    reasons : dict, optional
        Text for the statuses other than ``determined`` (keys of :data:`STATUSES`), in the data's
        terms; a generic text otherwise.
    atol : float
        Distance from a range limit within which the interval counts as reaching it. [unit]

    Returns
    -------
    ParameterStatus

    Examples
    --------
    >>> status_from_interval("f", 0.3, 0.27, 10.0, 0.0, 10.0).status
    'lower_bound'
    >>> status_from_interval("f", 0.3, 0.25, 0.35, 0.0, 10.0).status
    'determined'
    """
    reasons = reasons or {}
    at_min = lower <= range_min + atol
    at_max = upper >= range_max - atol
    if at_min and at_max:
        return ParameterStatus(name, "not_determined", math.nan, range_min, range_max, level,
                               reasons.get("not_determined", "the fit is equally good over the whole range searched"),
                               method)
    if at_max:
        return ParameterStatus(name, "lower_bound", math.nan, lower, range_max, level,
                               reasons.get("lower_bound", f"the fit is equally good for every value above {lower:.4g}"),
                               method)
    if at_min:
        return ParameterStatus(name, "upper_bound", math.nan, range_min, upper, level,
                               reasons.get("upper_bound", f"the fit is equally good for every value below {upper:.4g}"),
                               method)
    z = float(stats.norm.ppf(0.5 + level / 2))
    if value and (upper - lower) > 2 * z * MAX_RELATIVE_UNCERTAINTY * abs(value) and lower >= 0:
        # an interval wider than +/- 100 % of the value, on a positive parameter: say only its upper end
        return ParameterStatus(name, "upper_bound", math.nan, range_min, upper, level,
                               reasons.get("upper_bound", f"the data allow any value below {upper:.4g} (the interval "
                                                          f"is wider than the value itself)"), method)
    return ParameterStatus(name, "determined", float(value), float(lower), float(upper), level, "", method)


def parameter_status(name: str, value: float, stderr: float, range_min: float, range_max: float, *,
                     profile=None, level: float = DEFAULT_LEVEL, sensitivity: float | None = None,
                     reasons: dict | None = None) -> ParameterStatus:
    """What the data say about one parameter, from its standard error and, if given, its profile.

    Parameters
    ----------
    name : str
    value, stderr : float
        Least-squares estimate and standard error (NaN: not estimated). [unit of the parameter]
    range_min, range_max : float
        Allowed range of the parameter (the profile, if any, spans it). [unit]
    profile : (array_like, array_like), optional
        Grid over the whole range and chi-square at each point (other parameters re-optimised). It
        takes precedence over the standard error for the interval.
    level : float
        Confidence level. [-]
    sensitivity : float, optional
        Norm of the model's weighted Jacobian column for the parameter, scaled by the parameter's
        range (how many standard deviations of the data the parameter can move). Below 1e-9 the
        parameter is ``not_determined`` whatever the rest says. [-]
    reasons : dict, optional
        See :func:`status_from_interval`.

    Returns
    -------
    ParameterStatus

    Examples
    --------
    >>> parameter_status("zeta_hertz", 0.5, 0.05, 0.0, 1e3).describe()
    'zeta_hertz = 0.5, 95 % interval [0.402, 0.598]'
    >>> parameter_status("zeta_hertz", 0.5, 0.9, 0.0, 1e3).status
    'upper_bound'
    """
    reasons = reasons or {}
    if sensitivity is not None and not sensitivity > 1e-9:
        return ParameterStatus(name, "not_determined", math.nan, range_min, range_max, level,
                               reasons.get("not_determined", "the model does not depend on it at these data"),
                               "sensitivity")
    if profile is not None:
        grid, chi2 = profile
        best, lo, hi, _ = profile_interval(grid, chi2, chi2_threshold(level))
        est = value if math.isfinite(value) and lo <= value <= hi else best
        return status_from_interval(name, est, lo, hi, range_min, range_max, level=level, method="profile",
                                    reasons=reasons)
    if not (math.isfinite(stderr) and stderr >= 0 and math.isfinite(value)):
        return ParameterStatus(name, "not_determined", math.nan, range_min, range_max, level,
                               reasons.get("not_determined", "its standard error could not be estimated"), "covariance")
    z = float(stats.norm.ppf(0.5 + level / 2))
    lo, hi = value - z * stderr, value + z * stderr
    if value != 0 and stderr > MAX_RELATIVE_UNCERTAINTY * abs(value):
        lo = min(lo, range_min)  # the interval reaches the range's end: never a number
    return status_from_interval(name, value, lo, hi, range_min, range_max, level=level, method="covariance",
                                reasons=reasons)
