"""Timing harness of the benchmark: timed calls, time-limited solves, oblique errors, throughput,
memory and the machine description.

Times are ``time.perf_counter`` medians over repeats; the scipy solves run under a wall-clock
limit (:func:`microimpact._runtime.timeout.time_limit`) so a setting that would take minutes is
dropped instead of stalling the run.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import gc
import math
import os
import platform
import sys
import time
import tracemalloc
from dataclasses import dataclass, field
from pathlib import Path

import numba
import numpy as np
import scipy
import xarray as xr

from microimpact import __version__
from microimpact.presets import WALL_1990
from microimpact.solvers.impact import simulate_impact, simulate_many
from microimpact.solvers.reference import simulate_reference
from microimpact._runtime.timeout import TimeLimitExceeded, time_limit

__all__ = ["measure_throughput", "measure_memory", "machine_attrs", "ObliqueResults"]


def timed(func, repeats: int):
    """(median seconds [s], last result) of ``repeats`` calls of ``func``."""
    times = []
    result = None
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        result = func()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), result


def log(msg: str, verbose: bool) -> None:
    """Progress on stderr when ``verbose``."""
    if verbose:
        print(msg, file=sys.stderr, flush=True)


# =============================================================================== oblique results
@dataclass
class ObliqueResults:
    """Results of one method on the oblique cases: outcome, mu_t, mu_t', K_L [-] per case, and
    which cases timed out or failed (message, empty if none).

    Examples
    --------
    Empty results of three cases, filled in by a method's run:

    >>> r = ObliqueResults(3)
    >>> r.captured.tolist(), r.mu_t.tolist(), r.failed
    ([False, False, False], [nan, nan, nan], ['', '', ''])
    """

    n: int
    captured: np.ndarray = field(init=False)
    mu_t: np.ndarray = field(init=False)
    mu_tp: np.ndarray = field(init=False)
    K_L: np.ndarray = field(init=False)
    timeout: np.ndarray = field(init=False)
    failed: list = field(init=False)

    def __post_init__(self):
        self.captured = np.zeros(self.n, bool)
        self.mu_t, self.mu_tp, self.K_L = (np.full(self.n, np.nan) for _ in range(3))
        self.timeout = np.zeros(self.n, bool)
        self.failed = [""] * self.n

    def set(self, j: int, result) -> None:
        """Store case ``j`` from an :class:`microimpact.ImpactResult`."""
        self.captured[j] = result.outcome == "capture"
        self.mu_t[j], self.mu_tp[j], self.K_L[j] = result.mu_t, result.mu_tp, result.K_L

    def errors(self, ref: "ObliqueResults") -> tuple[float, float, int, int]:
        """(max |mu - mu_ref| over rebounds, max |K_L - K_L_ref|, outcome mismatches, missing cases)."""
        ok = ~self.timeout & np.array([not f for f in self.failed]) & np.isfinite(ref.K_L)
        mismatch = ok & (self.captured != ref.captured)
        reb = ok & ~mismatch & ~ref.captured
        mu = np.concatenate([np.abs(self.mu_t - ref.mu_t)[reb], np.abs(self.mu_tp - ref.mu_tp)[reb]])
        kl = np.abs(self.K_L - ref.K_L)[ok]
        return (float(np.max(mu)) if mu.size else math.nan, float(np.max(kl)) if kl.size else math.nan,
                int(np.sum(mismatch)), int(np.sum(~ok)))


def _case_contact(contact, case):
    return contact.with_(friction=case.friction)


def run_reference(contact, speeds, cases, rtol, method="DOP853", atol=None, limit=None):
    """e_n at ``speeds`` and the oblique ``cases`` by :func:`microimpact.solvers.reference.simulate_reference`.

    Parameters
    ----------
    rtol, atol : float
        Tolerances of solve_ivp (atol defaults to rtol: the state is O(1) nondimensional). [-]
    method : str
        solve_ivp method.
    limit : float or None
        Wall-clock limit per impact [s]; a normal impact over it has time inf, an oblique one is
        marked ``timeout``.

    Returns
    -------
    e_n : numpy.ndarray
        NaN where timed out. [-]
    times : numpy.ndarray
        Seconds per normal impact (inf where timed out). [s]
    oblique : ObliqueResults
    """
    atol = rtol if atol is None else atol
    e_n = np.full(len(speeds), np.nan)
    times = np.full(len(speeds), np.nan)
    for i, v in enumerate(speeds):
        try:
            with time_limit(limit):
                t0 = time.perf_counter()
                e_n[i] = simulate_reference(contact, float(v), rtol=rtol, atol=atol, method=method).e_n
                times[i] = time.perf_counter() - t0
        except TimeLimitExceeded:
            times[i] = math.inf
    obl = ObliqueResults(len(cases))
    for j, case in enumerate(cases):
        c = _case_contact(contact, case)
        try:
            with time_limit(limit):
                obl.set(j, simulate_reference(c, case.speed, case.incidence_deg, case.azimuth_deg,
                                              case.omega(c.radius), rtol=rtol, atol=atol, method=method))
        except TimeLimitExceeded:
            obl.timeout[j] = True
        except Exception as exc:  # noqa: BLE001 - a failing reference is a result to report
            obl.failed[j] = f"{type(exc).__name__}: {exc}"[:200]
    return e_n, times, obl


def engine_oblique(contact, cases, rtol) -> ObliqueResults:
    """The oblique cases by :func:`microimpact.simulate_impact`, one call each."""
    obl = ObliqueResults(len(cases))
    for j, case in enumerate(cases):
        c = _case_contact(contact, case)
        obl.set(j, simulate_impact(c, case.speed, case.incidence_deg, case.azimuth_deg, case.omega(c.radius), rtol=rtol))
    return obl


def engine_many_oblique(contact, cases, rtol) -> ObliqueResults:
    """The oblique cases in one call of :func:`microimpact.simulate_many`."""
    om = np.array([case.omega(contact.radius) for case in cases])
    ds = simulate_many(contact, [c.speed for c in cases], [c.incidence_deg for c in cases],
                       [c.azimuth_deg for c in cases], (om[:, 0], om[:, 1], om[:, 2]),
                       [c.friction for c in cases], rtol=rtol)
    obl = ObliqueResults(len(cases))
    obl.captured = ds["outcome"].values == 1
    obl.mu_t, obl.mu_tp, obl.K_L = ds["mu_t"].values, ds["mu_tp"].values, ds["K_L"].values
    return obl


# =============================================================================== throughput / memory
def random_oblique_batch(contact, n, seed=12345):
    """Speeds [m/s] log-uniform in 0.5-100 m/s, incidence 10-80 deg, azimuth, spins up to 10x the rolling
    spin [rad/s] and friction 0.15 or 0.5 of ``n`` random oblique impacts (distinct normal speeds)."""
    rng = np.random.default_rng(seed)
    speed = np.exp(rng.uniform(np.log(0.5), np.log(100.0), n))
    inc = rng.uniform(10.0, 80.0, n)
    az = rng.uniform(0.0, 360.0, n)
    w = speed * np.sin(np.radians(inc)) / contact.radius
    om = (rng.uniform(-1, 1, n) * w, rng.uniform(-10, 10, n) * w, rng.uniform(-10, 10, n) * w)
    fric = np.where(rng.random(n) < 0.5, 0.15, 0.5)
    return speed, inc, az, om, fric


def measure_throughput(contact=WALL_1990, n=100_000, repeats=3, rtol=1e-10) -> dict:
    """Median wall time [s] of simulate_many on ``n`` random oblique impacts (distinct normal speeds).

    Examples
    --------
    500 random oblique impacts, all with distinct normal speeds (no shared solves):

    >>> t = measure_throughput(n=500, repeats=1)
    >>> t["n"], t["n_distinct_normal_speeds"], t["seconds"] > 0.0
    (500, 500, True)
    """
    speed, inc, az, om, fric = random_oblique_batch(contact, n)
    simulate_many(contact, speed[:10], inc[:10], az[:10], tuple(o[:10] for o in om), fric[:10], rtol=rtol)
    t, ds = timed(lambda: simulate_many(contact, speed, inc, az, om, fric, rtol=rtol), repeats)
    n_distinct = int(np.unique(speed * np.cos(np.radians(inc))).size)
    return {"seconds": t, "n": n, "n_distinct_normal_speeds": n_distinct,
            "captured_fraction": float(ds["outcome"].mean()), "output_bytes": int(ds.nbytes), "rtol": rtol}


def measure_memory(contact=WALL_1990, n=10_000, rtol=1e-10) -> dict:
    """Peak traced Python/numpy memory [bytes] of simulate_many on ``n`` impacts, and its output size.

    Examples
    --------
    >>> m = measure_memory(n=200)
    >>> m["n"], m["input_bytes"], m["output_bytes"] > m["input_bytes"]
    (200, 11200, True)
    """
    speed, inc, az, om, fric = random_oblique_batch(contact, n)
    gc.collect()
    tracemalloc.start()
    tracemalloc.reset_peak()
    base = tracemalloc.get_traced_memory()[0]
    ds = simulate_many(contact, speed, inc, az, om, fric, rtol=rtol)
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    inputs = sum(a.nbytes for a in (speed, inc, az, fric, *om))
    return {"n": n, "peak_bytes": int(peak), "output_bytes": int(ds.nbytes), "input_bytes": int(inputs)}


# =============================================================================== machine
def load_average() -> float:
    """1-minute load average (NaN where the OS has none)."""
    return float(os.getloadavg()[0]) if hasattr(os, "getloadavg") else math.nan


def machine_attrs() -> dict:
    """Machine, library versions and date, as NetCDF attributes.

    Examples
    --------
    >>> attrs = machine_attrs()
    >>> {"python_version", "numpy_version", "numba_threads", "machine_cpu_count"} <= set(attrs)
    True
    """
    cpu = platform.processor() or ""
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    return {
        "machine_platform": platform.platform(),
        "machine_processor": cpu,
        "machine_cpu_count": os.cpu_count() or 0,
        "machine_load_average_1min_at_start": load_average(),
        "numba_threads": int(numba.get_num_threads()),
        "python_version": platform.python_version(),
        "numpy_version": np.__version__,
        "scipy_version": scipy.__version__,
        "numba_version": numba.__version__,
        "xarray_version": xr.__version__,
        "microimpact_version": __version__,
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    }
