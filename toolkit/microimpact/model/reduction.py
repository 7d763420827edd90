"""The nondimensional groups of the normal impact, law by law, and a contact with given groups.

The normal motion of every normal law of :mod:`microimpact.model.laws` is one second-order ODE
for the approach x(t) with x(0) = 0, x'(0) = v (the incident normal speed). Written in the law's
own length L and time T_c (the paper's X and T of Eqs. (29)-(30), corrected, for the ring law;
:func:`~microimpact.model.adhesion_models.adhesion_scales` for JKR and DMT; the Hertz impact scales
without adhesion) its coefficients of the elastic and adhesive terms are pure numbers fixed by the
law, and what is left are the groups of :data:`LAW_GROUPS`:

============================================= ======================================= ==========
law (:func:`law_of`)                          groups                                  count
============================================= ======================================= ==========
``ring`` (Eq. (27), f0 > 0)                   y0 = v T / X, C1 = C_H X / T,           3
                                              C2 = C_A X / T (Eqs. (28), (31)-(32))
``jkr``, ``jkr_force``, ``dmt`` (f0 > 0)      y0 = v T_J / L_J, C1 = C_H L_J / T_J,   3
                                              C2 = C_A L_J / T_J (their own units)
``hertz`` (f0 = 0, the paper's damping)       C1 = C_H v (x* / t* = v)                1
``jkr+mass_velocity``, ... (f0 > 0, a DEM     y0, C3 = eta a_u^p U / F                2
damping law of :mod:`.dem_damping`)
``hertz+mass_velocity``,                      C3 = eta a_u^p U / F                    1
``hertz+viscoelastic``
``hertz+tsuji``, ``hertz+coeff_restitution``  C3 = the damping factor of e            1
============================================= ======================================= ==========

(eta = c a^p is :func:`~microimpact.model.dem_damping.dem_damping_law`, a_u the law's unit of the
contact radius, U = L / T_c and F its force unit.) Every nondimensional normal output is a
function of the law's groups alone: e_n, t_c / T_c, t_capture / T_c, x_max / L, the friction impulse
J / (m v) = J' / y0 (J' = J / (F T_c), and m v = y0 F T_c because F T_c^2 = m L), the dissipated
fraction of m v^2 / 2, and whether the sphere is captured.

Why these and no fewer
----------------------
*Enough.* The ring law, m x'' = -sqrt(r) K x^(3/2) (1 + C_H x') + 2 pi f0 sqrt(r) x^(1/2)
(1 - C_A x'), holds the sphere and the material only as m, A = sqrt(r) K, B = 2 pi f0 sqrt(r),
C_H, C_A and the initial rate v: six quantities in the three base units kg, m, s, whose dimension
matrix has rank 3, so (Buckingham's Pi theorem) three products of them decide the motion. With
xi = x / X, tau = t / T, X = B / A (Eq. (29)), T^2 = m / sqrt(A B) (Eq. (30) corrected) it reads
xi'' = xi^(1/2) (1 - C2 xi') - xi^(3/2) (1 + C1 xi'), xi(0) = 0, xi'(0) = y0: the three groups.
JKR and DMT hold (m, E* / R or K sqrt(R), w R, C_H, C_A, v) alike; without adhesion the force
coefficient A, m, C_H and v leave one group (v C_H: the Hunt-Crossley parameter), and the DEM laws
replace (C_H, C_A) by their one coefficient. The radius does not enter on its own: it is inside A,
B and m only.

*No fewer.* Each group changes e_n (tests/test_reduction.py), and for the three-group laws the
Jacobian of the outputs (e_n, t_c / T, J / (m v), x_max / X) with respect to the logarithms of the
groups has rank 3 at generic points (its smallest singular value is far above the finite-difference
noise, tests/test_reduction.py): were they functions of two combinations of the groups, that
Jacobian would have rank at most 2 everywhere. For the two-group laws the same test shows rank 2.

The paper's zeta. With the paper's per-impact reference speed (``damping_reference_speed=None``,
Eqs. (14)-(15)) C_H = zeta_H / (D v^(1/5)), D = (r^3 K / m)^(2/5), and a short calculation gives
C1 = zeta_H (X / r) y0^(-1/5), C2 = zeta_A (X / r) y0^(-1/5): zeta_H and zeta_A are not groups on
their own; they enter with the equilibrium penetration over the radius, X / r = 2 pi f0 / (K r).
(:func:`paper_damping_groups` checks it, tests/test_reduction.py.)

References
----------
Cheng, W., Brach, R. M. and Dunn, P. F. (2002), Three-Dimensional Modeling of Microsphere
Contact/Impact with Smooth, Flat Surfaces, Aerosol Sci. Technol. 36:1081-1093,
doi:10.1080/02786820290092221, Eqs. (14)-(15), (27)-(32).

Buckingham, E. (1914), On physically similar systems; illustrations of the use of dimensional
equations, Phys. Rev. 4:345-376, doi:10.1103/PhysRev.4.345.

Hunt, K. H. and Crossley, F. R. E. (1975), Coefficient of restitution interpreted as damping in
vibroimpact, J. Appl. Mech. 42:440-445, doi:10.1115/1.3423596.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from microimpact.model import adhesion_models as am
from microimpact.model import dem_damping as dd
from microimpact.model.contact import Contact, adhesion_line_force_from_work, check_positive
from microimpact.model.law import nondimensional_impact

__all__ = ["LAW_GROUPS", "NormalGroups", "law_of", "groups", "ring_groups", "paper_damping_groups", "contact_with_groups"]

_THREE = ("incident_speed", "hertz_damping", "adhesion_damping")
_DEM_ADHESIVE = ("incident_speed", "dem_damping")
#: the groups of each normal law (:func:`law_of`), by their field names in :class:`NormalGroups`
LAW_GROUPS: dict[str, tuple[str, ...]] = {
    "ring": _THREE, "jkr": _THREE, "jkr_force": _THREE, "dmt": _THREE,
    "hertz": ("hertz_damping",),
    **{f"{n}+{d}": _DEM_ADHESIVE for n in ("jkr", "jkr_force", "dmt") for d in ("mass_velocity", "viscoelastic")},
    **{f"hertz+{d}": ("dem_damping",) for d in dd.DEM_DAMPING_MODELS},
}


@dataclass(frozen=True)
class NormalGroups:
    """The nondimensional groups of the normal impacts of one contact at given speeds.

    Attributes
    ----------
    law : str
        The normal law, a key of :data:`LAW_GROUPS` (:func:`law_of`).
    incident_speed : float or ndarray
        y0 = v / (L / T_c): the incident normal speed in the law's speed unit (Eq. (28) for the
        ring law); 1 for the paper's Hertz law, whose units follow the speed. [-]
    hertz_damping : float or ndarray
        C1 = C_H L / T_c, Eq. (31) (C_H from zeta_H by Eq. (15)); 0 with a DEM damping law. [-]
    adhesion_damping : float or ndarray
        C2 = C_A L / T_c, Eq. (32); 0 without adhesion or with a DEM damping law. [-]
    dem_damping : float or ndarray
        C3 = eta a_u^p (L / T_c) / F of a DEM damping law; 0 with the paper's damping. [-]
    length : float or ndarray
        The law's length unit L (X of Eq. (29), L_J, L_D or the Hertz x*): not a group. [m]
    time : float or ndarray
        The law's time unit T_c (T of Eq. (30) corrected, ...): not a group. [s]

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> g = groups(c, 1.0)
    >>> g.law, g.names, [round(x, 6) for x in g.values]
    ('ring', ('incident_speed', 'hertz_damping', 'adhesion_damping'), [0.793764, 0.003985, 0.231152])
    """

    law: str
    incident_speed: float
    hertz_damping: float
    adhesion_damping: float
    dem_damping: float
    length: float
    time: float

    @property
    def names(self) -> tuple[str, ...]:
        """The groups of this law, :data:`LAW_GROUPS`."""
        return LAW_GROUPS[self.law]

    @property
    def values(self) -> tuple:
        """The values of :attr:`names`, in that order. [-]"""
        return tuple(getattr(self, n) for n in self.names)


def law_of(contact: Contact) -> str:
    """The normal law of ``contact`` as :data:`LAW_GROUPS` names it.

    Without adhesion (f0 = 0) every normal model is Hertz's law; a DEM damping law is appended
    after a ``+``.

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> law_of(c), law_of(c.with_(adhesion_line_force=0.0)), law_of(c.with_(normal_model="dmt"))
    ('ring', 'hertz', 'dmt')
    """
    base = "hertz" if contact.adhesion_line_force == 0.0 else contact.normal_model
    return base if contact.damping_model == "paper" else f"{base}+{contact.damping_model}"


def _paper_groups(law, contact, v, units):
    """NormalGroups of the paper's damping in the units (length, time) of the law."""
    length, time = units
    c_h, c_a = contact.damping_coefficients(v)
    u = length / time
    return NormalGroups(law, v / u, c_h * u, c_a * u, 0.0 * v, length, time)


