"""Rule stress: seeded random stress sweep of the engine -> results/stress_summary.json (summary)
+ results/stress.nc (one row per case: inputs, measures, failures)."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import json  # noqa: E402

from microimpact.io.files import atomic_write, write_netcdf  # noqa: E402
from microimpact.studies.stress import stress_sweep  # noqa: E402

params = snakemake.params  # noqa: F821


def progress(i, n):
    if i % 1000 == 0 or i == n:
        print(f"{i}/{n} cases")


report = stress_sweep(params.cases, params.seed, reference_every=params.reference_every,
                      case_time_limit=params.case_time_limit, progress=progress)
with atomic_write(snakemake.output.summary) as f:  # noqa: F821
    f.write(json.dumps(report.summary, indent=2, allow_nan=False, default=str) + "\n")
write_netcdf(report.dataset, snakemake.output.netcdf)  # noqa: F821
s = report.summary
print(f"{s['cases_run']} cases (seed {s['seed']}) in {s['seconds']:.3g} s, {s['cases_failed']} failed: "
      + (", ".join(f"{k} {v}" for k, v in s["failures_by_kind"].items() if v) or "none"))
