"""The impact coefficients of Eqs. (21)-(25): restitution, impulse ratios and energy loss ratios.

One compiled scalar kernel (:func:`coefficients_kernel`) serves the single impact, the batches of
:func:`impact_coefficients` and the fused family pass of :mod:`microimpact.solvers.family`. Frame
and signs as in :mod:`microimpact.model.kinematics`.
"""

from __future__ import annotations

import math

import numpy as np
from microimpact._numba import njit
from microimpact.model.kinematics import flat_broadcast

__all__ = ["impact_coefficients", "coefficients_kernel"]


@njit(cache=True)
def coefficients_kernel(mass, moment_of_inertia, vn_i, vt_i, vtp_i, wn_i, wt_i, wtp_i,
                        vn_r, vt_r, vtp_r, wn_r, wt_r, wtp_r, captured):
    """Scalar Eqs. (21)-(25) (compiled); see :func:`impact_coefficients`. Returns
    (e_n, mu_t, mu_tp, K_L, K_t).

    Examples
    --------
    >>> coefficients_kernel(1.0, 0.4, -2.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 0.0, 0.0, 0.0, False)[0]
    0.5
    """
    if captured:
        e_n, mu_t, mu_tp = 0.0, math.nan, math.nan
    else:
        dvn = vn_r - vn_i
        e_n = -vn_r / vn_i  # Eq. (21), both as magnitudes
        mu_t = (vt_r - vt_i) / dvn if dvn != 0.0 else math.nan  # Eq. (22)
        mu_tp = (vtp_r - vtp_i) / dvn if dvn != 0.0 else math.nan  # Eq. (23)
    v2_i = vn_i * vn_i + vt_i * vt_i + vtp_i * vtp_i
    v2_r = vn_r * vn_r + vt_r * vt_r + vtp_r * vtp_r
    w2_i = wn_i * wn_i + wt_i * wt_i + wtp_i * wtp_i
    w2_r = wn_r * wn_r + wt_r * wt_r + wtp_r * wtp_r
    energy_in = mass * v2_i + moment_of_inertia * w2_i
    k_t = (energy_in - mass * v2_r - moment_of_inertia * w2_r) / energy_in  # Eq. (24)
    k_l = (v2_i - v2_r) / v2_i  # Eq. (25)
    return e_n, mu_t, mu_tp, k_l, k_t


@njit(cache=True)
def _coefficients_many(mass, inertia, vi, wi, vr, wr, captured, out):
    for k in range(captured.shape[0]):
        r = coefficients_kernel(mass, inertia, vi[0, k], vi[1, k], vi[2, k], wi[0, k], wi[1, k], wi[2, k],
                                vr[0, k], vr[1, k], vr[2, k], wr[0, k], wr[1, k], wr[2, k], captured[k])
        for j in range(5):
            out[j, k] = r[j]


def impact_coefficients(mass, moment_of_inertia, velocity_in, omega_in, velocity_out, omega_out, captured):
    """Restitution, impulse ratios and kinetic energy loss ratios, Eqs. (21)-(25).

    Parameters
    ----------
    mass : float  [kg]
    moment_of_inertia : float  [kg m^2]
    velocity_in, velocity_out : sequence of 3 floats or arrays
        (v_n, v_t, v_t') before and after. For a captured sphere velocity_out is the final state
        (normal component 0, tangential components of the final rolling or sliding motion). [m/s]
    omega_in, omega_out : sequence of 3 floats or arrays
        (omega_n, omega_t, omega_t') before and after. [rad/s]
    captured : bool or array of bool

    Returns
    -------
    dict with e_n, mu_t, mu_tp, K_L, K_t (floats for scalar input, arrays otherwise). For a captured sphere e_n = 0 and the impulse ratios are
    NaN (there is no rebound and so no impulse ratio); K_L and K_t use the final state.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (21)-(25).

    Examples
    --------
    In at (v_n, v_t) = (-2, 1) m/s, out at (1, 0.5) m/s, no spin: e_n = 1/2, mu_t = -0.5 / 3, and
    three quarters of the kinetic energy are kept:

    >>> r = impact_coefficients(1.0, 0.4, (-2.0, 1.0, 0.0), (0.0, 0.0, 0.0), (1.0, 0.5, 0.0), (0.0, 0.0, 0.0), False)
    >>> r["e_n"], round(r["mu_t"], 12), r["K_L"]
    (0.5, -0.166666666667, 0.75)
    """
    names = ("e_n", "mu_t", "mu_tp", "K_L", "K_t")
    if np.ndim(captured) == 0 and all(np.ndim(x) == 0 for x in (*velocity_in, *omega_in, *velocity_out, *omega_out)):
        r = coefficients_kernel(float(mass), float(moment_of_inertia), *map(float, velocity_in), *map(float, omega_in),
                                *map(float, velocity_out), *map(float, omega_out), bool(captured))
        return dict(zip(names, r))
    shape, flat = flat_broadcast(*(np.asarray(x, dtype=float) for x in (*velocity_in, *omega_in, *velocity_out, *omega_out)),
                                 np.asarray(captured, dtype=bool))
    out = np.empty((5, flat[0].size))
    _coefficients_many(float(mass), float(moment_of_inertia), np.stack(flat[0:3]), np.stack(flat[3:6]),
                       np.stack(flat[6:9]), np.stack(flat[9:12]), flat[12], out)
    return {name: out[j].reshape(shape) for j, name in enumerate(names)}
