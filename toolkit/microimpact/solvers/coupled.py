"""Compiled coupled solver for the sub-models beyond the paper: tangential compliance and
adhesion-aware friction (:mod:`microimpact.model.tangential_compliance`).

The paper's model (tangentially rigid, friction f |F_n|) needs one normal solve and the closed-form
tangential map (:mod:`microimpact.solvers.engine`, :mod:`microimpact.model.tangential`). This
solver is used only where a scene selects something else, so the paper's model pays nothing:

* ``friction_model="pulloff"`` with the rigid contact: the slip still falls linearly with the
  friction impulse, now f int |F_n + 2 F_po| dt, so the closed-form map still applies; the normal
  solve here accumulates that impulse (and int a |F_n + 2 F_po| dt for the twist) instead of the
  total variation of the normal rate that the engine uses.
* ``tangential_model="mindlin"``: the tangential force is a state (elastic, with micro-slip and a
  Coulomb limit), integrated together with the normal motion, the tangential velocity and the
  spins. The twist about n keeps its closed form (its torque depends on the normal solve only).
* ``tangential_model="mindlin_deresiewicz"``: the hysteretic law; the state z[10] is the branch
  coordinate p (smooth right-hand side), the branch (s, c) and the slip direction e are carried
  beside the state, and each turning point (s u.e changes sign) is located by the Illinois method on
  the step length, where the branch switches with the force continuous.
* ``rolling_friction > 0`` (with either compliant model): the torque mu_r r |F_n| against
  (omega_t, omega_t'). A step within which omega_r reverses is ended where it reaches zero, and
  omega_r is set to rest there (:func:`_end_at_rolling_stop`; also where it creeps within the
  tolerance of zero, :func:`_hold_rolling`); at rest the torque holds the sphere up to its limit.

Formulation: as the engine, nondimensional (xi = x / L, tau = t / T_c) in the Sundman variable
sigma, d tau = s d sigma with s = sqrt(xi), which keeps the right-hand side smooth where contact
starts and ends. State (s, y, tau, D, J, J_a, v_t, v_t', w_t, w_t', delta_t, delta_t') with v the
centre velocity and w = r omega the rim speeds in units of L / T_c, delta the tangential
displacement of the contact in L, J = int load dtau and J_a = int s load dtau (load =
:func:`friction_load`). Dormand-Prince 5(4) (the one core, :mod:`.dopri`) with error control on every state; the kinks of the
load are resolved by step rejection (the Mindlin force reaches its limit with zero slope, so gross
slip starts smoothly). After every accepted step the displacement is held at delta* in gross slip,
and the steps of the elastic Mindlin contact end where gross slip starts and ends
(:func:`_end_at_slip_change`: a step across either converged only first order). Separation (s = 0,
y < 0) and the largest penetration (y = 0, :func:`_root_state`) are located by the Illinois method on
the step length; capture is the exact energy test of the engine.

Hysteretic law where the Coulomb limit vanishes: the rate of p is ~ 1 / F_lim, and F_lim = f |F_n|
passes through zero twice in every impact with adhesion (and twice in every period of a captured
sphere's oscillation about the adhesive equilibrium, where F_n = 0). There T = 0 whatever p, so
(i) the error of p is measured as that of the force it makes, scaled by F_lim / F_ref (F_ref =
f max(1, a_a, y0^1.2), the order of the largest limit), and (ii) a zero of the limit within a step
is located (Illinois method on the step length, on the normal state alone, which does not depend on p) and
the branch restarts there as at first contact (:func:`_restart_branch`). Without them the steps
shrank geometrically towards each zero of F_lim and a captured impact reached the step limit. A
zero is looked for from the side of the load on which the branch was started, so that a root found
a rounding error short of it is not found again, and a step that contains one is either ended there
or rejected, never accepted without the restart (both happened, and rebounds differed by 1e-5 in
v_t between tolerances).

End of a captured impact (every tangential model): the integration stops once the normal
oscillation has decayed below the settle amplitude (``SETTLE_AMPLITUDE`` of the equilibrium
penetration, or ``SETTLE_PER_RTOL`` times rtol if that is larger: the integration error keeps the
amplitude of a long captured oscillation at 15-40 rtol, measured, so a fixed 1e-6 was never
reached at rtol >= 1e-7). A compliant contact with the pulloff limit and no rolling resistance
stops as soon as it is captured and past its largest penetration: its result is its angular
momentum about the contact point (below), which the contact force conserves, so following the
oscillation (5,000-6,000 steps) changed its velocities by 2e-14 (rounding). What the tangential
state still does after the stop is taken in closed form (:func:`_settle_captured`), so the result
does not depend on when the integration stopped:

* friction with a limit at rest ("pulloff": F_lim = 2 f F_po at the adhesive equilibrium): the
  contact force acts at the contact point, so the angular momentum about it is conserved, while
  friction removes every slip (sliding stops in finite time at the constant limit; a stuck elastic
  vibration of the contact averages to zero slip). The sphere ends rolling at that angular momentum
  (:func:`_rolling_state`), without twist; a frictionless one (f = 0) keeps its tangential motion.
  With rolling resistance the integration runs on to the tails of the paper's friction (settled,
  creeping, averaged); the rest of the rolling resistance is taken in closed form for f = 0 only
  (:func:`_rolling_tail`, which says why not for a held sphere). A held sphere's final rolling is
  checked (:func:`_held_rolling_error`): where the rolling torque reversed with the held contact's
  vibration it is solved again at a coarser tolerance, and a result that moves beyond
  :data:`HELD_ROLLING_TOLERANCE` is returned with ``not_determined`` and an
  :class:`~microimpact.solvers.UndeterminedOutcomeWarning`. Before, a stuck Mindlin contact was
  reported at the phase of its undamped vibration where the integration stopped (K_L differed by up
  to 5e-2 between rtol 1e-8 and 1e-10).
* the paper's friction ("net": F_lim = f |F_n| = 0 at the equilibrium): the rest of the
  oscillation is the linear damped tail about the equilibrium; its friction impulse (the total
  variation of the normal rate, :func:`microimpact.solvers.driver.linear_tail_variation`) and twist
  impulse (times a at the equilibrium) act as sliding friction, the closed-form map of the rigid
  contact (the limit is tiny, so the compliant contact is in gross slip while it slides).

Inertia-free limit before the capture (:func:`_law_creep`): a sphere not yet captured whose normal
motion follows the slow manifold into the equilibrium (the engine's test and thresholds,
:func:`microimpact.solvers.engine._inertia_free`: inertia ratio eps <= 1e-6, relaxation ratio >= 1e3,
y within 2 eps |y_m| + 10 atol_y of y_m) is captured there, and the integration stops with the
creeping captured sphere's tail above. Without it a nanometre sphere under zeta_A ~ 1e6 (C2 ~ 2e9)
crept in at y_m ~ 1 / C2 and reached the step limit before the energy test could capture it. Error:
the normal motion that of the engine's jump (the inertia ratio); the tail's friction impulse |y| is
the total variation of y to rest up to 2 |y - y_m| (y relaxes onto the manifold, then falls
monotonically), so the friction impulse is off by at most 2 f (2 eps |y_m| + 10 atol_y), whether
the contact slides or sticks while y relaxes (along the manifold F_lim = f |dy_m/dtau| is tiny, so
the contact slides, as the tail takes it); tests/test_coupled_creep.py checks the bound against
solves at rtol 1e-12. Without adhesion the strongly damped sphere leaves along the exact invariant
line y = -1/C1, where F_n = 0 and no tangential force acts (:func:`_exit_on_invariant_line`, the
engine's exit: at zeta_H ~ 1e6 and 1e4 m/s every compliant law reached the step limit before).
"""

from __future__ import annotations

import contextlib
import math
import warnings

import numpy as np
from numba import prange

from microimpact._numba import njit, njit_batch
from microimpact.model import law as _law
from microimpact.model import tangential_compliance as _tc
from microimpact.model.kinematics import flat_broadcast
from microimpact.model.tangential import stop_impulses, tangential_outcome  # closed-form maps
from microimpact.solvers import SolverError, UndeterminedOutcomeWarning, dopri, driver
from microimpact.solvers.compiled_law import compiled
from microimpact.solvers.driver import linear_tail_variation as _linear_tail_variation
from microimpact.solvers.engine import _SLOW_ENERGY, _averaged_tail, _equilibrium, _inertia_free, _is_creeping
from microimpact.solvers.engine import _slow_event_time, _slow_twist
from microimpact.solvers.solution import SolutionBatch

__all__ = ["solve_coupled", "coupled_kernel", "coupled_many", "CoupledError", "stops_at_capture", "HELD_ROLLING_TOLERANCE"]

_acc = compiled(_law.nondimensional_acceleration)
_energy = compiled(_law.nondimensional_energy)
_dissipation = compiled(_law.nondimensional_dissipation_rate)
_load = compiled(_tc.friction_load)
_force = compiled(_tc.mindlin_force)
_dstar = compiled(_tc.mindlin_stuck_displacement)
_md_ratio = compiled(_tc.md_force_ratio)
_md_rate = compiled(_tc.md_branch_rate)
_md_span = compiled(_tc.md_turning_span)

_N = 12
_S, _Y, _TAU, _D, _J, _JA, _VT, _VTP, _WT, _WTP, _FT, _FTP = range(_N)
_OK, _MAX_STEPS, _UNDERFLOW = 0, 1, 2
#: outcome code of a captured impact whose integration stopped creeping on the slow manifold (1: captured)
_CREEPING = 2
#: outcome code of a captured impact stopped after a twentieth of the step budget (its tail in
#: closed form: averaged when weakly damped, else linear; the engine's policy)
_LONG_TAIL = 3

class CoupledError(SolverError):
    """The coupled solver could not finish an impact (step limit or step-size underflow).

    Not expected for valid input: every impact ends by separation or by the settle criterion of
    the module docstring; this error reports a solver defect, with the normal speed of the impact.

    Examples
    --------
    One ``except`` catches the failure of any solver:

    >>> issubclass(CoupledError, SolverError), issubclass(CoupledError, RuntimeError)
    (True, True)
    """


# helpers compiled as calls, not numba-inlined: see the note in normal_models.py
@njit(cache=True)
def _branch_slip(z, hist):
    """s u.e: the contact-point slip along the current branch of the hysteretic law."""
    return hist[0] * ((z[_VT] + z[_WTP]) * hist[2] + (z[_VTP] - z[_WT]) * hist[3])


