"""Study: do the recommended impacts narrow zeta_H more than the same number placed uniformly?

Over random hidden truths (zeta_H log-uniform in [0.1, 2], zeta_A log-uniform in [10, 80], w_A and
the material of Table 1, one radius), each with a random starting design of a few e_n impacts
(simulated with the toolkit's solver, Gaussian noise of SIGMA), the study fits the start, asks
:func:`microimpact.analysis.design.design_impacts` for N impacts, simulates them and the N of
:func:`~microimpact.analysis.design.uniform_design`, refits both and records the 95 % profile
interval width of zeta_H (a one-sided bound counts by the interval it gives, e.g. [0, upper]),
whether it covers the truth, and the Fisher (expected) widths. Output: a JSON with each truth's row
and the medians of the width ratio recommended / uniform.

    python tests/study_design.py --truths 12 --n 6 --seed 54 --out docs/design-study.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np
import pandas as pd

from microimpact.analysis.design import DesignSpace, design_impacts, uniform_design
from microimpact.analysis.fitting import FitProblem, fit_damping, model_restitution
from microimpact.io import default_materials_path, read_materials
from microimpact.io.files import atomic_write

RADIUS = 3.45e-6  # [m], Table 1
SIGMA = 0.02  # [-] e_n standard uncertainty
PAIR = "ammonium_fluorescein_on_silicon"


def _simulate(material, truth, speeds, rng):
    e = model_restitution(FitProblem.from_arrays(np.full(len(speeds), RADIUS), speeds, material),
                          truth["zeta_hertz"], truth["zeta_adhesion"], truth["work_of_adhesion"])
    return np.clip(e + rng.normal(0.0, SIGMA, e.size), 0.0, 1.0)


def _fit(material, speeds, e_n):
    table = pd.DataFrame({"radius": RADIUS, "normal_speed": speeds, "e_n": e_n, "e_n_uncertainty": SIGMA})
    return fit_damping(table, material, confidence_intervals=False)


def one_truth(material, space, n, rng) -> dict:
    """The row of one hidden truth (see the module docstring)."""
    truth = {"zeta_hertz": float(np.exp(rng.uniform(np.log(0.1), np.log(2.0)))),
             "zeta_adhesion": float(np.exp(rng.uniform(np.log(10.0), np.log(80.0)))),
             "work_of_adhesion": float(material.work_of_adhesion)}
    start_v = np.sort(np.exp(rng.uniform(np.log(1.0), np.log(10.0), 4)))
    start_e = _simulate(material, truth, start_v, rng)
    start = _fit(material, start_v, start_e)
    design = design_impacts(start, space, n, parameters=("zeta_hertz",))
    row = {"truth": truth, "start_speeds": start_v.tolist(), "start_status": start.identifiability["zeta_hertz"].status,
           "fisher_design": design.width("zeta_hertz"), "fisher_uniform": design.width("zeta_hertz", which="uniform"),
           "design_speeds": design.rows["speed"].tolist()}
    noise_seed = int(rng.integers(2**31))
    for name, speeds in (("design", design.rows["normal_speed"].to_numpy()),
                         ("uniform", uniform_design(space, n)["normal_speed"].to_numpy())):
        e = _simulate(material, truth, speeds, np.random.default_rng(noise_seed))  # same noise draws for both
        st = _fit(material, np.concatenate([start_v, speeds]), np.concatenate([start_e, e])).identifiability["zeta_hertz"]
        row[f"refit_{name}"] = {"status": st.status, "lower": st.lower, "upper": st.upper, "width": st.upper - st.lower,
                                "covers": bool(st.lower <= truth["zeta_hertz"] <= st.upper)}
    return row


def summary(rows) -> dict:
    """Medians of the width ratios and the coverage of each design."""
    refit = [r["refit_design"]["width"] / r["refit_uniform"]["width"] for r in rows]
    fisher = [r["fisher_design"] / r["fisher_uniform"] for r in rows]
    return {"truths": len(rows), "median_refit_width_ratio": float(np.median(refit)),
            "median_fisher_width_ratio": float(np.median(fisher)),
            "refit_ratio_below_1": int(sum(x < 1 for x in refit)),
            "coverage_design": float(np.mean([r["refit_design"]["covers"] for r in rows])),
            "coverage_uniform": float(np.mean([r["refit_uniform"]["covers"] for r in rows])),
            "determined_design": int(sum(r["refit_design"]["status"] == "determined" for r in rows)),
            "determined_uniform": int(sum(r["refit_uniform"]["status"] == "determined" for r in rows)),
            "determined_start": int(sum(r["start_status"] == "determined" for r in rows))}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--truths", type=int, default=12)
    p.add_argument("--n", type=int, default=6, help="new impacts per design")
    p.add_argument("--seed", type=int, default=54)
    p.add_argument("--out", default=None, help="JSON file (default: print)")
    args = p.parse_args(argv)
    material = read_materials(default_materials_path())[PAIR]
    space = DesignSpace(radii=(RADIUS,), speed_range=(0.5, 20.0), e_n_sigma=SIGMA, n_speeds=25)
    rng = np.random.default_rng(args.seed)
    rows = []
    for k in range(args.truths):
        rows.append(one_truth(material, space, args.n, rng))
        r = rows[-1]
        print(f"truth {k + 1}/{args.truths}: zeta_H = {r['truth']['zeta_hertz']:.3g}, widths design "
              f"{r['refit_design']['width']:.3g} / uniform {r['refit_uniform']['width']:.3g}", file=sys.stderr)
    result = {"command": "python tests/study_design.py " + " ".join(argv if argv is not None else sys.argv[1:]),
              "setup": {"radius": RADIUS, "e_n_sigma": SIGMA, "speed_range": list(space.speed_range),
                        "n_speeds": space.n_speeds, "speed_sigma": space.speed_sigma, "n_new": args.n, "seed": args.seed,
                        "criterion": "A-optimal on zeta_H by the linearised Fisher information",
                        "material_pair": PAIR},
              "summary": summary(rows), "rows": rows}
    text = json.dumps(result, indent=1, default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else x)
    if args.out:
        with atomic_write(args.out) as f:
            f.write(text + "\n")
    else:
        print(text)
    print(json.dumps(result["summary"], indent=1), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
