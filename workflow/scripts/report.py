"""Rule report: lay out every result on A4 pages -> reports/report.pdf."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.report.pdf import build_report  # noqa: E402

inputs = dict(snakemake.input.items())  # noqa: F821
build_report(snakemake.output[0], **inputs, config=snakemake.params.config)  # noqa: F821