@njit(cache=True)
def _load_rate(s, y, xi_dd, c1, c2, ah, aa):
    """dF_n/dsigma of F_n = a_h s^3 (1 + c1 y) - a_a s (1 - c2 y), with ds = y/2, dy = s xi''."""
    return (3.0 * ah * s * s * (1.0 + c1 * y) - aa * (1.0 - c2 * y)) * 0.5 * y + (ah * c1 * s * s * s + aa * c2 * s) * s * xi_dd


@njit(cache=True)
def _md_terms(z, p, hist, s, xi_dd, load):
    """(F_lim, dF_lim/dsigma, s s_b u.e) of the hysteretic law at the state z (nondimensional)."""
    c1, c2, ah, aa, f, fpo, aware = p[0], p[1], p[2], p[3], p[4], p[5], p[6] > 0.5
    dfn = _load_rate(s, z[_Y], xi_dd, c1, c2, ah, aa)
    fn_aw = -xi_dd + 2.0 * fpo if aware else -xi_dd
    dlim = f * dfn * (1.0 if fn_aw >= 0.0 else -1.0)
    return f * load, dlim, s * _branch_slip(z, hist)


@njit(cache=True)
def _rhs(z, out, args):
    """d/dsigma of the state z; args = (p, hist).

    p = (c1, c2, a_h, a_a, f, F_po, adhesion_aware, kappa, k_rot, tangential mode (0 rigid,
    1 mindlin, 2 mindlin_deresiewicz), mu_r); hist = (s, c, e_t, e_t') the branch of the hysteretic
    law and the initial slip direction (hist[4:6]: see :func:`_end_at_rolling_stop`).
    """
    p, hist = args
    c1, c2, ah, aa, f, fpo, aware, kappa, krot = p[0], p[1], p[2], p[3], p[4], p[5], p[6] > 0.5, p[7], p[8]
    mode = p[9]
    s = z[_S]
    y = z[_Y]
    if s < 0.0:
        s = 0.0
    xi_dd = _acc(s, s * s * s, y, c1, c2, ah, aa)  # xi'' = -F_n
    load = _load(-xi_dd, fpo, aware) if s > 0.0 else 0.0
    out[_S] = 0.5 * y
    out[_Y] = s * xi_dd
    out[_TAU] = s
    out[_D] = s * _dissipation(s, s * s * s, y, c1, c2, ah, aa)
    out[_J] = s * load
    out[_JA] = s * s * load
    for i in range(_VT, _N):
        out[i] = 0.0
    if mode > 1.5:  # hysteretic Mindlin-Deresiewicz law along e, state p in z[_FT]
        lim, dlim, drive = _md_terms(z, p, hist, s, xi_dd, load)
        et, etp = hist[2], hist[3]
        t = lim * _md_ratio(z[_FT], hist[0], hist[1])
        out[_VT] = -s * t * et
        out[_VTP] = -s * t * etp
        out[_WTP] = -s * krot * t * et
        out[_WT] = s * krot * t * etp
        out[_FT] = _md_rate(z[_FT], hist[1], drive, kappa * s, lim, dlim)
    elif mode > 0.5:
        lim = f * load
        ft, fp = _force(z[_FT], z[_FTP], _dstar(kappa * s, lim), lim)
        out[_VT] = s * ft
        out[_VTP] = s * fp
        out[_WTP] = s * krot * ft
        out[_WT] = -s * krot * fp
        out[_FT] = s * (z[_VT] + z[_WTP])  # d delta / d tau = u, the slip of the contact point
        out[_FTP] = s * (z[_VTP] - z[_WT])
    if p[10] > 0.0 and s > 0.0:  # rolling resistance: torque mu_r r |F_n| against (omega_t, omega_t')
        lim_r = s * krot * p[10] * abs(xi_dd)
        wm = math.sqrt(z[_WT] * z[_WT] + z[_WTP] * z[_WTP])
        if wm > 0.0:
            g = lim_r / wm
            out[_WT] -= g * z[_WT]
            out[_WTP] -= g * z[_WTP]
        else:  # at rest (set there by _end_at_rolling_stop): held up to the limit, as friction at rest
            tm = math.sqrt(out[_WT] * out[_WT] + out[_WTP] * out[_WTP])
            held = 0.0 if tm <= lim_r else 1.0 - lim_r / tm
            out[_WT] *= held
            out[_WTP] *= held


#: one Dormand-Prince 5(4) step of the coupled model (the core's, :mod:`microimpact.solvers.dopri`)
_step = dopri.make_step(_rhs, _N)


@njit(cache=True)
def _stuck_displacement(z, p):
    """delta* of the elastic Mindlin contact at the state z (nondimensional)."""
    s = max(z[_S], 0.0)
    xi_dd = _acc(s, s * s * s, z[_Y], p[0], p[1], p[2], p[3])
    lim = p[4] * (_load(-xi_dd, p[5], p[6] > 0.5) if s > 0.0 else 0.0)
    return _dstar(p[7] * s, lim)


@njit(cache=True)
def _project(z, p):
    """Hold the tangential displacement at delta* (gross slip: the slip beyond it is not stored)."""
    dstar = _stuck_displacement(z, p)
    mag = math.sqrt(z[_FT] * z[_FT] + z[_FTP] * z[_FTP])
    if mag > dstar:
        z[_FT] *= dstar / mag
        z[_FTP] *= dstar / mag
        return True
    return False


@njit(cache=True)
def _gross_slip_margin(z, p):
    """|delta| - delta* of the elastic Mindlin contact: < 0 while part of the contact sticks."""
    return math.sqrt(z[_FT] * z[_FT] + z[_FTP] * z[_FTP]) - _stuck_displacement(z, p)


@njit(cache=True)
def _slip_excess(z, p, hist):
    """d(|delta| - delta*)/dsigma with delta moving with the slip: > 0 while gross slip goes on
    (:func:`_project` discards the slip beyond delta*), < 0 once the contact sticks again."""
    s = max(z[_S], 0.0)
    mag = math.sqrt(z[_FT] * z[_FT] + z[_FTP] * z[_FTP])
    if s == 0.0 or mag == 0.0:
        return 0.0
    xi_dd = _acc(s, s * s * s, z[_Y], p[0], p[1], p[2], p[3])
    lim, dlim, _ = _md_terms(z, p, hist, s, xi_dd, _load(-xi_dd, p[5], p[6] > 0.5))
    kt = p[7] * s
    dstar_rate = 1.5 * (dlim * kt - lim * p[7] * 0.5 * z[_Y]) / (kt * kt)  # delta* = 1.5 F_lim / k_t
    along = s * ((z[_VT] + z[_WTP]) * z[_FT] + (z[_VTP] - z[_WT]) * z[_FTP]) / mag
    return along - dstar_rate


@njit(cache=True)
def _load_argument(z, p):
    """F_n (paper's friction) or F_n + 2 F_po ("pulloff"): the signed load whose zeros are those of F_lim."""
    s = max(z[_S], 0.0)
    fn = -_acc(s, s * s * s, z[_Y], p[0], p[1], p[2], p[3])
    return fn + 2.0 * p[5] if p[6] > 0.5 else fn


@njit(cache=True)
def _restart_branch(z, p, hist):
    """Restart the hysteretic law where the Coulomb limit F_lim passes through zero.

    There T = s F_lim [1 - c (1 - p)^(3/2)] = 0 whatever the branch, so the contact keeps no
    memory: as the limit grows again it starts a virgin branch (c = 1, s = +1) along the slip
    direction at that instant, e = u / |u|, exactly as at first contact (:func:`_initial_branch`).
    Its branch coordinate is the only bounded solution of dp/dsigma = [A - (2/3) dF_lim/dsigma p]
    / F_lim as F_lim -> 0 (A = s |u| k_t / 1.5): p = A / ((2/3) dF_lim/dsigma), gross slip (p = 1)
    if that exceeds 1. Any other p has a rate ~ 1 / F_lim, which an explicit integrator can only
    follow with steps that shrink geometrically towards the zero of the limit.
    """
    c1, c2, ah, aa, f = p[0], p[1], p[2], p[3], p[4]
    s, y = max(z[_S], 0.0), z[_Y]
    ut, utp = z[_VT] + z[_WTP], z[_VTP] - z[_WT]
    um = math.sqrt(ut * ut + utp * utp)
    hist[0] = hist[1] = 1.0
    z[_FT] = 0.0
    if um > 0.0:
        hist[2], hist[3] = ut / um, utp / um
        xi_dd = _acc(s, s * s * s, y, c1, c2, ah, aa)
        dfn = _load_rate(s, y, xi_dd, c1, c2, ah, aa)
        a_term = s * um * p[7] * s / 1.5
        b_term = (2.0 / 3.0) * f * abs(dfn)
        z[_FT] = a_term / b_term if a_term < b_term else 1.0


@njit(cache=True)
def _initial_branch(z, p):
    """(s, c, e_t, e_t') at first contact, and p in z[_FT], for the hysteretic law.

    e is the initial slip direction; the contact starts in gross slip (p = 1: F_lim = 0 at first
    contact). Without slip, e is the slip that a rolling-resistance torque would start, and the
    contact starts stuck (p = 0, no force).
    """
    hist = np.zeros(6)  # (s, c, e_t, e_t') and the direction of omega_r at a rolling stop
    hist[0] = hist[1] = 1.0
    ut, utp = z[_VT] + z[_WTP], z[_VTP] - z[_WT]
    um = math.sqrt(ut * ut + utp * utp)
    wm = math.sqrt(z[_WT] * z[_WT] + z[_WTP] * z[_WTP])
    if um > 0.0:
        hist[2], hist[3] = ut / um, utp / um
        if p[9] > 1.5:
            # gross slip at first contact, unless the slip is too slow for it: then the contact
            # sticks from the start at the self-similar value of p where dp/dsigma = 0 as s -> 0
            # (the rate is linear in p, A + B (1 - p - 1/c), c = 1); starting on it avoids a
            # transient of rate ~ y / s at s -> 0 that would force steps of ~1e-100
            zp = z.copy()
            sp = 1e-6 * max(1.0, z[_Y] ** 0.4)
            zp[_S] = sp
            xi_dd = _acc(sp, sp * sp * sp, zp[_Y], p[0], p[1], p[2], p[3])
            lim, dlim, drive = _md_terms(zp, p, hist, sp, xi_dd, _load(-xi_dd, p[5], p[6] > 0.5))
            a_term = drive * p[7] * sp / 1.5
            b_term = (2.0 / 3.0) * dlim
            z[_FT] = 1.0
            if b_term > 0.0 and a_term < b_term:
                z[_FT] = max(a_term / b_term, 0.0)
    elif wm > 0.0:
        hist[2], hist[3] = -z[_WTP] / wm, z[_WT] / wm
    else:
        hist[2] = 1.0
    return hist


