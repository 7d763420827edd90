"""The normal contact law, Eqs. (1)-(6) and (27), and the twist friction torque, Eq. (18) corrected.

Each formula is written here once, in two forms:

* **SI** (array-friendly): :func:`hertz_force` (Eq. (2)), :func:`adhesion_force` (Eq. (5)),
  :func:`normal_force` (Eq. (27)), :func:`contact_potential_energy` V(x),
  :func:`damping_dissipation_rate`, :func:`twist_friction_torque` and the Hertz impact scales
  :func:`hertz_impact_scales` used when there is no adhesion.
* **Nondimensional** (xi = x / L, tau = t / T_c, y = d xi / d tau, s = sqrt(xi); coefficients a_h,
  a_a, C1, C2 as in :mod:`microimpact.solvers.engine`): :func:`nondimensional_acceleration`,
  :func:`nondimensional_energy` and :func:`nondimensional_dissipation_rate`. They take the powers
  of s = sqrt(xi) as arguments, so the right-hand side of the Sundman form (d tau = s d sigma) is a
  polynomial in s. These are plain scalar functions with arithmetic only (no
  branches, no ``math`` calls), so they work on numpy arrays as they are, and the compiled solvers
  compile them with numba (``njit(inline="always")``) instead of keeping a second copy.

Sign convention: x = -n >= 0 is the penetration (approach of the centre to the surface); a positive
normal force pushes the sphere away from the surface (+n).

Departures from the printed paper: Eq. (18) is replaced by the derived twist torque
(3 pi / 16) f a |F_n| (see :func:`twist_friction_torque`); without adhesion (f0 = 0) the paper's
scales X, T do not exist and the Hertz impact scales replace them (:func:`hertz_impact_scales`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "TWIST_TORQUE_FACTOR",
    "contact_radius",
    "hertz_force",
    "adhesion_force",
    "normal_force",
    "contact_potential_energy",
    "damping_dissipation_rate",
    "twist_friction_torque",
    "hertz_impact_scales",
    "nondimensional_acceleration",
    "nondimensional_energy",
    "nondimensional_dissipation_rate",
    "Scales",
    "nondimensional_scales",
    "nondimensional_impact",
]

#: Twist friction torque per unit f a |F_n|, 3 pi / 16 (Eq. (18) corrected, see
#: :func:`twist_friction_torque`). [-]
TWIST_TORQUE_FACTOR = 3.0 * math.pi / 16.0


# =============================================================================== SI forms
def contact_radius(radius, penetration):
    """Hertzian contact radius a = sqrt(r x), Eq. (6); 0 out of contact. [m]

    Parameters
    ----------
    radius : float
        Sphere radius r. [m]
    penetration : array_like
        x = -n. [m]

    References
    ----------
    Cheng, W., Brach, R. M. and Dunn, P. F. (2002), Three-dimensional modeling of microsphere contact/
    impact with smooth, flat surfaces, Aerosol Sci. Technol. 36:1045-1060, Eq. (6).

    Examples
    --------
    >>> contact_radius(4e-6, [1e-8, 0.0, -1e-8]).tolist()
    [2e-07, 0.0, 0.0]
    """
    return np.sqrt(radius * np.maximum(penetration, 0.0))


def hertz_force(radius, stiffness, penetration):
    """Hertzian elastic force F_H = sqrt(r) K x^(3/2), Eq. (2), positive away from the surface. [N]

    Parameters
    ----------
    radius : float
        Sphere radius r. [m]
    stiffness : float
        Effective stiffness K, Eq. (3). [Pa]
    penetration : array_like
        x = -n; no force for x <= 0. [m]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (2); Johnson, K. L. (1985), Contact Mechanics, Cambridge
    University Press, Sec. 4.2.

    Examples
    --------
    The energy stored at the largest penetration x* of an undamped Hertz impact,
    int F_H dx = (2/5) F_H(x*) x*, is the incident kinetic energy:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> x_max, _ = hertz_impact_scales(c.mass, c.stiffness, c.radius, 1.0)
    >>> round(float(0.4 * hertz_force(c.radius, c.stiffness, x_max) * x_max / (0.5 * c.mass)), 12)
    1.0
    """
    return math.sqrt(radius) * stiffness * np.maximum(penetration, 0.0) ** 1.5


def adhesion_force(radius, adhesion_line_force, penetration):
    """Adhesion ring force F_A = -2 pi a f0, Eq. (5), negative = towards the surface. [N]

    Parameters
    ----------
    radius : float
        Sphere radius r. [m]
    adhesion_line_force : float
        f0, Eq. (5). [N/m]
    penetration : array_like
        x = -n; no force for x <= 0. [m]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (5).

    Examples
    --------
    At the paper's length scale X = 2 pi f0 / K (Eq. (29)) the ring force balances the Hertz force:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> x = c.length_scale
    >>> round(float(adhesion_force(c.radius, c.adhesion_line_force, x) / hertz_force(c.radius, c.stiffness, x)), 12)
    -1.0
    """
    return -2.0 * math.pi * adhesion_line_force * contact_radius(radius, penetration)


def normal_force(contact, penetration, penetration_rate, c_hertz, c_adhesion):
    """Net normal force on the sphere along +n with the damping of Eq. (27). [N]

    F_n = F_H (1 + C_H x') + F_A (1 - C_A x'), i.e. F_HD = -C_H n' F_H and F_AD = C_A n' F_A;
    m x'' = -F_n.

    Parameters
    ----------
    contact : Contact
    penetration : array_like
        x = -n. [m]
    penetration_rate : array_like
        x' = -n'. [m/s]
    c_hertz, c_adhesion : float
        C_H and C_A of Eqs. (14)-(15). [s/m]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (27).

    Examples
    --------
    At the adhesive equilibrium x = X the net force vanishes at rest; moving inwards (x' > 0) the
    Hertz damping pushes out and the adhesion damping pulls in less, so the force is positive:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> float(normal_force(c, c.length_scale, 0.0, 0.1, 0.1))
    0.0
    >>> bool(normal_force(c, c.length_scale, 1.0, 0.1, 0.1) > 0.0)
    True
    """
    f_h = hertz_force(contact.radius, contact.stiffness, penetration)
    f_a = adhesion_force(contact.radius, contact.adhesion_line_force, penetration)
    return f_h * (1.0 + c_hertz * penetration_rate) + f_a * (1.0 - c_adhesion * penetration_rate)


def contact_potential_energy(contact, penetration):
    """V(x) = (2/5) sqrt(r) K x^(5/2) - (4/3) pi f0 sqrt(r) x^(3/2), so that F_H + F_A = -dV/dx. [J]

    The total energy E = m x'^2 / 2 + V(x) never increases under Eq. (27):
    dE/dt = -(C_H F_H + C_A |F_A|) x'^2 (:func:`damping_dissipation_rate`). Once E < 0 the sphere
    cannot reach x = 0 again: captured. At the equilibrium x = X, V(X) = -(4/15) m (X/T)^2.

    Parameters
    ----------
    contact : Contact
    penetration : array_like
        x = -n. [m]
    
    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (2) and (5) (the forces it integrates) and (27)

    Examples
    --------
    At the equilibrium X = 2 pi f0 / K the Hertz and adhesion forces cancel and
    V(X) = -(4/15) m (X/T)^2 (Eqs. (29)-(30)):

    >>> from microimpact.presets import WALL_1990 as c
    >>> x = c.length_scale
    >>> f_h = hertz_force(c.radius, c.stiffness, x)
    >>> bool(abs(f_h + adhesion_force(c.radius, c.adhesion_line_force, x)) <= 1e-12 * f_h)
    True
    >>> round(float(contact_potential_energy(c, x) / (c.mass * (x / c.time_scale) ** 2)), 12)
    -0.266666666667
    """
    x = np.maximum(penetration, 0.0)
    sr = math.sqrt(contact.radius)
    return 0.4 * sr * contact.stiffness * x**2.5 - 4.0 / 3.0 * math.pi * contact.adhesion_line_force * sr * x**1.5


def damping_dissipation_rate(contact, penetration, penetration_rate, c_hertz, c_adhesion):
    """Power removed by the normal damping of Eq. (27), (C_H F_H + C_A |F_A|) x'^2 >= 0. [W]

    Parameters as :func:`normal_force`: x [m], x' [m/s], C_H and C_A [s/m].

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (14)-(15) and (27).

    Examples
    --------
    (C_H F_H + C_A |F_A|) x'^2: at x = X, where F_H = |F_A|, with C_H = C_A = 1 s/m and x' = 2 m/s:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> f_h = hertz_force(c.radius, c.stiffness, c.length_scale)
    >>> round(float(damping_dissipation_rate(c, c.length_scale, 2.0, 1.0, 1.0) / (8.0 * f_h)), 12)
    1.0
    """
    f_h = hertz_force(contact.radius, contact.stiffness, penetration)
    f_a = adhesion_force(contact.radius, contact.adhesion_line_force, penetration)
    return (c_hertz * f_h - c_adhesion * f_a) * np.square(penetration_rate)


def twist_friction_torque(friction, contact_radius_, normal_force_):
    """Magnitude of the friction torque about n, (3 pi / 16) f a |F_n|. [N m]

    Parameters
    ----------
    friction : array_like
        Coulomb coefficient f. [-]
    contact_radius_ : array_like
        Contact radius a, Eq. (6). [m]
    normal_force_ : array_like
        F_n. [N]

    Notes
    -----
    Departure from the paper: Eq. (18) as printed, 75 pi f a F_n / (64 r^2), has units of N/m and is
    not a torque. Integrating Coulomb friction f |p| over the Hertz pressure
    p = p0 sqrt(1 - rho^2/a^2), p0 = 3 |F_n| / (2 pi a^2), gives
    2 pi f p0 int_0^a sqrt(1 - rho^2/a^2) rho^2 d rho = (3 pi / 16) f a |F_n|.
    The torque opposes the twist spin omega_n and stops when omega_n reaches zero.
    
    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (18)

    Examples
    --------
    >>> import math
    >>> round(float(twist_friction_torque(1.0, 1.0, 1.0)), 10) == round(3.0 * math.pi / 16.0, 10)
    True
    """
    return TWIST_TORQUE_FACTOR * friction * contact_radius_ * np.abs(normal_force_)


def hertz_impact_scales(mass, stiffness, radius, normal_speed):
    """Hertz impact scales x* = (5 m v^2 / (4 K sqrt(r)))^(2/5) and t* = x* / v. [m], [s]

    x* is the largest penetration of an undamped, non-adhesive Hertz impact at normal speed v.
    The solvers use these scales when f0 = 0 (then X = 0 and T is infinite); in them Eq. (27)
    reads xi'' = -(5/4) xi^(3/2) (1 + C1 y) with y(0) = 1, i.e. a_h = 5/4, a_a = 0. (Departure:
    the paper gives only the adhesive scaling, Eqs. (29)-(30).)

    Parameters
    ----------
    mass : float
        Sphere mass m. [kg]
    stiffness : float
        Effective stiffness K. [Pa]
    radius : float
        Sphere radius r. [m]
    normal_speed : float or array_like
        Incident normal speed v > 0. [m/s]

    Returns
    -------
    (length, time) : tuple of float or ndarray
        x* [m] and t* [s].

    References
    ----------
    Johnson, K. L. (1985), Contact Mechanics, Cambridge University Press, Sec. 11.4 (the impact of
    elastic spheres).

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> length, time = hertz_impact_scales(c.mass, c.stiffness, c.radius, 1.0)
    >>> f"{length:.6e} m", f"{time:.6e} s"
    ('2.386574e-08 m', '2.386574e-08 s')
    """
    length = (5.0 * mass * normal_speed**2 / (4.0 * stiffness * math.sqrt(radius))) ** 0.4
    return length, length / normal_speed


# =============================================================================== nondimensional forms
# Scalar arithmetic only: numpy arrays pass through, numba compiles them (see the module docstring).
def nondimensional_acceleration(root, root3, y, c1, c2, a_h, a_a):
    """xi'' = a_a xi^(1/2) (1 - C2 y) - a_h xi^(3/2) (1 + C1 y), Eqs. (27)-(28). [-]

    The nondimensional normal force is -xi''. The law is linear in the two half-integer powers of
    the penetration, so it takes them as arguments and each caller computes them from its own
    variables: ``root`` = xi^(1/2) and ``root3`` = xi^(3/2) (from xi, or s and s^3 with
    s = sqrt(xi)). Passing both times a common factor scales the result by it: the Sundman form
    dy/dsigma = s xi'' passes (s^2, s^4); xi'' / s, whose sign is that of -F_n without the trivial
    zero at first contact, passes (1, s^2). In free flight (xi <= 0) pass zeros.

    Parameters
    ----------
    root, root3 : float or array_like
        xi^(1/2) and xi^(3/2) (or both times a common factor), xi = x / L the nondimensional
        penetration. [-]
    y : float or array_like
        y = d xi / d tau. [-]
    c1, c2 : float
        Nondimensional damping C1 = C_H L / T_c, C2 = C_A L / T_c, Eqs. (31)-(32). [-]
    a_h, a_a : float
        Hertz and adhesion coefficients: 1, 1 in the paper's scales X, T (Eq. (28)); 5/4, 0 in the
        Hertz impact scales (:func:`hertz_impact_scales`). [-]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (27)-(28).

    Examples
    --------
    The equilibrium of the paper's scales is xi = 1 at rest; moving inwards there (y = 1) the
    damping gives -(C1 + C2):

    >>> nondimensional_acceleration(1.0, 1.0, 0.0, 0.3, 0.2, 1.0, 1.0)
    0.0
    >>> round(nondimensional_acceleration(1.0, 1.0, 1.0, 0.3, 0.2, 1.0, 1.0), 12)
    -0.5
    """
    return a_a * root * (1.0 - c2 * y) - a_h * root3 * (1.0 + c1 * y)


def nondimensional_energy(s, y, a_h, a_a):
    """Contact energy e = y^2 / 2 + (2/5) a_h s^5 - (2/3) a_a s^3, s = sqrt(xi). [-]

    The nondimensional form of m x'^2 / 2 + :func:`contact_potential_energy`, in units of
    m (L / T_c)^2. e < 0 means captured; e = -4/15 at the equilibrium (xi, y) = (1, 0) of the
    paper's scales.

    Parameters
    ----------
    s : float or array_like
        sqrt(xi), >= 0. [-]
    y : float or array_like
        y = d xi / d tau. [-]
    a_h, a_a : float
        As in :func:`nondimensional_acceleration`. [-]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (27)-(30).

    Examples
    --------
    >>> round(nondimensional_energy(1.0, 0.0, 1.0, 1.0), 12) == round(-4.0 / 15.0, 12)
    True
    >>> nondimensional_energy(0.0, 1.0, 1.25, 0.0)  # first contact in the Hertz scales: y0 = 1
    0.5
    """
    s3 = s * s * s
    return 0.5 * y * y + a_h * 0.4 * s3 * s * s - a_a * (2.0 / 3.0) * s3


def nondimensional_dissipation_rate(root, root3, y, c1, c2, a_h, a_a):
    """Rate of damping dissipation -de/dtau = (a_h C1 xi^(3/2) + a_a C2 xi^(1/2)) y^2 >= 0. [-]

    The nondimensional form of :func:`damping_dissipation_rate`. Parameters as
    :func:`nondimensional_acceleration` (the Sundman form passes (s^2, s^4) for s times the rate).

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (27)-(28).

    Examples
    --------
    >>> nondimensional_dissipation_rate(1.0, 1.0, 2.0, 0.5, 0.25, 1.0, 1.0)  # (0.5 + 0.25) 2^2
    3.0
    """
    return (a_h * c1 * root3 + a_a * c2 * root) * y * y


# =============================================================================== scales of one impact
@dataclass(frozen=True)
class Scales:
    """Nondimensional scales of one impact (see :func:`nondimensional_scales`).

    Attributes
    ----------
    length : float or ndarray
        L: X = 2 pi f0 / K (Eq. (29)) with adhesion, else the Hertz x*. [m]
    time : float or ndarray
        T_c: T of Eq. (30) (corrected) with adhesion, else t* = x* / v. [s]
    a_hertz, a_adhesion : float
        a_h, a_a of :func:`nondimensional_acceleration`: 1, 1 or 5/4, 0. [-]

    Examples
    --------
    With adhesion the length is X = 2 pi f0 / K of Eq. (29); without it the Hertz x* and time
    x* / v:

    >>> import math
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> s = nondimensional_scales(c, 1.0)
    >>> x = 2 * math.pi * c.adhesion_line_force / c.stiffness
    >>> round(s.length / x, 12), s.a_hertz, s.a_adhesion
    (1.0, 1.0, 1.0)
    >>> h = nondimensional_scales(c.with_(adhesion_line_force=0.0), 2.0)
    >>> round(h.time * 2.0 / h.length, 12), h.a_hertz, h.a_adhesion
    (1.0, 1.25, 0.0)
    """

    length: float
    time: float
    a_hertz: float
    a_adhesion: float

    @property
    def speed(self):
        """Speed scale L / T_c. [m/s]"""
        return self.length / self.time


def nondimensional_scales(contact, normal_speed) -> Scales:
    """Length and time scales of an impact at ``normal_speed`` as the solvers use them.

    With adhesion (f0 > 0) the paper's X and T, Eqs. (29)-(30) (T corrected), for which Eq. (28)
    has a_h = a_a = 1; without adhesion the Hertz impact scales of :func:`hertz_impact_scales`
    (a_h = 5/4, a_a = 0).

    Parameters
    ----------
    contact : Contact
    normal_speed : float or ndarray
        Incident normal speed, > 0. Without adhesion an array gives array scales. [m/s]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (29)-(30) (Eq. (30) is printed as T^2:
    :attr:`microimpact.model.contact.Contact.time_scale`).

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> sc = nondimensional_scales(c, 1.0)
    >>> f"{sc.length:.6e} m", f"{sc.time:.6e} s", sc.a_hertz, sc.a_adhesion
    ('2.625777e-08 m', '2.084247e-08 s', 1.0, 1.0)
    >>> nondimensional_scales(c.with_(adhesion_line_force=0.0), 1.0).a_hertz
    1.25
    """
    if contact.adhesion_line_force > 0.0:
        return Scales(contact.length_scale, contact.time_scale, 1.0, 1.0)
    length, time = hertz_impact_scales(contact.mass, contact.stiffness, contact.radius, normal_speed)
    return Scales(length, time, 1.25, 0.0)


def nondimensional_impact(contact, normal_speed):
    """Scales, initial rate and damping of an impact: (scales, y0, C1, C2).

    y0 = v / (L / T_c) is the nondimensional incident normal speed [-]; C1 = C_H L / T_c and
    C2 = C_A L / T_c (Eqs. (31)-(32) in the adhesive scales) [-], with C_H, C_A of Eqs. (14)-(15).

    Parameters
    ----------
    contact : Contact
    normal_speed : float or ndarray
        Incident normal speed, > 0. [m/s]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (14)-(15) and (29)-(32).

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> sc, y0, c1, c2 = nondimensional_impact(c, 1.0)
    >>> round(y0, 6), round(y0 * sc.speed, 12)
    (0.793764, 1.0)
    """
    sc = nondimensional_scales(contact, normal_speed)
    u = sc.speed
    c_h, c_a = contact.damping_coefficients(normal_speed)
    return sc, normal_speed / u, c_h * u, c_a * u
