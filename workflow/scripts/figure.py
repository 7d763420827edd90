"""Rules figure, fit_figure and sweep_figure: a figure of one result file -> reports/figures/<result>[.variant].png.

The figure is the one ``microimpact plot`` draws (microimpact.report.standard); its caption goes to
the log. The files are ``report()`` outputs of the HTML report (snakemake --report report.html).
"""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.io.files import atomic_path  # noqa: E402
from microimpact.report.standard import standard_figure  # noqa: E402

curves = snakemake.input.get("curves")  # noqa: F821  (the fit's model curves; fit_figure only)
variant = snakemake.params.get("variant")  # noqa: F821  (a sweep's other figures; sweep_figure only)
plot = standard_figure(snakemake.input.result, curves=curves, variant=variant)  # noqa: F821
with atomic_path(snakemake.output[0]) as tmp:  # noqa: F821
    plot.figure.savefig(tmp, format="png", dpi=150)
print(plot.caption)
