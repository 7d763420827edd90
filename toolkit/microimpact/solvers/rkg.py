"""The paper's integrator: fixed-step Runge-Kutta-Gill (Gill 1951) on the nondimensional Eq. (27).

Cheng, Brach & Dunn (2002) integrate the normal motion with a fixed-step fourth-order
Runge-Kutta-Gill method. Here it is numba-compiled, batched over all cores (``prange``) for the
benchmark (:func:`rkg_restitution`) and available as ``simulate_impact(..., method="rkg")``
through :func:`solve_normal_rkg`, which also returns the friction impulses that the closed-form
tangential map needs.

The system is xi' = y, y' = xi'' of :func:`microimpact.model.law.nondimensional_acceleration` in
tau = t / T_c (the plain form, not the engine's Sundman form), with the contact law compiled from
:mod:`microimpact.model.law` (see :mod:`microimpact.solvers.compiled_law`). The step is
dtau = (estimated contact duration) / N; the duration estimate comes from the engine at a loose
rtol = 1e-6, since a fixed-step code needs some such estimate to choose its step.

Accuracy: from first contact the solution has a tau^(5/2) (Hertz) or tau^(3/2) (adhesion) term, so
the global order drops from 4 to 2.5 or lower; with adhesion N = 1600 gives e_n to about 1e-6.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import prange

from microimpact._numba import njit, njit_batch
from microimpact.model.contact import check_positive
from microimpact.model.law import nondimensional_impact
from microimpact.solvers import compiled_law as law
from microimpact.solvers import engine
from microimpact.solvers.driver import OK, Trace
from microimpact.solvers.solution import NormalSolution, SolutionBatch

__all__ = ["RkgSetup", "RkgState", "rkg_setup", "rkg_state", "rkg_restitution", "solve_normal_rkg", "DEFAULT_STEPS"]

#: Default steps per estimated contact duration of :func:`solve_normal_rkg` (e_n to ~1e-6 with
#: adhesion, tests/test_benchmark.py).
DEFAULT_STEPS = 2000

#: Step limit, in units of the steps per contact, before the impact is declared unresolved.
_MAX_CONTACTS = 20

_G1 = 1.0 - 1.0 / math.sqrt(2.0)
_G2 = 1.0 + 1.0 / math.sqrt(2.0)

# Columns of the compiled impact result
_Y_OUT, _TAU_END, _N_STEPS, _OUTCOME, _J, _J_A, _XI_MAX, _TAU_J, _E_END = range(9)
_NCOL = 9


@njit(cache=True)
def _rkg_accel(xi, y, c1, c2, ah, aa):
    """xi'' of Eq. (27) in tau (:func:`microimpact.model.law.nondimensional_acceleration`); 0 outside contact."""
    if xi <= 0.0:
        return 0.0
    s = math.sqrt(xi)
    return law.nondimensional_acceleration(s, xi * s, y, c1, c2, ah, aa)


@njit(cache=True)
def _rkg_step(xi, y, h, c1, c2, ah, aa):
    """One classical Runge-Kutta-Gill step (Gill 1951) of the system xi' = y, y' = a(xi, y)."""
    k1x = h * y
    k1y = h * _rkg_accel(xi, y, c1, c2, ah, aa)
    x2 = xi + 0.5 * k1x
    y2 = y + 0.5 * k1y
    k2x = h * y2
    k2y = h * _rkg_accel(x2, y2, c1, c2, ah, aa)
    x3 = xi + (-0.5 + 1.0 / math.sqrt(2.0)) * k1x + _G1 * k2x
    y3 = y + (-0.5 + 1.0 / math.sqrt(2.0)) * k1y + _G1 * k2y
    k3x = h * y3
    k3y = h * _rkg_accel(x3, y3, c1, c2, ah, aa)
    x4 = xi - (1.0 / math.sqrt(2.0)) * k2x + _G2 * k3x
    y4 = y - (1.0 / math.sqrt(2.0)) * k2y + _G2 * k3y
    k4x = h * y4
    k4y = h * _rkg_accel(x4, y4, c1, c2, ah, aa)
    xn = xi + (k1x + 2.0 * _G1 * k2x + 2.0 * _G2 * k3x + k4x) / 6.0
    yn = y + (k1y + 2.0 * _G1 * k2y + 2.0 * _G2 * k3y + k4y) / 6.0
    return xn, yn


@njit(cache=True)
def _rkg_impact(y0, c1, c2, ah, aa, h, max_steps, j_target):
    """Fixed-step RKG from first contact (xi = 0, y = y0) to separation or capture.

    Separation: xi changes sign from + to -; its time is found by linear interpolation of xi. The
    exit speed is y at the end of that step: past the root the force is zero (free flight), so y is
    constant there and the step already integrates the motion through the separation point
    (linearly interpolating y as well would add an O(h^2.5) error). Capture: the contact energy
    e of :func:`microimpact.model.law.nondimensional_energy` falls below 0; the steps go on to
    the largest penetration (y <= 0) if the capture came on the way in, so that xi_max is the
    largest penetration (it was the xi of the capture step: 1/70 of it for a slow impact).

    The nondimensional friction impulse J = int |xi''| dtau is the total variation of y, summed as
    |dy| per step, and J_a = int s |xi''| dtau (s = sqrt(xi)) by the trapezoidal rule in y; both
    are exact where y is monotone within a step and otherwise O(h^2) (an extremum inside a step).
    ``j_target`` > 0: also record the time at which J reaches it (linear interpolation).

    Returns (y_out, tau_end, n_steps, outcome, J, J_a, xi_max, tau_j, e_end) with outcome 0
    rebound, 1 capture, -1 step limit; tau_end is the separation or the capture time.
    """
    xi = 0.0
    y = y0
    jn = 0.0
    ja = 0.0
    xi_max = 0.0
    tau_j = math.nan
    n_cap = 0  # the step at which the sphere was captured (0: not yet)
    e_cap = 0.0
    for n in range(1, max_steps + 1):
        xn, yn = _rkg_step(xi, y, h, c1, c2, ah, aa)
        dj = abs(yn - y)
        if j_target > 0.0 and math.isnan(tau_j) and jn + dj >= j_target:
            tau_j = (n - 1 + (j_target - jn) / dj) * h
        jn += dj
        ja += 0.5 * (math.sqrt(max(xi, 0.0)) + math.sqrt(max(xn, 0.0))) * dj
        if xi > 0.0 and xn <= 0.0:
            theta = xi / (xi - xn)
            return -yn, (n - 1 + theta) * h, n, 0, jn, ja, xi_max, tau_j, 0.5 * yn * yn
        xi, y = xn, yn
        xi_max = max(xi_max, xi)
        if n_cap == 0 and aa > 0.0 and xi > 0.0:
            e_cap = law.nondimensional_energy(math.sqrt(xi), y, ah, aa)
            if e_cap < 0.0:
                n_cap = n
        if n_cap > 0 and y <= 0.0:
            return 0.0, n_cap * h, n, 1, jn, ja, xi_max, tau_j, e_cap
    return math.nan, math.nan, max_steps, -1, jn, ja, xi_max, tau_j, math.nan


@njit_batch
def _rkg_many(y0, c1, c2, ah, aa, h, max_steps, out):
    for i in prange(y0.shape[0]):
        y_out, tau, n, outcome, jn, ja, xi_max, tau_j, e_end = _rkg_impact(
            y0[i], c1[i], c2[i], ah, aa, h[i], max_steps[i], 0.0)
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4] = y_out, tau, n, outcome, jn
        out[i, 5], out[i, 6], out[i, 7], out[i, 8] = ja, xi_max, tau_j, e_end


class RkgState(NamedTuple):
    """The state of Eq. (27) after fixed RKG steps (:func:`rkg_state`). [-]"""

    #: the nondimensional approach
    xi: float
    #: its rate d xi / d tau
    y: float


class RkgSetup(NamedTuple):
    """The nondimensional set-up of RKG impacts, per speed (:func:`rkg_setup`). [-]"""

    #: incident speed in the unit X / T, per speed
    y0: np.ndarray
    #: damping coefficients C1, C2 of Eq. (27), per speed
    c1: np.ndarray
    c2: np.ndarray
    #: the coefficients a_h, a_a of Eq. (27)
    a_hertz: object
    a_adhesion: object
    #: estimated contact duration in time units T, per speed
    duration: np.ndarray


@njit(cache=True)
def _rkg_state_core(xi, y, c1, c2, ah, aa, h, n):
    for _ in range(n):
        xi, y = _rkg_step(xi, y, h, c1, c2, ah, aa)
    return xi, y


def rkg_state(y0: float, c1: float, c2: float, a_hertz: float, a_adhesion: float, dtau: float,
              n_steps: int, xi0: float = 0.0) -> RkgState:
    """State (xi, y) after ``n_steps`` fixed RKG steps of length ``dtau`` from (xi0, y0). [-]

    The nondimensional Eq. (27): xi'' = -a_h xi^(3/2) (1 + C1 y) + a_a xi^(1/2) (1 - C2 y).
    Started at first contact (xi0 = 0) the solution has a (tau)^(5/2) term (Hertz) or a
    (tau)^(3/2) term (adhesion), so the global order of any fixed-step Runge-Kutta method drops
    from 4 to 2.5 (Hertz) or lower; started inside the contact it is smooth and RKG is 4th order.

    References
    ----------
    Gill (1951)

    Examples
    --------
    Undamped Hertz contact (a_h = 1, no adhesion) started inside the contact at rest: the energy
    y^2/2 + (2/5) xi^(5/2) stays at its start value 2/5 to the method's 4th-order error:

    >>> xi, y = rkg_state(0.0, 0.0, 0.0, 1.0, 0.0, 0.01, 100, xi0=1.0)
    >>> round(0.5 * y * y + 0.4 * xi ** 2.5, 9)
    0.4
    """
    return RkgState(*_rkg_state_core(float(xi0), float(y0), float(c1), float(c2), float(a_hertz),
                                     float(a_adhesion), float(dtau), int(n_steps)))


def rkg_setup(contact, speeds) -> RkgSetup:
    """Nondimensional y0, C1, C2, a_h, a_a and the estimated contact duration (tau) per speed.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (28)-(33)

    Gill (1951)

    Examples
    --------
    The paper's law in its own units has a_h = a_a = 1 (Eqs. (28)-(30)); the paper's microsphere at
    2 m/s stays in contact for about 4.4 time units T:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> y0, c1, c2, a_h, a_a, duration = rkg_setup(c, [2.0])
    >>> a_h, a_a, round(float(duration[0]), 1)
    (1.0, 1.0, 4.4)
    """
    speeds = np.atleast_1d(np.asarray(speeds, dtype=float))
    sc, y0, c1, c2 = nondimensional_impact(contact, speeds)
    y0, c1, c2, t_c = (np.ascontiguousarray(np.broadcast_to(a, speeds.shape), dtype=float)
                       for a in (y0, c1, c2, sc.time))
    # Estimated contact duration: the engine's at a loose rtol = 1e-6 (computed once, not timed);
    # 50 time units for a captured sphere.
    t_contact = engine.solve_normal_many(contact, speeds, None, rtol=1e-6)["contact_time"]
    dur = np.where(np.isfinite(t_contact), t_contact / t_c, 50.0)
    return RkgSetup(y0, c1, c2, sc.a_hertz, sc.a_adhesion, dur)


def rkg_restitution(contact, speeds, steps_per_contact: int, *, setup=None) -> SolutionBatch:
    """e_n by the fixed-step Runge-Kutta-Gill method, dtau = (estimated contact duration) / N.

    Parameters
    ----------
    contact : Contact
    speeds : array_like
        Incident normal speeds. [m/s]
    steps_per_contact : int
        N. [-]
    setup : tuple, optional
        Result of the internal set-up for these speeds (to keep it out of timings).

    Returns
    -------
    SolutionBatch
        ``e_n`` [-] (0 if captured, NaN if no outcome in 20 N steps), ``captured`` (bool) and
        ``n_steps`` (int); the other quantities are None (the benchmark times e_n alone).

    References
    ----------
    Cheng, Brach & Dunn (2002)

    Gill (1951)

    Examples
    --------
    400 steps per contact give e_n of the paper's microsphere at 2 m/s to about 1e-5 of the
    adaptive engine's (the paper's fixed-step method converges at about order 1.5 here):

    >>> from microimpact import simulate_impact
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> rkg = rkg_restitution(c, [2.0], 400)
    >>> abs(float(rkg.e_n[0]) - simulate_impact(c, 2.0).e_n) < 1e-4
    True
    """
    y0, c1, c2, ah, aa, dur = setup if setup is not None else rkg_setup(contact, speeds)
    h = dur / steps_per_contact
    max_steps = np.full(y0.shape, _MAX_CONTACTS * int(steps_per_contact), dtype=np.int64)
    out = np.empty((y0.size, _NCOL))
    _rkg_many(y0, c1, c2, ah, aa, h, max_steps, out)
    outcome = out[:, _OUTCOME]
    return SolutionBatch(
        e_n=np.where(outcome == 1, 0.0, np.where(outcome < 0, np.nan, out[:, _Y_OUT] / y0)),
        captured=outcome == 1,
        n_steps=out[:, _N_STEPS].astype(np.int64),
    )


def solve_normal_rkg(contact, normal_speed: float, *, steps: int = DEFAULT_STEPS,
                     friction_impulse_target: float | None = None) -> NormalSolution:
    """Solve the normal contact, Eq. (27), of one impact with the paper's fixed-step RKG.

    Parameters
    ----------
    contact : Contact
    normal_speed : float
        Incident normal speed, > 0. [m/s]
    steps : int
        Steps per estimated contact duration (the step size is duration / steps). [-]
    friction_impulse_target : float, optional
        Record the time at which J reaches this value (end of sliding). [N s]

    Returns
    -------
    NormalSolution
        As :func:`microimpact.solvers.engine.solve_normal`. A captured impact stops at the energy
        test (E < 0): its J and J_a cover the contact up to there only, and ``dissipated_energy``
        and ``max_penetration`` too. For a rebound the normal dissipation is m v^2 (1 - e_n^2) / 2
        (energy balance; the RKG does not integrate it).

    Raises
    ------
    ValueError
        For a bad speed or a number of steps < 1.
    EngineError
        If no outcome is reached within 20 contact durations' worth of steps.
    
    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (27) and its fixed-step Runge-Kutta-Gill solution

    Gill (1951)

    Examples
    --------
    The paper's fixed-step method against the adaptive engine at a tight tolerance:

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.solvers import engine
    >>> s = solve_normal_rkg(WALL_1990, 2.0)
    >>> bool(abs(s.e_n - engine.solve_normal(WALL_1990, 2.0, rtol=1e-12).e_n) < 1e-6)
    True
    """
    v = check_positive("normal_speed", normal_speed)
    if int(steps) < 1:
        raise ValueError(f"steps must be an integer >= 1, got {steps!r}")
    y0, c1, c2, ah, aa, dur = rkg_setup(contact, [v])
    sc, _, _, _ = nondimensional_impact(contact, v)
    j_unit = contact.mass * sc.speed  # N s
    jt = 0.0 if friction_impulse_target is None else float(friction_impulse_target) / j_unit
    r = _rkg_impact(y0[0], c1[0], c2[0], ah, aa, dur[0] / int(steps), _MAX_CONTACTS * int(steps), jt)
    if r[_OUTCOME] < 0:
        raise engine.EngineError(f"rkg found no outcome for normal speed {v!r} m/s within {int(r[_N_STEPS])} "
                                 f"steps ({_MAX_CONTACTS} estimated contact durations); increase steps")
    captured = r[_OUTCOME] == engine.CAPTURE
    y_out = r[_Y_OUT]  # exit speed, > 0
    dissipated = math.nan if captured else 0.5 * (y0[0] ** 2 - y_out**2)  # energy balance
    trace = Trace(OK, int(r[_OUTCOME]), -y_out, r[_TAU_END], dissipated, r[_J], r[_J_A], r[_XI_MAX],
                  r[_TAU_END] if captured else math.nan, r[_TAU_J], r[_E_END], int(r[_N_STEPS]), 0, 0, None, 0, 0)
    return engine.normal_solution(contact, sc, y0[0], trace)
