"""Rule dynamics_summary: v_c, capture velocity, C and omega_f of the paper's contact -> results/paper/dynamics.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.dynamics.nonlinear import dynamics_summary  # noqa: E402
from microimpact.io import write_netcdf  # noqa: E402
from microimpact.io.provenance import stamp_parameters  # noqa: E402
from microimpact.presets import named_contact  # noqa: E402

contact, source = named_contact(snakemake.params.contact)  # noqa: F821
ds = stamp_parameters(dynamics_summary(contact, snakemake.params.speeds), contact, source)  # noqa: F821
write_netcdf(ds, snakemake.output[0])  # noqa: F821
print(ds)
