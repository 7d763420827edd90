"""
Fit the damping to measured rebounds
====================================

A measured-impact CSV (units in the header) is read and checked by
:func:`microimpact.io.read_impacts`, and :func:`microimpact.analysis.analyse_impacts` fits the
Hertzian and adhesion damping ratios zeta_H, zeta_A jointly over all sphere sizes, with
profile-likelihood intervals. Here the measurements are synthetic, made by the model from stated
parameters that are *not* the paper's (zeta_H = 1.2, zeta_A = 12), with 3 % noise on e_n and 1 % on
the speed, so the fit can be checked against the truth.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import microimpact as mi
from microimpact.analysis import analyse_impacts, make_synthetic_impacts
from microimpact.io import read_impacts, read_materials

truth = {"zeta_hertz": 1.2, "zeta_adhesion": 12.0}
table = make_synthetic_impacts(**truth, n_per_radius=15, seed=7)
csv = Path(tempfile.mkdtemp()) / "impacts.csv"
table.to_csv(csv, index=False)
print(csv.read_text().splitlines()[0])  # the header: names and units

# %%
# Read it back as an analyst would, with the material from the bundled materials config, and fit.
data = read_impacts(csv)
pair = read_materials()["ammonium_fluorescein_on_silicon"]
result = analyse_impacts(data, pair, confidence_intervals=True)
print(result.report())

# %%
# The measured e_n per sphere size and the fitted model: ``fit.contact(radius)`` is the fitted
# material at that size (f0 from the work of adhesion by Eq. 7).
fit = result.damping
print(f"truth: zeta_H = {truth['zeta_hertz']}, zeta_A = {truth['zeta_adhesion']}")
fig, ax = plt.subplots(figsize=(6, 3.8), constrained_layout=True)
for i, (radius, rows) in enumerate(data.groupby("radius")):
    ax.errorbar(rows["normal_speed"], rows["e_n"], rows["e_n_uncertainty"], fmt="o", ms=3, color=f"C{i}",
                label=f"r = {radius * 1e6:.2f} um")
    v = np.geomspace(rows["normal_speed"].min() * 0.8, rows["normal_speed"].max() * 1.2, 100)
    ax.plot(v, mi.simulate_many(fit.contact(radius), speed=v).e_n, color=f"C{i}")
ax.set(xscale="log", xlabel="normal speed [m/s]", ylabel="e_n")
ax.legend(fontsize="small")
plt.show()
