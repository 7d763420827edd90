"""Are the reported intervals calibrated? A simulation-based study over random experiment designs.

Every estimator of the toolkit reports, for each fitted parameter, a 95 % interval, a one-sided
bound, or "not determined" (:mod:`microimpact.analysis.identifiability`), and the posterior a
95 % credible interval (:mod:`microimpact.analysis.posterior`). This study checks that those
statements hold on data nobody here designed: it draws the TRUE parameters and the EXPERIMENT
DESIGN at random, simulates a measured-impact CSV from the model at the truth with the stated noise,
reads it as an analyst would (:func:`microimpact.io.read_impacts`), fits it
(:func:`~microimpact.analysis.fitting.fit_damping`, :func:`~microimpact.analysis.oblique.fit_friction`,
optionally :func:`~microimpact.analysis.posterior.sample_posterior`) and records whether each
reported interval or bound contains the truth. Coverage is reported per parameter and per kind of
design with its binomial Monte Carlo error.

What is drawn (one ``numpy.random.default_rng(seed + k)`` stream per design k)
------------------------------------------------------------------------------
* truth: zeta_H log-uniform in [0.05, 2], zeta_A in [3, 100], w_A in [0.05, 0.5] J/m^2,
  f in [0.03, 1] (the material's density and stiffness: Table 1 row 2);
* whether w_A is fitted (probability 2/3; its start value then off the truth by a factor
  log-uniform in [0.5, 2]); otherwise it is given exactly;
* 1-3 sphere radii log-uniform in [0.5, 10] um, 4-20 normal impacts per radius, speeds log-spaced
  from 1.02-3 times the capture velocity (or, in a third of the designs, from 10-30 times it:
  far above capture) up to a factor 2-100 above (at most 100 m/s); in a tenth of the designs all
  impacts of a radius at one speed (a design that cannot determine both damping coefficients);
* noise: e_n relative 0.5-5 %, speed relative 0-2 %, angle 0-1 deg;
* oblique rows (probability 2/3): 2-4 speeds x 2-6 incidence angles spanning a random part of
  5-80 deg, one measured column (tangential restitution, rebound angle or rebound spin) with
  0.5-5 % noise; small angles and large f make every impact roll (f then only bounded from below).

Kinds of design, from the truth (independently of what the fit says): for friction, ``all rolling``
(every oblique impact ends in rolling at the true f), ``all sliding`` or ``mixed``; for the damping
parameters, ``one speed`` or ``speed range``.

A developer's study, not part of the installed package: run it from the repository's root,
``python tests/study_calibration.py --designs 300 --posterior-designs 12 --workers 2 --seed 1000
--out docs/calibration.json --figure docs/calibration.png`` (docs/calibration.md holds its results;
``tests/test_calibration.py`` runs a quick form and checks the committed results).

References
----------
Talts, S., Betancourt, M., Simpson, D., Vehtari, A., Gelman, A. (2018). Validating Bayesian
inference algorithms with simulation-based calibration. arXiv:1804.06788.
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing as mp
import re
import sys
import tempfile
import time
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from microimpact._runtime.usage import parse_or_status
from microimpact.analysis.analyst_fit import analyse_impacts
from microimpact.analysis.dirty_data import DIRTY_MATERIAL_PAIR, make_outlier_impacts, make_thornton_impacts
from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.oblique import ObliqueProblem, _FrictionObjective, fit_friction
from microimpact.analysis.posterior import PosteriorError, sample_posterior
from microimpact.analysis.synthetic import make_synthetic_impacts, make_synthetic_oblique
from microimpact.dynamics.nonlinear import capture_velocity
from microimpact.io import default_materials_path, read_impacts, read_materials
from microimpact.io.files import atomic_path, atomic_write, write_csv
from microimpact.io.materials import material_contact
from microimpact.model.parameters import TABLE1_ROW2
from microimpact.solvers import Deadline, TimeBudgetExceeded, engine

__all__ = ["draw_design", "run_design", "calibration_study", "summarise", "plot_calibration", "markdown_tables", "main",
           "FITTED", "LEVEL"]

#: the parameters whose statements are checked
FITTED = ("zeta_hertz", "zeta_adhesion", "work_of_adhesion", "friction")
#: the level of every interval and bound checked
LEVEL = 0.95


def _logu(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def draw_design(seed: int) -> dict:
    """The truth and the experiment design of one data set (module docstring), from ``seed``.

    Parameters
    ----------
    seed : int

    Returns
    -------
    dict
        ``truth`` (zeta_hertz, zeta_adhesion, work_of_adhesion [J/m^2], friction), ``fit_work_of_adhesion``,
        ``work_of_adhesion_start`` [J/m^2], ``radii`` [m], ``n_per_radius``, ``start_factor``,
        ``max_speed`` [m/s], ``one_speed``, noise levels, ``oblique`` (None or its design).

    Examples
    --------
    >>> d = draw_design(1)
    >>> sorted(d["truth"])
    ['friction', 'work_of_adhesion', 'zeta_adhesion', 'zeta_hertz']
    >>> draw_design(1) == d
    True
    """
    rng = np.random.default_rng(seed)
    truth = {"zeta_hertz": _logu(rng, 0.05, 2.0), "zeta_adhesion": _logu(rng, 3.0, 100.0),
             "work_of_adhesion": _logu(rng, 0.05, 0.5), "friction": _logu(rng, 0.03, 1.0)}
    fit_wa = bool(rng.uniform() < 2 / 3)
    wa_start = truth["work_of_adhesion"] * (_logu(rng, 0.5, 2.0) if fit_wa else 1.0)
    n_radii = int(rng.integers(1, 4))
    radii = tuple(sorted(_logu(rng, 0.5e-6, 10e-6) for _ in range(n_radii)))
    far = bool(rng.uniform() < 1 / 3)
    start = _logu(rng, 10.0, 30.0) if far else _logu(rng, 1.02, 3.0)
    design = {"seed": int(seed), "truth": truth, "fit_work_of_adhesion": fit_wa, "work_of_adhesion_start": wa_start,
              "radii": radii, "n_per_radius": int(rng.integers(4, 21)), "start_factor": start,
              "span": _logu(rng, 2.0, 100.0), "one_speed": bool(rng.uniform() < 0.1), "far_above_capture": far,
              "e_n_rel_sd": _logu(rng, 0.005, 0.05), "speed_rel_sd": float(rng.uniform(0.0, 0.02)),
              "angle_sd_deg": float(rng.uniform(0.0, 1.0)), "oblique": None}
    if rng.uniform() < 2 / 3:
        lo = float(rng.uniform(5.0, 60.0))
        hi = float(rng.uniform(lo + 5.0, 80.0))
        design["oblique"] = {
            "radius": float(radii[int(rng.integers(n_radii))]),
            "speed_factors": tuple(sorted(_logu(rng, 1.5, 60.0) for _ in range(int(rng.integers(2, 5))))),
            "incidence_deg": tuple(np.linspace(lo, hi, int(rng.integers(2, 7))).round(3)),
            "column": ("tangential_restitution", "rebound_angle", "rebound_spin")[int(rng.integers(3))],
            "tangential_sd": _logu(rng, 0.005, 0.05), "seed": int(rng.integers(2**31))}
    return design


def _material(design: dict) -> dict:
    t = design["truth"]
    return dict(density=TABLE1_ROW2.density, stiffness=TABLE1_ROW2.stiffness, work_of_adhesion=t["work_of_adhesion"],
                zeta_hertz=t["zeta_hertz"], zeta_adhesion=t["zeta_adhesion"], friction=t["friction"],
                material_pair="ammonium_fluorescein_on_silicon")


def _simulate(design: dict, folder: Path) -> Path:
    """The design's measured-impact CSV, written to ``folder``."""

    mat = _material(design)
    frames = []
    for r in design["radii"]:
        vc = capture_velocity(material_contact(SimpleNamespace(**mat), r), solver_rtol=1e-10)
        first = design["start_factor"] * vc
        top = min(first * design["span"], 100.0) if not design["one_speed"] else first * (1 + 1e-9)
        frames.append(make_synthetic_impacts(**mat, radii=(r,), n_per_radius=design["n_per_radius"],
                                             start_factor=design["start_factor"], max_speed=max(top, first * 1.0001),
                                             e_n_rel_sd=design["e_n_rel_sd"], speed_rel_sd=design["speed_rel_sd"],
                                             angle_sd_deg=design["angle_sd_deg"],
                                             seed=design["seed"] + int(r * 1e9)))
    ob = design["oblique"]
    if ob is not None:
        vc = capture_velocity(material_contact(SimpleNamespace(**mat), ob["radius"]), solver_rtol=1e-10)
        speeds = tuple(min(vc * k, 100.0) for k in ob["speed_factors"])
        o = make_synthetic_oblique(**mat, radii=(ob["radius"],), speeds=speeds, incidence_deg=ob["incidence_deg"],
                                   e_n_rel_sd=design["e_n_rel_sd"], speed_rel_sd=design["speed_rel_sd"],
                                   angle_sd_deg=max(design["angle_sd_deg"], 0.05), tangential_column=ob["column"],
                                   tangential_sd=ob["tangential_sd"], seed=ob["seed"])
        frames.append(o)
    df = pd.concat(frames, ignore_index=True)
    df["id"] = [f"d{design['seed']}-{i}" for i in range(len(df))]
    path = folder / f"design_{design['seed']}.csv"
    write_csv(df, path, float_format="%.6g")
    return path


