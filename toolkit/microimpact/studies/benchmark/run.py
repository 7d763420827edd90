"""The benchmark run: every method at every setting on one test set, then targets and a Dataset.

:func:`run_benchmark` is a sequence of short steps: warm-up, test set, reference
(:mod:`microimpact.studies.benchmark.reference`), one runner per method family writing into a :class:`_Table`, engine
diagnostics, targets, throughput and memory, and :func:`_dataset`.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field

import numba
import numpy as np
import xarray as xr

from microimpact._runtime.progress import progress_bar
from microimpact.io.provenance import contact_attributes, preset_parameter_source
from microimpact.io.variables import attributes
from microimpact.presets import WALL_1990
from microimpact.solvers import check_time_budget, engine
from microimpact.solvers.impact import simulate_impact, simulate_many
from microimpact.solvers.rkg import rkg_setup, rkg_restitution
from microimpact.studies.benchmark.cases import (
    ALL_METHODS, SCIPY_METHODS, BenchmarkConfig, level_rtol, level_steps, normal_speed_set,
)
from microimpact.studies.benchmark.harness import (
    ObliqueResults, engine_many_oblique, engine_oblique, load_average, log, machine_attrs, run_reference, timed,
)
from microimpact.studies.benchmark.reference import Reference, reference_set
from microimpact.studies.benchmark.targets import accuracy_targets, throughput_targets
from microimpact._runtime.timeout import time_limit

__all__ = ["run_benchmark"]

#: Variables of the (method, setting) table; units and long names from :mod:`microimpact.io.variables`.
_TABLE_VARIABLES = (
    "time_per_impact", "max_error_e_n", "max_rel_error_e_n", "max_error_mu", "max_error_K_L", "n_impacts",
    "rtol", "steps_per_contact", "mean_steps", "outcome_mismatches", "time_per_impact_normal_solve",
)


@dataclass
class _Table:
    """Results by (method, setting), filled by the runners; errors against ``reference``."""

    reference: Reference
    n_settings: int
    values: dict = field(init=False)
    status: np.ndarray = field(init=False)

    def __post_init__(self):
        shape = (len(ALL_METHODS), self.n_settings)
        self.values = {k: np.full(shape, np.nan) for k in _TABLE_VARIABLES}
        self.status = np.full(shape, "", dtype=object)

    def set(self, name: str, method: str, k: int, value) -> None:
        self.values[name][ALL_METHODS.index(method), k] = value

    def get(self, name: str, method: str, k: int | None = None):
        row = self.values[name][ALL_METHODS.index(method)]
        return row if k is None else row[k]

    def record(self, method, k, t, e_n, obl: ObliqueResults | None, n_imp, steps=math.nan, state="ok"):
        """Store time per impact ``t`` [s], e_n errors against the reference and oblique errors."""
        err = np.abs(np.asarray(e_n) - self.reference.e_n)
        finite = np.all(np.isfinite(err))
        self.set("time_per_impact", method, k, t)
        self.set("max_error_e_n", method, k, float(np.max(err)) if finite else math.nan)
        self.set("max_rel_error_e_n", method, k, float(np.max(err / np.abs(self.reference.e_n))) if finite else math.nan)
        if obl is not None:
            mu, kl, mismatches, missing = obl.errors(self.reference.oblique)
            self.set("max_error_mu", method, k, mu)
            self.set("max_error_K_L", method, k, kl)
            self.set("outcome_mismatches", method, k, mismatches)
            if missing:
                state += f"; {missing} oblique case(s) without result"
        self.set("n_impacts", method, k, n_imp)
        self.set("mean_steps", method, k, steps)
        self.status[ALL_METHODS.index(method), k] = state


# =============================================================================== runners
def _warm_up(contact) -> None:
    """Compile (or load from the cache) every numba function before anything is timed.

    On an empty cache the fit job needs the engine's batch kernel too; its compile lock
    (:func:`microimpact._numba.njit_batch`) lets one of the two jobs compile it and the other load
    it, instead of both compiling it. The Runge-Kutta-Gill call comes first but takes that lock
    first as well: its setup (:func:`microimpact.solvers.rkg.rkg_setup`) runs the engine's batch
    kernel for the contact durations, so in the pipeline this job, which starts before the fit
    (the fit waits for validate_data), compiles the engine and the fit loads it.
    """
    rkg_restitution(contact, [3.0], 10)
    engine.solve_normal_many(contact, np.array([2.0, 3.0]), np.array([False, True]))
    engine.solve_normal(contact, 3.0)
    simulate_many(contact, [2.0, 3.0], 30.0, rtol=1e-10)


def _run_engine(contact, speeds, cases, cfg: BenchmarkConfig, table: _Table, verbose: bool) -> None:
    """``engine``: one simulate_impact call per impact (and one engine.solve_normal, for comparison)."""
    for k in cfg.engine_levels:
        rt = level_rtol(k)
        table.set("rtol", "engine", k, rt)
        e_n, times, steps, t_normal = (np.empty(len(speeds)) for _ in range(4))
        for j, v in enumerate(speeds):
            times[j], r = timed(lambda v=v: simulate_impact(contact, float(v), rtol=rt), cfg.repeats_single)
            e_n[j] = r.e_n
            t_normal[j], sol = timed(lambda v=v: engine.solve_normal(contact, float(v), rtol=rt), cfg.repeats_single)
            steps[j] = sol.n_steps
        table.set("time_per_impact_normal_solve", "engine", k, float(np.median(t_normal)))
        table.record("engine", k, float(np.median(times)), e_n, engine_oblique(contact, cases, rt), len(speeds),
                     steps=float(np.mean(steps)))
        log(f"engine rtol {rt:g}: {np.median(times) * 1e6:.1f} us, err {table.get('max_error_e_n', 'engine', k):.2e}",
            verbose)


def _run_engine_batch(contact, speeds, batch_speeds, cases, cfg: BenchmarkConfig, table: _Table, verbose: bool) -> None:
    """``engine_batch``: engine.solve_normal_many on a batch of distinct speeds; oblique via simulate_many."""
    for k in cfg.engine_levels:
        rt = level_rtol(k)
        table.set("rtol", "engine_batch", k, rt)
        t, sol = timed(lambda: engine.solve_normal_many(contact, batch_speeds, None, rtol=rt), cfg.repeats_batch)
        e_n = engine.solve_normal_many(contact, speeds, None, rtol=rt)["e_n"]
        table.record("engine_batch", k, t / batch_speeds.size, e_n, engine_many_oblique(contact, cases, rt),
                     batch_speeds.size, steps=float(np.mean(sol["n_steps"])))
        log(f"engine_batch rtol {rt:g}: {t / batch_speeds.size * 1e6:.2f} us/impact", verbose)


def _run_rkg(contact, speeds, batch_speeds, cfg: BenchmarkConfig, table: _Table, verbose: bool) -> None:
    """``rkg``: the paper's fixed-step Runge-Kutta-Gill, numba batch; its setup is not timed."""
    setup_batch = rkg_setup(contact, batch_speeds)
    setup_set = rkg_setup(contact, speeds)
    for k in cfg.rkg_levels:
        n = level_steps(k)
        table.set("steps_per_contact", "rkg", k, n)
        t, sol = timed(lambda: rkg_restitution(contact, batch_speeds, n, setup=setup_batch), cfg.repeats_batch)
        r = rkg_restitution(contact, speeds, n, setup=setup_set)
        table.record("rkg", k, t / batch_speeds.size, r.e_n, None, batch_speeds.size,
                     steps=float(np.mean(sol.n_steps)))
        log(f"rkg N={n}: {t / batch_speeds.size * 1e6:.2f} us/impact, err {table.get('max_error_e_n', 'rkg', k):.2e}",
            verbose)


