"""Work-precision benchmark of the impact solvers on the WALL_1990 contact (Table 1, row 2).

Run ``python -m microimpact.studies.benchmark [--out DIR] [--quick] [--docs DIR]``.

What is measured (all in one run, on one machine, side by side)
----------------------------------------------------------------
* **Test set.** Normal impacts at ``n_speeds`` incident speeds log-spaced from just above the
  capture speed v_cap (found by bisection on the engine's outcome) to 100 m/s, and a fixed table of
  oblique impacts (incidence 10-80 deg, spins up to 10 times the rolling spin v_t / r, friction
  0.15 and 0.5; some captured, some rebounding).
* **Reference values** come from a much tighter solve whose own error is *bounded*, not assumed:
  scipy's DOP853 on the full 3-D equations (:func:`microimpact.solvers.reference.simulate_reference`) at
  rtol = 1e-13 is the reference; the bound is the largest of |DOP853(1e-13) - engine(1e-13)| (two
  independent integrators and codes) and |DOP853(1e-12) - DOP853(1e-13)| (self-convergence), over
  the test set. Errors below the bound are not resolved.
* **Methods**, each at several settings (dimension ``setting``; for adaptive methods setting k is
  rtol = 10^-(4+k), for the fixed-step Runge-Kutta-Gill method N = 25 * 2^k steps per contact):

  ``engine``          :func:`microimpact.simulate_impact` one call per impact (Python overhead incl.)
  ``engine_batch``    :func:`microimpact.solvers.engine.solve_normal_many` on a batch of distinct speeds
                      (both cores); oblique errors through :func:`microimpact.simulate_many`
  ``rkg``             fixed-step Runge-Kutta-Gill (Gill 1951) on the plain Eq. (27) in tau, the
                      paper's method, numba-compiled, batch over both cores (``prange``)
  ``RK45``, ``DOP853``, ``LSODA``, ``Radau``
                      :func:`microimpact.solvers.reference.simulate_reference` with that solve_ivp method
                      (one call per impact; atol = rtol on the O(1) nondimensional state)

* **Errors**: max over the normal set of |e_n - e_n_ref| (also relative), max over the rebounding
  oblique cases of |mu_t - ref| and |mu_t' - ref|, max over all oblique cases of |K_L - ref|.
* **Time per impact**: ``time.perf_counter``; for one-call methods the median over the normal set
  of each impact's median over repeats; for batch methods the median over repeats of the batch
  time divided by the batch size. Numba functions are compiled (warmed up) before timing.
* **Throughput and memory**: 100,000 oblique impacts with distinct normal speeds through
  :func:`microimpact.simulate_many`; peak traced memory (``tracemalloc``; numba's own small
  per-impact work arrays are not traced) for 10,000 and 100,000 impacts against the output size.

The results are an :class:`xarray.Dataset` (dims ``method``, ``setting``; variables
``time_per_impact`` [s], ``max_error_e_n``, ``max_error_mu`` [1], ...) whose attributes hold the
machine, library versions, the reference error bound, the targets and whether they were met.
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import gc
import json
import math
import os
import platform
import sys
import time
import tracemalloc
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr
from numba import njit, prange

from microimpact.solvers import engine
from microimpact.studies._timeout import TimeLimitExceeded
from microimpact.studies._timeout import time_limit as _time_limit  # time_limit is also a parameter name here
from microimpact.solvers.impact import simulate_impact, simulate_many
from microimpact.presets import WALL_1990

__all__ = [
    "BenchmarkConfig",
    "ObliqueCase",
    "capture_speed",
    "normal_speed_set",
    "oblique_cases",
    "rkg_state",
    "rkg_restitution",
    "run_benchmark",
    "write_benchmark",
    "benchmark_markdown",
    "main",
]

ADAPTIVE_METHODS = ("engine", "engine_batch", "RK45", "DOP853", "LSODA", "Radau")
SCIPY_METHODS = ("RK45", "DOP853", "LSODA", "Radau")
ALL_METHODS = ("engine", "engine_batch", "rkg") + SCIPY_METHODS

#: Targets of the brief (evaluated, not assumed)
TARGET_ERROR = 1e-8  # at this max e_n error ...
TARGET_RATIO = 300.0  # ... the engine must be at least this much faster than DOP853 (aim 1000)
TARGET_RATIO_AIM = 1000.0
TARGET_THROUGHPUT_SECONDS = 5.0  # for 100,000 oblique impacts through simulate_many


# =============================================================================== configuration
@dataclass(frozen=True)
class ObliqueCase:
    """One oblique impact of the test set.

    speed [m/s], incidence_deg [deg], azimuth_deg [deg]; spins as multiples of the rolling spin
    v sin(alpha) / r about (n, t, t'); friction [-].
    """

    speed: float
    incidence_deg: float
    azimuth_deg: float
    spin_n: float
    spin_t: float
    spin_tp: float
    friction: float

    def omega(self, radius: float) -> tuple[float, float, float]:
        """Spin (omega_n, omega_t, omega_t') [rad/s]."""
        w = self.speed * math.sin(math.radians(self.incidence_deg)) / radius
        return (self.spin_n * w, self.spin_t * w, self.spin_tp * w)


_OBLIQUE = (
    # speed, incidence, azimuth, spin_n, spin_t, spin_t', friction
    ObliqueCase(3.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.15),  # rebound, sliding throughout
    ObliqueCase(5.0, 30.0, 0.0, 0.0, 0.0, 1.0, 0.5),  # rebound, back-spin doubles the slip
    ObliqueCase(10.0, 60.0, 0.0, 0.5, 0.0, 10.0, 0.5),  # rebound, 10x spin + twist
    ObliqueCase(2.0, 45.0, 0.0, 0.0, 0.0, 0.0, 0.5),  # v_n = 1.41 m/s: captured, slip ends
    ObliqueCase(3.0, 70.0, 0.0, 1.0, 0.0, 0.0, 0.5),  # captured, with twist
    ObliqueCase(1.6, 10.0, 0.0, 0.0, 0.0, 0.0, 0.5),  # rebound just above capture
    ObliqueCase(20.0, 80.0, 0.0, 0.0, 0.0, -10.0, 0.15),  # rebound, large top-spin
    ObliqueCase(5.0, 45.0, 30.0, 0.0, 0.0, 0.0, 0.15),  # rebound, azimuth 30 deg
    ObliqueCase(50.0, 45.0, 90.0, 1.0, 3.0, 0.0, 0.5),  # rebound, spin about t, azimuth 90
    ObliqueCase(1.2, 10.0, 0.0, 0.0, 0.0, 2.0, 0.15),  # captured, spin
    ObliqueCase(100.0, 30.0, 45.0, 1.0, 1.0, 1.0, 0.15),  # rebound, all spins, azimuth 45
    ObliqueCase(8.0, 80.0, 0.0, 0.0, 0.0, -1.0, 0.5),  # captured, rolling (no slip)
)
_OBLIQUE_QUICK = tuple(_OBLIQUE[i] for i in (0, 1, 2, 3, 4, 5))


@dataclass(frozen=True)
class BenchmarkConfig:
    """Sizes of the benchmark. ``BenchmarkConfig.full()`` and ``.quick()`` are the two presets."""

    quick: bool
    n_speeds: int
    max_speed: float
    capture_margin: float
    engine_levels: tuple  # setting k -> rtol 10^-(4+k)
    scipy_levels: tuple
    rkg_levels: tuple  # setting k -> N = 25 * 2^k steps per contact
    oblique: tuple
    repeats_single: int
    repeats_scipy: int
    repeats_batch: int
    batch_size: int
    throughput_impacts: int
    throughput_repeats: int
    memory_sizes: tuple
    time_limit: float  # s per impact before a scipy setting is dropped
    reference_rtols: tuple = (1e-12, 1e-13)
    contact_name: str = "WALL_1990"
    notes: tuple = field(default_factory=tuple)

    @classmethod
    def full(cls) -> "BenchmarkConfig":
        return cls(
            quick=False, n_speeds=10, max_speed=100.0, capture_margin=1.02,
            engine_levels=tuple(range(9)), scipy_levels=tuple(range(7)), rkg_levels=tuple(range(9)),
            oblique=_OBLIQUE, repeats_single=15, repeats_scipy=3, repeats_batch=5, batch_size=4000,
            throughput_impacts=100_000, throughput_repeats=3, memory_sizes=(10_000, 100_000), time_limit=3.0,
        )

    @classmethod
    def quick_(cls) -> "BenchmarkConfig":
        return cls(
            quick=True, n_speeds=6, max_speed=100.0, capture_margin=1.02,
            engine_levels=(0, 2, 4, 6, 8), scipy_levels=(0, 2, 4), rkg_levels=(0, 2, 4, 6),
            oblique=_OBLIQUE_QUICK, repeats_single=5, repeats_scipy=1, repeats_batch=3, batch_size=1000,
            throughput_impacts=20_000, throughput_repeats=1, memory_sizes=(2_000, 20_000), time_limit=1.0,
            reference_rtols=(1e-11, 1e-12),
        )


def level_rtol(k: int) -> float:
    """rtol of setting k for the adaptive methods: 10^-(4+k)."""
    return 10.0 ** -(4 + k)


def level_steps(k: int) -> int:
    """Steps per contact of setting k for the Runge-Kutta-Gill method: 25 * 2^k."""
    return 25 * 2**k


# =============================================================================== test set
def capture_speed(contact=WALL_1990, *, rtol: float = 1e-12, lo: float = 1e-3, hi: float = 1e3,
                  rel_tol: float = 1e-12) -> float:
    """Capture speed [m/s]: the largest normal speed at which the engine reports a capture.

    Bisection on ``engine.solve_normal(...).outcome`` in log speed; returns the upper end of the
    final bracket (the smallest speed known to rebound).
    """
    if engine.solve_normal(contact, hi, rtol=rtol).outcome == "capture":
        raise ValueError(f"no rebound up to {hi} m/s")
    if engine.solve_normal(contact, lo, rtol=rtol).outcome != "capture":
        return lo
    while hi / lo - 1.0 > rel_tol:
        mid = math.sqrt(lo * hi)
        if engine.solve_normal(contact, mid, rtol=rtol).outcome == "capture":
            lo = mid
        else:
            hi = mid
    return hi


def normal_speed_set(contact=WALL_1990, n: int = 10, max_speed: float = 100.0, margin: float = 1.02):
    """``n`` normal speeds log-spaced from ``margin`` times the capture speed to ``max_speed``. [m/s]"""
    v_cap = capture_speed(contact)
    return np.geomspace(margin * v_cap, max_speed, n), v_cap


def oblique_cases(quick: bool = False) -> tuple:
    """The oblique test cases (:class:`ObliqueCase`)."""
    return _OBLIQUE_QUICK if quick else _OBLIQUE


from microimpact.solvers.rkg import _rkg_setup, rkg_restitution, rkg_state  # the paper's integrator


def _timed(func, repeats: int):
    """(median seconds, last result) of ``repeats`` calls of ``func``."""
    times = []
    result = None
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        result = func()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), result


def _log(msg: str, verbose: bool) -> None:
    if verbose:
        print(msg, file=sys.stderr, flush=True)


# =============================================================================== references
def _case_contact(contact, case: ObliqueCase):
    return contact.with_(friction=case.friction)


def _run_reference(contact, speeds, cases, rtol, method="DOP853", atol=None, time_limit=None):
    """e_n at ``speeds`` and (outcome, mu_t, mu_tp, K_L) of ``cases`` by simulate_reference."""
    from microimpact.solvers.reference import simulate_reference

    atol = rtol if atol is None else atol
    e_n = np.full(len(speeds), np.nan)
    times = np.full(len(speeds), np.nan)
    for i, v in enumerate(speeds):
        try:
            with _time_limit(time_limit):
                t0 = time.perf_counter()
                e_n[i] = simulate_reference(contact, float(v), rtol=rtol, atol=atol, method=method).e_n
                times[i] = time.perf_counter() - t0
        except TimeLimitExceeded:
            times[i] = math.inf
    obl = _oblique_nan(len(cases))
    for j, case in enumerate(cases):
        c = _case_contact(contact, case)
        try:
            with _time_limit(time_limit):
                r = simulate_reference(c, case.speed, case.incidence_deg, case.azimuth_deg, case.omega(c.radius),
                                       rtol=rtol, atol=atol, method=method)
            obl["captured"][j] = r.outcome == "capture"
            obl["mu_t"][j], obl["mu_tp"][j], obl["K_L"][j] = r.mu_t, r.mu_tp, r.K_L
        except TimeLimitExceeded:
            obl["timeout"][j] = True
        except Exception as exc:  # noqa: BLE001 - a failing reference is a result to report
            obl["failed"][j] = f"{type(exc).__name__}: {exc}"[:200]
    return e_n, times, obl


def _oblique_nan(n):
    return {
        "captured": np.zeros(n, bool),
        "mu_t": np.full(n, np.nan),
        "mu_tp": np.full(n, np.nan),
        "K_L": np.full(n, np.nan),
        "timeout": np.zeros(n, bool),
        "failed": [""] * n,
    }


def _engine_oblique(contact, cases, rtol):
    obl = _oblique_nan(len(cases))
    for j, case in enumerate(cases):
        c = _case_contact(contact, case)
        r = simulate_impact(c, case.speed, case.incidence_deg, case.azimuth_deg, case.omega(c.radius), rtol=rtol)
        obl["captured"][j] = r.outcome == "capture"
        obl["mu_t"][j], obl["mu_tp"][j], obl["K_L"][j] = r.mu_t, r.mu_tp, r.K_L
    return obl


def _engine_many_oblique(contact, cases, rtol):
    om = np.array([case.omega(contact.radius) for case in cases])
    ds = simulate_many(
        contact,
        [c.speed for c in cases],
        [c.incidence_deg for c in cases],
        [c.azimuth_deg for c in cases],
        (om[:, 0], om[:, 1], om[:, 2]),
        [c.friction for c in cases],
        rtol=rtol,
    )
    obl = _oblique_nan(len(cases))
    obl["captured"] = ds["outcome"].values == 1
    obl["mu_t"], obl["mu_tp"], obl["K_L"] = ds["mu_t"].values, ds["mu_tp"].values, ds["K_L"].values
    return obl


def _oblique_errors(obl, ref):
    """(max |mu - mu_ref| over rebounds, max |K_L - K_L_ref|, outcome mismatches, missing cases)."""
    ok = ~obl["timeout"] & np.array([not f for f in obl["failed"]]) & np.isfinite(ref["K_L"])
    mismatch = ok & (obl["captured"] != ref["captured"])
    reb = ok & ~mismatch & ~ref["captured"]
    mu = np.concatenate([np.abs(obl["mu_t"] - ref["mu_t"])[reb], np.abs(obl["mu_tp"] - ref["mu_tp"])[reb]])
    kl = np.abs(obl["K_L"] - ref["K_L"])[ok]
    missing = int(np.sum(~ok))
    return (float(np.max(mu)) if mu.size else math.nan, float(np.max(kl)) if kl.size else math.nan,
            int(np.sum(mismatch)), missing)


def _reference_set(contact, speeds, cases, cfg, verbose):
    """Reference values (DOP853 at the tightest rtol) and the bound on their error."""
    r_loose, r_tight = cfg.reference_rtols
    _log(f"reference: DOP853 at rtol {r_tight:g} and {r_loose:g}, engine at {r_tight:g}", verbose)
    t0 = time.perf_counter()
    e_t, _, obl_t = _run_reference(contact, speeds, cases, r_tight, atol=r_tight * 1e-2, time_limit=120.0)
    e_l, _, obl_l = _run_reference(contact, speeds, cases, r_loose, atol=r_loose * 1e-2, time_limit=120.0)
    e_eng = np.array([engine.solve_normal(contact, float(v), rtol=r_tight).e_n for v in speeds])
    obl_eng = _engine_oblique(contact, cases, r_tight)
    elapsed = time.perf_counter() - t0

    def diff(a, b):
        d = np.abs(np.asarray(a) - np.asarray(b))
        return float(np.nanmax(d)) if np.any(np.isfinite(d)) else math.nan

    ok = np.isfinite(obl_t["K_L"])
    reb = ok & ~obl_t["captured"] & ~obl_eng["captured"] & ~obl_l["captured"]
    bound = {
        "e_n_engine": diff(e_t, e_eng),
        "e_n_self": diff(e_t, e_l),
        "mu_engine": max(diff(obl_t["mu_t"][reb], obl_eng["mu_t"][reb]), diff(obl_t["mu_tp"][reb], obl_eng["mu_tp"][reb]))
        if reb.any() else math.nan,
        "mu_self": max(diff(obl_t["mu_t"][reb], obl_l["mu_t"][reb]), diff(obl_t["mu_tp"][reb], obl_l["mu_tp"][reb]))
        if reb.any() else math.nan,
        "K_L_engine": diff(obl_t["K_L"][ok], obl_eng["K_L"][ok]) if ok.any() else math.nan,
        "K_L_self": diff(obl_t["K_L"][ok], obl_l["K_L"][ok]) if ok.any() else math.nan,
        "outcome_mismatch": int(np.sum(ok & (obl_t["captured"] != obl_eng["captured"]))),
        "missing_cases": int(np.sum(~ok)),
        "seconds": elapsed,
    }
    bound["e_n"] = max(bound["e_n_engine"], bound["e_n_self"])
    bound["mu"] = np.nanmax([bound["mu_engine"], bound["mu_self"]])
    bound["K_L"] = np.nanmax([bound["K_L_engine"], bound["K_L_self"]])
    # per-case disagreement of the two formulations (for the report)
    per_case = []
    for j, case in enumerate(cases):
        per_case.append({
            "case": j, **{k: getattr(case, k) for k in case.__dataclass_fields__},
            "outcome_reference": "capture" if obl_t["captured"][j] else "rebound",
            "outcome_engine": "capture" if obl_eng["captured"][j] else "rebound",
            "d_mu_t": float(abs(obl_t["mu_t"][j] - obl_eng["mu_t"][j])),
            "d_mu_tp": float(abs(obl_t["mu_tp"][j] - obl_eng["mu_tp"][j])),
            "d_K_L": float(abs(obl_t["K_L"][j] - obl_eng["K_L"][j])),
            "reference_timeout": bool(obl_t["timeout"][j]),
            "reference_failed": obl_t["failed"][j],
        })
    return e_t, obl_t, bound, per_case


# =============================================================================== throughput / memory
def _random_oblique_batch(contact, n, seed=12345):
    rng = np.random.default_rng(seed)
    v_cap = 1.0
    speed = np.exp(rng.uniform(np.log(0.5 * v_cap), np.log(100.0), n))
    inc = rng.uniform(10.0, 80.0, n)
    az = rng.uniform(0.0, 360.0, n)
    w = speed * np.sin(np.radians(inc)) / contact.radius
    om = (rng.uniform(-1, 1, n) * w, rng.uniform(-10, 10, n) * w, rng.uniform(-10, 10, n) * w)
    fric = np.where(rng.random(n) < 0.5, 0.15, 0.5)
    return speed, inc, az, om, fric


def measure_throughput(contact=WALL_1990, n=100_000, repeats=3, rtol=1e-10):
    """Median wall time [s] of simulate_many on ``n`` random oblique impacts (distinct normal speeds)."""
    speed, inc, az, om, fric = _random_oblique_batch(contact, n)
    simulate_many(contact, speed[:10], inc[:10], az[:10], tuple(o[:10] for o in om), fric[:10], rtol=rtol)
    t, ds = _timed(lambda: simulate_many(contact, speed, inc, az, om, fric, rtol=rtol), repeats)
    n_distinct = int(np.unique(speed * np.cos(np.radians(inc))).size)
    return {"seconds": t, "n": n, "n_distinct_normal_speeds": n_distinct,
            "captured_fraction": float(ds["outcome"].mean()), "output_bytes": int(ds.nbytes), "rtol": rtol}


def measure_memory(contact=WALL_1990, n=10_000, rtol=1e-10):
    """Peak traced Python/numpy memory [bytes] of simulate_many on ``n`` impacts, and its output size."""
    speed, inc, az, om, fric = _random_oblique_batch(contact, n)
    gc.collect()
    tracemalloc.start()
    tracemalloc.reset_peak()
    base = tracemalloc.get_traced_memory()[0]
    ds = simulate_many(contact, speed, inc, az, om, fric, rtol=rtol)
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    inputs = sum(a.nbytes for a in (speed, inc, az, fric, *om))
    return {"n": n, "peak_bytes": int(peak), "output_bytes": int(ds.nbytes), "input_bytes": int(inputs)}


# =============================================================================== the benchmark
def _machine_attrs() -> dict:
    import numba
    import scipy

    from microimpact import __version__

    cpu = platform.processor() or ""
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    return {
        "machine_platform": platform.platform(),
        "machine_processor": cpu,
        "machine_cpu_count": os.cpu_count() or 0,
        "machine_load_average_1min_at_start": float(load),
        "numba_threads": int(numba.get_num_threads()),
        "python_version": platform.python_version(),
        "numpy_version": np.__version__,
        "scipy_version": scipy.__version__,
        "numba_version": numba.__version__,
        "xarray_version": xr.__version__,
        "microimpact_version": __version__,
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    }


def run_benchmark(quick: bool = False, *, contact=WALL_1990, config: BenchmarkConfig | None = None,
                  verbose: bool = False, throughput: bool = True) -> xr.Dataset:
    """Run the work-precision benchmark and return its results.

    Parameters
    ----------
    quick : bool
        Smaller test set, fewer settings and repeats (< 60 s; for CI and the workflow).
    contact : Contact
        Contact parameters (default WALL_1990, Table 1 row 2).
    config : BenchmarkConfig, optional
        Overrides ``quick``.
    verbose : bool
        Progress on stderr.
    throughput : bool
        Also measure the 100,000-impact throughput and the memory scaling.

    Returns
    -------
    xarray.Dataset
        Dims ``method`` and ``setting``; variables ``time_per_impact`` [s], ``max_error_e_n``,
        ``max_rel_error_e_n``, ``max_error_mu``, ``max_error_K_L`` [1], ``n_impacts``, ``rtol``,
        ``steps_per_contact``, ``mean_steps`` (engine and RKG), ``status``; attributes with the
        machine, versions, the reference error bound, targets and ratios.
    """
    cfg = config or (BenchmarkConfig.quick_() if quick else BenchmarkConfig.full())
    attrs = _machine_attrs()
    t_start = time.perf_counter()
    notes: list[str] = []

    # --- warm up numba (compile or load the cache) before anything is timed
    engine.solve_normal(contact, 3.0)
    engine.solve_normal_many(contact, np.array([2.0, 3.0]), np.array([False, True]))
    simulate_many(contact, [2.0, 3.0], 30.0, rtol=1e-10)
    rkg_restitution(contact, [3.0], 10)

    speeds, v_cap = normal_speed_set(contact, cfg.n_speeds, cfg.max_speed, cfg.capture_margin)
    cases = cfg.oblique
    _log(f"capture speed {v_cap:.10g} m/s; {len(speeds)} normal speeds, {len(cases)} oblique cases", verbose)

    e_ref, obl_ref, bound, per_case = _reference_set(contact, speeds, cases, cfg, verbose)
    _log(f"reference bound: e_n {bound['e_n']:.3g}, mu {bound['mu']:.3g}, K_L {bound['K_L']:.3g}", verbose)

    n_set = max(max(cfg.engine_levels), max(cfg.scipy_levels), max(cfg.rkg_levels)) + 1
    shape = (len(ALL_METHODS), n_set)
    res = {k: np.full(shape, np.nan) for k in (
        "time_per_impact", "max_error_e_n", "max_rel_error_e_n", "max_error_mu", "max_error_K_L",
        "n_impacts", "rtol", "steps_per_contact", "mean_steps", "outcome_mismatches",
        "time_per_impact_normal_solve")}
    status = np.full(shape, "", dtype=object)
    mi = {m: i for i, m in enumerate(ALL_METHODS)}

    def record(method, k, t, e_n, obl=None, n_imp=len(speeds), steps=math.nan, state="ok"):
        i = mi[method]
        err = np.abs(np.asarray(e_n) - e_ref)
        res["time_per_impact"][i, k] = t
        res["max_error_e_n"][i, k] = float(np.max(err)) if np.all(np.isfinite(err)) else math.nan
        res["max_rel_error_e_n"][i, k] = float(np.max(err / np.abs(e_ref))) if np.all(np.isfinite(err)) else math.nan
        if obl is not None:
            mu, kl, mism, missing = _oblique_errors(obl, obl_ref)
            res["max_error_mu"][i, k] = mu
            res["max_error_K_L"][i, k] = kl
            res["outcome_mismatches"][i, k] = mism
            if missing:
                state += f"; {missing} oblique case(s) without result"
        res["n_impacts"][i, k] = n_imp
        res["mean_steps"][i, k] = steps
        status[i, k] = state

    batch_speeds = np.geomspace(speeds[0], speeds[-1], cfg.batch_size)

    # --- engine, one call per impact
    for k in cfg.engine_levels:
        rt = level_rtol(k)
        res["rtol"][mi["engine"], k] = rt
        e_n = np.empty(len(speeds))
        times = np.empty(len(speeds))
        steps = np.empty(len(speeds))
        t_normal = np.empty(len(speeds))
        for j, v in enumerate(speeds):
            times[j], r = _timed(lambda v=v: simulate_impact(contact, float(v), rtol=rt), cfg.repeats_single)
            e_n[j] = r.e_n
            t_normal[j], sol = _timed(lambda v=v: engine.solve_normal(contact, float(v), rtol=rt), cfg.repeats_single)
            steps[j] = sol.n_steps
        res["time_per_impact_normal_solve"][mi["engine"], k] = float(np.median(t_normal))
        record("engine", k, float(np.median(times)), e_n, _engine_oblique(contact, cases, rt),
               steps=float(np.mean(steps)))
        _log(f"engine rtol {rt:g}: {np.median(times) * 1e6:.1f} us, err {res['max_error_e_n'][mi['engine'], k]:.2e}", verbose)

    # --- engine, batches through solve_normal_many / simulate_many
    for k in cfg.engine_levels:
        rt = level_rtol(k)
        res["rtol"][mi["engine_batch"], k] = rt
        t, sol = _timed(lambda: engine.solve_normal_many(contact, batch_speeds, None, rtol=rt), cfg.repeats_batch)
        e_n = engine.solve_normal_many(contact, speeds, None, rtol=rt)["e_n"]
        record("engine_batch", k, t / batch_speeds.size, e_n, _engine_many_oblique(contact, cases, rt),
               n_imp=batch_speeds.size, steps=float(np.mean(sol["n_steps"])))
        _log(f"engine_batch rtol {rt:g}: {t / batch_speeds.size * 1e6:.2f} us/impact", verbose)

    # --- Runge-Kutta-Gill, fixed step, numba-compiled batch
    setup_batch = _rkg_setup(contact, batch_speeds)
    setup_set = _rkg_setup(contact, speeds)
    for k in cfg.rkg_levels:
        n = level_steps(k)
        res["steps_per_contact"][mi["rkg"], k] = n
        t, sol = _timed(lambda: rkg_restitution(contact, batch_speeds, n, setup=setup_batch), cfg.repeats_batch)
        r = rkg_restitution(contact, speeds, n, setup=setup_set)
        record("rkg", k, t / batch_speeds.size, r["e_n"], None, n_imp=batch_speeds.size,
               steps=float(np.mean(sol["n_steps"])))
        _log(f"rkg N={n}: {t / batch_speeds.size * 1e6:.2f} us/impact, err {res['max_error_e_n'][mi['rkg'], k]:.2e}", verbose)

    # --- scipy solve_ivp methods through the reference solver
    for method in SCIPY_METHODS:
        dropped = False
        for k in cfg.scipy_levels:
            rt = level_rtol(k)
            i = mi[method]
            res["rtol"][i, k] = rt
            if dropped:
                status[i, k] = "dropped (a looser setting exceeded the time limit)"
                continue
            per = []
            e_n = None
            for rep in range(cfg.repeats_scipy):
                e_n, times, _ = _run_reference(contact, speeds, (), rt, method=method, time_limit=cfg.time_limit)
                per.append(times)
                if not np.all(np.isfinite(times)):
                    break
            times = np.median(np.array(per), axis=0)
            if not np.all(np.isfinite(times)):
                dropped = True
                res["time_per_impact"][i, k] = math.inf
                status[i, k] = f"dropped: an impact took more than {cfg.time_limit:g} s"
                notes.append(f"{method} at rtol {rt:g} dropped (an impact took > {cfg.time_limit:g} s); "
                             "tighter settings not run")
                _log(notes[-1], verbose)
                continue
            _, _, obl = _run_reference(contact, (), cases, rt, method=method, time_limit=4 * cfg.time_limit)
            record(method, k, float(np.median(times)), e_n, obl)
            for j, msg in enumerate(obl["failed"]):
                if msg:
                    notes.append(f"{method} at rtol {rt:g} (atol = rtol), oblique case {j}: {msg.splitlines()[0][:160]}")
            if obl["timeout"].any():
                notes.append(f"{method} at rtol {rt:g}: {int(obl['timeout'].sum())} oblique case(s) exceeded "
                             f"{4 * cfg.time_limit:g} s (cases {[int(x) for x in np.flatnonzero(obl['timeout'])]})")
            _log(f"{method} rtol {rt:g}: {np.median(times) * 1e3:.2f} ms, err {res['max_error_e_n'][i, k]:.2e}", verbose)

    # --- engine diagnostics: one solve_normal call per impact in a Python loop versus the batch on
    # 1 thread and on all threads (same speeds), to separate Python overhead, per-impact fixed cost
    # and thread scaling
    import numba

    diag = {}
    n_thr = numba.get_num_threads()
    for rt in (1e-4, 1e-10):
        sub = batch_speeds[:: max(1, batch_speeds.size // 1000)]
        t_loop, _ = _timed(lambda: [engine.solve_normal(contact, float(v), rtol=rt) for v in sub], cfg.repeats_batch)
        row = {"loop_solve_normal": t_loop / sub.size}
        for th in sorted({1, n_thr}):
            numba.set_num_threads(th)
            try:
                t_b, sol = _timed(lambda: engine.solve_normal_many(contact, sub, None, rtol=rt), cfg.repeats_batch)
            finally:
                numba.set_num_threads(n_thr)
            row[f"batch_{th}_threads"] = t_b / sub.size
        row["mean_steps"] = float(np.mean(sol["n_steps"]))
        row["n"] = int(sub.size)
        diag[f"{rt:g}"] = row
    _log(f"engine diagnostics: {diag}", verbose)

    # --- targets and ratios
    tpi = res["time_per_impact"]
    err = res["max_error_e_n"]

    def cheapest(method, target):
        i = mi[method]
        ok = np.isfinite(tpi[i]) & (err[i] <= target)
        if not ok.any():
            return math.nan, math.nan
        j = int(np.flatnonzero(ok)[np.argmin(tpi[i][ok])])
        return float(tpi[i, j]), float(err[i, j])

    t_dop, e_dop = cheapest("DOP853", TARGET_ERROR)
    dop_bound_note = ""
    if not math.isfinite(t_dop):  # DOP853 never reached the target: its most accurate run is a lower bound
        i = mi["DOP853"]
        ok = np.isfinite(tpi[i]) & np.isfinite(err[i])
        if ok.any():
            j = int(np.flatnonzero(ok)[np.argmin(err[i][ok])])
            t_dop, e_dop = float(tpi[i, j]), float(err[i, j])
            dop_bound_note = " (DOP853 did not reach the target error; its most accurate run used: ratio is a lower bound)"
    t_eng, e_eng = cheapest("engine", TARGET_ERROR)
    t_engb, e_engb = cheapest("engine_batch", TARGET_ERROR)
    t_rkg, e_rkg = cheapest("rkg", TARGET_ERROR)
    ratio_single = t_dop / t_eng
    ratio_batch = t_dop / t_engb

    eng_err = err[mi["engine"]][list(cfg.engine_levels)]
    eng_ok = np.isfinite(eng_err)
    e_valid = eng_err[eng_ok]
    # monotone-ish: no tightening raises the error by more than 3x (noise near the reference bound
    # is allowed), and the tightest setting is at least 1e4 times better than the loosest
    floor = 10.0 * bound["e_n"]
    increases = [float(b / a) for a, b in zip(e_valid[:-1], e_valid[1:]) if b > 3.0 * a and b > floor]
    converges = bool(e_valid.size >= 2 and not increases and e_valid[-1] <= 1e-4 * e_valid[0])

    targets = {
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
        "target_ratio_note": dop_bound_note.strip(),
        "engine_converges": converges,
        "engine_error_increases": json.dumps(increases),
    }

    if throughput:
        _log(f"throughput: {cfg.throughput_impacts} oblique impacts through simulate_many", verbose)
        thr = measure_throughput(contact, cfg.throughput_impacts, cfg.throughput_repeats)
        mems = [measure_memory(contact, n) for n in cfg.memory_sizes]
        per_100k = thr["seconds"] * 100_000 / thr["n"]
        growth_peak = mems[1]["peak_bytes"] / mems[0]["peak_bytes"]
        growth_out = mems[1]["output_bytes"] / mems[0]["output_bytes"]
        targets.update({
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
        })
        _log(f"throughput {thr['seconds']:.2f} s for {thr['n']}; memory peak growth {growth_peak:.2f} vs output {growth_out:.2f}", verbose)

    # --- the dataset
    setting = np.arange(n_set)
    dims = ("method", "setting")
    units = {
        "time_per_impact": ("s", "median computing time per impact"),
        "max_error_e_n": ("1", "max over the normal-speed set of |e_n - e_n_ref|"),
        "max_rel_error_e_n": ("1", "max over the normal-speed set of |e_n - e_n_ref| / e_n_ref"),
        "max_error_mu": ("1", "max over rebounding oblique cases of |mu_t - ref| and |mu_t' - ref|"),
        "max_error_K_L": ("1", "max over all oblique cases of |K_L - K_L_ref|"),
        "n_impacts": ("1", "distinct impacts per timing (batch size for batch methods)"),
        "rtol": ("1", "relative tolerance (adaptive methods)"),
        "steps_per_contact": ("1", "fixed steps per estimated contact duration (RKG)"),
        "mean_steps": ("1", "mean accepted steps per impact (engine, RKG)"),
        "outcome_mismatches": ("1", "oblique cases whose outcome differs from the reference"),
        "time_per_impact_normal_solve": ("s", "engine row only: median time of one engine.solve_normal call "
                                              "(the normal solve without simulate_impact's Python layer)"),
    }
    data = {k: (dims, res[k], {"units": u, "long_name": ln}) for k, (u, ln) in units.items()}
    data["status"] = (dims, status.astype(str), {"long_name": "ok, or why a setting has no result"})
    timing_mode = {
        "engine": f"single call: simulate_impact, median over repeats ({cfg.repeats_single}) and speeds",
        "engine_batch": f"batch of {batch_speeds.size} distinct speeds: engine.solve_normal_many, "
                        f"{attrs['numba_threads']} threads, median of {cfg.repeats_batch}",
        "rkg": f"batch of {batch_speeds.size} distinct speeds: numba prange, {attrs['numba_threads']} threads, "
               f"median of {cfg.repeats_batch}",
        **{m: f"single call: simulate_reference(method={m!r}, atol=rtol), median over repeats "
              f"({cfg.repeats_scipy}) and speeds" for m in SCIPY_METHODS},
    }
    data["timing_mode"] = (("method",), np.array([timing_mode[m] for m in ALL_METHODS]))
    data["e_n_reference"] = (("normal_speed",), e_ref, {"units": "1", "long_name": "reference e_n (DOP853, tightest rtol)"})
    ds = xr.Dataset(
        data,
        coords={
            "method": ("method", np.array(ALL_METHODS)),
            "setting": ("setting", setting, {
                "long_name": "solver setting level k",
                "description": "adaptive methods: rtol = 10^-(4+k); rkg: N = 25 * 2^k steps per contact",
            }),
            "normal_speed": ("normal_speed", speeds, {"units": "m s-1", "long_name": "normal-speed test set"}),
        },
    )
    ds.attrs.update(attrs)
    ds.attrs.update({
        "title": "work-precision benchmark of the microimpact solvers",
        "contact": cfg.contact_name,
        "quick": int(cfg.quick),
        "capture_speed": v_cap,
        "capture_speed_units": "m s-1",
        "n_normal_speeds": len(speeds),
        "n_oblique_cases": len(cases),
        "oblique_cases": json.dumps([c.__dict__ for c in cases]),
        "reference": (f"scipy DOP853 on the full 3-D equations (simulate_reference) at rtol = {cfg.reference_rtols[1]:g}, "
                      f"atol = rtol / 100; bound = max(|DOP853 - engine| at that rtol, "
                      f"|DOP853({cfg.reference_rtols[0]:g}) - DOP853({cfg.reference_rtols[1]:g})|)"),
        "reference_bound_e_n": bound["e_n"],
        "reference_bound_mu": float(bound["mu"]),
        "reference_bound_K_L": float(bound["K_L"]),
        "reference_e_n_dop853_vs_engine": bound["e_n_engine"],
        "reference_e_n_self_convergence": bound["e_n_self"],
        "reference_mu_dop853_vs_engine": bound["mu_engine"],
        "reference_mu_self_convergence": bound["mu_self"],
        "reference_K_L_dop853_vs_engine": bound["K_L_engine"],
        "reference_K_L_self_convergence": bound["K_L_self"],
        "reference_outcome_mismatches": bound["outcome_mismatch"],
        "reference_missing_cases": bound["missing_cases"],
        "reference_per_case": json.dumps(per_case),
        "reference_seconds": bound["seconds"],
        "notes": json.dumps(notes),
        "engine_diagnostics": json.dumps(diag),
        "total_seconds": time.perf_counter() - t_start,
        "machine_load_average_1min_at_end": float(os.getloadavg()[0]) if hasattr(os, "getloadavg") else math.nan,
    })
    ds.attrs.update(targets)
    # NetCDF attributes cannot be booleans: store 0/1
    for k, v in list(ds.attrs.items()):
        if isinstance(v, (bool, np.bool_)):
            ds.attrs[k] = int(v)
    return ds


# =============================================================================== output
def _json_value(v):
    if isinstance(v, (np.integer,)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        v = float(v)
        return v if math.isfinite(v) else (None if math.isnan(v) else ("inf" if v > 0 else "-inf"))
    if isinstance(v, np.ndarray):
        return [_json_value(x) for x in v.tolist()]
    if isinstance(v, list):
        return [_json_value(x) for x in v]
    return v


def benchmark_json(ds: xr.Dataset) -> dict:
    """The benchmark numbers as a JSON-able dict: attrs plus one record per (method, setting)."""
    rows = []
    for i, m in enumerate(ds["method"].values):
        for j, s in enumerate(ds["setting"].values):
            sel = ds.isel(method=i, setting=j)
            if str(sel["status"].values) == "" and not np.isfinite(float(sel["time_per_impact"])):
                continue
            row = {"method": str(m), "setting": int(s), "status": str(sel["status"].values)}
            for k in ("rtol", "steps_per_contact", "time_per_impact", "max_error_e_n", "max_rel_error_e_n",
                      "max_error_mu", "max_error_K_L", "mean_steps", "n_impacts", "outcome_mismatches"):
                row[k] = _json_value(float(sel[k]))
            rows.append(row)
    attrs = {}
    for k, v in ds.attrs.items():
        if isinstance(v, str) and v[:1] in "[{":
            with contextlib.suppress(ValueError):
                v = json.loads(v)
        attrs[k] = _json_value(v)
    return {"attrs": attrs, "results": rows,
            "e_n_reference": {"normal_speed_m_s": _json_value(ds["normal_speed"].values),
                              "e_n": _json_value(ds["e_n_reference"].values)}}


def _fmt(x, spec=".2e"):
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    if isinstance(x, float) and math.isinf(x):
        return "inf"
    return format(x, spec)


def _fmt_time(t):
    if not math.isfinite(t):
        return "-" if math.isnan(t) else "> limit"
    if t < 1e-3:
        return f"{t * 1e6:.3g} us"
    if t < 1:
        return f"{t * 1e3:.3g} ms"
    return f"{t:.3g} s"


def benchmark_markdown(ds: xr.Dataset) -> str:
    """A markdown summary of the benchmark (the table, ratios, reference bound, memory)."""
    a = ds.attrs
    js = benchmark_json(ds)
    lines = [
        "# Work-precision benchmark",
        "",
        f"Generated by `python -m microimpact.studies.benchmark{' --quick' if a.get('quick') else ''}` on {a['date']} "
        f"({'QUICK mode: small test set' if a.get('quick') else 'full mode'}).",
        "",
        f"Machine: {a['machine_processor']}, {a['machine_cpu_count']} CPUs, {a['machine_platform']}; "
        f"1-min load average {a['machine_load_average_1min_at_start']:.2f} at start, "
        f"{a.get('machine_load_average_1min_at_end', math.nan):.2f} at end (above 1 per CPU, other jobs "
        f"shared the CPUs: timings are medians but noisy, the 2-thread batches most); numba threads {a['numba_threads']}. "
        f"Python {a['python_version']}, numpy {a['numpy_version']}, scipy {a['scipy_version']}, "
        f"numba {a['numba_version']}, xarray {a['xarray_version']}, microimpact {a['microimpact_version']}.",
        "",
        f"Contact {a['contact']} (Table 1 row 2). Capture speed (bisection on the engine outcome): "
        f"{a['capture_speed']:.6g} m/s. Test set: {a['n_normal_speeds']} normal speeds log-spaced from "
        f"{float(ds['normal_speed'][0]):.4g} to {float(ds['normal_speed'][-1]):.4g} m/s; "
        f"{a['n_oblique_cases']} oblique cases (incidence 10-80 deg, spins up to 10 v_t/r, f = 0.15 and 0.5).",
        "",
        "## Reference and its error bound",
        "",
        f"{a['reference']}.",
        "",
        "| quantity | bound | DOP853 vs engine | DOP853 self-convergence |",
        "|---|---|---|---|",
        f"| e_n | {_fmt(a['reference_bound_e_n'])} | {_fmt(a['reference_e_n_dop853_vs_engine'])} | {_fmt(a['reference_e_n_self_convergence'])} |",
        f"| mu_t, mu_t' (rebounds) | {_fmt(a['reference_bound_mu'])} | {_fmt(a['reference_mu_dop853_vs_engine'])} | {_fmt(a['reference_mu_self_convergence'])} |",
        f"| K_L | {_fmt(a['reference_bound_K_L'])} | {_fmt(a['reference_K_L_dop853_vs_engine'])} | {_fmt(a['reference_K_L_self_convergence'])} |",
        "",
        f"Oblique cases whose outcome differs between the two: {a['reference_outcome_mismatches']}; "
        f"cases where the reference gave no result: {a['reference_missing_cases']}. "
        "Errors below the bound are not resolved by this reference.",
        "",
    ]
    per_case = js["attrs"].get("reference_per_case") or []
    bad = [c for c in per_case if (c["d_K_L"] or 0) > 1e-8 or (c["d_mu_t"] or 0) > 1e-8 or (c["d_mu_tp"] or 0) > 1e-8
           or c["reference_timeout"] or c["reference_failed"] or c["outcome_reference"] != c["outcome_engine"]]
    if bad:
        lines += ["Oblique cases where engine and reference disagree by more than 1e-8 (or the reference failed):", "",
                  "| case | v [m/s] | alpha [deg] | theta [deg] | spin (n, t, t') [v_t/r] | f | outcome ref / engine | d mu_t | d mu_t' | d K_L | reference |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        for c in bad:
            lines.append(
                f"| {c['case']} | {c['speed']:g} | {c['incidence_deg']:g} | {c['azimuth_deg']:g} | "
                f"({c['spin_n']:g}, {c['spin_t']:g}, {c['spin_tp']:g}) | {c['friction']:g} | "
                f"{c['outcome_reference']} / {c['outcome_engine']} | {_fmt(c['d_mu_t'])} | {_fmt(c['d_mu_tp'])} | "
                f"{_fmt(c['d_K_L'])} | {'timeout' if c['reference_timeout'] else (c['reference_failed'] or 'ok')} |")
        lines.append("")
    lines += [
        "## Results",
        "",
        "Time per impact: median (see `timing_mode`); batch methods use both cores. Errors are maxima over the "
        "test set against the reference.",
        "",
        "| method | setting | time per impact | max abs error e_n | max rel error e_n | max error mu | max error K_L | mean steps | status |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in js["results"]:
        setting = f"N = {int(r['steps_per_contact'])}" if r["method"] == "rkg" else f"rtol {r['rtol']:.0e}"
        t = r["time_per_impact"]
        t = math.inf if t == "inf" else (math.nan if t is None else t)
        lines.append(
            f"| {r['method']} | {setting} | {_fmt_time(t)} | {_fmt(r['max_error_e_n'])} | {_fmt(r['max_rel_error_e_n'])} | "
            f"{_fmt(r['max_error_mu'])} | {_fmt(r['max_error_K_L'])} | {_fmt(r['mean_steps'], '.0f')} | {r['status'] or 'ok'} |")
    i_eng = list(ds["method"].values).index("engine")
    tn = ds["time_per_impact_normal_solve"].isel(method=i_eng).values
    rt = ds["rtol"].isel(method=i_eng).values
    pairs = [f"rtol {r:.0e}: {_fmt_time(float(t))}" for r, t in zip(rt, tn) if np.isfinite(t)]
    lines += ["", "The `engine` single-call time is that of `simulate_impact` (normal incidence). One "
              "`engine.solve_normal` call alone takes " + "; ".join(pairs) + " (median); the difference is "
              "the Python layer of `simulate_impact` (input checks, tangential map, coefficients)."]
    i_b = list(ds["method"].values).index("engine_batch")
    tb = ds["time_per_impact"].isel(method=i_b).values
    sb = ds["mean_steps"].isel(method=i_b).values
    ok = np.isfinite(tb) & np.isfinite(sb)
    if ok.sum() >= 3:
        slope, icpt = np.polyfit(sb[ok], tb[ok], 1)
        threads = int(a.get("numba_threads", 1))
        lines += ["", f"Engine cost model (least squares over the `engine_batch` rows, wall time on {threads} "
                  f"threads): time per impact = {_fmt_time(icpt)} + {slope * 1e9:.0f} ns x accepted steps "
                  f"(about {_fmt_time(icpt * threads)} + {slope * 1e9 * threads:.0f} ns per step of CPU time per "
                  "impact). The fixed part is paid at every tolerance; at loose tolerances it dominates."]
    diag = json.loads(a.get("engine_diagnostics", "{}"))
    if diag:
        lines += ["", "Engine diagnostics (seconds per impact, same speeds): a Python loop over "
                  "`engine.solve_normal` versus `engine.solve_normal_many` on 1 thread and on all threads:", "",
                  "| rtol | mean steps | loop of solve_normal | batch, 1 thread | batch, all threads |", "|---|---|---|---|---|"]
        for rt, row in diag.items():
            multi = [k for k in row if k.startswith("batch_") and k != "batch_1_threads"]
            lines.append(f"| {rt} | {row['mean_steps']:.0f} | {_fmt_time(row['loop_solve_normal'])} | "
                         f"{_fmt_time(row['batch_1_threads'])} | {_fmt_time(row[multi[0]]) if multi else '-'} |")
    i_r = list(ds["method"].values).index("rkg")
    er = ds["max_error_e_n"].isel(method=i_r).values
    nr = ds["steps_per_contact"].isel(method=i_r).values
    tr = ds["time_per_impact"].isel(method=i_r).values
    okr = np.isfinite(er) & np.isfinite(nr) & np.isfinite(tr)
    if okr.sum() >= 3:
        e3, n3, t3 = er[okr][-3:], nr[okr][-3:], tr[okr][-3:]
        p = math.log(e3[0] / e3[-1]) / math.log(n3[-1] / n3[0])
        if p > 0 and e3[-1] > a["target_error_e_n"]:
            n_need = n3[-1] * (e3[-1] / a["target_error_e_n"]) ** (1.0 / p)
            lines += ["", f"RKG (fixed step, plain Eq. (27) in tau): observed order {p:.2f} in N over its last three "
                      f"settings (the x^(1/2) adhesion force is not smooth where contact starts and ends, so the "
                      f"4th order of the method is lost); reaching e_n error {a['target_error_e_n']:g} would need about "
                      f"N = {n_need:.2g} steps per contact, about {_fmt_time(t3[-1] * n_need / n3[-1])} per impact "
                      "(extrapolated)."]
    lines += ["", "Timing modes:", ""]
    for m, mode in zip(ds["method"].values, ds["timing_mode"].values):
        lines.append(f"- `{m}`: {mode}")
    lines += [
        "",
        "## Targets",
        "",
        f"At max e_n error <= {a['target_error_e_n']:g}: DOP853 {_fmt_time(a['dop853_time_at_target'])} "
        f"(error {_fmt(a['dop853_error_at_target'])}), engine single call {_fmt_time(a['engine_time_at_target'])} "
        f"(error {_fmt(a['engine_error_at_target'])}), engine batch {_fmt_time(a['engine_batch_time_at_target'])} "
        f"(error {_fmt(a['engine_batch_error_at_target'])}), RKG batch {_fmt_time(a['rkg_time_at_target'])}.",
        "",
        "| target | measured | met |",
        "|---|---|---|",
        f"| engine >= {a['target_ratio']:g}x faster than DOP853 at e_n error <= {a['target_error_e_n']:g} (single call) | "
        f"{_fmt(a['ratio_dop853_to_engine_single'], '.0f')}x | {'yes' if a['target_ratio_met_single'] else 'NO'} |",
        f"| same, engine batch (aim {a['target_ratio_aim']:g}x) | {_fmt(a['ratio_dop853_to_engine_batch'], '.0f')}x | "
        f"{'yes' if a['target_ratio_met_batch'] else 'NO'} (aim {'met' if a['target_ratio_aim_met_batch'] else 'not met'}) |",
        f"| engine errors fall as rtol tightens | increases > 3x above the noise floor: {a['engine_error_increases']} | "
        f"{'yes' if a['engine_converges'] else 'NO'} |",
    ]
    if a.get("target_ratio_note"):
        lines += ["", f"Note: {a['target_ratio_note']}"]
    if "throughput_seconds" in a:
        peaks = json.loads(a["memory_peak_bytes"])
        outs = json.loads(a["memory_output_bytes"])
        sizes = json.loads(a["memory_sizes"])
        lines += [
            f"| {a['throughput_impacts']:,} oblique impacts (distinct normal speeds) through simulate_many "
            f"in <= {a['target_throughput_seconds']:g} s | {a['throughput_seconds']:.2f} s"
            f"{' (scaled to 100k: %.2f s)' % a['throughput_seconds_per_100k'] if a['target_throughput_extrapolated'] else ''}"
            f" | {'yes' if a['target_throughput_met'] else 'NO'} |",
            f"| peak memory grows no faster than the output ({sizes[0]:,} -> {sizes[1]:,} impacts) | peak x{a['memory_peak_growth']:.2f}, "
            f"output x{a['memory_output_growth']:.2f} | {'yes' if a['target_memory_met'] else 'NO'} |",
            "",
            f"Throughput run: rtol {a['throughput_rtol']:g}, {a['throughput_distinct_normal_speeds']:,} distinct normal "
            f"speeds, captured fraction {a['throughput_captured_fraction']:.3f}. Memory (tracemalloc peak of "
            "Python/numpy allocations during simulate_many; numba's per-impact work arrays are not traced):",
            "",
            "| impacts | peak traced [MB] | output Dataset [MB] | peak per impact [B] |",
            "|---|---|---|---|",
        ]
        for n, p, o in zip(sizes, peaks, outs):
            lines.append(f"| {n:,} | {p / 1e6:.2f} | {o / 1e6:.2f} | {p / n:.0f} |")
    notes = json.loads(a.get("notes", "[]"))
    if notes:
        lines += ["", "## Notes", ""] + [f"- {n}" for n in notes]
    lines += ["", f"Total run time {a['total_seconds']:.0f} s.", ""]
    return "\n".join(lines)


def _plot(ds: xr.Dataset):
    """The work-precision figure (plots.plot_work_precision)."""
    from microimpact.report.figures import plot_work_precision

    return plot_work_precision(ds).figure


def write_benchmark(ds: xr.Dataset, out_dir, *, docs_dir=None) -> dict:
    """Write benchmark.nc, benchmark.json, benchmark.md and work_precision.pdf/png to ``out_dir``.

    All writes are atomic (:mod:`microimpact.io.files`). With ``docs_dir`` the markdown summary and
    the PNG are also written there (as ``benchmark.md`` and ``work_precision.png``).

    Returns
    -------
    dict of name -> pathlib.Path
    """
    from microimpact.io.files import atomic_path, atomic_write, write_netcdf

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"netcdf": out / "benchmark.nc", "json": out / "benchmark.json", "markdown": out / "benchmark.md",
             "pdf": out / "work_precision.pdf", "png": out / "work_precision.png"}
    write_netcdf(ds, paths["netcdf"])
    with atomic_write(paths["json"]) as f:
        json.dump(benchmark_json(ds), f, indent=1)
        f.write("\n")
    md = benchmark_markdown(ds)
    with atomic_write(paths["markdown"]) as f:
        f.write(md)
    fig = _plot(ds)
    for kind in ("pdf", "png"):
        with atomic_path(paths[kind]) as tmp:
            fig.savefig(tmp, format=kind, dpi=150, bbox_inches="tight")
    if docs_dir is not None:
        d = Path(docs_dir)
        d.mkdir(parents=True, exist_ok=True)
        with atomic_write(d / "benchmark.md") as f:
            f.write(md)
        with atomic_path(d / "work_precision.png") as tmp:
            fig.savefig(tmp, format="png", dpi=150, bbox_inches="tight")
        paths["docs_markdown"] = d / "benchmark.md"
        paths["docs_png"] = d / "work_precision.png"
    return paths


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m microimpact.studies.benchmark", description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results/benchmark", help="output directory (default results/benchmark)")
    parser.add_argument("--quick", action="store_true", help="small, fast run (< 60 s) for CI and the workflow")
    parser.add_argument("--docs", default=None, help="also write benchmark.md and work_precision.png here")
    parser.add_argument("--no-throughput", action="store_true", help="skip the 100k throughput and memory runs")
    args = parser.parse_args(argv)
    ds = run_benchmark(quick=args.quick, verbose=True, throughput=not args.no_throughput)
    paths = write_benchmark(ds, args.out, docs_dir=args.docs)
    for p in paths.values():
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
