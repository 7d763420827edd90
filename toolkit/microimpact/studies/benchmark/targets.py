"""The benchmark's targets, evaluated on its results: speed-up over DOP853 at the target error,
convergence of the engine with rtol, throughput and memory growth."""

from __future__ import annotations

import json
import math

import numpy as np

from microimpact.studies.benchmark.cases import (
    ALL_METHODS, SINGLE_CALL_TARGET_RATIO, TARGET_ERROR, TARGET_RATIO, TARGET_RATIO_AIM, TARGET_THROUGHPUT_SECONDS, BenchmarkConfig,
)
from microimpact.studies.benchmark.harness import log, measure_memory, measure_throughput

__all__ = ["accuracy_targets", "throughput_targets"]


def _cheapest(tpi, err, method, target) -> tuple[float, float]:
    """(time [s], error) of the fastest setting of ``method`` with max e_n error <= ``target``."""
    i = ALL_METHODS.index(method)
    ok = np.isfinite(tpi[i]) & (err[i] <= target)
    if not ok.any():
        return math.nan, math.nan
    j = int(np.flatnonzero(ok)[np.argmin(tpi[i][ok])])
    return float(tpi[i, j]), float(err[i, j])


def _dop853_at_target(tpi, err) -> tuple[float, float, str]:
    """DOP853 at the target error, or its most accurate run as a lower bound of the ratios."""
    t_dop, e_dop = _cheapest(tpi, err, "DOP853", TARGET_ERROR)
    if math.isfinite(t_dop):
        return t_dop, e_dop, ""
    i = ALL_METHODS.index("DOP853")
    ok = np.isfinite(tpi[i]) & np.isfinite(err[i])
    if not ok.any():
        return t_dop, e_dop, ""
    j = int(np.flatnonzero(ok)[np.argmin(err[i][ok])])
    return (float(tpi[i, j]), float(err[i, j]),
            "(DOP853 did not reach the target error; its most accurate run used: ratio is a lower bound)")


def _engine_convergence(err, cfg: BenchmarkConfig, reference_bound: float) -> tuple[bool, list]:
    """Whether the engine's error falls as rtol tightens: no tightening raises it by more than 3x
    above 10 x the reference bound (noise allowed), and the tightest setting is at least 1e4 times
    better than the loosest. Returns (converges, the ratios of the increases)."""
    eng_err = err[ALL_METHODS.index("engine")][list(cfg.engine_levels)]
    e_valid = eng_err[np.isfinite(eng_err)]
    floor = 10.0 * reference_bound
    increases = [float(b / a) for a, b in zip(e_valid[:-1], e_valid[1:]) if b > 3.0 * a and b > floor]
    return bool(e_valid.size >= 2 and not increases and e_valid[-1] <= 1e-4 * e_valid[0]), increases


def accuracy_targets(tpi, err, cfg: BenchmarkConfig, reference_bound: float) -> dict:
    """Times at the target e_n error, the DOP853/engine ratios and the convergence of the engine.

    Parameters
    ----------
    tpi, err : numpy.ndarray
        Time per impact [s] and max e_n error [-], dims (method, setting).
    reference_bound : float
        Error bound of the reference e_n. [-]

    Examples
    --------
    A made-up work-precision table (nine settings, the error ten times smaller at each, the time 1.5
    times larger): DOP853 and the batch engine reach the target error 1e-8 at the same setting, the
    engine's time 1/500 of DOP853's, which meets the target ratio; an engine whose error rises tenfold at one
    tightening does not converge:

    >>> import numpy as np
    >>> from microimpact.studies.benchmark.cases import ALL_METHODS, BenchmarkConfig
    >>> tpi, err = np.full((len(ALL_METHODS), 9), np.nan), np.full((len(ALL_METHODS), 9), np.nan)
    >>> for method, t, e in (("engine", 1e-5, 1e-4), ("engine_batch", 2e-6, 1e-4), ("rkg", 1e-5, 1e-3),
    ...                      ("DOP853", 1e-3, 1e-4)):
    ...     tpi[ALL_METHODS.index(method)] = t * 1.5 ** np.arange(9)
    ...     err[ALL_METHODS.index(method)] = e * 0.1 ** np.arange(9)
    >>> cfg = BenchmarkConfig.quick_()
    >>> t = accuracy_targets(tpi, err, cfg, reference_bound=1e-12)
    >>> round(t["ratio_dop853_to_engine_batch"]), t["target_ratio"], t["target_ratio_met_batch"], t["engine_converges"]
    (500, 300.0, True, True)
    >>> err[ALL_METHODS.index("engine"), 4] = 10 * err[ALL_METHODS.index("engine"), 2]
    >>> t = accuracy_targets(tpi, err, cfg, reference_bound=1e-12)
    >>> t["engine_converges"], t["engine_error_increases"]
    (False, '[10.0]')
    """
    t_dop, e_dop, note = _dop853_at_target(tpi, err)
    t_eng, e_eng = _cheapest(tpi, err, "engine", TARGET_ERROR)
    t_engb, e_engb = _cheapest(tpi, err, "engine_batch", TARGET_ERROR)
    t_rkg, _ = _cheapest(tpi, err, "rkg", TARGET_ERROR)
    ratio_single, ratio_batch = t_dop / t_eng, t_dop / t_engb
    converges, increases = _engine_convergence(err, cfg, reference_bound)
    return {
        "target_error_e_n": TARGET_ERROR,
        "dop853_time_at_target": t_dop,
        "dop853_error_at_target": e_dop,
        "engine_time_at_target": t_eng,
        "engine_error_at_target": e_eng,
        "engine_batch_time_at_target": t_engb,
        "engine_batch_error_at_target": e_engb,
        "rkg_time_at_target": t_rkg,
        "ratio_dop853_to_engine_single": ratio_single,
        "ratio_dop853_to_engine_batch": ratio_batch,
        "ratio_rkg_to_engine_batch": t_rkg / t_engb,
        "target_ratio": TARGET_RATIO,
        "target_ratio_aim": TARGET_RATIO_AIM,
        "target_ratio_met_single": bool(ratio_single >= TARGET_RATIO),
        "target_ratio_met_batch": bool(ratio_batch >= TARGET_RATIO),
        "target_ratio_aim_met_batch": bool(ratio_batch >= TARGET_RATIO_AIM),
        "single_call_target_ratio": SINGLE_CALL_TARGET_RATIO,
        "single_call_target_met": bool(ratio_single >= SINGLE_CALL_TARGET_RATIO),
        "target_ratio_note": note,
        "engine_converges": converges,
        "engine_error_increases": json.dumps(increases),
    }


