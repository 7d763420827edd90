"""Rule gather_sweep: combine the chunks of one case into results/sweeps/case_<case>.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.studies.sweeps import combine_sweeps, load_sweep, save_sweep  # noqa: E402

ds = combine_sweeps([load_sweep(path) for path in snakemake.input])  # noqa: F821
save_sweep(ds, snakemake.output[0])  # noqa: F821
print(ds)
