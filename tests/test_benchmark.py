"""Tests of the work-precision benchmark (microimpact.studies.benchmark).

No timing assertions: the machines are shared and noisy. What is tested: the Runge-Kutta-Gill
implementation (its order, on problems where the order is known), the structure of the benchmark
Dataset and its files, and that the engine's error falls as its tolerance is tightened.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from microimpact.studies import benchmark
from microimpact.solvers import engine
from microimpact.studies.benchmark import BenchmarkConfig, ObliqueCase, rkg_restitution, rkg_state
from microimpact.model.contact import Contact
from microimpact.presets import WALL_1990

# Hertz contact (no adhesion, no damping) with the size and material of Table 1 row 2. With f0 = 0
# the adhesion scales X, T degenerate; the engine (and the RKG code) then use the Hertz impact
# scales, in which y(0) = 1, a_h = 5/4, a_a = 0 and the exact restitution coefficient is 1.
HERTZ = Contact(radius=3.45e-6, density=1350.0, stiffness=1.776e9, adhesion_line_force=0.0)


def observed_orders(errors):
    errors = np.asarray(errors, dtype=float)
    return np.log2(errors[:-1] / errors[1:])


def test_hertz_scales_are_the_engines():
    sc = engine.nondimensional_scales(HERTZ, 2.0)
    assert (sc.a_hertz, sc.a_adhesion) == (1.25, 0.0)
    assert sc.length / sc.time == pytest.approx(2.0, rel=1e-15)  # y(0) = 1


def test_rkg_is_fourth_order_on_smooth_hertz_motion():
    """RKG (Gill 1951) converges at 4th order where the Hertz motion is smooth.

    Start at the largest compression of the elastic Hertz impact (xi = 1, y = 0) and integrate to
    tau = 0.8 (xi stays above 0.6, so xi^(3/2) is smooth). Reference: DOP853 at rtol 1e-13, whose
    error (~1e-13) is below the smallest RKG error compared here (~1e-9 at N = 40).
    """
    tau = 0.8
    ref = solve_ivp(lambda t, z: [z[1], -1.25 * z[0] ** 1.5], (0.0, tau), [1.0, 0.0], method="DOP853",
                    rtol=1e-13, atol=1e-15).y[:, -1]
    errors = []
    for n in (5, 10, 20, 40):
        xi, y = rkg_state(0.0, 0.0, 0.0, 1.25, 0.0, tau / n, n, xi0=1.0)
        errors.append(math.hypot(xi - ref[0], y - ref[1]))
    orders = observed_orders(errors)
    # halving the step divides the error by 2^4 = 16; observed 4.01, 4.01, 4.00
    assert orders == pytest.approx([4.0, 4.0, 4.0], abs=0.1)


def test_rkg_order_drops_from_first_contact_on_hertz():
    """From first contact the solution has a tau^(5/2) term: order 2.5 (measured, documented).

    Exact state at tau = 1 from energy conservation, y = sqrt(1 - xi^(5/2)), and
    tau(xi) = int_0^xi du / sqrt(1 - u^(5/2)) (computed with quad, error ~1e-13, far below the compared errors of 8e-9 to 2e-6).
    """
    from scipy.integrate import quad
    from scipy.optimize import brentq

    def tau_of(x):  # the integrand is smooth on [0, x] for x < 1
        return quad(lambda u: 1.0 / math.sqrt(1.0 - u**2.5), 0.0, x, epsabs=1e-14, epsrel=1e-13, limit=200)[0]

    xe = brentq(lambda x: tau_of(x) - 1.0, 0.5, 0.99, xtol=1e-15)
    ye = math.sqrt(1.0 - xe**2.5)
    errors = []
    for n in (20, 40, 80, 160):
        xi, y = rkg_state(1.0, 0.0, 0.0, 1.25, 0.0, 1.0 / n, n)
        errors.append(math.hypot(xi - xe, y - ye))
    orders = observed_orders(errors)
    assert orders == pytest.approx([2.5, 2.5, 2.5], abs=0.1)  # observed 2.49, 2.49, 2.50


def test_rkg_restitution_converges_on_hertz_elastic_impact():
    """e_n of the undamped Hertz impact is exactly 1; the RKG e_n error falls at order >= 4 as the
    step is halved (the entry and exit errors largely cancel by time-reversal symmetry: observed
    ~5), until round-off (~1e-11)."""
    errors = []
    for n in (25, 50, 100):
        r = rkg_restitution(HERTZ, [1.0, 10.0], n)
        assert not r.captured.any()
        errors.append(float(np.max(np.abs(r.e_n - 1.0))))
    assert np.all(observed_orders(errors) >= 3.9)
    assert errors[-1] < 1e-8


def test_rkg_matches_engine_on_adhesive_impact():
    """With adhesion (x^(1/2) force) RKG converges, slowly; at N = 1600 it agrees with the engine
    to 1e-5 (measured error 1.1e-6 at 3 m/s)."""
    ref = engine.solve_normal(WALL_1990, 3.0, rtol=1e-12).e_n
    r = rkg_restitution(WALL_1990, [3.0], 1600)
    assert abs(r.e_n[0] - ref) < 1e-5
    assert r.n_steps[0] == pytest.approx(1600, rel=0.01, abs=0)  # a step count: the duration estimate is accurate


def test_test_set_starts_just_above_the_capture_speed():
    """The capture speed of the test set (dynamics.capture_velocity to 1e-12) brackets the outcome."""
    speeds, v_cap = benchmark.normal_speed_set(WALL_1990, n=4, max_speed=50.0, margin=1.02)
    assert 1.0 < v_cap < 2.0  # 1.4492 m/s for Table 1 row 2
    assert engine.solve_normal(WALL_1990, v_cap * (1 + 1e-9), rtol=1e-12).outcome == "rebound"
    assert engine.solve_normal(WALL_1990, v_cap * (1 - 1e-9), rtol=1e-12).outcome == "capture"
    assert speeds[0] == pytest.approx(1.02 * v_cap, rel=1e-15) and speeds[-1] == pytest.approx(50.0, rel=1e-15)


def test_engine_error_falls_as_rtol_tightens():
    """Max e_n error over a few speeds against DOP853 at rtol 1e-12 (bound ~1e-11): each tightening
    by 100x lowers the error by at least 10x until the reference floor."""
    from microimpact.solvers.reference import simulate_reference

    speeds = [1.5, 4.0, 30.0]
    ref = np.array([simulate_reference(WALL_1990, v, rtol=1e-12, atol=1e-14).e_n for v in speeds])
    errs = []
    for rtol in (1e-4, 1e-6, 1e-8, 1e-10):
        e = np.array([engine.solve_normal(WALL_1990, v, rtol=rtol).e_n for v in speeds])
        errs.append(float(np.max(np.abs(e - ref))))
    for a, b in zip(errs[:-1], errs[1:]):
        assert b < a / 10.0
    assert errs[-1] < 1e-8


@pytest.fixture(scope="module")
def small_benchmark():
    cfg = BenchmarkConfig(
        quick=True, n_speeds=3, max_speed=50.0, capture_margin=1.05,
        engine_levels=(0, 2, 4), scipy_levels=(0,), rkg_levels=(0, 1),
        oblique=(ObliqueCase(5.0, 30.0, 0.0, 0.0, 0.0, 1.0, 0.5), ObliqueCase(2.0, 45.0, 0.0, 0.0, 0.0, 0.0, 0.5)),
        repeats_single=1, repeats_scipy=1, repeats_batch=1, batch_size=100,
        throughput_impacts=500, throughput_repeats=1, memory_sizes=(200, 500), time_limit=5.0,
        reference_rtols=(1e-10, 1e-11), family_size=3000, family_impacts=1000, family_check=100, fit_rows=120,
    )
    return benchmark.run_benchmark(config=cfg)


@pytest.mark.extended
def test_benchmark_dataset_structure(small_benchmark):
    ds = small_benchmark
    assert ds["time_per_impact"].dims == ("method", "setting")
    assert list(ds["method"].values) == list(benchmark.ALL_METHODS)
    for name, unit in (("time_per_impact", "s"), ("max_error_e_n", "1"), ("max_error_mu", "1"),
                       ("max_rel_error_e_n", "1"), ("max_error_K_L", "1"), ("n_impacts", "1")):
        assert ds[name].attrs["units"] == unit
        assert ds[name].attrs["long_name"]
    for key in ("machine_platform", "machine_cpu_count", "machine_processor", "python_version", "numpy_version",
                "scipy_version", "numba_version", "date", "reference_bound_e_n", "reference_bound_mu",
                "target_ratio_met_single", "target_ratio_met_batch", "ratio_dop853_to_engine_batch",
                "target_throughput_met", "target_memory_met", "memory_peak_bytes", "engine_converges",
                "capture_speed"):
        assert key in ds.attrs, key
    # the reference bound is small and positive: two formulations agree
    assert 0.0 < ds.attrs["reference_bound_e_n"] < 1e-8
    # every run setting has a time and an e_n error; mu errors for all but RKG
    run = ds["status"] == "ok"
    assert bool((np.isfinite(ds["time_per_impact"]) & (ds["time_per_impact"] > 0)).where(run, True).all())
    assert bool(np.isfinite(ds["max_error_e_n"]).where(run, True).all())
    assert np.isnan(ds["max_error_mu"].sel({"method": "rkg"})).all()
    assert np.isfinite(ds["max_error_mu"].sel({"method": "engine"}).isel(setting=[0, 2, 4])).all()
    # the batch engine is the same solver as the single-call engine
    np.testing.assert_allclose(ds["max_error_e_n"].sel({"method": "engine_batch"}).isel(setting=[0, 2, 4]),
                               ds["max_error_e_n"].sel({"method": "engine"}).isel(setting=[0, 2, 4]), rtol=1e-6)
    # engine errors fall with tolerance
    e = ds["max_error_e_n"].sel({"method": "engine"}).isel(setting=[0, 2, 4]).values
    assert e[0] > e[1] > e[2]
    # the family line: its interpolation error (tolerance rtol, checked at rtol / 2) stays within
    # the direct engine's own error at the same rtol plus rtol, and falls with it
    fam = ds["max_error_e_n"].sel({"method": "engine_family"}).isel(setting=[0, 2, 4]).values
    rt = ds["rtol"].sel({"method": "engine_family"}).isel(setting=[0, 2, 4]).values
    assert np.all(fam <= e + rt) and fam[0] > fam[1] > fam[2]
    for key in ("family_seconds", "family_max_error_e_n", "family_ratio_per_impact", "family_target_met",
                "family_memory_target_met", "fit_time_ratio", "fit_target_met"):
        assert key in ds.attrs, key
    assert ds.attrs["family_max_error_e_n"] <= 1e-9  # the family target's error, at its rtol 1e-9
    assert ds.attrs["family_path"].startswith("family")


@pytest.mark.extended
def test_write_benchmark(small_benchmark, tmp_path):
    import xarray as xr

    from microimpact.report.figures import plot_work_precision

    figure = plot_work_precision(small_benchmark).figure
    paths = benchmark.write_benchmark(small_benchmark, tmp_path / "out", figure=figure, docs_dir=tmp_path / "docs")
    for key in ("netcdf", "json", "markdown", "pdf", "png", "docs_markdown", "docs_png"):
        assert paths[key].is_file() and paths[key].stat().st_size > 0
    back = xr.open_dataset(paths["netcdf"])
    assert back["time_per_impact"].attrs["units"] == "s"
    back.close()
    data = json.loads(paths["json"].read_text())
    assert data["attrs"]["reference_bound_e_n"] == pytest.approx(small_benchmark.attrs["reference_bound_e_n"])
    assert {r["method"] for r in data["results"]} == set(benchmark.ALL_METHODS)
    md = paths["markdown"].read_text()
    assert "| method |" in md and "reference" in md.lower()
    costs = json.loads(small_benchmark.attrs["sub_model_costs"])  # each timed selection has its row
    assert "## Cost of the sub-models" in md and all(f"| {name} |" in md for name in costs)
    assert not list((tmp_path / "out").glob(".*.tmp"))  # atomic writes leave no temporaries


@pytest.mark.extended
def test_markdown_says_the_cpus_were_shared_only_when_the_load_says_so(small_benchmark):
    ds = small_benchmark.copy()
    cpus = ds.attrs["machine_cpu_count"]
    for load, shared in ((0.4 * cpus, False), (1.5 * cpus, True)):
        ds.attrs.update(machine_load_average_1min_at_start=load, machine_load_average_1min_at_end=load)
        assert ("above 1 per CPU" in benchmark.benchmark_markdown(ds)) is shared


@pytest.mark.extended
def test_write_benchmark_without_a_figure_writes_the_data_files(small_benchmark, tmp_path):
    paths = benchmark.write_benchmark(small_benchmark, tmp_path / "out")
    assert set(paths) == {"netcdf", "json", "markdown"}
    assert not list((tmp_path / "out").glob("work_precision.*"))


def test_benchmark_command_line_help():
    from microimpact.cli import main

    assert main(["benchmark", "--help"]) == 0
