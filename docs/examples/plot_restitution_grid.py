"""
Restitution over a grid of speeds and angles
============================================

:func:`microimpact.simulate_many` takes its inputs as numbers, arrays or
:class:`xarray.DataArray` objects and returns an :class:`xarray.Dataset`. DataArrays broadcast
by dimension name and keep their dimensions, each with an index coordinate, so the result can be
selected, plotted and written with xarray alone. The material is Table 1, row 2 of Cheng, Brach &
Dunn (2002).
"""

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

import microimpact as mi
from microimpact.presets import WALL_1990

speed = xr.DataArray(np.geomspace(0.5, 20.0, 80), dims="speed")  # [m/s]
angle = xr.DataArray([0.0, 30.0, 60.0], dims="incidence_deg")  # [deg] from the normal
ds = mi.simulate_many(WALL_1990, speed=speed, incidence_deg=angle)
print(ds[["e_n", "mu_t", "outcome"]])

# %%
# Every dimension is indexed: pick the impacts nearest 2 m/s.
print(ds.e_n.sel(speed=2.0, method="nearest").to_series())

# %%
# e_n is zero where the sphere is captured (below the capture speed of its normal speed); the
# impulse ratio mu_t (Eq. 22) is undefined there and left out.
fig, (ax_e, ax_mu) = plt.subplots(1, 2, figsize=(9, 3.6), constrained_layout=True)
ds.e_n.plot.line(x="speed", hue="incidence_deg", ax=ax_e, xscale="log")
ds.mu_t.where(ds.outcome == 0).sel(incidence_deg=[30.0, 60.0]).plot.line(
    x="speed", hue="incidence_deg", ax=ax_mu, xscale="log")
ax_e.set_title("normal restitution")
ax_mu.set_title("tangential impulse ratio")
plt.show()
