"""Rule gather_sweep: combine the chunks of one case into results/sweeps/case_<case>.nc."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.studies.sweeps import combine_sweeps, load_sweep, save_sweep  # noqa: E402

ds = combine_sweeps([load_sweep(path) for path in snakemake.input])  # noqa: F821
save_sweep(ds, snakemake.output[0])  # noqa: F821
print(ds)
