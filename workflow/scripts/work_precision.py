"""Rule work_precision: accuracy against cost of the engine and the scipy reference solver."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.benchmark import run_benchmark  # noqa: E402
from microimpact.io import write_netcdf  # noqa: E402

ds = run_benchmark(quick=snakemake.params.quick)  # noqa: F821
write_netcdf(ds, snakemake.output[0])  # noqa: F821
print(ds)