#: the events located within a step by :func:`_restep_to_root`: the Coulomb limit passing through
#: zero, separation (s = 0), a turning point of the hysteretic law, the rolling velocity reaching
#: zero, the largest penetration (y = 0), the friction impulse J and the contact energy reaching a
#: value. numpy integers, not int literals: numba compiles one specialization of a callee per
#: literal argument (four instead of one).
_EV_LOAD, _EV_SEPARATION, _EV_TURN, _EV_ROLL = np.int64(0), np.int64(1), np.int64(2), np.int64(3)
_EV_GROSS, _EV_STICK = np.int64(4), np.int64(5)  # elastic Mindlin contact: gross slip starts, ends
_EV_DEPTH, _EV_IMPULSE, _EV_ENERGY = np.int64(6), np.int64(7), np.int64(8)


@njit(cache=True)
def _event_value(z, code, args):
    p, hist = args
    if code == _EV_LOAD:
        return _load_argument(z, p)
    if code == _EV_SEPARATION:
        return z[_S]
    if code == _EV_ROLL:
        return z[_WT] * hist[4] + z[_WTP] * hist[5]
    if code == _EV_GROSS:
        return _gross_slip_margin(z, p)
    if code == _EV_STICK:
        return _slip_excess(z, p, hist)
    if code == _EV_DEPTH:
        return z[_Y]
    if code == _EV_IMPULSE:
        return z[_J]
    if code == _EV_ENERGY:
        return _energy(z[_S], z[_Y], p[2], p[3])
    return _branch_slip(z, hist)


#: the step length at which an event value reaches its target, solved on the step (Illinois method)
_root = dopri.make_root_on_step(_step, _event_value)


@njit(cache=True)
def _restep_to_root(code, target, fa, fb, tol, h, z, k1, p, hist, k, tmp, z1, err):
    """Re-step from z to where event ``code`` reaches ``target`` within the step h (fa, fb its
    values less target at the start and end of the step, opposite signs); z1 then holds the state
    there. Stops at |value - target| <= tol or a bracket below 1e-14 h; returns the step length."""
    return _root(code, target, fa, fb, tol, h, z, k1, (p, hist), (p, hist), k, tmp, z1, err)


@njit(cache=True)
def _end_at_limit_zero(en, gb, h, z, z1, k1, err, atol, rtol, p, hist, k, tmp):
    """A trial step from z to z1 within which the Coulomb limit passes through zero (load argument
    ``gb`` at z1): if the normal motion is accurate, end the step at the zero (Illinois method on the step
    length; at z itself if z is the zero within rounding) and have the branch restarted there;
    else reject the step. Accepting it on the error of all states, as before, let a zero pass
    without a restart (results then jumped by 1e-5 between tolerances). Returns (the error sum
    that decides the step, restart)."""
    if dopri.scaled_error_sum(z, z1, err, atol, rtol, _VT) > _VT:
        return max(en, 4.0 * _N), False  # rejected
    ga = _load_argument(z, p)
    if ga * gb < 0.0:
        _restep_to_root(_EV_LOAD, 0.0, ga, gb, 1e-13 * (abs(ga) + abs(gb)), h, z, k1, p, hist, k, tmp, z1, err)
    else:
        for i in range(_N):
            z1[i] = z[i]
    return float(_N), True  # accepted; the next step keeps the length h


@njit(cache=True)
def _error_sum(z, z1, err, atol, rtol, p, hysteretic, lim_ref):
    """Sum of the squared scaled errors of a step z -> z1 (the error of p as that of the force it
    makes, see the module docstring)."""
    if hysteretic:
        err[_FT] *= min(1.0, p[4] * abs(_load_argument(z1, p)) / lim_ref)
    return dopri.scaled_error_sum(z, z1, err, atol, rtol, _N)


@njit(cache=True)
def _end_at_rolling_stop(h, z, z1, k1, err, atol, rtol, p, hist, k, tmp, hysteretic, lim_ref):
    """A trial step z -> z1 within which the rolling velocity omega_r = (w_t, w_t') reverses.

    Model A's torque, -mu_r r |F_n| omega_r / |omega_r|, flips there, and an explicit integrator
    chatters about omega_r = 0 (600,000 steps, or the step limit, and a rest state set by rounding).
    At rest the torque is set-valued, as friction is: it holds omega_r = 0 while the other torques
    stay within its limit (:func:`_rhs`). So the step is ended where the component of omega_r
    along its direction at z vanishes (Illinois method on the step length), and the caller sets
    omega_r = 0 there if what is left of it is within the step's tolerance.

    Returns (the step's error sum, rest reached, step length); a step whose end is not at rest
    within the tolerance (omega_r turned by more than a right angle) is rejected.
    """
    wm = math.sqrt(z[_WT] * z[_WT] + z[_WTP] * z[_WTP])
    hist[4], hist[5] = z[_WT] / wm, z[_WTP] / wm
    fb = z1[_WT] * hist[4] + z1[_WTP] * hist[5]
    hs = _restep_to_root(_EV_ROLL, 0.0, wm, fb, 1e-13 * (wm + abs(fb)), h, z, k1, p, hist, k, tmp, z1, err)
    en = _error_sum(z, z1, err, atol, rtol, p, hysteretic, lim_ref)
    left = math.sqrt(z1[_WT] * z1[_WT] + z1[_WTP] * z1[_WTP])
    if left > atol[_WT] + rtol * wm:
        return max(en, 4.0 * _N), False, hs
    return en, True, hs


@njit(cache=True)
def _end_at_slip_change(slipping, h, en, z, z1, k1, err, atol, rtol, p, hist, k, tmp, lim_ref):
    """A trial step z -> z1 of the elastic Mindlin contact within which gross slip starts
    (|delta| reaches delta*) or, ``slipping``, ends (the slip along delta falls below the growth of
    delta*): end the step there (Illinois method on the step length).

    The force F_lim [1 - (1 - |delta|/delta*)^(3/2)] has an unbounded second derivative at
    |delta| = delta*, and the projection after a step in gross slip keeps the slip beyond delta*
    that came after the contact stuck again; a step across either lost order, and the solver
    converged about first order in rtol (rebound K_L 4e-4 apart between rtol 1e-8 and 1e-10).
    Returns (the step's error sum, a change was found, step length).
    """
    if slipping:
        fa, fb, code = _slip_excess(z, p, hist), _slip_excess(z1, p, hist), _EV_STICK
        if not (fa > 0.0 and fb < 0.0):
            return en, False, h
    else:
        fa, fb, code = _gross_slip_margin(z, p), _gross_slip_margin(z1, p), _EV_GROSS
        if not (fa < 0.0 and fb > 0.0):
            return en, False, h
    hs = _restep_to_root(code, 0.0, fa, fb, 1e-13 * (abs(fa) + abs(fb)), h, z, k1, p, hist, k, tmp, z1, err)
    if hs < 1e-6 * h:
        # a change at the start of the step: a value a rounding error off zero where F_lim ~ 0 (a
        # captured sphere with the paper's friction, twice per period); ending the step there
        # repeated it with zero-length steps, so the step is kept whole and the projection decides
        _step(z, k1, h, (p, hist), k, tmp, z1, err)
        return en, False, h
    return _error_sum(z, z1, err, atol, rtol, p, False, lim_ref), True, hs


#: the rest of omega_r taken within a step (:func:`_hold_rolling`) is at most this multiple of its
#: absolute tolerance: over a long step the other torques change, and rest may not come
_HOLD_SPAN = 100.0


@njit(cache=True)
def _rolling_approach(z, k1):
    """The rate at which |omega_r| falls at z, -d|w|/dsigma, or 0 where it does not fall."""
    wm = math.sqrt(z[_WT] * z[_WT] + z[_WTP] * z[_WTP])
    if wm == 0.0:
        return 0.0
    return max(-(z[_WT] * k1[_WT] + z[_WTP] * k1[_WTP]) / wm, 0.0)


@njit(cache=True)
def _hold_rolling(z, k1, tol, p, hist):
    """Set omega_r = 0 where it is within ``tol`` of zero and the torques there would hold it at rest
    (k1, the derivative at z, is updated).

    Near rest, model A's torque turns with omega_r at a rate ~ |other torques| / |omega_r|, which an
    explicit integrator follows only with steps that shrink with |omega_r|: omega_r spiralled about
    1e-10 for 200,000 steps without reversing. Within the tolerance, rest is as exact as the state.

    The caller also passes as ``tol`` what the last step length would take off |omega_r| at its
    present rate towards rest (:func:`_rolling_approach`): where the torques hold it, the exact
    solution reaches rest within that step and stays there (the sliding mode of the set-valued
    torque), and setting it there now moves the other states only by O(|omega_r|^2 / rate), through
    the slip. Without it, a stage of each step fell on the other side of omega_r = 0, where the
    torque is reversed: the steps shrank to 1e-8 and omega_r hovered at 1e-10 with the rate of
    4e-2 towards rest (rtol 1e-11, Table 1 row 2 with Mindlin contact and mu_r = 0.2 at 0.05 m/s,
    40 deg), until the step budget stopped the integration.
    """
    wt, wtp = z[_WT], z[_WTP]
    wm = math.sqrt(wt * wt + wtp * wtp)
    if wm == 0.0 or wm > tol:
        return
    z[_WT] = z[_WTP] = 0.0
    _rhs(z, k1, (p, hist))
    if k1[_WT] != 0.0 or k1[_WTP] != 0.0:  # not held: omega_r leaves rest
        z[_WT], z[_WTP] = wt, wtp
        _rhs(z, k1, (p, hist))


