"""Closed-form tangential and rotational outcome of an impact, Eqs. (16)-(20) and (18) corrected.

Coulomb friction of magnitude f |F_n| opposes the contact-point slip u = (u_t, u_t') (also while
F_n < 0, the paper's "pulling" friction). For a homogeneous sphere (I = 2 m r^2 / 5) Eqs. (16),
(17), (19) and (20) give du/dt = -(1/m + r^2/I) f |F_n| u/|u| = -(7/2)(f/m) |F_n| u/|u|: the slip
keeps its direction and its magnitude falls linearly with the friction impulse
J(t) = int_0^t |F_n| dt. Sliding therefore ends when J reaches J* = 2 m |u0| / (7 f), after which
the sphere rolls with no tangential force for the rest of the contact (no rolling resistance).
The whole tangential outcome thus depends on the normal solve only through J, and the twist
about n (torque (3 pi/16) f a |F_n|, see :func:`microimpact.model.law.twist_friction_torque`) only
through J_a = int a |F_n| dt. Both are verified against the full 3-D reference solver in the tests.
"""

from __future__ import annotations

import math

import numpy as np
from microimpact._numba import njit
from microimpact.model.kinematics import flat_broadcast
from microimpact.model.law import TWIST_TORQUE_FACTOR  # torque = factor * f * a * |F_n|

__all__ = ["stop_impulses", "tangential_outcome", "tangential_kernel"]


@njit(cache=True)
def _sliding_impulse(mass, friction, slip_speed):
    if slip_speed <= 0.0:
        return 0.0
    if friction == 0.0:
        return math.inf
    return 2.0 * mass * slip_speed / (7.0 * friction)


@njit(cache=True)
def _twist_stop(moment_of_inertia, friction, omega_n):
    w0 = abs(omega_n)
    if w0 == 0.0:
        return 0.0
    if friction == 0.0:
        return math.inf
    return w0 * moment_of_inertia / (TWIST_TORQUE_FACTOR * friction)


@njit(cache=True)
def tangential_kernel(mass, moment_of_inertia, radius, friction, v_t, v_tp, w_n, w_t, w_tp,
                      friction_impulse, twist_impulse):
    """Scalar tangential map (compiled); see :func:`tangential_outcome` for the physics and units.

    Returns (v_t, v_t', omega_n, omega_t, omega_t', slip_ended, sliding_impulse,
    friction_dissipation) after the contact.

    Examples
    --------
    A homogeneous sphere (I = 0.4 m r^2) sliding at 1 m/s without spin, given ample friction
    impulse, ends rolling at 5/7 of its speed:

    >>> out = tangential_kernel(1.0, 0.4, 1.0, 0.5, 1.0, 0.0, 0.0, 0.0, 0.0, 10.0, 0.0)
    >>> round(out[0], 12) == round(5 / 7, 12), out[5]
    (True, True)
    """
    f = friction
    u_t = v_t + radius * w_tp  # slip of the contact point, coefficients.slip_velocity
    u_tp = v_tp - radius * w_t
    slip = math.hypot(u_t, u_tp)
    j_star = _sliding_impulse(mass, f, slip)
    j_s = min(friction_impulse, j_star)
    dir_t = u_t / slip if slip > 0.0 else 0.0
    dir_tp = u_tp / slip if slip > 0.0 else 0.0
    p_t = -f * j_s * dir_t  # tangential impulse on the sphere [N s]
    p_tp = -f * j_s * dir_tp
    out_v_t = v_t + p_t / mass
    out_v_tp = v_tp + p_tp / mass
    out_w_tp = w_tp + radius * p_t / moment_of_inertia  # Eq. (20): I dw_t'/dt = r F_t
    out_w_t = w_t - radius * p_tp / moment_of_inertia  # Eq. (19): I dw_t/dt = -r F_t'
    # friction power f |F_n| |u| with |u| = |u0| - (7/2) f J / m
    sliding_loss = f * (slip * j_s - 1.75 * f * j_s * j_s / mass)
    # twist: |omega_n| falls by k J_a until it reaches zero
    k = TWIST_TORQUE_FACTOR * f / moment_of_inertia
    w0 = abs(w_n)
    ja_s = min(twist_impulse, _twist_stop(moment_of_inertia, f, w_n))
    out_w_n = math.copysign(max(w0 - k * ja_s, 0.0), w_n) if w0 > 0.0 else 0.0
    twist_loss = moment_of_inertia * (w0 * w0 - out_w_n * out_w_n) / 2.0
    slip_ended = slip == 0.0 or friction_impulse >= j_star
    return out_v_t, out_v_tp, out_w_n, out_w_t, out_w_tp, slip_ended, j_s, sliding_loss + twist_loss


