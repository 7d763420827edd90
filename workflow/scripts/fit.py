"""Rule fit: zeta_H, zeta_A (optionally w_A) from the measured e_n(v_n), the friction from the oblique
columns when present, and the posterior with its bands -> results/analyst/<pair>/{fit,posterior,oblique}.nc."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.analysis.analyst_fit import analyse_impacts  # noqa: E402
from microimpact.io import read_impacts, read_materials, select_material_pair  # noqa: E402

pair = snakemake.wildcards.pair  # noqa: F821  (this job's material pair: its rows of the data)
table = select_material_pair(read_impacts(snakemake.input.data, materials=snakemake.input.materials,  # noqa: F821
                                          material_pair=snakemake.params.material_pair),  # noqa: F821
                             pair, default=snakemake.params.material_pair)  # noqa: F821
base = read_materials(snakemake.input.materials)[pair]  # noqa: F821
opts = dict(snakemake.params.posterior)  # noqa: F821
enabled, eiv = opts.pop("enabled"), opts.pop("errors_in_variables")
result = analyse_impacts(table, base, rtol=snakemake.params.rtol, posterior=opts if enabled else False,  # noqa: F821
                         errors_in_variables=eiv, **snakemake.params.options)  # noqa: F821
result.save(snakemake.output[0], snakemake.output.posterior, snakemake.output.oblique)  # noqa: F821
print(result.report())