@njit(cache=True)
def _root_state(code, target, h, z, z1, k1, p, hist):
    """The state where event ``code`` reaches ``target`` within the accepted step z -> z1 of
    length h, re-stepped from z in scratch arrays (the step itself is kept). Used where a value
    at an instant is reported: the largest penetration (y = 0), the end of sliding (J = J*) and
    the capture (the energy test).

    The step's ends alone were O(h^2) off at rtol 1e-9: the largest penetration by up to 4e-4,
    the slip-end time (J interpolated linearly in the step) by 1e-4 and the capture time (the
    step's end) by 4e-2. The normal state does not depend on the tangential one, so a normal
    event's root is the normal motion's own even where the step is later ended earlier (at a
    turning point of the hysteretic law, a zero of the Coulomb limit); J grows monotonically, so
    its root is bracketed by the whole step too.
    """
    zs, tmp, err = np.empty(_N), np.empty(_N), np.empty(_N)
    ks = np.empty((7, _N))
    fa, fb = _event_value(z, code, (p, hist)) - target, _event_value(z1, code, (p, hist)) - target
    _restep_to_root(code, target, fa, fb, 1e-13 * (abs(fa) + abs(fb)), h, z, k1, p, hist, ks, tmp, zs, err)
    return zs


@njit(cache=True)
def _impulse_time(z, z1, j_stop, tau_j, h, k1, p, hist):
    """tau at which J reaches j_stop within the step z -> z1 of length h (``tau_j`` if known)."""
    if math.isnan(tau_j) and z[_J] < j_stop <= z1[_J]:
        return _root_state(_EV_IMPULSE, j_stop, h, z, z1, k1, p, hist)[_TAU]
    return tau_j


@njit(cache=True)
def _start(y0, vt0, vtp0, wt0, wtp0, p, rtol):
    """The state at first contact and the constants of one impact: returns (z, k1, hist, atol,
    sref, lim_ref, ecap, h): the state and its derivative, the branch of the hysteretic law
    (:func:`_initial_branch`), the absolute tolerances, the scale of s, the order of the largest
    Coulomb limit, the capture margin of the energy (the engine's) and the first step."""
    z = np.zeros(_N)
    z[_Y], z[_VT], z[_VTP], z[_WT], z[_WTP] = y0, vt0, vtp0, wt0, wtp0
    k1 = np.zeros(_N)
    hist = _initial_branch(z, p)
    _rhs(z, k1, (p, hist))
    ah, aa = p[2], p[3]
    yref = max(1.0, y0)
    sref = max(1.0, y0 ** 0.4)
    vref = max(yref, abs(vt0) + abs(wtp0), abs(vtp0) + abs(wt0))
    atol = np.empty(_N)
    atol[_S] = rtol * sref
    atol[_Y] = rtol * yref
    atol[_TAU] = rtol * sref
    atol[_D] = rtol * 0.5 * yref * yref
    atol[_J] = rtol * sref * yref
    atol[_JA] = rtol * sref * sref * yref
    for i in range(_VT, _FT):
        atol[i] = rtol * vref
    atol[_FT] = atol[_FTP] = rtol * (1.0 if p[9] > 1.5 else sref)
    lim_ref = p[4] * max(1.0, p[3], y0 ** 1.2) if p[4] > 0.0 else 1.0  # order of the largest F_lim
    ecap = -10.0 * rtol * (4.0 / 15.0) * (aa * aa * aa / (ah * ah) if ah > 0.0 else 1.0) ** 0.5
    h = 1e-3 * min(1.0, 2.0 / max(y0, 1e-300) ** 0.6)
    if y0 < 1.0:
        h = min(1e-3 * (12.0 / y0) ** (1.0 / 3.0), 1e-2)
    return z, k1, hist, atol, sref, lim_ref, ecap, h


@njit(cache=True)
def _end_at_events(en, h, z, z1, k1, err, atol, rtol, p, hist, k, tmp, lim_ref, slipping, load_side, elastic,
                   rolling, hysteretic):
    """A trial step z -> z1 of length h (error sum ``en``), ended at the earliest of a change of
    gross slip (:func:`_end_at_slip_change`), a rolling stop (:func:`_end_at_rolling_stop`) and a
    zero of the Coulomb limit (:func:`_end_at_limit_zero`). Returns (the error sum that decides
    the step, restart the branch, at rest, the step's length, slip change, load_side)."""
    restart = False
    at_rest = False
    h_end = h  # the step's length, shorter where it ends at an event
    slip_change = False
    if elastic and z[_S] > 0.0 and z1[_S] > 0.0:
        en, slip_change, h_end = _end_at_slip_change(slipping, h, en, z, z1, k1, err, atol, rtol, p, hist, k,
                                                     tmp, lim_ref)
    if rolling and z[_S] > 0.0 and z1[_S] > 0.0 and z[_WT] * z1[_WT] + z[_WTP] * z1[_WTP] < 0.0:
        en, at_rest, h_end = _end_at_rolling_stop(h_end, z, z1, k1, err, atol, rtol, p, hist, k, tmp, hysteretic,
                                                  lim_ref)
        slip_change = slip_change and not at_rest  # the rolling stop comes first
    if hysteretic and z[_S] > 0.0 and z1[_S] > 0.0:
        # the Coulomb limit passes through zero within the step, seen from the side the branch
        # was started on (a root found a rounding error short of the zero is not found again)
        gb = _load_argument(z1, p)
        if gb * load_side < 0.0:
            en, restart = _end_at_limit_zero(en, gb, h_end, z, z1, k1, err, atol, rtol, p, hist, k, tmp)
            if restart:  # the step now ends at that zero, before the rolling stop if any
                load_side = 1.0 if gb > 0.0 else -1.0
                at_rest = False
    return en, restart, at_rest, h_end, slip_change, load_side


@njit(cache=True)
def _separate(z, z1, k1, h_end, p, hist, k, tmp, err, sref, conservative, y0, j_stop, tau_j):
    """Separation within the accepted step z -> z1: its root on the step length; z becomes the
    state there (out of contact, nothing stored). Returns tau at which J reached j_stop."""
    _restep_to_root(_EV_SEPARATION, 0.0, z[_S], z1[_S], 1e-14 * sref, h_end, z, k1, p, hist, k, tmp, z1, err)
    z1[_S] = 0.0
    if conservative:  # leaves with its energy: U(0) = 0
        z1[_Y] = -y0
    tau_j = _impulse_time(z, z1, j_stop, tau_j, h_end, k1, p, hist)
    for i in range(_N):
        z[i] = z1[i]
    z[_FT] = z[_FTP] = 0.0  # out of contact: nothing stored
    return tau_j


@njit(cache=True)
def _tangential_update(z, k1, k, p, hist, turned, restart, load_side, slipping, slip_change, hysteretic, elastic,
                       refresh):
    """The tangential state after an accepted step (z its end): a new branch of the hysteretic law
    at a turning point or a zero of the Coulomb limit, the branch coordinate kept in [0, 1], the
    displacement held at delta* in gross slip, and the derivative at z into k1 (evaluated anew
    where the state changed, else the last stage of the step). Returns (load_side, slipping)."""
    if turned:  # new branch: s -> -s, c from the force ratio, p = 0 (force continuous)
        ratio = _md_ratio(z[_FT], hist[0], hist[1])
        hist[0] = -hist[0]
        hist[1] = _md_span(ratio, hist[0])
        z[_FT] = 0.0
    if restart:
        _restart_branch(z, p, hist)
    if hysteretic:
        if load_side == 0.0 and z[_S] > 0.0:
            g = _load_argument(z, p)
            load_side = 0.0 if g == 0.0 else (1.0 if g > 0.0 else -1.0)
        z[_FT] = min(max(z[_FT], 0.0), 1.0)
        _rhs(z, k1, (p, hist))
    elif elastic:
        projected = _project(z, p)
        slipping = (not slipping) if slip_change else projected
        _rhs(z, k1, (p, hist))
    elif refresh:
        _rhs(z, k1, (p, hist))
    else:
        for i in range(_N):
            k1[i] = k[6, i]
    return load_side, slipping


@njit(cache=True)
def _captured_stop(z, k1, atol, settle, peaked, conserved, j_stop, ja_stop, tail_closed, p, xe, omega0, ceq,
                   long_tail):
    """The outcome code at which the integration of a captured sphere stops (1, _CREEPING or
    _LONG_TAIL), or 0 while it goes on; ``long_tail``: a twentieth of the step budget is spent."""
    dx = z[_S] * z[_S] - xe
    amp = math.sqrt(dx * dx + (z[_Y] / omega0) ** 2) / xe
    # settled normal motion (the tangential rest is taken in closed form afterwards), or
    # the rigid contact's sliding and twist over
    if amp < settle or peaked and (conserved or z[_J] >= j_stop and z[_JA] >= ja_stop):
        return 1
    # strongly overdamped: it creeps into the equilibrium on the slow manifold, which an
    # explicit solver follows in ~C^2 steps (the step limit at zeta ~ 1e4); the engine's
    # creeping test, and the rest of the normal motion in closed form (_tail_impulses)
    # (with rolling resistance only under the pulloff friction: the tail's rolling resistance
    # is then taken in closed form for f = 0 and left out for a held sphere, _rolling_tail;
    # under the paper's friction the sphere slides as well, and no closed form is written)
    if tail_closed and ceq > 2.0 * omega0 and (peaked or z[_S] * z[_S] < xe) and _is_creeping(
            z, k1, atol[_Y], np.bool_(True), p[0], p[1], p[2], p[3], xe, omega0, ceq):
        return _CREEPING
    if tail_closed and peaked and long_tail:
        return _LONG_TAIL
    return 0


# ------------------------------------------------------------------ the coupled law in the one driver
# The law's parameters p = (y0, vt0, vtp0, wt0, wtp0, the parameter row (see _rhs), j_stop, ja_stop,
# settle) and its bookkeeping w = (hist, b): the branch history of the hysteretic law
# (:func:`_initial_branch`) and the array b (indices below; flags as 0.0 / 1.0), for the driver
# (:mod:`.driver`), which owns the loop, the budgets and the step control.
_B_TURNS, _B_HELD, _B_SLIPPING, _B_LOAD_SIDE, _B_CAPTURED, _B_PEAKED, _B_TAU_CAP, _B_TAU_ZERO = 0, 1, 2, 3, 4, 5, 6, 7
_B_TAU_J, _B_SMAX, _B_OUTCOME, _B_H_END, _B_RESTART, _B_AT_REST, _B_SLIP_CHANGE = 8, 9, 10, 11, 12, 13, 14
_B_SREF, _B_LIM_REF, _B_ECAP, _B_XE, _B_OMEGA0, _B_CEQ = 15, 16, 17, 18, 19, 20
_B_SIZE = 21


