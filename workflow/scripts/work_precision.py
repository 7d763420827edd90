"""Rule work_precision: accuracy against cost of the engine, scipy's solvers and Runge-Kutta-Gill
-> results/benchmark/ (benchmark.nc, .json, .md, work_precision.pdf/.png)."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.report.figures import plot_work_precision  # noqa: E402
from microimpact.studies.benchmark import run_benchmark, write_benchmark  # noqa: E402

params = snakemake.params  # noqa: F821
ds = run_benchmark(quick=params.quick, throughput=params.throughput, verbose=True)
write_benchmark(ds, params.out_dir, figure=plot_work_precision(ds).figure)
print(ds)
