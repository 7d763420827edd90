"""Fast impact engine: a compiled solver of the normal contact, Eq. (27), with events.

Why this is cheap (see the decoupling section of the model notes, verified in the tests against the
full 3-D reference solver):

* the normal motion does not depend on the tangential or rotational state, so one 1-D solve per
  normal speed serves every incidence angle, azimuth, spin and friction coefficient;
* the tangential and rotational outcome depends on the normal solve only through two integrals,
  J = int |F_n| dt and J_a = int a |F_n| dt (see :mod:`microimpact.model.tangential`);
* the contact energy E = m x'^2/2 + V(x) never increases, so E < 0 is an exact capture test.

Numerical formulation
---------------------
Nondimensional penetration xi = x / X and time tau = t / T (Eqs. (28)-(30), T corrected), so that
xi'' = -a_h xi^(3/2) (1 + C1 y) + a_a xi^(1/2) (1 - C2 y), y = xi'. With adhesion (f0 > 0) the
paper's scales give a_h = a_a = 1. Without adhesion X = 0 and the Hertz impact scales
x* = (5 m v^2 / (4 K sqrt r))^(2/5), t* = x*/v are used instead (a_h = 5/4, a_a = 0). The law, its
energy, its dissipation and these scales are those of :mod:`microimpact.model.law`, compiled by
:mod:`microimpact.solvers.compiled_law`.

The xi^(1/2) terms make the force non-smooth in tau where contact starts and ends, which costs
adaptive solvers order and steps there. With s = sqrt(xi) and the Sundman-type time change
d tau = s d sigma the system becomes polynomial, hence smooth everywhere, including s = 0:

    ds/dsigma = y / 2,   dy/dsigma = a_a s^2 (1 - C2 y) - a_h s^4 (1 + C1 y),   dtau/dsigma = s.

Separation is the simple root s = 0 (with y < 0). The friction impulse J is the total variation
of y, because the nondimensional normal force is -dy/dtau: it is summed exactly over the monotone
pieces of y, whose ends (the zeros of dy/dsigma) are located as events. J_a and the damping
dissipation D are integrated as extra states. Integration is Dormand-Prince 5(4) (the one core of the
compiled solvers, :mod:`.dopri`, run by their one driver, :mod:`.driver`, into which this law plugs its
events, its inertia-free limit and its captured end) with error control
on all states; events are located by re-stepping from the start of the step (Illinois method), so
their accuracy is that of the integrator.

Regimes left to closed forms instead of a step limit
----------------------------------------------------
* **Inertia-free (overdamped) limit.** When the damping force dwarfs inertia (inertia ratio
  |y_m'| / damping below :data:`INERTIA_FREE_ENTER` = 1e-6), relaxes the motion much faster than
  the sphere crosses the contact (relaxation ratio above :data:`RELAXATION_ENTER` = 1e3) and the
  state lies on the slow manifold
  y_m(xi) = (a_a - a_h xi) / (a_h C1 xi + a_a C2) (where xi'' = 0), Eq. (27) reduces to
  xi' = y_m(xi), whose time, friction impulse (|dy| is monotone) and twist impulse are closed forms
  or quadratures. With adhesion the sphere creeps into the equilibrium xi_e = a_a / a_h: a capture
  (if a ratio would leave :data:`INERTIA_FREE_RESUME` = 1e-4 or :data:`RELAXATION_RESUME` = 100 on
  the way, the engine jumps to
  that point and resumes explicit integration there, starting on the manifold with its first
  inertia correction). Without adhesion y_m = -1/C1 is an exact invariant line, so the sphere leaves
  at x' = -1/C_H (e_n = 1/(C_H v_n)). The energy the jump skips is booked as dissipated. An explicit
  solver needs ~(damping rate x duration) steps there: 2e6 steps were not enough at zeta = 1e6.
* **Weakly damped captured tails.** A captured sphere with C / omega0 <= 1e-2 whose oscillation is
  still too large for the linear tail after a twentieth of the step budget gets its remaining
  friction and twist impulses by the method of averaging (:func:`_averaged_tail`: per-cycle
  integrals of the undamped orbit; relative error ~C / omega0, measured 1e-4 at C = 6e-4).
* **Very fast adhesive impacts** (y0 > :data:`MAX_ADHESIVE_SPEED`) are solved in the Hertz impact
  scales, with adhesion as the small coefficient a_a (:func:`engine_scales`).
* A result whose SI units overflow raises :class:`microimpact.solvers.ModelDomainError`.
"""

from __future__ import annotations

import math
import os
from typing import NamedTuple

import numpy as np
from numba import prange, set_num_threads

from microimpact._numba import njit, njit_batch
from microimpact.model.contact import check_positive
from microimpact.solvers import DEFAULT_RTOL, ModelDomainError, SolverError
from microimpact.model.law import Scales, hertz_impact_scales, nondimensional_impact, nondimensional_scales  # nondimensional_scales: re-exported
from microimpact.solvers import compiled_law as law
from microimpact.solvers import dopri, driver
from microimpact.solvers.dopri import hermite, illinois_point, illinois_update
from microimpact.solvers.solution import NormalSolution, SolutionBatch

__all__ = ["EngineError", "EngineScales", "engine_scales", "MAX_ADHESIVE_SPEED", "solve_normal", "solve_normal_many", "normal_solution", "nondimensional_scales"]

# Status codes of the compiled core
_OK = 0
_MAX_STEPS = 1
_STEP_UNDERFLOW = 2

# Outcome codes
REBOUND = 0
CAPTURE = 1
OUTCOME_NAMES = ("rebound", "capture")

_NSTATE = 5  # s, y, tau, D, J_a

# Events located within a step (:func:`_locate`): s = 0, y = target, dy/dsigma = 0 (an extremum of y),
# energy = target; and of the inertia-free path (:func:`_slow_event_time`): energy or y = target.
# numpy integers, not int literals: numba compiles one specialization of a callee per literal
# argument (the four codes would cost four compiles of _locate).
_EV_S, _EV_Y, _EV_DY, _EV_ENERGY = np.int64(0), np.int64(1), np.int64(2), np.int64(3)
_SLOW_ENERGY, _SLOW_Y = np.int64(0), np.int64(1)
_MAX_STEPS_DEFAULT = 2_000_000

#: Smallest nondimensional incident speed y0 = v_n T / X (adhesive contact) the engine resolves.
#: Below about 1e-39 the incident energy y0^2 / 2 is lost in round-off against the contact well
#: (depth 4/15) and the Sundman-time integration from s = 0 returns wrong outcomes (negative e_n
#: was seen at 1e-60); 1e-30 keeps nine decades of margin. Physically such a sphere is captured
#: whenever there is any damping.
MIN_NONDIMENSIONAL_SPEED = 1e-30


#: Largest nondimensional incident speed y0 = v_n T / X (adhesive contact) integrated in the paper's
#: scales X, T. Beyond it the penetration reaches ~y0^(4/5) X and its powers approach the
#: floating-point range (at y0 ~ 1e148, a density of 1e300 kg/m^3, the states overflowed): the
#: engine then integrates in the Hertz impact scales x*, t* = x*/v, where adhesion enters as the small
#: coefficient a_a = (5/4) X / x* (:func:`engine_scales`). Both forms are the same Eq. (27); the
#: switch point lies far above the stress domain (y0 <= ~1e10), so its results do not move.
MAX_ADHESIVE_SPEED = 1e12


class EngineScales(NamedTuple):
    """The scales of the engine's solve of one impact (or per element, of arrays), :func:`engine_scales`."""

    #: the units and coefficients a_h, a_a of Eq. (27)
    scales: Scales
    #: the incident speed in the unit X / T [-]
    y0: object
    #: the damping coefficients C1, C2 of Eq. (27) [-]
    c1: object
    c2: object


def engine_scales(contact, normal_speed) -> EngineScales:
    """Scales of the engine's solve of each impact: (Scales, y0, C1, C2), per element for arrays.

    :func:`microimpact.model.law.nondimensional_impact`, except that an adhesive impact with
    y0 > :data:`MAX_ADHESIVE_SPEED` uses the Hertz impact scales (a_h = 5/4, a_a = (5/4) X / x*).

    Parameters
    ----------
    contact : Contact
    normal_speed : float or ndarray
        Incident normal speed, > 0. [m/s]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (28)-(32)

    Examples
    --------
    The paper's scales: a_h = a_a = 1, and y0 the incident speed in the unit X/T:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> sc, y0, c1, c2 = engine_scales(c, 2.0)
    >>> (sc.a_hertz, sc.a_adhesion), round(y0, 4), y0 == 2.0 / sc.speed
    ((1.0, 1.0), 1.5875, True)
    """
    sc, y0, c1, c2 = nondimensional_impact(contact, normal_speed)
    if type(y0) is float and (y0 <= MAX_ADHESIVE_SPEED or not sc.a_adhesion > 0.0):
        return EngineScales(sc, y0, c1, c2)  # one impact in the paper's scales: the common case, without numpy
    if not (sc.a_adhesion > 0.0 and np.any(np.asarray(y0) > MAX_ADHESIVE_SPEED)):
        return EngineScales(sc, y0, c1, c2)
    v = np.asarray(normal_speed, dtype=float)
    shape = np.broadcast(v, y0).shape
    big = np.broadcast_to(np.asarray(y0) > MAX_ADHESIVE_SPEED, shape)
    length, time, ah, aa, y0, c1, c2 = (np.array(np.broadcast_to(a, shape), dtype=float)
                                        for a in (sc.length, sc.time, sc.a_hertz, sc.a_adhesion, y0, c1, c2))
    vb = np.broadcast_to(v, shape)[big]
    xs, ts = hertz_impact_scales(contact.mass, contact.stiffness, contact.radius, vb)
    c_h, c_a = contact.damping_coefficients(vb)
    length[big], time[big], ah[big], aa[big] = xs, ts, 1.25, 1.25 * contact.length_scale / xs
    y0[big], c1[big], c2[big] = 1.0, c_h * vb, c_a * vb
    if not shape:
        return EngineScales(Scales(float(length), float(time), float(ah), float(aa)), float(y0), float(c1), float(c2))
    return EngineScales(Scales(length, time, ah, aa), y0, c1, c2)