@njit(cache=True)
def _law_start(p, rtol, rec, rec_cap):
    """The driver's start (:func:`_start`): the state, its derivative, the first step, the
    tolerances and the bookkeeping (hist, b) of one impact."""
    row = p[5]
    z, k1, hist, atol, sref, lim_ref, ecap, h = _start(p[0], p[1], p[2], p[3], p[4], row, rtol)
    b = np.zeros(_B_SIZE)
    # its gross slip (found by the projection at first contact, then by events), the sign of the
    # Coulomb limit's load argument since the last restart (0: not yet known) and the capture time
    # (tau_zero: where the energy first fell below zero, the capture time, as the engine's)
    b[_B_TAU_CAP] = b[_B_TAU_ZERO] = b[_B_TAU_J] = math.nan
    b[_B_SREF], b[_B_LIM_REF], b[_B_ECAP] = sref, lim_ref, ecap
    b[_B_XE], b[_B_OMEGA0], b[_B_CEQ] = _equilibrium(row[0], row[1], row[2], row[3])
    return z, k1, h, atol, (hist, b)


@njit(cache=True, inline="always")
def _law_args(p, w):
    """The right-hand side's arguments: (the parameter row, the branch history)."""
    return (p[5], w[0])


@njit(cache=True, inline="always")
def _law_too_small(h, z):
    return h < 1e-300


@njit(cache=True)
def _law_norm(z, z1, k1, h, p, w, atol, rtol, k, tmp, err):
    """The error norm of the trial step z -> z1 (:func:`_error_sum`), the step ended at the earliest
    of its events first (:func:`_end_at_events`: a change of gross slip, a rolling stop, a zero of
    the Coulomb limit), which the accepted step's events then read from b."""
    row = p[5]
    hist, b = w
    hysteretic = row[9] > 1.5
    en = _error_sum(z, z1, err, atol, rtol, row, hysteretic, b[_B_LIM_REF])
    en, restart, at_rest, h_end, slip_change, load_side = _end_at_events(
        en, h, z, z1, k1, err, atol, rtol, row, hist, k, tmp, b[_B_LIM_REF], b[_B_SLIPPING] != 0.0, b[_B_LOAD_SIDE],
        0.5 < row[9] < 1.5, row[10] > 0.0, hysteretic)
    b[_B_RESTART], b[_B_AT_REST], b[_B_H_END] = 1.0 if restart else 0.0, 1.0 if at_rest else 0.0, h_end
    b[_B_SLIP_CHANGE], b[_B_LOAD_SIDE] = 1.0 if slip_change else 0.0, load_side
    return math.sqrt(en / _N)


@njit(cache=True)
def _law_events(z, z1, k1, h, p, w, atol, rtol, k, tmp, err, rec, rec_cap):
    """The events within the accepted step z -> z1 (the largest penetration, separation, a turning
    point of the hysteretic law, the end of sliding, the capture) and the advance to its end: the
    normal energy kept exact where undamped, a rolling stop, the tangential state
    (:func:`_tangential_update`) and a held rolling velocity."""
    y0, row, j_stop = p[0], p[5], p[6]
    hist, b = w
    ah, aa = row[2], row[3]
    hysteretic, rolling, elastic = row[9] > 1.5, row[10] > 0.0, 0.5 < row[9] < 1.5
    damped = row[0] > 0.0 or row[1] > 0.0
    conservative = not damped and aa > 0.0
    h_end, restart, at_rest = b[_B_H_END], b[_B_RESTART] != 0.0, b[_B_AT_REST] != 0.0
    captured, tau_j, smax = b[_B_CAPTURED] != 0.0, b[_B_TAU_J], b[_B_SMAX]
    if b[_B_PEAKED] == 0.0 and z[_Y] > 0.0 and z1[_Y] <= 0.0:
        smax = max(smax, _root_state(_EV_DEPTH, 0.0, h_end, z, z1, k1, row, hist)[_S])
        b[_B_PEAKED] = 1.0
    if z1[_S] < 0.0 and z[_S] > 0.0:  # separation within the step: its root on the step length
        b[_B_TAU_J] = _separate(z, z1, k1, h_end, row, hist, k, tmp, err, b[_B_SREF], conservative, y0, j_stop, tau_j)
        b[_B_SMAX], b[_B_OUTCOME] = smax, 0.0
        return driver.END
    turned = False
    if not restart and hysteretic and _branch_slip(z, hist) > 0.0 and _branch_slip(z1, hist) < 0.0:
        # turning point of the hysteretic law within the step: its root on the step length
        ga, gb = _branch_slip(z, hist), _branch_slip(z1, hist)
        _restep_to_root(_EV_TURN, 0.0, ga, gb, 1e-13 * (abs(ga) + abs(gb)), h_end, z, k1, row, hist, k, tmp, z1, err)
        turned = True
        at_rest = False
    tau_j = _impulse_time(z, z1, j_stop, tau_j, h_end, k1, row, hist)
    if not captured and damped and aa > 0.0:
        e1 = _energy(z1[_S], z1[_Y], ah, aa)
        if math.isnan(b[_B_TAU_ZERO]) and e1 < 0.0 <= _energy(z[_S], z[_Y], ah, aa):
            b[_B_TAU_ZERO] = _root_state(_EV_ENERGY, 0.0, h_end, z, z1, k1, row, hist)[_TAU]
        if e1 < b[_B_ECAP]:  # the capture test, with the engine's margin
            captured = True
            b[_B_TAU_CAP] = b[_B_TAU_ZERO] if not math.isnan(b[_B_TAU_ZERO]) else _root_state(
                _EV_ENERGY, b[_B_ECAP], h_end, z, z1, k1, row, hist)[_TAU]
    for i in range(_N):
        z[i] = z1[i]
    refresh = False
    if conservative and z[_S] > 0.0:
        # undamped with adhesion: the normal motion keeps its energy y0^2 / 2 exactly (it does
        # not feel the tangential state), so y is put back on that energy; round-off of the
        # order of rtol times the well's depth would otherwise trap a slow sphere in the well
        # (y0 ~ 1e-5: the step limit, where the engine mirrors the way out)
        v2 = 2.0 * (0.5 * y0 * y0 - _energy(z[_S], 0.0, ah, aa))
        z[_Y] = math.copysign(math.sqrt(v2), z[_Y]) if v2 > 0.0 else 0.0
        refresh = True
    if at_rest:
        z[_WT] = z[_WTP] = 0.0
        if captured:
            b[_B_HELD] += 1.0
    b[_B_TURNS] += 1.0 if turned else 0.0
    load_side, slipping = _tangential_update(z, k1, k, row, hist, turned, restart, b[_B_LOAD_SIDE],
                                             b[_B_SLIPPING] != 0.0, b[_B_SLIP_CHANGE] != 0.0, hysteretic, elastic,
                                             refresh)
    if rolling and z[_S] > 0.0:
        _hold_rolling(z, k1, atol[_WT] * min(max(1.0, h_end * _rolling_approach(z, k1) / atol[_WT]), _HOLD_SPAN),
                      row, hist)
    b[_B_LOAD_SIDE], b[_B_SLIPPING], b[_B_CAPTURED] = load_side, 1.0 if slipping else 0.0, 1.0 if captured else 0.0
    b[_B_TAU_J], b[_B_SMAX] = tau_j, max(smax, z[_S])
    return driver.GO_ON


@njit(cache=True)
def _exit_on_invariant_line(z, row, j_stop, b):
    """The rest of an impact without adhesion on the inertia-free path y = -1/C1 (the engine's
    jump, :func:`~microimpact.solvers.engine._inertia_free_jump`): the line is an exact invariant of
    xi'' = -a_h xi^(3/2) (1 + C1 y), on which F_n = 0, so the sphere leaves at y = -1/C1 after
    tau = C1 xi, and no tangential force acts on the way (F_lim = f |F_n| = 0, and F_po = 0; the
    rolling torque mu_r r |F_n| = 0): the tangential state is kept, the stored displacement released
    at separation (:func:`_separate`). The relaxation onto the line from within 10 atol_y of it is
    booked in J and J_a as the engine books it (|dy|); its tangential impulse, at most
    f 10 atol_y, is left out. z becomes the state at separation; outcome rebound into b.

    Why: at zeta_H ~ 1e6 and 1e4 m/s the exit takes ~(C1 xi)^2 explicit steps: the step limit
    under every compliant law (the ring law took the line before)."""
    xi0 = z[_S] * z[_S]
    y_t = -1.0 / row[0]
    dj = abs(z[_Y] - y_t)
    if math.isnan(b[_B_TAU_J]) and z[_J] < j_stop <= z[_J] + dj:
        b[_B_TAU_J] = z[_TAU]
    e_now = _energy(z[_S], z[_Y], row[2], row[3])
    z[_J] += dj
    z[_JA] += z[_S] * dj
    z[_TAU] += row[0] * xi0
    z[_S], z[_Y] = 0.0, y_t
    z[_D] += e_now - 0.5 * y_t * y_t
    z[_FT] = z[_FTP] = 0.0  # out of contact: nothing stored
    b[_B_OUTCOME] = 0.0


