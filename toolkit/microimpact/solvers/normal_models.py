"""Compiled normal solver of the JKR and DMT adhesion models (and a scipy reference for them).

The paper's ring law keeps its tuned engine (:mod:`.engine`); the alternative normal models of
:mod:`microimpact.model.adhesion_models` are integrated here and return the same
:class:`~microimpact.solvers.solution.NormalSolution` (e_n, contact time, friction impulse
J = int |F_n| dt, twist impulse J_a = int a |F_n| dt, largest penetration, rebound or capture), so
that :func:`microimpact.simulate_impact` and :func:`microimpact.simulate_many` apply the same
closed-form tangential map to them. The decoupling that makes the map exact for the ring law holds
for any normal law in which friction does not act back on the normal motion.

Numerical formulation
---------------------
Both laws are written in their own nondimensional units (:func:`~microimpact.model.adhesion_models.adhesion_scales`)
and with a Sundman-type time change that makes the right-hand side a polynomial, smooth at the ends
of contact where the force is not smooth in time:

* JKR, state q = sqrt(a / a_c) (delta / L_J = q^4 - 4 q): d tau = 4 (q^3 - 1) d sigma gives
  dq/dsigma = y, dy/dsigma = -4 (q^3 - 1) F(q, y). Contact starts at q0 = 4^(1/3) (delta = 0) and
  breaks at the simple root q = 1 (delta = delta_c), where delta(a) has its minimum and the force
  has a square-root singularity in time.
* DMT, state s = sqrt(delta / L_D): d tau = s d sigma gives ds/dsigma = y / 2,
  dy/dsigma = -s F(s, y). Contact starts and ends at s = 0.

The tau, J, J_a and damping-dissipation states are integrated with the motion. Dormand-Prince 5(4)
(Dormand & Prince 1980; the one core, :mod:`.dopri`) with the root-mean-square error of every state;
a step ends where the net force changes sign (|F_n|, integrated into J and J_a, has a kink there);
separation is located by re-stepping from the start of the step (Illinois method), also where the
sphere crosses the break and comes back within one step (a slow exit just above the sticking
velocity, once missed: the sphere then oscillated for 30 contact times before it left). Capture is the exact energy test: once
y^2/2 + U(z) falls below U at the break point, the sphere can never leave (the damping only removes
energy). A captured sphere is followed at least to its largest penetration (y = 0); one whose
tangential outcome is needed until its friction and twist impulses reach the values that end
sliding and twist, or until it settles.

Regimes left to closed forms instead of a step limit (the engine's, :mod:`.engine`):

* **Inertia-free (overdamped) limit.** Where the damping rate C dwarfs the stiffness (inertia
  ratio |dy_m/dx| / C below the engine's ``INERTIA_FREE_ENTER`` here and ``INERTIA_FREE_RESUME``
  all the way to the equilibrium, relaxation ratio above ``RELAXATION_ENTER``) and the rate lies on
  the slow manifold y_m = -E / C, the sphere creeps into the equilibrium: a capture whose time,
  friction impulse (the total variation of y_m), twist impulse and dissipation are quadratures
  along the path (:func:`_slow_jump`). A captured sphere that creeps inwards or has turned takes
  the path under the engine's looser creeping test (ratio 1e-2). An explicit solver needs ~C^2
  steps there: 2e6 were not enough at zeta = 1e5 (15 % of random JKR/DMT impacts over the extended
  domain had no result before). A Hertz sphere under a damping that vanishes with the contact
  radius (``viscoelastic``) creeps out, and inertia returns just before it leaves: the creep is
  taken along the manifold only while it is inertia-free (the engine's thresholds) and integrated
  again from there, to the exit (e_n then follows the exact overdamped law e_n ~ eta_n0^-5 v^-1,
  tests/test_dem_damping.py; it ended in the step limit above ~4000 critical dampings before).
* **Captured tails.** A captured sphere whose tangential outcome needs the rest of its oscillation
  ends with the linear damped tail about the equilibrium in closed form once its error (~
  amplitude / equilibrium approach) is below ``tail_tolerance`` of J, or after a twentieth of the
  step budget (the integration noise of 15-40 rtol can hold a weakly damped oscillation above the
  settle test indefinitely); then, when weakly damped (C <= 1e-2 omega0), by the method of
  averaging over the undamped orbits (:func:`_averaged_tail`, relative error ~C / omega0).

References
----------
Dormand, J. R. and Prince, P. J. (1980), A family of embedded Runge-Kutta formulae, J. Comput.
Appl. Math. 6:19-26, doi:10.1016/0771-050X(80)90013-3.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from microimpact._numba import njit, njit_batch
from microimpact.model import adhesion_models as am
from microimpact.model import dem_damping as dd
from microimpact.model.contact import check_positive
from microimpact.solvers import DEFAULT_RTOL, dopri, driver, engine
from microimpact.solvers.driver import linear_tail_variation as _linear_tail_variation
from microimpact.solvers.engine import (CAPTURE, INERTIA_FREE_ENTER, INERTIA_FREE_RESUME, OUTCOME_NAMES, REBOUND,
                                       RELAXATION_ENTER, RELAXATION_RESUME, EngineError)
from microimpact.solvers.solution import NormalSolution, SolutionBatch

__all__ = ["solve_normal", "solve_normal_many", "solve_normal_reference", "settled_contact_energy",
           "MODEL_CODES"]

#: the models this module integrates, and their codes in the compiled core
MODEL_CODES = {"jkr": 1, "dmt": 2, "jkr_force": 3, "hertz": 4}
_JKR, _DMT, _JKR_FORCE, _HERTZ = 1, 2, 3, 4  # both JKR codes share the law; they differ where contact breaks
_Q_BREAK_FORCE = am.JKR_Q_BREAK["jkr_force"]  # q^3 = 3, where F = -F_c
_OK, _MAX_STEPS, _STEP_UNDERFLOW = 0, 1, 2
_N = 6  # state: z (q or s), y, tau, D, J, J_a
_MAX_STEPS_DEFAULT = 2_000_000

# The helpers of this solver are compiled as calls, not inlined by numba (``inline="always"``):
# numba's inlining copies and re-types a helper at every call site (the right-hand side sits in the
# seven stages of the unrolled step), which made the first JKR impact compile several times longer;
# LLVM still inlines them when it links the kernel, so the compiled code runs as fast and gives the
# same numbers bit for bit (docs/model.md, "How it is computed").
_jkr_force = njit(cache=True)(am.jkr_nondimensional_force)
_jkr_potential = njit(cache=True)(am.jkr_nondimensional_potential)
_jkr_dissipation = njit(cache=True)(am.jkr_nondimensional_dissipation_rate)
_dmt_force = njit(cache=True)(am.dmt_nondimensional_force)
_dmt_potential = njit(cache=True)(am.dmt_nondimensional_potential)
_dmt_dissipation = njit(cache=True)(am.dmt_nondimensional_dissipation_rate)
_hertz_force = njit(cache=True)(am.hertz_nondimensional_force)
_hertz_potential = njit(cache=True)(am.hertz_nondimensional_potential)
_hertz_dissipation = njit(cache=True)(am.hertz_nondimensional_dissipation_rate)
_dem_force = njit(cache=True)(dd.dem_damping_nondimensional_force)

# --------------------------------------------------------------------------- compiled core
@njit(cache=True)
def _terms(u, args):
    """(d tau/d sigma, dz/d sigma, the net force F, the dissipation rate, the contact radius a) at
    the state u, in the model's units; args = (model, c1, c2, c3, p3)."""
    model, c1, c2, c3, p3 = args
    z, y = u[0], u[1]
    if _is_jkr(model):
        g = 4.0 * (z * z * z - 1.0)  # d tau / d sigma
        dz = y
        f = _jkr_force(z, y, c1, c2)
        p = _jkr_dissipation(z, y, c1, c2)
        a = z * z  # contact radius / a_c
    elif model == _DMT:
        g = z
        dz = 0.5 * y
        f = _dmt_force(z, y, c1, c2)
        p = _dmt_dissipation(z, y, c1, c2)
        a = z  # contact radius / sqrt(R L_D)
    else:
        g = z
        dz = 0.5 * y
        f = _hertz_force(z, y, c1)
        p = _hertz_dissipation(z, y, c1)
        a = z  # contact radius / sqrt(R L)
    fd = _dem_force(a, y, c3, p3)
    return g, dz, f + fd, p + fd * y, a


