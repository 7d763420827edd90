"""Contact models beyond the paper: tangential compliance (Mindlin) and adhesion-aware friction.

Each formula is written here once. The SI functions take arrays; the nondimensional ones
(:func:`friction_load`, :func:`microslip_factor`, :func:`mindlin_force_rate`) are scalar arithmetic
that numba compiles into the coupled solver (:mod:`microimpact.solvers.coupled`) and that the scipy
reference solver calls as they are.

Tangential compliance ("mindlin")
---------------------------------
The paper's contact is tangentially rigid: friction f |F_n| acts against the slip of the contact
point and stops when the slip does. Real contacts deform tangentially: a Hertz contact of radius a
between two elastic bodies has the tangential stiffness (Mindlin 1949; Johnson 1985, Sec. 7.2)

    k_t = 8 G* a,    1/G* = (2 - nu_1)/G_1 + (2 - nu_2)/G_2,

so that, for identical Poisson ratios, k_t / k_n = 2 (1 - nu) / (2 - nu) with k_n = 2 E* a the normal
contact stiffness. Micro-slip -- the annulus of the contact that slips before the whole contact
does -- softens the contact as the tangential force approaches the Coulomb limit F_lim. Mindlin's
load-displacement relation of a sphere under a normal load and a growing tangential displacement
delta (Mindlin 1949; Johnson 1985, Eqs. (7.40)-(7.42)) gives the force

    F_t = -F_lim [1 - (1 - |delta| / delta*)^(3/2)] delta / |delta|,   delta* = 3 F_lim / (2 k_t),

which is -k_t delta for small displacements, reaches the limit with zero slope at |delta| =
delta* (micro-slip has spread over the whole contact) and is F_lim in gross sliding, where the
displacement is held at delta* (the slip beyond it is not stored). The state is the tangential
displacement of the contact, d delta / dt = u (the contact-point slip velocity); F_lim and k_t
follow the normal solve at every instant. This is the monotonic-loading curve of
Mindlin & Deresiewicz (1953), without their unloading/reloading memory (it is elastic below
gross slip); a simplification like that of the DEM forms compared by Di Renzo & Di Maio (2004).
With micro-slip switched off (F_t = -k_t delta up to the limit) it is their "no-slip" Mindlin
model; as k_t grows without bound it becomes the rigid contact of the paper.

Hysteretic tangential contact ("mindlin_deresiewicz")
-----------------------------------------------------
The "mindlin" force above is a function of the displacement: unloading retraces the loading curve
and the energy of micro-slip is returned. Mindlin & Deresiewicz (1953) showed that it is not:
after a turning point the contact first sticks again everywhere (full stiffness k_t) and the
unloading curve is the loading curve scaled by two (Masing's rule). Thornton (1991) and Thornton &
Yin (1991) wrote this as an incremental law for a varying normal load,

    dT = k_t theta d delta + s f dL (1 - theta),   theta^3 = 1 - s (T - T_r) / (c F_lim),

with T the tangential force resisting the displacement delta (along the slip direction), s = +-1
the direction of the current branch, T_r the force at its turning point, L the friction load
(F_lim = f L) and c = 1 on the first (virgin) loading, c = 2 on unloading and reloading from gross
slip. The second term (theirs) lets a contact near gross slip follow the changing limit: it slips
when the normal load falls and sticks when it rises.

Here the branch is written so that it always ends, with zero stiffness, at the opposite Coulomb
limit: c = 1 + |T_r| / F_lim at the turning point (c = 2 from gross slip, Mindlin-Deresiewicz's
case; c = 1 on the virgin curve), and the turning point moves with the limit, T_r = s F_lim (1 - c)
(Thornton's T* <- T* +- f dL). This replaces Masing's loop-closure bookkeeping (a stack of turning
points) for turning points below the limit, where it is an interpolation between the virgin (c = 1)
and the Mindlin-Deresiewicz (c = 2) curves. With the branch coordinate p in [0, 1],

    T = s F_lim [1 - c (1 - p)^(3/2)],    theta = (1 - p)^(1/2),

the incremental law becomes (:func:`md_branch_rate`)

    dp/dt = s u k_t / (1.5 c F_lim) + (2/3) (dF_lim/dt / F_lim) (1 - p - 1/c),

whose right-hand side is smooth in p (the force law in T has the non-Lipschitz theta = (1 - ...)^(1/3)
that made the incremental form stiff), with p held at 1 in gross slip. Turning points (the slip
along the branch, s u, changes sign) are located as events; there p restarts at 0 with s -> -s,
which keeps the force continuous. At constant normal load and from gross slip this is exactly the
Mindlin-Deresiewicz curve; for small displacements it is k_t delta (no-slip Mindlin) like the
"mindlin" model, so both share the rigid limit as G* grows. The tangential dynamics of a sphere on a
flat is isotropic and starts from zero force, so the force stays along the initial slip direction e
and a scalar law along e is exact (with rolling resistance about another axis, only the slip along
e is resisted).

A turning point while the load falls (the reading chosen, and the alternatives)
-------------------------------------------------------------------------------
Right after a turning point the contact sticks everywhere (theta = 1, p = 0). If the normal load then
falls faster than the elastic reloading raises the force, the rate above would take p below 0; the
law needs a rule for the force there, and Thornton (1991) can be read in more than one way. Its
incremental form has no load term at theta = 1 (s f dL (1 - theta) = 0), which read literally keeps
the force; its update of the turning point, T* <- T* +- f dL, moves the turning point with the
limit. The force held at a turning point falls as F_lim^k (:func:`md_held_span_rate`,
:data:`MD_UNLOADING_EXPONENTS`):

* k = 1, "limit" (chosen; the solvers' law): the force keeps its ratio to the limit, so p is held at
  0 with c fixed. It is Thornton's own turning-point update applied at the turning point, where
  force and turning point coincide, and needs no further rule: the force can never leave the limit.
* k = 2/3, "rescaled_displacement": the stored displacement shrinks with the contact radius (T ~ a^2
  for Hertz without adhesion, a ~ F_lim^(1/3)), as LAMMPS's ``mindlin_rescale`` does on unloading.
* k = 1/3, "displacement": the displacement is kept and the stiffness 8 G* a falls (LAMMPS
  ``mindlin``).
* k = 0, "force": the force is kept (the literal reading; LAMMPS ``mindlin/force``, the force
  history of Thornton et al. 2013).

For k < 1 the force falls more slowly than the limit and can reach it; from there it follows the
limit (c = 2). The energy stored in a stuck Hertz-Mindlin contact is of order T^2 / k_t, which
scales as a^(6k - 1) while the contact shrinks: for k < 1/6 it GROWS as the load falls, that is the
contact creates energy. Measured with the independent scipy integration
(:func:`microimpact.solvers.hysteretic_reference.hysteretic_reference`) on the Kharaz et al. (2001)
conditions (5 mm alumina on glass, 3.9 m/s, e_n = 1, f = 0.092): the "force" reading returns up to
22 % MORE tangential kinetic energy than came in (0.1 deg incidence; a gain at every angle up to
1 deg), the other three never gain. That rules out k = 0 on physical grounds; among the remaining
ones "limit" is the one that follows from the law itself rather than from a DEM code's bookkeeping.
The Kharaz comparison shows all four (:mod:`microimpact.analysis.kharaz`, variables
``*_md_<reading>``): all-angle RMS of the tangential restitution 0.027 (limit), 0.038
(rescaled_displacement), 0.051 (displacement), 0.064 (force); the readings differ only below about
10 deg, where the contact sticks before the load peaks. The choice was made before this comparison
and is not tuned to it.

Rolling resistance
------------------
Optional (``Contact.rolling_friction`` mu_r > 0, off by default): the constant directional torque
(Zhou et al. 1999; model A of Ai et al. 2011)

    M_r = -mu_r r |F_n| omega_r / |omega_r|,

with omega_r = (omega_t, omega_t') the rolling angular velocity relative to the fixed surface. A
sphere rolling without slip on the flat then decelerates at (5/7) mu_r |F_n| / m
(I = (2/5) m r^2: the friction force (5/7) M_r / r keeps the contact point at rest). Model A has
no viscous part, and as written its torque flips each time omega_r crosses zero (Ai et al. 2011
discuss the oscillation at rest). Here rest is treated as friction at rest is: at omega_r = 0 the
torque is set-valued, holding the sphere while the other torques stay within mu_r r |F_n| and
letting it go with the excess (:func:`microimpact.solvers.coupled._end_at_rolling_stop`).

Adhesion-aware friction ("pulloff")
-----------------------------------
The paper's Coulomb limit is f |F_n| with F_n the NET normal force (Hertz plus adhesion plus
damping). At the adhesive equilibrium F_n = 0, so a captured sphere slides and spins without
friction for ever. In an adhesive contact the friction is set by the contact area, which the
adhesion keeps finite; Thornton & Yin (1991) therefore take the Coulomb limit relative to the
pull-off force F_po,

    F_lim = f |F_n + 2 F_po|,

which equals f F_n-like sliding friction for a large compressive load and 2 f F_po at the adhesive
equilibrium. For the paper's ring force the pull-off force is the largest tension of the static
law F_H + F_A = sqrt(r) (K x^(3/2) - 2 pi f0 x^(1/2)), reached at x = X/3:

    F_po = (4 pi / 3) f0 sqrt(r X / 3)      (:func:`pulloff_force`).

References
----------
* Mindlin, R. D. (1949), Compliance of elastic bodies in contact, J. Appl. Mech. 16:259-268.
* Mindlin, R. D. and Deresiewicz, H. (1953), Elastic spheres in contact under varying oblique
  forces, J. Appl. Mech. 20:327-344.
* Johnson, K. L. (1985), Contact Mechanics, Cambridge University Press, Sec. 7.2.
* Maw, N., Barber, J. R. and Fawcett, J. N. (1976), The oblique impact of elastic spheres,
  Wear 38:101-114, doi:10.1016/0043-1648(76)90201-7.
* Walton, O. R. and Braun, R. L. (1986), Viscosity, granular-temperature, and stress
  calculations for shearing assemblies of inelastic, frictional disks, J. Rheol. 30:949-980.
* Thornton, C. (1991), Interparticle sliding in the presence of adhesion, J. Phys. D 24:1942-1946.
* Thornton, C. and Yin, K. K. (1991), Impact of elastic spheres with and without adhesion,
  Powder Technol. 65:153-166, doi:10.1016/0032-5910(91)80178-L.
* Di Renzo, A. and Di Maio, F. P. (2004), Comparison of contact-force models for the
  simulation of collisions in DEM-based granular flow codes, Chem. Eng. Sci. 59:525-541,
  doi:10.1016/j.ces.2003.09.037.
* Di Renzo, A. and Di Maio, F. P. (2005), An improved integral non-linear model for the contact
  of particles in distinct element simulations, Chem. Eng. Sci. 60:1303-1312,
  doi:10.1016/j.ces.2004.10.004.
* Zhou, Y. C., Wright, B. D., Yang, R. Y., Xu, B. H. and Yu, A. B. (1999), Rolling friction in
  the dynamic simulation of sandpile formation, Physica A 269:536-553,
  doi:10.1016/S0378-4371(99)00183-1.
* Ai, J., Chen, J.-F., Rotter, J. M. and Ooi, J. Y. (2011), Assessment of rolling resistance
  models in discrete element simulations, Powder Technol. 206:269-282,
  doi:10.1016/j.powtec.2010.09.030.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "shear_modulus_from_elastic",
    "effective_shear_modulus",
    "tangential_stiffness",
    "stiffness_ratio",
    "pulloff_force",
    "nondimensional_pulloff_force",
    "nondimensional_tangential_stiffness",
    "friction_load",
    "mindlin_force",
    "mindlin_stuck_displacement",
    "maw_incidence_parameter",
    "md_force_ratio",
    "md_branch_rate",
    "md_turning_span",
    "MD_UNLOADING_EXPONENTS",
    "md_held_span_rate",
    "rolling_deceleration",
]


# =============================================================================== SI forms
def shear_modulus_from_elastic(youngs_modulus, poisson):
    """Shear modulus of an isotropic material, G = E / (2 (1 + nu)). [Pa]

    Parameters
    ----------
    youngs_modulus : array_like
        Young's modulus E. [Pa]
    poisson : array_like
        Poisson ratio nu. [-]

    References
    ----------
    Timoshenko, S. P. and Goodier, J. N. (1970), Theory of Elasticity, 3rd ed., McGraw-Hill, Sec. 6.

    Examples
    --------
    >>> round(float(shear_modulus_from_elastic(70e9, 0.22)) / 1e9, 4)
    28.6885
    """
    return np.asarray(youngs_modulus, dtype=float) / (2.0 * (1.0 + np.asarray(poisson, dtype=float)))


def effective_shear_modulus(shear_sphere, poisson_sphere, shear_surface, poisson_surface):
    """Effective shear modulus G* = 1 / ((2 - nu_1)/G_1 + (2 - nu_2)/G_2). [Pa]

    Parameters
    ----------
    shear_sphere, shear_surface : float
        Shear moduli G_1, G_2. [Pa]
    poisson_sphere, poisson_surface : float
        Poisson ratios nu_1, nu_2. [-]

    Notes
    -----
    With it the Mindlin (1949) tangential stiffness of a contact of radius a is k_t = 8 G* a
    (Johnson 1985, Eq. 7.42 summed over both bodies; Di Renzo & Di Maio 2004, Table 1).
    
    References
    ----------
    Mindlin (1949)

    Examples
    --------
    Two equal glass bodies (E = 70 GPa, nu = 0.22): G* = G / (2 (2 - nu)):

    >>> g = float(shear_modulus_from_elastic(70e9, 0.22))
    >>> round(g / 1e9, 4), round(float(effective_shear_modulus(g, 0.22, g, 0.22)) / (g / (2 * (2 - 0.22))), 12)
    (28.6885, 1.0)
    """
    return 1.0 / ((2.0 - poisson_sphere) / shear_sphere + (2.0 - poisson_surface) / shear_surface)


def tangential_stiffness(shear_modulus, contact_radius):
    """Mindlin tangential stiffness of a contact without slip, k_t = 8 G* a. [N/m]

    Parameters
    ----------
    shear_modulus : float
        Effective shear modulus G*, :func:`effective_shear_modulus`. [Pa]
    contact_radius : array_like
        Contact radius a. [m]

    References
    ----------
    Mindlin (1949);
    Johnson, K. L. (1985), Contact Mechanics, Cambridge University Press, Sec. 7.2.

    Examples
    --------
    >>> float(tangential_stiffness(1e9, 1e-7))  # G* = 1 GPa, a = 0.1 um: 8 G* a
    800.0
    """
    return 8.0 * shear_modulus * np.asarray(contact_radius, dtype=float)


def stiffness_ratio(poisson):
    """k_t / k_n = 2 (1 - nu) / (2 - nu) of a Hertz-Mindlin contact of like materials. [-]

    k_n = dF_H/dx = 2 E* a is the normal contact stiffness (Johnson 1985, Sec. 7.2).

    Parameters
    ----------
    poisson : array_like
        Poisson ratio nu. [-]

    References
    ----------
    Johnson, K. L. (1985), Contact Mechanics, Cambridge University Press, Sec. 7.2.

    Examples
    --------
    >>> round(float(stiffness_ratio(0.3)), 6), float(stiffness_ratio(0.0))
    (0.823529, 1.0)
    """
    nu = np.asarray(poisson, dtype=float)
    return 2.0 * (1.0 - nu) / (2.0 - nu)


def maw_incidence_parameter(incidence_deg, friction, poisson, normal_restitution=1.0):
    """Non-dimensional incidence psi = tan(alpha) / (f (1 + e_n)) * 2 (1 - nu) / (2 - nu). [-]

    Maw, Barber & Fawcett (1976) and Thornton & Yin (1991) plot the rebound against this
    parameter (their Psi_1 for e_n = 1 is 2 psi): below about 1 the contact sticks over most of
    the impact and the tangential elasticity reverses the contact-point velocity; at large psi the
    sphere slides throughout and follows rigid-body Coulomb theory.

    Parameters
    ----------
    incidence_deg : array_like
        Incidence angle from the surface normal. [deg]
    friction : float
        Coulomb coefficient f. [-]
    poisson : float
        Poisson ratio nu (like materials). [-]
    normal_restitution : float
        e_n of the impact. [-]

    References
    ----------
    Maw, N., Barber, J. R. and Fawcett, J. N. (1976), The oblique impact of elastic spheres, Wear
    38:101-114, doi:10.1016/0043-1648(76)90201-5; Thornton, C. and Yin, K. K. (1991), Impact of
    elastic spheres with and without adhesion, Powder Technol. 65:153-166.

    Examples
    --------
    >>> round(float(maw_incidence_parameter(45.0, 0.5, 0.0)), 12)  # tan 45 / (0.5 x 2) x 1
    1.0
    """
    t = np.tan(np.radians(np.asarray(incidence_deg, dtype=float)))
    return t / (friction * (1.0 + normal_restitution)) * stiffness_ratio(poisson)


def pulloff_force(contact):
    """Pull-off force of the paper's ring adhesion, F_po = (4 pi / 3) f0 sqrt(r X / 3). [N]

    The largest tension of the static normal law F_H + F_A = sqrt(r) (K x^(3/2) - 2 pi f0 x^(1/2))
    (Eqs. (2), (5)), at x = X/3 with X = 2 pi f0 / K (Eq. (29)). Zero without adhesion.

    Parameters
    ----------
    contact : Contact

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (2) and (5) (the ring law whose largest tension it is)

    Examples
    --------
    The paper's microsphere (Table 1 row 2); the largest tension of the static law is at x = X/3:

    >>> from microimpact.model.law import adhesion_force, hertz_force
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> x = c.length_scale / 3.0
    >>> round(float(-(hertz_force(c.radius, c.stiffness, x) + adhesion_force(c.radius, c.adhesion_line_force, x))
    ...             / pulloff_force(c)), 12)
    1.0
    >>> f"{pulloff_force(c):.4e} N"
    '5.4024e-06 N'
    """
    x = contact.length_scale / 3.0
    return 4.0 * math.pi / 3.0 * contact.adhesion_line_force * math.sqrt(contact.radius * x)


def nondimensional_pulloff_force(a_h, a_a):
    """F_po in the solvers' force unit m L / T_c^2: the largest tension of a_h xi^(3/2) - a_a xi^(1/2). [-]

    Reached at xi = a_a / (3 a_h): F_po = (2 / (3 sqrt(3))) a_a^(3/2) / a_h^(1/2); 0 without
    adhesion. In the paper's scales (a_h = a_a = 1) it is 0.3849.

    Parameters
    ----------
    a_h, a_a : float
        Hertz and adhesion coefficients of :func:`microimpact.model.law.nondimensional_acceleration`. [-]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (2), (5) and (28)-(30)

    Examples
    --------
    >>> round(nondimensional_pulloff_force(1.0, 1.0), 4), nondimensional_pulloff_force(1.25, 0.0)
    (0.3849, 0.0)
    """
    if a_a <= 0.0:
        return 0.0
    return 2.0 / (3.0 * math.sqrt(3.0)) * a_a**1.5 / math.sqrt(a_h)


def nondimensional_tangential_stiffness(contact, scales) -> float:
    """kappa = 8 G* sqrt(r L) T_c^2 / m: the Mindlin stiffness in the solvers' units is kappa s. [-]

    With xi = x / L and s = sqrt(xi) the contact radius is a = sqrt(r L) s (Eq. (6)), so
    k_t T_c^2 / m = kappa s.

    Parameters
    ----------
    contact : Contact
        Must have ``shear_modulus`` (G*). [Pa]
    scales : microimpact.model.law.Scales
        L [m] and T_c [s] of the impact.

    References
    ----------
    Mindlin (1949)

    Cheng, Brach & Dunn (2002), Eqs. (29)-(30) (the units)

    Examples
    --------
    kappa s at s = 1 is k_t T_c^2 / m with k_t = 8 G* a at a = sqrt(r L):

    >>> import math
    >>> from microimpact.model.law import nondimensional_scales
    >>> from microimpact.model.parameters import TABLE1_ROW2
    >>> c = TABLE1_ROW2.with_(tangential_model="mindlin", shear_modulus=0.5e9)
    >>> sc = nondimensional_scales(c, 1.0)
    >>> k_t = float(tangential_stiffness(c.shear_modulus, math.sqrt(c.radius * sc.length)))
    >>> round(nondimensional_tangential_stiffness(c, sc) / (k_t * sc.time**2 / c.mass), 12)
    1.0
    """
    return 8.0 * contact.shear_modulus * math.sqrt(contact.radius * scales.length) * scales.time**2 / contact.mass


# =============================================================================== nondimensional forms
# Scalar arithmetic (numba compiles them into the coupled solver; see the module docstring).
def friction_load(normal_force, pulloff, adhesion_aware):
    """The load L with Coulomb limit F_lim = f L: |F_n| (the paper's) or |F_n + 2 F_po|. [N] or [-]

    Parameters
    ----------
    normal_force : float
        Net normal force F_n (positive pushes the sphere off the surface). [N] or nondimensional
    pulloff : float
        Pull-off force F_po in the same unit.
    adhesion_aware : bool
        True for the "pulloff" friction model (Thornton & Yin 1991), False for the paper's "net".

    References
    ----------
    Thornton, C. and Yin, K. K. (1991), Powder Technol. 65:153-166.

    Examples
    --------
    Under a net tension of 1 with pull-off force 0.5 the paper's load is 1, the adhesion-aware 0:

    >>> friction_load(-1.0, 0.5, False), friction_load(-1.0, 0.5, True)
    (1.0, 0.0)
    """
    if adhesion_aware:
        return abs(normal_force + 2.0 * pulloff)
    return abs(normal_force)


def mindlin_stuck_displacement(stiffness, limit):
    """delta* = 3 F_lim / (2 k_t): the displacement at which the whole contact slips. [m] or [-]

    Parameters
    ----------
    stiffness : float
        k_t = 8 G* a (:func:`tangential_stiffness`). [N/m] or nondimensional
    limit : float
        Coulomb limit F_lim. [N] or nondimensional

    References
    ----------
    Mindlin (1949), J. Appl. Mech. 16:259-268; Johnson (1985), Eqs. (7.40)-(7.42).

    Examples
    --------
    >>> mindlin_stuck_displacement(2.0, 1.0)
    0.75
    """
    if stiffness <= 0.0:
        return 0.0
    return 1.5 * limit / stiffness


def mindlin_force(delta_t, delta_tp, stuck_displacement, limit):
    """Tangential force (F_t, F_t') of Mindlin's micro-slip contact at the displacement delta. [N]

    F = -F_lim [1 - (1 - |delta| / delta*)^(3/2)] delta / |delta| for |delta| < delta*, and
    -F_lim delta / |delta| beyond (gross slip); see the module docstring.

    Parameters
    ----------
    delta_t, delta_tp : float
        Tangential displacement of the contact (integral of the slip velocity). [m] or nondimensional
    stuck_displacement : float
        delta* of :func:`mindlin_stuck_displacement`. [m] or nondimensional
    limit : float
        Coulomb limit F_lim >= 0. [N] or nondimensional

    References
    ----------
    Mindlin (1949), J. Appl. Mech. 16:259-268; Johnson (1985), Eqs. (7.40)-(7.42).

    Examples
    --------
    -k_t delta for a small displacement (k_t = 1.5 F_lim / delta* = 2), the limit at delta*:

    >>> round(mindlin_force(1e-6, 0.0, 0.75, 1.0)[0] / -2e-6, 6), mindlin_force(0.75, 0.0, 0.75, 1.0)
    (1.0, (-1.0, -0.0))
    """
    d = math.sqrt(delta_t * delta_t + delta_tp * delta_tp)
    if d == 0.0 or limit <= 0.0:
        return 0.0, 0.0
    q = d / stuck_displacement if stuck_displacement > 0.0 else math.inf
    magnitude = limit if q >= 1.0 else limit * (1.0 - (1.0 - q) ** 1.5)
    return -magnitude * delta_t / d, -magnitude * delta_tp / d


def md_force_ratio(branch_coordinate, branch_sign, branch_span):
    """T / F_lim = s [1 - c (1 - p)^(3/2)] of the hysteretic (Mindlin-Deresiewicz) contact. [-]

    T is the force resisting the displacement along the initial slip direction (the force on the
    sphere is -T e). See the module docstring.

    Parameters
    ----------
    branch_coordinate : float
        p, 0 at the turning point, 1 at gross slip (clipped to [0, 1]). [-]
    branch_sign : float
        s = +1 or -1, the direction of the current branch. [-]
    branch_span : float
        c = 1 + |T_r| / F_lim of the branch (1 virgin, 2 from gross slip). [-]

    References
    ----------
    Mindlin & Deresiewicz (1953); Thornton, C. (1991), Interparticle sliding in the presence of adhesion,
    J. Phys. D 24:1942-1946.

    Examples
    --------
    A branch from gross slip (c = 2) starts at the opposite limit and ends at the limit:

    >>> md_force_ratio(0.0, 1.0, 2.0), md_force_ratio(1.0, 1.0, 2.0)
    (-1.0, 1.0)
    """
    p = min(max(branch_coordinate, 0.0), 1.0)
    return branch_sign * (1.0 - branch_span * (1.0 - p) ** 1.5)


def md_branch_rate(branch_coordinate, branch_span, branch_slip, stiffness, limit, limit_rate):
    """dp/dt = s u k_t / (1.5 c F_lim) + (2/3) (dF_lim/dt / F_lim) (1 - p - 1/c). [1/s] or [-]

    The Thornton (1991) incremental law dT = k_t theta d delta + s dF_lim (1 - theta) in the branch
    coordinate p (module docstring), held in [0, 1]: 0 when p >= 1 and the rate is positive (gross
    slip) or p <= 0 and it is negative; 0 without a Coulomb limit.

    Parameters
    ----------
    branch_coordinate : float
        p. [-]
    branch_span : float
        c of the branch. [-]
    branch_slip : float
        s u, the slip velocity of the contact point along the branch direction. [m/s] or nondimensional
    stiffness : float
        k_t = 8 G* a, :func:`tangential_stiffness`. [N/m] or nondimensional
    limit : float
        F_lim = f L. [N] or nondimensional
    limit_rate : float
        dF_lim / dt. [N/s] or nondimensional

    References
    ----------
    Thornton (1991), J. Phys. D 24:1942-1946.

    Examples
    --------
    On the virgin curve (c = 1, p = 0) at constant limit the rate is u k_t / (1.5 F_lim); at gross
    slip (p = 1) it is held:

    >>> md_branch_rate(0.0, 1.0, 1.0, 3.0, 2.0, 0.0), md_branch_rate(1.0, 2.0, 1.0, 3.0, 2.0, 0.0)
    (1.0, 0.0)
    """
    if limit <= 0.0:
        return 0.0
    rate = (branch_slip * stiffness / (1.5 * branch_span)
            + (2.0 / 3.0) * limit_rate * (1.0 - branch_coordinate - 1.0 / branch_span)) / limit
    if (branch_coordinate >= 1.0 and rate > 0.0) or (branch_coordinate <= 0.0 and rate < 0.0):
        return 0.0
    return rate


def md_turning_span(force_ratio, new_sign):
    """c = 1 - s' T / F_lim of the branch that starts at a turning point with force ratio T / F_lim. [-]

    s' is the new branch direction; c = 2 from gross slip (T / F_lim = -s'), the
    Mindlin-Deresiewicz unloading curve. Kept >= 1e-9 (c = 0 only at the limit in the new direction).

    Parameters
    ----------
    force_ratio : float
        T / F_lim at the turning point, :func:`md_force_ratio`. [-]
    new_sign : float
        s' = +1 or -1. [-]

    References
    ----------
    Mindlin, R. D. and Deresiewicz, H. (1953), Elastic spheres in contact under varying oblique
    forces, J. Appl. Mech. 20:327-344

    Examples
    --------
    >>> md_turning_span(-1.0, 1.0), md_turning_span(0.0, 1.0)  # from gross slip; from zero force
    (2.0, 1.0)
    """
    return max(1.0 - new_sign * force_ratio, 1e-9)


#: Readings of a turning point held by a falling load (p = 0 while the Coulomb limit falls faster
#: than the elastic reloading): the force there falls as F_lim^k. "limit" (k = 1, the solvers'
#: law) keeps T / F_lim; the others are compared with it in :mod:`microimpact.analysis.kharaz`
#: (:func:`microimpact.solvers.hysteretic_reference.hysteretic_reference`). For a Hertz contact
#: without adhesion a ~ F_lim^(1/3), so k = 2/3 is the stored displacement scaled with the contact
#: radius (LAMMPS ``mindlin_rescale``), k = 1/3 the displacement kept (LAMMPS ``mindlin``:
#: T = 8 G* a delta) and k = 0 the force kept (LAMMPS ``mindlin/force``; Thornton's incremental law
#: read literally at theta = 1, where its load term s f dL (1 - theta) vanishes). [-]
MD_UNLOADING_EXPONENTS = {"limit": 1.0, "rescaled_displacement": 2.0 / 3.0, "displacement": 1.0 / 3.0,
                          "force": 0.0}


def md_held_span_rate(branch_span, limit, limit_rate, exponent):
    """dc/dt of a branch held at its turning point (p = 0) while the Coulomb limit falls. [1/s]

    At p = 0 the force is T = s F_lim (1 - c) (:func:`md_force_ratio`). If T falls as F_lim^k
    while the limit falls, then (1 - c) ~ F_lim^(k - 1) and

        dc/dt = (1 - k) (1 - c) (dF_lim/dt) / F_lim,

    which is 0 for k = 1 (the force keeps its ratio to the limit, :data:`MD_UNLOADING_EXPONENTS`
    "limit") and positive for k < 1 (the force falls more slowly than the limit, so the branch
    span c = 1 - s T / F_lim grows). At c = 2 the force has reached the opposite limit; there it
    can only follow the limit, and the rate is 0.

    Parameters
    ----------
    branch_span : float
        c of the held branch. [-]
    limit : float
        F_lim. [N] or nondimensional
    limit_rate : float
        dF_lim/dt, negative while the load falls. [N/s] or nondimensional
    exponent : float
        k, the power of F_lim the held force follows (:data:`MD_UNLOADING_EXPONENTS`). [-]

    References
    ----------
    Thornton, C. (1991), Interparticle sliding in the presence of adhesion, J. Phys. D
    24:1942-1946 (the incremental law this reads at theta = 1).
    Thornton, C., Cummins, S. J. and Cleary, P. W. (2013), An investigation of the comparative
    behaviour of alternative contact force models during inelastic collisions, Powder Technol.
    233:30-46, doi:10.1016/j.powtec.2012.08.012 (force-history and rescaled forms).

    Examples
    --------
    A force held constant (k = 0) at T = -F_lim / 2 (c = 1.5) while the limit falls by 10 % per
    second: (1 - c) ~ 1 / F_lim grows in size at 10 % per second, dc/dt = 0.05; the limit reading
    keeps c, and a branch at the opposite limit stays there:

    >>> round(md_held_span_rate(1.5, 1.0, -0.1, 0.0), 12), md_held_span_rate(1.5, 1.0, -0.1, 1.0)
    (0.05, 0.0)
    >>> md_held_span_rate(2.0, 1.0, -0.1, 0.0)
    0.0
    """
    if branch_span >= 2.0 or limit <= 0.0:
        return 0.0
    return (1.0 - exponent) * (1.0 - branch_span) * limit_rate / limit


def rolling_deceleration(rolling_friction, normal_force, mass):
    """(5/7) mu_r |F_n| / m: deceleration of a homogeneous sphere rolling without slip. [m/s^2]

    From m dv/dt = F_t, (2/5) m r^2 d omega/dt = r F_t - mu_r r |F_n| and v = r omega (module
    docstring, "Rolling resistance").

    Parameters
    ----------
    rolling_friction : float
        mu_r. [-]
    normal_force : array_like
        F_n. [N]
    mass : float
        m. [kg]

    References
    ----------
    Zhou, Y. C., Wright, B. D., Yang, R. Y., Xu, B. H. and Yu, A. B. (1999), Rolling friction in the
    dynamic simulation of sandpile formation, Physica A 269:536-553.

    Examples
    --------
    >>> float(rolling_deceleration(0.01, 7.0, 1e-12))  # (5/7) 0.01 x 7 N / 1e-12 kg
    50000000000.0
    """
    return 5.0 / 7.0 * rolling_friction * np.abs(np.asarray(normal_force, dtype=float)) / mass
