"""Rule flags: each measured impact's sensitivity to unmeasured spin and angle error, whether it
is near capture, and the spin consistent with it (over the posterior draws), under the fitted model
-> results/analyst/<pair>/flags.csv + results/analyst/<pair>/flags.nc."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.io.files import restore_label_coordinates  # noqa: E402

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

import xarray as xr  # noqa: E402

from microimpact.analysis.fit_result import DampingFit  # noqa: E402
from microimpact.analysis.flags import flag_measurements, write_flags  # noqa: E402
from microimpact.analysis.posterior import Posterior  # noqa: E402
from microimpact.io import read_impacts, select_material_pair  # noqa: E402
from microimpact.studies.material import stamp_fitted  # noqa: E402

fit_ds = restore_label_coordinates(xr.load_dataset(snakemake.input.fit))  # noqa: F821
pair = snakemake.wildcards.pair  # noqa: F821  (this job's material pair: its rows of the data)
table = select_material_pair(read_impacts(snakemake.input.data, materials=snakemake.input.materials,  # noqa: F821
                                          material_pair=snakemake.params.material_pair),  # noqa: F821
                             pair, default=snakemake.params.material_pair)  # noqa: F821
ds = flag_measurements(table, DampingFit.from_dataset(fit_ds), rtol=snakemake.params.rtol,  # noqa: F821
                       posterior=Posterior.load_optional(snakemake.input.posterior),  # noqa: F821
                       **({} if snakemake.params.n_draws is None else {"n_draws": snakemake.params.n_draws}))  # noqa: F821
ds = stamp_fitted(ds, fit_ds)
write_flags(ds, snakemake.output.csv, snakemake.output.nc)  # noqa: F821
print(ds)