def _check_resolvable(y0, adhesive: bool, normal_speed) -> None:
    """ValueError for incident speeds below :data:`MIN_NONDIMENSIONAL_SPEED` (adhesive contacts)."""
    if isinstance(y0, float) and (y0 >= MIN_NONDIMENSIONAL_SPEED or not adhesive):
        return
    y = np.asarray(y0, dtype=float)
    if adhesive and np.any(y < MIN_NONDIMENSIONAL_SPEED):
        v = float(np.asarray(normal_speed, dtype=float).ravel()[int(np.argmin(y.ravel()))]) if y.ndim else float(normal_speed)
        raise ValueError(
            f"normal speed {v!r} m/s is below what the engine resolves: v_n T/X = {float(y.min()):.3g} < "
            f"{MIN_NONDIMENSIONAL_SPEED:g} (the incident energy is below round-off of the adhesive contact "
            "well; with any damping such a sphere is captured)")


def _check_restitution(e_n, normal_speed, rtol: float) -> None:
    """EngineError if a computed e_n left [0, 1] by more than the solve's own error: a wrong result is
    never returned. An undamped impact (zeta_H = zeta_A = 0, which a fit visits at its bounds) has
    e_n = 1 exactly, computed to the tolerance of the solve: up to 1 + 100 rtol is that error."""
    top = 1.0 + max(1e-9, 100.0 * rtol)
    if isinstance(e_n, float) and 0.0 <= e_n <= top:
        return
    e = np.asarray(e_n, dtype=float)
    bad = ~((e >= 0.0) & (e <= top))
    if np.any(bad):
        i = int(np.flatnonzero(bad.ravel())[0])
        v = float(np.asarray(normal_speed, dtype=float).ravel()[i]) if e.ndim else float(normal_speed)
        raise EngineError(f"engine failed for normal speed {v!r} m/s: e_n = {float(e.ravel()[i]):.6g} "
                          "is outside [0, 1]")


_MUST_BE_FINITE = ("max_penetration", "friction_impulse", "twist_impulse", "dissipated_energy", "final_energy")


def _check_domain(contact, values: dict, normal_speed) -> None:
    """ModelDomainError if a result that must be finite overflowed in SI units (the nondimensional
    solve succeeded; its units did not)."""
    if all(type(q) is float and math.isfinite(q) for q in map(values.__getitem__, _MUST_BE_FINITE)):
        return  # one impact, all finite: the common case, without numpy
    for name in _MUST_BE_FINITE:
        q = np.asarray(values[name], dtype=float)
        bad = ~np.isfinite(q)
        if np.any(bad):
            i = int(np.flatnonzero(bad.ravel())[0])
            pen = float(np.asarray(values["max_penetration"], dtype=float).ravel()[i])
            v = float(np.asarray(normal_speed, dtype=float).ravel()[i])
            raise ModelDomainError(
                f"normal speed {v!r} m/s: the {name.replace('_', ' ')} is {float(q.ravel()[i])!r}, not representable; "
                f"the largest penetration is {pen:.3g} m, {pen / contact.radius:.3g} times the radius "
                f"{contact.radius!r} m, far outside Hertz contact (x << r, Eqs. (1)-(6)): these inputs leave "
                "the model's domain")


def _failure(status) -> str:
    """What a status code of the compiled core means."""
    return "step limit reached" if status == _MAX_STEPS else "step size underflow"


class EngineError(SolverError):
    """The compiled solver could not finish an impact (a caller's step limit, step-size underflow,
    or a result that failed its own check). Not raised for valid input at the default step limit:
    the stress sweep of the extended domain checks this.

    Examples
    --------
    A step limit far below what an impact needs (the default is 2,000,000):

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> solve_normal_many(c, [1.0], max_steps=5)
    Traceback (most recent call last):
    ...
    microimpact.solvers.engine.EngineError: engine failed for normal speed 1.0 m/s:
    step limit reached

    One ``except SolverError`` catches every solver's failure:

    >>> issubclass(EngineError, SolverError)
    True
    """


# --------------------------------------------------------------------------- compiled core
# The helpers called at every step (the right-hand side, the law, the stepper's error norm and step
# control in .dopri) are inlined by numba (``inline="always"``): with every helper a plain call the
# engine ran markedly slower. Those called once per impact or only in rare regimes (the set-up, the
# inertia-free limit and its tests, the undamped mirror) are compiled as calls, which LLVM may still
# inline: numba's inlining copies and re-types a helper at every call site, which lengthened
# the driver's compile and gained no speed (docs/model.md, "How it is computed").
@njit(cache=True, inline="always")
def _derivatives(s, y, c1, c2, ah, aa, sgn):
    """d/dsigma of the state (s, y, tau, D, J_a) at (s, y) (see the module docstring)."""
    s2 = s * s
    g = law.nondimensional_acceleration(s2, s2 * s2, y, c1, c2, ah, aa)  # dy/dsigma = s xi''
    return 0.5 * y, g, s, law.nondimensional_dissipation_rate(s2, s2 * s2, y, c1, c2, ah, aa), sgn * s * g


@njit(cache=True, inline="always")
def _rhs(u, out, args):
    c1, c2, ah, aa, sgn = args
    """d/dsigma of the state u, written into out."""
    out[0], out[1], out[2], out[3], out[4] = _derivatives(u[0], u[1], c1, c2, ah, aa, sgn)


#: one Dormand-Prince 5(4) step of the ring law (the core's, :mod:`microimpact.solvers.dopri`)
_step = dopri.make_step(_rhs, _NSTATE)


@njit(cache=True)
def _event_on_interpolant(code, target, th, u0, k1, u1, k7, h, ah, aa):
    if code == _EV_DY:  # d/dth of the y interpolant (proportional to dy/dsigma)
        y0, y1, d0, d1 = u0[1], u1[1], k1[1], k7[1]
        return (6.0 * th * th - 6.0 * th) * (y0 - y1) + (3.0 * th * th - 4.0 * th + 1.0) * h * d0 + (3.0 * th * th - 2.0 * th) * h * d1
    s = hermite(u0[0], u1[0], k1[0], k7[0], h, th)
    if code == _EV_S:
        return s
    y = hermite(u0[1], u1[1], k1[1], k7[1], h, th)
    if code == _EV_Y:
        return y - target
    return law.nondimensional_energy(s, y, ah, aa) - target


@njit(cache=True)
def _locate(code, target, u0, k1, h, g0, g1, c1, c2, ah, aa, sgn, k, tmp, u1, err):
    """Step length h* in (0, h] at which event ``code`` crosses zero; on return u1, k[6] hold the
    step to h*.

    The root is found on the cubic Hermite interpolant of the step (no right-hand-side calls),
    then the step is taken again to h*. That suffices: at every event of this model the quantities
    that are kept are stationary in sigma (at separation ds/dsigma = y/2 but dy/dsigma, dtau/dsigma
    ~ s, s^2 vanish; at an extremum or a turning point the located variable is stationary), or the
    event only records a time.
    """
    k7 = k[6].copy()
    end = u1.copy()
    a, b = 0.0, 1.0
    if code == _EV_DY:
        fa, fb = g0 * h, g1 * h
    else:
        fa, fb = g0, g1
    side = 0
    th = 1.0
    for _ in range(50):
        th = illinois_point(a, fa, b, fb)
        fs = _event_on_interpolant(code, target, th, u0, k1, end, k7, h, ah, aa)
        if fs == 0.0 or (b - a) < 1e-13:
            break
        a, fa, b, fb, side = illinois_update(a, fa, b, fb, th, fs, side)
    hs = th * h
    _step(u0, k1, hs, (c1, c2, ah, aa, sgn), k, tmp, u1, err)
    return hs


@njit(cache=True)
def _energy(u, code, args):
    ah, aa = args
    """The contact energy at the state u (the one event function solved on the step itself)."""
    return law.nondimensional_energy(u[0], u[1], ah, aa)


#: the step length at which the contact energy reaches a target, solved on the step itself rather
#: than on its interpolant: the time at which E first falls below zero is recorded where E falls
#: slowly (near the capture speed), so a small error of E is a large one of the time; on the cubic
#: Hermite interpolant, as :func:`_locate` finds it, the capture time was 1e-6 off at rtol 1e-9
_energy_crossing = dopri.make_root_on_step(_step, _energy)


_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)


#: the linear damped tail of a captured sphere, shared by every law (the driver's)
_linear_tail_variation = driver.linear_tail_variation


