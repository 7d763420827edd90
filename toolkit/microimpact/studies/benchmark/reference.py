"""Reference values of the benchmark and the bound on their own error.

DOP853 on the full 3-D equations (:func:`microimpact.solvers.reference.simulate_reference`) at the
tight rtol of :attr:`BenchmarkConfig.reference_rtols` is the reference. Its error is bounded, not
assumed: the bound is the larger of |DOP853 - engine| at that rtol (two independent integrators
and codes) and |DOP853(loose) - DOP853(tight)| (self-convergence), over the test set.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from microimpact.solvers import engine
from microimpact.studies.benchmark.harness import ObliqueResults, engine_oblique, log, run_reference

__all__ = ["Reference", "reference_set"]

#: Wall-clock limit of one reference impact. [s]
REFERENCE_TIME_LIMIT = 120.0


@dataclass(frozen=True)
class Reference:
    """Reference values and the bound on their error.

    Attributes
    ----------
    e_n : numpy.ndarray
        Reference e_n at the normal speeds. [-]
    oblique : ObliqueResults
        Reference results of the oblique cases.
    bound : dict
        ``e_n``, ``mu``, ``K_L`` (the bounds) and their parts ``*_engine``, ``*_self``;
        ``outcome_mismatch``, ``missing_cases`` and ``seconds`` [s].
    per_case : list of dict
        Per oblique case: inputs, the two outcomes and |engine - reference| of mu_t, mu_t', K_L.

    Examples
    --------
    See :func:`reference_set`.

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.studies.benchmark.cases import BenchmarkConfig, oblique_cases
    >>> ref = reference_set(WALL_1990, [2.0], oblique_cases(quick=True)[:1], BenchmarkConfig.quick_())
    >>> sorted(k for k in ref.bound if not k.endswith(("_engine", "_self")))
    ['K_L', 'e_n', 'missing_cases', 'mu', 'outcome_mismatch', 'seconds']
    """

    e_n: np.ndarray
    oblique: ObliqueResults
    bound: dict
    per_case: list


def _max_abs_diff(a, b) -> float:
    d = np.abs(np.asarray(a) - np.asarray(b))
    return float(np.nanmax(d)) if np.any(np.isfinite(d)) else math.nan


def _bound(e_tight, e_loose, e_engine, tight: ObliqueResults, loose: ObliqueResults, eng: ObliqueResults) -> dict:
    ok = np.isfinite(tight.K_L)
    reb = ok & ~tight.captured & ~eng.captured & ~loose.captured

    def mu_diff(other):
        if not reb.any():
            return math.nan
        return max(_max_abs_diff(tight.mu_t[reb], other.mu_t[reb]), _max_abs_diff(tight.mu_tp[reb], other.mu_tp[reb]))

    bound = {
        "e_n_engine": _max_abs_diff(e_tight, e_engine),
        "e_n_self": _max_abs_diff(e_tight, e_loose),
        "mu_engine": mu_diff(eng),
        "mu_self": mu_diff(loose),
        "K_L_engine": _max_abs_diff(tight.K_L[ok], eng.K_L[ok]) if ok.any() else math.nan,
        "K_L_self": _max_abs_diff(tight.K_L[ok], loose.K_L[ok]) if ok.any() else math.nan,
        "outcome_mismatch": int(np.sum(ok & (tight.captured != eng.captured))),
        "missing_cases": int(np.sum(~ok)),
    }
    bound["e_n"] = max(bound["e_n_engine"], bound["e_n_self"])
    bound["mu"] = float(np.nanmax([bound["mu_engine"], bound["mu_self"]]))
    bound["K_L"] = float(np.nanmax([bound["K_L_engine"], bound["K_L_self"]]))
    return bound


def _per_case(cases, tight: ObliqueResults, eng: ObliqueResults) -> list[dict]:
    """Disagreement of the two formulations per oblique case (for the report)."""
    return [{
        "case": j, **{k: getattr(case, k) for k in case.__dataclass_fields__},
        "outcome_reference": "capture" if tight.captured[j] else "rebound",
        "outcome_engine": "capture" if eng.captured[j] else "rebound",
        "d_mu_t": float(abs(tight.mu_t[j] - eng.mu_t[j])),
        "d_mu_tp": float(abs(tight.mu_tp[j] - eng.mu_tp[j])),
        "d_K_L": float(abs(tight.K_L[j] - eng.K_L[j])),
        "reference_timeout": bool(tight.timeout[j]),
        "reference_failed": tight.failed[j],
    } for j, case in enumerate(cases)]


def reference_set(contact, speeds, cases, cfg, verbose: bool = False) -> Reference:
    """Reference values (DOP853 at the tight rtol, atol = rtol / 100) and the bound on their error.

    Examples
    --------
    Two normal speeds and two oblique cases of the 1990 wall sphere: the scipy DOP853 reference and
    the engine agree to about 1e-12 at rtol 1e-12, and the reference's own error bound is as small:

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.studies.benchmark.cases import BenchmarkConfig, oblique_cases
    >>> ref = reference_set(WALL_1990, [2.0, 5.0], oblique_cases(quick=True)[:2], BenchmarkConfig.quick_())
    >>> ref.e_n.round(6).tolist(), ref.bound["outcome_mismatch"], ref.bound["e_n"] < 1e-10
    ([0.442528, 0.667963], 0, True)
    """
    r_loose, r_tight = cfg.reference_rtols
    log(f"reference: DOP853 at rtol {r_tight:g} and {r_loose:g}, engine at {r_tight:g}", verbose)
    t0 = time.perf_counter()
    e_t, _, tight = run_reference(contact, speeds, cases, r_tight, atol=r_tight * 1e-2, limit=REFERENCE_TIME_LIMIT)
    e_l, _, loose = run_reference(contact, speeds, cases, r_loose, atol=r_loose * 1e-2, limit=REFERENCE_TIME_LIMIT)
    e_eng = np.array([engine.solve_normal(contact, float(v), rtol=r_tight).e_n for v in speeds])
    eng = engine_oblique(contact, cases, r_tight)
    bound = _bound(e_t, e_l, e_eng, tight, loose, eng)
    bound["seconds"] = time.perf_counter() - t0
    return Reference(e_t, tight, bound, _per_case(cases, tight, eng))
