"""Rule figures: the standard figures of one part's result files -> reports/figures/<part>/<name>.png.

The figures are those ``microimpact plot`` draws (microimpact.report.standard), listed by
part_figures() in common.smk; their captions go to the log. The files are ``report()`` outputs of
the HTML report (snakemake --report report.html).
"""

import os

from microimpact._runtime.joblog import log_job  # noqa: E402

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.report.standard import FigureFile, save_standard_figures  # noqa: E402

out_dir = snakemake.output[0]  # noqa: F821
curves = snakemake.input.get("curves")  # noqa: F821  (the fit's model curves; the analyst's part only)
files = [
    FigureFile(f["result"], os.path.join(out_dir, f["name"] + ".png"),
               curves if f["name"] == "fit" else None, f["variant"])
    for f in snakemake.params.figures  # noqa: F821
]
for file, caption in zip(files, save_standard_figures(files, workers=snakemake.threads)):  # noqa: F821
    print(f"{file.out}: {caption}")
