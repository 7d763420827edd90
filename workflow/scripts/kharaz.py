"""Rule kharaz: the model against the Kharaz et al. (2001) oblique impacts -> results/kharaz.nc."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.io import write_netcdf  # noqa: E402
from microimpact.analysis.kharaz import kharaz_comparison  # noqa: E402

ds = kharaz_comparison(snakemake.input[0], contact_models=dict(snakemake.params.contact_models))  # noqa: F821
write_netcdf(ds, snakemake.output[0])  # noqa: F821
print(ds)
