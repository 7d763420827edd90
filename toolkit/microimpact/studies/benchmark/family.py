"""The family path in the benchmark: its own method line and the million-impact target.

``engine_family`` builds :func:`microimpact.solvers.family.normal_family` over the test set's speed
range at each rtol and evaluates it on ``cfg.family_size`` distinct normal speeds; its time per
impact includes the build. :func:`family_targets` runs ``cfg.family_impacts`` oblique impacts with
distinct normal speeds through :func:`microimpact.simulate_many` (family path), measures the
largest e_n error against tight direct engine solves on a random subset, and compares the wall
time with 100 scipy DOP853 impacts at the target error, taken from the same run's table.
"""

from __future__ import annotations

import gc
import json
import math
import tempfile
import tracemalloc
from pathlib import Path

import numpy as np

from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.synthetic import make_synthetic_impacts
from microimpact.io.files import write_csv
from microimpact.io.impacts import read_impacts
from microimpact.io.materials import default_materials_path, read_materials

from microimpact.solvers.family import normal_family
from microimpact.solvers.impact import simulate_many
from microimpact.studies.benchmark.cases import ALL_METHODS, BenchmarkConfig, level_rtol
from microimpact.studies.benchmark.harness import ObliqueResults, random_oblique_batch, log, timed

__all__ = ["run_engine_family", "family_targets", "fit_scaling", "FAMILY_TARGET_ERROR", "FAMILY_TARGET_DOP853_IMPACTS"]

#: the million impacts must reach this largest e_n error ...
FAMILY_TARGET_ERROR = 1e-9
#: ... in at most the time of this many DOP853 impacts at the same or looser error
FAMILY_TARGET_DOP853_IMPACTS = 100
#: tolerance of the direct solves that judge the family (four orders of magnitude tighter than the family's)
_JUDGE_RTOL = 1e-13


def _family_oblique(contact, cases, rtol) -> ObliqueResults:
    """The oblique cases in one simulate_many call on the family path."""
    om = np.array([case.omega(contact.radius) for case in cases])
    ds = simulate_many(contact, [c.speed for c in cases], [c.incidence_deg for c in cases],
                       [c.azimuth_deg for c in cases], (om[:, 0], om[:, 1], om[:, 2]),
                       [c.friction for c in cases], rtol=rtol, family=True)
    obl = ObliqueResults(len(cases))
    obl.captured = ds["outcome"].values == 1
    obl.mu_t, obl.mu_tp, obl.K_L = ds["mu_t"].values, ds["mu_tp"].values, ds["K_L"].values
    return obl


def run_engine_family(contact, speeds, cases, cfg: BenchmarkConfig, table, verbose: bool) -> None:
    """``engine_family``: build the family and evaluate it on ``cfg.family_size`` distinct speeds.

    Examples
    --------
    The family line of a two-speed test set at rtol 1e-4 and 1e-6 (settings 0 and 2), recorded in the
    benchmark's results table: the e_n error against the reference falls as rtol tightens:

    >>> import dataclasses
    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.studies.benchmark.cases import BenchmarkConfig, oblique_cases
    >>> from microimpact.studies.benchmark.reference import reference_set
    >>> from microimpact.studies.benchmark.run import _Table
    >>> cfg = dataclasses.replace(BenchmarkConfig.quick_(), engine_levels=(0, 2), family_size=100)
    >>> speeds, cases = np.array([2.0, 5.0]), oblique_cases(quick=True)[:1]
    >>> table = _Table(reference_set(WALL_1990, speeds, cases, cfg), n_settings=3)
    >>> run_engine_family(WALL_1990, speeds, cases, cfg, table, verbose=False)
    >>> e = table.get("max_error_e_n", "engine_family")
    >>> bool(e[2] < e[0] < 1e-5), table.status[ALL_METHODS.index("engine_family")].tolist()
    (True, ['ok', '', 'ok'])
    """
    family_speeds = np.geomspace(speeds[0], speeds[-1], cfg.family_size)
    for k in cfg.engine_levels:
        rt = level_rtol(k)
        table.set("rtol", "engine_family", k, rt)

        def build_and_evaluate(rt=rt):
            fam = normal_family(contact, speeds[0], speeds[-1], rtol=rt)
            fam.evaluate(family_speeds)
            return fam

        t, fam = timed(build_and_evaluate, cfg.repeats_batch)
        # oblique errors of the family path are judged on the million-impact target (family_targets)
        # and in tests/test_family.py: a family over these few cases would cost more than the table
        table.record("engine_family", k, t / family_speeds.size, fam.evaluate(speeds)["e_n"],
                     _family_oblique(contact, cases, rt) if cfg.family_oblique else None, family_speeds.size,
                     steps=fam.n_solves)
        log(f"engine_family rtol {rt:g}: {t / family_speeds.size * 1e6:.3f} us/impact, {fam.n_solves} solves",
            verbose)


