"""Rule fit: zeta_H, zeta_A (optionally w_A) from the measured e_n(v_n) -> results/analyst/fit.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.solvers.engine import set_threads  # noqa: E402

set_threads(snakemake.threads)  # noqa: F821  (the rule's threads: numba uses no more)

from microimpact.analysis.fitting import fit_damping  # noqa: E402
from microimpact.io import read_impacts, read_materials  # noqa: E402

table = read_impacts(snakemake.input.data, materials=snakemake.input.materials,  # noqa: F821
                     material_pair=snakemake.params.material_pair)  # noqa: F821
base = read_materials(snakemake.input.materials)[snakemake.params.material_pair]  # noqa: F821
fit = fit_damping(table, base, rtol=snakemake.params.rtol, **snakemake.params.options)  # noqa: F821
fit.save(snakemake.output[0])  # noqa: F821
print(fit.report())
