"""Alternative normal adhesion models: JKR and DMT, with the paper's damping forms; the Tabor parameter.

Each formula is written here once. The paper's own normal law (the adhesion ring force, Eqs. (4)-(6)
of Cheng, Brach & Dunn 2002) is in :mod:`microimpact.model.law`; a :class:`~microimpact.model.contact.Contact`
selects between them with ``normal_model`` ("ring", "jkr", "dmt"). The work of adhesion is the one
of the contact, w = :attr:`Contact.work_of_adhesion` (Eq. (7) inverted), so the three models share
the same surface energy; E* = 3 K / 4 (Eq. (3)).

JKR (Johnson, Kendall & Roberts 1971), sphere of radius R on a flat, contact radius a:

    delta = a^2 / R - sqrt(2 pi w a / E*),      F = 4 E* a^3 / (3 R) - sqrt(8 pi w E* a^3),

F positive away from the surface (repulsive), delta the approach (penetration). Contact forms at
delta = 0 on approach (the force jumps to -(8/9) F_c, F_c = (3/2) pi w R); it breaks on unloading at
the critical approach delta_c = -(3/4) (pi^2 w^2 R / E*^2)^(1/3) where d delta / d a = 0,
a_c = (pi w R^2 / (8 E*))^(1/3), with force -(5/9) F_c (Thornton & Ning 1998). With
q = sqrt(a / a_c), L_J = a_c^2 / R and F_J = pi w R the relation is a polynomial:

    delta / L_J = q^4 - 4 q,       F / F_J = q^6 / 6 - q^3,       q in [1, inf),

contact forms at q0 = 4^(1/3), breaks at q = 1, and the zero-load equilibrium is q^3 = 6 (a = a0,
the JKR zero-load radius that Eq. (7) matches). The potential U with F = dU/d delta is
U / (F_J L_J) = q^10 / 15 - 2 q^7 / 3 + q^4; the energy lost in one undamped contact cycle (the
adhesion hysteresis of Johnson & Pollock 1994) is U(1) - U(q0) = 2/5 + (12/5) 4^(1/3) = 4.2098 in
these units.

Where the contact breaks. The JKR relation has two stable ways to end a contact, and they are not
the same physics: under a controlled *displacement* (a rigid sphere pulled by its own inertia, the
case of an impact; Johnson & Pollock 1994, Thornton & Ning 1998) the contact follows the curve
down to d delta / d a = 0, q = 1, where the force has risen back to -(5/9) F_c; under a controlled
*load* it breaks at the largest tension, F = -F_c, where dF/da = 0: q^3 = 3, delta = -3^(1/3) L_J.
``normal_model="jkr"`` is the first (the impact literature's); ``"jkr_force"`` the second, which
DEM engines use (LAMMPS ``pair_style granular`` ``jkr``: contact is lost where the pull-off force
is reached), so that a user can match such an engine. The hysteresis of the force-controlled cycle
is U(3^(1/3)) - U(q0) = (3/5) 4^(4/3) - (2/5) 3^(4/3) = 2.0791, and its sticking velocity is
sqrt(2.0791 / 4.2098) = 0.703 times the displacement-controlled one.

DMT (Derjaguin, Muller & Toporov 1975): the Hertz force and a constant pull-off force,

    F = sqrt(R) K delta^(3/2) - 2 pi w R    (delta > 0),   F = 0  (delta <= 0),

with a = sqrt(R delta). Contact forms and breaks at delta = 0, so the undamped law is conservative:
in the DMT limit there is no adhesion hysteresis (Johnson & Pollock 1994), and only damping can
capture a sphere.

Damping: the same forms and coefficients as the paper's Eq. (27), applied to the repulsive (Hertzian)
and the adhesive part of each law: F_n = F_rep (1 + C_H x') + F_adh (1 - C_A x'), with C_H, C_A from
zeta_H, zeta_A by Eqs. (14)-(15). For JKR F_rep = 4 E* a^3 / (3 R), F_adh = -sqrt(8 pi w E* a^3);
for DMT F_rep = sqrt(R) K x^(3/2), F_adh = -2 pi w R. The damping power is
(C_H F_rep + C_A |F_adh|) x'^2 >= 0, so the contact energy never increases (this is a choice of
this toolkit, made to keep zeta_H and zeta_A meaning what they mean in the paper's law).

Tabor parameter (Tabor 1977): mu_T = (R w^2 / (E*^2 z0^3))^(1/3), z0 an equilibrium separation of
the surfaces. The adhesion map of Johnson & Greenwood (1997) puts JKR at mu_T > ~5 and DMT at
mu_T < ~0.1; in between the Maugis (1992) transition applies, which neither model describes.

References
----------
Johnson, K. L., Kendall, K. and Roberts, A. D. (1971), Surface energy and the contact of elastic
solids, Proc. R. Soc. Lond. A 324:301-313, doi:10.1098/rspa.1971.0141.
Derjaguin, B. V., Muller, V. M. and Toporov, Yu. P. (1975), Effect of contact deformations on the
adhesion of particles, J. Colloid Interface Sci. 53:314-326, doi:10.1016/0021-9797(75)90018-1.
Tabor, D. (1977), Surface forces and surface interactions, J. Colloid Interface Sci. 58:2-13,
doi:10.1016/0021-9797(77)90366-6.
Maugis, D. (1992), Adhesion of spheres: the JKR-DMT transition using a Dugdale model,
J. Colloid Interface Sci. 150:243-269, doi:10.1016/0021-9797(92)90285-T.
Johnson, K. L. and Pollock, H. M. (1994), The role of adhesion in the impact of elastic spheres,
J. Adhesion Sci. Technol. 8:1323-1332, doi:10.1163/156856194X00627.
Johnson, K. L. and Greenwood, J. A. (1997), An adhesion map for the contact of elastic spheres,
J. Colloid Interface Sci. 192:326-333, doi:10.1006/jcis.1997.4984.
Thornton, C. and Ning, Z. (1998), A theoretical model for the stick/bounce behaviour of adhesive,
elastic-plastic spheres, Powder Technol. 99:154-162, doi:10.1016/S0032-5910(98)00099-0.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

__all__ = [
    "DEFAULT_EQUILIBRIUM_SEPARATION",
    "JKR_REGIME_MIN_TABOR",
    "DMT_REGIME_MAX_TABOR",
    "JKR_HYSTERESIS",
    "JKR_HYSTERESIS_FORCE",
    "JKR_Q_BREAK",
    "jkr_hysteresis",
    "THORNTON_NING_COEFFICIENT",
    "AdhesionRegimeWarning",
    "AdhesionScales",
    "adhesion_scales",
    "tabor_parameter",
    "check_adhesion_regime",
    "jkr_approach",
    "jkr_force",
    "jkr_critical_approach",
    "jkr_contact_radius",
    "jkr_q_from_approach",
    "dmt_force",
    "jkr_sticking_velocity",
    "thornton_ning_sticking_velocity",
    "jkr_nondimensional_force",
    "jkr_nondimensional_potential",
    "dmt_nondimensional_force",
    "dmt_nondimensional_potential",
]

#: Default equilibrium separation z0 of the Tabor parameter: 0.4 nm, an interatomic spacing of the
#: order Tabor (1977) and Johnson & Greenwood (1997) use (their maps take z0 of a few tenths of a nm). [m]
DEFAULT_EQUILIBRIUM_SEPARATION = 0.4e-9
#: JKR applies above this Tabor parameter (Johnson & Greenwood 1997 adhesion map). [-]
JKR_REGIME_MIN_TABOR = 5.0
#: DMT applies below this Tabor parameter (Johnson & Greenwood 1997 adhesion map). [-]
DMT_REGIME_MAX_TABOR = 0.1
#: JKR q at contact formation (delta = 0): q0^3 = 4. [-]
JKR_Q_FORMATION = 4.0 ** (1.0 / 3.0)
#: Energy lost in one undamped JKR contact cycle, U(1) - U(q0) = 2/5 + (12/5) 4^(1/3), in units of
#: F_J L_J = pi w a_c^2 (module docstring). [-]
JKR_HYSTERESIS = 0.4 + 2.4 * JKR_Q_FORMATION
#: JKR q at which contact breaks, per normal model: q = 1 (d delta/da = 0) under a controlled
#: displacement ("jkr"), q^3 = 3 (dF/da = 0, F = -F_c) under a controlled load ("jkr_force"). [-]
JKR_Q_BREAK = {"jkr": 1.0, "jkr_force": 3.0 ** (1.0 / 3.0)}
#: Energy lost in one undamped force-controlled JKR cycle, U(3^(1/3)) - U(q0), in units F_J L_J. [-]
JKR_HYSTERESIS_FORCE = 0.6 * 4.0 ** (4.0 / 3.0) - 0.4 * 3.0 ** (4.0 / 3.0)
#: Numerical coefficient of the Thornton & Ning (1998) sticking velocity, as published (3 digits). [-]
THORNTON_NING_COEFFICIENT = 1.84


class AdhesionRegimeWarning(UserWarning):
    """The selected normal adhesion model is outside its regime of the Tabor parameter.

    JKR is meant for mu_T > ~5 (compliant, large, strongly adhering contacts), DMT for mu_T < ~0.1
    (stiff, small, weakly adhering ones) (Johnson & Greenwood 1997). Outside, the results are a
    model's extrapolation; the warning names the contact's mu_T and the regime.

    Examples
    --------
    The paper's microsphere is a JKR contact (mu_T = 11.2); DMT is outside its regime there:

    >>> import warnings
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     _ = check_adhesion_regime(c.with_(normal_model="dmt"))
    >>> caught[0].category.__name__, str(caught[0].message)
    ('AdhesionRegimeWarning', "normal_model='dmt' with Tabor parameter mu_T = 11.2 > 0.1
    (z0 = 4e-10 m): outside the DMT regime (Johnson & Greenwood 1997)")
    """


@dataclass(frozen=True)
class AdhesionScales:
    """Scales of the nondimensional JKR or DMT law (module docstring).

    Attributes
    ----------
    length : float
        L_J = a_c^2 / R (JKR) or L_D = (2 pi w sqrt(R) / K)^(2/3) (DMT). [m]
    force : float
        F_J = pi w R (JKR) or 2 pi w R (DMT). [N]
    time : float
        sqrt(m L / F). [s]
    radius : float
        Contact radius unit: a_c (JKR: a = a_c q^2) or sqrt(R L_D) (DMT: a = sqrt(R L_D) s). [m]

    Examples
    --------
    The JKR force unit is pi w R (DMT: 2 pi w R), the contact-radius unit a_c with L_J = a_c^2 / R,
    and the time unit sqrt(m L / F):

    >>> import math
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> s = adhesion_scales(c.with_(normal_model="jkr"))
    >>> w, r = c.work_of_adhesion, c.radius
    >>> round(s.force / (math.pi * w * r), 12), round(s.radius**2 / r / s.length, 12)
    (1.0, 1.0)
    >>> round(s.time**2 * s.force / (c.mass * s.length), 12)
    1.0
    >>> round(adhesion_scales(c.with_(normal_model="dmt")).force / (2 * math.pi * w * r), 12)
    1.0
    """

    length: float
    force: float
    time: float
    radius: float

    @property
    def speed(self) -> float:
        """L / T. [m/s]"""
        return self.length / self.time


def _effective_modulus(contact) -> float:
    """E* = 3 K / 4, Eq. (3). [Pa]"""
    return 0.75 * contact.stiffness


def adhesion_scales(contact, model: str | None = None) -> AdhesionScales:
    """Length, force, time and contact-radius units of the JKR or DMT law of ``contact``.

    Parameters
    ----------
    contact : Contact
        With adhesion (f0 > 0, so w > 0).
    model : {"jkr", "dmt", "jkr_force"}, optional
        Default ``contact.normal_model``; both JKR break criteria share the JKR units.

    References
    ----------
    Johnson, K. L., Kendall, K. and Roberts, A. D. (1971), Proc. R. Soc. Lond. A 324:301-313;
    Derjaguin, B. V., Muller, V. M. and Toporov, Yu. P. (1975), J. Colloid Interface Sci. 53:314-326.

    Examples
    --------
    The JKR contact breaks (displacement-controlled) at delta_c = -3 L_J, where a = a_c:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> sc = adhesion_scales(c.with_(normal_model="jkr"))
    >>> r, k, w = c.radius, c.stiffness, c.work_of_adhesion
    >>> round(float(jkr_critical_approach(r, k, w) / sc.length), 12), round(float(jkr_approach(r, k, w, sc.radius) / sc.length), 12)
    (-3.0, -3.0)
    """
    model = contact.normal_model if model is None else model
    w, r, k = contact.work_of_adhesion, contact.radius, contact.stiffness
    if not w > 0.0:
        raise ValueError("the JKR and DMT scales need adhesion (adhesion_line_force > 0)")
    if model in ("jkr", "jkr_force"):
        a_c = (math.pi * w * r * r / (8.0 * _effective_modulus(contact))) ** (1.0 / 3.0)
        length, force, a_unit = a_c * a_c / r, math.pi * w * r, a_c
    elif model == "dmt":
        length = (2.0 * math.pi * w * math.sqrt(r) / k) ** (2.0 / 3.0)
        force, a_unit = 2.0 * math.pi * w * r, math.sqrt(r * length)
    else:
        raise ValueError(f"adhesion_scales is for normal_model 'jkr', 'jkr_force' or 'dmt', got {model!r}")
    return AdhesionScales(length, force, math.sqrt(contact.mass * length / force), a_unit)


# =============================================================================== Tabor parameter
def tabor_parameter(radius, stiffness, work_of_adhesion, equilibrium_separation=DEFAULT_EQUILIBRIUM_SEPARATION):
    """Tabor parameter mu_T = (R w^2 / (E*^2 z0^3))^(1/3) (Tabor 1977), E* = 3 K / 4. [-]

    Parameters
    ----------
    radius : array_like
        Sphere radius R. [m]
    stiffness : array_like
        Effective stiffness K of Eq. (3). [Pa]
    work_of_adhesion : array_like
        w. [J/m^2]
    equilibrium_separation : float
        z0 (default :data:`DEFAULT_EQUILIBRIUM_SEPARATION`). [m]

    References
    ----------
    Tabor, D. (1977), Surface forces and surface interactions, J. Colloid Interface Sci. 58:2-13,
    doi:10.1016/0021-9797(77)90366-5.

    Examples
    --------
    The paper's microsphere (Table 1) with z0 = 0.4 nm lies in the JKR regime (mu_T > 5):

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> round(float(tabor_parameter(c.radius, c.stiffness, c.work_of_adhesion)), 2)
    11.23
    """
    e_star = 0.75 * np.asarray(stiffness, dtype=float)
    return np.cbrt(np.asarray(radius, dtype=float) * np.square(work_of_adhesion)
                   / (e_star**2 * equilibrium_separation**3))


def check_adhesion_regime(contact, equilibrium_separation=DEFAULT_EQUILIBRIUM_SEPARATION, *, stacklevel=2) -> float:
    """The contact's Tabor parameter; an :class:`AdhesionRegimeWarning` if its model is outside its regime.

    JKR outside mu_T > :data:`JKR_REGIME_MIN_TABOR`, DMT outside mu_T < :data:`DMT_REGIME_MAX_TABOR`
    (Johnson & Greenwood 1997). The paper's ring model ("ring") and contacts without adhesion are
    not checked.

    Returns
    -------
    float
        mu_T. [-]

    References
    ----------
    Johnson, K. L. and Greenwood, J. A. (1997), An adhesion map for the contact of elastic spheres,
    J. Colloid Interface Sci. 192:326-333, doi:10.1006/jcis.1997.4984.

    Examples
    --------
    >>> import warnings
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     mu = check_adhesion_regime(c.with_(normal_model="dmt"))
    >>> round(mu, 2), caught[0].category.__name__
    (11.23, 'AdhesionRegimeWarning')
    """
    mu = float(tabor_parameter(contact.radius, contact.stiffness, contact.work_of_adhesion, equilibrium_separation))
    if contact.work_of_adhesion > 0.0:
        if contact.normal_model in ("jkr", "jkr_force") and mu < JKR_REGIME_MIN_TABOR:
            warnings.warn(f"normal_model={contact.normal_model!r} with Tabor parameter mu_T = {mu:.3g} < {JKR_REGIME_MIN_TABOR:g} "
                          f"(z0 = {equilibrium_separation:.3g} m): outside the JKR regime (Johnson & Greenwood 1997)",
                          AdhesionRegimeWarning, stacklevel=stacklevel)
        elif contact.normal_model == "dmt" and mu > DMT_REGIME_MAX_TABOR:
            warnings.warn(f"normal_model='dmt' with Tabor parameter mu_T = {mu:.3g} > {DMT_REGIME_MAX_TABOR:g} "
                          f"(z0 = {equilibrium_separation:.3g} m): outside the DMT regime (Johnson & Greenwood 1997)",
                          AdhesionRegimeWarning, stacklevel=stacklevel)
    return mu


# =============================================================================== SI forms
def jkr_approach(radius, stiffness, work_of_adhesion, contact_radius_):
    """JKR approach delta(a) = a^2 / R - sqrt(2 pi w a / E*) (Johnson et al. 1971). [m]

    Parameters: R [m], K [Pa] (E* = 3 K / 4), w [J/m^2], contact radius a [m].

    References
    ----------
    Johnson, Kendall & Roberts (1971), Proc. R. Soc. Lond. A 324:301-313.

    Examples
    --------
    Contact forms (delta = 0) at a = 4^(2/3) a_c:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> a_c = adhesion_scales(c.with_(normal_model="jkr")).radius
    >>> abs(float(jkr_approach(c.radius, c.stiffness, c.work_of_adhesion, 4.0 ** (2.0 / 3.0) * a_c))) < 1e-22
    True
    """
    a = np.asarray(contact_radius_, dtype=float)
    return a * a / radius - np.sqrt(2.0 * math.pi * work_of_adhesion * a / (0.75 * stiffness))


def jkr_force(radius, stiffness, work_of_adhesion, contact_radius_):
    """JKR force F(a) = 4 E* a^3 / (3 R) - sqrt(8 pi w E* a^3), positive = repulsive. [N]

    Parameters: R [m], K [Pa] (E* = 3 K / 4), w [J/m^2], contact radius a [m].

    References
    ----------
    Johnson, Kendall & Roberts (1971), Proc. R. Soc. Lond. A 324:301-313.

    Examples
    --------
    At the break of the displacement-controlled contact (a = a_c) the force is -(5/9) F_c, F_c = (3/2) pi w R:

    >>> import math
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> r, k, w = c.radius, c.stiffness, c.work_of_adhesion
    >>> a_c = adhesion_scales(c.with_(normal_model="jkr")).radius
    >>> round(float(jkr_force(r, k, w, a_c) / (1.5 * math.pi * w * r)), 12) == round(-5.0 / 9.0, 12)
    True
    """
    a = np.asarray(contact_radius_, dtype=float)
    e_star = 0.75 * stiffness
    return 4.0 * e_star * a**3 / (3.0 * radius) - np.sqrt(8.0 * math.pi * work_of_adhesion * e_star * a**3)


def jkr_critical_approach(radius, stiffness, work_of_adhesion):
    """Approach at which a JKR contact breaks, delta_c = -(3/4) (pi^2 w^2 R / E*^2)^(1/3). [m]

    (Thornton & Ning 1998); the minimum of :func:`jkr_approach`, at a_c = (pi w R^2 / (8 E*))^(1/3).

    References
    ----------
    Thornton, C. and Ning, Z. (1998), A theoretical model for the stick/bounce behaviour of adhesive,
    elastic-plastic spheres, Powder Technol. 99:154-162, doi:10.1016/S0032-5910(98)00099-0.

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> f"{float(jkr_critical_approach(c.radius, c.stiffness, c.work_of_adhesion)):.4e} m"
    '-7.2251e-09 m'
    """
    e_star = 0.75 * stiffness
    return -0.75 * np.cbrt(math.pi**2 * np.square(work_of_adhesion) * radius / e_star**2)


def jkr_q_from_approach(approach_ratio):
    """q >= 1 on the stable JKR branch with q^4 - 4 q = delta / L_J (module docstring). [-]

    Newton's method from above the root (q^4 - 4 q is convex and increasing for q > 1), vectorised.

    Parameters
    ----------
    approach_ratio : array_like
        delta / L_J >= -3 (delta_c / L_J = -3). [-]

    References
    ----------
    Johnson, Kendall & Roberts (1971)

    Examples
    --------
    >>> q = jkr_q_from_approach([-3.0, 0.0, 10.0])
    >>> q.round(8).tolist(), (q**4 - 4 * q).round(12).tolist()
    ([1.0, 1.58740105, 2.06744159], [-3.0, 0.0, 10.0])
    """
    d = np.asarray(approach_ratio, dtype=float)
    q = np.sqrt(np.sqrt(np.maximum(d, 0.0) + 4.0)) + 1.0  # q^4 - 4q > d here
    for _ in range(80):
        step = (q**4 - 4.0 * q - d) / (4.0 * q**3 - 4.0)
        q = np.maximum(q - step, 1.0)
        if np.all(np.abs(step) <= 4e-16 * q):
            break
    return q


def jkr_contact_radius(radius, stiffness, work_of_adhesion, approach):
    """Contact radius a(delta) = a_c q^2 on the stable JKR branch (a >= a_c), delta >= delta_c. [m]

    Parameters: R [m], K [Pa] (E* = 3 K / 4), w [J/m^2], approach delta [m].

    References
    ----------
    Johnson, Kendall & Roberts (1971), Proc. R. Soc. Lond. A 324:301-313.

    Examples
    --------
    At first touch (delta = 0) a = 4^(2/3) a_c:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> a_c = adhesion_scales(c.with_(normal_model="jkr")).radius
    >>> round(float(jkr_contact_radius(c.radius, c.stiffness, c.work_of_adhesion, 0.0) / a_c), 10)
    2.5198420998
    """
    a_c = np.cbrt(math.pi * work_of_adhesion * radius**2 / (8.0 * 0.75 * stiffness))
    return a_c * jkr_q_from_approach(np.asarray(approach, dtype=float) / (a_c * a_c / radius)) ** 2


def dmt_force(radius, stiffness, work_of_adhesion, approach):
    """DMT force F = sqrt(R) K delta^(3/2) - 2 pi w R for delta > 0, 0 otherwise. [N]

    (Derjaguin, Muller & Toporov 1975). Parameters: R [m], K [Pa], w [J/m^2], approach delta [m].

    References
    ----------
    Derjaguin, Muller & Toporov (1975), J. Colloid Interface Sci. 53:314-326.

    Examples
    --------
    The pull-off force 2 pi w R acts at any approach > 0, and is balanced at delta = L_D:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> r, k, w = c.radius, c.stiffness, c.work_of_adhesion
    >>> dmt_force(r, k, w, [-1e-9, 0.0]).tolist()
    [0.0, 0.0]
    >>> abs(float(dmt_force(r, k, w, adhesion_scales(c.with_(normal_model="dmt")).length))) < 1e-18
    True
    """
    d = np.asarray(approach, dtype=float)
    return np.where(d > 0.0, math.sqrt(radius) * stiffness * np.maximum(d, 0.0) ** 1.5 - 2.0 * math.pi * work_of_adhesion * radius, 0.0)


# =============================================================================== sticking velocity
def jkr_hysteresis(normal_model: str = "jkr") -> float:
    """Energy lost in one undamped JKR contact cycle, in units F_J L_J = pi w a_c^2. [-]

    U(q_break) - U(4^(1/3)) with the break of ``normal_model`` (:data:`JKR_Q_BREAK`): 4.2098 for the
    displacement-controlled break ("jkr"), 2.0791 for the force-controlled one ("jkr_force").

    References
    ----------
    Johnson, Kendall & Roberts (1971)

    Examples
    --------
    >>> round(jkr_hysteresis("jkr"), 4), round(jkr_hysteresis("jkr_force"), 4)
    (4.2098, 2.0791)
    """
    return JKR_HYSTERESIS_FORCE if normal_model == "jkr_force" else JKR_HYSTERESIS


def jkr_sticking_velocity(contact) -> float:
    """Exact undamped JKR sticking velocity v_s = sqrt(2 Delta_E / m), Delta_E = H pi w a_c^2. [m/s]

    Below v_s an elastic JKR impact is captured; above, e_n = sqrt(1 - v_s^2 / v^2). Delta_E is the
    work of the adhesive force between the break and delta = 0 on unloading (Johnson & Pollock
    1994); H = :func:`jkr_hysteresis` of the contact's break criterion ("jkr_force": force-controlled;
    otherwise the displacement-controlled "jkr").

    References
    ----------
    Johnson, K. L. and Pollock, H. M. (1994), The role of adhesion in the impact of elastic spheres,
    J. Adhesion Sci. Technol. 8:1323-1332, doi:10.1163/156856194X00627.

    Examples
    --------
    The paper's microsphere: 0.452 m/s with the displacement-controlled break, 0.318 m/s with the
    force-controlled one (LAMMPS's ``jkr``):

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> [round(jkr_sticking_velocity(c.with_(normal_model=m)), 4) for m in ("jkr", "jkr_force")]
    [0.452, 0.3176]
    """
    sc = adhesion_scales(contact, "jkr")
    return math.sqrt(2.0 * jkr_hysteresis(contact.normal_model) * sc.force * sc.length / contact.mass)


def thornton_ning_sticking_velocity(radius, density, stiffness, work_of_adhesion) -> float:
    """Thornton & Ning (1998): v_s = 1.84 (w^5 / (rho^3 E*^2 R^5))^(1/6), E* = 3 K / 4. [m/s]

    Parameters: R [m], rho [kg/m^3], K [Pa], w [J/m^2]. The coefficient is published to three
    digits; :func:`jkr_sticking_velocity` gives sqrt(3 H pi^(2/3) / 8) = 1.84018 in its place
    (H = :data:`JKR_HYSTERESIS`).

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> round(thornton_ning_sticking_velocity(c.radius, c.density, c.stiffness, c.work_of_adhesion), 4)
    0.4519
    """
    e_star = 0.75 * stiffness
    return THORNTON_NING_COEFFICIENT * (work_of_adhesion**5 / (density**3 * e_star**2 * radius**5)) ** (1.0 / 6.0)


# =============================================================================== nondimensional forms
# Scalar arithmetic only, so that numpy arrays pass through and numba compiles them as they are.
def jkr_nondimensional_force(q, y, c1, c2):
    """F / F_J = (q^6 / 6)(1 + C1 y) - q^3 (1 - C2 y), with y = d(delta/L_J)/d(t/T). [-]

    The repulsive part q^6 / 6 and the adhesive part -q^3 carry the damping forms of Eq. (27);
    C1 = C_H L_J / T, C2 = C_A L_J / T.

    References
    ----------
    Johnson, Kendall & Roberts (1971)

    Examples
    --------
    Zero at the zero-load equilibrium q^3 = 6 at rest; -5/6 at the displacement-controlled break q = 1:

    >>> round(jkr_nondimensional_force(6.0 ** (1.0 / 3.0), 0.0, 0.1, 0.1), 12)
    0.0
    >>> round(jkr_nondimensional_force(1.0, 0.0, 0.0, 0.0), 12)
    -0.833333333333
    """
    q3 = q * q * q
    return q3 * q3 / 6.0 * (1.0 + c1 * y) - q3 * (1.0 - c2 * y)


def jkr_nondimensional_potential(q):
    """U / (F_J L_J) = q^10 / 15 - 2 q^7 / 3 + q^4, dU/d(delta/L_J) = F / F_J undamped. [-]

    References
    ----------
    Johnson, Kendall & Roberts (1971)

    Examples
    --------
    The adhesion hysteresis of one undamped cycle, U(1) - U(4^(1/3)):

    >>> round(jkr_nondimensional_potential(1.0) - jkr_nondimensional_potential(4.0 ** (1.0 / 3.0)), 4)
    4.2098
    """
    q3 = q * q * q
    q4 = q3 * q
    return q4 * (q3 * q3 / 15.0 - 2.0 * q3 / 3.0 + 1.0)


def jkr_nondimensional_dissipation_rate(q, y, c1, c2):
    """Damping power / (F_J L_J / T) = (C1 q^6 / 6 + C2 q^3) y^2 >= 0. [-]

    Examples
    --------
    >>> round(jkr_nondimensional_dissipation_rate(1.0, 2.0, 0.6, 0.5), 12)  # (0.6 / 6 + 0.5) 2^2
    2.4
    """
    q3 = q * q * q
    return (c1 * q3 * q3 / 6.0 + c2 * q3) * y * y


def dmt_nondimensional_force(s, y, c1, c2):
    """F / F_D = s^3 (1 + C1 y) - (1 - C2 y), s = sqrt(delta / L_D), in contact. [-]

    References
    ----------
    Derjaguin, B. V., Muller, V. M. and Toporov, Yu. P. (1975), Effect of contact deformations on
    the adhesion of particles, J. Colloid Interface Sci. 53:314-326,
    doi:10.1016/0021-9797(75)90018-1

    Examples
    --------
    >>> dmt_nondimensional_force(1.0, 0.0, 0.3, 0.3), dmt_nondimensional_force(0.0, 0.0, 0.3, 0.3)
    (0.0, -1.0)
    """
    return s * s * s * (1.0 + c1 * y) - (1.0 - c2 * y)


def dmt_nondimensional_potential(s):
    """U / (F_D L_D) = (2/5) s^5 - s^2 (contact energy relative to first touch). [-]

    References
    ----------
    Derjaguin, B. V., Muller, V. M. and Toporov, Yu. P. (1975), Effect of contact deformations on
    the adhesion of particles, J. Colloid Interface Sci. 53:314-326,
    doi:10.1016/0021-9797(75)90018-1

    Examples
    --------
    >>> round(dmt_nondimensional_potential(1.0), 12)  # the bottom of the well, s = 1
    -0.6
    """
    s2 = s * s
    return s2 * (0.4 * s2 * s - 1.0)


def dmt_nondimensional_dissipation_rate(s, y, c1, c2):
    """Damping power / (F_D L_D / T) = (C1 s^3 + C2) y^2 >= 0. [-]

    Examples
    --------
    >>> dmt_nondimensional_dissipation_rate(1.0, 2.0, 0.5, 0.25)  # (0.5 + 0.25) 2^2
    3.0
    """
    return (c1 * s * s * s + c2) * y * y


# =============================================================================== Hertz, in the same form
# Without adhesion the DMT law is Hertz's. Its own units: the speed-dependent largest undamped approach
# L = (5 m v^2 / (4 K sqrt(R)))^(2/5) of an impact at v, force K sqrt(R) L^(3/2); state s = sqrt(delta / L)
# as for DMT. Used with the DEM damping laws (microimpact.model.dem_damping); the paper's damped Hertz
# law is the ring law with f0 = 0 (microimpact.model.law).
def hertz_scales(contact, normal_speed) -> AdhesionScales:
    """Length, force, time and contact-radius units of the Hertz law for impacts at ``normal_speed``.

    L = (5 m v^2 / (4 K sqrt(R)))^(2/5) (the undamped largest approach), F = K sqrt(R) L^(3/2),
    T = sqrt(m L / F), a unit sqrt(R L); arrays for an array of speeds. [m], [N], [s], [m]

    Examples
    --------
    The undamped impact in these units enters at y0 = sqrt(4/5) and turns at s = 1:

    >>> from microimpact.model.contact import Contact
    >>> sc = hertz_scales(Contact(1e-6, 2000.0, 1e9, 0.0), 1.0)
    >>> round(float(1.0 / sc.speed), 6)
    0.894427
    """
    v = np.asarray(normal_speed, dtype=float)
    k_sqrt_r = contact.stiffness * math.sqrt(contact.radius)
    length = (1.25 * contact.mass * v * v / k_sqrt_r) ** 0.4
    force = k_sqrt_r * length**1.5
    return AdhesionScales(length, force, np.sqrt(contact.mass * length / force), np.sqrt(contact.radius * length))


def hertz_nondimensional_force(s, y, c1):
    """Hertz force with the paper's Hertzian damping, F / F_H = s^3 (1 + C1 y), s = sqrt(delta / L). [-]

    Examples
    --------
    >>> hertz_nondimensional_force(1.0, 0.0, 0.3), round(hertz_nondimensional_force(1.0, -1.0, 0.3), 12)
    (1.0, 0.7)
    """
    return s * s * s * (1.0 + c1 * y)


def hertz_nondimensional_potential(s):
    """U / (F_H L) = (2/5) s^5 of the Hertz law. [-]

    Examples
    --------
    The undamped impact turns at s = 1 with the incident energy y0^2 / 2 = 2/5:

    >>> hertz_nondimensional_potential(1.0)
    0.4
    """
    return 0.4 * s**5


def hertz_nondimensional_dissipation_rate(s, y, c1):
    """Power of the Hertzian damping, C1 s^3 y^2. [-]

    Examples
    --------
    >>> hertz_nondimensional_dissipation_rate(1.0, 2.0, 0.5)
    2.0
    """
    return c1 * s * s * s * y * y