@njit(cache=True)
def _law_creep(z, k1, p, w, atol, rec, rec_cap):
    """The inertia-free limit before the capture: a sphere not yet captured whose normal motion
    follows the slow manifold into the equilibrium (the engine's :func:`~microimpact.solvers.engine._inertia_free`,
    its thresholds) is captured; the integration stops there with outcome _CREEPING, and its tail
    is taken in closed form as that of a creeping captured sphere (:func:`_captured_stop`,
    :func:`_settle_captured`). The capture time is where the energy on the manifold falls below
    zero (or the capture margin), as the engine's jump finds it. A creeping captured sphere ends in
    :func:`_captured_stop` (unchanged); no jump that resumes the integration (the tangential state
    would have to be carried along it).

    Why: a nanometre sphere under zeta_A ~ 1e6 creeps from first contact into the well at
    y_m ~ 1 / C2, so slowly (tau ~ C2 to reach the equilibrium) that it is not captured within the
    step budget (the energy test needs an approach of ~rtol^(2/3) of the equilibrium): the step
    limit, at C2 ~ 2e9 (issue 55's corner of the stress domain)."""
    hist, b = w
    row = p[5]
    c1, c2, ah, aa = row[0], row[1], row[2], row[3]
    if aa == 0.0 and c1 > 0.0 and z[_S] > 0.0:
        slow, _ = _inertia_free(z, atol[_Y], c1, c2, ah, aa, 0.0)
        if not slow:
            return driver.CREEP_NONE
        _exit_on_invariant_line(z, row, p[6], b)
        return driver.CREEP_END
    tail_closed = not row[10] > 0.0 or row[6] > 0.5  # as _law_captured_end: a closed form of the tail
    if b[_B_CAPTURED] != 0.0 or not (aa > 0.0 and (c1 > 0.0 or c2 > 0.0) and z[_S] > 0.0 and tail_closed):
        return driver.CREEP_NONE
    xe = b[_B_XE]
    slow, xi_t = _inertia_free(z, atol[_Y], c1, c2, ah, aa, xe)
    if not (slow and xi_t == xe):
        return driver.CREEP_NONE
    tau_zero = b[_B_TAU_ZERO]
    if math.isnan(tau_zero):
        tau_zero = _slow_event_time(z, xe, 0.0, _SLOW_ENERGY, c1, c2, ah, aa)
    tau_cap = _slow_event_time(z, xe, b[_B_ECAP], _SLOW_ENERGY, c1, c2, ah, aa)
    b[_B_TAU_ZERO] = tau_zero
    b[_B_TAU_CAP] = tau_cap if math.isnan(tau_zero) else tau_zero
    b[_B_CAPTURED], b[_B_OUTCOME] = 1.0, _CREEPING
    return driver.CREEP_END


@njit(cache=True)
def _law_captured_end(z, k1, p, w, atol, long_tail):
    """Whether a captured sphere stops (:func:`_captured_stop`), its outcome code into b."""
    b = w[1]
    if b[_B_CAPTURED] == 0.0:
        return False
    row = p[5]
    tail_closed = not row[10] > 0.0 or row[6] > 0.5  # a captured sphere's tail is taken in closed form
    # a captured sphere with friction limited at rest and no rolling resistance ends rolling at its
    # angular momentum about the contact point, which the contact force conserves (_rolling_state):
    # nothing after the capture and the largest penetration changes the result
    conserved = row[11] > 0.5  # stops_at_capture(contact), column 11 of the parameter rows
    outcome = _captured_stop(z, k1, atol, p[8], b[_B_PEAKED] != 0.0, conserved, p[6], p[7], tail_closed, row,
                             b[_B_XE], b[_B_OMEGA0], b[_B_CEQ], long_tail)
    b[_B_OUTCOME] = outcome
    return outcome > 0


@njit(cache=True)
def _law_finish(status, z, p, w, n_steps, n_rej):
    """The driver's :class:`~microimpact.solvers.driver.Trace` of a coupled impact (its whole end
    state in ``state``)."""
    b = w[1]
    row = p[5]
    outcome, smax = int(b[_B_OUTCOME]), b[_B_SMAX]
    if outcome >= 1 and b[_B_PEAKED] == 0.0:  # crept into the equilibrium without turning: its supremum
        smax = max(smax, math.sqrt(b[_B_XE]))
    return driver.Trace(status, outcome, z[_Y], z[_TAU], z[_D], z[_J], z[_JA], smax * smax, b[_B_TAU_CAP], b[_B_TAU_J],
                        _energy(z[_S], z[_Y], row[2], row[3]), n_steps, n_rej, 0, z, int(b[_B_TURNS]),
                        int(b[_B_HELD]))


#: the one driver (:mod:`.driver`) running the coupled law
_drive = driver.make_driver(driver.Law(_law_start, _law_args, _step, _law_too_small, _law_norm, _law_events,
                                       _law_creep, _law_captured_end, _law_finish, _N))
_NO_RECORD = np.zeros((1, 3))


@njit(cache=True)
def coupled_kernel(y0, vt0, vtp0, wt0, wtp0, p, rtol, j_stop, ja_stop, settle, max_steps):
    """Integrate one impact of the coupled model (nondimensional; see the module docstring) with the
    one driver.

    Parameters (all nondimensional): y0 incident normal rate; vt0, vtp0 tangential velocity;
    wt0, wtp0 rim speeds r omega_t, r omega_t'; p the law's parameters (see :func:`_rhs`); j_stop,
    ja_stop the impulses after which a captured sphere's sliding and twist are over (rigid
    contact); settle the oscillation amplitude (relative to the equilibrium) at which a captured
    sphere's integration stops (its tangential rest follows in closed form: see the module
    docstring).

    Returns the :class:`~microimpact.solvers.driver.Trace` (its ``state`` the 12 states at the end,
    its outcome 0 for a rebound, 1, _CREEPING or _LONG_TAIL for a capture; its steps the accepted
    and the rejected ones, whose sum is bounded by ``max_steps``).
    """
    return _drive((y0, vt0, vtp0, wt0, wtp0, p, j_stop, ja_stop, settle), rtol, max_steps, _NO_RECORD, 0)


@njit_batch
def coupled_many(y0, vt0, vtp0, wt0, wtp0, p, rtol, j_stop, ja_stop, settle, max_steps, out_state, out_info):
    """:func:`coupled_kernel` for many impacts in parallel; p has one row per impact.

    Writes the end states into ``out_state`` (n, 12) and (status, outcome, largest xi, tau at
    capture, tau at slip end, steps tried (accepted and rejected), turning points of the hysteretic
    law, rolling stops after the capture) into ``out_info`` (n, 8).
    """
    for i in prange(y0.shape[0]):
        r = coupled_kernel(y0[i], vt0[i], vtp0[i], wt0[i], wtp0[i], p[i], rtol, j_stop[i], ja_stop[i], settle,
                           max_steps)
        for j in range(_N):
            out_state[i, j] = r.state[j]
        out_info[i, 0] = r.status
        out_info[i, 1] = r.outcome
        out_info[i, 2] = r.max_approach
        out_info[i, 3] = r.tau_capture
        out_info[i, 4] = r.tau_slip_end
        out_info[i, 5] = r.n_steps + r.n_rejected
        out_info[i, 6] = r.turning_points
        out_info[i, 7] = r.held_rolling_stops


#: amplitude of the captured normal oscillation, relative to the equilibrium penetration, at which
#: the integration of a captured sphere stops (the tangential rest is then taken in closed form)
SETTLE_AMPLITUDE = 1e-6
#: the settle amplitude is at least this multiple of rtol: integration error holds the amplitude of
#: a long captured oscillation at 15-40 rtol (measured at rtol 1e-6 and 1e-7), so a smaller one
#: may never be reached (the step limit was, at rtol 1e-7 with Mindlin contact)
SETTLE_PER_RTOL = 1e3

#: default step limit of one impact (the status code _MAX_STEPS is a different name)
_DEFAULT_MAX_STEPS = 2_000_000


def stops_at_capture(contact) -> bool:
    """Whether a captured impact of ``contact`` ends at its capture (past the largest penetration):
    a compliant contact with the pulloff limit and no rolling resistance, whose result is then
    fixed by its angular momentum about the contact point (module docstring).

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> held = c.with_(tangential_model="mindlin", shear_modulus=0.3 * c.stiffness, friction_model="pulloff")
    >>> stops_at_capture(held), stops_at_capture(held.with_(rolling_friction=0.01)), stops_at_capture(c)
    (True, False, False)
    """
    return contact.tangential_model != "rigid" and contact.friction_model == "pulloff" and contact.rolling_friction == 0.0


def _rolling_state(states, rows, krot):
    """Set the tangential velocities and rim speeds of ``rows`` of ``states`` (n, 12) to rolling at
    their angular momentum about the contact point.

    The contact force acts at the contact point, so m v_t - I omega_t' / r and m v_t' + I omega_t / r
    are conserved; rolling (u = 0) at that angular momentum is v = (k v - w) / (k + 1), w = -v, with
    k = m r^2 / I (2.5 for a homogeneous sphere: the 5/7 rule). It is also the time average of a
    stuck elastic vibration of the contact (its slip averages to zero).
    """
    vt = (krot * states[rows, _VT] - states[rows, _WTP]) / (krot + 1.0)
    vtp = (krot * states[rows, _VTP] + states[rows, _WT]) / (krot + 1.0)
    states[rows, _VT], states[rows, _WTP] = vt, -vt
    states[rows, _VTP], states[rows, _WT] = vtp, vtp


@njit(cache=True)
def _tail_impulses(s, y, p, outcome):
    """(J, J_a) still to come, nondimensional, of captured spheres whose integration stopped at
    (s, y) near the equilibrium: the linear damped tail's total variation of y (the friction
    impulse, F_n = -dy/dtau) and that times a = sqrt(xi_e) (the twist impulse); of those that
    stopped creeping on the slow manifold (``outcome`` _CREEPING), |y| (y falls monotonically to 0)
    and int s |dy| along the manifold; of those stopped by the budget (_LONG_TAIL) while weakly
    damped (C <= 1e-2 omega0) in the well, the averaged tail (the engine's policy for each)."""
    j = np.empty(s.size)
    ja = np.empty(s.size)
    for i in range(s.size):
        c1, c2, ah, aa = p[i, 0], p[i, 1], p[i, 2], p[i, 3]
        xe, omega0, ceq = _equilibrium(c1, c2, ah, aa)
        if outcome[i] == _CREEPING:
            j[i] = abs(y[i])
            ja[i] = _slow_twist(s[i] * s[i], xe, c1, c2, ah, aa)
            continue
        e_now = _energy(s[i], y[i], ah, aa)
        if outcome[i] == _LONG_TAIL and ceq <= 1e-2 * omega0 and e_now < 0.0:
            j[i], ja[i] = _averaged_tail(e_now, c1, c2, ah, aa, xe)
            continue
        j[i] = _linear_tail_variation(s[i] * s[i] - xe, y[i], omega0, ceq)
        ja[i] = j[i] * math.sqrt(xe)
    return j, ja


