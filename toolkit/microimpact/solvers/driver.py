"""The one compiled driver of the adaptive normal solvers: a contact law plugs in, the driver runs it.

The paper's ring law (:mod:`.engine`) and the JKR, DMT and Hertz-with-DEM-damping laws
(:mod:`microimpact.solvers.normal_models`) are integrated by one loop, :func:`make_driver`'s ``drive``. The split
follows PyBaMM's of model, solver and solution [1]_:

* **the law** (a :class:`Law` of compiled functions) states its right-hand side (through its
  Dormand-Prince step, :func:`microimpact.solvers.dopri.make_step`), its state at first contact
  and its absolute tolerances, its own bookkeeping (an array ``w``: the largest penetration, the
  impulses not carried as states, whether it turned or was captured), its events within a step
  (separation, turning point, capture, the end of sliding, the kinks of |F_n|), its inertia-free
  creep and the test that a captured sphere may stop, and what its solution is made of;
* **the driver** owns the stepping, the error control (the root-mean-square error norm and the
  step-size control of :mod:`.dopri`), the step budget and the step-size floor, the order in which a
  law's events, its creep and its captured end are asked for at each accepted step, the budget
  after which a long captured tail is closed, and the closed-form tails every law shares: the
  linear damped tail (:func:`linear_tail_variation`) and the method of averaging [2]_
  (:func:`make_averaged_tail`), which a law plugs its per-cycle orbit integrals into;
* **the solution** is one record, :class:`Trace`, nondimensional, which each solver turns into
  its SI :class:`~microimpact.solvers.solution.NormalSolution` at its Python boundary.

A law is plugged in by a factory (a closure over its compiled functions), as
:func:`microimpact.solvers.dopri.make_step` plugs in a right-hand side: numba compiles one driver per
law, in which LLVM inlines the law's functions, and caches it keyed by the closure's contents (a
compiled function passed as an argument would not be cached). The scipy reference solvers and the
paper's Runge-Kutta-Gill integrator (:mod:`.rkg`) stay outside, on purpose: a yardstick does not
share the code it checks.

References
----------
.. [1] Sulzer, V., Marquis, S. G., Timms, R., Robinson, M. & Chapman, S. J. (2021). Python Battery
   Mathematical Modelling (PyBaMM). J. Open Res. Softw. 9, 14, doi:10.5334/jors.309.
.. [2] Sanders, J. A., Verhulst, F. & Murdock, J. (2007). Averaging Methods in Nonlinear Dynamical
   Systems, 2nd ed., Springer (first-order averaging of a weakly damped oscillator).
"""

from __future__ import annotations

import collections
import math

import numpy as np

from microimpact._numba import njit
from microimpact.solvers import dopri

__all__ = ["Law", "Trace", "make_driver", "stop_reason", "write_common_row", "make_error_norm", "make_averaged_tail", "linear_tail_variation", "OK", "MAX_STEPS",
           "STEP_UNDERFLOW", "GO_ON", "END", "END_UNCOUNTED", "CREEP_NONE", "CREEP_RESUME", "CREEP_END"]

#: status of a solve: finished, step budget spent, step size below the law's floor
OK, MAX_STEPS, STEP_UNDERFLOW = 0, 1, 2
#: what a law's events say of an accepted step: go on, the impact ended with this step, or it ended
#: before the step counts (the undamped ring law, completed by symmetry at its turning point)
GO_ON, END, END_UNCOUNTED = 0, 1, 2
#: what a law's creep says: nothing, the integration resumes from a new state, the impact ended
CREEP_NONE, CREEP_RESUME, CREEP_END = 0, 1, 2

