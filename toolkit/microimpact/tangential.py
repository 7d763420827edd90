"""Closed-form tangential and rotational outcome of an impact, Eqs. (16)-(20) and (18) corrected.

Coulomb friction of magnitude f |F_n| opposes the contact-point slip u = (u_t, u_t') (also while
F_n < 0, the paper's "pulling" friction). For a homogeneous sphere (I = 2 m r^2 / 5) Eqs. (16),
(17), (19) and (20) give du/dt = -(1/m + r^2/I) f |F_n| u/|u| = -(7/2)(f/m) |F_n| u/|u|: the slip
keeps its direction and its magnitude falls linearly with the friction impulse
J(t) = int_0^t |F_n| dt. Sliding therefore ends when J reaches J* = 2 m |u0| / (7 f), after which
the sphere rolls with no tangential force for the rest of the contact (no rolling resistance).
The whole tangential outcome thus depends on the normal solve only through J, and the twist
about n (torque (3 pi/16) f a |F_n|, see :func:`microimpact.forces.twist_friction_torque`) only
through J_a = int a |F_n| dt. Both are verified against the full 3-D reference solver in the tests.
"""

from __future__ import annotations

import numpy as np

from .coefficients import slip_velocity

__all__ = ["sliding_friction_impulse", "twist_stop_impulse", "tangential_outcome"]

TWIST_TORQUE_FACTOR = 3.0 * np.pi / 16.0  # torque = factor * f * a * |F_n|


def sliding_friction_impulse(mass, friction, slip_speed):
    """Friction impulse J* = 2 m |u0| / (7 f) after which sliding stops. [N s]

    Returns inf where there is no friction and 0 where there is no slip.
    """
    mass, friction, slip_speed = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (mass, friction, slip_speed)))
    with np.errstate(divide="ignore", invalid="ignore"):
        j = np.where(slip_speed > 0.0, 2.0 * mass * slip_speed / (7.0 * friction), 0.0)
    return np.where((friction == 0.0) & (slip_speed > 0.0), np.inf, j)


def twist_stop_impulse(moment_of_inertia, friction, omega_n):
    """Twist impulse J_a* = |omega_n| I / ((3 pi/16) f) after which the spin about n has stopped. [N m s]

    Returns 0 where there is no twist and inf where there is twist but no friction.
    """
    friction, omega_n = np.broadcast_arrays(np.asarray(friction, dtype=float), np.asarray(omega_n, dtype=float))
    w0 = np.abs(omega_n)
    with np.errstate(divide="ignore", invalid="ignore"):
        j = np.where(w0 > 0.0, w0 * moment_of_inertia / (TWIST_TORQUE_FACTOR * friction), 0.0)
    return np.where((friction == 0.0) & (w0 > 0.0), np.inf, j)


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
    """
    _, v_t, v_tp = (np.asarray(a, dtype=float) for a in velocity_in)
    w_n, w_t, w_tp = (np.asarray(a, dtype=float) for a in omega_in)
    f = np.asarray(friction, dtype=float)
    jn = np.asarray(friction_impulse, dtype=float)
    ja = np.asarray(twist_impulse, dtype=float)
    u_t, u_tp = slip_velocity(radius, v_t, v_tp, w_t, w_tp)
    slip = np.hypot(u_t, u_tp)
    j_star = sliding_friction_impulse(mass, f, slip)
    j_s = np.minimum(jn, j_star)
    with np.errstate(invalid="ignore", divide="ignore"):
        dir_t = np.where(slip > 0.0, u_t / slip, 0.0)
        dir_tp = np.where(slip > 0.0, u_tp / slip, 0.0)
    p_t = -f * j_s * dir_t  # tangential impulse on the sphere [N s]
    p_tp = -f * j_s * dir_tp
    out_v_t = v_t + p_t / mass
    out_v_tp = v_tp + p_tp / mass
    out_w_tp = w_tp + radius * p_t / moment_of_inertia  # Eq. (20): I dw_t'/dt = r F_t
    out_w_t = w_t - radius * p_tp / moment_of_inertia  # Eq. (19): I dw_t/dt = -r F_t'
    # friction power f |F_n| |u| with |u| = |u0| - (7/2) f J / m
    sliding_loss = f * (slip * j_s - 1.75 * f * j_s**2 / mass)
    # twist: |omega_n| falls by k J_a until it reaches zero
    k = TWIST_TORQUE_FACTOR * f / moment_of_inertia
    w0 = np.abs(w_n)
    ja_s = np.minimum(ja, twist_stop_impulse(moment_of_inertia, f, w_n))
    out_w_n = np.sign(w_n) * np.maximum(w0 - k * ja_s, 0.0)
    twist_loss = moment_of_inertia * (w0**2 - out_w_n**2) / 2.0
    slip_ended = (slip == 0.0) | (jn >= j_star)
    return {
        "v_t": out_v_t,
        "v_tp": out_v_tp,
        "omega_n": out_w_n,
        "omega_t": out_w_t,
        "omega_tp": out_w_tp,
        "slip_ended": slip_ended,
        "sliding_impulse": j_s,
        "friction_dissipation": sliding_loss + twist_loss,
    }
