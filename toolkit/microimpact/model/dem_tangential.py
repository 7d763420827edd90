"""Tangential laws of DEM engines (LAMMPS GRANULAR), beside the paper's rigid contact and the
Mindlin laws of :mod:`microimpact.model.tangential_compliance`.

A :class:`~microimpact.model.contact.Contact` selects one with ``tangential_model``:

================================== ===================================== ===============================
``tangential_model``               LAMMPS (``pair_style granular``,      stiffness k of the history
                                   ``tangential``)                       spring
================================== ===================================== ===============================
``"linear_history"``               ``linear_history k x mu``             k = ``tangential_stiffness``
                                                                         [N/m]
``"lammps_mindlin"``               ``mindlin 8G* x mu``                  k = 8 G* a (``shear_modulus``
                                                                         G*, a the normal law's
                                                                         contact radius)
``"lammps_mindlin_rescale"``       ``mindlin_rescale 8G* x mu``          8 G* a
``"lammps_mindlin_force"``         ``mindlin/force 8G* x mu``            8 G* a
``"lammps_mindlin_rescale_force"`` ``mindlin_rescale/force 8G* x mu``    8 G* a
================================== ===================================== ===============================

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

The Mindlin variants differ in what the history H is and how it follows the contact radius
(:func:`lammps_history_rate`, :func:`lammps_elastic_force`): ``mindlin`` and ``mindlin_rescale``
store the displacement, F_e = -k H with dH/dt = u, so that the force falls with k = 8 G* a as the
contact shrinks; the ``/force`` variants store the elastic force itself, dH/dt = -k u (Thornton et
al. 2013, Eq. 18), which keeps its value as a falls; the ``rescale`` variants scale H by a_new / a_old
while a falls (LAMMPS: ``history *= a / a_old`` at each step of unloading), dH/dt gaining
(da/dt / a) H there, so that the stored energy does not outlive the contact that held it (the
displacement form then falls as a^2, the force form as a).

In continuous time (the limit of LAMMPS's step, which the solver follows,
:mod:`microimpact.solvers.dem_tangential`): in stick, d xi / dt = u; in slide, the force stays on
the limit, F_t = mu F_n0 e, and its direction e turns with the part of the trial force's rate
across it; the contact sticks again when the trial force's rate along e falls below the rate of the
limit (the trial force would move inside the limit). This is LAMMPS's return mapping as its step
goes to zero; its first-order convergence to it is tested (tests/test_dem_tangential.py).

Rolling resistance is LAMMPS's ``rolling sds`` (:mod:`microimpact.model.dem_rolling`,
``Contact.rolling_model="lammps_sds"``), twisting LAMMPS's ``twisting sds`` or ``marshall``
(:mod:`microimpact.model.dem_twisting`, ``Contact.twisting_model``); without it the spin about the
normal is unchanged, as with LAMMPS's default ``twisting none``.

References
----------
LAMMPS documentation, ``pair_style granular``, tangential models (version 22 Jul 2025),
https://docs.lammps.org/pair_granular.html; source src/GRANULAR/gran_sub_mod_tangential.cpp and
gran_sub_mod_normal.cpp (``set_fncrit``).

Thornton, C., Cummins, S. J. and Cleary, P. W. (2013), An investigation of the comparative behaviour
of alternative contact force models during inelastic collisions, Powder Technol. 233:30-46,
doi:10.1016/j.powtec.2012.08.012.

Luding, S. (2008), Cohesive, frictional powders: contact models for tension, Granular Matter
10:235-246, doi:10.1007/s10035-008-0099-x.

Mindlin, R. D. (1949), Compliance of elastic bodies in contact, J. Appl. Mech. 16:259-268.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["DEM_TANGENTIAL_MODELS", "FORCE_HISTORY_MODELS", "RESCALED_MODELS", "lammps_tangential_stiffness",
           "lammps_pulloff_force", "lammps_critical_normal_force", "lammps_critical_normal_force_rate", "lammps_tangential_force", "lammps_elastic_force",
           "lammps_history_of_force", "lammps_history_rate"]

#: the DEM tangential laws (Contact.tangential_model), with their LAMMPS names
DEM_TANGENTIAL_MODELS = {"linear_history": "linear_history", "lammps_mindlin": "mindlin",
                         "lammps_mindlin_rescale": "mindlin_rescale", "lammps_mindlin_force": "mindlin/force",
                         "lammps_mindlin_rescale_force": "mindlin_rescale/force"}
#: the laws whose history is the elastic force (LAMMPS's ``/force`` variants), not the displacement
FORCE_HISTORY_MODELS = frozenset({"lammps_mindlin_force", "lammps_mindlin_rescale_force"})
#: the laws whose history is scaled by a_new / a_old while the contact radius falls
RESCALED_MODELS = frozenset({"lammps_mindlin_rescale", "lammps_mindlin_rescale_force"})


def lammps_tangential_stiffness(tangential_model: str, stiffness: float, contact_radius):
    """Stiffness of the history spring of a DEM tangential law. [N/m]

    Parameters
    ----------
    tangential_model : str
        One of :data:`DEM_TANGENTIAL_MODELS`.
    stiffness : float
        LAMMPS's k_t: [N/m] for ``linear_history``; 8 G* [Pa] for the Mindlin variants.
    contact_radius : float or ndarray
        Contact radius a of the normal law. [m]

    Returns
    -------
    k_t for ``linear_history``, k_t a for the Mindlin variants. [N/m]

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
    if tangential_model in DEM_TANGENTIAL_MODELS:
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