def groups(contact: Contact, speed) -> NormalGroups:
    """The nondimensional groups of the normal impacts of ``contact`` at ``speed``, by law.

    Parameters
    ----------
    contact : Contact
        Any normal law and damping law that the solvers run (:func:`law_of`).
    speed : float or ndarray
        Incident normal speed v > 0. [m/s]

    Returns
    -------
    NormalGroups
        Scalars for a scalar ``speed``; arrays of its shape otherwise.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (14)-(15), (28)-(32); the module docstring for the other laws.

    Examples
    --------
    Two spheres a decade apart in size with the same groups (:func:`contact_with_groups`):

    >>> c, v = contact_with_groups("ring", incident_speed=2.0, hertz_damping=0.01, adhesion_damping=0.3,
    ...                            radius=1e-5, density=3000.0, stiffness=5e10, work_of_adhesion=0.5)
    >>> [round(float(x), 12) for x in groups(c, v).values]
    [2.0, 0.01, 0.3]
    """
    v = speed if isinstance(speed, np.ndarray) else check_positive("speed [m/s]", speed)
    law = law_of(contact)
    hertz = contact.adhesion_line_force == 0.0
    if contact.damping_model == "paper":
        if law == "ring" or hertz:  # the paper's scales X, T, or Hertz's x*, t* = x*/v (model.law)
            sc = nondimensional_impact(contact, v)[0]
            return _paper_groups(law, contact, v, (sc.length, sc.time))
        sc = am.adhesion_scales(contact)
        return _paper_groups(law, contact, v, (sc.length, sc.time))
    sc = am.hertz_scales(contact, v) if hertz else am.adhesion_scales(contact)
    eta, p = dd.dem_damping_law(contact)
    c3 = eta * sc.radius**p * sc.speed / sc.force
    plain = (lambda x: x) if isinstance(v, np.ndarray) else float  # scalar speed: scalar groups
    y0, c3, length, time = (plain(x) for x in (v / sc.speed, c3 + 0.0 * v, sc.length, sc.time))
    return NormalGroups(law, y0, 0.0 * v, 0.0 * v, c3, length, time)


