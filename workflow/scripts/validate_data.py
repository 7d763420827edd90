"""Rule validate_data: read and check the impact CSV, write the validated table (SI units).

stderr is left on the terminal: a bad file stops the pipeline here with one ImpactDataError that
lists every problem (file, row, line, column, value, what is accepted) where the analyst sees it.
"""

from microimpact._runtime.joblog import log_job

log_job(snakemake, keep_stderr=True)  # noqa: F821  (the ImpactDataError is for the terminal)

from microimpact.io import read_impacts, write_csv  # noqa: E402

table = read_impacts(snakemake.input.data, materials=snakemake.input.materials,  # noqa: F821
                     material_pair=snakemake.params.material_pair)  # noqa: F821
write_csv(table, snakemake.output.table)  # noqa: F821
print(f"{len(table)} impacts from {snakemake.input.data} (sha256 {table.attrs.get('sha256', '?')})")  # noqa: F821
