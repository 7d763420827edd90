"""
From measured impacts to a LAMMPS input: fit LAMMPS's laws, export, run LAMMPS
==============================================================================

:func:`microimpact.analysis.dem_fit.rank_dem_laws` fits the damping coefficient of each LAMMPS
GRANULAR law (Hertz with ``coeff_restitution``, ``tsuji``, ``viscoelastic`` or ``mass_velocity``)
to measured normal restitution and ranks the laws by AIC; the best one, when the data determine it,
is written as LAMMPS input and run by LAMMPS. The command line does the same in two commands
(``microimpact lammps fit`` and ``microimpact lammps verify``).

The "measurements" here are made, so that the truth is known: 16 impacts of a 2 um sphere between
0.1 and 10 m/s, whose restitution falls with speed as LAMMPS's ``viscoelastic`` damping makes it
fall, with a Gaussian scatter of 0.01 that is also stated as each impact's uncertainty.
"""

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from microimpact.analysis.dem_fit import dem_law_restitution, rank_dem_laws
from microimpact.io.lammps import lammps_input
from microimpact.studies.lammps_check import LammpsUnavailable, verify_lammps

material = {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0}  # no adhesion: Hertz
radius = 2e-6
speed = np.geomspace(0.1, 10.0, 16)
eta_true = 1e14  # 1/(m s): e_n from 0.87 at 0.1 m/s to 0.70 at 10 m/s
rng = np.random.default_rng(7)
e_true = dem_law_restitution(material, radius, speed, "hertz", "viscoelastic", eta_true)
measured = pd.DataFrame({"radius": radius, "normal_speed": speed,
                         "e_n": e_true + rng.normal(0.0, 0.01, speed.size), "e_n_uncertainty": 0.01})

# %%
# Every Hertz law fitted to the same impacts. The speed-independent laws (``coeff_restitution``,
# ``tsuji``) and ``mass_velocity`` do not describe a restitution that falls with speed: they are
# "inadequate" (chi^2 improbable for the stated uncertainties) and get no value.
ranked, fits = rank_dem_laws(measured, material)
print(ranked[["law", "status", "value", "interval_low", "interval_high", "chisqr", "delta_aic"]].to_string(index=False))
best = fits[ranked["law"].iloc[0]]
print(best.describe())
print(f"true eta_n0 = {eta_true:.6g} 1/(m s)")

# %%
# The data and each law's best curve.
v = np.geomspace(speed.min(), speed.max(), 60)
fig, ax = plt.subplots(figsize=(6, 3.6), constrained_layout=True)
ax.errorbar(speed, measured["e_n"], yerr=0.01, fmt="o", color="k", ms=4, label="measured")
for name, f in fits.items():
    curve = dem_law_restitution(material, radius, v, f.normal_model, f.damping_model, f.best)
    ax.plot(v, curve, lw=2 if name == best.law else 1, label=f"{name} ({f.status})")
ax.set(xscale="log", xlabel="normal speed [m/s]", ylabel="e_n")
ax.legend(fontsize="x-small")

# %%
# The best law as LAMMPS input (micro units), and LAMMPS on it against microimpact.
contact = best.contact(radius)
text = lammps_input(contact, units="micro", fitted={"damping_coefficient": best.describe()})
print(text.splitlines()[-1])
try:
    table = verify_lammps(text, speeds=(0.1, 1.0, 10.0), incidences=(0.0, 60.0))
except LammpsUnavailable as exc:
    print(f"skipped: {exc}")
else:
    print(table[["speed", "incidence_deg", "e_n_microimpact", "e_n_lammps", "difference", "step_error"]]
          .to_string(index=False))
    print(f"LAMMPS {table.attrs['lammps_version']}: passed = {table.attrs['passed']}")
plt.show()