@njit(cache=True)
def _rhs(u, out, args):
    """d/dsigma of the state u = (z, y, tau, D, J, J_a), written into out."""
    g, dz, f, p, a = _terms(u, args)
    out[0] = dz
    out[1] = -g * f
    out[2] = g
    out[3] = g * p
    out[4] = g * abs(f)
    out[5] = g * a * abs(f)


@njit(cache=True)
def _is_jkr(model):
    """Whether the model's state is JKR's q (else DMT's or Hertz's s)."""
    return model == _JKR or model == _JKR_FORCE


@njit(cache=True)
def _energy(model, z, y):
    """Contact energy y^2/2 + U(z) in the model's units. [-]"""
    if _is_jkr(model):
        return 0.5 * y * y + _jkr_potential(z)
    if model == _DMT:
        return 0.5 * y * y + _dmt_potential(z)
    return 0.5 * y * y + _hertz_potential(z)


#: one Dormand-Prince 5(4) step of the model (the core's, :mod:`microimpact.solvers.dopri`)
_step = dopri.make_step(_rhs, _N)


# --------------------------------------------------------------------------- inertia-free limit
# The force is F = E(z) + C(z) y (static part and damping coefficient, linear in the rate y of
# x = delta / L). When the damping rate C dwarfs the stiffness (C^2 >> dE/dx), the rate relaxes in
# a time 1/C onto the slow manifold y_m(z) = -E / C and the sphere creeps along it into the
# equilibrium, where E = 0. An explicit solver is held to steps of ~1/C by its stability and needs
# ~C^2 of them (2e6 were not enough at zeta = 1e5). On the manifold F = -dy/dtau is small and known:
# the friction impulse still to come is the total variation of y_m, the twist impulse int a |dy_m|,
# the time int dx / y_m, and the energy left is dissipated. The thresholds are the engine's
# (:data:`microimpact.solvers.engine.INERTIA_FREE_ENTER` and the others), so every normal law enters
# the limit where the ring law does, with an error of the order of the inertia ratio.
_GL3_X, _GL3_W = np.polynomial.legendre.leggauss(3)
#: inertia ratio up to which a captured sphere that creeps into the equilibrium is taken along the
#: slow manifold, and the band about it (relative) it must lie in (the engine's creeping test)
CREEP_RATIO = 1e-2
CREEP_BAND = 1e-2
_SLOW_CELLS = 600  # cells of the path, geometric in the distance to the equilibrium (ratio 1.047)
_SLOW_DECADES = 12.0  # the path ends 1e-12 of its length before the equilibrium (y_m is then ~0)


@njit(cache=True)
def _static_and_damping(model, z, c1, c2, c3, p3):
    """(E, C) of F = E(z) + C(z) y: the undamped force and the damping rate (the dissipation rate
    at y = 1). [-]"""
    dem = _dem_force(_radius(model, z), 1.0, c3, p3)
    if _is_jkr(model):
        return _jkr_force(z, 0.0, c1, c2), _jkr_dissipation(z, 1.0, c1, c2) + dem
    if model == _DMT:
        return _dmt_force(z, 0.0, c1, c2), _dmt_dissipation(z, 1.0, c1, c2) + dem
    return _hertz_force(z, 0.0, c1), _hertz_dissipation(z, 1.0, c1) + dem


@njit(cache=True)
def _approach(model, z):
    """x = delta / L of the model's z (q^4 - 4 q for JKR, s^2 for DMT). [-]"""
    return z**4 - 4.0 * z if _is_jkr(model) else z * z


@njit(cache=True)
def _radius(model, z):
    """Contact radius in the model's unit (q^2 for JKR, s for DMT). [-]"""
    return z * z if _is_jkr(model) else z


@njit(cache=True)
def _slow_speed(model, z, c1, c2, c3, p3):
    """y_m(z) = -E / C, the rate on the slow manifold. [-]"""
    e, c = _static_and_damping(model, z, c1, c2, c3, p3)
    return -e / c if c > 0.0 else math.nan  # undamped here (a DEM damping that vanishes with a): no manifold


@njit(cache=True)
def _difference_step(model, z):
    """Step of the central differences along the slow path: relative to z for Hertz, whose path
    ends at s = 0 (where x = s^2 is flat in s, so a step larger than z gives a wrong slope)."""
    return 1e-6 * (abs(z) if model == _HERTZ else max(abs(z), 1.0))


@njit(cache=True)
def _slow_ratios(model, z, z_eq, c1, c2, c3, p3):
    """(inertia ratio |dy_m/dx| / C, relaxation ratio C |x - x_eq| / |y_m|) at z (engine.py)."""
    e, c = _static_and_damping(model, z, c1, c2, c3, p3)
    if not c > 0.0:
        return math.inf, 0.0
    dz = _difference_step(model, z)
    dx = _approach(model, z + dz) - _approach(model, z - dz)
    if dx == 0.0:
        return math.inf, 0.0
    slope = (_slow_speed(model, z + dz, c1, c2, c3, p3) - _slow_speed(model, z - dz, c1, c2, c3, p3)) / dx
    ym = -e / c
    relax = math.inf if ym == 0.0 else c * abs(_approach(model, z) - _approach(model, z_eq)) / abs(ym)
    return abs(slope) / c, relax


@njit(cache=True)
def _slow_time_between(model, z0, z1, c1, c2, c3, p3):
    """tau from z0 to z1 on the slow manifold, int dx / y_m (3-point Gauss-Legendre). [-]"""
    if z1 == z0:  # a state already at the equilibrium (y_m = 0 there): no path (was 0/0)
        return 0.0
    t = 0.0
    for i in range(3):
        z = 0.5 * (z0 + z1) + 0.5 * (z1 - z0) * _GL3_X[i]
        dz = 1e-6 * max(abs(z), 1.0)
        dxdz = (_approach(model, z + dz) - _approach(model, z - dz)) / (2.0 * dz)
        t += 0.5 * (z1 - z0) * _GL3_W[i] * dxdz / _slow_speed(model, z, c1, c2, c3, p3)
    return t


@njit(cache=True)
def _point_value(model, kind, z, target, ya, c1, c2, c3, p3):
    """What :func:`_slow_point` brings to zero: U(z) - target (kind _EV_U), the energy on the slow
    manifold - target (_EV_ENERGY), or target - |y_m(z) - ya| (_EV_J)."""
    if kind == _EV_U:
        return _energy(model, z, 0.0) - target
    ym = _slow_speed(model, z, c1, c2, c3, p3)
    return (_energy(model, z, ym) - target) if kind == _EV_ENERGY else (target - abs(ym - ya))


