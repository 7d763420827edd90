"""Convergence diagnostics of an MCMC sample: rank-normalised split R-hat and bulk effective sample size.

The definitions are those of Vehtari et al. (2021), as ArviZ computes them (``az.rhat``,
``az.ess(method="bulk")``); written here so that the toolkit does not depend on ArviZ, and tested
against ArviZ on the same draws (tests/test_posterior_convergence.py). An ensemble sampler's
walkers are not independent chains, but their between/within comparison detects the same failures
(walkers that have not mixed, a chain still drifting), and ArviZ users read them the same way.

References
----------
* Vehtari, A., Gelman, A., Simpson, D., Carpenter, B., Buerkner, P.-C. (2021). Rank-normalization,
  folding, and localization: an improved R-hat for assessing convergence of MCMC. Bayesian Analysis
  16(2), 667-718. doi:10.1214/20-BA1221
* Geyer, C. J. (1992). Practical Markov chain Monte Carlo. Statistical Science 7(4), 473-483.
  doi:10.1214/ss/1177011137
"""

from __future__ import annotations

import numpy as np
from scipy import stats

__all__ = ["split_rhat", "ess_bulk", "RHAT_MAX", "ESS_MIN"]

#: R-hat below which the chains count as mixed (Vehtari et al. 2021 recommend 1.01)
RHAT_MAX = 1.01
#: bulk effective sample size needed for reported 95 % intervals (Vehtari et al. 2021: 100 per chain
#: with 4 chains; their quantile estimates need a few hundred)
ESS_MIN = 400


def _split(draws: np.ndarray) -> np.ndarray:
    """(chains, draws) -> (2 chains, draws // 2): each chain cut in two halves (an odd middle draw dropped)."""
    x = np.asarray(draws, dtype=float)
    half = x.shape[1] // 2
    return np.concatenate([x[:, :half], x[:, x.shape[1] - half:]], axis=0)


def _usable_split(draws) -> np.ndarray | None:
    """The split chains, or None where they hold a non-finite or no varying draw (no diagnostic then)."""
    x = _split(draws)
    return x if np.all(np.isfinite(x)) and np.ptp(x) > 0 else None


def _rank_normalise(x: np.ndarray) -> np.ndarray:
    """Normal scores of the pooled ranks (average ranks for ties), fractional offset 3/8 (Blom)."""
    r = stats.rankdata(x, method="average").reshape(x.shape)
    return stats.norm.ppf((r - 0.375) / (x.size + 0.25))


def _rhat(x: np.ndarray) -> float:
    m, n = x.shape
    between = n * np.var(np.mean(x, axis=1), ddof=1)
    within = np.mean(np.var(x, axis=1, ddof=1))
    return float(np.sqrt(((n - 1) / n * within + between / n) / within))


def split_rhat(draws) -> float:
    """Rank-normalised split R-hat: the larger of the bulk and the folded (tail) R-hat. [-]

    Parameters
    ----------
    draws : array_like
        Shape (chains, draws) of one parameter.

    Returns
    -------
    float
        1 for chains that sample the same distribution; above :data:`RHAT_MAX`, not mixed.

    References
    ----------
    Vehtari et al. (2021), doi:10.1214/20-BA1221, section 4.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> round(split_rhat(rng.normal(size=(4, 1000))), 2)
    1.0
    >>> split_rhat(rng.normal(size=(4, 1000)) + np.arange(4)[:, None]) > 1.5
    True
    """
    x = _usable_split(draws)
    if x is None:
        return float("nan")
    bulk = _rhat(_rank_normalise(x))
    folded = np.abs(x - np.median(x))
    tail = _rhat(_rank_normalise(folded))
    return max(bulk, tail)


def _autocovariance(x: np.ndarray) -> np.ndarray:
    """Biased autocovariance of each chain (rows), by FFT."""
    n = x.shape[1]
    size = 2 ** int(np.ceil(np.log2(2 * n)))
    y = x - x.mean(axis=1, keepdims=True)
    f = np.fft.rfft(y, n=size, axis=1)
    return np.fft.irfft(f * np.conjugate(f), n=size, axis=1)[:, :n] / n


def _ess(x: np.ndarray) -> float:
    """Effective sample size of (chains, draws) by Geyer's initial monotone sequence (Vehtari et al. 2021, eq. 10-13)."""
    m, n = x.shape
    acov = _autocovariance(x)
    chain_mean = x.mean(axis=1)
    mean_var = np.mean(acov[:, 0]) * n / (n - 1)
    var_plus = mean_var * (n - 1) / n + (np.var(chain_mean, ddof=1) if m > 1 else 0.0)
    rho = np.zeros(n)
    rho[0] = 1.0
    rho_even, rho_odd = 1.0, 1.0 - (mean_var - np.mean(acov[:, 1])) / var_plus
    rho[1] = rho_odd
    t = 1
    while t < n - 3 and rho_even + rho_odd > 0.0:  # Geyer's initial positive sequence
        rho_even = 1.0 - (mean_var - np.mean(acov[:, t + 1])) / var_plus
        rho_odd = 1.0 - (mean_var - np.mean(acov[:, t + 2])) / var_plus
        if rho_even + rho_odd >= 0:
            rho[t + 1], rho[t + 2] = rho_even, rho_odd
        t += 2
    last = t - 2
    if rho_even > 0:  # the last even term improves the estimate (as ArviZ and Stan)
        rho[last + 1] = rho_even
    t = 1
    while t <= last - 2:  # Geyer's initial monotone sequence
        if rho[t + 1] + rho[t + 2] > rho[t - 1] + rho[t]:
            rho[t + 1] = (rho[t - 1] + rho[t]) / 2.0
            rho[t + 2] = rho[t + 1]
        t += 2
    tau = -1.0 + 2.0 * np.sum(rho[: last + 1]) + np.sum(rho[last + 1: last + 2])
    tau = max(tau, 1.0 / np.log10(m * n))  # the bound Stan and ArviZ use for antithetic chains
    return float(m * n / tau)


def ess_bulk(draws) -> float:
    """Bulk effective sample size: ESS of the rank-normalised split chains. [draws]

    Parameters
    ----------
    draws : array_like
        Shape (chains, draws) of one parameter.

    Returns
    -------
    float

    References
    ----------
    Vehtari et al. (2021), doi:10.1214/20-BA1221, section 3.2; Geyer (1992), doi:10.1214/ss/1177011137.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> 3000 < ess_bulk(rng.normal(size=(4, 1000))) < 5000
    True
    """
    x = _usable_split(draws)
    return float("nan") if x is None else _ess(_rank_normalise(x))
