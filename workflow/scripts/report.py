"""Rule report: lay out the result files on A4 pages -> reports/report.pdf (no simulation is run)."""

from microimpact.io.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.report.pdf import build_report  # noqa: E402

inputs = dict(snakemake.input.items())  # noqa: F821  (named inputs; lists such as the sweeps stay lists)
build_report(snakemake.output[0], inputs, config=snakemake.params.config, workers=snakemake.threads)  # noqa: F821