@njit(cache=True)
def _slow_point(model, kind, target, za, zb_, ya, c1, c2, c3, p3):
    """The z in [za, zb_] where the value of ``kind`` (:func:`_point_value`) reaches zero, by
    bisection (each is monotone there: a cell of the slow path, or one side of the well)."""
    lo, hi = za, zb_
    vlo = _point_value(model, kind, lo, target, ya, c1, c2, c3, p3)
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if (_point_value(model, kind, mid, target, ya, c1, c2, c3, p3) > 0.0) == (vlo > 0.0):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@njit(cache=True)
def _slow_jump(model, u, z_eq, c1, c2, c3, p3, atol_y, threshold, captured, j_target, need_slip, enter, resume, band,
               partial=False):
    """Whether the state u follows the slow manifold into the equilibrium and, if so, the rest of
    the impact in closed form and quadratures.

    Returns (yes, tau_capture, tau_slip_end, tau_end, D, J, J_a, z_end, y_end, complete):
    tau_capture where the energy falls below the capture threshold (NaN if ``captured`` already),
    tau_slip_end where J reaches j_target (NaN if not needed or not reached), and the states at the
    end of the path: the equilibrium (complete), or with ``partial`` the last point of the path that
    is still inertia-free, where the explicit integration takes over again (the engine's
    hand-back: a Hertz sphere under a damping that vanishes with a creeps out along the manifold
    until inertia returns just before it leaves).

    Thresholds: the inertia ratio at most ``enter`` here and ``resume`` on the whole path (the
    relaxation ratio at least 1e-3 and 1e-2 of their inverses, as the engine's), and y within
    ``band`` |y_m| (plus twice the ratio and ten absolute tolerances) of the manifold.
    """
    nan = math.nan
    no = (False, nan, nan, nan, nan, nan, nan, nan, nan, False)
    z = u[0]
    eps, relax = _slow_ratios(model, z, z_eq, c1, c2, c3, p3)
    if not (eps <= enter and relax >= RELAXATION_ENTER * INERTIA_FREE_ENTER / enter):
        return no
    ym = _slow_speed(model, z, c1, c2, c3, p3)
    if abs(u[1] - ym) > (2.0 * eps + band) * abs(ym) + 10.0 * atol_y:
        return no
    d0 = z - z_eq
    ratio = 10.0 ** (-_SLOW_DECADES / _SLOW_CELLS)
    cells = _SLOW_CELLS
    zk = z_eq + d0 * ratio**_SLOW_CELLS  # its far end first: where a damping that vanishes with a fails
    eps, relax = _slow_ratios(model, zk, z_eq, c1, c2, c3, p3)
    complete = eps <= resume and relax >= RELAXATION_RESUME * INERTIA_FREE_RESUME / resume
    if not complete and not partial:
        return no
    for k in range(1, _SLOW_CELLS + 1):  # the whole path (or with partial, a first part) inertia-free
        zk = z_eq + d0 * ratio**k
        eps, relax = _slow_ratios(model, zk, z_eq, c1, c2, c3, p3)
        if not (eps <= resume and relax >= RELAXATION_RESUME * INERTIA_FREE_RESUME / resume):
            if not partial or k == 1:
                return no
            cells, complete = k - 1, False
            break
    tau, jf, ja = u[2], u[4] + abs(u[1] - ym), u[5] + _radius(model, z) * abs(u[1] - ym)
    tau_cap, tau_slip = nan, nan
    need_cap = not captured
    za, ya = z, ym
    for k in range(1, cells + 1):
        zb_ = z_eq + d0 * ratio**k
        yb = _slow_speed(model, zb_, c1, c2, c3, p3)
        dj = abs(yb - ya)
        if need_cap and _energy(model, zb_, yb) < threshold:
            zc = _slow_point(model, _EV_ENERGY, threshold, za, zb_, ya, c1, c2, c3, p3)
            tau_cap = tau + _slow_time_between(model, za, zc, c1, c2, c3, p3)
            need_cap = False
        if need_slip and jf + dj >= j_target:
            zs = _slow_point(model, _EV_J, j_target - jf, za, zb_, ya, c1, c2, c3, p3)
            tau_slip = tau + _slow_time_between(model, za, zs, c1, c2, c3, p3)
            need_slip = False
        for i in range(3):
            zi = 0.5 * (za + zb_) + 0.5 * (zb_ - za) * _GL3_X[i]
            dzi = _difference_step(model, zi)
            slope = (_slow_speed(model, zi + dzi, c1, c2, c3, p3) - _slow_speed(model, zi - dzi, c1, c2, c3, p3)) / (2.0 * dzi)
            ja += 0.5 * abs(zb_ - za) * _GL3_W[i] * _radius(model, zi) * abs(slope)
        tau += _slow_time_between(model, za, zb_, c1, c2, c3, p3)
        jf += dj
        za, ya = zb_, yb
    if not complete:  # handed back at (za, ya) on the manifold
        dissipated = u[3] + _energy(model, u[0], u[1]) - _energy(model, za, ya)
        return True, tau_cap, tau_slip, tau, dissipated, jf, ja, za, ya, False
    # the last 1e-12 of the path: y_m falls from ya to 0 at z_eq
    jf += abs(ya)
    ja += _radius(model, z_eq) * abs(ya)
    if need_slip and jf >= j_target:
        tau_slip = tau
    dissipated = u[3] + _energy(model, u[0], u[1]) - _energy(model, z_eq, 0.0)
    return True, tau_cap, tau_slip, tau, dissipated, jf, ja, z_eq, 0.0, True


# --------------------------------------------------------------------------- averaged tail
_GL16_X, _GL16_W = np.polynomial.legendre.leggauss(16)


@njit(cache=True)
def _orbit_integrals(model, e, z_lo, z_eq, c1, c2, c3, p3):
    """Per cycle of the undamped orbit at energy e in the well: (energy lost to the damping,
    total variation of y, int a |dy|). On each side of z_eq, z = end + (z_eq - end) t^2 from the
    turning point makes y ~ sqrt(z - end) smooth in t (16-point Gauss-Legendre); int a |dy| by
    parts, 2 a_eq y_max - int y da (inwards) + int y da (outwards), per half-cycle."""
    ymax = math.sqrt(max(2.0 * (e - _energy(model, z_eq, 0.0)), 0.0))
    za = _slow_point(model, _EV_U, e, z_lo, z_eq, 0.0, c1, c2, c3, p3)
    zhi = 2.0 * z_eq
    while _energy(model, zhi, 0.0) < e:
        zhi *= 2.0
    zb_ = _slow_point(model, _EV_U, e, z_eq, zhi, 0.0, c1, c2, c3, p3)
    loss = 0.0
    twist = 2.0 * _radius(model, z_eq) * ymax
    for side in range(2):
        end = za if side == 0 else zb_
        width = z_eq - end
        for i in range(_GL16_X.shape[0]):
            t = 0.5 * (_GL16_X[i] + 1.0)
            z = end + width * t * t
            y = math.sqrt(max(2.0 * (e - _energy(model, z, 0.0)), 0.0))
            dzdt = 2.0 * width * t * 0.5 * _GL16_W[i]  # dz/dt times the weight on [0, 1]
            dz = 1e-6 * max(abs(z), 1.0)
            dxdz = (_approach(model, z + dz) - _approach(model, z - dz)) / (2.0 * dz)
            dadz = (_radius(model, z + dz) - _radius(model, z - dz)) / (2.0 * dz)
            c = _static_and_damping(model, z, c1, c2, c3, p3)[1]
            loss += c * y * dxdz * abs(dzdt)  # int C y dx over the half-orbit's side
            # - int_{z_a}^{z_eq} y da + int_{z_eq}^{z_b} y da: both are - sum y a' dz/dt w (dz/dt < 0 outside)
            twist -= y * dadz * dzdt
    return 2.0 * loss, 4.0 * ymax, 2.0 * twist


@njit(cache=True)
def _orbit(e, oargs):
    """:func:`_orbit_integrals` with its parameters as one tuple (the driver's averaging calls it)."""
    model, z_lo, z_eq, c1, c2, c3, p3 = oargs
    return _orbit_integrals(model, e, z_lo, z_eq, c1, c2, c3, p3)


#: the driver's method of averaging over this law's orbits
_averaged = driver.make_averaged_tail(_orbit)


@njit(cache=True)
def _averaged_tail(model, e_now, z_lo, z_eq, c1, c2, c3, p3):
    """(J, J_a) still to come for a weakly damped captured sphere of energy e_now: the driver's
    method of averaging (:func:`microimpact.solvers.driver.make_averaged_tail`) over the undamped
    orbits of the model, from the bottom of the well U(z_eq); relative error ~ C / omega0."""
    return _averaged(e_now, _energy(model, z_eq, 0.0), (model, z_lo, z_eq, c1, c2, c3, p3))


#: what :func:`_locate` finds: z (the boundary), the contact energy, the friction impulse J, y
#: (the largest penetration at y = 0); numpy integers, so that one specialization is compiled for all
_EV_Z, _EV_ENERGY, _EV_J, _EV_Y = np.int64(0), np.int64(1), np.int64(2), np.int64(3)
_EV_F = np.int64(5)  # the net normal force, whose zeros are kinks of |F_n| (integrated into J, J_a)
_EV_U = np.int64(4)  # the potential U(z), for the turning points of an orbit (_slow_point only)


@njit(cache=True)
def _event_value(u, kind, args):
    model = args[0]
    if kind == _EV_F:
        return _terms(u, args)[2]
    if kind == _EV_Z:
        return u[0]
    if kind == _EV_ENERGY:
        return _energy(model, u[0], u[1])
    if kind == _EV_Y:
        return u[1]
    return u[4]


#: the step length at which an event value reaches its target, solved on the step (Illinois method)
_root = dopri.make_root_on_step(_step, _event_value)


@njit(cache=True)
def _locate(model, kind, target, u0, k1, h, c1, c2, c3, p3, k, tmp, u1, err):
    """Re-step from u0 to the step length in (0, h] at which the event value ``kind`` equals
    ``target`` (u1 holds the state at h on entry); u1 then holds the state there."""
    args = (model, c1, c2, c3, p3)
    fa = _event_value(u0, kind, args) - target
    fb = _event_value(u1, kind, args) - target
    return _root(kind, target, fa, fb, 1e-15 * max(1.0, abs(target)), h, u0, k1, args, args, k, tmp, u1, err)


