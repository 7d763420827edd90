"""The posterior of the bundled data by ``method="solve"`` and ``method="emulator"`` side by side.

One process: the damping fit of data/synthetic_microspheres.csv (as ``microimpact fit``, without
profile intervals), then :func:`microimpact.analysis.posterior.sample_posterior` by each method with
the same seed until converged. Printed and written as JSON: the CPU time of each
(``time.process_time``; the emulator's table is loaded or built before, its cold build timed on its
own), their ratio, and for every parameter the median and the 2.5 % and 97.5 % quantiles of both
chains with their Monte Carlo standard errors (from the bulk effective sample size, normal
approximation: sd sqrt(p (1 - p) / ESS) / phi(z_p)) and the difference in units of the combined
error::

    python tests/study_posterior_speed.py --out docs/posterior-speed.json

With the same seed the two chains see the same random numbers; likelihoods that differ by far less
than one unit of log-probability take the same accept/reject decisions, so the quantiles may agree
exactly: the comparison then shows that the emulator did not move a single decision.

Exit status 0. Nothing is asserted: timings are not tests (tests/test_posterior_speed.py holds the tests).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
from scipy import stats

from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.posterior import EMULATOR_TOLERANCE, POSTERIOR_DOMAIN, sample_posterior
from microimpact.io import default_materials_path, read_impacts, read_materials
from microimpact.solvers import emulator

REPO = Path(__file__).resolve().parents[1]
PROBS = {"q025": 0.025, "median": 0.5, "q975": 0.975}


def _quantile_mcse(x, p, ess):
    """Monte Carlo standard error of the p-quantile of samples x with effective size ess (normal approximation)."""
    return float(np.std(x) * math.sqrt(p * (1 - p) / ess) / stats.norm.pdf(stats.norm.ppf(p)))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--tol", type=float, default=EMULATOR_TOLERANCE)
    args = ap.parse_args(argv)
    table = read_impacts(REPO / "data" / "synthetic_microspheres.csv")
    material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    fit = fit_damping(table, material, confidence_intervals=False)
    t = time.process_time()
    emulator.ring_emulator(emulator._table_tolerance(args.tol), POSTERIOR_DOMAIN)
    table_s = time.process_time() - t
    posts, cpu = {}, {}
    for method in ("solve", "emulator"):
        t = time.process_time()
        posts[method] = sample_posterior(table, fit, method=method, emulator_tol=args.tol)
        cpu[method] = time.process_time() - t
    rows = {}
    for name in posts["solve"].names:
        row = {}
        for method, post in posts.items():
            x = post.samples[:, post.names.index(name)]
            ess = post.info["ess_bulk"][name]
            row[method] = {k: float(np.quantile(x, p)) for k, p in PROBS.items()}
            row[method] |= {f"{k}_mcse": _quantile_mcse(x, p, ess) for k, p in PROBS.items()} | {"ess_bulk": ess}
        row["difference_in_mcse"] = {k: abs(row["solve"][k] - row["emulator"][k])
                                     / math.hypot(row["solve"][f"{k}_mcse"], row["emulator"][f"{k}_mcse"]) for k in PROBS}
        rows[name] = row
    out = {"data": "data/synthetic_microspheres.csv", "seed": posts["solve"].seed, "emulator_tol": args.tol,
           "cpu_s": cpu, "ratio_solve_over_emulator": cpu["solve"] / cpu["emulator"],
           "emulator_table_cpu_s (loaded or built before the chains)": table_s,
           "steps": {m: int(p.chain.shape[0]) for m, p in posts.items()}, "parameters": rows,
           "command": "python tests/study_posterior_speed.py --out docs/posterior-speed.json"}
    text = json.dumps(out, indent=2)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
