"""Rule work_precision: accuracy against cost of the engine, scipy's solvers and Runge-Kutta-Gill
-> results/benchmark/ (benchmark.nc, .json, .md, work_precision.pdf/.png)."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.report.figures import plot_work_precision  # noqa: E402
from microimpact.studies.benchmark import run_benchmark, write_benchmark  # noqa: E402

params = snakemake.params  # noqa: F821
ds = run_benchmark(quick=params.quick, throughput=params.throughput, verbose=True)
write_benchmark(ds, params.out_dir, figure=plot_work_precision(ds).figure)
print(ds)