def throughput_targets(contact, cfg: BenchmarkConfig, verbose: bool = False) -> dict:
    """Throughput of simulate_many (scaled to 100,000 impacts) and growth of its peak memory
    against the growth of its output.

    Examples
    --------
    500 impacts (scaled to 100,000, so marked extrapolated) and the memory of 200 and 400 impacts,
    whose output doubles:

    >>> import dataclasses
    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.studies.benchmark.cases import BenchmarkConfig
    >>> cfg = dataclasses.replace(BenchmarkConfig.quick_(), throughput_impacts=500, memory_sizes=(200, 400))
    >>> t = throughput_targets(WALL_1990, cfg)
    >>> t["throughput_impacts"], t["throughput_distinct_normal_speeds"], t["target_throughput_extrapolated"]
    (500, 500, True)
    >>> t["memory_output_growth"], t["memory_sizes"]
    (2.0, '[200, 400]')
    """
    log(f"throughput: {cfg.throughput_impacts} oblique impacts through simulate_many", verbose)
    thr = measure_throughput(contact, cfg.throughput_impacts, cfg.throughput_repeats)
    mems = [measure_memory(contact, n) for n in cfg.memory_sizes]
    per_100k = thr["seconds"] * 100_000 / thr["n"]
    growth_peak = mems[1]["peak_bytes"] / mems[0]["peak_bytes"]
    growth_out = mems[1]["output_bytes"] / mems[0]["output_bytes"]
    log(f"throughput {thr['seconds']:.2f} s for {thr['n']}; memory peak growth {growth_peak:.2f} vs output "
        f"{growth_out:.2f}", verbose)
    return {
        "throughput_impacts": thr["n"],
        "throughput_seconds": thr["seconds"],
        "throughput_seconds_per_100k": per_100k,
        "throughput_rtol": thr["rtol"],
        "throughput_captured_fraction": thr["captured_fraction"],
        "throughput_distinct_normal_speeds": thr["n_distinct_normal_speeds"],
        "target_throughput_seconds": TARGET_THROUGHPUT_SECONDS,
        "target_throughput_met": bool(per_100k <= TARGET_THROUGHPUT_SECONDS),
        "target_throughput_extrapolated": bool(thr["n"] != 100_000),
        "memory_sizes": json.dumps([m["n"] for m in mems]),
        "memory_peak_bytes": json.dumps([m["peak_bytes"] for m in mems]),
        "memory_output_bytes": json.dumps([m["output_bytes"] for m in mems]),
        "memory_peak_per_impact_bytes": json.dumps([m["peak_bytes"] / m["n"] for m in mems]),
        "memory_peak_growth": growth_peak,
        "memory_output_growth": growth_out,
        # growing no faster than the output (10 % allowance for fixed overheads and noise)
        "target_memory_met": bool(growth_peak <= 1.1 * growth_out),
    }
