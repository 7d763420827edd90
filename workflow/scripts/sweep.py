"""Rule paper_sweeps: every configured Table 2 case with the paper's contact
-> results/paper/sweeps/case_<case>.nc."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.io.provenance import stamp_parameters  # noqa: E402
from microimpact.presets import named_contact  # noqa: E402
from microimpact.studies.sweeps import case_spec, run_sweep, save_sweep  # noqa: E402

params = snakemake.params  # noqa: F821
contact, source = named_contact(params.contact)
for case, path in zip(params.cases, snakemake.output):  # noqa: F821
    ds = run_sweep(contact, case_spec(case, params.overrides[case]), case=case, rtol=params.rtol)
    save_sweep(stamp_parameters(ds, contact, source), path)
    print(f"case {case}: {dict(ds.sizes)}")
