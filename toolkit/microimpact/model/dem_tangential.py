"""Tangential laws of DEM engines (LAMMPS GRANULAR), beside the paper's rigid contact and the
Mindlin laws of :mod:`microimpact.model.tangential_compliance`.

A :class:`~microimpact.model.contact.Contact` selects one with ``tangential_model``:

=========================== ============================ ======================================
``tangential_model``        LAMMPS (``pair_style         stiffness k of the history spring
                            granular``, ``tangential``)
=========================== ============================ ======================================
``"linear_history"``        ``linear_history k x mu``    k = ``tangential_stiffness`` [N/m]
``"lammps_mindlin"``        ``mindlin 8G* x mu``         k = 8 G* a (``shear_modulus`` G*,
                                                         a the normal law's contact radius)
=========================== ============================ ======================================

Both keep a history xi, the tangential displacement of the contact point since first touch
(LAMMPS's ``history``), and give the force

    F_t = -k xi - eta_t u,       eta_t = x_gamma,t eta_n,

u the velocity of the contact point relative to the wall (the slip velocity), eta_n the normal
damping coefficient of the contact's DEM damping law (:func:`microimpact.model.dem_damping.dem_damping_law`,
LAMMPS's "damping prefactor"; 0 without damping) and x_gamma,t = ``Contact.tangential_damping``.
While |F_t| <= mu F_n0 the contact sticks and d xi / dt = u. Where the trial force exceeds the
limit, LAMMPS scales the force to mu F_n0 and resets the history to the elastic part of the scaled
force, xi = -(F_t + eta_t u) / k (:func:`lammps_tangential_force`): the contact slides, with the
force at the limit along the trial force. F_n0 (LAMMPS's ``Fncrit``,
:func:`lammps_critical_normal_force`) is the magnitude of the total normal force (elastic plus
damping) for Hertz, and |F_ne + 2 F_po| for DMT and JKR, F_ne the elastic normal force with its
adhesion and F_po the pull-off force (2 pi w R for DMT, (3/2) pi w R for JKR).

Where these differ from microimpact's own laws. microimpact's "mindlin" is Mindlin's micro-slip
law, whose stiffness falls as the force approaches the limit (Mindlin 1949), and
"mindlin_deresiewicz" adds its loading history; LAMMPS's laws are a linear spring (in xi) capped by
the limit. Their friction limit is F_n0 above, where microimpact's is f |F_n| ("net") or
f |F_n + 2 F_po| ("pulloff"). The paper's contact is tangentially rigid. For a contact that slides
throughout, all give the same impulse f int F_n0 dt.

In continuous time (the limit of LAMMPS's step, which the solver follows,
:mod:`microimpact.solvers.dem_tangential`): in stick, d xi / dt = u; in slide, the force stays on
the limit, F_t = mu F_n0 e, and its direction e turns with the part of the trial force's rate
across it; the contact sticks again when the trial force's rate along e falls below the rate of the
limit (the trial force would move inside the limit). This is LAMMPS's return mapping as its step
goes to zero; its first-order convergence to it is tested (tests/test_dem_tangential.py).

Twisting and rolling resistance (LAMMPS ``twisting``, ``rolling``) are not modelled with these
laws: the spin about the normal is unchanged, as with LAMMPS's default ``twisting none``.

References
----------
LAMMPS documentation, ``pair_style granular``, tangential models (version 22 Jul 2025),
https://docs.lammps.org/pair_granular.html; source src/GRANULAR/gran_sub_mod_tangential.cpp and
gran_sub_mod_normal.cpp (``set_fncrit``).

Luding, S. (2008), Cohesive, frictional powders: contact models for tension, Granular Matter
10:235-246, doi:10.1007/s10035-008-0099-x.

Mindlin, R. D. (1949), Compliance of elastic bodies in contact, J. Appl. Mech. 16:259-268.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["DEM_TANGENTIAL_MODELS", "lammps_tangential_stiffness", "lammps_critical_normal_force",
           "lammps_tangential_force"]

#: the DEM tangential laws (Contact.tangential_model), with their LAMMPS names
DEM_TANGENTIAL_MODELS = {"linear_history": "linear_history", "lammps_mindlin": "mindlin"}


def lammps_tangential_stiffness(tangential_model: str, stiffness: float, contact_radius):
    """Stiffness of the history spring of a DEM tangential law. [N/m]

    Parameters
    ----------
    tangential_model : {"linear_history", "lammps_mindlin"}
    stiffness : float
        LAMMPS's k_t: [N/m] for ``linear_history``; 8 G* [Pa] for ``lammps_mindlin``.
    contact_radius : float or ndarray
        Contact radius a of the normal law. [m]

    Returns
    -------
    k_t for ``linear_history``, k_t a for ``lammps_mindlin``. [N/m]

    References
    ----------
    LAMMPS documentation, ``pair_style granular``, https://docs.lammps.org/pair_granular.html.

    Examples
    --------
    >>> lammps_tangential_stiffness("linear_history", 250.0, 1e-7)
    250.0
    >>> round(lammps_tangential_stiffness("lammps_mindlin", 8e9, 1e-7), 9)  # 8 G* a, G* = 1 GPa
    800.0
    """
    if tangential_model == "linear_history":
        return stiffness
    if tangential_model == "lammps_mindlin":
        return stiffness * contact_radius
    raise ValueError(f"tangential_model must be one of {', '.join(map(repr, DEM_TANGENTIAL_MODELS))}, "
                     f"got {tangential_model!r}")


def lammps_critical_normal_force(elastic_force, damping_force, pulloff_force):
    """LAMMPS's F_n0, the normal force that sets the friction limit mu F_n0. [N]

    |F_ne + F_nd| without adhesion (``pulloff_force`` 0: Hertz), |F_ne + 2 F_po| with it (DMT, JKR;
    the damping is left out).

    Parameters
    ----------
    elastic_force : float or ndarray
        Elastic normal force F_ne with its adhesive part, repulsive positive. [N]
    damping_force : float or ndarray
        Normal damping force F_nd. [N]
    pulloff_force : float
        F_po: 2 pi w R for DMT, (3/2) pi w R for JKR, 0 without adhesion. [N]

    Any consistent units serve (the solver calls it in the normal law's units).

    References
    ----------
    LAMMPS source, src/GRANULAR/gran_sub_mod_normal.cpp, ``set_fncrit``.

    Examples
    --------
    At the adhesive equilibrium (F_ne = 0) the limit is 2 F_po, not 0:

    >>> lammps_critical_normal_force(0.0, 0.0, 1e-7)
    2e-07
    >>> lammps_critical_normal_force(-1e-8, -3e-8, 0.0)  # Hertz: the damping counts
    4e-08
    """
    if pulloff_force > 0.0:
        return abs(elastic_force + 2.0 * pulloff_force)
    return abs(elastic_force + damping_force)


def lammps_tangential_force(history, slip_velocity, stiffness: float, damping: float, limit: float):
    """Force and history of one evaluation of LAMMPS's history laws: the trial force, scaled to
    the limit if it exceeds it, and the history reset to the scaled force's elastic part.

    Parameters
    ----------
    history : array_like, shape (..., 2)
        Tangential displacement xi after the step's update (xi + u dt). [m]
    slip_velocity : array_like, shape (..., 2)
        Velocity u of the contact point relative to the wall. [m/s]
    stiffness : float
        k of the spring (:func:`lammps_tangential_stiffness`). [N/m]
    damping : float
        eta_t = x_gamma,t eta_n. [kg/s]
    limit : float
        mu F_n0. [N]

    Returns
    -------
    force, history : ndarray
        F_t [N] and the history to keep [m].

    References
    ----------
    LAMMPS source, src/GRANULAR/gran_sub_mod_tangential.cpp (``calculate_forces`` of the
    linear-history and Mindlin models).

    Examples
    --------
    A spring of 100 N/m stretched by 1 nm pulls with 1e-7 N; with a limit of 5e-8 N the force is
    halved and the history with it:

    >>> f, xi = lammps_tangential_force([1e-9, 0.0], [0.0, 0.0], 100.0, 0.0, 5e-8)
    >>> [round(float(x) * 1e9, 12) + 0.0 for x in f], [round(float(x) * 1e9, 12) + 0.0 for x in xi]
    ([-50.0, 0.0], [0.5, 0.0])
    """
    xi = np.array(history, dtype=float)
    u = np.asarray(slip_velocity, dtype=float)
    damp = -damping * u
    force = -stiffness * xi + damp
    size = np.linalg.norm(force, axis=-1, keepdims=True)
    over = (size > limit) & (np.linalg.norm(xi, axis=-1, keepdims=True) > 0.0)
    scale = np.where(over, limit / np.where(size > 0.0, size, 1.0), 1.0)
    force = force * scale
    if stiffness > 0.0:
        xi = np.where(over, -(force - damp) / stiffness, xi)
    return force, xi
