"""Study: do the recommended impacts narrow zeta_H more than the same number placed uniformly?

Over random hidden truths (zeta_H log-uniform in [0.1, 2], zeta_A log-uniform in [10, 80], w_A and
the material of Table 1), each with a random starting design of a few e_n impacts at the radius of
Table 1
(simulated with the toolkit's solver, Gaussian noise of SIGMA), the study fits the start, asks
:func:`microimpact.analysis.design.design_impacts` for N impacts, simulates them and the N of
:func:`~microimpact.analysis.design.uniform_design`, refits both and records the 95 % profile
interval width of zeta_H (a one-sided bound counts by the interval it gives, e.g. [0, upper]),
whether it covers the truth, and the Fisher (expected) widths. Output: a JSON with each truth's row
and the medians of the width ratio recommended / uniform, the coverage with its binomial Monte Carlo
error.

Friction: each truth also draws a Coulomb coefficient f log-uniform in FRICTION_RANGE and a start
of three oblique impacts at 10-30 deg (e_t measured, sigma SIGMA_T), which end rolling for most f
and leave f not determined. With the damping refitted after the recommended impacts,
:func:`~microimpact.analysis.design.design_friction` recommends N_FRICTION oblique impacts; the
study simulates them (the solver's closed-form tangential map at the truth) and the same number
spread uniformly over the same angles, speeds and sizes, refits f with
:func:`~microimpact.analysis.oblique.fit_friction` and records its status and coverage. The
friction draws use their own random stream, so the damping rows do not depend on them.

Size classes: ``--radii`` gives the sizes the laboratory can measure (default: Table 1's one). With
several, the candidates and the uniform designs (sizes cycled) span them all, while the start stays
at Table 1's radius; the multi-size case of docs/design-study-sizes.json uses 1.29, 3.45 and 6.9 um.

    python tests/study_design.py --truths 50 --n 6 --seed 54 --out docs/design-study.json
    python tests/study_design.py --replot docs/design-study.json --figure docs/design-study.png
    python tests/study_design.py --truths 50 --n 6 --seed 54 --radii 1.29e-6,3.45e-6,6.9e-6 --out docs/design-study-sizes.json
    python tests/study_design.py --replot docs/design-study-sizes.json --figure docs/design-study-sizes.png
"""

from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np
import pandas as pd

from microimpact.analysis.design import (FRICTION_RANGE, OBLIQUE_ANGLES_DEG, DesignSpace, design_friction,
                                         design_impacts, uniform_design, uniform_oblique_design)
from microimpact.analysis.fitting import FitProblem, fit_damping, model_restitution
from microimpact.analysis.oblique import fit_friction, rebound_state
from microimpact.io import default_materials_path, read_materials
from microimpact.io.files import atomic_write

RADIUS = 3.45e-6  # [m], Table 1
SIGMA = 0.02  # [-] e_n standard uncertainty
PAIR = "ammonium_fluorescein_on_silicon"
SIGMA_T = 0.02  # [-] e_t standard uncertainty
N_FRICTION = 6  # new oblique impacts per friction design
START_ANGLES = (10.0, 20.0, 30.0)  # [deg] the oblique start: rolling for most f, f not determined


def friction_space(radii) -> DesignSpace:
    """The oblique space: the design's default angles (20-85 deg), 2-20 m/s, the study's sizes."""
    return DesignSpace(radii=tuple(radii), speed_range=(2.0, 20.0), incidence_deg=OBLIQUE_ANGLES_DEG,
                       e_t_sigma=SIGMA_T, n_speeds=10)


def _simulate(material, truth, radii, speeds, rng):
    e = model_restitution(FitProblem.from_arrays(radii, speeds, material),
                          truth["zeta_hertz"], truth["zeta_adhesion"], truth["work_of_adhesion"])
    return np.clip(e + rng.normal(0.0, SIGMA, e.size), 0.0, 1.0)


def _fit(material, radii, speeds, e_n):
    table = pd.DataFrame({"radius": radii, "normal_speed": speeds, "e_n": e_n, "e_n_uncertainty": SIGMA})
    return fit_damping(table, material, confidence_intervals=False)