@njit(cache=True)
def _event_state(model, kind, target, u0, u1, k1, h, c1, c2, c3, p3):
    """The state where the event value ``kind`` reaches ``target`` within the accepted step
    u0 -> u1 of length h, by re-stepping in scratch arrays (the step itself is kept). What it
    replaced was O(h^2) or O(h^4) in the step: the slip-end time interpolated linearly in J (1e-4
    off at rtol 1e-9), the capture time at the step's end (6 % for DMT, 3x for a slow JKR
    impact), the largest penetration as the maximum of the step's cubic Hermite interpolant (2e-8,
    and its end was wrong where the step also separated)."""
    ks = np.empty((7, _N))
    us = u1.copy()
    tmp = np.empty(_N)
    err = np.empty(_N)
    _locate(model, kind, target, u0, k1, h, c1, c2, c3, p3, ks, tmp, us, err)
    return us


@njit(cache=True)
def _start(model, y0, c1, c2, c3, p3, rtol):
    """The state at first contact and the constants of one impact: returns (u, k1, zb, z_eq,
    threshold, e_eq, x_eq, c_eq, omega_eq, atol, h): the state and its derivative, where contact
    breaks, the equilibrium, the capture threshold (the energy at the break), the energy, approach,
    damping rate and stiffness (sqrt(dE/dx)) at the equilibrium, the absolute tolerances and the
    first step."""
    u = np.zeros(_N)
    k1 = np.zeros(_N)
    if _is_jkr(model):  # breaks at q = 1 (displacement-controlled) or q^3 = 3 (force-controlled)
        zb, z_eq = (_Q_BREAK_FORCE if model == _JKR_FORCE else 1.0), 6.0 ** (1.0 / 3.0)
        u[0] = 4.0 ** (1.0 / 3.0)
    else:  # DMT's equilibrium s = 1; Hertz rests at s = 0 (reached only by an inertia-free creep)
        zb, z_eq = 0.0, (1.0 if model == _DMT else 0.0)
        u[0] = 0.0
    u[1] = y0
    threshold = _energy(model, zb, 0.0)
    e_eq = _energy(model, z_eq, 0.0)
    x_eq = _approach(model, z_eq)
    c_eq = _static_and_damping(model, z_eq, c1, c2, c3, p3)[1]
    omega_eq = 1.0  # Hertz: no oscillation about s = 0 (the captured tail below is never reached)
    if model != _HERTZ:  # the stiffness dE/dx at the equilibrium, by a central difference
        dz_eq = 1e-6 * z_eq
        omega_eq = math.sqrt((_static_and_damping(model, z_eq + dz_eq, c1, c2, c3, p3)[0]
                              - _static_and_damping(model, z_eq - dz_eq, c1, c2, c3, p3)[0])
                             / (_approach(model, z_eq + dz_eq) - _approach(model, z_eq - dz_eq)))
    yref = max(1.0, y0)
    zref = max(1.0, u[0])
    # y to rtol y0: e_n = -y_end / y0 is then accurate to rtol also for slow impacts (y0 < 1)
    atol = np.array([rtol * zref, rtol * y0, rtol * zref, rtol * 0.5 * yref * yref, rtol * yref, rtol * yref * zref])
    _rhs(u, k1, (model, c1, c2, c3, p3))
    h = 1e-2 * min(1.0, 1.0 / y0)
    return u, k1, zb, z_eq, threshold, e_eq, x_eq, c_eq, omega_eq, atol, h


#: what :func:`_creep` tells the loop: nothing happened, the integration resumes from a new state,
#: the impact ended at the equilibrium
_CREEP_NONE, _CREEP_RESUME, _CREEP_END = driver.CREEP_NONE, driver.CREEP_RESUME, driver.CREEP_END


@njit(cache=True)
def _creep(model, u, k1, z_eq, c1, c2, c3, p3, atol_y, threshold, outcome, j_target, tau_slip, tau_cap, e_cap,
           zmax, turned):
    """The inertia-free creep along the slow manifold (:func:`_slow_jump`) from the strongly damped
    state u, if it applies. Returns (action, outcome, tau_cap, tau_slip, e_cap, zmax): action
    _CREEP_END where the rest of the impact is taken in closed form (a capture; u is then the
    equilibrium), _CREEP_RESUME where a Hertz creep is handed back to the integration (u and k1
    the state and derivative there), _CREEP_NONE otherwise."""
    # a captured sphere creeping into the equilibrium: the engine's looser creeping test
    # (what is left of J, J_a then carries an error of ~1e-2 of itself); else only where
    # inertia is negligible all the way. A Hertz sphere that creeps out inertia-free all the
    # way to s = 0 never leaves (e_n = 0 whatever the error of the test): the creeping test too
    creep = model == _HERTZ or outcome == CAPTURE and (turned or u[0] < z_eq)
    jumped, tc, ts, te, dd, jj, jja, _, _, _ = _slow_jump(
        model, u, z_eq, c1, c2, c3, p3, atol_y, threshold, outcome == CAPTURE, j_target,
        j_target > 0.0 and math.isnan(tau_slip), CREEP_RATIO if creep else INERTIA_FREE_ENTER,
        CREEP_RATIO if creep else INERTIA_FREE_RESUME, CREEP_BAND if creep else 0.0)
    if not jumped and model == _HERTZ:
        # a damping that vanishes with a (viscoelastic): inertia returns before s = 0, so the
        # creep is taken along the manifold only while it is inertia-free (the engine's
        # thresholds, error ~ their square), then integrated again to the exit
        moved, tc, ts, te, dd, jj, jja, z_end, y_end, whole = _slow_jump(
            model, u, z_eq, c1, c2, c3, p3, atol_y, threshold, True, j_target,
            j_target > 0.0 and math.isnan(tau_slip), INERTIA_FREE_ENTER, INERTIA_FREE_RESUME, 0.0, True)
        jumped = moved and whole
        if moved and not whole:
            if not math.isnan(ts):
                tau_slip = ts
            u[0], u[1], u[2], u[3], u[4], u[5] = z_end, y_end, te, dd, jj, jja
            _rhs(u, k1, (model, c1, c2, c3, p3))
            return _CREEP_RESUME, outcome, tau_cap, tau_slip, e_cap, zmax
    if not jumped:
        return _CREEP_NONE, outcome, tau_cap, tau_slip, e_cap, zmax
    # the inertia-free limit: the rest of the impact in closed form, a capture
    if outcome == REBOUND:
        outcome = CAPTURE
        tau_cap = u[2] if math.isnan(tc) else tc
        e_cap = threshold
    if not math.isnan(ts):
        tau_slip = ts
    if u[0] < z_eq:  # crept inwards: the equilibrium is the supremum of the approach
        zmax = max(zmax, z_eq)
    u[0], u[1], u[2], u[3], u[4], u[5] = z_eq, 0.0, te, dd, jj, jja
    return _CREEP_END, outcome, tau_cap, tau_slip, e_cap, zmax


@njit(cache=True)
def _captured_end(model, u, e_now, zmax, turned, need_tail, tail_tol, j_stop, ja_stop, long_tail, zb, z_eq, e_eq,
                  e_cap, x_eq, c_eq, omega_eq, threshold, c1, c2, c3, p3):
    """Whether the integration of a captured sphere (state u, energy e_now) can stop; returns
    (done, zmax). The friction and twist impulses still to come are added to u[4], u[5] in closed
    form where the linear or the averaged tail ends it. ``long_tail``: a twentieth of the step
    budget is spent."""
    # settled: oscillation amplitude below tail_tol (energy ratio floored at 1e-14, above
    # the round-off of the energy near the bottom of the well)
    if e_now - e_eq <= max(tail_tol * tail_tol, 1e-14) * (e_cap - e_eq):
        if not turned:  # crept into the equilibrium without turning: its supremum
            zmax = max(zmax, z_eq)
        return True, zmax
    # not before the largest penetration: a capture found on the way in (at the first
    # step for a slow JKR impact) stopped short of it, up to 6x at rtol 1e-9
    if turned and (not need_tail or u[4] >= j_stop and u[5] >= ja_stop):
        return True, zmax
    if turned and c_eq == 0.0 and long_tail and math.isfinite(j_stop) and math.isfinite(ja_stop):
        # undamped: the orbit keeps its energy, so J and J_a grow by the same amount each period
        # without end and reach any finite stop; the stops are the outcome (the step limit before:
        # an undamped JKR capture of 3.7 um/s, case 7862 of seed 0 in the stress sweep)
        u[4] = max(u[4], j_stop)
        u[5] = max(u[5], ja_stop)
        return True, zmax
    if turned and c_eq > 0.0:  # (undamped: the oscillation never ends; j_stop ends it)
        # the linear damped tail about the equilibrium in closed form (the engine's), once its
        # relative error (~ amplitude / x_eq) makes an error below tail_tol of J, or after a
        # twentieth of the step budget (integration noise of 15-40 rtol can hold a weakly
        # damped oscillation above the settle test indefinitely)
        dxl = _approach(model, u[0]) - x_eq
        tail = _linear_tail_variation(dxl, u[1], omega_eq, c_eq)
        amp = math.sqrt(dxl * dxl + (u[1] / omega_eq) ** 2)
        if long_tail and c_eq <= 1e-2 * omega_eq and e_now < threshold:  # weakly damped: averaged
            jt, jat = _averaged_tail(model, e_now, zb, z_eq, c1, c2, c3, p3)
            u[4] += jt
            u[5] += jat
            return True, zmax
        if amp / x_eq * tail <= tail_tol * u[4] or long_tail:
            u[4] += tail
            u[5] += _radius(model, z_eq) * tail
            return True, zmax
    return False, zmax