# ------------------------------------------------------------------ the inertia-free (overdamped) limit
#: Inertia ratio below which the engine leaves the explicit integration for the inertia-free limit
#: (see :func:`_inertia_free`). Below it the explicit solver would need more than ~1/sqrt(ratio)
#: steps per unit of slow time (its stability bound), and the limit is exact to the ratio.
INERTIA_FREE_ENTER = 1e-6
#: Inertia ratio at which a jump along the inertia-free path that cannot reach the equilibrium
#: hands the motion back to the explicit integration (hysteresis against INERTIA_FREE_ENTER).
INERTIA_FREE_RESUME = 1e-4
#: Relaxation ratio R = damping rate x transit time = sqrt(xi) (a_h C1 xi + a_a C2) xi / |y_m| above
#: which the motion is taken to follow the slow manifold (and which the jump keeps above
#: RELAXATION_RESUME). A flat manifold (small inertia ratio) is not enough: a fast sphere may cross
#: it in less than one relaxation time, and then its lag behind y_m is not the adiabatic one
#: (measured: e_n off by 7e-5 relative at R ~ 60 before this criterion).
RELAXATION_ENTER = 1e3
RELAXATION_RESUME = 1e2


@njit(cache=True)
def _slow_speed(xi, c1, c2, ah, aa):
    """Inertia-free speed y_m(xi) = (a_a - a_h xi) / (a_h C1 xi + a_a C2): xi'' = 0 in Eq. (27)."""
    return (aa - ah * xi) / (ah * c1 * xi + aa * c2)


@njit(cache=True)
def _inertia_ratio(xi, c1, c2, ah, aa):
    """|xi''| / |static force| on the inertia-free path at xi, |y_m'| / (sqrt(xi) (a_h C1 xi + a_a C2)).

    It decreases with xi, so along a path towards smaller xi its largest value is at the end."""
    d = ah * c1 * xi + aa * c2
    return ah * aa * (c1 + c2) / (math.sqrt(xi) * d * d * d)


@njit(cache=True)
def _relaxation_ratio(xi, c1, c2, ah, aa):
    """Damping rate times transit time on the slow manifold, sqrt(xi) d xi / |y_m|, d = a_h C1 xi +
    a_a C2 (inf at the equilibrium, where y_m = 0)."""
    d = ah * c1 * xi + aa * c2
    num = abs(aa - ah * xi)
    if num == 0.0:
        return math.inf
    return math.sqrt(xi) * d * d * xi / num


@njit(cache=True)
def _follows(x, c1, c2, ah, aa):
    """Whether the slow manifold at x is still followed adiabatically (both resume bounds hold)."""
    return (_inertia_ratio(x, c1, c2, ah, aa) <= INERTIA_FREE_RESUME
            and _relaxation_ratio(x, c1, c2, ah, aa) >= RELAXATION_RESUME)


@njit(cache=True)
def _slow_time(xi0, xi1, c1, c2, ah, aa):
    """tau from xi0 to xi1 along the inertia-free path: int dxi / y_m, in closed form."""
    t = -c1 * (xi1 - xi0)
    if aa > 0.0:
        t -= aa * (c1 + c2) / ah * math.log(abs(aa - ah * xi1) / abs(aa - ah * xi0))
    return t


@njit(cache=True)
def _slow_path(x, c1, c2, ah, aa):
    """y on the slow manifold to first order in the inertia ratio: y_m - y_m' y_m / damping, with
    damping = sqrt(xi) (a_h C1 xi + a_a C2) (from xi'' = damping (y_m - y) and xi'' ~ y_m' y_m)."""
    d = ah * c1 * x + aa * c2
    ym = (aa - ah * x) / d
    return ym + ah * aa * (c1 + c2) / (d * d) * ym / (math.sqrt(x) * d)


@njit(cache=True)
def _slow_twist(xi0, xi1, c1, c2, ah, aa):
    """int s |dy| from xi0 to xi1 along the slow manifold, first inertia correction included
    (:func:`_slow_path`; error of second order in the inertia ratio). Gauss-Legendre in ln xi on
    panels of at most a factor e^2 in xi; dy/dxi by a central difference (relative step 1e-5:
    truncation ~1e-10, round-off ~1e-11 relative)."""
    if aa == 0.0 or xi0 == xi1:
        return 0.0
    lo, hi = math.log(min(xi0, xi1)), math.log(max(xi0, xi1))
    panels = min(200, max(1, int(math.ceil((hi - lo) / 2.0))))
    width = (hi - lo) / panels
    total = 0.0
    for p in range(panels):
        mid = lo + (p + 0.5) * width
        for i in range(_GL_X.shape[0]):
            x = math.exp(mid + 0.5 * width * _GL_X[i])
            dx = 1e-5 * x
            slope = (_slow_path(x + dx, c1, c2, ah, aa) - _slow_path(x - dx, c1, c2, ah, aa)) / (2.0 * dx)
            total += _GL_W[i] * x * math.sqrt(x) * abs(slope)
    return 0.5 * width * total


@njit(cache=True)
def _inertia_free(u, atol_y, c1, c2, ah, aa, xe):
    """Whether the motion follows the inertia-free (overdamped) path: returns (yes, target xi).

    When the damping force is so large that inertia is negligible (inertia ratio below
    INERTIA_FREE_ENTER), Eq. (27) reduces to the first-order law xi' = y_m(xi): the sphere creeps
    towards the equilibrium xi_e = a_a / a_h (towards 0 without adhesion, where y_m = -1/C1 exactly
    and the exit speed follows). An explicit solver would need ~(damping rate x duration) steps,
    the stiffness, to follow it. Conditions: strongly damped here (inertia ratio and relaxation
    ratio, :data:`RELAXATION_ENTER`), and on the path within twice the inertia correction
    (|y - y_m| ~ ratio |y_m|) plus ten absolute tolerances; without adhesion (the path is then
    exact and invariant) at least 100 explicit steps saved. The target is xi_e (a capture), 0 (a
    rebound without adhesion) or, when a ratio would leave its resume bound before xi_e, the point
    where it does (the integration resumes there).
    """
    s = u[0]
    xi = s * s
    d = ah * c1 * xi + aa * c2
    # cheapest test first (it runs at every step): strong damping, without divisions
    if aa == 0.0:
        if not ah * c1 * c1 * xi * xi * s >= 100.0:
            return False, 0.0
    elif not ah * aa * (c1 + c2) <= INERTIA_FREE_ENTER * s * d * d * d:
        return False, 0.0
    ym = (aa - ah * xi) / d
    if aa == 0.0:
        return abs(u[1] - ym) <= 10.0 * atol_y, 0.0
    eps = _inertia_ratio(xi, c1, c2, ah, aa)
    if abs(u[1] - ym) > 2.0 * eps * abs(ym) + 10.0 * atol_y:
        return False, 0.0
    if _relaxation_ratio(xi, c1, c2, ah, aa) < RELAXATION_ENTER:
        return False, 0.0
    if xi <= xe:  # inwards both ratios improve all the way to xe
        return True, xe
    # outwards: the first point (from xi towards xe) where either ratio leaves its resume bound,
    # on a grid geometric in xi - xe, then bisection; none: the sphere creeps into xe
    prev = xi
    decades = math.log10((xi - xe) / (1e-12 * xe))  # down to xe (1 + 1e-12), however far xi is
    for k in range(1, 241):
        x = xe + (xi - xe) * 10.0 ** (-decades * k / 240.0)
        if not _follows(x, c1, c2, ah, aa):
            lo, hi = x, prev
            for _ in range(100):
                mid = 0.5 * (lo + hi)
                if _follows(mid, c1, c2, ah, aa):
                    hi = mid
                else:
                    lo = mid
            return hi < xi, hi
        prev = x
    return True, xe


@njit(cache=True)
def _slow_event_time(u, xi_end, target, kind, c1, c2, ah, aa):
    """tau at which, along the inertia-free path from the state u towards xi_end, the energy
    (kind _SLOW_ENERGY) or y (kind _SLOW_Y) reaches ``target``; NaN if it does not."""
    xi0 = u[0] * u[0]
    a, b = xi0, xi_end
    if kind == _SLOW_Y:
        # invert y_m: xi = a_a (1 - y C2) / (a_h (1 + y C1))
        if aa == 0.0:
            return u[2]
        x = aa * (1.0 - target * c2) / (ah * (1.0 + target * c1))
        if not (min(a, b) <= x <= max(a, b)):
            return math.nan
        return u[2] + _slow_time(xi0, x, c1, c2, ah, aa)
    fa = law.nondimensional_energy(math.sqrt(a), _slow_speed(a, c1, c2, ah, aa), ah, aa) - target
    fb = law.nondimensional_energy(math.sqrt(b), _slow_speed(b, c1, c2, ah, aa), ah, aa) - target
    if fa < 0.0 or fb >= 0.0:
        return math.nan if fa >= 0.0 else u[2]
    for _ in range(200):
        m = 0.5 * (a + b)
        if law.nondimensional_energy(math.sqrt(m), _slow_speed(m, c1, c2, ah, aa), ah, aa) >= target:
            a = m
        else:
            b = m
    return u[2] + _slow_time(xi0, a, c1, c2, ah, aa)


# ------------------------------------------------------------------ weakly damped captured tail (averaging)
_GL16_X, _GL16_W = np.polynomial.legendre.leggauss(16)


@njit(cache=True)
def _potential(xi, ah, aa):
    """V(xi) = (2/5) a_h xi^(5/2) - (2/3) a_a xi^(3/2), nondimensional. [-]"""
    s = math.sqrt(xi)
    return (0.4 * ah * xi * xi - (2.0 / 3.0) * aa * xi) * s