def _friction_kind(table, truth: dict, damping_fit) -> str | None:
    """'all rolling', 'all sliding' or 'mixed' at the TRUE f and damping, from the closed-form thresholds."""
    try:
        problem = ObliqueProblem.from_table(table)
    except ValueError:
        return None
    t = truth

    def contact_of(r):
        return material_contact(damping_fit, r, zeta_hertz=t["zeta_hertz"], zeta_adhesion=t["zeta_adhesion"],
                                work_of_adhesion=t["work_of_adhesion"])
    thresholds = _FrictionObjective(problem, contact_of, False, 1e-8).rolling_thresholds()
    rolls = thresholds <= t["friction"]
    return "all rolling" if rolls.all() else "all sliding" if not rolls.any() else "mixed"


def _statement(status) -> dict:
    return {"status": status.status, "value": status.value, "lower": status.lower, "upper": status.upper}


def _printed_relative_error(text: str, name: str) -> float:
    """The largest stderr / |value| of the lines ``name = value +/- stderr`` in ``text`` (NaN: none).

    Examples
    --------
    >>> _printed_relative_error("  friction = 0.25 +/- 0.05 (with ...)", "friction")
    0.2
    """
    found = [abs(float(s) / float(v)) for v, s in
             re.findall(rf"\b{re.escape(name)}\s*= ([-+0-9.eE]+) \+/- ([0-9.eE+-]+)", text) if float(v) != 0]
    return max(found) if found else math.nan