def _dop853_time(tpi, err) -> tuple[float, float, str]:
    """DOP853's time per impact [s] and error at the loosest setting that reaches
    FAMILY_TARGET_ERROR (the cheapest at that error), or its most accurate (a lower bound)."""
    i = ALL_METHODS.index("DOP853")
    ok = np.isfinite(tpi[i]) & (err[i] <= FAMILY_TARGET_ERROR)
    if ok.any():
        j = int(np.flatnonzero(ok)[np.argmin(tpi[i][ok])])
        return float(tpi[i, j]), float(err[i, j]), ""
    fin = np.flatnonzero(np.isfinite(tpi[i]) & np.isfinite(err[i]))
    if not fin.size:
        return math.nan, math.nan, "DOP853 gave no result"
    j = int(fin[np.argmin(err[i][fin])])
    return float(tpi[i, j]), float(err[i, j]), "DOP853 did not reach 1e-9: its most accurate setting, a lower bound"


def _peak_bytes(contact, n) -> tuple[int, int]:
    """(peak memory growth, output bytes) of simulate_many on the family path for ``n`` impacts.

    On Linux the peak resident set size, reset before the call (/proc/self/clear_refs): it counts
    the large outputs, which live in their own memory maps (solvers.family._fresh_array) that
    tracemalloc does not see; elsewhere tracemalloc's peak (the same below 16 MB of output)."""
    speed, inc, az, om, fric = random_oblique_batch(contact, n, seed=7)
    gc.collect()
    if _reset_peak_rss():
        base = _status_bytes("VmRSS")
        ds = simulate_many(contact, speed, inc, az, om, fric, rtol=FAMILY_TARGET_ERROR, family=True)
        return _status_bytes("VmHWM") - base, int(ds.nbytes)
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    ds = simulate_many(contact, speed, inc, az, om, fric, rtol=FAMILY_TARGET_ERROR, family=True)
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    return int(peak), int(ds.nbytes)


def _reset_peak_rss() -> bool:
    """Reset the process's peak resident set size (Linux >= 4.0); False where that is not possible."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
        return _status_bytes("VmHWM") > 0
    except OSError:
        return False


def _status_bytes(key: str) -> int:
    """A size from /proc/self/status (``VmRSS``, ``VmHWM``) in bytes."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1]) * 1024
    return 0


def _growth(before: int, after: int) -> float:
    """after / before, NaN where the smaller measurement is 0 (below the resolution of the peak
    resident set size: small batches fit in pages already resident), so no target is met on it.

    >>> _growth(1000, 8000), _growth(0, 8000)
    (8.0, nan)
    """
    return after / before if before > 0 else math.nan


def family_targets(contact, cfg: BenchmarkConfig, tpi, err, verbose: bool = False) -> dict:
    """The million-impact target of the family path, its e_n error and memory growth.

    Parameters
    ----------
    contact : Contact
    cfg : BenchmarkConfig
        ``family_impacts``, ``family_check``, ``family_memory_sizes``, ``throughput_repeats``.
    tpi, err : numpy.ndarray
        Time per impact [s] and max e_n error [-] of the benchmark table, dims (method, setting):
        DOP853's row gives the time compared with.

    References
    ----------
    Hairer, E., Norsett, S. P. and Wanner, G. (1993), Solving Ordinary Differential Equations I,
    2nd ed., Springer, Sec. II.10 (DOP853).

    Examples
    --------
    200 impacts (memory at 10 and 20) against a made-up DOP853 line whose loosest setting at an
    e_n error <= 1e-9 is the one compared with:

    >>> import dataclasses
    >>> from microimpact.presets import WALL_1990
    >>> cfg = dataclasses.replace(BenchmarkConfig.quick_(), family_impacts=200, family_check=20,
    ...                           family_memory_sizes=(10, 20), throughput_repeats=1)
    >>> tpi, err = np.full((len(ALL_METHODS), 3), np.nan), np.full((len(ALL_METHODS), 3), np.nan)
    >>> i = ALL_METHODS.index("DOP853")
    >>> tpi[i], err[i] = [2e-3, 4e-3, 8e-3], [1e-7, 5e-10, 1e-11]  # [s], [-]
    >>> t = family_targets(WALL_1990, cfg, tpi, err)
    >>> t["family_max_error_e_n"] <= FAMILY_TARGET_ERROR, t["family_error_checked_on"], t["family_path"][:7]
    (True, 20, 'family:')
    >>> t["family_dop853_time_per_impact"], t["family_dop853_error_e_n"], t["family_memory_output_growth"]
    (0.004, 5e-10, 2.0)
    >>> math.isclose(t["family_ratio_per_impact"], 4e-3 / t["family_seconds_per_impact"])
    True
    """
    n = cfg.family_impacts
    speed, inc, az, om, fric = random_oblique_batch(contact, n)
    simulate_many(contact, speed[:3000], inc[:3000], az[:3000], tuple(o[:3000] for o in om), fric[:3000],
                  rtol=FAMILY_TARGET_ERROR, family=True)  # compiled before timing
    t, ds = timed(lambda: simulate_many(contact, speed, inc, az, om, fric, rtol=FAMILY_TARGET_ERROR, family=True),
                  cfg.throughput_repeats)
    idx = np.random.default_rng(1).choice(n, min(n, cfg.family_check), replace=False)
    judge = simulate_many(contact, speed[idx], inc[idx], az[idx], tuple(o[idx] for o in om), fric[idx],
                          rtol=_JUDGE_RTOL, family=False)
    e_err = float(np.max(np.abs(ds["e_n"].values[idx] - judge["e_n"].values)))
    t_dop, e_dop, note = _dop853_time(tpi, err)
    (p0, o0), (p1, o1) = (_peak_bytes(contact, m) for m in cfg.family_memory_sizes)
    log(f"family: {n:,} oblique impacts in {t:.2f} s, e_n error {e_err:.2e}; {t_dop / (t / n):,.0f}x DOP853 per impact",
        verbose)
    return {
        "family_impacts": n,
        "family_seconds": t,
        "family_seconds_per_impact": t / n,
        "family_max_error_e_n": e_err,
        "family_error_checked_on": int(idx.size),
        "family_normal_solves": int(ds.attrs["normal_solves"]),
        "family_path": ds.attrs["normal_solve_path"],
        "family_dop853_time_per_impact": t_dop,
        "family_dop853_error_e_n": e_dop,
        "family_dop853_note": note,
        "family_ratio_per_impact": t_dop / (t / n),
        "family_target_error": FAMILY_TARGET_ERROR,
        "family_target_dop853_impacts": FAMILY_TARGET_DOP853_IMPACTS,
        # per impact: 1,000,000 impacts in the time of 100 DOP853 impacts is a ratio of 10,000 (a
        # smaller run, as --quick, amortizes the family's build over fewer impacts: harder to meet)
        "family_target_ratio": 1e6 / FAMILY_TARGET_DOP853_IMPACTS,
        "family_target_met": bool(t_dop / (t / n) >= 1e6 / FAMILY_TARGET_DOP853_IMPACTS and e_err <= FAMILY_TARGET_ERROR),
        "family_memory_peak_growth": _growth(p0, p1),
        "family_memory_output_growth": o1 / o0,
        # the peak at the larger batch as a fraction of its output: below 1, memory is bounded by
        # what the caller gets back
        "family_memory_peak_fraction_of_output": p1 / o1,
        # growing no faster than the output (10 % allowance for the allocator's granularity: the
        # smaller batch's arrays stay in numpy's allocator, the larger's are memory maps)
        "family_memory_target_met": bool(_growth(p0, p1) <= 1.1 * o1 / o0),
    }