def _oblique_table(material, truth, friction, rows, rng):
    """Oblique impacts (radius, speed, incidence_deg) with e_n and e_t of the truth plus noise."""
    radius = rows["radius"].to_numpy(float) if "radius" in rows.columns else np.full(len(rows), RADIUS)
    speed, angle = rows["speed"].to_numpy(float), rows["incidence_deg"].to_numpy(float)
    vt = np.empty(speed.size)
    e_n = np.empty(speed.size)
    for r in np.unique(radius):
        i = radius == r
        c = material.contact(float(r)).with_(zeta_hertz=truth["zeta_hertz"], zeta_adhesion=truth["zeta_adhesion"],
                                             friction=friction)
        out = rebound_state(c, speed[i], angle[i], np.zeros(int(i.sum())))
        vt[i] = out["velocity_out_t"]
        e_n[i] = np.where(out["captured"], 0.0, out["velocity_out_n"] / (speed[i] * np.cos(np.radians(angle[i]))))
    vt_in = speed * np.sin(np.radians(angle))
    return pd.DataFrame({"radius": radius, "speed": speed, "incidence_deg": angle, "e_n": e_n,
                         "tangential_restitution": vt / vt_in + rng.normal(0.0, SIGMA_T, speed.size),
                         "tangential_restitution_uncertainty": SIGMA_T})


def _friction_status(material, truth, friction, tables, damping):
    st = fit_friction(pd.concat(tables, ignore_index=True), damping).identifiability["friction"]
    return {"status": st.status, "lower": st.lower, "upper": st.upper, "width": st.upper - st.lower,
            "covers": bool(st.lower <= friction <= st.upper)}


def friction_truth(material, truth, damping, space, rng) -> dict:
    """The friction part of one truth: start, recommended and uniform oblique designs, refitted."""
    friction = float(np.exp(rng.uniform(*np.log(FRICTION_RANGE))))
    start_rows = pd.DataFrame({"speed": np.exp(rng.uniform(np.log(5.0), np.log(20.0), len(START_ANGLES))),
                               "incidence_deg": START_ANGLES})
    start = _oblique_table(material, truth, friction, start_rows, rng)
    start = start[start["e_n"] > 0]
    row = {"friction": friction, "start": [dict(zip(("speed", "incidence_deg"), x))
                                           for x in start_rows.itertuples(index=False)]}
    row["refit_start"] = _friction_status(material, truth, friction, [start], damping)
    design = design_friction(damping, space, N_FRICTION, existing=start.assign(radius=RADIUS))
    noise_seed = int(rng.integers(2**31))
    row["design_rows"] = design.rows[["radius", "speed", "incidence_deg"]].to_dict("records")
    for name, rows in (("design", design.rows), ("uniform", uniform_oblique_design(space, N_FRICTION))):
        new = _oblique_table(material, truth, friction, rows, np.random.default_rng(noise_seed))
        row[f"refit_{name}"] = _friction_status(material, truth, friction, [start, new[new["e_n"] > 0]], damping)
    return row


def one_truth(material, space, n, rng, friction_rng=None) -> dict:
    """The row of one hidden truth (see the module docstring)."""
    truth = {"zeta_hertz": float(np.exp(rng.uniform(np.log(0.1), np.log(2.0)))),
             "zeta_adhesion": float(np.exp(rng.uniform(np.log(10.0), np.log(80.0)))),
             "work_of_adhesion": float(material.work_of_adhesion)}
    start_v = np.sort(np.exp(rng.uniform(np.log(1.0), np.log(10.0), 4)))
    start_r = np.full(start_v.size, RADIUS)
    start_e = _simulate(material, truth, start_r, start_v, rng)
    start = _fit(material, start_r, start_v, start_e)
    design = design_impacts(start, space, n, parameters=("zeta_hertz",))
    row = {"truth": truth, "start_speeds": start_v.tolist(), "start_status": start.identifiability["zeta_hertz"].status,
           "fisher_design": design.width("zeta_hertz"), "fisher_uniform": design.width("zeta_hertz", which="uniform"),
           "design_speeds": design.rows["speed"].tolist(), "design_radii": design.rows["radius"].tolist()}
    noise_seed = int(rng.integers(2**31))
    fits = {}
    for name, rows in (("design", design.rows), ("uniform", uniform_design(space, n))):
        radii, speeds = rows["radius"].to_numpy(float), rows["normal_speed"].to_numpy(float)
        e = _simulate(material, truth, radii, speeds, np.random.default_rng(noise_seed))  # same noise draws for both
        refit = _fit(material, np.concatenate([start_r, radii]), np.concatenate([start_v, speeds]),
                     np.concatenate([start_e, e]))
        st = refit.identifiability["zeta_hertz"]
        row[f"refit_{name}"] = {"status": st.status, "lower": st.lower, "upper": st.upper, "width": st.upper - st.lower,
                                "covers": bool(st.lower <= truth["zeta_hertz"] <= st.upper)}
        fits[name] = refit
    if friction_rng is not None:
        row["friction"] = friction_truth(material, truth, fits["design"], friction_space(space.radii), friction_rng)
    return row


