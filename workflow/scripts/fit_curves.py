"""Rule fit_curves: model e_n(v_n) at the fit for every measured size -> results/analyst/fit_curves.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import xarray as xr  # noqa: E402

from microimpact.io import write_netcdf  # noqa: E402
from microimpact.studies.material import stamp_fitted  # noqa: E402
from microimpact.studies.sweeps import restitution_curves  # noqa: E402

fit = xr.load_dataset(snakemake.input.fit)  # noqa: F821
curves = restitution_curves(fit, rtol=snakemake.params.rtol)  # noqa: F821
curves = stamp_fitted(curves, fit)
write_netcdf(curves, snakemake.output[0])  # noqa: F821
print(curves)
