"""The Thornton & Ning (1998) elastic-plastic adhesive normal contact as a law of the one compiled driver.

The law's closed forms are :mod:`microimpact.model.thornton_ning` ((TN1)-(TN12)); this module
states them as a :class:`microimpact.solvers.driver.Law` and solves one undamped normal impact
with :func:`microimpact.solvers.driver.make_driver`'s ``drive`` (no loop of its own):

* **state** u = (x, y, tau, W): x = delta / L, y = dx/dtau, tau = t / (L / V_i) and W the work
  of the contact force, int F d delta / (m V_i^2); L is the larger of the undamped Hertz largest
  approach at V_i, (5 m V_i^2 / (4 K sqrt(R)))^(2/5), and the JKR length a_c^2 / R, so that x is of
  order 1 at every speed;
* **its own bookkeeping** (the driver's ``w``): the branch (elastic loading (TN1), plastic loading
  (TN3), unloading (TN6)), the radius of curvature R_b and the shift delta_p of the branch's JKR
  curve, the break approach (TN7), delta_max, the outcome and the capture time;
* **its events** within an accepted step, located on the step itself
  (:func:`microimpact.solvers.dopri.make_root_on_step`): yield (x reaches delta_y / L while
  loading: the force is continuous, its slope is not, so the step ends there), the turning point
  (y = 0: delta_max, then R_p (TN4), delta_p (TN5) and the break (TN7) of the unloading curve), the
  break (x reaches delta_break / L with y < 0: the sphere separates, e = |y|) and, on the unloading
  curve, a turning point with y rising (captured: undamped, it oscillates on (TN6) forever, never
  again reaching delta_max, as :mod:`microimpact.solvers.plastic_reference` also ends it).

The yield point (a_y, delta_y, F_y) is the model's (TN2), :func:`~microimpact.model.thornton_ning.yield_point`,
passed in the parameters: where the JKR force per contact area reaches p_y, not the paper's centre
pressure (the model module's docstring, "Yield", gives the reasons and the alternatives), so the
driver, the closed form and the scipy reference share one yield and R_p >= R on every unloading.

The formulas are the model module's compiled kernels, each written there once and called here:
the force on a JKR curve of radius R_b, :func:`~microimpact.model.thornton_ning.curve_force`
(TN1), (TN6), in q = sqrt(a / a_c): delta - delta_p = (a_c^2 / R_b) (q^4 - 4 q), solved for q >= 1
by Newton's method (:func:`~microimpact.model.thornton_ning.curve_q`); without adhesion
a = sqrt(R_b (delta - delta_p)); beyond the break (a trial stage may probe there) a = a_c. The
plastic line (TN3) is :func:`~microimpact.model.thornton_ning.plastic_force` and
:func:`~microimpact.model.thornton_ning.plastic_contact_radius`, the unloading curve (TN4)-(TN7)
:func:`~microimpact.model.thornton_ning.unloading_curve`, which
:func:`~microimpact.model.thornton_ning.unloading_state` (the solution's ``state``) also evaluates.

References
----------
Thornton, C. and Ning, Z. (1998), A theoretical model for the stick/bounce behaviour of adhesive,
elastic-plastic spheres, Powder Technol. 99:154-162, doi:10.1016/S0032-5910(98)00099-0.
Thornton, C. (1997), Coefficient of restitution for collinear collisions of elastic-perfectly
plastic spheres, J. Appl. Mech. 64:383-386, doi:10.1115/1.2787319.
"""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import NamedTuple

import numpy as np

from microimpact._numba import njit
from microimpact.model import thornton_ning as tn
from microimpact.solvers import DEFAULT_RTOL, driver, dopri
from microimpact.solvers.solution import NormalSolution

__all__ = ["LawParameters", "solve_thornton_ning", "law_parameters", "REBOUND", "CAPTURE"]

#: outcomes of one impact
REBOUND, CAPTURE = 0, 1
_N = 4  # state: x, y, tau, W
_MAX_STEPS_DEFAULT = 1_000_000
#: branches of the law (w[_W_BRANCH])
_ELASTIC, _PLASTIC, _UNLOADING = 0, 1, 2
_W_BRANCH, _W_RB, _W_DP, _W_DBREAK, _W_DMAX, _W_OUTCOME, _W_TAU_CAP, _W_RP = 0, 1, 2, 3, 4, 5, 6, 7
_W_SIZE = 8
#: the parameters tuple p: R [m], E* [Pa], w [J/m^2], p_y [Pa], a_y [m], delta_y [m], F_y [N], L [m],
#: acc = L / (m V_i^2) [1/N]
_P_R, _P_ES, _P_W, _P_PY, _P_AY, _P_DY, _P_FY, _P_L, _P_ACC = range(9)


