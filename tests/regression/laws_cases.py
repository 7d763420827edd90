"""The impacts of the every-law regression baseline (tests/regression/baseline/laws.nc).

``python tests/regression/laws_cases.py`` rewrites the baseline from the current code. It was
written on commit b2dc57e (2026-11-26), before the inertia-free limit of the JKR and DMT solvers,
so that changes to the solvers can show which numbers moved. ``tests/test_regression.py``
compares: every case the old code solved must come out the same to solver noise.

The cases are random impacts over the ordinary domain (damping up to 1e3, so that every law
solved every case when the baseline was written), in every sub-model selection of
:func:`microimpact.simulate_impact`'s engine.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from microimpact.studies.stress import LAWS

#: name -> Contact sub-model fields of each selection (the stress sweep's laws; shear modulus added
#: for the compliant ones below, 0.3 K as when the baseline was written)
_STRESS_NAMES = {"ring": "ring", "jkr": "jkr", "jkr_force": "jkr_force", "dmt": "dmt", "mindlin": "mindlin",
                 "mindlin_deresiewicz": "mindlin_deresiewicz", "mindlin_pulloff": "mindlin_pulloff",
                 "md_pulloff_rolling": "mindlin_deresiewicz_pulloff_rolling"}
SELECTIONS = {name: LAWS[law] for name, law in _STRESS_NAMES.items()}
FIELDS = ("e_n", "mu_t", "mu_tp", "contact_time", "capture_time", "max_penetration", "friction_impulse",
          "dissipated_energy", "final_contact_energy")
VECTORS = ("velocity_out", "omega_out")
RTOL = 1e-9
N = 40


def cases():
    """N impact inputs (dicts): radius 1-100 um, speeds 0.01-30 m/s, damping 0-1e3, any angle."""
    rng = np.random.default_rng(2611)

    def logu(lo, hi):
        return float(10.0 ** rng.uniform(math.log10(lo), math.log10(hi)))

    out = []
    for _ in range(N):
        out.append({
            "radius": logu(1e-6, 1e-4), "density": logu(1e3, 1e4), "stiffness": logu(1e9, 1e11),
            "work_of_adhesion": logu(1e-3, 1.0), "zeta_hertz": logu(1e-2, 1e3), "zeta_adhesion": logu(1e-2, 1e3),
            "friction": float(rng.uniform(0.05, 1.0)), "speed": logu(1e-2, 30.0),
            "incidence_deg": float(rng.uniform(0.0, 85.0)), "azimuth_deg": float(rng.uniform(0.0, 360.0)),
            "omega": tuple(float(w) for w in rng.normal(0.0, 1e4, 3)),
        })
    return out


def contact(case, selection):
    from microimpact import Contact

    extra = dict(SELECTIONS[selection])
    if "tangential_model" in extra:
        extra["shear_modulus"] = 0.3 * case["stiffness"]
    return Contact.from_work_of_adhesion(case["radius"], case["density"], case["stiffness"], case["work_of_adhesion"],
                                         zeta_hertz=case["zeta_hertz"], zeta_adhesion=case["zeta_adhesion"],
                                         friction=case["friction"], **extra)


def solve(case, selection):
    from microimpact import simulate_impact

    r = simulate_impact(contact(case, selection), case["speed"], case["incidence_deg"], case["azimuth_deg"],
                        case["omega"], rtol=RTOL)
    values = [float(getattr(r, f)) for f in FIELDS]
    for v in VECTORS:
        values.extend(float(x) for x in getattr(r, v))
    return values


def columns():
    return list(FIELDS) + [f"{v}_{i}" for v in VECTORS for i in range(3)]


def solve_all():
    """{selection: array (N, columns)}."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # DMT outside its Tabor regime: solved all the same
        return {sel: np.array([solve(c, sel) for c in cases()]) for sel in SELECTIONS}


def as_dataset(results):
    import xarray as xr

    data = {sel: (("impact", "quantity"), arr) for sel, arr in results.items()}
    return xr.Dataset(data, coords={"quantity": columns()}, attrs={"rtol": RTOL})


if __name__ == "__main__":
    out = Path(__file__).parent / "baseline" / "laws.nc"
    as_dataset(solve_all()).to_netcdf(out)
    print("wrote", out)