def _timed_scipy_normal(contact, speeds, method, rt, cfg: BenchmarkConfig):
    """(e_n, median seconds per normal impact) over ``cfg.repeats_scipy``; inf where a solve timed out."""
    per, e_n = [], None
    for _ in range(cfg.repeats_scipy):
        e_n, times, _ = run_reference(contact, speeds, (), rt, method=method, limit=cfg.time_limit)
        per.append(times)
        if not np.all(np.isfinite(times)):
            break
    return e_n, np.median(np.array(per), axis=0)


def _oblique_notes(method, rt, obl: ObliqueResults, limit: float) -> list[str]:
    notes = [f"{method} at rtol {rt:g} (atol = rtol), oblique case {j}: {msg.splitlines()[0][:160]}"
             for j, msg in enumerate(obl.failed) if msg]
    if obl.timeout.any():
        notes.append(f"{method} at rtol {rt:g}: {int(obl.timeout.sum())} oblique case(s) exceeded {limit:g} s "
                     f"(cases {[int(x) for x in np.flatnonzero(obl.timeout)]})")
    return notes


def _run_scipy(contact, speeds, cases, cfg: BenchmarkConfig, table: _Table, notes: list, verbose: bool) -> None:
    """scipy's solve_ivp methods through the reference solver; a setting over the time limit is
    dropped with the tighter ones."""
    for method in SCIPY_METHODS:
        i = ALL_METHODS.index(method)
        dropped = False
        for k in cfg.scipy_levels:
            rt = level_rtol(k)
            table.set("rtol", method, k, rt)
            if dropped:
                table.status[i, k] = "dropped (a looser setting exceeded the time limit)"
                continue
            e_n, times = _timed_scipy_normal(contact, speeds, method, rt, cfg)
            if not np.all(np.isfinite(times)):
                dropped = True
                table.set("time_per_impact", method, k, math.inf)
                table.status[i, k] = f"dropped: an impact took more than {cfg.time_limit:g} s"
                notes.append(f"{method} at rtol {rt:g} dropped (an impact took > {cfg.time_limit:g} s); "
                             "tighter settings not run")
                log(notes[-1], verbose)
                continue
            _, _, obl = run_reference(contact, (), cases, rt, method=method, limit=cfg.oblique_time_limit)
            table.record(method, k, float(np.median(times)), e_n, obl, len(speeds))
            notes.extend(_oblique_notes(method, rt, obl, cfg.oblique_time_limit))
            log(f"{method} rtol {rt:g}: {np.median(times) * 1e3:.2f} ms, err {table.get('max_error_e_n', method, k):.2e}",
                verbose)


