"""Rule sweep_chunk: chunk <chunk> of <nchunks> (split along speed) of one Table 2 case."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact import Contact  # noqa: E402
from microimpact.studies.sweeps import run_sweep, save_sweep, split_spec  # noqa: E402

wc = snakemake.wildcards  # noqa: F821
spec = split_spec(snakemake.params.spec, int(wc.nchunks))[int(wc.chunk)]  # noqa: F821
ds = run_sweep(Contact(**snakemake.params.contact), spec, case=wc.case)  # noqa: F821
save_sweep(ds, snakemake.output[0])  # noqa: F821
print(ds)