def run_design(design: dict, *, posterior: bool = False, folder: Path | None = None) -> dict:
    """Simulate, fit and check one design (see the module docstring).

    Parameters
    ----------
    design : dict
        From :func:`draw_design`.
    posterior : bool
        Also sample the posterior (default chain, until converged) and check its intervals.
    folder : pathlib.Path, optional
        Where the CSV is written (a temporary directory by default).

    Returns
    -------
    dict
        ``seed``, ``n_rows``, ``seconds`` (wall), ``cpu_seconds`` (this process's CPU), and per
        fitted parameter a record: ``truth``, ``kind``,
        the fit's ``status``, ``value``, ``lower``, ``upper``, ``covered``, ``printed_relative_error``
        (the relative standard error printed as a number, NaN where none is printed) and, with
        ``posterior``, ``posterior_lower``/``posterior_upper``/``posterior_covered`` (or
        ``posterior_error``). An error of the fit itself is recorded as ``error``.

    Examples
    --------
    Design 262 (one size, four normal impacts, w_A given: about a second): zeta_H is only bounded
    from above by so few impacts, zeta_A determined, and both statements hold the truth:

    >>> design = draw_design(262)
    >>> design["oblique"], design["n_per_radius"], design["fit_work_of_adhesion"]
    (None, 4, False)
    >>> record = run_design(design)
    >>> {n: (record[n]["status"], record[n]["covered"]) for n in ("zeta_hertz", "zeta_adhesion")}
    {'zeta_hertz': ('upper_bound', True), 'zeta_adhesion': ('determined', True)}
    """
    t0, c0 = time.perf_counter(), time.process_time()
    with tempfile.TemporaryDirectory() as tmp:
        path = _simulate(design, Path(folder or tmp))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            table = read_impacts(path)
    mat = _material(design)
    base = SimpleNamespace(density=mat["density"], stiffness=mat["stiffness"],
                           work_of_adhesion=design["work_of_adhesion_start"], friction=0.5, damping_reference_speed=None)
    out = {"seed": design["seed"], "n_rows": int(len(table)), "fit_work_of_adhesion": design["fit_work_of_adhesion"]}
    try:
        ObliqueProblem.from_table(table)
        oblique = True
    except ValueError:  # no oblique design, or every oblique impact captured: nothing to fit f from
        oblique = False
    try:
        fit = fit_damping(table, base, fit_work_of_adhesion=design["fit_work_of_adhesion"], confidence_intervals=False)
        ff = fit_friction(table, fit) if oblique else None
    except (ValueError, RuntimeError) as exc:
        return out | {"error": f"{type(exc).__name__}: {exc}", "seconds": time.perf_counter() - t0,
                      "cpu_seconds": time.process_time() - c0}
    damping_kind = "one speed" if design["one_speed"] else "speed range"
    statuses = dict(fit.identifiability)
    kinds = {n: damping_kind for n in statuses}
    stderr = dict(fit.stderr)
    if ff is not None:
        statuses |= ff.identifiability
        kinds["friction"] = _friction_kind(table, design["truth"], fit)
        stderr["friction"] = ff.stderr["friction"]
    # what an analyst reads: the relative error of every "value +/- stderr" the fit reports print
    printed_text = fit.report() + ("\n" + ff.report() if ff is not None else "")
    for name, st in statuses.items():
        truth = design["truth"][name]
        printed = _printed_relative_error(printed_text, name)
        out[name] = {"truth": truth, "kind": kinds[name], **_statement(st), "covered": bool(st.contains(truth)),
                     "printed_relative_error": printed}
    if posterior:
        _check_posterior(out, table, fit, ff, design)
    out["seconds"] = time.perf_counter() - t0
    out["cpu_seconds"] = time.process_time() - c0  # this process's CPU (one engine thread): the cost on a shared machine
    return out