def _engine_diagnostics(contact, batch_speeds, cfg: BenchmarkConfig) -> dict:
    """Seconds per impact of a Python loop over engine.solve_normal versus the batch on 1 thread and
    on all threads (same speeds): Python overhead, per-impact fixed cost and thread scaling."""
    diag = {}
    n_thr = numba.get_num_threads()
    sub = batch_speeds[:: max(1, batch_speeds.size // 1000)]
    for rt in (1e-4, 1e-10):
        t_loop, _ = timed(lambda: [engine.solve_normal(contact, float(v), rtol=rt) for v in sub], cfg.repeats_batch)
        row = {"loop_solve_normal": t_loop / sub.size}
        for th in sorted({1, n_thr}):
            numba.set_num_threads(th)
            try:
                t_b, sol = timed(lambda: engine.solve_normal_many(contact, sub, None, rtol=rt), cfg.repeats_batch)
            finally:
                numba.set_num_threads(n_thr)
            row[f"batch_{th}_threads"] = t_b / sub.size
        row["mean_steps"] = float(np.mean(sol["n_steps"]))
        row["n"] = int(sub.size)
        diag[f"{rt:g}"] = row
    return diag


# =============================================================================== the Dataset
def diagnostics_lines(diag: dict) -> list[str]:
    """The progress lines of :func:`_engine_diagnostics`: one per tolerance, times per impact in us.

    Examples
    --------
    >>> row = {"loop_solve_normal": 2.5e-6, "batch_1_threads": 1.0e-6, "batch_2_threads": 0.6e-6, "mean_steps": 41.0,
    ...        "n": 1000}
    >>> print(diagnostics_lines({"0.0001": row})[0])
    engine diagnostics, rtol 0.0001: loop of solve_normal 2.50 us, batch on 1 thread 1.00 us, on 2 threads 0.60 us per impact (41 steps, 1000 speeds)
    """
    lines = []
    for rt, row in diag.items():
        batch = [(int(k.split("_")[1]), v) for k, v in row.items() if k.startswith("batch_")]
        on = ", on ".join(f"{n} thread{'s' if n > 1 else ''} {1e6 * t:.2f} us" for n, t in batch)
        lines.append(f"engine diagnostics, rtol {rt}: loop of solve_normal {1e6 * row['loop_solve_normal']:.2f} us, "
                     f"batch on {on} per impact ({row['mean_steps']:.0f} steps, {row['n']} speeds)")
    return lines


def sub_model_lines(costs: dict) -> list[str]:
    """The progress lines of :func:`~microimpact.studies.benchmark.sub_models.sub_model_costs`: one
    per selection of sub-models, its time per impact and its ratio to the paper's model.

    Examples
    --------
    >>> costs = {"paper (rigid, net)": {"time_per_impact": 2e-6, "ratio_to_paper": 1.0},
    ...          "mindlin": {"time_per_impact": 3.1e-5, "ratio_to_paper": 15.5}}
    >>> for line in sub_model_lines(costs):
    ...     print(line)
    sub-model cost, paper (rigid, net): 2 us per impact (1.0 x the paper's model)
    sub-model cost, mindlin: 31 us per impact (15.5 x the paper's model)
    """
    return [f"sub-model cost, {name}: {1e6 * c['time_per_impact']:.3g} us per impact ({c['ratio_to_paper']:.1f} x the "
            "paper's model)" for name, c in costs.items()]


def _timing_modes(cfg: BenchmarkConfig, batch_size: int, threads: int) -> list[str]:
    modes = {
        "engine": f"single call: simulate_impact, median over repeats ({cfg.repeats_single}) and speeds",
        "engine_batch": f"batch of {batch_size} distinct speeds: engine.solve_normal_many, "
                        f"{threads} threads, median of {cfg.repeats_batch}",
        "engine_family": f"family built over the test speeds and evaluated at {cfg.family_size} distinct speeds "
                         f"(build included), {threads} threads, median of {cfg.repeats_batch}",
        "rkg": f"batch of {batch_size} distinct speeds: numba prange, {threads} threads, median of {cfg.repeats_batch}",
        **{m: f"single call: simulate_reference(method={m!r}, atol=rtol), median over repeats "
              f"({cfg.repeats_scipy}) and speeds" for m in SCIPY_METHODS},
    }
    return [modes[m] for m in ALL_METHODS]


def _reference_attrs(cfg: BenchmarkConfig, reference: Reference) -> dict:
    bound = reference.bound
    return {
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
        "reference_per_case": json.dumps(reference.per_case),
        "reference_seconds": bound["seconds"],
    }


def _dataset(table: _Table, cfg: BenchmarkConfig, speeds, batch_size: int, attrs: dict) -> xr.Dataset:
    """The results as a Dataset (dims method, setting); ``attrs`` become its attributes (booleans as 0/1)."""
    dims = ("method", "setting")
    data = {k: (dims, table.values[k], attributes(k)) for k in _TABLE_VARIABLES}
    data["status"] = (dims, table.status.astype(str), {"long_name": "ok, or why a setting has no result"})
    data["timing_mode"] = (("method",), np.array(_timing_modes(cfg, batch_size, attrs["numba_threads"])),
                           attributes("timing_mode"))
    data["e_n_reference"] = (("normal_speed",), table.reference.e_n, attributes("e_n_reference"))
    ds = xr.Dataset(data, coords={
        "method": ("method", np.array(ALL_METHODS), attributes("method")),
        "setting": ("setting", np.arange(table.n_settings), {
            "long_name": "solver setting level k",
            "description": "adaptive methods: rtol = 10^-(4+k); rkg: N = 25 * 2^k steps per contact",
        }),
        "normal_speed": ("normal_speed", speeds, attributes("normal_speed", long_name="normal-speed test set")),
    })
    # NetCDF attributes cannot be booleans: store 0/1
    ds.attrs.update({k: int(v) if isinstance(v, (bool, np.bool_)) else v for k, v in attrs.items()})
    return ds


# =============================================================================== the benchmark
from microimpact.studies.benchmark.family import family_targets, fit_scaling, run_engine_family  # noqa: E402
from microimpact.studies.benchmark.sub_models import sub_model_costs  # noqa: E402

#: stages of the progress bar of run_benchmark (speed set, reference, engine, engine batch, engine
#: family, RKG, scipy, engine diagnostics and sub-model costs; the throughput runs add one)
_STAGES = 8


def run_benchmark(quick: bool = False, *, contact=WALL_1990, config: BenchmarkConfig | None = None,
                  verbose: bool = False, throughput: bool = True, progress=None,
                  time_budget: float | None = None) -> xr.Dataset:
    """Run the work-precision benchmark and return its results.

    Parameters
    ----------
    quick : bool
        Smaller test set, fewer settings and repeats (for CI and the workflow).
    contact : Contact
        Contact parameters (default WALL_1990, Table 1 row 2).
    config : BenchmarkConfig, optional
        Overrides ``quick``.
    verbose : bool
        Progress on stderr.
    throughput : bool
        Also measure the 100,000-impact throughput and the memory scaling.
    progress : bool, optional
        A progress bar of the stages on stderr (:func:`microimpact._runtime.progress.progress_bar`),
        drawn only when stderr is a terminal. Default: none.
    time_budget : float, optional
        Stop with :class:`microimpact.solvers.TimeBudgetExceeded` once the run has taken this long
        [s] (checked by a timer, so within a compiled call's duration, well under a second here;
        main thread only). Default: no limit.

    Returns
    -------
    xarray.Dataset
        Dims ``method`` and ``setting``; variables ``time_per_impact`` [s], ``max_error_e_n``,
        ``max_rel_error_e_n``, ``max_error_mu``, ``max_error_K_L`` [1], ``n_impacts``, ``rtol``,
        ``steps_per_contact``, ``mean_steps`` (engine and RKG), ``status``; attributes with the
        machine, versions, the reference error bound, targets and ratios.

    Examples
    --------
    The full run takes minutes and the quick one about a minute (``python -m
    microimpact.studies.benchmark --quick``); a time budget that is not a positive number is refused
    before anything runs:

    >>> run_benchmark(quick=True, time_budget=0)
    Traceback (most recent call last):
    ...
    ValueError: time_budget must be a number of seconds > 0 (or None: no limit), got 0
    """
    cfg = config or (BenchmarkConfig.quick_() if quick else BenchmarkConfig.full())
    time_budget = check_time_budget(time_budget)
    attrs = machine_attrs()
    t_start = time.perf_counter()
    notes: list[str] = []
    with time_limit(time_budget, "benchmark"), progress_bar(_STAGES + int(throughput), "benchmark", progress) as advance:
        _warm_up(contact)
        speeds, v_cap = normal_speed_set(contact, cfg.n_speeds, cfg.max_speed, cfg.capture_margin)
        cases = cfg.oblique
        log(f"capture speed {v_cap:.10g} m/s; {len(speeds)} normal speeds, {len(cases)} oblique cases", verbose)
        advance()
        reference = reference_set(contact, speeds, cases, cfg, verbose)
        b = reference.bound
        log(f"reference bound: e_n {b['e_n']:.3g}, mu {b['mu']:.3g}, K_L {b['K_L']:.3g}", verbose)
        advance()

        table = _Table(reference, cfg.n_settings)
        batch_speeds = np.geomspace(speeds[0], speeds[-1], cfg.batch_size)
        for stage in (lambda: _run_engine(contact, speeds, cases, cfg, table, verbose),
                      lambda: _run_engine_batch(contact, speeds, batch_speeds, cases, cfg, table, verbose),
                      lambda: run_engine_family(contact, speeds, cases, cfg, table, verbose),
                      lambda: _run_rkg(contact, speeds, batch_speeds, cfg, table, verbose),
                      lambda: _run_scipy(contact, speeds, cases, cfg, table, notes, verbose)):
            stage()
            advance()
        diag, sub_grid, sub_costs = _diagnostics_and_sub_models(contact, speeds, batch_speeds, cfg, verbose)
        advance()

        targets = accuracy_targets(table.values["time_per_impact"], table.values["max_error_e_n"], cfg, b["e_n"])
        if throughput:
            targets.update(_throughput_stage(contact, cfg, table, verbose))
            advance()
    attrs.update(_run_attrs(contact, cfg, v_cap, speeds, cases, reference, notes, diag, sub_costs, sub_grid,
                            t_start, targets))
    return _dataset(table, cfg, speeds, batch_speeds.size, attrs)


def _diagnostics_and_sub_models(contact, speeds, batch_speeds, cfg: BenchmarkConfig, verbose: bool) -> tuple:
    """(diag, sub_grid, sub_costs) of :func:`run_benchmark`: the engine's diagnostics at the batch
    speeds, and the grid of speeds [m/s] and angles [deg] of the sub-models' costs with those costs,
    each logged."""
    diag = _engine_diagnostics(contact, batch_speeds, cfg)
    for line in diagnostics_lines(diag):
        log(line, verbose)
    sub_grid = (np.geomspace(speeds[0], speeds[-1], 4 if cfg.quick else 32),
                np.linspace(0.0, 85.0, 5 if cfg.quick else 18))
    sub_costs = sub_model_costs(contact, *sub_grid, repeats=1 if cfg.quick else 3)
    for line in sub_model_lines(sub_costs):
        log(line, verbose)
    return diag, sub_grid, sub_costs


def _throughput_stage(contact, cfg: BenchmarkConfig, table: _Table, verbose: bool) -> dict:
    """The throughput targets of :func:`run_benchmark`: the 100,000-impact throughput and memory
    scaling, the family's, and the fit's scaling."""
    targets = dict(throughput_targets(contact, cfg, verbose))
    targets.update(family_targets(contact, cfg, table.values["time_per_impact"],
                                  table.values["max_error_e_n"], verbose))
    # the small fit of the side-by-side pair is 100 rows, or fit_rows when that is fewer
    targets.update(fit_scaling((min(100, cfg.fit_rows), cfg.fit_rows), verbose=verbose))
    return targets


def _run_attrs(contact, cfg: BenchmarkConfig, v_cap, speeds, cases, reference: Reference, notes, diag, sub_costs,
               sub_grid, t_start, targets) -> dict:
    """The attributes of :func:`run_benchmark`'s dataset beyond the machine's: the run, its reference,
    diagnostics and sub-model costs, its duration, the targets and the contact."""
    return {
        "title": "work-precision benchmark of the microimpact solvers",
        "contact": cfg.contact_name,
        "quick": int(cfg.quick),
        "capture_speed": v_cap,
        "capture_speed_units": "m s-1",
        "n_normal_speeds": len(speeds),
        "n_oblique_cases": len(cases),
        "oblique_cases": json.dumps([c.__dict__ for c in cases]),
        **_reference_attrs(cfg, reference),
        "notes": json.dumps(notes),
        "engine_diagnostics": json.dumps(diag),
        "sub_model_costs": json.dumps(sub_costs),
        "sub_model_grid": json.dumps({"speeds": sub_grid[0].tolist(), "incidence_deg": sub_grid[1].tolist()}),
        "total_seconds": time.perf_counter() - t_start,
        "machine_load_average_1min_at_end": load_average(),
        **targets,
        **contact_attributes(contact),
        "parameter_source": preset_parameter_source(cfg.contact_name.lower().replace("_", "")),
    }
