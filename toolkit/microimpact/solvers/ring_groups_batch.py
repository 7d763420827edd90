"""e_n of many ring-law impacts of many contacts from their nondimensional groups, in one compiled call.

The engine's :func:`~microimpact.solvers.engine.solve_normal_many` solves the impacts of one
contact: each call builds the contact's scales and checks its results in Python. A posterior's
walkers are a new contact each, with a few impacts each outside the emulator's table
(:mod:`microimpact.solvers.emulator`), so that per-call cost, not the integration, was most of what
the table's fallback cost. The normal impact of the ring law depends on its three groups alone
(y0, C1, C2; :mod:`microimpact.model.reduction`), so impacts of any number of contacts are one
array of groups: :func:`restitution_of_groups` passes them to the engine's batch kernel in one
call, in the paper's scales (a_h = a_a = 1, what :func:`~microimpact.solvers.engine.engine_scales`
gives for y0 up to :data:`~microimpact.solvers.engine.MAX_ADHESIVE_SPEED`), and checks every
result as the engine does. :func:`fallback_of_groups` is
:func:`~microimpact.solvers.emulator.fallback_restitution` over groups: the same tolerances.

This module is not part of the emulator's table key (its sources do not change the table).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from microimpact.solvers import MIN_RTOL, DEFAULT_RTOL, engine
from microimpact.solvers.emulator import FALLBACK_RTOL, NEAR_CAPTURE_E, NODE_RTOL_FLOOR

__all__ = ["GroupOutcome", "restitution_of_groups", "fallback_of_groups", "outcome_of_groups"]


class GroupOutcome(NamedTuple):
    """The normal outcomes of impacts given by their groups (arrays of the groups' shape): captured,
    e_n [-], and the friction and twist impulses in the groups' units (:func:`outcome_of_groups`)."""

    captured: np.ndarray
    e_n: np.ndarray
    friction_impulse: np.ndarray
    twist_impulse: np.ndarray


def outcome_of_groups(y0, c1, c2, *, rtol: float = DEFAULT_RTOL) -> GroupOutcome:
    """:func:`restitution_of_groups` with the impulses: ``captured``, ``e_n`` [-], and the friction and
    twist impulses in the groups' units, ``friction_impulse`` J / (m X / T) and ``twist_impulse``
    J_a / (m X / T sqrt(r X)) [-] (the engine's own; :func:`~microimpact.solvers.engine.solve_normal_many`
    multiplies them by these scales).

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> from microimpact.model import reduction
    >>> out = outcome_of_groups(*reduction.ring_groups([c], [[3.0]]), rtol=1e-10)
    >>> j = engine.solve_normal_many(c, [3.0], rtol=1e-10)["friction_impulse"][0] / (c.mass * c.length_scale / c.time_scale)
    >>> bool(abs(out.friction_impulse[0, 0] / j - 1) < 1e-9)
    True
    """
    y, a, b = (np.array(x, dtype=float) for x in np.broadcast_arrays(y0, c1, c2))
    shape = y.shape
    out = _solve(y.ravel(), a.ravel(), b.ravel(), rtol)
    captured = out[:, 1] == engine.CAPTURE
    e = np.where(captured, 0.0, -out[:, 2] / y.ravel())
    engine._check_restitution(e, y.ravel(), rtol)
    return GroupOutcome(captured.reshape(shape), e.reshape(shape), out[:, 5].reshape(shape), out[:, 6].reshape(shape))


def _solve(y, a, b, rtol) -> np.ndarray:
    """The engine batch kernel's rows (status, outcome, y_end, ..., impulses) of the impacts (y0, C1, C2)."""
    y, a, b = (np.ascontiguousarray(x, dtype=float) for x in (y, a, b))
    if y.size and not (np.all(y >= engine.MIN_NONDIMENSIONAL_SPEED) and np.all(y <= engine.MAX_ADHESIVE_SPEED)):
        raise ValueError(f"y0 must lie in [{engine.MIN_NONDIMENSIONAL_SPEED:g}, {engine.MAX_ADHESIVE_SPEED:g}] "
                         "(the paper's scales)")
    ones, no = np.ones(y.size), np.zeros(y.size, dtype=np.bool_)
    inf = np.full(y.size, np.inf)
    out = np.empty((y.size, 11))
    # writable, contiguous arrays of the engine's own dtypes: one compiled kernel for every caller
    engine._integrate_many(y, a, b, ones, ones.copy(), float(rtol), no, float(rtol), int(engine._MAX_STEPS_DEFAULT),
                           inf, inf.copy(), out)
    status = out[:, 0]
    if np.any(status != engine._OK):
        i = int(np.flatnonzero(status != engine._OK)[0])
        raise engine.EngineError(f"engine failed at y0 = {y[i]!r}, C1 = {a[i]!r}, C2 = {b[i]!r}: "
                                 f"{engine._failure(status[i])}")
    return out


def restitution_of_groups(y0, c1, c2, *, rtol: float = DEFAULT_RTOL) -> np.ndarray:
    """e_n of ring-law impacts given by their groups (arrays of one shape), one engine batch call. [-]

    Parameters
    ----------
    y0, c1, c2 : array_like
        Incident speed v T / X and damping groups C1 = C_H X / T, C2 = C_A X / T (Eqs. (28),
        (31)-(32)) of each impact, y0 in [MIN_NONDIMENSIONAL_SPEED, MAX_ADHESIVE_SPEED]. [-]
    rtol : float
        Relative tolerance of the solves. [-]

    Returns
    -------
    numpy.ndarray
        e_n, 0 where captured. [-]

    Raises
    ------
    ValueError
        A y0 outside the range the paper's scales serve.
    EngineError
        A solve failed or gave e_n outside [0, 1] beyond its own error (as the engine's).

    Examples
    --------
    The same numbers as the engine's solve of the contact (the paper's microsphere):

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> from microimpact.model import reduction
    >>> y0, c1, c2 = reduction.ring_groups([c], [[0.5, 3.0]])
    >>> e = restitution_of_groups(y0, c1, c2, rtol=1e-10)
    >>> bool(abs(e - engine.solve_normal_many(c, [0.5, 3.0], rtol=1e-10)["e_n"]).max() < 1e-9), float(e[0, 0])
    (True, 0.0)
    """
    return outcome_of_groups(y0, c1, c2, rtol=rtol).e_n


def fallback_of_groups(y0, c1, c2, tol: float) -> np.ndarray:
    """e_n to the absolute tolerance ``tol`` by the solver, as
    :func:`~microimpact.solvers.emulator.fallback_restitution`: at ``rtol = FALLBACK_RTOL tol``, and
    those that barely rebound (e_n < NEAR_CAPTURE_E) again at ``tol min(e_n) / 12`` (one rtol for
    all of them: the smallest such e_n sets it). [-]

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> from microimpact.model import reduction
    >>> fallback_of_groups(*reduction.ring_groups([c], [[0.5, 3.0]]), 1e-6).round(4).tolist()
    [[0.0, 0.5866]]
    """
    rtol = max(tol * FALLBACK_RTOL, NODE_RTOL_FLOOR)
    y, a, b = (np.array(x, dtype=float) for x in np.broadcast_arrays(y0, c1, c2))
    e = restitution_of_groups(y, a, b, rtol=rtol)
    near = (e > 0.0) & (e < NEAR_CAPTURE_E)
    if near.any():
        tight = max(tol * float(e[near].min()) / 12.0, MIN_RTOL * 1.01)
        if tight < rtol:
            e[near] = restitution_of_groups(y[near], a[near], b[near], rtol=tight)
    return e
