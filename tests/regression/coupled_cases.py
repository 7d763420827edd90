"""The impacts of the coupled-solver regression baseline (tests/regression/baseline/coupled.nc).

``python tests/regression/coupled_cases.py`` rewrites the baseline from the current code; it was
written on commit 7271c03, before the coupled solver located the largest penetration and stopped
captured pulloff impacts early (2026-11-23). ``tests/test_regression.py`` compares.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: (tangential model, friction model, rolling friction) of each selection
SELECTIONS = (
    ("rigid", "pulloff", 0.0),
    ("mindlin", "net", 0.0),
    ("mindlin", "pulloff", 0.0),
    ("mindlin", "pulloff", 0.01),
    ("mindlin_deresiewicz", "net", 0.0),
    ("mindlin_deresiewicz", "pulloff", 0.0),
)
RTOL = 1e-9
N = 60


def impacts():
    """(velocity_in, omega_in, friction) of the N impacts: speeds 0.05-50 m/s (about half of them
    captured), incidences 0-85 deg, random spins."""
    from microimpact.model.kinematics import incident_velocity

    rng = np.random.default_rng(23)
    speed = np.exp(rng.uniform(np.log(0.05), np.log(50.0), N))
    inc = rng.uniform(0.0, 85.0, N)
    az = rng.uniform(0.0, 360.0, N)
    v = tuple(np.array([incident_velocity(a, b, c) for a, b, c in zip(speed, inc, az)]).T)
    w = tuple(rng.normal(0.0, 2e5, N) for _ in range(3))
    return v, w, np.full(N, 0.15)


def contact(tangential, friction, rolling):
    from microimpact.presets import WALL_1990

    return WALL_1990.with_(tangential_model=tangential, friction_model=friction, rolling_friction=rolling,
                           shear_modulus=1e10)


def solve_all():
    """{selection name: dict of result arrays} of the coupled solver over :func:`impacts`."""
    from microimpact.solvers.coupled import solve_coupled

    v, w, f = impacts()
    return {"-".join(map(str, sel)): solve_coupled(contact(*sel), v, w, f, rtol=RTOL) for sel in SELECTIONS}


def as_dataset(results):
    import xarray as xr

    data = {f"{name}:{key}": ("impact", np.asarray(val, dtype=float))
            for name, res in results.items() for key, val in res.items()}
    return xr.Dataset(data, attrs={"rtol": RTOL, "selections": ", ".join(results)})


if __name__ == "__main__":
    out = Path(__file__).parent / "baseline" / "coupled.nc"
    as_dataset(solve_all()).to_netcdf(out)
    print("wrote", out)
