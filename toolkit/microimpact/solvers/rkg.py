"""The paper's integrator: fixed-step Runge-Kutta-Gill (Gill 1951) on the nondimensional Eq. (27).

Cheng, Brach & Dunn (2002) integrate the normal motion with a fixed-step fourth-order
Runge-Kutta-Gill method. Here it is numba-compiled and batched over all cores (``prange``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from microimpact.solvers import engine

__all__ = ["rkg_state", "rkg_restitution"]


_G1 = 1.0 - 1.0 / math.sqrt(2.0)
_G2 = 1.0 + 1.0 / math.sqrt(2.0)


@njit(cache=True)
def _rkg_accel(xi, y, c1, c2, ah, aa):
    """xi'' of Eq. (27) in tau: -a_h xi^(3/2) (1 + C1 y) + a_a xi^(1/2) (1 - C2 y); 0 outside contact."""
    if xi <= 0.0:
        return 0.0
    s = math.sqrt(xi)
    return -ah * xi * s * (1.0 + c1 * y) + aa * s * (1.0 - c2 * y)


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
def _rkg_impact(y0, c1, c2, ah, aa, h, max_steps):
    """Fixed-step RKG from first contact (xi = 0, y = y0) to separation or capture.

    Separation: xi changes sign from + to -; its time is found by linear interpolation of xi. The
    exit speed is y at the end of that step: past the root the force is zero (free flight), so y is
    constant there and the step already integrates the motion through the separation point
    (linearly interpolating y as well would add an O(h^2.5) error). Capture: the contact energy
    E = y^2/2 + (2/5) a_h xi^(5/2) - (2/3) a_a xi^(3/2) falls below 0.

    Returns (y_out, tau_sep, n_steps, outcome) with outcome 0 rebound, 1 capture, -1 step limit.
    """
    xi = 0.0
    y = y0
    for n in range(1, max_steps + 1):
        xn, yn = _rkg_step(xi, y, h, c1, c2, ah, aa)
        if xi > 0.0 and xn <= 0.0:
            theta = xi / (xi - xn)
            return -yn, (n - 1 + theta) * h, n, 0
        xi, y = xn, yn
        if aa > 0.0 and xi > 0.0:
            s = math.sqrt(xi)
            if 0.5 * y * y + 0.4 * ah * xi * xi * s - (2.0 / 3.0) * aa * xi * s < 0.0:
                return 0.0, math.nan, n, 1
    return math.nan, math.nan, max_steps, -1


@njit(cache=True, parallel=True)
def _rkg_many(y0, c1, c2, ah, aa, h, max_steps, out):
    for i in prange(y0.shape[0]):
        r = _rkg_impact(y0[i], c1[i], c2[i], ah, aa, h[i], max_steps[i])
        out[i, 0] = r[0]
        out[i, 1] = r[1]
        out[i, 2] = r[2]
        out[i, 3] = r[3]


@njit(cache=True)
def _rkg_state_core(xi, y, c1, c2, ah, aa, h, n):
    for _ in range(n):
        xi, y = _rkg_step(xi, y, h, c1, c2, ah, aa)
    return xi, y


def rkg_state(y0: float, c1: float, c2: float, a_hertz: float, a_adhesion: float, dtau: float,
              n_steps: int, xi0: float = 0.0) -> tuple[float, float]:
    """State (xi, y) after ``n_steps`` fixed RKG steps of length ``dtau`` from (xi0, y0). [-]

    The nondimensional Eq. (27): xi'' = -a_h xi^(3/2) (1 + C1 y) + a_a xi^(1/2) (1 - C2 y).
    Started at first contact (xi0 = 0) the solution has a (tau)^(5/2) term (Hertz) or a
    (tau)^(3/2) term (adhesion), so the global order of any fixed-step Runge-Kutta method drops
    from 4 to 2.5 (Hertz) or lower; started inside the contact it is smooth and RKG is 4th order.
    """
    return _rkg_state_core(float(xi0), float(y0), float(c1), float(c2), float(a_hertz), float(a_adhesion),
                           float(dtau), int(n_steps))


def _rkg_setup(contact, speeds):
    """Nondimensional y0, C1, C2, a_h, a_a and the estimated contact duration (tau) per speed."""
    speeds = np.asarray(speeds, dtype=float)
    y0 = np.empty_like(speeds)
    c1 = np.empty_like(speeds)
    c2 = np.empty_like(speeds)
    dur = np.empty_like(speeds)
    for i, v in enumerate(speeds):
        sc = engine.nondimensional_scales(contact, float(v))
        u = sc.length / sc.time
        ch, ca = contact.damping_coefficients(float(v))
        y0[i], c1[i], c2[i] = v / u, ch * u, ca * u
        # Estimated contact duration: the engine's at a loose rtol = 1e-6 (computed once, not
        # timed); a fixed-step code needs some such estimate to choose its step.
        sol = engine.solve_normal(contact, float(v), rtol=1e-6)
        dur[i] = sol.contact_time / sc.time if math.isfinite(sol.contact_time) else 50.0
    return y0, c1, c2, sc.a_hertz, sc.a_adhesion, dur


def rkg_restitution(contact, speeds, steps_per_contact: int, *, setup=None) -> dict:
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
    dict with ``e_n`` [-] (0 if captured, NaN if no outcome in 20 N steps), ``captured`` (bool),
    ``n_steps`` (int) and ``contact_time`` [s].
    """
    y0, c1, c2, ah, aa, dur = setup if setup is not None else _rkg_setup(contact, speeds)
    h = dur / steps_per_contact
    max_steps = np.full(y0.shape, 20 * int(steps_per_contact), dtype=np.int64)
    out = np.empty((y0.size, 4))
    _rkg_many(y0, c1, c2, ah, aa, h, max_steps, out)
    return {
        "e_n": np.where(out[:, 3] == 1, 0.0, np.where(out[:, 3] < 0, np.nan, out[:, 0] / y0)),
        "captured": out[:, 3] == 1,
        "n_steps": out[:, 2].astype(np.int64),
        "tau": out[:, 1],
    }


# =============================================================================== timing helpers
