"""Rule bifurcation: the (C1, C2) plane of Fig. 4 with the Table 1 cases and the paper's contact at
the phase-portrait speeds -> results/paper/bifurcation.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.dynamics.nonlinear import bifurcation_plane, table1_cases  # noqa: E402
from microimpact.io import write_netcdf  # noqa: E402
from microimpact.io.provenance import stamp_parameters  # noqa: E402
from microimpact.presets import named_contact  # noqa: E402

contact, source = named_contact(snakemake.params.contact)  # noqa: F821
cases = [(f"simulation, v={v:g} m/s", contact, v) for v in snakemake.params.speeds] + table1_cases()  # noqa: F821
ds = stamp_parameters(bifurcation_plane(cases), contact, source)
write_netcdf(ds, snakemake.output[0])  # noqa: F821
print(ds)
