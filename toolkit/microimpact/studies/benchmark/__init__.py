"""Work-precision benchmark of the impact solvers on the WALL_1990 contact (Table 1, row 2).

Run ``python -m microimpact.studies.benchmark [--out DIR] [--quick] [--docs DIR]``.

What is measured (all in one run, on one machine, side by side)
----------------------------------------------------------------
* **Test set.** Normal impacts at ``n_speeds`` incident speeds log-spaced from just above the
  capture speed v_cap (:func:`microimpact.dynamics.capture_velocity`) to 100 m/s, and a fixed table of
  oblique impacts (incidence 10-80 deg, spins up to 10 times the rolling spin v_t / r, friction
  0.15 and 0.5; some captured, some rebounding).
* **Reference values** come from a much tighter solve whose own error is *bounded*, not assumed:
  scipy's DOP853 on the full 3-D equations (:func:`microimpact.solvers.reference.simulate_reference`) at
  rtol = 1e-13 is the reference; the bound is the largest of |DOP853(1e-13) - engine(1e-13)| (two
  independent integrators and codes) and |DOP853(1e-12) - DOP853(1e-13)| (self-convergence), over
  the test set. Errors below the bound are not resolved.
* **Methods**, each at several settings (dimension ``setting``; for adaptive methods setting k is
  rtol = 10^-(4+k), for the fixed-step Runge-Kutta-Gill method N = 25 * 2^k steps per contact):

  ``engine``
      :func:`microimpact.simulate_impact` one call per impact (Python overhead incl.)
  ``engine_batch``
      :func:`microimpact.solvers.engine.solve_normal_many` on a batch of distinct speeds (both
      cores); oblique errors through :func:`microimpact.simulate_many`
  ``engine_family``
      :func:`microimpact.solvers.family.normal_family` built over the test set's speeds and
      evaluated on many distinct speeds (build included in the time per impact); oblique errors
      through :func:`microimpact.simulate_many` on the family path
  ``rkg``
      fixed-step Runge-Kutta-Gill (Gill 1951) on the plain Eq. (27) in tau, the paper's method,
      numba-compiled, batch over both cores (``prange``)
  ``RK45``, ``DOP853``, ``LSODA``, ``Radau``
      :func:`microimpact.solvers.reference.simulate_reference` with that solve_ivp method (one
      call per impact; atol = rtol on the O(1) nondimensional state)

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

Modules
-------
:mod:`.cases` the test set, the settings and the targets; :mod:`.harness` timed and time-limited
solves, throughput, memory and the machine; :mod:`.reference` the reference values and their
error bound; :mod:`.targets` the targets evaluated; :mod:`.run` :func:`run_benchmark`;
:mod:`.markdown` the JSON record and the Markdown summary; :mod:`.output` :func:`write_benchmark`
(the figure is :func:`microimpact.report.figures.plot_work_precision`); :mod:`.cli` (run by ``__main__``) the
command line. The Runge-Kutta-Gill integrator lives in :mod:`microimpact.solvers.rkg`.
"""

from microimpact.solvers.rkg import rkg_restitution, rkg_state
from microimpact.studies.benchmark import cases as _cases
from microimpact.studies.benchmark.cases import *  # noqa: F401,F403 - the test set, settings and targets
from microimpact.studies.benchmark.harness import measure_memory, measure_throughput
from microimpact.studies.benchmark.markdown import benchmark_json, benchmark_markdown
from microimpact.studies.benchmark.output import write_benchmark
from microimpact.studies.benchmark.run import run_benchmark

__all__ = [
    *_cases.__all__,
    "measure_memory",
    "measure_throughput",
    "rkg_restitution",
    "rkg_state",
    "run_benchmark",
    "write_benchmark",
    "benchmark_json",
    "benchmark_markdown",
]
