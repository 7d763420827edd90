"""Work-precision lines of the normal models: the paper's ring force (its engine), JKR and DMT side by side.

The cost of a normal model is that of its compiled normal solve (the tangential map is the same
closed form for all three). For each model and tolerance, the batch solver
(``solve_normal_many``, one thread) runs the same normal speeds; the error of e_n is taken against
that model's own reference: its solver at rtol 1e-13 for the ring law, and the scipy DOP853
integration in physical time (:func:`microimpact.solvers.normal_models.solve_normal_reference`) at
rtol 1e-12 for JKR and DMT. Times are per impact, measured alternately in one process, so that the
ratios (the quantity reported) compare like with like on a shared machine.
"""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from microimpact.model.adhesion_models import AdhesionRegimeWarning
from microimpact.presets import WALL_1990
from microimpact.solvers import engine, normal_models
from microimpact.studies.benchmark.harness import timed

__all__ = ["normal_model_work_precision", "NORMAL_MODELS"]

NORMAL_MODELS = ("ring", "jkr", "dmt")


def _reference_e_n(contact, speeds):
    if contact.normal_model == "ring":
        return engine.solve_normal_many(contact, speeds, rtol=1e-13)["e_n"]
    return np.array([normal_models.solve_normal_reference(contact, float(v), rtol=1e-12).e_n for v in speeds])


def normal_model_work_precision(contact=WALL_1990, speeds=None, rtols=(1e-6, 1e-8, 1e-10),
                                repeats: int = 5) -> xr.Dataset:
    """Cost per impact and largest e_n error of each normal model's compiled solve, per tolerance.

    Parameters
    ----------
    contact : Contact
        The contact (its normal_model is replaced by each of :data:`NORMAL_MODELS`).
    speeds : array_like, optional
        Normal speeds [m/s]; default 40 log-spaced in 0.3-30 m/s (captures and rebounds).
    rtols : sequence of float
        Tolerances of the compiled solves. [-]
    repeats : int
        Timing repeats (the median is kept).

    Returns
    -------
    xarray.Dataset
        ``time_per_impact`` [s] and ``max_error_e_n`` [-] on (normal_model, rtol), and
        ``cost_ratio`` [-]: time per impact over that of the ring law's engine at the same rtol.

    Examples
    --------
    Two speeds at one tolerance, timed once (an illustration: the timings of so short a run are
    noise): each model's e_n is within 1e-5 of its own reference at rtol 1e-6, and the costs are
    given relative to the ring law's engine:

    >>> ds = normal_model_work_precision(speeds=[2.0, 5.0], rtols=(1e-6,), repeats=1)
    >>> dict(ds.sizes), ds["normal_model"].values.tolist()
    ({'normal_model': 3, 'rtol': 1}, ['ring', 'jkr', 'dmt'])
    >>> bool((ds["max_error_e_n"] < 1e-5).all()), ds["cost_ratio"].sel(normal_model="ring").values.tolist()
    (True, [1.0])
    """
    speeds = np.geomspace(0.3, 30.0, 40) if speeds is None else np.asarray(speeds, dtype=float)
    engine.set_threads(1)
    time_, err = np.full((len(NORMAL_MODELS), len(rtols)), np.nan), np.full((len(NORMAL_MODELS), len(rtols)), np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AdhesionRegimeWarning)
        for i, model in enumerate(NORMAL_MODELS):
            c = contact.with_(normal_model=model)
            solver = engine if model == "ring" else normal_models
            ref = _reference_e_n(c, speeds)
            for j, rtol in enumerate(rtols):
                e = solver.solve_normal_many(c, speeds, rtol=rtol)["e_n"]  # also compiles
                err[i, j] = float(np.max(np.abs(e - ref)))
                time_[i, j] = timed(lambda: solver.solve_normal_many(c, speeds, rtol=rtol), repeats)[0] / speeds.size
    engine.set_threads()
    ds = xr.Dataset(
        {"time_per_impact": (("normal_model", "rtol"), time_, {"units": "s", "long_name": "compute time per normal solve"}),
         "max_error_e_n": (("normal_model", "rtol"), err, {"units": "1", "long_name": "largest |e_n - reference e_n|"}),
         "cost_ratio": (("normal_model", "rtol"), time_ / time_[0], {"units": "1", "long_name": "time per impact over the ring engine's"})},
        coords={"normal_model": list(NORMAL_MODELS), "rtol": ("rtol", np.asarray(rtols), {"units": "1", "long_name": "relative tolerance"})})
    ds.attrs.update(title="Work-precision of the normal models", n_speeds=int(speeds.size), threads=1)
    return ds