def lammps_pulloff_force(normal_model: str, radius: float, work_of_adhesion: float) -> float:
    """LAMMPS's pull-off force F_po of a normal law, the one in its friction limit. [N]

    (3/2) pi w R for JKR (``normal_model`` "jkr_force", LAMMPS's ``jkr``), 2 pi w R for DMT, 0 for
    Hertz (``"ring"`` without adhesion).

    Parameters
    ----------
    normal_model : {"ring", "jkr_force", "dmt"}
    radius : float
        Sphere radius R (the wall's is infinite). [m]
    work_of_adhesion : float
        w = 2 gamma, LAMMPS's ``cohesion`` gamma being w / 2. [J/m^2]

    References
    ----------
    LAMMPS source, src/GRANULAR/gran_sub_mod_normal.cpp (``F_pulloff`` of the JKR and DMT models).

    Examples
    --------
    >>> round(lammps_pulloff_force("jkr_force", 1e-6, 0.02) / (math.pi * 0.02 * 1e-6), 12)
    1.5
    >>> lammps_pulloff_force("ring", 1e-6, 0.0)
    0.0
    """
    if normal_model == "jkr_force":
        return 1.5 * math.pi * work_of_adhesion * radius
    if normal_model == "dmt":
        return 2.0 * math.pi * work_of_adhesion * radius
    return 0.0


def lammps_critical_normal_force_rate(elastic_force, damping_force, pulloff_force, elastic_rate, damping_rate):
    """d F_n0 / dt of :func:`lammps_critical_normal_force`, where F_n0 is not zero. [N/s]

    Parameters
    ----------
    elastic_force, damping_force, pulloff_force : float
        As :func:`lammps_critical_normal_force`. [N]
    elastic_rate, damping_rate : float
        dF_ne/dt and dF_nd/dt. [N/s]

    Any consistent units serve (the solver calls it per its own time variable).

    References
    ----------
    LAMMPS source, src/GRANULAR/gran_sub_mod_normal.cpp, ``set_fncrit``.

    Examples
    --------
    With adhesion the damping does not count; without it, it does, with the sign of the total:

    >>> lammps_critical_normal_force_rate(-1.0, 5.0, 1.0, 2.0, 3.0)
    2.0
    >>> lammps_critical_normal_force_rate(-1.0, -3.0, 0.0, 2.0, 3.0)
    -5.0
    """
    if pulloff_force > 0.0:
        return elastic_rate if elastic_force + 2.0 * pulloff_force >= 0.0 else -elastic_rate
    rate = elastic_rate + damping_rate
    return rate if elastic_force + damping_force >= 0.0 else -rate