def _check_posterior(out: dict, table, fit, ff, design: dict) -> None:
    """Add the posterior's 95 % statements (or its refusal) to the design's record."""
    try:
        post = sample_posterior(table, fit, ff, seed=design["seed"])
    except PosteriorError as exc:
        for name in post_names(fit, ff):
            out[name]["posterior_error"] = str(exc)[:300]
        return
    for name in post.names:
        status = post.info["status"].get(name, "determined")
        if status == "determined":
            lo, hi = post.interval(name, LEVEL)
        else:  # the fit's bound (Posterior.bound): what the posterior reports for it
            lo, hi = post.info["bounds"][name]
        truth = design["truth"][name]
        out[name] |= {"posterior_lower": lo, "posterior_upper": hi, "posterior_covered": bool(lo <= truth <= hi),
                      "posterior_steps": int(post.chain.shape[0])}


def post_names(fit, ff) -> list:
    """The parameters a posterior of these fits samples."""
    return list(fit.varied) + (["friction"] if ff is not None else [])


def _worker(args):
    seed, posterior = args
    engine.set_threads(1)  # one engine thread per worker process
    return run_design(draw_design(seed), posterior=posterior)


def calibration_study(n_designs: int, *, seed: int = 0, posterior_designs: int = 0, workers: int = 1,
                      time_budget: float | None = None, progress: bool = False, records_path=None) -> list[dict]:
    """Run :func:`run_design` for ``n_designs`` random designs (seeds ``seed`` ... ``seed + n - 1``).

    Parameters
    ----------
    n_designs : int
    seed : int
        Seed of the first design.
    posterior_designs : int
        How many of the designs (the first ones) also sample the posterior.
    workers : int
        Processes (one engine thread each).
    time_budget : float, optional
        Wall-clock budget [s]; the study stops with TimeBudgetExceeded once past it.
    progress : bool
        One line per design on stderr.
    records_path : path, optional
        A JSON-lines file: each finished design's record is appended to it as it finishes, and the
        designs already in it (same seed, same posterior flag) are taken from it instead of run
        again, so that an interrupted study resumes where it stopped.

    Returns
    -------
    list of dict
        One record per design, in seed order.

    Examples
    --------
    A study of one cheap design (seed 262, see :func:`run_design`), summarised: its zeta_A interval
    holds the truth:

    >>> records = calibration_study(1, seed=262)
    >>> [r["seed"] for r in records], summarise(records)["zeta_adhesion"]["least_squares"]["determined"]["coverage"]
    ([262], 1.0)
    """
    deadline = Deadline.start(time_budget, "calibration study")
    jobs = [(seed + k, k < posterior_designs) for k in range(n_designs)]
    done = _read_records(records_path, jobs)
    records = list(done.values())
    jobs = [j for j in jobs if j[0] not in done]

    def note(rec):
        records.append(rec)
        if records_path is not None:
            with open(records_path, "a") as f:  # one line per design, written as it finishes
                f.write(json.dumps(rec, default=float) + "\n")
        if progress:
            parts = [f"{n} {'in' if rec[n]['covered'] else 'OUT'} ({rec[n]['status']})" for n in FITTED if n in rec]
            print(f"calibration: design {len(records)}/{n_designs} (seed {rec['seed']}, {rec['n_rows']} rows): "
                  + (rec.get("error") or ", ".join(parts)) + f", {rec['seconds']:.1f} s ({rec.get('cpu_seconds', math.nan):.1f} CPU-s)", file=sys.stderr, flush=True)
        deadline.check(f"{len(records)} of {n_designs} designs")

    if workers > 1:
        with mp.get_context("spawn").Pool(workers) as pool:
            for rec in pool.imap_unordered(_worker, jobs):
                note(rec)
    else:
        for job in jobs:
            note(_worker(job))
    return sorted(records, key=lambda r: r["seed"])