def ring_groups(contacts, speeds) -> tuple:
    """(y0, C1, C2) of many ring-law contacts at once: row i of ``speeds`` [m/s] belongs to contact i. [-]

    The numbers of :func:`groups` (tests/test_reduction.py compares them), computed for all rows
    together from each contact's X, T (Eqs. (29)-(30)) and the damping speed scale of Eqs. (14)-(15):
    C = zeta / ((r^3 K / m)^(2/5) v_ref^(1/5)) X / T, v_ref the impact's speed or the contact's fixed
    ``damping_reference_speed``. A batch over many contacts pays one array operation instead of a
    :func:`groups` call per contact.

    Parameters
    ----------
    contacts : sequence of Contact
        Ring-law contacts with adhesion (:func:`law_of` "ring"), N of them.
    speeds : array_like, shape (N,) or (N, M)
        Incident normal speeds. [m/s]

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> y0, c1, c2 = ring_groups([c, c.with_(radius=1e-5)], [[1.0], [1.0]])
    >>> [round(float(x), 6) for x in (y0[0, 0], c1[0, 0], c2[0, 0])] == [round(x, 6) for x in groups(c, 1.0).values]
    True
    """
    contacts = list(contacts)
    v = np.asarray(speeds, dtype=float).reshape(len(contacts), -1)
    x = np.array([c.length_scale for c in contacts])[:, None]
    t = np.array([c.time_scale for c in contacts])[:, None]
    d = np.array([c.damping_speed_scale for c in contacts])[:, None]
    z_h = np.array([c.zeta_hertz for c in contacts])[:, None]
    z_a = np.array([c.zeta_adhesion for c in contacts])[:, None]
    fixed = np.array([np.nan if c.damping_reference_speed is None else c.damping_reference_speed for c in contacts])[:, None]
    u = x / t
    per_speed = u / (d * np.where(np.isnan(fixed), v, fixed) ** 0.2)  # X / T over (r^3 K sqrt(v_ref) / m)^(2/5)
    return v / u, z_h * per_speed, z_a * per_speed


def paper_damping_groups(contact: Contact, speed) -> tuple:
    """(C1, C2) of the ring law from the paper's zeta: zeta (X / r) y_ref^(-1/5), Eqs. (14)-(15). [-]

    y_ref = v_ref T / X, v_ref the damping reference speed (the impact's own ``speed`` by default).
    The same numbers as :func:`groups` by another route (module docstring): zeta_H and zeta_A enter
    e_n only with X / r.

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> g = groups(c, 3.0)
    >>> c1, c2 = paper_damping_groups(c, 3.0)
    >>> round(c1 / g.hertz_damping, 12), round(c2 / g.adhesion_damping, 12)
    (1.0, 1.0)
    """
    if law_of(contact) != "ring":
        raise ValueError(f"paper_damping_groups is for the ring law with adhesion, got {law_of(contact)!r}")
    x, t = contact.length_scale, contact.time_scale
    y_ref = contact.reference_speed(speed) * t / x
    factor = x / contact.radius * y_ref**-0.2
    return contact.zeta_hertz * factor, contact.zeta_adhesion * factor