def _rolling_tail(states, rows, p, outcome):
    """Rolling resistance over the rest of the normal oscillation of captured frictionless spheres
    (pulloff friction, f = 0), after the integration stopped at a tail (``outcome``); edits
    ``states`` (n, 12).

    Without friction no tangential force acts, so only the torque mu_r r |F_n| against omega_r
    changes the motion: the rim speed |w| = r |omega_r| falls by k mu_r R (k = m r^2 / I) at a fixed
    direction, to rest at the least, where R = int |F_n| dt is the total variation of the normal
    rate of the tail (:func:`_tail_impulses`, the friction impulse of the paper's law).
    Nondimensional (speeds in L / T_c, R in m L / T_c): d w / d tau = -k mu_r |F_n| w / |w|
    (:func:`_rhs`).

    Not for spheres held by friction (f > 0): they roll, but the stuck contact vibrates, and where
    the vibration's rim speed exceeds the mean rolling speed omega_r turns with it and the torque
    averages out. Measured (paper's microsphere, Mindlin and Mindlin-Deresiewicz contact, mu_r =
    0.01, 0.05 and 0.2 m/s at 40 deg): the followed rolling speed changes by 0.06-1 % from an
    amplitude of 1e-2 of the equilibrium down to 1e-6, while this closed form, which takes the
    torque along the mean rolling, removed 30 % more. Their tail's rolling resistance is left out,
    and :func:`_held_rolling_error` bounds what it could still change.
    """
    j_tail, _ = _tail_impulses(states[rows, _S], states[rows, _Y], p[rows], outcome[rows])
    loss = p[rows, 8] * p[rows, 10] * j_tail
    rim = np.hypot(states[rows, _WT], states[rows, _WTP])
    with np.errstate(invalid="ignore", divide="ignore"):
        factor = np.where(rim > 0.0, np.clip(1.0 - loss / rim, 0.0, 1.0), 1.0)
    states[rows, _WT] *= factor
    states[rows, _WTP] *= factor


#: a captured sphere held by friction with rolling resistance has its tangential outcome checked
#: (:func:`_held_rolling_error`); it is reported as not determined where the error estimate exceeds
#: this fraction of its speed scale (the larger of the incident and the final |v_t| + r |omega_t|)
HELD_ROLLING_TOLERANCE = 1e-3
#: the check's second run is at this multiple of rtol (the error estimate of the coarser run, an
#: upper estimate of the finer one's where the integration converges), or at rtol divided by it
#: where the multiple would pass 1e-4
HELD_ROLLING_CHECK_FACTOR = 10.0


def _held_rolling(contact, captured, f):
    """Captured impacts held by friction (the pulloff limit, f > 0) with rolling resistance."""
    return captured & (contact.friction_model == "pulloff") & (f > 0.0) & (contact.rolling_friction > 0.0)


def _held_rolling_tail_bound(states, held, outcome, p):
    """Bound on what the rolling resistance left out after the stop can still change the rolling
    speed of the ``held`` impacts (:func:`_held_rolling`; nondimensional, 0 elsewhere).

    The torque mu_r r |F_n| changes only the angular momentum about the contact point, by at most
    mu_r r R, where R is the rest of int |F_n| dt (:func:`_tail_impulses`); the rolling speed at that
    angular momentum (:func:`_rolling_state`) by k mu_r R / (k + 1), k = m r^2 / I.
    """
    bound = np.zeros(held.size)
    rows = np.flatnonzero(held)
    if rows.size:
        j_tail, _ = _tail_impulses(states[rows, _S], states[rows, _Y], p[rows], outcome[rows])
        bound[rows] = p[rows, 8] * p[rows, 10] * j_tail / (p[rows, 8] + 1.0)
    return bound


def _second_solve_difference(contact, v_in, w_in, f, out, rows, rtol, max_steps):
    """Largest difference of (v_t, v_t', r omega_t, r omega_t') [m/s] between ``out`` and a second
    solve of ``rows`` at ``rtol``; inf for an impact whose second solve fails (then it is not
    determined, and the first result still stands)."""
    def again(sel):
        return solve_coupled(contact, tuple(x[sel] for x in v_in), tuple(x[sel] for x in w_in), f[sel],
                             rtol=rtol, max_steps=max_steps, check_held_rolling=False)

    def difference(res, sel):
        d = np.zeros(len(sel))
        for key, scale in (("v_t", 1.0), ("v_tp", 1.0), ("omega_t", contact.radius), ("omega_tp", contact.radius)):
            d = np.maximum(d, scale * np.abs(out[key][sel] - getattr(res, key)))
        return d

    try:
        return difference(again(rows), rows)
    except CoupledError:  # one at a time, to keep the checks of the others
        diff = np.full(rows.size, np.inf)
        for j in range(rows.size):
            with contextlib.suppress(CoupledError):
                diff[j] = difference(again(rows[j:j + 1]), rows[j:j + 1])[0]
        return diff


def _held_rolling_error(contact, v_in, w_in, f, out, held, info, tail_bound, rtol, max_steps, check):
    """Error estimate [m/s] of the final tangential velocity and rim speed of captured spheres held
    by friction with rolling resistance, and whether it exceeds :data:`HELD_ROLLING_TOLERANCE`.

    Such a sphere rolls at its angular momentum about the contact point, which only the rolling
    torque changes, and the torque's direction follows omega_r. The stuck contact vibrates: where
    the vibration's rim speed exceeds the mean rolling, omega_r reverses with it (rolling stops
    after the capture, counted by :func:`coupled_kernel`), and each reversal is a discontinuity of
    model A's torque that the integration must resolve. On the stress sweep (law
    ``mindlin_deresiewicz_pulloff_rolling``, seed 0, 300 cases) this check flags 45 of the 146
    captured spheres held by friction at rtol 1e-8 and 40 at 1e-10; in 5 of them the result also
    moves between the two tolerances beyond the sweep's convergence tolerance (case 20: v_t / v =
    -0.021, -0.033, -0.033 at rtol 1e-8, 1e-10, 1e-12). There omega_r circles rest in the plane at
    ~1e-9 of the speed scale with steps of |omega_r| / |d omega_r / dt|, a stage of each step on
    either side of rest,
    until the integration stops at a twentieth of the step budget and the rolling resistance still
    to come is left out. Others with hundreds of reversals converge to 1e-7, as the paper's
    microsphere at 0.05 m/s and 40 deg (30 reversals, 1e-5). Whether an impact is of the first kind
    is not known before it is run, so these impacts (reversals after the capture, or a stop by the
    step budget) run a second time at :data:`HELD_ROLLING_CHECK_FACTOR` x rtol, and the estimate is
    the largest difference of (v_t, v_t', r omega_t, r omega_t') plus
    :func:`_held_rolling_tail_bound`, the rolling resistance the integration left out. Impacts
    without reversals, whose torque stays against the mean rolling, carry at most the rolling speed
    itself (the torque can only stop it). A rolling resistance with its own elastic spring (model C
    of Ai et al. 2011) holds a stuck vibration elastically instead of reversing a constant torque:
    LAMMPS's ``rolling sds``, ``rolling_model="lammps_sds"`` with a DEM tangential law
    (:mod:`microimpact.model.dem_rolling`).

    References
    ----------
    Ai, J., Chen, J.-F., Rotter, J. M., Ooi, J. Y. (2011). Assessment of rolling resistance models
    in discrete element simulations. Powder Technology 206, 269-282.
    """
    reversed_ = info[:, 7] > 0
    # without reversals the torque stays against the mean rolling: it can at most stop it
    error = np.where(reversed_, tail_bound, np.minimum(tail_bound, np.hypot(out["v_t"], out["v_tp"])))
    rows = np.flatnonzero(held & (reversed_ | (info[:, 1] == _LONG_TAIL)))
    if check and rows.size:
        # coarser where that is still a tolerance the solver is meant for, else finer
        coarse = HELD_ROLLING_CHECK_FACTOR * rtol
        check_rtol = coarse if coarse <= 1e-4 else rtol / HELD_ROLLING_CHECK_FACTOR
        error[rows] += _second_solve_difference(contact, v_in, w_in, f, out, rows, check_rtol, max_steps)
    scale = np.maximum(np.hypot(v_in[1], v_in[2]) + contact.radius * np.hypot(w_in[1], w_in[2]),
                       np.hypot(out["v_t"], out["v_tp"]) + contact.radius * np.hypot(out["omega_t"], out["omega_tp"]))
    undetermined = held & (error > HELD_ROLLING_TOLERANCE * scale)
    if check and undetermined.any():
        n = int(undetermined.sum())
        worst = float(np.max(error[undetermined] / np.maximum(scale[undetermined], 1e-300)))
        warnings.warn(
            f"{n} of {undetermined.size} impacts: the final tangential velocity and spin of a captured sphere held "
            f"by friction with rolling resistance are not determined (error estimate up to {worst:.2g} of the "
            f"speed scale): the rolling torque reverses with the held contact's vibration (model A); the result "
            f"says so in not_determined", UndeterminedOutcomeWarning, stacklevel=5)
    return error, undetermined


def _settle_captured(contact, states, captured, outcome, p, unit, j_unit, ja_unit, jl, jal):
    """The tangential rest of captured spheres after the integration stopped (module docstring).

    Edits ``states`` (n, 12); returns the friction and twist impulses [N s], [N m s] that the
    closed-form maps (the twist, the rigid contact) are to use: the followed ones ``jl``, ``jal``
    plus the tail's, unbounded with a friction limit at rest. ``unit``, ``j_unit``, ``ja_unit``: the
    units of speed [m/s], friction impulse [N s] and twist impulse [N m s] of each impact.
    """
    rows = np.flatnonzero(captured)
    if rows.size == 0:
        return jl, jal
    jl, jal = jl.copy(), jal.copy()
    if contact.friction_model == "pulloff":
        # (without friction, f = 0, there is no limit at rest: the impulses stay as followed, and the
        # twist map would otherwise meet 0 x inf)
        held = rows[p[rows, 4] > 0.0]
        jl[held] = jal[held] = np.inf
        if p[0, 9] > 0.0:
            # frictionless (f = 0) spheres keep their tangential velocity and spin: no force holds them
            _rolling_state(states, held, p[0, 8])
            if p[0, 10] > 0.0:
                _rolling_tail(states, rows[p[rows, 4] == 0.0], p, outcome)
        return jl, jal
    m, inertia, r = contact.mass, contact.moment_of_inertia, contact.radius
    j_tail, ja_tail = _tail_impulses(states[rows, _S], states[rows, _Y], p[rows], outcome[rows])
    u = unit[rows]
    j_tail *= j_unit[rows]
    ja_tail *= ja_unit[rows]
    if p[0, 9] > 0.0:  # compliant: the tail slides the state as the rigid contact's map does
        zero = np.zeros(rows.size)
        tail = tangential_outcome(m, inertia, r, p[rows, 4], (zero, states[rows, _VT] * u, states[rows, _VTP] * u),
                                  (zero, states[rows, _WT] * u / r, states[rows, _WTP] * u / r), j_tail, zero)
        states[rows, _VT], states[rows, _VTP] = tail["v_t"] / u, tail["v_tp"] / u
        states[rows, _WT], states[rows, _WTP] = tail["omega_t"] * r / u, tail["omega_tp"] * r / u
    jl[rows] += j_tail
    jal[rows] += ja_tail
    return jl, jal


