"""Rule material_sweep: one Table 2 case for the fitted material, every measured size, the measured
speed range -> results/analyst/sweeps/case_<case>.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import xarray as xr  # noqa: E402

from microimpact.studies.material import material_sweep  # noqa: E402
from microimpact.studies.sweeps import case_spec, save_sweep  # noqa: E402

case = snakemake.wildcards.case  # noqa: F821
spec = case_spec(case, snakemake.params.overrides)  # noqa: F821
ds = material_sweep(xr.load_dataset(snakemake.input.fit), spec, case=case, rtol=snakemake.params.rtol)  # noqa: F821
save_sweep(ds, snakemake.output[0])  # noqa: F821
print(ds)