@njit(cache=True)
def _turning_point(e, lo, hi, ah, aa):
    """The xi in [lo, hi] where V(xi) = e (V monotone there), by bisection."""
    flo = _potential(lo, ah, aa) - e
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        fm = _potential(mid, ah, aa) - e
        if (fm > 0.0) == (flo > 0.0):
            lo, flo = mid, fm
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(cache=True)
def _orbit_integrals(e, c1, c2, ah, aa, xe):
    """Per cycle of the undamped orbit at energy e < 0 in the well: (energy lost to the damping,
    total variation of y, int s |dy|). Quadrature on each side of xe with xi = end + (xe - end) t^2
    from the turning point, which makes y ~ sqrt(xi - end) smooth in t."""
    ve = _potential(xe, ah, aa)
    ymax = math.sqrt(max(2.0 * (e - ve), 0.0))
    xa = _turning_point(e, 0.0, xe, ah, aa)
    xb = _turning_point(e, xe, (5.0 / 3.0) * aa / ah, ah, aa)
    loss = 0.0
    twist = 0.0
    for side in range(2):
        end = xa if side == 0 else xb
        width = xe - end
        sub = 0.0
        for i in range(_GL16_X.shape[0]):
            t = 0.5 * (_GL16_X[i] + 1.0)
            xi = end + width * t * t
            y = math.sqrt(max(2.0 * (e - _potential(xi, ah, aa)), 0.0))
            sx = math.sqrt(xi)
            dxi = 2.0 * width * t * 0.5 * _GL16_W[i]  # dxi/dt times the weight on [0, 1]
            loss += (ah * c1 * xi * sx + aa * c2 * sx) * y * abs(dxi)  # int damping * y dxi (= y^2 dtau)
            sub += y / (2.0 * sx) * dxi  # int y ds from the turning point to xe
        # W/2 = 2 s_e y_max - int_{xa}^{xe} y ds + int_{xe}^{xb} y ds, and the second is -sub here
        twist -= sub
    # both half-cycles (in and out) alike
    return 2.0 * loss, 4.0 * ymax, 2.0 * (2.0 * math.sqrt(xe) * ymax + twist)


@njit(cache=True)
def _orbit(e, oargs):
    """:func:`_orbit_integrals` with its parameters as one tuple (the driver's averaging calls it)."""
    c1, c2, ah, aa, xe = oargs
    return _orbit_integrals(e, c1, c2, ah, aa, xe)


#: the driver's method of averaging over this law's orbits
_averaged = driver.make_averaged_tail(_orbit)


@njit(cache=True)
def _averaged_tail(e_now, c1, c2, ah, aa, xe):
    """(J, J_a) still to come for a weakly damped captured sphere of energy e_now: the driver's
    method of averaging (:func:`microimpact.solvers.driver.make_averaged_tail`) over the undamped
    orbits of the ring law, from the well's bottom V(xe). Relative error of the order of the
    damping ratio C / omega0 (the change of the orbit within one cycle)."""
    return _averaged(e_now, _potential(xe, ah, aa), (c1, c2, ah, aa, xe))


# ------------------------------------------------------------------ pieces of one impact
@njit(cache=True)
def _first_sign(y0, c1, c2, ah, aa):
    """Sign of dy/dsigma at first contact, from its leading term in s (xi''/s at s = 0; without
    adhesion, or if that vanishes, the Hertz term decides)."""
    lead = law.nondimensional_acceleration(1.0, 0.0, y0, c1, c2, ah, aa)
    if lead == 0.0:
        lead = law.nondimensional_acceleration(0.0, 1.0, y0, c1, c2, ah, aa)
    return 1.0 if lead > 0.0 else -1.0


@njit(cache=True)
def _absolute_tolerances(y0, rtol):
    """Absolute tolerances of the states (s, y, tau, D, J_a), scaled with their sizes in an impact."""
    yref = max(1.0, y0)
    sref = max(1.0, y0 ** 0.4)
    atol = np.empty(_NSTATE)
    atol[0] = rtol * sref
    atol[1] = rtol * yref
    atol[2] = rtol * sref
    atol[3] = rtol * 0.5 * yref * yref
    atol[4] = rtol * sref * yref
    return atol


@njit(cache=True)
def _equilibrium(c1, c2, ah, aa):
    """(xi_e, omega0, C_eq): equilibrium penetration, sqrt(V''(xi_e)) and the damping coefficient
    there, for the tail bound of a captured sphere (xi_e = 0 without adhesion)."""
    xe = aa / ah if ah > 0.0 else 0.0
    omega0 = 1.0
    ceq = 0.0
    if aa > 0.0:
        se = math.sqrt(xe)
        omega0 = math.sqrt(ah * se)
        ceq = ah * c1 * xe * se + aa * c2 * se
    return xe, omega0, ceq


@njit(cache=True)
def _initial_step(y0):
    h = 1e-3 * min(1.0, 2.0 / max(y0, 1e-300) ** 0.6)
    if y0 < 1.0:
        h = min(1e-3 * (12.0 / y0) ** (1.0 / 3.0), 1e-2)
    return h


@njit(cache=True)
def _mirror_undamped(u, u1, k1, hev, J, j_target, tau_jtarget, y0, c1, c2, ah, aa, sgn, k, tmp, err):
    """At the turning point of an undamped impact, complete it by symmetry; returns (J, tau_jtarget).

    Without damping the motion is time-reversible: the way out mirrors the way in, so e_n = 1
    exactly and every integral doubles. Integrating the way out instead would let round-off in E
    (relative to the depth of the well) trap a slow sphere. u becomes the state at separation.
    """
    j_turn = J + abs(u1[1] - u[1])
    tau_turn = u1[2]
    ja_turn = u1[4]
    if math.isnan(tau_jtarget) and 0.0 < j_target <= j_turn:
        # reached on the way in, within this step (the way out is left to the caller)
        _step(u, k1, hev, (c1, c2, ah, aa, sgn), k, tmp, u1, err)
        yt = u[1] - (j_target - J)
        _locate(_EV_Y, yt, u, k1, hev, u[1] - yt, u1[1] - yt, c1, c2, ah, aa, sgn, k, tmp, u1, err)
        tau_jtarget = u1[2]
    u[0] = 0.0
    u[1] = -y0
    u[2] = 2.0 * tau_turn
    u[3] = 0.0
    u[4] = 2.0 * ja_turn
    return 2.0 * j_turn, tau_jtarget


@njit(cache=True, inline="always")
def _is_creeping(u, kend, atol_y, need_tail, c1, c2, ah, aa, xe, omega0, ceq):
    """Whether a strongly overdamped captured sphere creeps to the equilibrium.

    Once inertia is negligible (|xi''| << |V'(xi)|) and the sphere creeps towards the equilibrium,
    the motion is a gradient flow that approaches X monotonically. An explicit solver would need
    ~C^2 steps to follow it, and nothing more is to be learnt: y falls monotonically to 0 (its
    total variation from here is |y|) and the largest penetration is X itself (or what was reached
    before). Criterion: moving towards X, decelerating (so y falls monotonically to zero from here:
    its total variation is exactly |y|), and inertia small against the static force.
    """
    s = u[0]
    if not ((s * s - xe) * u[1] < 0.0 and s > 0.0):
        return False
    vp = -law.nondimensional_acceleration(s, s * s * s, 0.0, c1, c2, ah, aa)  # static force
    acc = kend[1] / s
    # (beyond C ~ 100 the deceleration, ~y/C^2, drowns in the integration noise and the slow
    # manifold is followed to O(1/C^2) anyway)
    stiff = ceq > 100.0 * omega0
    creeping = abs(acc) <= 1e-3 * abs(vp) and acc * u[1] < 0.0
    if stiff and not creeping:
        # very stiff: y itself may be below the absolute tolerance, so compare with the slow
        # manifold (to first order in the inertia ratio eps) instead of the (noisy) acceleration.
        # Within 10 eps^2 of it (its own error), |y| falls monotonically from here, so the friction
        # impulse still to come is |y|. (A 1 % band let the sphere stop while y still rose to its
        # peak: J short by twice the rise, 0.25 % at C ~ 100, measured in the extended stress sweep.)
        # Or within 1 % of y_m (the band that copes with noisy y) but not still clearly
        # accelerating.
        xi = s * s
        eps = _inertia_ratio(xi, c1, c2, ah, aa)
        yp = _slow_path(xi, c1, c2, ah, aa)
        ym = (aa - ah * xi) / (ah * c1 * xi + aa * c2)
        creeping = ((eps <= 1e-2 and abs(u[1] - yp) <= 10.0 * eps * eps * abs(yp) + 10.0 * atol_y)
                    or (abs(u[1] - ym) <= 1e-2 * abs(ym) + 10.0 * atol_y
                        and (acc * u[1] <= 0.0 or abs(acc) <= 1e-3 * abs(vp))))
    # The twist tail along the inertia-free path is accurate to the neglected inertia only (~1e-3
    # here, ~1/C^2 on the slow manifold), so when the tail matters it is followed by the
    # integrator unless that is impractical (C > 100: ~C^2 steps).
    return creeping and (stiff or not need_tail)