def _coverage(hits) -> dict:
    """Fraction, its binomial Monte Carlo standard error at 95 % (sqrt(0.95 x 0.05 / n)) and the
    distance from 95 % in those errors."""
    n = len(hits)
    p = float(np.mean(hits)) if n else math.nan
    se = math.sqrt(0.95 * 0.05 / n) if n else math.nan
    return {"fraction": p, "n": n, "mc_standard_error_at_95": se, "z_from_95": (p - 0.95) / se if n else math.nan}


def friction_summary(rows) -> dict:
    """Of the truths whose start leaves f not determined: how many each design determines, and coverage."""
    fr = [r["friction"] for r in rows if "friction" in r]
    open_ = [r for r in fr if r["refit_start"]["status"] != "determined"]
    out = {"truths": len(fr), "start_not_determined": len(open_)}
    for name in ("design", "uniform"):
        det = [r["refit_" + name]["status"] == "determined" for r in open_]
        out[f"determined_{name}"] = int(sum(det))
        out[f"determined_fraction_{name}"] = float(np.mean(det)) if det else math.nan
        out[f"coverage_{name}"] = _coverage([r["refit_" + name]["covers"] for r in fr])
    both = [r["refit_design"]["width"] / r["refit_uniform"]["width"] for r in fr
            if r["refit_design"]["status"] == r["refit_uniform"]["status"] == "determined"]
    out["median_width_ratio_both_determined"] = float(np.median(both)) if both else math.nan
    out["both_determined"] = len(both)
    return out


def summary(rows) -> dict:
    """Medians of the width ratios and the coverage of each design."""
    refit = [r["refit_design"]["width"] / r["refit_uniform"]["width"] for r in rows]
    fisher = [r["fisher_design"] / r["fisher_uniform"] for r in rows]
    return {"truths": len(rows), "median_refit_width_ratio": float(np.median(refit)),
            "refit_width_ratio_quartiles": [float(np.quantile(refit, 0.25)), float(np.quantile(refit, 0.75))],
            "coverage_design_mc": _coverage([r["refit_design"]["covers"] for r in rows]),
            "coverage_uniform_mc": _coverage([r["refit_uniform"]["covers"] for r in rows]),
            "friction": friction_summary(rows),
            "median_fisher_width_ratio": float(np.median(fisher)),
            "refit_ratio_below_1": int(sum(x < 1 for x in refit)),
            "coverage_design": float(np.mean([r["refit_design"]["covers"] for r in rows])),
            "coverage_uniform": float(np.mean([r["refit_uniform"]["covers"] for r in rows])),
            "determined_design": int(sum(r["refit_design"]["status"] == "determined" for r in rows)),
            "determined_uniform": int(sum(r["refit_uniform"]["status"] == "determined" for r in rows)),
            "determined_start": int(sum(r["start_status"] == "determined" for r in rows))}