def _read_records(path, jobs) -> dict:
    """{seed: record} of the designs of ``jobs`` already in the JSON-lines file ``path`` (a record
    counts only when it was run with the posterior flag the job asks for)."""
    if path is None or not Path(path).exists():
        return {}
    wanted = dict(jobs)
    done = {}
    for line in Path(path).read_text().splitlines():
        if not line.strip():
            continue
        rec = json.loads(line)
        with_posterior = any("posterior_covered" in rec.get(n, {}) or "posterior_error" in rec.get(n, {}) for n in FITTED)
        if rec["seed"] in wanted and (with_posterior == wanted[rec["seed"]] or "error" in rec):
            done[rec["seed"]] = rec
    return done


def _binomial(k: int, n: int) -> dict:
    p = k / n if n else math.nan
    return {"n": n, "covered": k, "coverage": p, "mc_error": math.sqrt(p * (1 - p) / n) if n else math.nan}


def summarise(records: list[dict]) -> dict:
    """Coverage per parameter, per fit status and per kind of design, with binomial MC errors.

    Returns
    -------
    dict
        ``n_designs``, ``errors``; per parameter ``least_squares`` (``determined``: coverage of the
        95 % intervals; ``bounds``: how often a one-sided bound or 'not determined' range holds the
        truth; ``by_kind``), ``posterior`` (the same for the posterior, and ``refused``), and
        ``printed_relative_error_above_100_percent`` (must be 0).

    Examples
    --------
    >>> r = [{"seed": 0, "n_rows": 5, "friction": {"kind": "mixed", "status": "determined", "covered": True,
    ...       "printed_relative_error": 0.1}}]
    >>> summarise(r)["friction"]["least_squares"]["determined"]["coverage"]
    1.0
    """
    out = {"n_designs": len(records), "errors": [r["error"] for r in records if "error" in r]}
    for name in FITTED:
        recs = [r[name] for r in records if name in r]
        if not recs:
            continue
        det = [x for x in recs if x["status"] == "determined"]
        bnd = [x for x in recs if x["status"] != "determined"]
        kinds = sorted({str(x["kind"]) for x in recs})
        entry = {"least_squares": {
            "determined": _binomial(sum(x["covered"] for x in det), len(det)),
            "bounds": _binomial(sum(x["covered"] for x in bnd), len(bnd)),
            "status_counts": {s: sum(x["status"] == s for x in recs) for s in
                              ("determined", "lower_bound", "upper_bound", "not_determined")},
            "by_kind": {k: {"determined": _binomial(sum(x["covered"] for x in det if str(x["kind"]) == k),
                                                    sum(str(x["kind"]) == k for x in det)),
                            "bounds": _binomial(sum(x["covered"] for x in bnd if str(x["kind"]) == k),
                                                sum(str(x["kind"]) == k for x in bnd))} for k in kinds}},
            "printed_relative_error_above_100_percent": sum(
                1 for x in recs if math.isfinite(x.get("printed_relative_error", math.nan)) and x["printed_relative_error"] > 1.0)}
        post = [x for x in recs if "posterior_covered" in x]
        refused = [x for x in recs if "posterior_error" in x]
        if post or refused:
            pdet = [x for x in post if x["status"] == "determined"]
            pbnd = [x for x in post if x["status"] != "determined"]
            entry["posterior"] = {"determined": _binomial(sum(x["posterior_covered"] for x in pdet), len(pdet)),
                                  "bounds": _binomial(sum(x["posterior_covered"] for x in pbnd), len(pbnd)),
                                  "refused": len(refused),
                                  "refused_kinds": sorted({str(x["kind"]) for x in refused})}
        out[name] = entry
    return out

#: how the tables of docs/calibration.md name the parameters
LABELS = {"zeta_hertz": "zeta_H", "zeta_adhesion": "zeta_A", "work_of_adhesion": "w_A", "friction": "f"}


