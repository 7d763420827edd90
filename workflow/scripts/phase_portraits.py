"""Rule phase_portraits: Fig. 5 trajectories of the paper's contact -> results/paper/phase_portraits.nc."""

import sys

sys.stdout = sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

from microimpact.dynamics.nonlinear import phase_portraits, save_phase_portraits  # noqa: E402
from microimpact.io.provenance import stamp_parameters  # noqa: E402
from microimpact.presets import named_contact  # noqa: E402

contact, source = named_contact(snakemake.params.contact)  # noqa: F821
portraits = [stamp_parameters(ds, contact, source) for ds in phase_portraits(contact, snakemake.params.speeds)]  # noqa: F821
save_phase_portraits(portraits, snakemake.output[0])  # noqa: F821
for ds in portraits:
    print(ds.attrs["normal_speed"], "m/s:", ds.attrs["motion_type"])