# --------------------------------------------------------------------------- the law's force, compiled
@njit(cache=True)
def _force(x, args):
    """The contact force [N] at x = delta / L on the branch of args = (branch, R_b, delta_p, p...)."""
    branch, r_b, d_p, r, es, w, py, a_y, d_y, f_y, length = (args[0], args[1], args[2], args[3], args[4], args[5],
                                                            args[6], args[7], args[8], args[9], args[10])
    d = x * length
    if branch == _PLASTIC:
        return tn.plastic_force(d, r, py, d_y, f_y)  # (TN3)
    return tn.curve_force(d - d_p, r_b, es, w)  # (TN1), (TN6)


@njit(cache=True)
def _rhs(u, out, args):
    """d/dtau of (x, y, tau, W): y, -F acc, 1, F acc y."""
    f = _force(u[0], args) * args[11]
    out[0] = u[1]
    out[1] = -f
    out[2] = 1.0
    out[3] = f * u[1]


_step = dopri.make_step(_rhs, _N)


@njit(cache=True)
def _value(u, code, vargs):
    """Event functions on the state: 0 the approach x, 1 the rate y."""
    return u[0] if code == 0 else u[1]


_root = dopri.make_root_on_step(_step, _value)


@njit(cache=True, inline="always")
def _law_args(p, w):
    return (w[_W_BRANCH], w[_W_RB], w[_W_DP], p[_P_R], p[_P_ES], p[_P_W], p[_P_PY], p[_P_AY], p[_P_DY], p[_P_FY],
            p[_P_L], p[_P_ACC])


@njit(cache=True)
def _law_start(p, rtol, rec, rec_cap):
    """First contact: x = 0, y = 1 on the elastic loading curve of radius R."""
    w = np.zeros(_W_SIZE)
    w[_W_BRANCH], w[_W_RB], w[_W_DP], w[_W_OUTCOME], w[_W_TAU_CAP], w[_W_RP] = _ELASTIC, p[_P_R], 0.0, REBOUND, math.nan, p[_P_R]
    u = np.array([0.0, 1.0, 0.0, 0.0])
    k1 = np.zeros(_N)
    _rhs(u, k1, _law_args(p, w))
    return u, k1, 1e-3, np.full(_N, 1e-3 * rtol), w


@njit(cache=True)
def _law_too_small(h, u):
    return h < 1e-14 * max(1.0, abs(u[2]))


@njit(cache=True)
def _unloading(p, w, d_max):
    """The unloading curve from delta_max, (TN4)-(TN7), into w: R_p, delta_p, the break."""
    r, es, wa, py, a_y, d_y, f_y = p[_P_R], p[_P_ES], p[_P_W], p[_P_PY], p[_P_AY], p[_P_DY], p[_P_FY]
    yielded = d_max > d_y
    a_max, f_max = 0.0, 0.0  # not read below yield
    if yielded:
        a_max = tn.plastic_contact_radius(d_max, r, a_y, d_y)  # (TN3)
        f_max = tn.plastic_force(d_max, r, py, d_y, f_y)
    r_p, d_p, _, d_break = tn.unloading_curve(d_max, a_max, a_max**3, f_max, yielded, r, es, wa)
    w[_W_BRANCH], w[_W_RB], w[_W_DP], w[_W_DBREAK], w[_W_DMAX], w[_W_RP] = _UNLOADING, r_p, d_p, d_break, d_max, r_p


@njit(cache=True)
def _switch(u, k1, p, w):
    """The state at an event becomes the start of the next step, k1 on the (new) branch."""
    _rhs(u, k1, _law_args(p, w))