def _percent(c: dict | None) -> str:
    if not c or not c["n"]:
        return "-"
    return f"{100 * c['coverage']:.1f} +/- {100 * c['mc_error']:.1f} % ({c['covered']}/{c['n']})"


def markdown_tables(summary: dict) -> str:
    """The result tables of docs/calibration.md, made from a study's summary (so the page cannot
    drift from the committed JSON: ``tests/test_calibration.py`` compares them).

    Coverage is written ``percent +/- one binomial standard error (covered/n)``.

    Examples
    --------
    >>> r = [{"seed": 0, "n_rows": 5, "friction": {"kind": "mixed", "status": "determined", "covered": True,
    ...       "printed_relative_error": 0.1}}]
    >>> print(markdown_tables(summarise(r)).splitlines()[2])
    | f | 1 | 100.0 +/- 0.0 % (1/1) | - | 1 / 0 / 0 / 0 | - | - | - |
    """
    lines = ["| parameter | designs | 95 % intervals (determined) | bounds and 'not determined' ranges "
             "| determined / lower bound / upper bound / not determined | posterior 95 % intervals "
             "| posterior, parameter not determined | posterior refused |",
             "|---|---|---|---|---|---|---|---|"]
    for name in FITTED:
        if name not in summary:
            continue
        ls, po = summary[name]["least_squares"], summary[name].get("posterior", {})
        sc = ls["status_counts"]
        lines.append(f"| {LABELS[name]} | {sum(sc.values())} | {_percent(ls['determined'])} | {_percent(ls['bounds'])} "
                     f"| {sc['determined']} / {sc['lower_bound']} / {sc['upper_bound']} / {sc['not_determined']} "
                     f"| {_percent(po.get('determined'))} | {_percent(po.get('bounds'))} | {po.get('refused', '-')} |")
    lines += ["", "| parameter | kind of design (from the truth) | 95 % intervals | bounds and ranges |",
              "|---|---|---|---|"]
    for name in FITTED:
        for kind, c in summary.get(name, {}).get("least_squares", {}).get("by_kind", {}).items():
            lines.append(f"| {LABELS[name]} | {kind} | {_percent(c['determined'])} | {_percent(c['bounds'])} |")
    return "\n".join(lines) + "\n"


def plot_calibration(summary: dict, path) -> Path:
    """Coverage per parameter (least squares and posterior) with 2-sigma MC error bars and the
    93-97 % target band; written atomically (:func:`microimpact.io.files.atomic_path`).

    Examples
    --------
    The figure of a one-record summary, written as PNG:

    >>> r = [{"seed": 0, "n_rows": 5, "friction": {"kind": "mixed", "status": "determined", "covered": True,
    ...       "printed_relative_error": 0.1}}]
    >>> path = plot_calibration(summarise(r), "calibration.png")
    >>> path.name, path.read_bytes()[1:4]
    ('calibration.png', b'PNG')
    """

    fig = Figure(figsize=(7.0, 3.4), layout="constrained")
    ax = fig.add_subplot()
    names = [n for n in FITTED if n in summary]
    labels = {"zeta_hertz": "ζ_H", "zeta_adhesion": "ζ_A", "work_of_adhesion": "w_A", "friction": "f"}  # figure glyphs
    ax.axhspan(0.93, 0.97, color="0.85", label="target 93-97 %")
    ax.axhline(0.95, color="0.5", lw=0.8)
    series = [("least_squares", "determined", "o", "least squares: 95 % interval"),
              ("least_squares", "bounds", "^", "least squares: bound / range"),
              ("posterior", "determined", "s", "posterior: 95 % interval")]
    lowest: list[float] = []
    for j, (src, what, marker, label) in enumerate(series):
        xs, ys, es, ns = [], [], [], []
        for i, n in enumerate(names):
            c = summary[n].get(src, {}).get(what)
            if c and c["n"]:
                xs.append(i + 0.18 * (j - 1))
                ys.append(c["coverage"])
                es.append(2 * max(c["mc_error"], 1e-3))
                ns.append(c["n"])
        # bars clipped to [0, 1]: a coverage cannot leave it (a few posterior designs give +/- 70 %)
        lo_err = [min(e, y) for e, y in zip(es, ys)]
        hi_err = [min(e, 1.0 - y) for e, y in zip(es, ys)]
        ax.errorbar(xs, ys, yerr=[lo_err, hi_err], fmt=marker, capsize=3, label=label)
        lowest.extend(ys)
        for x, y, n in zip(xs, ys, ns):
            ax.annotate(f"n={n}", (x, y), textcoords="offset points", xytext=(0, -14), ha="center", fontsize=7)
    ax.set_xticks(range(len(names)), [labels[n] for n in names])
    ax.set_ylim(min([0.7, *(y - 0.08 for y in lowest)]), 1.02)  # every point on the axes
    ax.set_ylabel("fraction holding the truth")
    ax.set_title(f"Calibration over {summary['n_designs']} random designs (error bars: 2 MC standard errors)",
                 fontsize=9)
    ax.legend(fontsize=7, loc="lower right")  # the low posterior points of few designs sit on the left
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip(".") or "png", dpi=150)
    return path


