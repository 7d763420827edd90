"""Rule material_simulations: what the fit drives -> results/analyst/<pair>/: the model e_n(v_n) curves
(fit_curves.nc), the critical and capture velocity per measured size (dynamics.nc) and every
configured Table 2 case for the fitted material (sweeps/case_<case>.nc)."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.io.files import restore_label_coordinates  # noqa: E402

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

import xarray as xr  # noqa: E402

from microimpact.io import write_netcdf  # noqa: E402
from microimpact.studies.material import material_dynamics, material_sweep, stamp_fitted  # noqa: E402
from microimpact.studies.sweeps import case_spec, restitution_curves, save_sweep  # noqa: E402

params, output = snakemake.params, snakemake.output  # noqa: F821
fit = restore_label_coordinates(xr.load_dataset(snakemake.input.fit))  # noqa: F821
write_netcdf(stamp_fitted(restitution_curves(fit, rtol=params.rtol), fit), output.fit_curves)
write_netcdf(material_dynamics(fit, rtol=params.rtol), output.dynamics)
for case, path in zip(params.cases, output.sweeps):
    ds = material_sweep(fit, case_spec(case, params.overrides[case]), case=case, rtol=params.rtol)
    save_sweep(ds, path)
    print(f"case {case}: {dict(ds.sizes)}")
