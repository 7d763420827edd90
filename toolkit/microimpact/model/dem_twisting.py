"""Twisting resistance of DEM engines: LAMMPS GRANULAR's ``twisting sds`` and ``twisting marshall``.

A :class:`~microimpact.model.contact.Contact` with ``twisting_model="lammps_sds"`` or
``"lammps_marshall"`` (and one of the DEM tangential laws, :mod:`microimpact.model.dem_tangential`)
resists the spin about the wall normal as LAMMPS's ``twisting`` keyword does. The law acts on the
twist rate Omega = omega . n_w (n_w the unit normal from the wall to the sphere's centre; the wall
does not spin) through a scalar spring-dashpot-slider with the history xi (an angle, the twist since
first touch):

    M_0 = -k_twist xi - gamma_twist Omega,        d xi / dt = Omega,

and where |M_0| exceeds the limit mu_twist F_n0 the torque is -mu_twist F_n0 sgn(Omega) and the
history is reset to xi = (mu_twist F_n0 sgn(Omega) - gamma_twist Omega) / k_twist
(:func:`lammps_twisting_torque`); F_n0 is the critical normal force of the tangential limit
(:func:`microimpact.model.dem_tangential.lammps_critical_normal_force`). The torque acts about n_w
and only changes Omega: I dOmega/dt = M. The spin about the normal enters neither the slip nor the
rolling velocity of a sphere on a flat wall, so the twist is a problem of its own, driven by the
normal motion (:mod:`microimpact.solvers.dem_tangential` integrates it with the normal law).

Two details of LAMMPS's code (``gran_sub_mod_twisting.cpp``, version 22 Jul 2025) that differ from a
spring-slider written from the physics, followed here so that an exported input reproduces:

* The sliding torque opposes the twist rate (sgn(Omega)), not the trial torque: where the spring
  unwinds faster than the falling limit allows, the torque changes sign at the switch.
* ``marshall`` takes k_twist = k_t a^2 / 2 with k_t the tangential model's *coefficient*: the
  stiffness [N/m] of ``linear_history``, but 8 G* [Pa] of the ``mindlin`` laws, whose stiffness is
  8 G* a. So with a Mindlin law the twisting stiffness is 4 G* a^2 [N], a factor a below Marshall's
  (2009) Eq. (32) with the Mindlin stiffness (4 G* a^3, [N m]); LAMMPS's version is the one here.

The ``marshall`` stiffness follows the contact radius, so a stuck spring's energy k xi^2 / 2 changes
with it at fixed xi: the normal motion can pump the twist, and |Omega| after the impact can exceed
|Omega| before (docs/guide/lammps.md; LAMMPS gives the same).

Units: k_twist [N m/rad], gamma_twist [N m s/rad], and mu_twist a length [m] (the limit
mu_twist F_n0 is a torque; Marshall's mu_twist = 2 a mu / 3). ``Contact.twisting_stiffness``,
``twisting_damping``, ``twisting_friction`` hold those of ``sds``; ``marshall`` has no parameters of its
own. Where it differs from the paper's model: Cheng et al. (2002) let the spin about the normal
decay by the sliding friction over the contact area (the engine's twist torque); LAMMPS's laws are a
spring in series with that limit, with the limit of the tangential law's F_n0.

References
----------
Marshall, J. S. (2009), Discrete-element modeling of particulate aerosol flows, J. Comput. Phys.
228(5):1541-1561, doi:10.1016/j.jcp.2008.10.035, Eqs. (30)-(34), (44).

LAMMPS documentation, ``pair_style granular``, twisting models (version 22 Jul 2025),
https://docs.lammps.org/pair_granular.html; source src/GRANULAR/gran_sub_mod_twisting.cpp.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DEM_TWISTING_MODELS", "lammps_marshall_twisting_coefficients", "lammps_twisting_torque"]

#: the DEM twisting laws (Contact.twisting_model), with their LAMMPS names
DEM_TWISTING_MODELS = {"lammps_sds": "sds", "lammps_marshall": "marshall"}


def lammps_marshall_twisting_coefficients(contact_radius, tangential_coefficient: float, tangential_damping,
                                          friction: float):
    """(k_twist, gamma_twist, mu_twist) of LAMMPS's ``twisting marshall`` at contact radius a.

    Parameters
    ----------
    contact_radius : float or ndarray
        a. [m]
    tangential_coefficient : float
        The tangential model's coefficient k_t: the stiffness of ``linear_history`` [N/m], 8 G* of
        the ``mindlin`` laws [Pa] (see the module docstring).
    tangential_damping : float or ndarray
        eta_t, the tangential damping of the moment (x_gamma,t times the normal damping). [N s/m]
    friction : float
        mu of the tangential law. [-]

    Returns
    -------
    tuple of 3
        k_t a^2 / 2 [N m/rad with linear_history], eta_t a^2 / 2 [N m s/rad], 2 a mu / 3 [m].

    References
    ----------
    Marshall (2009), Eqs. (32)-(33); LAMMPS source, src/GRANULAR/gran_sub_mod_twisting.cpp
    (``GranSubModTwistingMarshall``).

    Examples
    --------
    A ``linear_history`` spring of 1000 N/m at a = 10 nm, eta_t = 1e-6 N s/m and mu = 0.3:

    >>> [float(f"{x:.6g}") for x in lammps_marshall_twisting_coefficients(1e-8, 1000.0, 1e-6, 0.3)]
    [5e-14, 5e-23, 2e-09]
    """
    a2 = np.square(contact_radius)
    return 0.5 * tangential_coefficient * a2, 0.5 * np.multiply(tangential_damping, a2), \
        2.0 / 3.0 * friction * np.asarray(contact_radius)


def lammps_twisting_torque(history, twist_rate, stiffness, damping, limit):
    """Torque and history of one evaluation of LAMMPS's twisting spring-dashpot-slider.

    Parameters
    ----------
    history : float or ndarray
        xi after the step's update (xi + Omega dt). [rad]
    twist_rate : float or ndarray
        Omega = omega . n_w. [rad/s]
    stiffness : float or ndarray
        k_twist, > 0. [N m/rad]
    damping : float or ndarray
        gamma_twist. [N m s/rad]
    limit : float or ndarray
        mu_twist F_n0. [N m]

    Returns
    -------
    torque, history : ndarray
        M about n_w [N m] and the history to keep [rad]: the trial -k xi - gamma Omega, or where it
        exceeds the limit -limit sgn(Omega) with xi reset to (limit sgn(Omega) - gamma Omega) / k.

    References
    ----------
    Marshall (2009), Eqs. (30), (34); LAMMPS source, src/GRANULAR/gran_sub_mod_twisting.cpp.

    Examples
    --------
    A twisting spring of 1e-12 N m/rad wound by 0.01 rad holds 1e-14 N m; with a limit of 4e-15 N m
    and the sphere still twisting forward it slides, and the history falls to 0.004 rad:

    >>> m, xi = lammps_twisting_torque(0.01, 10.0, 1e-12, 0.0, 4e-15)
    >>> float(m), round(float(xi), 15)
    (-4e-15, 0.004)
    """
    xi = np.asarray(history, dtype=float)
    w = np.asarray(twist_rate, dtype=float)
    trial = -np.multiply(stiffness, xi) - np.multiply(damping, w)
    sign = np.sign(w)
    over = np.abs(trial) > limit
    torque = np.where(over, -np.multiply(limit, sign), trial)
    xi = np.where(over, (np.multiply(limit, sign) - np.multiply(damping, w)) / stiffness, xi)
    return torque, xi
