"""Rule dynamics_summary: v_c, capture velocity, C and omega_f of the simulation contact -> results/dynamics.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact import Contact  # noqa: E402
from microimpact.dynamics.nonlinear import dynamics_summary  # noqa: E402
from microimpact.io import write_netcdf  # noqa: E402

ds = dynamics_summary(Contact(**snakemake.params.contact), snakemake.params.speeds)  # noqa: F821
write_netcdf(ds, snakemake.output[0])  # noqa: F821
print(ds)