@njit(cache=True, inline="always")
def _capture_finished(u, kend, J, turned, follow, need_tail, settle_amp, tail_tol, j_stop, ja_stop,
                      noise, atol_y, c1, c2, ah, aa, xe, omega0, ceq, long_tail):
    """Whether the integration of a captured sphere can stop; returns (done, dJ, dJ_a), the
    friction and twist impulses still to come that are added in closed form.

    ``long_tail``: a twentieth of the step budget is spent on a captured oscillation that is still
    too large for the linear tail. Weakly damped (its amplitude falls by exp(-pi C / omega) per
    cycle; C ~ 1e-7 needs ~1e8 cycles), the tail is then the averaged one (:func:`_averaged_tail`,
    relative error ~C / omega); otherwise the linear one whatever the amplitude (relative error
    ~amplitude / X). Either instead of a step limit."""
    # linearised amplitude about the equilibrium, from the state itself (E - E_min would cancel
    # to round-off long before the tail is negligible); below a few absolute tolerances it is
    # integration noise, not motion
    dx = u[0] * u[0] - xe
    amp = max(math.sqrt(dx * dx + (u[1] / omega0) ** 2) - noise, 0.0)
    creeping = ceq > 2.0 * omega0 and _is_creeping(u, kend, atol_y, need_tail, c1, c2, ah, aa, xe, omega0, ceq)
    if follow:
        return amp <= settle_amp, 0.0, 0.0
    if creeping:
        return True, abs(u[1]), _slow_twist(u[0] * u[0], xe, c1, c2, ah, aa)
    if amp == 0.0:
        return True, 0.0, 0.0  # settled to within the integration noise
    if not turned:
        return False, 0.0, 0.0  # the largest penetration is not known yet
    if need_tail and J >= j_stop and u[4] >= ja_stop:
        return True, 0.0, 0.0  # sliding and twist have ended: the rest of the tail changes nothing
    if need_tail:
        # the friction impulse still to come is the total variation of y over the decaying
        # motion; in the linear regime it has a closed form, whose relative error is of the order
        # of the amplitude over the equilibrium penetration
        tail = _linear_tail_variation(dx, u[1], omega0, ceq)
        if (amp / xe) * tail <= tail_tol * J:
            return True, tail, math.sqrt(xe) * tail
        if long_tail and ceq <= 1e-2 * omega0:
            e_now = law.nondimensional_energy(u[0], u[1], ah, aa)
            if e_now < 0.0:
                jt, jat = _averaged_tail(e_now, c1, c2, ah, aa, xe)
                return True, jt, jat
        if long_tail:
            return True, tail, math.sqrt(xe) * tail
        return False, 0.0, 0.0
    return True, 0.0, 0.0  # captured and past the largest penetration


@njit(cache=True)
def _start(y0, c1, c2, ah, aa, rtol, rec, rec_cap):
    """The state at first contact and the constants of one impact: returns (u, k1, sgn, atol,
    noise, damped, ecap, xe, omega0, ceq, h, n_rec), the state and its derivative, the expected sign of
    dy/dsigma, the absolute tolerances, the amplitude below which a captured oscillation is
    integration noise, whether the impact is damped, the capture margin of the energy, the
    equilibrium (:func:`_equilibrium`), the first step and the rows of the trajectory ``rec``
    (its first, the incident state, where it has room)."""
    u = np.zeros(_NSTATE)
    u[1] = y0
    k1 = np.zeros(_NSTATE)
    sgn = _first_sign(y0, c1, c2, ah, aa)
    _rhs(u, k1, (c1, c2, ah, aa, sgn))
    atol = _absolute_tolerances(y0, rtol)
    noise = 10.0 * (atol[0] + atol[1])
    damped = c1 > 0.0 or (c2 > 0.0 and aa > 0.0)  # adhesion damping needs adhesion
    ecap = -10.0 * rtol * (4.0 / 15.0) * (aa * aa * aa / (ah * ah) if ah > 0.0 else 1.0) ** 0.5
    xe, omega0, ceq = _equilibrium(c1, c2, ah, aa)
    n_rec = 0
    if rec_cap > 0:
        rec[0, 0], rec[0, 1], rec[0, 2] = 0.0, 0.0, y0
        n_rec = 1
    return u, k1, sgn, atol, noise, damped, ecap, xe, omega0, ceq, _initial_step(y0), n_rec


@njit(cache=True)
def _capture_events(e0, e1, ecap, tau_zero, tau_capture, hev, u, k1, c1, c2, ah, aa, sgn, k, tmp, u1, err):
    """The capture events within the step u -> u1 (energy e0 -> e1) of an adhesive damped impact not
    yet captured: where E first falls below zero, and the capture (E below the margin ecap).
    Returns (captured, tau_zero, tau_capture, recorded); ``recorded``: u1 was moved to an event.

    Capture is E below zero by more than the integration can drift (without damping E is conserved,
    so a negative E could only be integration error); a true capture keeps losing energy and crosses
    the margin a little later. The capture time is where E first fell below zero (the margin's
    crossing, reported before, was up to 1e-6 later at rtol 1e-9, where E falls slowly: near the
    capture speed)."""
    recorded = False
    captured = False
    if math.isnan(tau_zero) and e0 >= 0.0 and e1 < 0.0:
        _energy_crossing(_EV_ENERGY, 0.0, e0, e1, 0.0, hev, u, k1, (c1, c2, ah, aa, sgn), (ah, aa), k, tmp, u1, err)
        tau_zero = u1[2]
        recorded = True
    if e0 >= ecap and e1 < ecap:
        captured = True
        if math.isnan(tau_zero):  # (E below zero with no crossing seen: the margin's)
            _locate(_EV_ENERGY, ecap, u, k1, hev, e0 - ecap, e1 - ecap, c1, c2, ah, aa, sgn, k, tmp, u1, err)
            tau_zero = u1[2]
            recorded = True
        tau_capture = tau_zero
    return captured, tau_zero, tau_capture, recorded


@njit(cache=True)
def _slip_end(recorded, J, j_target, hev, u, k1, c1, c2, ah, aa, sgn, k, tmp, u1, err):
    """The end of sliding within the step u -> u1 (J at its start; y is monotone within the step):
    returns (tau where J reaches j_target, NaN if it does not; recorded). ``recorded``: u1 was
    moved to an earlier event, so the step is taken again first; on return, whether u1 was moved
    (to the end of sliding)."""
    if recorded:
        _step(u, k1, hev, (c1, c2, ah, aa, sgn), k, tmp, u1, err)
        recorded = False
    dj = abs(u1[1] - u[1])
    if J < j_target and J + dj >= j_target:
        yt = u[1] + (j_target - J) * (1.0 if u1[1] > u[1] else -1.0)
        _locate(_EV_Y, yt, u, k1, hev, u[1] - yt, u1[1] - yt, c1, c2, ah, aa, sgn, k, tmp, u1, err)
        return u1[2], True
    return math.nan, recorded


@njit(cache=True)
def _largest_penetration(u, k1, hev, u1, smax, J, j_target, tau_jtarget, damped, y0, c1, c2, ah, aa, sgn, k, tmp,
                         err):
    """The largest penetration (y = 0) within the step u -> u1, with u1 moved there; an undamped
    impact is then completed by symmetry (:func:`_mirror_undamped`). Returns (smax, J, tau_jtarget)."""
    _locate(_EV_Y, 0.0, u, k1, hev, u[1], u1[1], c1, c2, ah, aa, sgn, k, tmp, u1, err)
    smax = max(smax, u1[0])
    if not damped:
        J, tau_jtarget = _mirror_undamped(u, u1, k1, hev, J, j_target, tau_jtarget, y0, c1, c2, ah, aa, sgn, k, tmp,
                                          err)
    return smax, J, tau_jtarget


@njit(cache=True, inline="always")
def _record(rec, n_rec, rec_cap, u):
    """Append (tau, s, y) of the state u to the trajectory ``rec`` while it has room; returns the
    new number of rows."""
    if rec_cap > 0 and n_rec < rec_cap:
        rec[n_rec, 0], rec[n_rec, 1], rec[n_rec, 2] = u[2], u[0], u[1]
        n_rec += 1
    return n_rec


@njit(cache=True)
def _inertia_free_jump(u, k1, kend, xi_t, J, j_target, tau_jtarget, captured, tau_zero, tau_capture, smax, rec,
                       rec_cap, n_rec, sgn, c1, c2, ah, aa, xe, ecap):
    """The jump along the inertia-free path from the state u to xi_t (:func:`_inertia_free`), in
    closed form: the events on the way, the friction and twist impulses, the time and the energy
    the jump skips (booked as dissipated). u becomes the state at xi_t.

    Returns (outcome, J, tau_jtarget, captured, tau_zero, tau_capture, smax, n_rec, sgn): outcome
    REBOUND (the invariant line without adhesion) or CAPTURE (the equilibrium) where the impact
    ends, -1 where the explicit integration resumes at xi_t (k1 and kend then hold the derivative
    there, sgn the sign of dy/dsigma)."""
    xi0 = u[0] * u[0]
    e_now = law.nondimensional_energy(u[0], u[1], ah, aa)
    if aa > 0.0 and xi_t == xe:
        y_t = 0.0
    elif aa == 0.0:
        y_t = -1.0 / c1
    else:  # the slow path and its first inertia correction, y_m - y_m' y_m / damping
        y_t = _slow_speed(xi_t, c1, c2, ah, aa)
        dd = ah * c1 * xi_t + aa * c2
        y_t += ah * aa * (c1 + c2) / (dd * dd) * y_t / (math.sqrt(xi_t) * dd)
    dj = abs(u[1] - y_t)
    if math.isnan(tau_jtarget) and j_target > 0.0 and J < j_target <= J + dj:
        tau_jtarget = _slow_event_time(u, xi_t, u[1] + (j_target - J) * (1.0 if y_t > u[1] else -1.0),
                                       _SLOW_Y, c1, c2, ah, aa)
    if not captured and aa > 0.0:
        if math.isnan(tau_zero):
            tau_zero = _slow_event_time(u, xi_t, 0.0, _SLOW_ENERGY, c1, c2, ah, aa)
        tc = _slow_event_time(u, xi_t, ecap, _SLOW_ENERGY, c1, c2, ah, aa)
        if not math.isnan(tc):
            captured = True
            tau_capture = tc if math.isnan(tau_zero) else tau_zero
    J += dj
    if aa == 0.0:
        u[4] += u[0] * dj
        u[2] += c1 * xi0
    else:
        u[4] += _slow_twist(xi0, xi_t, c1, c2, ah, aa)
        if xi_t != xe:
            u[2] += _slow_time(xi0, xi_t, c1, c2, ah, aa)
    u[0] = math.sqrt(xi_t)
    u[1] = y_t
    u[3] += e_now - law.nondimensional_energy(u[0], u[1], ah, aa)
    smax = max(smax, u[0])
    if not (aa > 0.0 and xi_t == xe):
        n_rec = _record(rec, n_rec, rec_cap, u)
    outcome = -1
    if aa == 0.0:
        outcome = REBOUND
    elif xi_t == xe:
        outcome = CAPTURE
    else:  # resume the explicit integration where inertia matters again
        s2 = xi_t
        g = law.nondimensional_acceleration(s2, s2 * s2, u[1], c1, c2, ah, aa)
        if g != 0.0:
            sgn = 1.0 if g > 0.0 else -1.0
        _rhs(u, kend, (c1, c2, ah, aa, sgn))
        for i in range(_NSTATE):
            k1[i] = kend[i]
    return outcome, J, tau_jtarget, captured, tau_zero, tau_capture, smax, n_rec, sgn


