"""Rule design: what to measure next, from the damping fit -> results/analyst/<pair>/design.json
(the report page) + design.csv (the measured-impact template, e_n empty)."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

import json  # noqa: E402

from microimpact.analysis.design import (design_next_impacts, design_record, design_template,  # noqa: E402
                                         fit_design_space)
from microimpact.analysis.fit_result import DampingFit  # noqa: E402
from microimpact.io.files import atomic_write, write_csv  # noqa: E402

fit = DampingFit.load(snakemake.input.fit)  # noqa: F821
space = fit_design_space(fit)
# only what the config gives: the rest is the library's default (microimpact.analysis.design_defaults)
given = {k: (tuple(v) if k == "parameters" else v) for k, v in snakemake.params.options.items() if v is not None}  # noqa: F821
design = design_next_impacts(fit, space, rtol=snakemake.params.rtol, **given)  # noqa: F821
write_csv(design_template(design, space), snakemake.output.csv, float_format="%.6g")  # noqa: F821
with atomic_write(snakemake.output.json) as f:  # noqa: F821
    json.dump(design_record(design, space, source=str(snakemake.input.fit)), f, indent=1)  # noqa: F821
print(design.summary())
