"""Rule material_dynamics: critical and capture velocity of the fitted material per measured size
-> results/analyst/dynamics.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import xarray as xr  # noqa: E402

from microimpact.io import write_netcdf  # noqa: E402
from microimpact.studies.material import material_dynamics  # noqa: E402

ds = material_dynamics(xr.load_dataset(snakemake.input.fit), rtol=snakemake.params.rtol)  # noqa: F821
write_netcdf(ds, snakemake.output[0])  # noqa: F821
print(ds)