# ------------------------------------------------------------------ the ring law in the one driver
# The law's parameters p = (y0, c1, c2, a_h, a_a, need_tail, tail_tol, j_target, follow, settle_amp,
# j_stop, ja_stop) and its bookkeeping w (indices below; flags as 0.0 / 1.0), for the driver
# (:mod:`.driver`), which owns the loop, the error control and the budgets.
_W_J, _W_SMAX, _W_TAU_CAPTURE, _W_TAU_JTARGET, _W_TAU_ZERO, _W_CAPTURED, _W_TURNED, _W_OUTCOME = 0, 1, 2, 3, 4, 5, 6, 7
_W_SGN, _W_NREC, _W_NOISE, _W_DAMPED, _W_ECAP, _W_XE, _W_OMEGA0, _W_CEQ = 8, 9, 10, 11, 12, 13, 14, 15
_W_SIZE = 16


@njit(cache=True)
def _law_start(p, rtol, rec, rec_cap):
    """The driver's start (:func:`_start`): the state, its derivative, the first step, the
    tolerances and the bookkeeping of one impact."""
    u, k1, sgn, atol, noise, damped, ecap, xe, omega0, ceq, h, n_rec = _start(p[0], p[1], p[2], p[3], p[4], rtol,
                                                                              rec, rec_cap)
    w = np.zeros(_W_SIZE)
    w[_W_TAU_CAPTURE] = w[_W_TAU_JTARGET] = w[_W_TAU_ZERO] = math.nan  # tau_zero: where E first fell below zero
    w[_W_OUTCOME] = -1.0
    w[_W_SGN], w[_W_NREC], w[_W_NOISE], w[_W_DAMPED] = sgn, n_rec, noise, 1.0 if damped else 0.0
    w[_W_ECAP], w[_W_XE], w[_W_OMEGA0], w[_W_CEQ] = ecap, xe, omega0, ceq
    return u, k1, h, atol, w


@njit(cache=True, inline="always")
def _law_args(p, w):
    """The right-hand side's arguments: (C1, C2, a_h, a_a, the expected sign of dy/dsigma)."""
    return (p[1], p[2], p[3], p[4], w[_W_SGN])


@njit(cache=True, inline="always")
def _law_too_small(h, u):
    return h < 1e-300


@njit(cache=True, inline="always")
def _keep(w, J, smax, tau_capture, tau_jtarget, tau_zero, captured, turned, outcome, sgn, n_rec):
    """Write the bookkeeping of the ring law back into w."""
    w[_W_J], w[_W_SMAX], w[_W_TAU_CAPTURE], w[_W_TAU_JTARGET], w[_W_TAU_ZERO] = J, smax, tau_capture, tau_jtarget, tau_zero
    w[_W_CAPTURED], w[_W_TURNED] = 1.0 if captured else 0.0, 1.0 if turned else 0.0
    w[_W_OUTCOME], w[_W_SGN], w[_W_NREC] = outcome, sgn, n_rec


@njit(cache=True, inline="always")
def _law_events(u, u1, k1, h, p, w, atol, rtol, k, tmp, err, rec, rec_cap):
    """The events of the ring law within the accepted step u -> u1, and the advance to its end.

    Events that end a piece of the solution (separation; an extremum of y, where the sign of |F_n|
    flips) shorten the step to the earliest of them. Events that only record something (largest
    penetration, capture, end of sliding) are located inside the step without changing it, so the
    trajectory, and e_n, do not depend on which of them a caller asked for.
    """
    y0, c1, c2, ah, aa, j_target = p[0], p[1], p[2], p[3], p[4], p[7]
    J, smax, tau_capture, tau_jtarget, tau_zero = w[_W_J], w[_W_SMAX], w[_W_TAU_CAPTURE], w[_W_TAU_JTARGET], w[_W_TAU_ZERO]
    captured, turned, damped = w[_W_CAPTURED] != 0.0, w[_W_TURNED] != 0.0, w[_W_DAMPED] != 0.0
    outcome, sgn, n_rec, ecap = int(w[_W_OUTCOME]), w[_W_SGN], int(w[_W_NREC]), w[_W_ECAP]
    hev, code = h, -1
    g0, g1 = k1[1], k[6, 1]
    if u[0] > 0.0 and u1[0] <= 0.0:
        hev = _locate(_EV_S, 0.0, u, k1, h, u[0], u1[0], c1, c2, ah, aa, sgn, k, tmp, u1, err)
        code = 0
        _step(u, k1, h, (c1, c2, ah, aa, sgn), k, tmp, u1, err)
    # an extremum of y: dy/dsigma leaves its expected sign (comparing with the expected sign,
    # not with g0, keeps the root just found at the start of this step from being found again)
    if u[0] > 0.0 and g1 * sgn < 0.0:
        if g0 * sgn <= 0.0:
            g0 = sgn * 1e-300
        hh = _locate(_EV_DY, 0.0, u, k1, h, g0, g1, c1, c2, ah, aa, sgn, k, tmp, u1, err)
        if code < 0 or hh < hev:
            hev, code = hh, 2
    if code >= 0:
        _step(u, k1, hev, (c1, c2, ah, aa, sgn), k, tmp, u1, err)
        # dy/dsigma ~ s^2 vanishes at the surface too, so an extremum found at the end of
        # contact is the separation itself
        if code == 2 and u1[0] <= 0.0 and u1[1] < 0.0:
            code = 0
    recorded = False  # u1 was moved to a recorded event: take the step again before using it
    if not turned and u[1] > 0.0 and u1[1] <= 0.0:  # largest penetration
        smax, J, tau_jtarget = _largest_penetration(u, k1, hev, u1, smax, J, j_target, tau_jtarget, damped, y0, c1,
                                                    c2, ah, aa, sgn, k, tmp, err)
        turned = recorded = True
        if not damped:  # completed by symmetry, before the step counts
            _keep(w, J, smax, tau_capture, tau_jtarget, tau_zero, captured, turned, REBOUND, sgn, n_rec)
            return driver.END_UNCOUNTED
    if not captured and damped and aa > 0.0:
        if recorded:
            _step(u, k1, hev, (c1, c2, ah, aa, sgn), k, tmp, u1, err)
            recorded = False
        e0 = law.nondimensional_energy(u[0], u[1], ah, aa)
        e1 = law.nondimensional_energy(u1[0], u1[1], ah, aa)
        if (math.isnan(tau_zero) and e0 >= 0.0 and e1 < 0.0) or (e0 >= ecap and e1 < ecap):
            captured, tau_zero, tau_capture, recorded = _capture_events(
                e0, e1, ecap, tau_zero, tau_capture, hev, u, k1, c1, c2, ah, aa, sgn, k, tmp, u1, err)
    if math.isnan(tau_jtarget) and j_target > 0.0:  # end of sliding
        tau_jtarget, recorded = _slip_end(recorded, J, j_target, hev, u, k1, c1, c2, ah, aa, sgn, k, tmp, u1, err)
    if recorded:
        _step(u, k1, hev, (c1, c2, ah, aa, sgn), k, tmp, u1, err)
    # |dy| rather than sgn * dy: robust to an extremum that falls between two steps unnoticed
    # (a signed sum would then subtract; measured: more convergence failures in the stress sweep)
    J += abs(u1[1] - u[1])
    # advance; after an event the derivative is evaluated anew, otherwise it is the last
    # stage of the step (first same as last)
    for i in range(_NSTATE):
        u[i] = u1[i]
    if code == 0:
        u[0] = 0.0  # exactly at the surface
    if code == 2 or code == 0:
        if code == 2:
            sgn = -sgn
        _rhs(u, k1, (c1, c2, ah, aa, sgn))
    else:
        for i in range(_NSTATE):
            k1[i] = k[6, i]
    smax = max(smax, u[0])
    n_rec = _record(rec, n_rec, rec_cap, u)
    if code == 0:
        outcome = REBOUND
    _keep(w, J, smax, tau_capture, tau_jtarget, tau_zero, captured, turned, outcome, sgn, n_rec)
    return driver.END if code == 0 else driver.GO_ON


