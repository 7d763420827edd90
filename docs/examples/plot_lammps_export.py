"""
A contact as LAMMPS input, checked by LAMMPS
============================================

:func:`microimpact.io.lammps.lammps_input` writes a contact as the ``fix wall/gran ... granular``
line of LAMMPS's GRANULAR package, and :func:`microimpact.studies.lammps_check.verify_lammps` runs
LAMMPS on that text (one sphere against the wall, over speeds and angles, at two steps) and compares
it with microimpact. Here: the paper's ammonium fluorescein microsphere with the force-controlled
JKR break that LAMMPS uses (``normal_model="jkr_force"``), without damping or friction, the laws
LAMMPS can express. LAMMPS itself comes from the ``[lammps]`` extra; without it the comparison is
skipped.
"""

import matplotlib.pyplot as plt
import numpy as np

from microimpact.io.lammps import LammpsExportError, lammps_input
from microimpact.model.adhesion_models import jkr_sticking_velocity
from microimpact.presets import WALL_1990
from microimpact.studies.lammps_check import LammpsUnavailable, verify_lammps

# %%
# The paper's contact has its nonlinear damping, the ring adhesion force and friction: LAMMPS has no
# law for any of them, and the export says so, naming each.
try:
    lammps_input(WALL_1990)
except LammpsExportError as exc:
    print(exc)

# %%
# Without them, and with JKR adhesion of the same work of adhesion, the contact is one LAMMPS line
# (in LAMMPS's ``micro`` units here), under a header that records the contact.
contact = WALL_1990.with_(normal_model="jkr_force", zeta_hertz=0.0, zeta_adhesion=0.0, friction=0.0)
text = lammps_input(contact, units="micro")
print(text)

# %%
# LAMMPS against microimpact, and against the energy balance of an undamped force-controlled JKR
# impact, e_n = sqrt(1 - (v_s / v_n)^2) above the sticking velocity v_s.
v_s = jkr_sticking_velocity(contact)
speeds = v_s * np.geomspace(0.5, 10.0, 9)
try:
    table = verify_lammps(text, speeds=speeds, incidences=(0.0,))
except LammpsUnavailable as exc:
    print(f"skipped: {exc}")
else:
    print(table[["speed", "outcome_lammps", "e_n_microimpact", "e_n_lammps", "difference", "step_error"]]
          .to_string(index=False))
    print(f"LAMMPS {table.attrs['lammps_version']}: passed = {table.attrs['passed']}")
    v = np.geomspace(v_s, speeds.max(), 200)
    fig, ax = plt.subplots(figsize=(6, 3.6), constrained_layout=True)
    ax.plot(v / v_s, np.sqrt(1.0 - (v_s / v) ** 2), color="0.7", lw=3, label="sqrt(1 - (v_s / v)^2)")
    ax.plot(table["speed"] / v_s, table["e_n_microimpact"], "o", ms=7, mfc="none", label="microimpact")
    ax.plot(table["speed"] / v_s, table["e_n_lammps"], "x", ms=7, label="LAMMPS (fix wall/gran, jkr)")
    ax.set(xscale="log", xlabel="v_n / v_s", ylabel="e_n")
    ax.legend(fontsize="small")
    plt.show()