#: The compiled functions of a contact law that the driver runs (see the module docstring):
#:
#: * ``start(p, rtol, rec, rec_cap) -> (u, k1, h, atol, w)``: the state at first contact, its
#:   derivative, the first step, the absolute tolerances and the law's bookkeeping array;
#: * ``args(p, w) -> tuple``: the arguments of the law's right-hand side at this step;
#: * ``step``: the law's Dormand-Prince step (:func:`microimpact.solvers.dopri.make_step`);
#: * ``step_too_small(h, u) -> bool``: the step-size floor;
#: * ``norm(u, u1, k1, h, p, w, atol, rtol, k, tmp, err) -> float``: the error norm of the trial
#:   step u -> u1, at most 1 to accept it (:func:`error_norm` for most laws; a law whose step ends
#:   at an event, as the coupled law's at a change of slip, ends it here);
#: * ``events(u, u1, k1, h, p, w, atol, rtol, k, tmp, err, rec, rec_cap) -> GO_ON | END | END_UNCOUNTED``: the
#:   events within the accepted step u -> u1 located, and the state advanced (u, k1 at its end);
#: * ``creep(u, k1, p, w, atol, rec, rec_cap) -> CREEP_NONE | CREEP_RESUME | CREEP_END``: the inertia-free limit;
#: * ``captured_end(u, k1, p, w, atol, long_tail) -> bool``: whether a captured sphere may stop
#:   (``long_tail``: a twentieth of the step budget is spent);
#: * ``finish(status, u, p, w, n_steps, n_rejected) -> Trace``;
#: * ``n``: the number of states (a compile-time constant of the error norm).
Law = collections.namedtuple("Law", "start args step step_too_small norm events creep captured_end finish n")

#: The nondimensional solution of one impact, in the units of its law: status (OK, MAX_STEPS,
#: STEP_UNDERFLOW); outcome (the solver's REBOUND or CAPTURE); the rate and time at the end;
#: the damping dissipation; the friction and twist impulses J = int |F_n| dt and int a |F_n| dt;
#: the largest approach (xi for the ring law, the law's z for the others); the capture time and
#: the time at which J reached its target (NaN where not); the contact energy at the end; the
#: accepted and rejected steps and the rows of the recorded trajectory; the whole state at the end;
#: the turning points of a hysteretic tangential law and the rolling stops after a capture (0 for
#: the normal laws).
Trace = collections.namedtuple("Trace", "status outcome y_end tau_end dissipated friction_impulse twist_impulse "
                                        "max_approach tau_capture tau_slip_end final_energy n_steps n_rejected "
                                        "n_recorded state turning_points held_rolling_stops")


def stop_reason(status, captured: bool, followed: bool = False) -> str:
    """Why a solve of the driver stopped, as :class:`~microimpact.solvers.solution.NormalSolution`
    says it: its budget ("max_steps", "step_underflow"), else "separation", "capture" (at the
    capture test) or "settled" (a captured sphere ``followed`` past it).

    Examples
    --------
    >>> stop_reason(OK, False), stop_reason(OK, True), stop_reason(OK, True, True), stop_reason(MAX_STEPS, True)
    ('separation', 'capture', 'settled', 'max_steps')
    """
    if int(status) != OK:
        return "max_steps" if int(status) == MAX_STEPS else "step_underflow"
    if not captured:
        return "separation"
    return "settled" if followed else "capture"