# --------------------------------------------------------------------------- the laws in the one driver
# The law's parameters p = (model, c1, c2, c3, p3, y0, need_tail, tail_tol, j_target, j_stop, ja_stop)
# and its bookkeeping w (indices below; flags as 0.0 / 1.0) for the driver (:mod:`.driver`), which
# owns the loop, the error control and the budgets.
_W_OUTCOME, _W_TURNED, _W_TAU_CAP, _W_TAU_SLIP, _W_E_CAP, _W_ZMAX, _W_E_NOW = 0, 1, 2, 3, 4, 5, 6
_W_ZB, _W_Z_EQ, _W_THRESHOLD, _W_E_EQ, _W_X_EQ, _W_C_EQ, _W_OMEGA_EQ = 7, 8, 9, 10, 11, 12, 13
_W_SIZE = 14


@njit(cache=True)
def _law_start(p, rtol, rec, rec_cap):
    """The driver's start (:func:`_start`): the state, its derivative, the first step, the
    tolerances and the bookkeeping of one impact."""
    u, k1, zb, z_eq, threshold, e_eq, x_eq, c_eq, omega_eq, atol, h = _start(p[0], p[5], p[1], p[2], p[3], p[4], rtol)
    w = np.zeros(_W_SIZE)
    w[_W_OUTCOME], w[_W_TAU_CAP], w[_W_TAU_SLIP], w[_W_E_CAP], w[_W_ZMAX] = REBOUND, math.nan, math.nan, threshold, u[0]
    w[_W_ZB], w[_W_Z_EQ], w[_W_THRESHOLD], w[_W_E_EQ] = zb, z_eq, threshold, e_eq
    w[_W_X_EQ], w[_W_C_EQ], w[_W_OMEGA_EQ] = x_eq, c_eq, omega_eq
    return u, k1, h, atol, w


@njit(cache=True, inline="always")
def _law_args(p, w):
    """The right-hand side's arguments: (model, C1, C2, C3, p3)."""
    return (p[0], p[1], p[2], p[3], p[4])


@njit(cache=True, inline="always")
def _law_too_small(h, u):
    return h < 1e-14 * max(1.0, abs(u[2]))


@njit(cache=True, inline="always")
def _law_events(u, u1, k1, h, p, w, atol, rtol, k, tmp, err, rec, rec_cap):
    """The events within the accepted step u -> u1 (the kink of |F_n|, separation, the largest
    penetration, the end of sliding, the capture), and the advance to its end."""
    model, c1, c2, c3, p3, j_target = p[0], p[1], p[2], p[3], p[4], p[8]
    args = (model, c1, c2, c3, p3)
    outcome, zb, zmax, turned, tau_slip = int(w[_W_OUTCOME]), w[_W_ZB], w[_W_ZMAX], w[_W_TURNED] != 0.0, w[_W_TAU_SLIP]
    threshold = w[_W_THRESHOLD]
    # the step ends where the net force changes sign: |F_n|, integrated into J and J_a, has a
    # kink there, across which a step loses order (its error then hides in the norm's mean;
    # measured: the rebound velocity 4x its tolerance at rtol 1e-8). Not where the kink cannot
    # matter: integrating |F| instead of F across it differs by at most h |g| min(|F0|, |F1|),
    # and below J's tolerance (a captured sphere at rest, whose F is round-off about zero:
    # located at every step, 1.9e6 steps) the step is kept. A zero at the very start of the
    # step (the one just located) is not located again.
    hk = h
    t0, t1 = _terms(u, args), _terms(u1, args)
    f0, f1 = t0[2], t1[2]
    if ((f0 > 0.0 and f1 < 0.0) or (f0 < 0.0 and f1 > 0.0)) and h * max(abs(t0[0]), abs(t1[0])) * min(
            abs(f0), abs(f1)) > atol[4] + rtol * abs(u1[4]):
        hk = _root(_EV_F, 0.0, f0, f1, 0.0, h, u, k1, args, args, k, tmp, u1, err)
        if hk < 1e-9 * h:
            hk = h
            _step(u, k1, h, args, k, tmp, u1, err)
    separated = u1[0] <= zb and u1[1] < 0.0 and u[0] > zb and outcome == REBOUND
    if not separated and outcome == REBOUND and u[0] > zb and u[1] < 0.0 and u1[1] >= 0.0 and _event_state(
            model, _EV_Y, 0.0, u, u1, k1, hk, c1, c2, c3, p3)[0] <= zb:
        # the sphere crossed the break, turned beyond it and came back within one step (a slow
        # exit just above the sticking velocity): it left at the crossing
        hk = _locate(model, _EV_Y, 0.0, u, k1, hk, c1, c2, c3, p3, k, tmp, u1, err)
        separated = True
    if separated:
        _locate(model, _EV_Z, zb, u, k1, hk, c1, c2, c3, p3, k, tmp, u1, err)
    if u[1] > 0.0 and u1[1] <= 0.0:
        zmax = max(zmax, _event_state(model, _EV_Y, 0.0, u, u1, k1, hk, c1, c2, c3, p3)[0])
        turned = True
    zmax = max(zmax, u1[0])
    if j_target > 0.0 and math.isnan(tau_slip) and u1[4] >= j_target:
        tau_slip = _event_state(model, _EV_J, j_target, u, u1, k1, hk, c1, c2, c3, p3)[2]
    e_now = _energy(model, u1[0], u1[1])
    if not separated and outcome == REBOUND and e_now < threshold and model != _HERTZ:
        w[_W_OUTCOME] = CAPTURE
        w[_W_E_CAP] = e_now
        # where the energy fell below the threshold (at the start: captured from first contact)
        w[_W_TAU_CAP] = u[2] if _energy(model, u[0], u[1]) < threshold else _event_state(
            model, _EV_ENERGY, threshold, u, u1, k1, hk, c1, c2, c3, p3)[2]
    for i in range(_N):
        u[i] = u1[i]
    for i in range(_N):
        k1[i] = k[6, i]
    w[_W_ZMAX], w[_W_TURNED], w[_W_TAU_SLIP], w[_W_E_NOW] = zmax, 1.0 if turned else 0.0, tau_slip, e_now
    return driver.END if separated else driver.GO_ON


@njit(cache=True, inline="always")
def _law_creep(u, k1, p, w, atol, rec, rec_cap):
    """The inertia-free creep (:func:`_creep`) where the sphere is strongly damped here (Hertz, whose
    DEM damping may vanish with a: also once turned; a strongly damped approach can end with y at
    the noise level of atol, never seen to turn). The cheap test first."""
    model, c1, c2, c3, p3 = p[0], p[1], p[2], p[3], p[4]
    turned = w[_W_TURNED] != 0.0
    if not ((model == _HERTZ and turned) or _static_and_damping(model, u[0], c1, c2, c3, p3)[1] >= 10.0):
        return driver.CREEP_NONE
    action, outcome, tau_cap, tau_slip, e_cap, zmax = _creep(
        model, u, k1, w[_W_Z_EQ], c1, c2, c3, p3, atol[1], w[_W_THRESHOLD], int(w[_W_OUTCOME]), p[8], w[_W_TAU_SLIP],
        w[_W_TAU_CAP], w[_W_E_CAP], w[_W_ZMAX], turned)
    w[_W_OUTCOME], w[_W_TAU_CAP], w[_W_TAU_SLIP], w[_W_E_CAP], w[_W_ZMAX] = outcome, tau_cap, tau_slip, e_cap, zmax
    return action