@njit(cache=True, inline="always")
def _law_creep(u, k1, p, w, atol, rec, rec_cap):
    """The inertia-free limit of a damped impact (:func:`_inertia_free`): finish, or jump and
    resume, in closed form."""
    c1, c2, ah, aa = p[1], p[2], p[3], p[4]
    xe = w[_W_XE]
    if not (w[_W_DAMPED] != 0.0 and u[0] > 0.0):
        return driver.CREEP_NONE
    slow, xi_t = _inertia_free(u, atol[1], c1, c2, ah, aa, xe)
    if not slow:
        return driver.CREEP_NONE
    outcome, J, tau_jtarget, captured, tau_zero, tau_capture, smax, n_rec, sgn = _inertia_free_jump(
        u, k1, k1, xi_t, w[_W_J], p[7], w[_W_TAU_JTARGET], w[_W_CAPTURED] != 0.0, w[_W_TAU_ZERO],
        w[_W_TAU_CAPTURE], w[_W_SMAX], rec, rec_cap, int(w[_W_NREC]), w[_W_SGN], c1, c2, ah, aa, xe, w[_W_ECAP])
    _keep(w, J, smax, tau_capture, tau_jtarget, tau_zero, captured, w[_W_TURNED] != 0.0, outcome, sgn, n_rec)
    return driver.CREEP_END if outcome >= 0 else driver.CREEP_RESUME


@njit(cache=True, inline="always")
def _law_captured_end(u, k1, p, w, atol, long_tail):
    """Whether a captured sphere may stop (:func:`_capture_finished`); the impulses still to come
    are added in closed form."""
    if w[_W_CAPTURED] == 0.0:
        return False
    c1, c2, ah, aa, need_tail, tail_tol, follow, settle_amp, j_stop, ja_stop = (
        p[1], p[2], p[3], p[4], p[5], p[6], p[8], p[9], p[10], p[11])
    xe = w[_W_XE]
    turned = w[_W_TURNED] != 0.0
    done, dj, dja = _capture_finished(u, k1, w[_W_J], turned, follow, need_tail, settle_amp, tail_tol, j_stop,
                                      ja_stop, w[_W_NOISE], atol[1], c1, c2, ah, aa, xe, w[_W_OMEGA0], w[_W_CEQ],
                                      long_tail)
    if done:
        w[_W_J] += dj
        u[4] += dja
        w[_W_OUTCOME] = CAPTURE
        if not turned and xe > w[_W_SMAX] * w[_W_SMAX]:
            w[_W_SMAX] = math.sqrt(xe)  # approached the equilibrium without turning: its supremum
    return done


@njit(cache=True)
def _law_finish(status, u, p, w, n_steps, n_rej):
    """The driver's :class:`~microimpact.solvers.driver.Trace` of a ring-law impact."""
    smax = w[_W_SMAX]
    return driver.Trace(status, int(w[_W_OUTCOME]), u[1], u[2], u[3], w[_W_J], u[4], smax * smax, w[_W_TAU_CAPTURE],
                        w[_W_TAU_JTARGET], law.nondimensional_energy(u[0], u[1], p[3], p[4]), n_steps, n_rej,
                        int(w[_W_NREC]), u, 0, 0)


#: the one driver (:mod:`.driver`) running the ring law
_drive = driver.make_driver(driver.Law(_law_start, _law_args, _step, _law_too_small, driver.make_error_norm(_NSTATE),
                                       _law_events, _law_creep, _law_captured_end, _law_finish, _NSTATE))


@njit(cache=True)
def _integrate(y0, c1, c2, ah, aa, rtol, need_tail, tail_tol, j_target, follow, settle_amp,
               max_steps, rec, rec_cap, j_stop, ja_stop):
    """Integrate one normal impact (Dormand-Prince 5(4) in sigma, see the module docstring) with the
    one driver; returns its :class:`~microimpact.solvers.driver.Trace` (nondimensional: y, tau, D, J,
    J_a, the largest xi, the capture and slip-end times, e at the end, the steps and the rows
    recorded into ``rec``)."""
    return _drive((y0, c1, c2, ah, aa, need_tail, tail_tol, j_target, follow, settle_amp, j_stop, ja_stop), rtol,
                  max_steps, rec, rec_cap)


@njit_batch
def _integrate_many(y0, c1, c2, ah, aa, rtol, need_tail, tail_tol, max_steps, j_stop, ja_stop, out):
    dummy = np.zeros((1, 3))
    for i in prange(y0.shape[0]):
        # numpy scalars, not literals: one compiled _integrate serves this kernel and solve_normal
        r = _integrate(y0[i], c1[i], c2[i], ah[i], aa[i], rtol, need_tail[i], tail_tol, 0.0, np.bool_(False), 0.0,
                       max_steps, dummy, np.int64(0), j_stop[i], ja_stop[i])
        driver.write_common_row(r, out, i)
        out[i, 9] = r.final_energy
        out[i, 10] = r.n_steps


# --------------------------------------------------------------------------- Python interface
#: The record array of a solve that records nothing (never written: its capacity is 0)
_NO_RECORD = np.zeros((1, 3))


def solve_normal(contact, normal_speed: float, *, rtol: float = DEFAULT_RTOL, trajectory: bool = False,
                 follow_capture: bool = False, need_tail: bool = False, tail_tolerance: float | None = None,
                 friction_impulse_target: float | None = None, settle_amplitude: float = 1e-4,
                 max_steps: int = _MAX_STEPS_DEFAULT, friction_impulse_stop: float = math.inf,
                 twist_impulse_stop: float = math.inf) -> NormalSolution:
    """Solve the normal contact, Eq. (27), of one impact.

    Parameters
    ----------
    contact : Contact
    normal_speed : float
        Incident normal speed, > 0. [m/s]
    rtol : float
        Relative tolerance of the integration (absolute tolerances scale with it). [-]
    trajectory : bool
        Also return the trajectory at the accepted steps.
    follow_capture : bool
        For a captured sphere keep integrating until the oscillation amplitude is below
        ``settle_amplitude`` times the equilibrium penetration X (for phase portraits).
    need_tail : bool
        For a captured sphere keep integrating until the friction impulse still to come is below
        ``tail_tolerance`` (default ``rtol``) relative to J (needed for the tangential outcome).
        Without it a capture stops at the exact energy test.
    friction_impulse_target : float, optional
        Record the time at which J reaches this value (end of sliding). [N s]
    settle_amplitude : float
        See ``follow_capture``. [-]
    friction_impulse_stop, twist_impulse_stop : float
        With ``need_tail``, a captured sphere stops as soon as J and J_a have both reached these
        (sliding and twist are over, so the rest of the tail cannot change the outcome). [N s], [N m s]
    max_steps : int
        Step limit; EngineError beyond it. A guard only: the default is never reached by valid
        input (strong damping leaves for the inertia-free limit, long weakly damped tails for the
        averaged tail, very fast adhesive impacts for the Hertz scales; see the module docstring).

    Returns
    -------
    NormalSolution

    Raises
    ------
    ValueError
        Bad ``normal_speed`` or ``rtol``, or a speed below :data:`MIN_NONDIMENSIONAL_SPEED`.
    ModelDomainError
        The impact leaves the model's domain: a result is not representable in SI units (the
        message gives the penetration over the radius).
    EngineError
        ``max_steps`` reached, step-size underflow, or e_n outside [0, 1] (never returned).
    
    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (27)

    Dormand & Prince (1980)

    Hairer, Norsett & Wanner (1993), Secs. II.5-II.6

    Examples
    --------
    The paper's microsphere at 2 m/s, against the independent 3-D reference integration:

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.solvers.reference import simulate_reference
    >>> s = solve_normal(WALL_1990, 2.0)
    >>> s.outcome, round(s.e_n, 6), abs(s.e_n - simulate_reference(WALL_1990, 2.0, rtol=1e-10).e_n) < 1e-7
    ('rebound', 0.442528, True)
    """
    v = check_positive("normal_speed", normal_speed)
    if not (0.0 < rtol < 1.0):
        raise ValueError(f"rtol must lie in (0, 1), got {rtol!r}")
    sc, y0, c1, c2 = engine_scales(contact, v)
    _check_resolvable(y0, sc.a_adhesion > 0.0, v)
    u = sc.speed
    j_unit = contact.mass * u  # N s
    jt = 0.0 if friction_impulse_target is None else float(friction_impulse_target) / j_unit
    cap = 4096 if (trajectory or follow_capture) else 0
    while True:
        rec = np.zeros((cap, 3)) if cap else _NO_RECORD
        r = _integrate(y0, c1, c2, sc.a_hertz, sc.a_adhesion, rtol, need_tail,
                       rtol if tail_tolerance is None else tail_tolerance, jt, follow_capture,
                       settle_amplitude * (sc.a_adhesion / sc.a_hertz if sc.a_adhesion > 0 else 1.0),
                       max_steps, rec, cap, friction_impulse_stop / j_unit,
                       twist_impulse_stop / (j_unit * math.sqrt(contact.radius * sc.length)))
        if cap == 0 or r.n_recorded < cap:
            break
        cap *= 4
    if c1 == 0.0 and c2 == 0.0 and jt > 0.0 and math.isnan(r.tau_slip_end) and jt < r.friction_impulse:
        r = _slip_end_by_reversal(r, y0, sc, rtol, jt, max_steps, rec)
    if r.status != _OK:
        raise EngineError(f"engine failed for normal speed {v!r} m/s: {_failure(r.status)} after {r.n_steps} steps")
    solution = normal_solution(contact, sc, y0, r, trajectory=rec[:r.n_recorded] if cap else None,
                               followed=need_tail or follow_capture)
    _check_restitution(solution.e_n, v, rtol)
    _check_domain(contact, vars(solution), v)
    return solution



