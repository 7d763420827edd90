"""Rule report: lay out the result files on A4 pages -> reports/report.pdf (no simulation is run)."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.report.pdf import build_report  # noqa: E402

named = dict(snakemake.input.items())  # noqa: F821  (named inputs; lists such as the sweeps stay lists)
pairs = {p: {k.rsplit("__", 1)[0]: v for k, v in named.items() if k.endswith(f"__{i}")}
         for i, p in enumerate(snakemake.params.pairs)}  # noqa: F821
inputs = {k: v for k, v in named.items() if "__" not in k}
build_report(snakemake.output[0], inputs, pairs=pairs, config=snakemake.params.config,  # noqa: F821
             workers=snakemake.threads)  # noqa: F821