def lammps_tangential_force(history, slip_velocity, stiffness: float, damping: float, limit: float,
                            tangential_model: str = "lammps_mindlin"):
    """Force and history of one evaluation of LAMMPS's history laws: the trial force, scaled to
    the limit if it exceeds it, and the history reset to the scaled force's elastic part.

    Parameters
    ----------
    history : array_like, shape (..., 2)
        History H after the step's update: the displacement xi (+ u dt) [m], or for the ``/force``
        variants (:data:`FORCE_HISTORY_MODELS`) the elastic force (- k u dt) [N].
    slip_velocity : array_like, shape (..., 2)
        Velocity u of the contact point relative to the wall. [m/s]
    stiffness : float
        k of the spring (:func:`lammps_tangential_stiffness`). [N/m]
    damping : float
        eta_t = x_gamma,t eta_n. [kg/s]
    limit : float
        mu F_n0. [N]
    tangential_model : str
        One of :data:`DEM_TANGENTIAL_MODELS` (which history H is). [-]

    Returns
    -------
    force, history : ndarray
        F_t [N] and the history to keep [m] or [N].

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
    force = lammps_elastic_force(tangential_model, xi, stiffness) + damp
    size = np.linalg.norm(force, axis=-1, keepdims=True)
    over = (size > limit) & (np.linalg.norm(xi, axis=-1, keepdims=True) > 0.0)
    scale = np.where(over, limit / np.where(size > 0.0, size, 1.0), 1.0)
    force = force * scale
    if stiffness > 0.0 or tangential_model in FORCE_HISTORY_MODELS:
        xi = np.where(over, lammps_history_of_force(tangential_model, force - damp, stiffness), xi)
    return force, xi


def lammps_elastic_force(tangential_model: str, history, stiffness):
    """Elastic part of the tangential force of a DEM law, F_e = -k H, or H for the ``/force``
    variants, whose history is that force. [N]

    Parameters
    ----------
    tangential_model : str
        One of :data:`DEM_TANGENTIAL_MODELS`.
    history : float or ndarray
        H: displacement [m], or force [N] (:data:`FORCE_HISTORY_MODELS`).
    stiffness : float
        k of the spring now (:func:`lammps_tangential_stiffness`). [N/m]

    Any consistent units serve (the solver calls it in the normal law's units).

    References
    ----------
    LAMMPS source, src/GRANULAR/gran_sub_mod_tangential.cpp, ``GranSubModTangentialMindlin``.

    Examples
    --------
    >>> lammps_elastic_force("lammps_mindlin", 2e-9, 100.0) * 1e7, lammps_elastic_force("lammps_mindlin_force", -2e-7, 100.0) * 1e7
    (-2.0, -2.0)
    """
    if tangential_model in FORCE_HISTORY_MODELS:
        return history
    return -stiffness * history


def lammps_history_of_force(tangential_model: str, elastic_force, stiffness):
    """The history that gives the elastic force ``elastic_force``: the inverse of
    :func:`lammps_elastic_force` (LAMMPS's reset of the history where the force is scaled to the
    limit). [m] or [N]

    Parameters
    ----------
    tangential_model : str
        One of :data:`DEM_TANGENTIAL_MODELS`.
    elastic_force : float or ndarray
        F_e. [N]
    stiffness : float
        k of the spring now, > 0 for the displacement histories. [N/m]

    References
    ----------
    LAMMPS source, src/GRANULAR/gran_sub_mod_tangential.cpp, ``GranSubModTangentialMindlin``.

    Examples
    --------
    >>> round(lammps_history_of_force("lammps_mindlin", -2e-7, 100.0) * 1e9, 12), lammps_history_of_force("lammps_mindlin_force", -2e-7, 100.0) * 1e7
    (2.0, -2.0)
    """
    if tangential_model in FORCE_HISTORY_MODELS:
        return elastic_force
    return -elastic_force / stiffness


def lammps_history_rate(tangential_model: str, history, slip_velocity, stiffness, radius_rate):
    """dH/dt of a stuck contact: the continuous-time limit of LAMMPS's history update. [m/s] or [N/s]

    u for a displacement history, -k u for a ``/force`` history (:data:`FORCE_HISTORY_MODELS`);
    the ``rescale`` variants (:data:`RESCALED_MODELS`) add (da/dt / a) H while the contact radius
    falls (LAMMPS scales H by a_new / a_old at each such step).

    Parameters
    ----------
    tangential_model : str
        One of :data:`DEM_TANGENTIAL_MODELS`.
    history : float or ndarray
        H. [m] or [N]
    slip_velocity : float or ndarray
        u, the velocity of the contact point relative to the wall. [m/s]
    stiffness : float
        k of the spring now. [N/m]
    radius_rate : float
        (da/dt) / a of the contact radius. [1/s]

    Any consistent units serve; the solver passes rates per its own time variable.

    References
    ----------
    LAMMPS source, src/GRANULAR/gran_sub_mod_tangential.cpp, ``GranSubModTangentialMindlin``
    (``mindlin_force``, ``mindlin_rescale``); Thornton et al. (2013), Eq. (18).

    Examples
    --------
    Unloading at da/dt / a = -100 1/s with a displacement history of 1 nm and no slip: only the
    rescaled law lets it fall, at -1e-7 m/s:

    >>> lammps_history_rate("lammps_mindlin", 1e-9, 0.0, 50.0, -100.0)
    0.0
    >>> round(lammps_history_rate("lammps_mindlin_rescale", 1e-9, 0.0, 50.0, -100.0), 20)
    -1e-07
    >>> lammps_history_rate("lammps_mindlin_force", 0.0, 2e-3, 50.0, -100.0)  # -k u
    -0.1
    """
    rate = -stiffness * slip_velocity if tangential_model in FORCE_HISTORY_MODELS else slip_velocity
    if tangential_model in RESCALED_MODELS and radius_rate < 0.0:
        rate = rate + radius_rate * history
    return rate