#: the dirty-data kinds of :func:`dirty_study`: name -> table maker of a seed (issue 51 item 8)
DIRTY_KINDS = {
    "clean": lambda seed: make_outlier_impacts(0, seed=seed),
    "1 outlier": lambda seed: make_outlier_impacts(1, seed=seed),
    "2 outliers": lambda seed: make_outlier_impacts(2, seed=seed),
    "3 outliers": lambda seed: make_outlier_impacts(3, seed=seed),
    "Thornton 1997 law": lambda seed: make_thornton_impacts(seed=seed),
}


def run_dirty_design(kind: str, seed: int, folder: Path) -> dict:
    """One dirty-data design: the verdict, the outliers named, and whether the interval of the
    fit after the handling (the refit without the named outliers) covers the generating values."""
    df = DIRTY_KINDS[kind](seed)
    path = write_csv(df, folder / f"{kind.replace(' ', '_')}_{seed}.csv", float_format="%.6g")
    material = read_materials(default_materials_path())[DIRTY_MATERIAL_PAIR]
    result = analyse_impacts(read_impacts(path), material)
    v = result.damping.verdict
    final = result.without_outliers or result.damping
    truth = df.attrs.get("truth", {})
    covered = {}
    for name, value in truth.items():
        lo, hi = final.interval(name)
        covered[name] = None if lo != lo else bool(lo < value < hi)
    planted = set(df.attrs.get("outlier_ids", []))
    return {"kind": kind, "seed": seed, "verdict": v.verdict, "p_value": v.p_value,
            "outliers_named": list(v.outlier_ids), "outliers_planted": sorted(planted),
            "named_exactly": set(v.outlier_ids) == planted, "false_alarm": bool(set(v.outlier_ids) - planted),
            "after_handling": final.verdict.verdict, "covered": covered}


def summarise_dirty(records: list[dict]) -> dict:
    """Per kind: how often the verdict is right, outliers named exactly, false alarms, coverage."""
    out = {}
    for kind in DIRTY_KINDS:
        rs = [r for r in records if r["kind"] == kind]
        if not rs:
            continue
        right = (lambda r: r["verdict"] == "adequate") if kind == "clean" else (lambda r: r["verdict"] == "inadequate")
        entry = {"verdict_right": _binomial(sum(map(right, rs)), len(rs)),
                 "outliers_named_exactly": _binomial(sum(r["named_exactly"] for r in rs), len(rs)),
                 "false_alarm": _binomial(sum(r["false_alarm"] for r in rs), len(rs)),
                 "adequate_after_handling": _binomial(sum(r["after_handling"] == "adequate" for r in rs), len(rs))}
        for name in FITTED:
            cov = [r["covered"][name] for r in rs if r["covered"].get(name) is not None]
            if cov:
                entry[f"coverage_{name}"] = _binomial(sum(cov), len(cov))
        out[kind] = entry
    return out


def plot_dirty(summary: dict, path) -> Path:
    """Bars of the dirty-data study's rates per kind, with their Monte Carlo errors."""
    fig = Figure(figsize=(8, 3.6), layout="constrained")
    ax = fig.subplots()
    measures = ["verdict_right", "outliers_named_exactly", "false_alarm", "coverage_zeta_adhesion"]
    kinds = list(summary)
    width = 0.8 / len(measures)
    for k, m in enumerate(measures):
        vals = [summary[c].get(m, {}).get("coverage", np.nan) for c in kinds]
        errs = [summary[c].get(m, {}).get("mc_error", np.nan) for c in kinds]
        ax.bar(np.arange(len(kinds)) + (k - 1.5) * width, vals, width, yerr=errs, label=m.replace("_", " "))
    ax.axhline(0.95, color="k", lw=0.6, ls="--")
    ax.axhline(0.05, color="k", lw=0.6, ls=":")
    ax.set_xticks(np.arange(len(kinds)), kinds)
    ax.set_ylim(0, 1.05)
    ax.set_ylabel("fraction of designs")
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5))
    fig.savefig(path)
    return Path(path)