@njit(cache=True, inline="always")
def _law_captured_end(u, k1, p, w, atol, long_tail):
    """Whether a captured sphere may stop (:func:`_captured_end`)."""
    if int(w[_W_OUTCOME]) != CAPTURE:
        return False
    model, c1, c2, c3, p3, need_tail, tail_tol, j_stop, ja_stop = p[0], p[1], p[2], p[3], p[4], p[6], p[7], p[9], p[10]
    done, zmax = _captured_end(model, u, w[_W_E_NOW], w[_W_ZMAX], w[_W_TURNED] != 0.0, need_tail, tail_tol, j_stop,
                               ja_stop, long_tail, w[_W_ZB], w[_W_Z_EQ], w[_W_E_EQ], w[_W_E_CAP], w[_W_X_EQ], w[_W_C_EQ],
                               w[_W_OMEGA_EQ], w[_W_THRESHOLD], c1, c2, c3, p3)
    w[_W_ZMAX] = zmax
    return done


@njit(cache=True)
def _law_finish(status, u, p, w, n_steps, n_rej):
    """The driver's :class:`~microimpact.solvers.driver.Trace` of one impact, in the model's units
    (the final energy relative to free flight)."""
    model = p[0]
    e_free = _energy(model, 4.0 ** (1.0 / 3.0) if _is_jkr(model) else 0.0, 0.0)
    return driver.Trace(status, int(w[_W_OUTCOME]), u[1], u[2], u[3], u[4], u[5], w[_W_ZMAX], w[_W_TAU_CAP],
                        w[_W_TAU_SLIP], _energy(model, u[0], u[1]) - e_free, n_steps, n_rej, 0, u, 0, 0)


#: the one driver (:mod:`.driver`) running the JKR, DMT and Hertz laws
_drive = driver.make_driver(driver.Law(_law_start, _law_args, _step, _law_too_small, driver.make_error_norm(_N),
                                       _law_events, _law_creep, _law_captured_end, _law_finish, _N))
_NO_RECORD = np.zeros((1, 3))


@njit(cache=True)
def _integrate(model, y0, c1, c2, c3, p3, rtol, need_tail, tail_tol, j_target, j_stop, ja_stop, max_steps):
    """One normal impact in the model's nondimensional units, by the one driver; its
    :class:`~microimpact.solvers.driver.Trace`."""
    return _drive((model, c1, c2, c3, p3, y0, need_tail, tail_tol, j_target, j_stop, ja_stop), rtol, max_steps,
                  _NO_RECORD, 0)


@njit_batch
def _integrate_many(model, y0, c1, c2, c3, p3, rtol, need_tail, tail_tol, j_stop, ja_stop, max_steps, out):
    """:func:`_integrate` over arrays of speeds on all cores; row i of out holds impact i."""
    for i in prange(y0.size):
        r = _integrate(model, y0[i], c1[i], c2[i], c3[i], p3, rtol, need_tail[i], tail_tol, 0.0, j_stop[i], ja_stop[i],
                       max_steps)
        driver.write_common_row(r, out, i)
        out[i, 9] = r.tau_slip_end
        out[i, 10] = r.final_energy
        out[i, 11] = r.n_steps
        out[i, 12] = r.n_rejected


# --------------------------------------------------------------------------- Python interface
def _setup(contact, normal_speed):
    """(model code, scales, y0, C1, C2, C3, p3) of impacts at ``normal_speed`` [m/s] (scalar or array).

    C3 a^p3 y is the DEM damping (:func:`microimpact.model.dem_damping.dem_damping_law`) in the
    model's units; the Hertz law (ring, f0 = 0, with a DEM damping) has speed-dependent units."""
    if _hertz(contact):
        sc, model = am.hertz_scales(contact, normal_speed), _HERTZ
    else:
        sc, model = am.adhesion_scales(contact), MODEL_CODES[contact.normal_model]
    u = sc.speed
    c_h, c_a = contact.damping_coefficients(normal_speed)
    eta, p3 = dd.dem_damping_law(contact)
    c3 = eta * sc.radius**p3 * u / sc.force
    return model, sc, normal_speed / u, c_h * u, c_a * u, c3, p3


def _penetration(model, sc, zmax):
    """Largest approach delta [m] from the largest z (q for JKR, s for DMT)."""
    return sc.length * (zmax**4 - 4.0 * zmax if model in (_JKR, _JKR_FORCE) else zmax * zmax)


#: below this e_n the exit rate is the more accurate e_n (the energy balance's is ~sqrt(rtol))
_EXIT_RATE_BELOW = 0.1


def _restitution(model, y0, damping_loss, y_end):
    """e_n of a rebound from the energy balance, sqrt(1 - 2 (D + H) / y0^2), or, below
    ``_EXIT_RATE_BELOW``, the exit rate -y_end / y0. [-]

    D is the integrated damping dissipation and H the JKR hysteresis of the model's break (0 for
    DMT and Hertz), in units F L. The energy balance is more accurate than the exit rate where e_n
    is not small (a few 1e-9 against 1e-8 at rtol 1e-8, checked against the reference at rtol
    1e-13), and exact without damping; but its error in e_n grows as rtol / e_n and reaches
    ~sqrt(rtol) as e_n -> 0 (a strongly damped Hertz rebound of true e_n 1e-6 gave 1e-4), where the
    exit rate keeps its error ~rtol.
    """
    hysteresis = {_JKR: am.JKR_HYSTERESIS, _JKR_FORCE: am.JKR_HYSTERESIS_FORCE}.get(model, 0.0)
    loss = np.asarray(damping_loss, dtype=float) + hysteresis
    balance = np.sqrt(np.maximum(1.0 - 2.0 * loss / np.square(y0), 0.0))
    return np.where(balance >= _EXIT_RATE_BELOW, balance, np.maximum(-np.asarray(y_end, dtype=float), 0.0) / y0)


def _hertz(contact):
    """Without adhesion JKR and DMT are the Hertz law."""
    return contact.adhesion_line_force == 0.0


def _law_name(contact):
    """The normal law and the damping, as an error message names them."""
    law = "hertz" if _hertz(contact) else contact.normal_model
    return law if contact.damping_model == "paper" else f"{law} ({contact.damping_model} damping)"


def _paper_hertz(contact):
    """The Hertz law with the paper's damping: the paper's engine solves it (a DEM damping is solved here)."""
    return _hertz(contact) and contact.damping_model == "paper"


def solve_normal(contact, normal_speed: float, *, rtol: float = DEFAULT_RTOL, need_tail: bool = False,
                 tail_tolerance: float | None = None, friction_impulse_target: float | None = None,
                 friction_impulse_stop: float = math.inf, twist_impulse_stop: float = math.inf,
                 max_steps: int = _MAX_STEPS_DEFAULT) -> NormalSolution:
    """Solve the JKR or DMT normal contact of one impact (``contact.normal_model``).

    Parameters are those of :func:`microimpact.solvers.engine.solve_normal` (no trajectory):
    ``normal_speed`` [m/s], ``rtol`` [-], ``need_tail``, ``tail_tolerance`` [-],
    ``friction_impulse_target`` [N s], ``friction_impulse_stop`` [N s], ``twist_impulse_stop`` [N m s].

    Returns
    -------
    NormalSolution
        ``dissipated_energy`` is all the energy the normal contact removes: damping plus, for JKR,
        the adhesion hysteresis of the contact cycle (``JKR_HYSTERESIS`` pi w a_c^2 for a rebound). [J]

    References
    ----------
    Johnson, K. L., Kendall, K. and Roberts, A. D. (1971), Surface energy and the contact of
    elastic solids, Proc. R. Soc. Lond. A 324:301-313, doi:10.1098/rspa.1971.0141.

    Examples
    --------
    Undamped, a JKR rebound loses only the hysteresis H of the contact cycle,
    e_n = sqrt(1 - 2 H / y0^2) in the JKR units:

    >>> import math
    >>> from microimpact.model import adhesion_models as am
    >>> from microimpact.model.parameters import TABLE1_ROW2
    >>> c = TABLE1_ROW2.with_(normal_model="jkr", zeta_hertz=0.0, zeta_adhesion=0.0)
    >>> sc = am.adhesion_scales(c)
    >>> y0 = 2.0 / (sc.length / sc.time)
    >>> abs(solve_normal(c, 2.0).e_n - math.sqrt(1.0 - 2.0 * am.JKR_HYSTERESIS / y0**2)) < 1e-8
    True

    Strongly damped, the sphere creeps into the equilibrium (the inertia-free limit, a few dozen
    steps); the normal force keeps its sign, so int |F_n| dt is the normal momentum m v:

    >>> s = solve_normal(c.with_(zeta_adhesion=1e6), 0.05)
    >>> s.outcome, round(s.friction_impulse / (c.mass * 0.05), 9), s.n_steps < 1000
    ('capture', 1.0, True)
    """
    v = check_positive("normal_speed", normal_speed)
    if _paper_hertz(contact):
        return engine.solve_normal(contact.with_(normal_model="ring"), v, rtol=rtol, need_tail=need_tail,
                                   tail_tolerance=tail_tolerance, friction_impulse_target=friction_impulse_target,
                                   friction_impulse_stop=friction_impulse_stop, twist_impulse_stop=twist_impulse_stop,
                                   max_steps=max_steps)
    model, sc, y0, c1, c2, c3, p3 = _setup(contact, v)
    sc = am.AdhesionScales(*(float(x) for x in (sc.length, sc.force, sc.time, sc.radius)))
    j_unit = sc.force * sc.time
    jt = 0.0 if friction_impulse_target is None else float(friction_impulse_target) / j_unit
    r = _integrate(model, y0, c1, c2, c3, p3, float(rtol), bool(need_tail), float(rtol if tail_tolerance is None else tail_tolerance),
                   jt, friction_impulse_stop / j_unit, twist_impulse_stop / (j_unit * sc.radius), int(max_steps))
    if r.status != _OK:
        raise EngineError(f"{_law_name(contact)} solver failed for normal speed {v!r} m/s after {r.n_steps} steps")
    captured = r.outcome == CAPTURE
    e_unit = sc.force * sc.length
    e_n = 0.0 if captured else float(_restitution(model, y0, r.dissipated, r.y_end))
    return NormalSolution(
        outcome=OUTCOME_NAMES[int(r.outcome)],
        e_n=e_n,
        contact_time=math.inf if captured else r.tau_end * sc.time,
        capture_time=r.tau_capture * sc.time,
        max_penetration=_penetration(model, sc, r.max_approach),
        friction_impulse=r.friction_impulse * j_unit,
        twist_impulse=r.twist_impulse * j_unit * sc.radius,
        dissipated_energy=0.5 * y0 * y0 * (1.0 - e_n * e_n) * e_unit if not captured else r.dissipated * e_unit,
        final_energy=r.final_energy * e_unit if captured else 0.5 * (e_n * y0) ** 2 * e_unit,
        slip_end_time=r.tau_slip_end * sc.time,
        n_steps=int(r.n_steps),
        n_rejected=int(r.n_rejected),
        stop_reason=driver.stop_reason(r.status, captured, need_tail),
    )


