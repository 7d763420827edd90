"""Rolling resistance of DEM engines: LAMMPS GRANULAR's spring-dashpot-slider (``rolling sds``).

A :class:`~microimpact.model.contact.Contact` with ``rolling_model="lammps_sds"`` (and one of the
DEM tangential laws, :mod:`microimpact.model.dem_tangential`) resists rolling as LAMMPS's
``rolling sds k_roll gamma_roll mu_roll`` does. The law acts on the rolling velocity

    v_rl = R omega x n_w,

n_w the unit normal from the wall to the sphere's centre (microimpact's n points into the wall,
n_w = -n) and R the sphere's radius (the wall's effective radius is infinite). It is written as a
"pseudo-force" on the same footing as the tangential history laws: a history xi_r (a length, the
rolling displacement since first touch) and

    F_r = -k_roll xi_r - gamma_roll v_rl,       |F_r| <= mu_roll F_n0,

with d xi_r / dt = v_rl while |F_r| is inside the limit and, where the trial force exceeds it,
the force scaled to the limit and the history reset to xi_r = -(F_r + gamma_roll v_rl) / k_roll
(:func:`lammps_rolling_force`); F_n0 is the same critical normal force as the tangential limit's
(:func:`microimpact.model.dem_tangential.lammps_critical_normal_force`). F_r is no force on the
sphere: it enters as the torque R n_w x F_r (:func:`lammps_rolling_torque`). So the rolling law is
LAMMPS's ``linear_history`` tangential law with constant stiffness, written on v_rl in place of the
slip; the solver (:mod:`microimpact.solvers.dem_tangential`) integrates it the same way, in the
limit of LAMMPS's step.

Units: k_roll [N/m], gamma_roll [N s/m] (``Contact.rolling_stiffness``, ``Contact.rolling_damping``),
mu_roll dimensionless (``Contact.rolling_friction``); the resistive torque is at most
mu_roll F_n0 R. Where it differs from microimpact's own rolling resistance (``rolling_model="torque"``,
a constant torque mu_r R |F_n| against the rolling, Zhou et al. 1999): the SDS torque grows with
the rolling displacement (spring) and rate (dashpot) and reaches mu_roll F_n0 R only when the spring
slides, so small or short rolling is resisted less, and its limit is LAMMPS's F_n0, not |F_n|.

The velocity uses Wang et al. (2015), Eq. (31), as LAMMPS does; the spin about the normal enters
neither it nor the slip (twisting: :mod:`microimpact.model.dem_twisting`).

References
----------
LAMMPS documentation, ``pair_style granular``, rolling models (version 22 Jul 2025),
https://docs.lammps.org/pair_granular.html; source src/GRANULAR/gran_sub_mod_rolling_kernel.h
(``gran_rolling_sds``) and granular_model.cpp (rolling velocity and torque).

Wang, Y., Alonso-Marroquin, F. and Guo, W. W. (2015), Rolling and sliding in 3-D discrete element
models, Particuology 23:49-55, doi:10.1016/j.partic.2015.01.006.

Zhou, Y. C., Wright, B. D., Yang, R. Y., Xu, B. H. and Yu, A. B. (1999), Rolling friction in the
dynamic simulation of sandpile formation, Physica A 269:536-553, doi:10.1016/S0378-4371(99)00183-1.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DEM_ROLLING_MODELS", "lammps_rolling_velocity", "lammps_rolling_force", "lammps_rolling_torque"]

#: the DEM rolling laws (Contact.rolling_model), with their LAMMPS names
DEM_ROLLING_MODELS = {"lammps_sds": "sds"}


def lammps_rolling_velocity(radius: float, omega_t, omega_tp):
    """Rolling velocity v_rl = R omega x n_w of a sphere on the wall, in the wall's (t, t') axes. [m/s]

    Parameters
    ----------
    radius : float
        Sphere radius R. [m]
    omega_t, omega_tp : float or ndarray
        Spin about t and about t' = n x t (microimpact's frame, n into the wall). [rad/s]

    Returns
    -------
    tuple of 2
        (v_rl,t, v_rl,t') = (-R omega_t', R omega_t). [m/s]

    Notes
    -----
    With n_w = -n, omega x n_w = -(omega_t t x n + omega_t' t' x n) = -omega_t' t + omega_t t'.
    A sphere rolling forward without slip (v_t = -R omega_t') has v_rl = v_t: the contact point
    is at rest, and v_rl is the speed at which the contact moves along the wall.

    References
    ----------
    Wang et al. (2015), Eq. (31); LAMMPS source, src/GRANULAR/granular_model.cpp (``vrl``).

    Examples
    --------
    A 1 um sphere spinning backwards at 1e5 rad/s about t' (omega_t' > 0) rolls at -0.1 m/s along t:

    >>> [round(x, 15) for x in lammps_rolling_velocity(1e-6, 0.0, 1e5)]
    [-0.1, 0.0]
    """
    return -radius * omega_tp, radius * omega_t


def lammps_rolling_force(history, rolling_velocity, stiffness: float, damping: float, limit: float):
    """Pseudo-force and history of one evaluation of LAMMPS's ``rolling sds``: the trial force
    -k xi_r - gamma v_rl, scaled to the limit if it exceeds it, the history reset to the scaled
    force's elastic part.

    Parameters
    ----------
    history : array_like, shape (..., 2)
        Rolling displacement xi_r after the step's update (xi_r + v_rl dt). [m]
    rolling_velocity : array_like, shape (..., 2)
        v_rl (:func:`lammps_rolling_velocity`). [m/s]
    stiffness : float
        k_roll, > 0. [N/m]
    damping : float
        gamma_roll. [N s/m]
    limit : float
        mu_roll F_n0. [N]

    Returns
    -------
    force, history : ndarray
        F_r [N] and the history to keep [m]. Where the trial force exceeds the limit while the
        history is 0, LAMMPS sets F_r = 0 (and keeps the history); so does this.

    References
    ----------
    LAMMPS source, src/GRANULAR/gran_sub_mod_rolling_kernel.h (``gran_rolling_sds``).

    Examples
    --------
    A rolling spring of 100 N/m stretched by 1 nm holds 1e-7 N; with a limit of 4e-8 N it slides
    and its history falls to 0.4 nm:

    >>> f, xi = lammps_rolling_force([1e-9, 0.0], [0.0, 0.0], 100.0, 0.0, 4e-8)
    >>> [round(float(x) * 1e9, 12) + 0.0 for x in f], [round(float(x) * 1e9, 12) + 0.0 for x in xi]
    ([-40.0, 0.0], [0.4, 0.0])
    """
    xi = np.array(history, dtype=float)
    w = np.asarray(rolling_velocity, dtype=float)
    damp = -damping * w
    force = -stiffness * xi + damp
    size = np.linalg.norm(force, axis=-1, keepdims=True)
    held = np.linalg.norm(xi, axis=-1, keepdims=True) > 0.0
    over = size > limit
    scale = np.where(over, np.where(held, limit / np.where(size > 0.0, size, 1.0), 0.0), 1.0)
    force = force * scale
    xi = np.where(over & held, -(force - damp) / stiffness, xi)
    return force, xi


def lammps_rolling_torque(radius: float, force):
    """Torque R n_w x F_r of the rolling pseudo-force on the sphere, in microimpact's (n, t, t'). [N m]

    Parameters
    ----------
    radius : float
        Sphere radius R. [m]
    force : array_like, shape (..., 2)
        F_r in the wall's (t, t') axes (:func:`lammps_rolling_force`). [N]

    Returns
    -------
    ndarray, shape (..., 3)
        (0, R F_r,t', -R F_r,t). With :func:`lammps_rolling_velocity`, d v_rl / dt = R^2 / I F_r
        from this torque: a pseudo-force against v_rl slows the rolling.

    References
    ----------
    LAMMPS source, src/GRANULAR/granular_model.cpp (``torroll``).

    Examples
    --------
    >>> [float(x) for x in lammps_rolling_torque(1e-6, [-1e-8, 0.0])]
    [0.0, 0.0, 1e-14]
    """
    f = np.asarray(force, dtype=float)
    zero = np.zeros(f.shape[:-1])
    return np.stack([zero, radius * f[..., 1], -radius * f[..., 0]], axis=-1)