def _tsuji_restitution(factor: float) -> float:
    """The e in (0, 1] with tsuji_damping_factor(e) = factor (bisection: the fit decreases in e)."""
    lo, hi = 1e-12, 1.0
    if not dd.tsuji_damping_factor(hi) <= factor <= dd.tsuji_damping_factor(lo):
        raise ValueError(f"dem_damping={factor!r} is outside the tsuji factors "
                         f"[{dd.tsuji_damping_factor(hi):.6g}, {dd.tsuji_damping_factor(lo):.6g}]")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if dd.tsuji_damping_factor(mid) > factor else (lo, mid)
        if hi - lo <= 1e-16:
            break
    return 0.5 * (lo + hi)


def _dem_contact(law, base, g, normal_speed):
    """(contact, speed) of a DEM damping law with dem_damping C3 (and incident_speed for adhesion)."""
    damping = law.split("+")[1]
    if damping == "coeff_restitution":
        return base.with_(damping_coefficient=dd.restitution_of_damping_factor(g["dem_damping"])), normal_speed
    if damping == "tsuji":
        return base.with_(damping_coefficient=_tsuji_restitution(g["dem_damping"])), normal_speed
    probe = base.with_(damping_coefficient=1.0)
    hertz = law.startswith("hertz")
    sc = am.hertz_scales(probe, normal_speed) if hertz else am.adhesion_scales(probe)
    v = normal_speed if hertz else g["incident_speed"] * sc.speed
    eta_unit, p = dd.dem_damping_law(probe)  # eta per unit damping_coefficient
    coefficient = g["dem_damping"] * float(sc.force) / (eta_unit * float(sc.radius) ** p * float(sc.speed))
    return base.with_(damping_coefficient=coefficient), float(v)


def contact_with_groups(law: str, *, radius: float = 1e-6, density: float = 1000.0, stiffness: float = 1e9,
                        work_of_adhesion: float = 0.1, normal_speed: float = 1.0, **group_values):
    """A contact and an incident normal speed whose impact has the given groups: the inverse of :func:`groups`.

    The sphere and the material (``radius``, ``density``, ``stiffness``, ``work_of_adhesion``, f0
    by Eq. (7)) are free: the groups fix the speed and the damping. The paper's damping is set as
    zeta_H, zeta_A with the per-impact reference speed (Eqs. (14)-(15)).

    Parameters
    ----------
    law : str
        A key of :data:`LAW_GROUPS`.
    radius, density, stiffness, work_of_adhesion : float
        r [m], rho [kg/m^3], K [Pa] and w_A [J/m^2] (ignored without adhesion).
    normal_speed : float
        The speed for a law in which the speed is not a group (Hertz; the speed then only
        sets the units). [m/s]
    **group_values
        Every group of the law, by its name in :data:`LAW_GROUPS`. [-]

    Returns
    -------
    (Contact, float)
        The contact and the incident normal speed [m/s].

    Examples
    --------
    >>> c, v = contact_with_groups("hertz", hertz_damping=0.2, normal_speed=3.0)
    >>> round(groups(c, v).hertz_damping, 12), v
    (0.2, 3.0)
    """
    if law not in LAW_GROUPS:
        raise ValueError(f"law must be one of {', '.join(LAW_GROUPS)}, got {law!r}")
    if set(group_values) != set(LAW_GROUPS[law]):
        raise ValueError(f"law {law!r} has the groups {', '.join(LAW_GROUPS[law])}; got {', '.join(group_values) or 'none'}")
    g = {k: check_positive(k, x) if k != "hertz_damping" and k != "adhesion_damping" else float(x)
         for k, x in group_values.items()}
    normal, _, damping = law.partition("+")
    hertz = normal == "hertz"
    f0 = 0.0 if hertz else adhesion_line_force_from_work(stiffness, radius, work_of_adhesion)
    base = Contact(radius, density, stiffness, f0, normal_model="ring" if hertz else normal,
                   damping_model=damping or "paper",
                   damping_coefficient=1.0 if damping in dd.RESTITUTION_DAMPING_MODELS else 0.0)
    if damping:
        return _dem_contact(law, base, g, normal_speed)
    if hertz:
        v = check_positive("normal_speed", normal_speed)  # the Hertz speed unit x* / t* is v itself
        c_h, c_a = g["hertz_damping"] / v, 0.0
    else:
        units = (base.length_scale, base.time_scale) if normal == "ring" else (
            am.adhesion_scales(base).length, am.adhesion_scales(base).time)
        u = units[0] / units[1]
        v = g["incident_speed"] * u
        c_h, c_a = g["hertz_damping"] / u, g["adhesion_damping"] / u
    scale = base.damping_speed_scale * v**0.2  # C = zeta / scale, Eqs. (14)-(15)
    return base.with_(zeta_hertz=c_h * scale, zeta_adhesion=c_a * scale), float(v)
