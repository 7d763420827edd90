"""Rule reproduction: the paper's numbers and statements checked by computation (CSV + Markdown)."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.io import write_csv  # noqa: E402
from microimpact.presets import named_contact  # noqa: E402
from microimpact.studies.reproduction import reproduction_table, write_reproduction_markdown  # noqa: E402

contact, source = named_contact(snakemake.params.contact)  # noqa: F821
table = reproduction_table(contact)
table.attrs["parameter_source"] = source
write_csv(table, snakemake.output.table)  # noqa: F821
write_reproduction_markdown(table, snakemake.output.markdown)  # noqa: F821
print(table.to_string())