@njit(cache=True)
def _law_events(u, u1, k1, h, p, w, atol, rtol, k, tmp, err, rec, rec_cap):
    """Yield, the turning point, the break and the capture within the accepted step u -> u1."""
    branch = int(w[_W_BRANCH])
    args = _law_args(p, w)
    length = p[_P_L]
    if branch != _UNLOADING:
        x_y = p[_P_DY] / length
        hs = h
        turned = u[1] > 0.0 and u1[1] <= 0.0
        if turned:
            hs = _root(1, 0.0, u[1], u1[1], 0.0, h, u, k1, args, args, k, tmp, u1, err)
        if branch == _ELASTIC and u1[0] > x_y:  # it yielded before it turned: end the step at yield
            _root(0, x_y, u[0] - x_y, u1[0] - x_y, 0.0, hs, u, k1, args, args, k, tmp, u1, err)
            u[:] = u1
            w[_W_BRANCH] = _PLASTIC
            _switch(u, k1, p, w)
            return driver.GO_ON
        u[:] = u1
        if turned:
            u[1] = 0.0  # the turning point itself (the root is zero to round-off)
            _unloading(p, w, u[0] * length)
            _switch(u, k1, p, w)
        else:
            k1[:] = k[6]
        return driver.GO_ON
    x_b = w[_W_DBREAK] / length
    hs = h
    rising = u[1] < 0.0 and u1[1] >= 0.0
    if rising:  # turned back on the unloading curve: captured, unless it passed the break first
        hs = _root(1, 0.0, u[1], u1[1], 0.0, h, u, k1, args, args, k, tmp, u1, err)
    if u1[0] <= x_b and u[0] > x_b:
        _root(0, x_b, u[0] - x_b, u1[0] - x_b, 0.0, hs, u, k1, args, args, k, tmp, u1, err)
        u[:] = u1
        return driver.END
    u[:] = u1
    k1[:] = k[6]
    if rising:
        w[_W_OUTCOME], w[_W_TAU_CAP] = CAPTURE, u[2]
        return driver.END
    return driver.GO_ON


@njit(cache=True)
def _law_creep(u, k1, p, w, atol, rec, rec_cap):
    return driver.CREEP_NONE  # undamped: no inertia-free limit


@njit(cache=True)
def _law_captured_end(u, k1, p, w, atol, long_tail):
    return False  # a capture ends in the events


@njit(cache=True)
def _law_finish(status, u, p, w, n_steps, n_rej):
    """The driver's Trace: the rate and time at the end, delta_max [m] as max_approach, the work W as
    the final energy; R_p is read from the state's bookkeeping by :func:`_integrate`."""
    return driver.Trace(status, int(w[_W_OUTCOME]), u[1], u[2], 0.0, 0.0, 0.0, w[_W_DMAX], w[_W_TAU_CAP], math.nan,
                        u[3], n_steps, n_rej, 0, u, 0, 0)


_drive = driver.make_driver(driver.Law(_law_start, _law_args, _step, _law_too_small, driver.make_error_norm(_N),
                                       _law_events, _law_creep, _law_captured_end, _law_finish, _N))
_NO_RECORD = np.zeros((1, 3))


@njit(cache=True)
def _integrate(p, rtol, max_steps):
    """One impact by the one driver: its :class:`~microimpact.solvers.driver.Trace`. Called from Python
    through this module-level function, not as ``_drive``: numba's cache keys a closure such as
    ``_drive`` by its pickled contents, which differ between processes, so ``_drive`` called
    directly would be compiled again in every process; compiled into this function it is cached."""
    return _drive(p, rtol, max_steps, _NO_RECORD, 0)


# --------------------------------------------------------------------------- Python interface
class LawParameters(NamedTuple):
    """The parameters of one impact for the compiled driver (:func:`law_parameters`)."""

    #: the driver's positional parameter tuple p (SI; the module docstring), read inside compiled code
    p: tuple
    #: the length unit L of the impact [m]
    length: float


def law_parameters(pc: tn.PlasticContact, normal_speed: float) -> LawParameters:
    """The law's parameters tuple p of one impact (SI; see the module docstring) and its length L [m].

    Examples
    --------
    >>> pc = tn.PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> p, length = law_parameters(pc, 1.0)
    >>> len(p), round(length / (1.25e-14 / (4e9 / 3 * 1e-3)) ** 0.4, 12)
    (9, 1.0)
    """
    v = float(normal_speed)
    y = tn.yield_point(pc)
    hertz = (1.25 * pc.mass * v * v / (pc.stiffness * math.sqrt(pc.radius))) ** 0.4
    jkr = (math.pi * pc.work_of_adhesion * pc.radius**2 / (8.0 * pc.e_star)) ** (2.0 / 3.0) / pc.radius
    length = max(hertz, jkr)
    p = (pc.radius, pc.e_star, pc.work_of_adhesion, pc.yield_pressure, y.contact_radius, y.approach, y.force,
         length, length / (pc.mass * v * v))
    return LawParameters(tuple(float(x) for x in p), length)