@njit(cache=True)
def _tangential_many(mass, inertia, radius, f, v_t, v_tp, w_n, w_t, w_tp, jn, ja, out, ended):
    for i in range(v_t.shape[0]):
        r = tangential_kernel(mass, inertia, radius, f[i], v_t[i], v_tp[i], w_n[i], w_t[i], w_tp[i], jn[i], ja[i])
        out[0, i] = r[0]
        out[1, i] = r[1]
        out[2, i] = r[2]
        out[3, i] = r[3]
        out[4, i] = r[4]
        ended[i] = r[5]
        out[5, i] = r[6]
        out[6, i] = r[7]


@njit(cache=True)
def _stops_many(mass, inertia, f, slip, w_n, j_out, ja_out):
    for i in range(slip.shape[0]):
        j_out[i] = _sliding_impulse(mass, f[i], slip[i])
        ja_out[i] = _twist_stop(inertia, f[i], w_n[i])


def _flat(*arrays):
    return flat_broadcast(*(np.asarray(a, dtype=float) for a in arrays))


def stop_impulses(mass, moment_of_inertia, friction, slip_speed, omega_n):
    """Impulses after which sliding and twisting stop, (J*, J_a*). [N s], [N m s]

    J* = 2 m |u0| / (7 f) and J_a* = |omega_n| I / ((3 pi/16) f); each is 0 where there is no
    slip (no twist) and inf where there is slip (twist) but no friction.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (16)-(20) and (18) corrected (module docstring).

    Examples
    --------
    J* = 2 m |u0| / (7 f): m = 1 kg, slip 1 m/s, f = 0.5:

    >>> j, ja = stop_impulses(1.0, 0.4, 0.5, 1.0, 0.0)
    >>> round(float(j), 12) == round(4 / 7, 12), float(ja)
    (True, 0.0)
    """
    shape, (f, slip, w) = _flat(friction, slip_speed, omega_n)
    j, ja = np.empty(f.size), np.empty(f.size)
    _stops_many(float(mass), float(moment_of_inertia), f, slip, w, j, ja)
    return j.reshape(shape), ja.reshape(shape)


def tangential_outcome(mass, moment_of_inertia, radius, friction, velocity_in, omega_in, friction_impulse, twist_impulse):
    """Tangential velocity and spin after the contact, from the normal solve's impulses.

    Parameters
    ----------
    mass : float  [kg]
    moment_of_inertia : float  [kg m^2]
    radius : float  [m]
    friction : array_like
        Coulomb coefficient f. [-]
    velocity_in : tuple of array_like
        (v_n, v_t, v_t') before contact. [m/s]
    omega_in : tuple of array_like
        (omega_n, omega_t, omega_t') before contact. [rad/s]
    friction_impulse : array_like
        J = int |F_n| dt over the contact. [N s]
    twist_impulse : array_like
        J_a = int a |F_n| dt over the contact. [N m s]

    Returns
    -------
    dict of arrays: ``v_t``, ``v_tp`` [m/s], ``omega_n``, ``omega_t``, ``omega_tp`` [rad/s] after
    contact, ``slip_ended`` (bool), ``sliding_impulse`` (friction impulse actually transmitted,
    min(J, J*)) [N s], ``friction_dissipation`` (sliding plus twist) [J].

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (16)-(20) and (18) corrected (module docstring).

    Examples
    --------
    The sliding sphere of :func:`tangential_kernel`: it rolls off at 5/7 of its speed, and friction
    took 1/7 of the 0.5 J it had:

    >>> o = tangential_outcome(1.0, 0.4, 1.0, 0.5, (-1.0, 1.0, 0.0), (0.0, 0.0, 0.0), 10.0, 0.0)
    >>> round(float(o["v_t"]) * 7, 12), round(float(o["friction_dissipation"]) * 7, 12), bool(o["slip_ended"])
    (5.0, 1.0, True)
    """
    shape, (f, v_t, v_tp, w_n, w_t, w_tp, jn, ja) = _flat(
        friction, velocity_in[1], velocity_in[2], *omega_in, friction_impulse, twist_impulse)
    out = np.empty((7, f.size))
    ended = np.empty(f.size, dtype=np.bool_)
    _tangential_many(float(mass), float(moment_of_inertia), float(radius), f, v_t, v_tp, w_n, w_t, w_tp, jn, ja,
                     out, ended)
    names = ("v_t", "v_tp", "omega_n", "omega_t", "omega_tp", "sliding_impulse", "friction_dissipation")
    result = {name: out[i].reshape(shape) for i, name in enumerate(names)}
    result["slip_ended"] = ended.reshape(shape)
    return result
