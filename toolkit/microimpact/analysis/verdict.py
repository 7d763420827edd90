"""The verdict of a fit: adequate or not, which rows are outliers, and what the misfit looks like.

A fit's numbers are conditional on its model describing the data. :func:`assess_residuals` turns
the standardized residuals of a fit into a :class:`Verdict`, carried by every fit result and shown
wherever its numbers are (the text report, ``fit --json``, the fit file's attributes, the plot):

* **adequacy**: with stated uncertainties, the chi-square test (chi-square of N - k degrees of
  freedom; rejected when p < :data:`ADEQUACY_P`); without them, no test is possible and the fit is
  "judged against the scatter" (its covariance scaled by the reduced chi-square);
* **outliers**: rows whose standardized residual is improbable given the number of rows: beyond the
  two-sided Sidak threshold ``t`` with ``P(max_i |z_i| > t) = OUTLIER_FALSE_ALARM`` for N independent
  standard normal residuals (Sidak 1967), so a clean data set names a row with probability
  :data:`OUTLIER_FALSE_ALARM` in all; without stated uncertainties the residuals are standardized by
  their median absolute deviation (1.4826 MAD, Rousseeuw & Croux 1993). More rows beyond it than an
  isolated few (:data:`MAX_OUTLIER_FRACTION`) are a systematic misfit, not outliers;
* **misfit in words**: where the model lies too low or too high against speed (terciles of the
  measured speed range), by size, and the runs of one sign in speed order (Wald & Wolfowitz 1940).

References
----------
* Sidak, Z. (1967). Rectangular confidence regions for the means of multivariate normal
  distributions. J. Am. Stat. Assoc. 62(318), 626-633. doi:10.1080/01621459.1967.10482935
* Rousseeuw, P. J., Croux, C. (1993). Alternatives to the median absolute deviation. J. Am. Stat.
  Assoc. 88(424), 1273-1283. doi:10.1080/01621459.1993.10476408
* Wald, A., Wolfowitz, J. (1940). On a test whether two samples are from the same population.
  Ann. Math. Statist. 11(2), 147-162. doi:10.1214/aoms/1177731909
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

__all__ = ["Verdict", "assess_residuals", "ADEQUATE", "INADEQUATE", "NO_UNCERTAINTIES", "ADEQUACY_P",
           "OUTLIER_FALSE_ALARM", "MAX_OUTLIER_FRACTION", "sidak_threshold", "VERDICT_ATTRS", "p_value_text"]

ADEQUATE = "adequate"
INADEQUATE = "inadequate"
NO_UNCERTAINTIES = "no stated uncertainties"
#: p-value of the chi-square test below which a fit with stated uncertainties is inadequate
ADEQUACY_P = 1e-3
#: the probability that a clean data set of any size names one or more outliers
OUTLIER_FALSE_ALARM = 0.05
#: more rows beyond the outlier threshold than this fraction of the rows (and more than 3): a
#: systematic misfit, not isolated outliers
MAX_OUTLIER_FRACTION = 0.1
#: MAD -> standard deviation of a normal distribution (Rousseeuw & Croux 1993)
_MAD_SCALE = 1.4826
#: the fit-file attributes of a verdict (the report reads these names)
VERDICT_ATTRS = ("verdict", "verdict_text", "chi_square", "degrees_of_freedom", "p_value", "outlier_ids",
                 "outlier_threshold_text", "misfit_description", "interval_note")


def p_value_text(p: float) -> str:
    """'p = 0.15', or 'p < 1e-300' where p underflows to 0 (a p of exactly 0 would be a claim).

    Examples
    --------
    >>> p_value_text(0.1533), p_value_text(0.0)
    ('p = 0.15', 'p < 1e-300')
    """
    return "p < 1e-300" if p == 0 else f"p = {p:.2g}"


def sidak_threshold(n: int, false_alarm: float = OUTLIER_FALSE_ALARM) -> float:
    """|z| beyond which one of ``n`` independent standard normal residuals falls with probability
    ``false_alarm`` in all (two-sided Sidak threshold). [1]

    Parameters
    ----------
    n : int
        Number of residuals.
    false_alarm : float
        Probability that any of the ``n`` exceeds the threshold. [-]

    Returns
    -------
    float

    References
    ----------
    Sidak (1967), doi:10.1080/01621459.1967.10482935.

    Examples
    --------
    >>> round(sidak_threshold(1), 3), round(sidak_threshold(40), 2)
    (1.96, 3.22)
    """
    per_row = -math.expm1(math.log1p(-false_alarm) / max(int(n), 1))
    return float(stats.norm.isf(per_row / 2))


@dataclass(frozen=True)
class Verdict:
    """Whether a fit's model describes its data, its outliers and its misfit in words.

    Attributes
    ----------
    verdict : str
        :data:`ADEQUATE`, :data:`INADEQUATE` or :data:`NO_UNCERTAINTIES`.
    chi_square, degrees_of_freedom, p_value : float
        The chi-square test (NaN without stated uncertainties).
    outlier_ids : tuple of str
        The CSV's id (else its row number) of each outlier.
    outlier_threshold : float
        The |standardized residual| beyond which a row is an outlier. [1]
    false_alarm : float
        Probability that a clean data set names an outlier. [-]
    misfit_description : str
        The residuals' structure in words ("" when adequate).
    what : str
        What was fitted ("damping law", "friction", ...), for the text.
    """

    verdict: str
    chi_square: float
    degrees_of_freedom: float
    p_value: float
    outlier_ids: tuple = ()
    outlier_threshold: float = math.nan
    false_alarm: float = OUTLIER_FALSE_ALARM
    misfit_description: str = ""
    what: str = "model"
    #: the verdict of the refit without the outliers, in words ("" when none were named)
    without_outliers: str = ""
    #: ids the analyst excluded (``--exclude``)
    excluded: tuple = ()

    @property
    def rejected(self) -> bool:
        """True when the chi-square test rejects the model."""
        return self.verdict == INADEQUATE

    @property
    def widening(self) -> float:
        """sqrt(reduced chi-square) of a rejected model (the factor its intervals are widened by), else 1."""
        if not self.rejected or not self.degrees_of_freedom > 0:
            return 1.0
        return float(math.sqrt(self.chi_square / self.degrees_of_freedom))

    def text(self) -> str:
        """One sentence: the verdict and its numbers."""
        if self.verdict == NO_UNCERTAINTIES:
            return (f"{NO_UNCERTAINTIES}: the {self.what} is judged against the scatter (no chi-square test; "
                    "intervals scaled by the residual scatter)")
        return (f"{self.verdict}: chi-square {self.chi_square:.4g} for {self.degrees_of_freedom:.0f} degrees of "
                f"freedom ({p_value_text(self.p_value)})")

    def outlier_threshold_text(self) -> str:
        """The outlier threshold and its false-alarm rate in words."""
        if not math.isfinite(self.outlier_threshold):
            return "no outlier test (too few rows)"
        scale = ("stated uncertainty" if self.verdict != NO_UNCERTAINTIES
                 else "robust scatter (1.4826 x median absolute deviation)")
        return (f"|standardized residual| > {self.outlier_threshold:.3g} (residual / {scale}): a clean data set of "
                f"this size names a row with probability {self.false_alarm:.0%} (Sidak)")

    def interval_note(self) -> str:
        """What the fit's intervals mean here."""
        if self.rejected:
            return (f"conditional on a rejected model; widened by sqrt(reduced chi-square) = {self.widening:.3g} "
                    "also given")
        if self.verdict == NO_UNCERTAINTIES:
            return "from the residual scatter (no stated uncertainties): valid only if the model describes the data"
        return "95 % profile-likelihood intervals of an adequate model"

    def lines(self) -> list[str]:
        """The verdict's lines of a text report (verdict, outliers, misfit, intervals)."""
        out = [f"  verdict     : {self.text()}"]
        if self.outlier_ids:
            out.append(f"  outliers    : {', '.join(self.outlier_ids)} ({self.outlier_threshold_text()})")
        if self.without_outliers:
            out.append(f"  without them: {self.without_outliers}")
        if self.excluded:
            out.append(f"  excluded    : {', '.join(self.excluded)} (by the analyst: --exclude)")
        if self.misfit_description:
            out.append(f"  misfit      : {self.misfit_description}")
        out.append(f"  intervals   : {self.interval_note()}")
        return out

    def to_attrs(self) -> dict:
        """The fit-file attributes :data:`VERDICT_ATTRS` (floats NaN where not applicable)."""
        return {"verdict": self.verdict, "verdict_text": self.text(), "chi_square": float(self.chi_square),
                "degrees_of_freedom": float(self.degrees_of_freedom), "p_value": float(self.p_value),
                "outlier_ids": ",".join(self.outlier_ids), "outlier_threshold": float(self.outlier_threshold),
                "outlier_false_alarm": float(self.false_alarm), "outlier_threshold_text": self.outlier_threshold_text(),
                "misfit_description": self.misfit_description, "interval_note": self.interval_note(),
                "interval_widening": self.widening, "without_outliers_text": self.without_outliers,
                "excluded_ids": ",".join(self.excluded)}

    def to_record(self) -> dict:
        """The verdict for ``--json``: its attributes with the ids as a list."""
        return self.to_attrs() | {"outlier_ids": list(self.outlier_ids), "excluded_ids": list(self.excluded),
                                  "rejected": self.rejected}