def solve_thornton_ning(pc: tn.PlasticContact, normal_speed: float, *, rtol: float = DEFAULT_RTOL,
                        max_steps: int = _MAX_STEPS_DEFAULT) -> NormalSolution:
    """One undamped normal impact under the Thornton & Ning (1998) law, by the compiled driver.

    Parameters
    ----------
    pc : PlasticContact
        The contact (R, m, K, w, p_y).
    normal_speed : float
        Incident normal speed V_i > 0. [m/s]
    rtol : float
        Relative tolerance of the driver (absolute: 1e-3 rtol of the nondimensional state). [-]
    max_steps : int
        Budget of accepted and rejected steps.

    Returns
    -------
    NormalSolution
        ``e_n`` the restitution |delta'| / V_i at the break (0 if captured, NaN if the driver
        stopped at its budget, which ``stop_reason`` says); ``max_penetration`` delta_max;
        ``capture_time`` the time of the turning point on the unloading curve at which a captured
        sphere is recognised; ``dissipated_energy`` the work of the contact force over the contact,
        int F d delta = the kinetic energy lost (plastic work plus adhesive hysteresis; NaN if
        captured: undamped, a captured sphere keeps its energy in the contact);
        ``final_energy`` the kinetic energy at the end; J and J_a are not integrated (NaN).
        ``state``: the plastic state of the unloading curve, the fields of
        :class:`~microimpact.model.thornton_ning.UnloadingState` (``plastic_radius`` R_p [m],
        ``plastic_approach`` delta_p [m], ``break_approach`` [m], ``yielded``, ...), and ``work``,
        int F d delta from first contact to the end [J].

    Raises
    ------
    ValueError
        If ``normal_speed`` is not a finite number > 0 or ``rtol`` not in (0, 1).

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162; Thornton (1997), J. Appl. Mech. 64:383.

    Examples
    --------
    Without adhesion, Thornton's (1997) closed form (TN12) at V_i = 4 V_y:

    >>> pc = tn.PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> r = solve_thornton_ning(pc, 4 * tn.yield_velocity(pc), rtol=1e-11)
    >>> r.stop_reason, r.state["yielded"], round(r.e_n, 8), round(float(tn.thornton_restitution(0.25)), 8)
    ('separation', True, 0.81227887, 0.81227887)
    """
    v = float(normal_speed)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"solve_thornton_ning: normal_speed must be a finite number > 0, got {normal_speed!r}")
    if not (0.0 < rtol < 1.0):
        raise ValueError(f"solve_thornton_ning: rtol must be in (0, 1), got {rtol!r}")
    p, length = law_parameters(pc, v)
    r = _integrate(p, float(rtol), int(max_steps))
    return _solution(pc, v, length, r)


def _solution(pc: tn.PlasticContact, v: float, length: float, r) -> NormalSolution:
    """The NormalSolution (SI) of the driver's Trace ``r`` of one impact at ``v`` [m/s], length unit L [m]."""
    captured = bool(r.outcome == CAPTURE)
    ok = r.status == driver.OK
    rebound = 0.0 if captured or not ok else abs(float(r.y_end)) * v
    d_max = float(r.max_approach)
    work = float(r.final_energy) * pc.mass * v * v
    state = asdict(tn.unloading_state(pc, d_max)) if d_max > 0.0 else {}
    return NormalSolution(
        outcome="capture" if captured else "rebound", e_n=rebound / v if ok else math.nan,
        contact_time=math.inf if captured else float(r.tau_end) * length / v,
        capture_time=float(r.tau_capture) * length / v, max_penetration=d_max,
        friction_impulse=math.nan, twist_impulse=math.nan,
        dissipated_energy=math.nan if captured else work, final_energy=0.5 * pc.mass * v * v - work,
        slip_end_time=math.nan, n_steps=int(r.n_steps), n_rejected=int(r.n_rejected),
        stop_reason=driver.stop_reason(r.status, captured), state={**state, "work": work})
