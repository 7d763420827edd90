"""Rule paper_sweep_chunk: chunk <chunk> of <nchunks> (split along speed) of one Table 2 case."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.io.provenance import stamp_parameters  # noqa: E402
from microimpact.presets import named_contact  # noqa: E402
from microimpact.studies.sweeps import case_spec, run_sweep, save_sweep, split_spec  # noqa: E402

params = snakemake.params  # noqa: F821
wc = snakemake.wildcards  # noqa: F821
contact, source = named_contact(params.contact)
spec = split_spec(case_spec(wc.case, params.overrides), int(wc.nchunks))[int(wc.chunk)]
ds = run_sweep(contact, spec, case=wc.case, rtol=params.rtol)
save_sweep(stamp_parameters(ds, contact, source), snakemake.output[0])  # noqa: F821
print(ds)