def dirty_main(n: int, seed: int, out, figure) -> int:
    """``python tests/study_calibration.py --dirty N --out J [--figure F]``: N seeds of every kind."""
    records = []
    with tempfile.TemporaryDirectory() as tmp:
        for kind in DIRTY_KINDS:
            for s in range(seed, seed + n):
                records.append(run_dirty_design(kind, s, Path(tmp)))
                print(json.dumps({k: records[-1][k] for k in ("kind", "seed", "verdict", "outliers_named")}),
                      file=sys.stderr, flush=True)
    summary = summarise_dirty(records)
    with atomic_write(out) as f:
        json.dump({"summary": summary, "setup": {"designs_per_kind": n, "seed": seed}, "designs": records}, f,
                  indent=1, default=float)
    if figure:
        plot_dirty(summary, figure)
    print(json.dumps(summary, indent=1))
    return 0


def main(argv=None) -> int:
    """``python tests/study_calibration.py``: run the study, write JSON (and the figure).

    Examples
    --------
    Zero designs are refused with status 2 (the message goes to stderr); one cheap design (seed 262,
    see :func:`run_design`) prints the coverage of the 95 % intervals and writes the JSON:

    >>> main(["--designs", "0", "--out", "calibration.json"])
    2
    >>> main(["--designs", "1", "--seed", "262", "--out", "calibration.json"])
    {
     "zeta_hertz": {
      "n": 0,
      "covered": 0,
      "coverage": NaN,
      "mc_error": NaN
     },
     "zeta_adhesion": {
      "n": 1,
      "covered": 1,
      "coverage": 1.0,
      "mc_error": 0.0
     }
    }
    0
    >>> import json
    >>> with open("calibration.json") as f:
    ...     saved = json.load(f)
    >>> len(saved["designs"]), saved["summary"]["setup"]["seed"]
    (1, 262)
    """
    p = argparse.ArgumentParser(prog="python tests/study_calibration.py", description=__doc__.split("\n")[0])
    p.add_argument("--designs", type=int, default=300, help="random designs (default 300)")
    p.add_argument("--posterior-designs", type=int, default=0, help="of which also sample the posterior (default 0)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first design (default 0)")
    p.add_argument("--workers", type=int, default=1, help="processes (default 1)")
    p.add_argument("--time-budget", type=float, default=None, metavar="SECONDS", help="stop past this wall-clock time")
    p.add_argument("--out", required=True, help="output JSON")
    p.add_argument("--records", default=None, metavar="JSONL",
                   help="append each design's record here as it finishes and resume from the designs already in it")
    p.add_argument("--figure", default=None, help="also draw the coverage figure here (.png or .pdf)")
    p.add_argument("--dirty", type=int, default=0, metavar="N",
                   help="instead: the dirty-data study, N seeds of each kind (clean, 1-3 outliers, Thornton law)")
    args, status = parse_or_status(p, argv)
    if args is None:
        return status
    if args.dirty > 0:
        return dirty_main(args.dirty, args.seed, args.out, args.figure)
    for name in ("designs", "workers"):
        if getattr(args, name) < 1:
            print(f"calibration: error: --{name} must be >= 1", file=sys.stderr)
            return 2
    if not 0 <= args.posterior_designs <= args.designs or args.seed < 0:
        print("calibration: error: --posterior-designs must lie in [0, --designs] and --seed be >= 0", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    try:
        records = calibration_study(args.designs, seed=args.seed, posterior_designs=args.posterior_designs,
                                    workers=args.workers, time_budget=args.time_budget, progress=True,
                                    records_path=args.records)
    except TimeBudgetExceeded as exc:
        print(f"calibration: error: {exc}", file=sys.stderr)
        return 3
    summary = summarise(records)
    summary["setup"] = {"designs": args.designs, "posterior_designs": args.posterior_designs, "seed": args.seed,
                        "level": LEVEL, "workers": args.workers, "seconds": round(time.perf_counter() - t0, 1),
                        "cpu_seconds_of_the_designs": round(sum(r.get("cpu_seconds", math.nan) for r in records), 1),
                        "command": "python tests/study_calibration.py " + " ".join(argv if argv is not None else sys.argv[1:])}
    with atomic_write(args.out) as f:
        json.dump({"summary": summary, "designs": records}, f, indent=1, default=float)
    if args.figure:
        plot_calibration(summary, args.figure)
    print(json.dumps({n: summary[n]["least_squares"]["determined"] for n in FITTED if n in summary}, indent=1))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
