"""Rule sweep: one Table 2 case on its grid -> results/sweeps/case_<case>.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact import Contact  # noqa: E402
from microimpact.studies.sweeps import run_sweep, save_sweep  # noqa: E402

ds = run_sweep(Contact(**snakemake.params.contact), snakemake.params.spec, case=snakemake.wildcards.case)  # noqa: F821
save_sweep(ds, snakemake.output[0])  # noqa: F821
print(ds)