def draw_figure(result: dict, path) -> None:
    """Left: the refitted zeta_H width, recommended against uniform, per truth; right: the friction
    status of each truth after its start, the recommended and the uniform oblique impacts."""
    from matplotlib.figure import Figure  # a study's figure: matplotlib only when asked for
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    rows = result["rows"]
    fig = Figure(figsize=(8.0, 3.4), layout="constrained")
    ax, bx = fig.subplots(1, 2)
    w_d = np.array([r["refit_design"]["width"] for r in rows])
    w_u = np.array([r["refit_uniform"]["width"] for r in rows])
    cov = np.array([r["refit_design"]["covers"] for r in rows])
    ax.loglog(w_u[cov], w_d[cov], "o", ms=3.5, label="covers the truth")
    ax.loglog(w_u[~cov], w_d[~cov], "x", ms=5, color="C3", label="misses it")
    lim = [min(w_d.min(), w_u.min()) * 0.8, max(w_d.max(), w_u.max()) * 1.2]
    ax.plot(lim, lim, "k-", lw=0.7, label="equal")
    ax.plot(lim, np.array(lim) / 1.5, "k--", lw=0.7, label="1.5x narrower")
    ax.set_xlabel("95 % width of zeta_H, uniform [-]")
    ax.set_ylabel("95 % width of zeta_H, recommended [-]")
    sizes = ", ".join(f"{2e6 * r:.3g}" for r in result["setup"].get("radii", [result["setup"]["radius"]]))
    ax.set_title(f"median ratio {result['summary']['median_refit_width_ratio']:.2f} ({len(rows)} truths; "
                 f"d = {sizes} um)", fontsize=9)
    ax.legend(fontsize=7, frameon=False)
    ticks = [t for t in (0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0) if lim[0] <= t <= lim[1]]
    for axis in (ax.xaxis, ax.yaxis):  # plain labels at 1-2-5, no crowded minor ones
        axis.set_ticks(ticks)
        axis.set_major_formatter(ScalarFormatter())
        axis.set_minor_formatter(NullFormatter())
    statuses = ["determined", "lower_bound", "upper_bound", "not_determined"]
    fr = [r["friction"] for r in rows if "friction" in r]
    counts = {k: [sum(r[k]["status"] == s for r in fr) for s in statuses]
              for k in ("refit_start", "refit_design", "refit_uniform")}
    x = np.arange(len(statuses))
    for i, (k, label) in enumerate((("refit_start", "start (10-30 deg)"), ("refit_design", "+ recommended"),
                                    ("refit_uniform", "+ uniform"))):
        bx.bar(x + (i - 1) * 0.27, counts[k], 0.27, label=label)
    bx.set_xticks(x, [s.replace("_", "\n") for s in statuses], fontsize=8)
    bx.set_ylabel("truths")
    bx.set_title("friction status after the refit", fontsize=9)
    bx.legend(fontsize=7, frameon=False)
    fig.savefig(path, dpi=120)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--truths", type=int, default=50)
    p.add_argument("--n", type=int, default=6, help="new impacts per design")
    p.add_argument("--seed", type=int, default=54)
    p.add_argument("--radii", default=str(RADIUS), help="comma-separated size classes [m] (default Table 1's)")
    p.add_argument("--out", default=None, help="JSON file (default: print)")
    p.add_argument("--figure", default=None, help="PNG of the widths and the friction statuses")
    p.add_argument("--replot", default=None, metavar="JSON", help="draw --figure from a study's JSON, run nothing")
    args = p.parse_args(argv)
    if args.replot:
        with open(args.replot, encoding="utf-8") as f:
            draw_figure(json.load(f), args.figure or "design-study.png")
        return 0
    material = read_materials(default_materials_path())[PAIR]
    radii = tuple(float(r) for r in args.radii.split(","))
    space = DesignSpace(radii=radii, speed_range=(0.5, 20.0), e_n_sigma=SIGMA, n_speeds=25)
    rng = np.random.default_rng(args.seed)
    rows = []
    for k in range(args.truths):
        rows.append(one_truth(material, space, args.n, rng, np.random.default_rng([args.seed, k])))
        r = rows[-1]
        print(f"truth {k + 1}/{args.truths}: zeta_H = {r['truth']['zeta_hertz']:.3g}, widths design "
              f"{r['refit_design']['width']:.3g} / uniform {r['refit_uniform']['width']:.3g}; f = "
              f"{r['friction']['friction']:.3g}: start {r['friction']['refit_start']['status']}, design "
              f"{r['friction']['refit_design']['status']}, uniform {r['friction']['refit_uniform']['status']}",
              file=sys.stderr)
    result = {"command": "python tests/study_design.py " + " ".join(argv if argv is not None else sys.argv[1:]),
              "setup": {"radius": RADIUS, "radii": list(radii), "e_n_sigma": SIGMA, "speed_range": list(space.speed_range),
                        "n_speeds": space.n_speeds, "speed_sigma": space.speed_sigma, "n_new": args.n, "seed": args.seed,
                        "criterion": "A-optimal on zeta_H by the linearised Fisher information",
                        "friction": {"range": list(FRICTION_RANGE), "e_t_sigma": SIGMA_T, "n_new": N_FRICTION,
                                     "start_angles_deg": list(START_ANGLES),
                                     "angles_deg": list(OBLIQUE_ANGLES_DEG),
                                     "speed_range": list(friction_space(radii).speed_range),
                                     "criterion": "Bayesian A on ln f over the range (log-uniform)"},
                        "material_pair": PAIR},
              "summary": summary(rows), "rows": rows}
    text = json.dumps(result, indent=1, default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else x)
    if args.out:
        with atomic_write(args.out) as f:
            f.write(text + "\n")
    else:
        print(text)
    print(json.dumps(result["summary"], indent=1), file=sys.stderr)
    if args.figure:
        draw_figure(result, args.figure)
    return 0


if __name__ == "__main__":
    sys.exit(main())