#: column 9 of the parameter rows: the tangential model
_TANGENTIAL_MODES = {"rigid": 0.0, "mindlin": 1.0, "mindlin_deresiewicz": 2.0}


def _parameter_rows(contact, sc, c1, c2, f, length, time) -> np.ndarray:
    """The law's parameters of each impact, one row each (the columns of :func:`_rhs`): C1, C2, the
    Hertz and adhesion coefficients, f, the pull-off force, the friction model, the Mindlin
    stiffness, m r^2 / I, the tangential model (0 rigid, 1 Mindlin, 2 Mindlin-Deresiewicz) and
    mu_r, and 1 where a captured impact ends at its capture (:func:`stops_at_capture`); ``length``,
    ``time`` the impacts' scales [m], [s]."""
    m, r = contact.mass, contact.radius
    mode = _TANGENTIAL_MODES[contact.tangential_model]
    p = np.empty((f.size, 12))
    p[:, 0] = np.broadcast_to(c1, f.shape)
    p[:, 1] = np.broadcast_to(c2, f.shape)
    p[:, 2], p[:, 3] = sc.a_hertz, sc.a_adhesion
    p[:, 4] = f
    p[:, 5] = _tc.nondimensional_pulloff_force(sc.a_hertz, sc.a_adhesion)
    p[:, 6] = 1.0 if contact.friction_model == "pulloff" else 0.0
    p[:, 7] = (8.0 * contact.shear_modulus * np.sqrt(r * length) * time**2 / m) if mode > 0.0 else 0.0
    p[:, 8] = m * r * r / contact.moment_of_inertia
    p[:, 9] = mode
    p[:, 10] = contact.rolling_friction
    p[:, 11] = 1.0 if stops_at_capture(contact) else 0.0
    return p


def _tangential_si(contact, mindlin, states, info, f, v_in, w_in, slip, jl, jal, u, time):
    """The tangential outcome in SI: (velocities and spins by name, slip ended, slip end time [s]).

    A compliant contact's tangential state is integrated and its twist keeps its closed form
    (torque (3 pi/16) f a load); the rigid contact's whole outcome is the closed-form map of the
    impulses ``jl``, ``jal`` [N s], [N m s]."""
    m, inertia, r = contact.mass, contact.moment_of_inertia, contact.radius
    if mindlin:
        tw = tangential_outcome(m, inertia, r, f, v_in, w_in, 0.0, jal)
        out = {"v_t": states[:, _VT] * u, "v_tp": states[:, _VTP] * u, "omega_n": tw["omega_n"],
               "omega_t": states[:, _WT] * u / r, "omega_tp": states[:, _WTP] * u / r}
        slip_out = np.hypot(out["v_t"] + r * out["omega_tp"], out["v_tp"] - r * out["omega_t"])
        return out, slip_out <= 1e-9 * np.maximum(slip, 1e-300), np.full(slip.size, np.nan)
    tan = tangential_outcome(m, inertia, r, f, v_in, w_in, jl, jal)
    slip_end_time = np.where(slip == 0.0, 0.0, info[:, 4] * time)
    return ({k: tan[k] for k in ("v_t", "v_tp", "omega_n", "omega_t", "omega_tp")}, tan["slip_ended"],
            np.where(tan["slip_ended"], slip_end_time, np.nan))



def _nondimensional_stops(mindlin: bool, m, inertia, r, f, slip, w_n, u, length) -> tuple[np.ndarray, np.ndarray]:
    """(J, J_a) at which sliding and twist end (:func:`stop_impulses`), in units of m u and
    m u sqrt(r L); for a compliant (Mindlin) law none: (inf, 0)."""
    if mindlin:
        return np.full(slip.size, np.inf), np.zeros(slip.size)
    j_star, ja_star = stop_impulses(m, inertia, f, slip, w_n)
    return j_star / (m * u), ja_star / (m * u * np.sqrt(r * length))


def _check_status(info: np.ndarray, speed: np.ndarray) -> None:
    """CoupledError for the first impact whose integration failed (``info[:, 0]``: the step limit
    or a step-size underflow), naming its normal speed [m/s] and its steps."""
    bad = info[:, 0] != _OK
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        what = "step limit reached" if info[i, 0] == _MAX_STEPS else "step size underflow"
        raise CoupledError(f"coupled solver failed for normal speed {float(speed[i])!r} m/s: {what} "
                           f"after {int(info[i, 5])} steps")

def solve_coupled(contact, velocity_in, omega_in, friction, *, rtol: float, max_steps: int = _DEFAULT_MAX_STEPS,
                  check_held_rolling: bool = True) -> SolutionBatch:
    """Impacts of a contact that selects tangential compliance or adhesion-aware friction.

    Parameters
    ----------
    contact : Contact
        ``tangential_model`` "rigid", "mindlin" or "mindlin_deresiewicz", ``friction_model`` "net" or
        "pulloff", ``rolling_friction`` mu_r >= 0 (compliant models only).
    velocity_in : tuple of 3 arrays
        (v_n, v_t, v_t') before contact, v_n < 0, broadcast to one shape. [m/s]
    omega_in : tuple of 3 arrays
        (omega_n, omega_t, omega_t') before contact. [rad/s]
    friction : array
        Coulomb coefficient f per impact. [-]
    rtol : float
        Relative tolerance of the integration. [-]
    max_steps : int
        Step limit of one impact.
    check_held_rolling : bool
        Check the tangential outcome of captured spheres held by friction with rolling resistance
        (:func:`_held_rolling_error`); False in that check's own second run.

    Returns
    -------
    SolutionBatch
        1-D arrays (SI): ``captured``, ``e_n``, ``v_t``, ``v_tp`` [m/s], ``omega_n``,
    ``omega_t``, ``omega_tp`` [rad/s], ``contact_time``, ``capture_time``, ``slip_end_time`` [s],
    ``max_penetration`` [m], ``turning_points`` (hysteretic law), ``friction_impulse`` (int of the
    friction load, |F_n| or |F_n + 2 F_po|; for a captured sphere over the part followed, as
    :class:`~microimpact.model.kinematics.ImpactResult` says) [N s], ``slip_ended`` (bool),
    ``n_steps``, ``tangential_error`` (the error estimate of the final tangential velocity and rim
    speed of a captured sphere held by friction with rolling resistance, else 0) [m/s] and
    ``not_determined`` (bool: that estimate exceeds :data:`HELD_ROLLING_TOLERANCE` of the speed
    scale; an :class:`~microimpact.solvers.UndeterminedOutcomeWarning` says how many).

    Raises
    ------
    CoupledError
        If an impact reaches the step limit or the step size underflows.

    """
    _, (v_n, v_t, v_tp, w_n, w_t, w_tp, f) = flat_broadcast(
        *(np.asarray(a, dtype=float) for a in (*velocity_in, *omega_in, friction)))
    speed = -v_n
    sc, y0, c1, c2 = _law.nondimensional_impact(contact, speed)
    y0 = np.array(np.broadcast_to(y0, speed.shape))
    u = np.array(np.broadcast_to(sc.speed, speed.shape))
    length = np.array(np.broadcast_to(sc.length, speed.shape))
    time = np.array(np.broadcast_to(sc.time, speed.shape))
    m, inertia, r = contact.mass, contact.moment_of_inertia, contact.radius
    p = _parameter_rows(contact, sc, c1, c2, f, length, time)
    mode = _TANGENTIAL_MODES[contact.tangential_model]
    mindlin = mode > 0.0
    aware = contact.friction_model == "pulloff"
    slip = np.hypot(v_t + r * w_tp, v_tp - r * w_t)
    j_stop, ja_stop = _nondimensional_stops(mindlin, m, inertia, r, f, slip, w_n, u, length)
    j_unit = m * u
    ja_unit = j_unit * np.sqrt(r * length)
    states = np.empty((speed.size, _N))
    info = np.empty((speed.size, 8))
    coupled_many(y0, v_t / u, v_tp / u, r * w_t / u, r * w_tp / u,
                 p, float(rtol), np.ascontiguousarray(j_stop), np.ascontiguousarray(ja_stop),
                 max(SETTLE_AMPLITUDE, SETTLE_PER_RTOL * rtol),
                 int(max_steps), states, info)
    _check_status(info, speed)
    captured = info[:, 1] >= 1
    jl = states[:, _J] * j_unit
    jal = states[:, _JA] * ja_unit
    if aware and not mindlin:  # sliding that ends at rest, after the integration stopped
        late = captured & np.isnan(info[:, 4]) & np.isfinite(j_stop) & (states[:, _J] < j_stop)
        info[late, 4] = states[late, _TAU] + (j_stop[late] - states[late, _J]) / (2.0 * p[late, 5])
    held = _held_rolling(contact, captured, f)
    tail_bound = _held_rolling_tail_bound(states, held, info[:, 1], p) * u
    j_map, ja_map = _settle_captured(contact, states, captured, info[:, 1], p, u, j_unit, ja_unit, jl, jal)
    out, slip_ended, slip_end_time = _tangential_si(contact, mindlin, states, info, f, (v_n, v_t, v_tp),
                                                    (w_n, w_t, w_tp), slip, j_map, ja_map, u, time)
    error, undetermined = _held_rolling_error(contact, (v_n, v_t, v_tp), (w_n, w_t, w_tp), f, out, held, info,
                                              tail_bound, rtol, max_steps, check_held_rolling)
    return SolutionBatch(
        captured=captured,
        e_n=np.where(captured, 0.0, -states[:, _Y] / y0),
        **out,
        contact_time=np.where(captured, np.inf, states[:, _TAU] * time),
        capture_time=info[:, 3] * time,
        slip_end_time=slip_end_time,
        max_penetration=info[:, 2] * length,
        friction_impulse=jl,
        slip_ended=np.asarray(slip_ended, dtype=bool),
        n_steps=info[:, 5].astype(np.int64),
        turning_points=info[:, 6].astype(np.int64),
        tangential_error=error,
        not_determined=undetermined,
    )