def solve_normal_many(contact, normal_speed, need_tail=None, *, rtol: float = DEFAULT_RTOL,
                      tail_tolerance: float | None = None, max_steps: int = _MAX_STEPS_DEFAULT,
                      friction_impulse_stop=math.inf, twist_impulse_stop=math.inf) -> SolutionBatch:
    """JKR or DMT normal solves of many speeds in parallel; the
    :class:`~microimpact.solvers.solution.SolutionBatch` of :func:`microimpact.solvers.engine.solve_normal_many`
    (SI arrays).

    Parameters as there: ``normal_speed`` [m/s] (1-D, > 0), ``need_tail`` per speed,
    ``friction_impulse_stop`` [N s] and ``twist_impulse_stop`` [N m s] per speed.

    References
    ----------
    Johnson, Kendall & Roberts (1971)

    Derjaguin, B. V., Muller, V. M. and Toporov, Yu. P. (1975), Effect of contact deformations on
    the adhesion of particles, J. Colloid Interface Sci. 53:314-326,
    doi:10.1016/0021-9797(75)90018-1

    Dormand & Prince (1980)

    Examples
    --------
    An undamped JKR impact at twice the sticking velocity v_s rebounds with
    e_n = sqrt(1 - (v_s / v)^2) = sqrt(3) / 2 (the adhesion hysteresis is the only loss):

    >>> import numpy as np
    >>> from microimpact.model.adhesion_models import jkr_sticking_velocity
    >>> from microimpact.model.parameters import TABLE1_ROW2
    >>> c = TABLE1_ROW2.with_(normal_model="jkr", zeta_hertz=0.0, zeta_adhesion=0.0)
    >>> r = solve_normal_many(c, np.array([2.0 * jkr_sticking_velocity(c)]), rtol=1e-10)
    >>> round(float(r["e_n"][0]), 8) == round(3**0.5 / 2, 8)
    True
    """
    if _paper_hertz(contact):
        return engine.solve_normal_many(contact.with_(normal_model="ring"), normal_speed, need_tail, rtol=rtol,
                                        tail_tolerance=tail_tolerance, max_steps=max_steps,
                                        friction_impulse_stop=friction_impulse_stop, twist_impulse_stop=twist_impulse_stop)
    v = np.ascontiguousarray(normal_speed, dtype=float).ravel()
    if v.size and (not np.all(np.isfinite(v)) or np.any(v <= 0.0)):
        raise ValueError(f"normal speeds must be finite and > 0, got {v[~(np.isfinite(v) & (v > 0.0))][0]!r}")
    nt = np.zeros(v.shape, dtype=np.bool_) if need_tail is None else np.ascontiguousarray(need_tail, dtype=np.bool_).ravel()
    model, sc, y0, c1, c2, c3, p3 = _setup(contact, v)
    y0, c1, c2, c3 = (np.ascontiguousarray(np.broadcast_to(x, v.shape), dtype=float) for x in (y0, c1, c2, c3))
    j_unit = sc.force * sc.time
    jstop = np.ascontiguousarray(np.broadcast_to(np.asarray(friction_impulse_stop, dtype=float), v.shape) / j_unit)
    jastop = np.ascontiguousarray(np.broadcast_to(np.asarray(twist_impulse_stop, dtype=float), v.shape) / (j_unit * sc.radius))
    out = np.empty((v.size, 13))
    _integrate_many(model, y0, c1, c2, c3, p3, float(rtol), nt, float(rtol if tail_tolerance is None else tail_tolerance),
                    jstop, jastop, int(max_steps), out)
    if np.any(out[:, 0] != _OK):
        i = int(np.flatnonzero(out[:, 0] != _OK)[0])
        raise EngineError(f"{_law_name(contact)} solver failed for normal speed {float(v[i])!r} m/s")
    captured = out[:, 1] == CAPTURE
    e_unit = sc.force * sc.length
    e_n = np.where(captured, 0.0, _restitution(model, y0, out[:, 4], out[:, 2]))
    return SolutionBatch(
        captured=captured,
        e_n=e_n,
        contact_time=np.where(captured, np.inf, out[:, 3] * sc.time),
        capture_time=out[:, 8] * sc.time,
        max_penetration=_penetration(model, sc, out[:, 7]),
        friction_impulse=out[:, 5] * j_unit,
        twist_impulse=out[:, 6] * j_unit * sc.radius,
        dissipated_energy=np.where(captured, out[:, 4], 0.5 * y0**2 * (1.0 - e_n**2)) * e_unit,
        final_energy=np.where(captured, out[:, 10], 0.5 * (e_n * y0) ** 2) * e_unit,
        n_steps=out[:, 11].astype(np.int64),
    )


def settled_contact_energy(contact) -> float:
    """Contact energy of a sphere at rest at the JKR or DMT equilibrium, relative to free flight. [J]

    JKR: U(6^(1/3)) - U(4^(1/3)) (contact forms at delta = 0 without work); DMT: U(1). In units
    F L of :func:`~microimpact.model.adhesion_models.adhesion_scales`.

    References
    ----------
    Johnson, Kendall & Roberts (1971)

    Derjaguin, B. V., Muller, V. M. and Toporov, Yu. P. (1975), Effect of contact deformations on
    the adhesion of particles, J. Colloid Interface Sci. 53:314-326,
    doi:10.1016/0021-9797(75)90018-1

    Examples
    --------
    The JKR well, -0.6 (6^(4/3) - 4^(4/3)) F_J L_J, and the DMT well, -0.6 F_D L_D:

    >>> from microimpact.model import adhesion_models as am
    >>> from microimpact.model.parameters import TABLE1_ROW2
    >>> for model in ("jkr", "dmt"):
    ...     c = TABLE1_ROW2.with_(normal_model=model)
    ...     sc = am.adhesion_scales(c)
    ...     print(model, round(settled_contact_energy(c) / (sc.force * sc.length), 6))
    jkr -2.731872
    dmt -0.6
    """
    if _hertz(contact):
        return 0.0
    sc = am.adhesion_scales(contact)
    if contact.normal_model in ("jkr", "jkr_force"):
        u = am.jkr_nondimensional_potential(6.0 ** (1.0 / 3.0)) - am.jkr_nondimensional_potential(am.JKR_Q_FORMATION)
    else:
        u = am.dmt_nondimensional_potential(1.0)
    return float(u * sc.force * sc.length)


