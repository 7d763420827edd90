"""The every-law impacts of laws_cases.py at three tolerances: the baseline of the one Dormand-Prince
core (tests/regression/baseline/integrators.nc).

``python tests/regression/integrator_cases.py`` rewrites the baseline from the current code. It was
written on commit f7859b5 (2026-11-27), before the three hand-written Dormand-Prince steppers (engine,
coupled solver, JKR/DMT solver) were replaced by one (:mod:`microimpact.solvers.dopri`), so that
``tests/test_regression.py`` can show which numbers that moved and by how much.
"""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import numpy as np

RTOLS = (1e-6, 1e-8, 1e-10)


def _laws_cases():
    spec = importlib.util.spec_from_file_location("laws_cases", Path(__file__).parent / "laws_cases.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def solve(case, selection, rtol):
    from microimpact import simulate_impact

    laws = _laws_cases()
    r = simulate_impact(laws.contact(case, selection), case["speed"], case["incidence_deg"], case["azimuth_deg"],
                        case["omega"], rtol=rtol)
    values = [float(getattr(r, f)) for f in laws.FIELDS]
    for v in laws.VECTORS:
        values.extend(float(x) for x in getattr(r, v))
    return values


def solve_all():
    """{selection: array (rtol, impact, quantity)}."""
    laws = _laws_cases()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # DMT outside its Tabor regime: solved all the same
        return {sel: np.array([[solve(c, sel, rtol) for c in laws.cases()] for rtol in RTOLS])
                for sel in laws.SELECTIONS}


def as_dataset(results):
    import xarray as xr

    data = {sel: (("rtol", "impact", "quantity"), arr) for sel, arr in results.items()}
    return xr.Dataset(data, coords={"rtol": list(RTOLS), "quantity": _laws_cases().columns()})


if __name__ == "__main__":
    out = Path(__file__).parent / "baseline" / "integrators.nc"
    as_dataset(solve_all()).to_netcdf(out)
    print("wrote", out)
