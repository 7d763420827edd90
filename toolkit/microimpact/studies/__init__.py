"""Studies: what is computed in bulk.

- :mod:`.sweeps`: the Table 2 sensitivity sweeps (and any grid) as NetCDF-ready Datasets.
- :mod:`.stress`: the seeded stability sweep over decades of every input.
- :mod:`.benchmark`: the work-precision study of the solvers, side by side.
- :mod:`.reproduction`: the paper's numbers and claims checked by computation.
"""