def assess_residuals(standardized, n_parameters: int, *, stated: bool = True, ids=None, speed=None, radius=None,
                     false_alarm: float = OUTLIER_FALSE_ALARM, what: str = "model") -> Verdict:
    """The :class:`Verdict` of a fit from its standardized residuals (model - measured) / sigma.

    Parameters
    ----------
    standardized : array_like
        (model - measured) / stated uncertainty; without stated uncertainties, model - measured. [1]
    n_parameters : int
        Number of fitted parameters.
    stated : bool
        Whether the uncertainties were stated (else no chi-square test).
    ids : sequence of str, optional
        The CSV's id of each row (default: 1, 2, ...).
    speed, radius : array_like, optional
        Normal impact speed [m/s] and radius [m] of each row, for the misfit in words.
    false_alarm : float
        Probability that a clean data set names an outlier. [-]
    what : str
        What was fitted, for the text.

    Returns
    -------
    Verdict

    Examples
    --------
    Forty clean residuals and two rows 20 standard deviations off:

    >>> z = np.random.default_rng(1).normal(size=40)
    >>> z[[5, 17]] = [20.0, -22.0]
    >>> v = assess_residuals(z, 2, ids=[f"r{i}" for i in range(40)])
    >>> v.verdict, v.outlier_ids
    ('inadequate', ('r5', 'r17'))
    >>> assess_residuals(np.delete(z, [5, 17]), 2).verdict
    'adequate'
    """
    z = np.asarray(standardized, dtype=float)
    n = z.size
    ids = tuple(str(i) for i in (ids if ids is not None else range(1, n + 1)))
    dof = n - n_parameters
    if stated:
        chi2 = float(z @ z)
        p = float(stats.chi2.sf(chi2, dof)) if dof > 0 else math.nan
        verdict = INADEQUATE if dof > 0 and p < ADEQUACY_P else ADEQUATE
        scaled = z
    else:
        chi2 = p = math.nan
        verdict = NO_UNCERTAINTIES
        mad = _MAD_SCALE * float(np.median(np.abs(z - np.median(z)))) if n else 0.0
        scaled = z / mad if mad > 0 else np.zeros_like(z)
    threshold = sidak_threshold(n, false_alarm) if n > n_parameters + 2 else math.nan
    beyond = np.flatnonzero(np.abs(scaled) > threshold) if math.isfinite(threshold) else np.array([], int)
    isolated = beyond.size <= max(3, math.ceil(MAX_OUTLIER_FRACTION * n))
    outliers = tuple(ids[i] for i in beyond) if isolated else ()  # in row order
    misfit = ""
    if verdict != ADEQUATE:
        keep = np.ones(n, bool)
        keep[beyond if isolated else []] = False
        misfit = describe_misfit(scaled[keep], None if speed is None else np.asarray(speed, float)[keep],
                                 None if radius is None else np.asarray(radius, float)[keep],
                                 n_beyond=0 if isolated else beyond.size, threshold=threshold)
    if verdict == NO_UNCERTAINTIES and not misfit.startswith("systematic"):
        misfit = ""
    return Verdict(verdict, chi2, float(dof), p, outliers, threshold, false_alarm, misfit, what)