# --------------------------------------------------------------------------- scipy reference
def solve_normal_reference(contact, normal_speed: float, *, rtol: float = 1e-10, need_tail: bool = False,
                           friction_impulse_stop: float = math.inf, twist_impulse_stop: float = math.inf,
                           max_time: float = 1e5) -> NormalSolution:
    """Independent check of :func:`solve_normal`: the JKR or DMT law in the approach delta and time.

    :func:`scipy.integrate.solve_ivp` (DOP853) integrates delta/L, its rate and J, J_a, D in
    nondimensional time (no Sundman change), the JKR contact radius from delta by Newton's method
    (:func:`~microimpact.model.adhesion_models.jkr_contact_radius`); separation and capture are
    solve_ivp events. A captured sphere with ``need_tail`` is followed until J, J_a reach the stops
    or ``max_time`` (in units of T). Parameters as :func:`solve_normal`. [m/s], [-], [N s], [N m s]

    References
    ----------
    Johnson, Kendall & Roberts (1971)

    Derjaguin, B. V., Muller, V. M. and Toporov, Yu. P. (1975), Effect of contact deformations on
    the adhesion of particles, J. Colloid Interface Sci. 53:314-326,
    doi:10.1016/0021-9797(75)90018-1

    Virtanen, P. et al. (2020), SciPy 1.0: fundamental algorithms for scientific computing in
    Python, Nat. Methods 17:261-272, doi:10.1038/s41592-019-0686-2 (``solve_ivp``, DOP853,
    ``brentq``)

    Examples
    --------
    >>> from microimpact.model.adhesion_models import jkr_sticking_velocity
    >>> from microimpact.model.parameters import TABLE1_ROW2
    >>> c = TABLE1_ROW2.with_(normal_model="jkr", zeta_hertz=0.0, zeta_adhesion=0.0)
    >>> bool(round(solve_normal_reference(c, 2.0 * jkr_sticking_velocity(c), rtol=1e-12).e_n, 8) == round(3**0.5 / 2, 8))
    True
    """
    # imported here, not at the module's top: scipy.integrate would add to the start-up of every
    # JKR/DMT solve, and only this reference check uses it
    from scipy.integrate import solve_ivp

    v = check_positive("normal_speed", normal_speed)
    model, sc, y0, c1, c2, c3, p3 = _setup(contact, v)
    sc = am.AdhesionScales(*(float(x) for x in (sc.length, sc.force, sc.time, sc.radius)))
    zq, rhs, l_c = _reference_rhs(model, c1, c2, c3, p3)
    potential = {_DMT: am.dmt_nondimensional_potential, _HERTZ: am.hertz_nondimensional_potential}.get(
        model, am.jkr_nondimensional_potential)
    energy = (lambda w: 0.5 * w[1] ** 2 + potential(zq(w[0])))
    thr = energy([l_c, 0.0])
    j_unit = sc.force * sc.time
    js, jas = friction_impulse_stop / j_unit, twist_impulse_stop / (j_unit * sc.radius)
    events = _reference_events(energy, thr, l_c, js, jas, need_tail)
    _, capture, turning, stopped = events
    w0 = [0.0, y0, 0.0, 0.0, 0.0]
    captured = energy(w0) < thr  # at the start: an undamped JKR impact below the sticking velocity
    opts = {"method": "DOP853", "rtol": rtol, "atol": rtol * max(1.0, y0) * 1e-2}
    # first to the largest penetration, so that a capture on the way in does not end the solve
    # short of it; then on to separation, or to the capture (the stops with need_tail)
    capture.terminal, turning.terminal, stopped.terminal = False, True, False
    parts = [solve_ivp(rhs, (0.0, max_time), w0, events=events, **opts)]
    w1 = parts[0].y[:, -1]
    captured = captured or parts[0].t_events[1].size > 0
    turned = parts[0].status == 1 and parts[0].t_events[0].size == 0
    if turned and not (captured and (not need_tail or (w1[3] >= js and w1[4] >= jas))):
        capture.terminal, turning.terminal, stopped.terminal = not need_tail, False, True
        parts.append(solve_ivp(rhs, (parts[0].t[-1], max_time), w1, events=events, **opts))
        captured = captured or parts[1].t_events[1].size > 0
    return _reference_solution(parts, captured, y0, sc, need_tail)


def _reference_rhs(model, c1, c2, c3, p3):
    """(zq, rhs, l_c) of :func:`solve_normal_reference` for the normal law ``model``: the model's z
    (q for JKR, s for DMT) from delta / L, the right-hand side of (delta / L, its rate, D, J, J_a)
    in time / T, and the delta / L at which the contact breaks."""
    jkr = model in (_JKR, _JKR_FORCE)
    # break at delta_c / L_J = -3 (JKR, q = 1), at -3^(1/3) (force-controlled JKR, q^3 = 3) or at
    # delta = 0 (DMT)
    l_c = {_JKR: -3.0, _JKR_FORCE: _Q_BREAK_FORCE**4 - 4.0 * _Q_BREAK_FORCE}.get(model, 0.0)

    def zq(d):  # the model's z (q for JKR, s for DMT) from delta / L
        return float(am.jkr_q_from_approach(max(d, -3.0))) if jkr else math.sqrt(max(d, 0.0))

    def rhs(_t, w):
        z, y = zq(w[0]), w[1]
        if jkr:
            f, diss, a = am.jkr_nondimensional_force(z, y, c1, c2), am.jkr_nondimensional_dissipation_rate(z, y, c1, c2), z * z
        elif model == _DMT:
            f, diss, a = am.dmt_nondimensional_force(z, y, c1, c2), am.dmt_nondimensional_dissipation_rate(z, y, c1, c2), z
        else:
            f, diss, a = am.hertz_nondimensional_force(z, y, c1), am.hertz_nondimensional_dissipation_rate(z, y, c1), z
        fd = dd.dem_damping_nondimensional_force(a, y, c3, p3)
        return [y, -(f + fd), diss + fd * y, abs(f + fd), a * abs(f + fd)]

    return zq, rhs, l_c


def _reference_events(energy, thr, l_c, js, jas, need_tail) -> tuple:
    """The solve_ivp events (separation, capture, turning, stopped) of :func:`solve_normal_reference`:
    delta / L falling through the break ``l_c``, the contact energy ``energy`` falling through the
    capture threshold ``thr``, the largest penetration, and (with ``need_tail``) a captured sphere
    whose J, J_a have reached the stops ``js``, ``jas`` (nondimensional). Their ``terminal`` is set
    by the caller."""
    def separation(_t, w):
        return w[0] - l_c
    separation.terminal, separation.direction = True, -1.0

    def capture(_t, w):
        return energy(w) - thr
    capture.direction = -1.0

    def turning(_t, w):
        return w[1]
    turning.direction = -1.0

    def stopped(_t, w):  # a captured sphere whose sliding and twist are over
        return min(w[3] - js, w[4] - jas, thr - energy(w)) if need_tail else -1.0
    stopped.direction = 1.0
    return separation, capture, turning, stopped


def _reference_solution(parts, captured, y0, sc, need_tail) -> NormalSolution:
    """The NormalSolution of :func:`solve_normal_reference` from its solve_ivp results ``parts``
    (nondimensional, incident rate ``y0``) in the SI units of the scales ``sc``."""
    j_unit = sc.force * sc.time
    sol = parts[-1]
    capture_times = [t for part in parts for t in part.t_events[1]]
    w_end = sol.y[:, -1]
    e_unit = sc.force * sc.length
    return NormalSolution(
        outcome="capture" if captured else "rebound",
        e_n=0.0 if captured else -w_end[1] / y0,
        contact_time=math.inf if captured else sol.t[-1] * sc.time,
        capture_time=(capture_times[0] * sc.time if capture_times else 0.0) if captured else math.nan,
        max_penetration=float(max(np.max(part.y[0]) for part in parts)) * sc.length,
        friction_impulse=w_end[3] * j_unit,
        twist_impulse=w_end[4] * j_unit * sc.radius,
        dissipated_energy=(w_end[2] if captured else 0.5 * (y0**2 - w_end[1] ** 2)) * e_unit,
        final_energy=0.0 if captured else 0.5 * w_end[1] ** 2 * e_unit,
        slip_end_time=math.nan,
        n_steps=sum(int(part.t.size) for part in parts),
        n_rejected=0,
        stop_reason=("settled" if need_tail else "capture") if captured else "separation",
    )
