"""Calibration of the posterior intervals: do the 95 % intervals cover the generating values?

:func:`posterior_coverage` makes ``n_datasets`` seeded SYNTHETIC e_n(v) data sets from known
zeta_H, zeta_A (:func:`microimpact.analysis.synthetic.make_synthetic_impacts`, seeds
``first_seed`` ...), fits each (:func:`~microimpact.analysis.fitting.fit_damping`), samples its
posterior (:func:`~microimpact.analysis.posterior.sample_posterior`) and records whether each
parameter's equal-tailed 95 % credible interval contains the generating value. Calibrated
intervals cover in about 95 % of the cases; with N intervals the binomial standard deviation is
sqrt(0.95 x 0.05 / N) (3 % for N = 50 per parameter).

Run ``python -m microimpact.analysis.coverage --out docs/posterior_coverage.json`` (several minutes);
the committed result is read by ``tests/test_posterior.py``.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
import pandas as pd

from microimpact.io.files import atomic_write

__all__ = ["posterior_coverage", "COVERAGE_SETUP"]

#: the study's setup (recorded with the result)
COVERAGE_SETUP = dict(n_datasets=50, first_seed=1000, radii=(1.29e-6, 3.45e-6), n_per_radius=12, walkers=16,
                      steps=600, burn=200, level=0.95)


def posterior_coverage(n_datasets: int = 50, *, first_seed: int = 1000, radii=(1.29e-6, 3.45e-6), n_per_radius: int = 12,
                       walkers: int = 16, steps: int = 600, burn: int = 200, level: float = 0.95,
                       progress: bool = False, time_budget: float | None = None) -> pd.DataFrame:
    """One row per data set: the fitted and posterior values and whether each interval covers.

    Parameters
    ----------
    n_datasets : int
        Number of seeded synthetic data sets.
    first_seed : int
        Seed of the first; the others follow.
    radii : tuple of float
        Sphere radii of each data set. [m]
    n_per_radius : int
        Impacts per radius.
    walkers, steps, burn : int
        Sampler settings.
    level : float
        Credible level of the intervals. [-]
    progress : bool
        Print one line per data set to stderr.
    time_budget : float, optional
        Wall-clock budget of the whole study (the fits and chains share it); None: no limit. [s]

    Returns
    -------
    pandas.DataFrame
        ``seed``, and per parameter p in (zeta_hertz, zeta_adhesion): ``p_true``, ``p_fit``,
        ``p_stderr``, ``p_low``, ``p_high``, ``p_covered``, ``p_tau``; ``acceptance``, ``seconds``.

    Raises
    ------
    TimeBudgetExceeded
        The study ran past ``time_budget``; the message names the stage and how far it got.
    """
    import sys

    from microimpact.analysis.fitting import fit_damping
    from microimpact.analysis.posterior import sample_posterior
    from microimpact.analysis.synthetic import SYNTHETIC_DEFAULTS, make_synthetic_impacts
    from microimpact.io.impacts import read_impacts
    from microimpact.io.files import write_csv
    from microimpact.solvers import Deadline
    import tempfile
    from pathlib import Path
    from types import SimpleNamespace

    deadline = Deadline.start(time_budget, "coverage study")
    truth = {k: SYNTHETIC_DEFAULTS[k] for k in ("zeta_hertz", "zeta_adhesion")}
    base = SimpleNamespace(**{k: SYNTHETIC_DEFAULTS[k] for k in ("density", "stiffness", "work_of_adhesion", "friction")},
                           damping_reference_speed=None)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(n_datasets):
            t0 = time.perf_counter()
            seed = first_seed + k
            path = Path(tmp) / f"coverage_{seed}.csv"
            write_csv(make_synthetic_impacts(seed=seed, radii=tuple(radii), n_per_radius=n_per_radius), path,
                      float_format="%.6g")
            table = read_impacts(path)
            fit = fit_damping(table, base, confidence_intervals=False, time_budget=deadline)
            post = sample_posterior(table, fit, walkers=walkers, steps=steps, burn=burn, seed=seed,
                                    time_budget=deadline, require_convergence=False)
            row = {"seed": seed}
            for p, true in truth.items():
                lo, hi = post.interval(p, level)
                row |= {f"{p}_true": true, f"{p}_fit": fit.values[p], f"{p}_stderr": fit.stderr[p], f"{p}_low": lo,
                        f"{p}_high": hi, f"{p}_covered": bool(lo <= true <= hi), f"{p}_tau": post.autocorr_time[p]}
            row |= {"acceptance": float(post.acceptance_fraction.mean()), "seconds": time.perf_counter() - t0}
            rows.append(row)
            deadline.check(f"{len(rows)} of {n_datasets} data sets")
            if progress:
                print(f"coverage: data set {k + 1}/{n_datasets} (seed {seed}): "
                      + ", ".join(f"{p} {'in' if row[f'{p}_covered'] else 'OUT'}" for p in truth)
                      + f", {row['seconds']:.1f} s", file=sys.stderr, flush=True)
    return pd.DataFrame(rows)


def summarise(df: pd.DataFrame, setup: dict) -> dict:
    """The coverage per parameter and overall, with the setup, for the committed JSON."""
    names = ("zeta_hertz", "zeta_adhesion")
    cov = {p: int(df[f"{p}_covered"].sum()) for p in names}
    total = len(df) * len(names)
    return {"setup": setup, "n_datasets": len(df), "covered": cov, "intervals": total,
            "covered_total": int(sum(cov.values())), "coverage": sum(cov.values()) / total,
            "coverage_per_parameter": {p: cov[p] / len(df) for p in names},
            "max_autocorr_time": float(max(df[f"{p}_tau"].max() for p in names)),
            "mean_acceptance": float(df["acceptance"].mean()),
            "per_dataset": df.to_dict(orient="records")}


def main(argv=None) -> int:
    """``python -m microimpact.analysis.coverage --out docs/posterior_coverage.json``."""
    ap = argparse.ArgumentParser(description="posterior interval coverage over seeded synthetic data sets")
    ap.add_argument("--out", required=True, help="JSON result")
    ap.add_argument("--n", type=int, default=COVERAGE_SETUP["n_datasets"])
    args = ap.parse_args(argv)
    setup = dict(COVERAGE_SETUP) | {"n_datasets": args.n}
    df = posterior_coverage(args.n, **{k: v for k, v in setup.items() if k != "n_datasets"}, progress=True)
    summary = summarise(df, setup | {"radii": list(setup["radii"])})
    with atomic_write(args.out) as fh:  # a study of minutes: an interruption leaves the old file whole
        json.dump(summary, fh, indent=1, default=float)
    print(f"coverage {summary['covered_total']}/{summary['intervals']} = {100 * summary['coverage']:.1f} %")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