def _slip_end_by_reversal(r, y0, sc, rtol, jt, max_steps, rec):
    """The trace ``r`` of an undamped impact whose J reached the target ``jt`` only on the way out,
    with the time of that found by time reversal: J reaches jt on the way out when it reached
    J - jt on the way in (nondimensional)."""
    r_in = _integrate(y0, 0.0, 0.0, sc.a_hertz, sc.a_adhesion, rtol, False, rtol, r.friction_impulse - jt, False,
                      0.0, max_steps, rec, 0, math.inf, math.inf)
    return r._replace(tau_slip_end=r.tau_end - r_in.tau_slip_end)

def normal_solution(contact, scales, y0, trace, *, trajectory=None, followed: bool = False) -> NormalSolution:
    """The :class:`NormalSolution` in SI units of a nondimensional normal solve (engine or RKG).

    Parameters
    ----------
    contact : Contact
    scales : microimpact.model.law.Scales
        L [m], T_c [s] of the solve.
    y0 : float
        Nondimensional incident normal speed. [-]
    trace : microimpact.solvers.driver.Trace
        The solve's nondimensional record: outcome (REBOUND or CAPTURE), y and tau at the end
        (separation for a rebound), D, J, J_a, the largest xi, the capture and slip-end times and e
        at the end (units m (L/T_c)^2, m L/T_c, m L/T_c sqrt(r L), L, T_c), the steps. [-]
    trajectory : ndarray, shape (n, 3), optional
        Rows (tau, s, y) at the accepted steps. [-]
    followed : bool
        A captured sphere was followed past the capture test (its ``stop_reason`` is "settled").

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (21) and (29)-(30)

    Examples
    --------
    A rebound at half the incident nondimensional speed: e_n = 0.5, the times in units of T_c, the
    lengths of L, and the final energy, (1/2) (y0/2)^2 in units of m (L/T_c)^2, is e_n^2 = 1/4 of
    the incident kinetic energy:

    >>> import math
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> from microimpact.solvers.driver import OK, Trace
    >>> from microimpact.solvers.engine import REBOUND, engine_scales
    >>> sc, y0, c1, c2 = engine_scales(c, 2.0)
    >>> trace = Trace(OK, REBOUND, -0.5 * y0, 3.0, 0.0, 0.0, 0.0, 1.2, math.nan, math.nan, 0.125 * y0**2, 40, 2, 0,
    ...               None, 0, 0)
    >>> s = normal_solution(c, sc, y0, trace)
    >>> s.outcome, s.e_n, round(s.contact_time / sc.time, 12)
    ('rebound', 0.5, 3.0)
    >>> round(s.max_penetration / sc.length, 12)
    1.2
    >>> round(s.final_energy / (0.5 * c.mass * 2.0**2), 12), s.n_steps, s.time
    (0.25, 40, None)
    """
    u = scales.speed
    j_unit = contact.mass * u  # N s
    energy_unit = contact.mass * u * u  # J
    captured = trace.outcome == CAPTURE
    time = pen = rate = None
    if trajectory is not None:
        time = trajectory[:, 0] * scales.time
        pen = trajectory[:, 1] ** 2 * scales.length
        rate = trajectory[:, 2] * u
    return NormalSolution(
        outcome=OUTCOME_NAMES[int(trace.outcome)],
        e_n=0.0 if captured else -trace.y_end / y0,
        contact_time=math.inf if captured else trace.tau_end * scales.time,
        capture_time=trace.tau_capture * scales.time,
        max_penetration=trace.max_approach * scales.length,
        friction_impulse=trace.friction_impulse * j_unit,
        twist_impulse=trace.twist_impulse * j_unit * math.sqrt(contact.radius * scales.length),
        dissipated_energy=trace.dissipated * energy_unit,
        final_energy=trace.final_energy * energy_unit,
        slip_end_time=trace.tau_slip_end * scales.time,
        n_steps=int(trace.n_steps),
        n_rejected=int(trace.n_rejected),
        stop_reason=driver.stop_reason(trace.status, captured, followed),
        time=time,
        penetration=pen,
        penetration_rate=rate,
    )


def solve_normal_many(contact, normal_speed, need_tail=None, *, rtol: float = DEFAULT_RTOL,
                      tail_tolerance: float | None = None, max_steps: int = _MAX_STEPS_DEFAULT,
                      friction_impulse_stop=math.inf, twist_impulse_stop=math.inf) -> SolutionBatch:
    """Solve many normal impacts in parallel (both cores); arrays in, a :class:`SolutionBatch` of SI
    arrays out.

    Parameters
    ----------
    contact : Contact
    normal_speed : array_like, 1-D
        Distinct incident normal speeds, > 0. [m/s]
    need_tail : array_like of bool, optional
        Per speed, whether a captured sphere must be followed for its friction impulse.
    friction_impulse_stop, twist_impulse_stop : array_like, optional
        Per speed, the impulses beyond which the tail is not needed (see :func:`solve_normal`).
        [N s], [N m s]

    Returns
    -------
    SolutionBatch
        ``captured`` (bool), ``e_n`` [-], ``contact_time`` [s], ``capture_time`` [s],
        ``max_penetration`` [m], ``friction_impulse`` [N s], ``twist_impulse`` [N m s],
        ``dissipated_energy`` [J], ``final_energy`` [J], ``n_steps``.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (27)

    Dormand & Prince (1980)

    Hairer, Norsett & Wanner (1993), Secs. II.5-II.6

    Examples
    --------
    An elastic Hertz impact (no adhesion, no damping) rebounds with e_n = 1 after the contact time
    2 B(2/5, 1/2) / (5/2) x_max / v = 2.94328 x_max / v, x_max = (5 m v^2 / (4 k))^(2/5):

    >>> import math
    >>> from scipy.special import beta
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> h = c.with_(zeta_hertz=0.0, zeta_adhesion=0.0, adhesion_line_force=0.0)
    >>> r = solve_normal_many(h, [0.5, 2.0])
    >>> x_max = (1.25 * h.mass * 2.0**2 / (math.sqrt(h.radius) * h.stiffness)) ** 0.4
    >>> t_c = r["contact_time"][1]
    >>> r["e_n"].tolist(), round(float(t_c * 2.0 / x_max / (0.8 * beta(0.4, 0.5))), 7)
    ([1.0, 1.0], 1.0)
    """
    v = np.ascontiguousarray(normal_speed, dtype=float).ravel()
    if v.size and (not np.all(np.isfinite(v)) or np.any(v <= 0.0)):
        bad = v[~(np.isfinite(v) & (v > 0.0))][0]
        raise ValueError(f"normal speeds must be finite and > 0, got {bad!r}")
    nt = np.zeros(v.shape, dtype=np.bool_) if need_tail is None else np.ascontiguousarray(need_tail, dtype=np.bool_).ravel()
    sc, y0, c1, c2 = engine_scales(contact, v)
    _check_resolvable(y0, np.any(np.asarray(sc.a_adhesion) > 0.0), v)
    u = sc.speed
    # writable copies, whatever the shapes: a read-only view (what broadcasting gives) would make
    # numba compile the parallel kernel a second time
    u, c1, c2, y0 = (np.array(np.broadcast_to(a, v.shape), dtype=float) for a in (u, c1, c2, y0))
    length, time = sc.length, sc.time
    ah, aa = (np.array(np.broadcast_to(a, v.shape), dtype=float) for a in (sc.a_hertz, sc.a_adhesion))
    ju = contact.mass * u
    jstop = np.broadcast_to(np.asarray(friction_impulse_stop, dtype=float), v.shape) / ju
    jastop = np.broadcast_to(np.asarray(twist_impulse_stop, dtype=float), v.shape) / (ju * np.sqrt(contact.radius * length))
    out = np.empty((v.size, 11))
    _integrate_many(y0, c1, c2, ah, aa, float(rtol), nt, float(rtol if tail_tolerance is None else tail_tolerance),
                    int(max_steps), np.ascontiguousarray(jstop), np.ascontiguousarray(jastop), out)
    status = out[:, 0]
    if np.any(status != _OK):
        i = int(np.flatnonzero(status != _OK)[0])
        raise EngineError(f"engine failed for normal speed {float(v[i])!r} m/s: {_failure(status[i])}")
    captured = out[:, 1] == CAPTURE
    eu = contact.mass * u * u
    e_n = np.where(captured, 0.0, -out[:, 2] / y0)
    _check_restitution(e_n, v, rtol)
    result = SolutionBatch(
        captured=captured,
        e_n=e_n,
        contact_time=np.where(captured, np.inf, out[:, 3] * time),
        capture_time=out[:, 8] * time,
        max_penetration=out[:, 7] * length,
        friction_impulse=out[:, 5] * ju,
        twist_impulse=out[:, 6] * ju * np.sqrt(contact.radius * length),
        dissipated_energy=out[:, 4] * eu,
        final_energy=out[:, 9] * eu,
        n_steps=out[:, 10].astype(np.int64),
    )
    _check_domain(contact, result, v)
    return result


def set_threads(n: int | None = None) -> None:
    """Use ``n`` threads for :func:`solve_normal_many` (default: all cores)."""
    set_num_threads(n or os.cpu_count() or 1)
