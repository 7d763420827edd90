"""Rule report: lay out the result files on A4 pages -> reports/report.pdf (no simulation is run)."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.report.pdf import build_report  # noqa: E402

inputs = dict(snakemake.input.items())  # noqa: F821  (named inputs; lists such as the sweeps stay lists)
build_report(snakemake.output[0], inputs, config=snakemake.params.config, workers=snakemake.threads)  # noqa: F821
