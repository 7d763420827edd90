"""Normal contact force and contact energy, Eqs. (1)-(6) and (27), and the friction torque of Eq. (18).

Sign convention: x = -n >= 0 is the penetration (approach of the centre to the surface); a positive
normal force pushes the sphere away from the surface (+n).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "contact_radius",
    "hertz_force",
    "adhesion_force",
    "normal_force",
    "contact_potential_energy",
    "twist_friction_torque",
]


def contact_radius(radius, penetration):
    """Hertzian contact radius a = sqrt(r x), Eq. (6). [m]"""
    return np.sqrt(radius * np.maximum(penetration, 0.0))


def hertz_force(radius, stiffness, penetration):
    """Hertzian elastic force F_H = sqrt(r) K x^(3/2), Eq. (2), positive away from the surface. [N]"""
    return math.sqrt(radius) * stiffness * np.maximum(penetration, 0.0) ** 1.5


def adhesion_force(radius, adhesion_line_force, penetration):
    """Adhesion ring force F_A = -2 pi a f0, Eq. (5), negative = towards the surface. [N]"""
    return -2.0 * math.pi * adhesion_line_force * contact_radius(radius, penetration)


def normal_force(contact, penetration, penetration_rate, c_hertz, c_adhesion):
    """Net normal force on the sphere along +n with the damping of Eq. (27). [N]

    F_n = F_H (1 + C_H x') + F_A (1 - C_A x'), i.e. F_HD = -C_H n' F_H and F_AD = C_A n' F_A.

    Parameters
    ----------
    contact : Contact
    penetration : array_like
        x = -n. [m]
    penetration_rate : array_like
        x' = -n'. [m/s]
    c_hertz, c_adhesion : float
        C_H and C_A of Eqs. (14)-(15). [s/m]
    """
    f_h = hertz_force(contact.radius, contact.stiffness, penetration)
    f_a = adhesion_force(contact.radius, contact.adhesion_line_force, penetration)
    return f_h * (1.0 + c_hertz * penetration_rate) + f_a * (1.0 - c_adhesion * penetration_rate)


def contact_potential_energy(contact, penetration):
    """V(x) = (2/5) sqrt(r) K x^(5/2) - (4/3) pi f0 sqrt(r) x^(3/2), so that F_H + F_A = -dV/dx. [J]

    The total energy E = m x'^2 / 2 + V(x) never increases under Eq. (27):
    dE/dt = -(C_H F_H + C_A |F_A|) x'^2. Once E < 0 the sphere cannot reach x = 0 again: captured.
    """
    x = np.maximum(penetration, 0.0)
    sr = math.sqrt(contact.radius)
    return 0.4 * sr * contact.stiffness * x**2.5 - 4.0 / 3.0 * math.pi * contact.adhesion_line_force * sr * x**1.5


def twist_friction_torque(friction, contact_radius_, normal_force_):
    """Magnitude of the friction torque about n, (3 pi / 16) f a |F_n|. [N m]

    Departure from the paper: Eq. (18) as printed, 75 pi f a F_n / (64 r^2), has units of N/m and is
    not a torque. Integrating Coulomb friction f |p| over the Hertz pressure
    p = p0 sqrt(1 - rho^2/a^2), p0 = 3 |F_n| / (2 pi a^2), gives
    2 pi f p0 int_0^a sqrt(1 - rho^2/a^2) rho^2 d rho = (3 pi / 16) f a |F_n|.
    The torque opposes the twist spin omega_n and stops when omega_n reaches zero.
    """
    return 3.0 * math.pi / 16.0 * friction * contact_radius_ * np.abs(normal_force_)