def make_driver(law):
    """The compiled driver of one contact law.

    Parameters
    ----------
    law : Law
        The law's compiled functions (see :data:`Law`).

    Returns
    -------
    drive : numba-compiled function
        ``drive(p, rtol, max_steps, rec, rec_cap) -> Trace``: one impact of the law with
        parameters ``p`` (a tuple, the law's), relative tolerance ``rtol`` and at most
        ``max_steps`` accepted and rejected steps; ``rec`` (rows (tau, s, y), capacity
        ``rec_cap``) receives the trajectory where the law records one.

    Notes
    -----
    At each step: the step, its error norm; a rejected step is retried shorter (the status is
    STEP_UNDERFLOW below the law's floor); at an accepted step the law locates its events and
    advances, then may creep along its inertia-free path, and a captured sphere may stop (after a
    twentieth of the budget with a closed-form tail). The step then grows by the error norm.

    Examples
    --------
    The Thornton & Ning law (:mod:`microimpact.solvers.thornton_ning_law`) plugs in as a
    :class:`Law` of its compiled functions and the driver's error norm of its 4 states:

    >>> from microimpact.model import thornton_ning as tn
    >>> from microimpact.solvers import thornton_ning_law as tnl
    >>> law = Law(tnl._law_start, tnl._law_args, tnl._step, tnl._law_too_small, make_error_norm(4), tnl._law_events,
    ...           tnl._law_creep, tnl._law_captured_end, tnl._law_finish, 4)
    >>> law.n, tnl._drive.py_func.__qualname__
    (4, 'make_driver.<locals>.drive')

    Its module runs ``make_driver(law)`` once, through a cached module-level function (a driver
    compiled in a doctest could not be cached, so this example runs the module's). Without adhesion
    its rebound is Thornton's (1997) closed form, at V_i = 4 V_y:

    >>> pc = tn.PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> p, length = tnl.law_parameters(pc, 4 * tn.yield_velocity(pc))
    >>> r = tnl._integrate(p, 1e-11, 100_000)
    >>> r.status == OK, r.outcome == tnl.REBOUND, round(-float(r.y_end), 8), round(float(tn.thornton_restitution(0.25)), 8)
    (True, True, 0.81227887, 0.81227887)
    """
    start, args_of, step, too_small, error_norm = law.start, law.args, law.step, law.step_too_small, law.norm
    events, creep, captured_end, finish, n = law.events, law.creep, law.captured_end, law.finish, law.n

    @njit(cache=True)
    def drive(p, rtol, max_steps, rec, rec_cap):
        u, k1, h, atol, w = start(p, rtol, rec, rec_cap)
        k = np.zeros((7, n))
        tmp = np.zeros(n)
        u1 = np.zeros(n)
        err = np.zeros(n)
        status, n_acc, n_rej = OK, 0, 0
        while True:
            if n_acc + n_rej >= max_steps:
                status = MAX_STEPS
                break
            step(u, k1, h, args_of(p, w), k, tmp, u1, err)
            norm = error_norm(u, u1, k1, h, p, w, atol, rtol, k, tmp, err)
            if not norm <= 1.0:  # (a NaN norm, from an overflowing trial step, is a rejection too)
                n_rej += 1
                h = dopri.shrunk_step(h, norm)
                if too_small(h, u):
                    status = STEP_UNDERFLOW
                    break
                continue
            ended = events(u, u1, k1, h, p, w, atol, rtol, k, tmp, err, rec, rec_cap)
            if ended == END_UNCOUNTED:
                break
            n_acc += 1
            if ended == END:
                break
            action = creep(u, k1, p, w, atol, rec, rec_cap)
            if action == CREEP_RESUME:  # the step size is kept
                continue
            if action == CREEP_END:
                break
            if captured_end(u, k1, p, w, atol, 20 * (n_acc + n_rej) >= max_steps):
                break
            h = dopri.grown_step(h, norm)
        return finish(status, u, p, w, n_acc, n_rej)

    return drive


@njit(cache=True, inline="always")
def write_common_row(r, out, i):
    """Write the fields every normal law's batch row starts with into ``out[i, 0:9]``: status,
    outcome, y_end, tau_end, dissipated, friction_impulse, twist_impulse, max_approach,
    tau_capture of the :class:`Trace` ``r`` (the columns after them differ by law).

    Examples
    --------
    >>> import numpy as np
    >>> r = Trace(0, 1, -0.5, 2.0, 0.1, 0.3, 0.0, 1.2, np.nan, np.nan, 0.0, 10, 1, 0, np.zeros(1), 0, 0)
    >>> out = np.zeros((1, 9))
    >>> write_common_row(r, out, 0)
    >>> out[0, :4].tolist()
    [0.0, 1.0, -0.5, 2.0]
    """
    out[i, 0] = r.status
    out[i, 1] = r.outcome
    out[i, 2] = r.y_end
    out[i, 3] = r.tau_end
    out[i, 4] = r.dissipated
    out[i, 5] = r.friction_impulse
    out[i, 6] = r.twist_impulse
    out[i, 7] = r.max_approach
    out[i, 8] = r.tau_capture


def make_error_norm(n):
    """The driver's ``norm`` of a law of n states that ends no step inside its norm: the
    root-mean-square scaled error of :func:`microimpact.solvers.dopri.error_norm`.

    Examples
    --------
    >>> import numpy as np
    >>> norm = make_error_norm(2)
    >>> u = np.ones(2)
    >>> float(norm(u, u, u, 0.1, (), u, np.zeros(2), 1e-6, None, None, np.array([1e-6, 1e-6])))
    1.0
    """

    @njit(cache=True, inline="always")
    def norm(u, u1, k1, h, p, w, atol, rtol, k, tmp, err):
        return dopri.error_norm(u, u1, err, atol, rtol, n)

    return norm


