"""Cost per impact of each selectable sub-model, measured side by side with the paper's model.

The paper's model (rigid contact, friction f |F_n|) runs as one normal solve per normal speed plus
the closed-form map; adhesion-aware friction and tangential compliance run the coupled solver
(:mod:`microimpact.solvers.coupled`). The same oblique impacts are timed for each selection,
interleaved (paper, pulloff, mindlin, paper, ...) so that a change of machine load falls on all of
them alike; only the ratios to the paper's model are meant to be compared.
"""

from __future__ import annotations

import time

import numpy as np

from microimpact.solvers.impact import simulate_many

__all__ = ["SUB_MODEL_SELECTIONS", "sub_model_costs"]

#: name -> Contact changes of each timed selection
SUB_MODEL_SELECTIONS = {
    "paper (rigid, net)": {},
    "pulloff friction (rigid, pulloff)": {"friction_model": "pulloff"},
    "tangential compliance (mindlin, net)": {"tangential_model": "mindlin"},
    "compliance + pulloff (mindlin, pulloff)": {"tangential_model": "mindlin", "friction_model": "pulloff"},
    "hysteretic compliance (mindlin_deresiewicz, net)": {"tangential_model": "mindlin_deresiewicz"},
    "hysteretic + rolling resistance (mu_r 0.01)": {"tangential_model": "mindlin_deresiewicz",
                                                    "rolling_friction": 0.01},
}


def sub_model_costs(contact, speeds, incidence_deg, *, shear_modulus: float | None = None, repeats: int = 3) -> dict:
    """Median wall time per impact [s] of each sub-model selection and its ratio to the paper's model.

    Parameters
    ----------
    contact : Contact
        The paper's model contact (default sub-models).
    speeds, incidence_deg : array_like
        Impact speeds [m/s] and incidence angles [deg], broadcast together (an outer grid).
    shear_modulus : float, optional
        G* for the compliant selections; default ``contact.shear_modulus`` or, if None, the
        isotropic value with nu = 0.25 from K (E* = 3 K / 4, G = E / (2 (1 + nu))). [Pa]
    repeats : int
        Interleaved repetitions; the median is kept.

    Returns
    -------
    dict
        name -> {"time_per_impact": s, "ratio_to_paper": -}.

    Examples
    --------
    One impact at 2 m/s and 30 deg, timed once (an illustration: one impact's timings are noise): a
    time and a ratio for every selection, the paper's model the unit:

    >>> from microimpact.presets import WALL_1990
    >>> costs = sub_model_costs(WALL_1990, [2.0], [30.0], repeats=1)
    >>> list(costs) == list(SUB_MODEL_SELECTIONS), costs["paper (rigid, net)"]["ratio_to_paper"]
    (True, 1.0)
    >>> all(c["time_per_impact"] > 0 for c in costs.values())
    True
    """
    g = shear_modulus or contact.shear_modulus
    if g is None:  # like materials, nu = 0.25: E = E* (1 - nu^2), G* = G / (2 (2 - nu)) for two alike
        e = 0.75 * contact.stiffness * 2.0 * (1.0 - 0.25**2)
        g = e / (2.0 * 1.25) / (2.0 * (2.0 - 0.25))
    v = np.asarray(speeds, dtype=float)[:, None]
    a = np.asarray(incidence_deg, dtype=float)[None, :]
    n = np.broadcast(v, a).size
    contacts = {name: contact.with_(**changes, shear_modulus=g) for name, changes in SUB_MODEL_SELECTIONS.items()}
    for c in contacts.values():  # compile and warm up on the whole grid: some impacts reach kernels
        simulate_many(c, v, a)     # that others never call, and numba compiles each on first use
    times = {name: [] for name in contacts}
    for _ in range(max(1, int(repeats))):
        for name, c in contacts.items():
            t0 = time.perf_counter()
            simulate_many(c, v, a)
            times[name].append((time.perf_counter() - t0) / n)
    paper = float(np.median(times["paper (rigid, net)"]))
    return {name: {"time_per_impact": float(np.median(t)), "ratio_to_paper": float(np.median(t)) / paper}
            for name, t in times.items()}
