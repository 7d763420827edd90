"""Rule phase_portraits: Fig. 5 trajectories at the configured normal speeds -> results/phase_portraits.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact import Contact  # noqa: E402
from microimpact.dynamics.nonlinear import phase_portraits, save_phase_portraits  # noqa: E402

portraits = phase_portraits(Contact(**snakemake.params.contact), snakemake.params.speeds)  # noqa: F821
save_phase_portraits(portraits, snakemake.output[0])  # noqa: F821
for ds in portraits:
    print(ds.attrs["normal_speed"], "m/s:", ds.attrs["motion_type"])