# --------------------------------------------------------------------------- the shared closed-form tails
@njit(cache=True)
def linear_tail_variation(dx, y, omega0, c):
    """Total variation of y from now to rest for dx'' = -omega0^2 dx - c dx' (dx' = y): the friction
    impulse still to come of a captured sphere in the linear regime about its equilibrium. [-]

    Examples
    --------
    Overdamped from rest at dx = 1 (c = 10, omega0 = 1): y falls monotonically after one extremum,
    so the variation is twice that extremum; undamped the variation never ends:

    >>> v = linear_tail_variation(1.0, 0.0, 1.0, 10.0)
    >>> 0.0 < v < 2.0 / 10.0 * 1.1
    True
    """
    yp = -omega0 * omega0 * dx - c * y
    a = 0.5 * c
    if a < omega0 * (1.0 - 1e-9):
        wd = math.sqrt(omega0 * omega0 - a * a)
        b = (yp + a * y) / wd
        # y' = e^{-a tau} (P cos + Q sin), extrema of y every pi/wd from the first, theta1
        pc = yp
        qs = -a * b - wd * y
        th = math.atan2(qs, pc) + 0.5 * math.pi
        while th < 0.0:
            th += math.pi
        while th >= math.pi:
            th -= math.pi
        y1 = math.exp(-a * th / wd) * (y * math.cos(th) + b * math.sin(th))
        q = math.exp(-a * math.pi / wd)  # ratio of successive |extrema|
        return abs(y1 - y) + abs(y1) * (1.0 + q) / (1.0 - q)
    disc = math.sqrt(max(a * a - omega0 * omega0, 0.0)) + 1e-9 * omega0
    l1 = -a + disc
    l2 = -a - disc
    ca = (yp - l2 * y) / (l1 - l2)
    cb = y - ca
    if ca != 0.0:
        ratio = -cb * l2 / (ca * l1)
        if ratio > 1.0:  # one extremum ahead, then monotone to rest
            t1 = math.log(ratio) / (l1 - l2)
            y1 = ca * math.exp(l1 * t1) + cb * math.exp(l2 * t1)
            return abs(y1 - y) + abs(y1)
    return abs(y)


_GL16_X, _GL16_W = np.polynomial.legendre.leggauss(16)


def make_averaged_tail(orbit_integrals):
    """The method of averaging (Sanders, Verhulst & Murdock 2007) for the captured tail of a law, from its per-cycle orbit integrals.

    Parameters
    ----------
    orbit_integrals : numba-compiled function
        ``orbit_integrals(e, oargs) -> (loss, variation, twist)``: per cycle of the undamped orbit
        at energy e in the law's well, the energy the damping removes, the total variation of the
        rate y and int a |dy|.

    Returns
    -------
    averaged_tail : numba-compiled function
        ``averaged_tail(e_now, e_bottom, oargs) -> (J, J_a)``: the friction and twist impulses
        still to come of a weakly damped captured sphere of energy ``e_now`` in a well whose bottom
        is ``e_bottom``: int (variation per cycle) / (energy lost per cycle) de from the bottom to
        e_now, in q = sqrt(e - e_bottom), where the integrand is smooth (16-point Gauss-Legendre).
        Relative error of the order of the damping ratio C / omega0 (the change of the orbit within
        one cycle).

    Examples
    --------
    A linear oscillator of unit frequency with a damping rate c: per cycle of amplitude A it loses
    pi c A^2 and y varies by 4 A, so from the energy A^2/2 the variation still to come is
    4 A / (pi c), which the quadrature recovers (its integrand is constant in q):

    >>> import math
    >>> from microimpact._numba import njit
    >>> @njit
    ... def oscillator(e, oargs):
    ...     amplitude = math.sqrt(2.0 * e)
    ...     return math.pi * oargs[0] * amplitude**2, 4.0 * amplitude, 0.0
    >>> tail = make_averaged_tail(oscillator)
    >>> j, _ = tail(0.5, 0.0, (1e-3,))
    >>> round(float(j) / (4.0 / (math.pi * 1e-3)), 12)
    1.0
    """

    @njit(cache=True)
    def averaged_tail(e_now, e_bottom, oargs):
        q_now = math.sqrt(max(e_now - e_bottom, 0.0))
        jt = 0.0
        jat = 0.0
        if q_now == 0.0:
            return jt, jat
        for i in range(_GL16_X.shape[0]):
            q = 0.5 * q_now * (_GL16_X[i] + 1.0)
            loss, var, tw = orbit_integrals(e_bottom + q * q, oargs)
            w = 0.5 * q_now * _GL16_W[i] * 2.0 * q / loss
            jt += w * var
            jat += w * tw
        return jt, jat

    return averaged_tail
