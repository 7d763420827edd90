"""Rule paper_dynamics: the nonlinear analysis of the paper's contact -> results/paper/: the Fig. 5
phase portraits (phase_portraits.nc), v_c, the capture velocity, C and omega_f at those speeds
(dynamics.nc), and the (C1, C2) plane of Fig. 4 with the Table 1 cases (bifurcation.nc)."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.dynamics.nonlinear import (  # noqa: E402
    bifurcation_plane,
    dynamics_summary,
    phase_portraits,
    save_phase_portraits,
    table1_cases,
)
from microimpact.io import write_netcdf  # noqa: E402
from microimpact.io.provenance import stamp_parameters  # noqa: E402
from microimpact.presets import named_contact  # noqa: E402

params, output = snakemake.params, snakemake.output  # noqa: F821
contact, source = named_contact(params.contact)
portraits = [stamp_parameters(ds, contact, source) for ds in phase_portraits(contact, params.speeds)]
save_phase_portraits(portraits, output.phase_portraits)
write_netcdf(stamp_parameters(dynamics_summary(contact, params.speeds), contact, source), output.dynamics)
cases = [(f"simulation, v={v:g} m/s", contact, v) for v in params.speeds] + table1_cases()
write_netcdf(stamp_parameters(bifurcation_plane(cases), contact, source), output.bifurcation)
for ds in portraits:
    print(ds.attrs["normal_speed"], "m/s:", ds.attrs["motion_type"])
