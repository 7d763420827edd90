"""
Three adhesion laws on one material
===================================

The paper's adhesion ring force (``normal_model="ring"``) against the JKR and DMT contacts with
the same work of adhesion and stiffness. JKR loses energy in its loading-unloading hysteresis even
without damping, so with all damping off it still captures slow spheres, below its sticking
velocity (Thornton & Ning 1998); DMT without damping returns every sphere with e_n = 1.
The Tabor parameter tells which law suits the material.
"""

import dataclasses

import matplotlib.pyplot as plt
import numpy as np

import microimpact as mi
from microimpact.model.adhesion_models import tabor_parameter
from microimpact.presets import WALL_1990

undamped = dataclasses.replace(WALL_1990, zeta_hertz=0.0, zeta_adhesion=0.0)
speed = np.geomspace(0.05, 20.0, 120)  # [m/s]
print(f"Tabor parameter: {tabor_parameter(WALL_1990.radius, WALL_1990.stiffness, WALL_1990.work_of_adhesion):.1f} (JKR above about 5)")

fig, ax = plt.subplots(figsize=(6, 3.8), constrained_layout=True)
for model, style in [("ring", "-"), ("jkr", "--"), ("dmt", ":")]:
    for contact, colour, label in [(WALL_1990, "C0", "damped"), (undamped, "C1", "undamped")]:
        c = dataclasses.replace(contact, normal_model=model)
        e_n = mi.simulate_many(c, speed=speed).e_n
        ax.plot(speed, e_n, style, color=colour, label=f"{model}, {label}")
ax.set(xscale="log", xlabel="normal speed [m/s]", ylabel="e_n", ylim=(-0.02, 1.05))
ax.legend(ncols=2, fontsize="small")
plt.show()