def fit_scaling(sizes=(100, 100_000), repeats: int = 1, verbose: bool = False) -> dict:
    """Wall time of :func:`microimpact.analysis.fitting.fit_damping` on synthetic data sets of
    ``sizes`` rows (the bundled synthetic material, four radii), side by side; the large fit uses
    restitution families, the small one direct solves.

    Returns
    -------
    dict
        ``fit_sizes`` and ``fit_seconds`` [s] (JSON lists), ``fit_time_ratio`` (last over first),
        ``fit_target_ratio``, ``fit_target_met`` and ``fit_zeta`` (JSON list of the fitted
        (zeta_hertz, zeta_adhesion) [-] per size).

    References
    ----------
    Cheng, Brach & Dunn (2002), Table 1 row 2 (the damping of the synthetic data).

    Examples
    --------
    One fit of 20 rows (five per radius; a fit of a few rows takes seconds, most of it the
    identifiability check): a single size has a time ratio of 1, and the fit finds the damping the
    noisy synthetic data were made with (Table 1 row 2: 0.5 and 29; fitted 0.512 and 28.97):

    >>> from microimpact.model.parameters import TABLE1_ROW2
    >>> s = fit_scaling(sizes=(20,))
    >>> s["fit_sizes"], s["fit_time_ratio"], s["fit_target_met"]
    ('[20]', 1.0, True)
    >>> [(zeta_h, zeta_a)] = json.loads(s["fit_zeta"])
    >>> abs(zeta_h - TABLE1_ROW2.zeta_hertz) < 0.05, abs(zeta_a - TABLE1_ROW2.zeta_adhesion) < 0.2
    (True, True)
    """
    base = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    seconds, zeta = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            path = Path(tmp) / f"impacts_{n}.csv"
            write_csv(make_synthetic_impacts(n_per_radius=max(1, n // 4)), path)
            table = read_impacts(path)
            t, fit = timed(lambda table=table: fit_damping(table, base, confidence_intervals=False), repeats)
            seconds.append(t)
            zeta.append((fit.zeta_hertz, fit.zeta_adhesion))
            log(f"fit of {len(table):,} rows: {t:.2f} s", verbose)
    return {"fit_sizes": json.dumps(list(sizes)), "fit_seconds": json.dumps(seconds),
            "fit_time_ratio": seconds[-1] / seconds[0], "fit_target_ratio": 20.0,
            "fit_target_met": bool(seconds[-1] <= 20.0 * seconds[0]), "fit_zeta": json.dumps(zeta)}