def _runs_test(signs) -> float:
    """Two-sided p of the Wald-Wolfowitz runs test of a sequence of +1/-1 (normal approximation)."""
    s = np.asarray(signs)
    n1, n2 = int(np.sum(s > 0)), int(np.sum(s < 0))
    if n1 == 0 or n2 == 0:
        return 0.0 if s.size > 8 else 1.0
    runs = 1 + int(np.count_nonzero(s[1:] != s[:-1]))
    n = n1 + n2
    mean = 2.0 * n1 * n2 / n + 1
    var = 2.0 * n1 * n2 * (2.0 * n1 * n2 - n) / (n * n * (n - 1)) if n > 1 else 0.0
    return 1.0 if var <= 0 else float(2 * stats.norm.sf(abs(runs - mean) / math.sqrt(var)))


def describe_misfit(z, speed=None, radius=None, *, n_beyond: int = 0, threshold: float = math.nan) -> str:
    """The structure of standardized residuals (model - measured) / sigma in words.

    Where the model lies too low or too high in each third of the measured speed range (a mean
    standardized residual beyond 2 / sqrt(rows in that third)), by size likewise, and the runs of
    one sign in speed order (Wald-Wolfowitz; few runs: a systematic misfit, not scatter).

    Examples
    --------
    >>> v = np.linspace(1, 30, 30)
    >>> print(describe_misfit(np.where(v < 10, -3.0, 3.0), v))
    model too low at 1-10 m/s (mean standardized residual -2.4), too high at 11-30 m/s (+3); 2 runs of one sign in speed order where 14 are expected (runs test p = 2.4e-07): systematic in speed, not scatter; e_n falls with speed faster than the law allows (as plastic loss does: an elastic-plastic law may describe it)
    """
    z = np.asarray(z, float)
    parts = []
    if n_beyond:
        parts.append(f"systematic: {n_beyond} rows beyond the outlier threshold {threshold:.3g}, too many to be isolated outliers")
    if speed is None or z.size < 6:
        return "; ".join(parts) or "residuals larger than their stated uncertainties"
    order = np.argsort(speed)
    v, zz = np.asarray(speed)[order], z[order]
    bins = np.array_split(np.arange(v.size), 3)
    groups = []  # consecutive thirds on the same side, merged: [side, first row, last row, rows]
    for b in bins:
        m = float(np.mean(zz[b]))
        side = None if abs(m) <= 2 / math.sqrt(b.size) else ("too low" if m < 0 else "too high")
        if groups and groups[-1][0] == side:
            groups[-1][2], groups[-1][3] = b[-1], np.concatenate([groups[-1][3], b])
        else:
            groups.append([side, b[0], b[-1], b])
    sides = [g[0] for g in groups if g[0] is not None]
    words = []
    for side, first, last, rows in groups:
        if side is not None:
            m = float(np.mean(zz[rows]))
            words.append(f"{side} at {v[first]:.3g}-{v[last]:.3g} m/s"
                         + (f" (mean standardized residual {m:+.2g})" if not words else f" ({m:+.2g})"))
    if words:
        parts.append("model " + ", ".join(words))
    signs = np.sign(zz[zz != 0])
    runs = 1 + int(np.count_nonzero(signs[1:] != signs[:-1])) if signs.size else 0
    n1, n2 = int(np.sum(signs > 0)), int(np.sum(signs < 0))
    expected = 2.0 * n1 * n2 / max(n1 + n2, 1) + 1
    p_runs = _runs_test(signs)
    if p_runs < 0.01 and runs < expected:  # fewer runs than chance: a trend (more: alternation, not a trend)
        parts.append(f"{runs} runs of one sign in speed order where {expected:.0f} are expected (runs test p = "
                     f"{p_runs:.2g}): systematic in speed, not scatter")
    if radius is not None:
        r = np.asarray(radius)[order]
        sizes = np.unique(r)
        if sizes.size > 1:
            by = [(s, float(np.mean(zz[r == s])), int(np.sum(r == s))) for s in sizes]
            off = [f"{'too high' if m > 0 else 'too low'} for radius {s * 1e6:.3g} um ({m:+.2g})"
                   for s, m, k in by if abs(m) > 2 / math.sqrt(k)]
            if off and len(off) < sizes.size:
                parts.append("by size: " + ", ".join(off))
    if sides and sides[-1] == "too high" and "too low" in sides[:-1]:
        parts[-1] += ("; e_n falls with speed faster than the law allows (as plastic "
                                                        "loss does: an elastic-plastic law may describe it)")
    return "; ".join(parts) or "residuals larger than their stated uncertainties, without a trend in speed or size"
