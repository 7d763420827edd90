"""Rule model_comparison: each normal model fitted to e_n(v_n), AIC/BIC -> results/analyst/<pair>/model_comparison.nc."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.analysis.model_comparison import compare_normal_models  # noqa: E402
from microimpact.io import read_impacts, read_materials, select_material_pair, write_netcdf  # noqa: E402
from microimpact.io.materials import material_contact  # noqa: E402
from microimpact.io.provenance import materials_parameter_source, stamp_parameters  # noqa: E402

pair = snakemake.wildcards.pair  # noqa: F821  (this job's material pair: its rows of the data)
table = select_material_pair(read_impacts(snakemake.input.data, materials=snakemake.input.materials,  # noqa: F821
                                          material_pair=snakemake.params.material_pair),  # noqa: F821
                             pair, default=snakemake.params.material_pair)  # noqa: F821
base = read_materials(snakemake.input.materials)[pair]  # noqa: F821
ds = compare_normal_models(table, base, snakemake.params.models, rtol=snakemake.params.rtol)  # noqa: F821
# the material (start values) per radius; each model's fitted zeta_H, zeta_A, w_A are variables of the file
ds = stamp_parameters(ds, [material_contact(base, float(r)) for r in ds["radius"].values],
                      materials_parameter_source(pair) + " (start values; fitted parameters per normal model)")
write_netcdf(ds, snakemake.output[0])  # noqa: F821
print(ds[["aic", "bic", "delta_aic", "delta_bic", "zeta_hertz", "zeta_adhesion", "work_of_adhesion"]].to_dataframe())
