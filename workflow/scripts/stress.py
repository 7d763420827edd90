"""Rule stress: seeded random stress sweep of the engine -> results/stress_summary.json (summary)
+ results/stress.nc (one row per case: inputs, measures, failures)."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.io.files import write_netcdf  # noqa: E402
from microimpact.studies.stress import stress_sweep, summary_line, write_stress_summary  # noqa: E402

params = snakemake.params  # noqa: F821


def progress(i, n):
    if i % 1000 == 0 or i == n:
        print(f"{i}/{n} cases")


report = stress_sweep(params.cases, params.seed, reference_every=params.reference_every,
                      case_time_limit=params.case_time_limit, progress=progress)
write_stress_summary(report.summary, snakemake.output.summary)  # noqa: F821
ds = report.dataset
# every case draws its own contact (inputs are variables of the file, one row per case)
ds.attrs["parameter_source"] = f"stress: seeded random draw, seed {params.seed}, {params.cases} cases"
write_netcdf(ds, snakemake.output.netcdf)  # noqa: F821
print(summary_line(report.summary))
