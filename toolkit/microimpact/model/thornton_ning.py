"""The Thornton & Ning (1998) elastic-plastic adhesive normal contact of a sphere on a flat.

A sphere of radius R (mass m) meets a flat; delta is the approach (penetration), a the contact
radius, E* = 3 K / 4 the contact modulus (Eq. (3) of Cheng, Brach & Dunn 2002), w the work of
adhesion and p_y the limiting contact pressure (yield pressure). Forces are positive when
repulsive. Every formula below is written once, here; the equation numbers (TN1)-(TN12) are this
module's, listed with their sources. Those the compiled law
(:mod:`microimpact.solvers.thornton_ning_law`) needs, (TN1) and (TN3)-(TN7), are numba kernels of
this module (:func:`curve_force`, :func:`plastic_force`, :func:`unloading_curve`, ...), which the
Python functions evaluate with NumPy.

Loading, elastic (JKR; Johnson, Kendall & Roberts 1971), with the radius of curvature R::

    (TN1)  delta(a; R) = a^2 / R - sqrt(2 pi w a / E*),   F(a; R) = 4 E* a^3 / (3 R) - sqrt(8 pi w E* a^3)

contact forms at delta = 0 (a = a_0 = 4^(2/3) a_c, a_c^3 = pi w R^2 / (8 E*)); without adhesion
(w = 0) this is Hertz's law F = K sqrt(R) delta^(3/2).

Yield. The JKR pressure is p(r) = p_1 sqrt(1 - r^2/a^2) - p_2 / sqrt(1 - r^2/a^2), with the Hertz
part p_1 = 2 E* a / (pi R) and the adhesive part p_2 = sqrt(2 w E* / (pi a)). Thornton & Ning
(1998) make the contact yield where its centre value p_1 - p_2 reaches p_y, and beyond yield let
each increment of contact area carry p_y, dF / d(pi a^2) = p_y, (TN3). Without adhesion the two
statements agree: the Hertz contact's increment dF / d(pi a^2) = p_1 is its centre pressure (which
makes (TN3) exact for a Hertz pressure cut off at p_y, Thornton 1997). With adhesion they do not:
the JKR contact's increment, from (TN1) at fixed R, is

    dF / d(pi a^2) = p_1 - (3/2) p_2   (< p_1 - p_2),

so at the centre-pressure yield (TN3) would make new area carry p_2 / 2 more than the elastic contact
gives it: the loading would stiffen as it yields, R_p (TN4) would come out below R (a flattening
that sharpens the contact) and W_p (TN9) below 0 just above yield (e > 1 in a rebound). Choice made
here: the contact yields where the two statements agree, where the JKR increment reaches p_y::

    (TN2)  dF / d(pi a^2) = 2 E* a / (pi R) - (3/2) sqrt(2 w E* / (pi a)) = p_y   ->   a_y, delta_y, F_y by (TN1)

(without adhesion a_y = pi R p_y / (2 E*), Thornton 1997, as the paper's criterion). The JKR
increment grows with a, so the plastic force F_y + pi p_y (a^2 - a_y^2) stays at or below the JKR
force F(a; R) of the same contact radius: R_p >= R at every delta_max >= delta_y (R_p = R at
yield, continuous), and at yield the line (TN3) is softer than the JKR curve. The price: the
centre pressure at yield is p_y + p_2 / 2, above the paper's limit, while this law is still
elastic. Alternatives not taken: the paper's criterion with R_p clamped to R (it keeps the
stiffening at yield, the unloading curve of radius R cannot pass through (delta_max, F_max) at
a_max, and W_p < 0 remains in some cases) and the JKR pressure cut off at p_y over the elastic
contact (it keeps the paper's criterion and R_p >= R but replaces the straight line (TN3), its
closed-form work and largest approach). PyGran's ``computeYieldRadius`` solves the paper's
centre-pressure equation (it cites it as Eq. (65) of the paper); ``docs/laws/thornton_ning.md``
gives the reasons at more length.

With this yield W_p >= 0 (checked on a grid over the whole parameter range, not proven) at every
largest approach above yield where the yield force F_y >= 0,
i.e. p_y >= (9/4)^(1/3) times the first-contact centre pressure (:data:`TENSILE_YIELD_LIMIT`;
the yield then lies at or beyond the JKR zero-load radius). Below that the contact yields under
tension, and W_p < 0 just above yield: the contact radius of (TN3) grows over a longer approach
than the unloading curve (TN6) needs for the same a, and under a tensile F_y that extra approach
gains work. The loading work W_load is negative there too, so no impact ends its loading there:
over impacts (W_load(delta_max) = (1/2) m V_i^2 >= 0) W_p >= 0 on the whole domain p_y > the
first-contact centre pressure (the tests scan it).

Loading, plastic (Thornton 1997; Thornton & Ning 1998): the pressure is held at p_y over the
growing contact, so each increment of contact area carries p_y::

    (TN3)  F = F_y + pi p_y (a^2 - a_y^2),   a^2 = a_y^2 + R (delta - delta_y)   (delta > delta_y)

a straight line of slope pi R p_y in delta. Choice made here: the contact grows as
a^2 - a_y^2 = R (delta - delta_y) (the geometric growth of Thornton 1997, which (TN3) needs to be
linear); PyGran instead keeps the JKR relation (TN1) for a on the plastic branch, whose force is
then not linear in delta. Without adhesion both are a^2 = R delta.

Unloading (from the largest approach delta_max > delta_y, with a_max and F_max of (TN3)): elastic
JKR with the plastically enlarged radius of curvature R_p, the curve shifted by the plastic
approach delta_p so that it passes through (delta_max, F_max) with the contact radius a_max::

    (TN4)  F_max = 4 E* a_max^3 / (3 R_p) - sqrt(8 pi w E* a_max^3)
           ->  R_p = 4 E* a_max^3 / (3 (F_max + sqrt(8 pi w E* a_max^3)))
    (TN5)  delta_max - delta_p = delta(a_max; R_p)
    (TN6)  F = F(a; R_p) with delta - delta_p = delta(a; R_p)

Without adhesion (TN4) is Thornton's (1997) R_p = 4 E* a_max^3 / (3 F_max). PyGran computes the
adhesive sum F_max + sqrt(8 pi w E* a_max^3) but then divides by F_max alone; with that R_p the
unloading curve would not pass through F_max, so (TN4) is used as written. Below yield
(delta_max <= delta_y) R_p = R and delta_p = 0: unloading retraces the loading curve.

Pull-off from the flattened contact (Thornton & Ning 1998): the contact breaks where
d delta / d a = 0 on (TN6), the displacement-controlled break of an impact (Johnson & Pollock
1994; the package's ``normal_model="jkr"``)::

    (TN7)  a_cp^3 = pi w R_p^2 / (8 E*),   delta_break = delta_p - (3/4) (pi^2 w^2 R_p / E*^2)^(1/3),
           F_break = -(5/9) F_cp,   F_cp = (3/2) pi w R_p   (the pull-off force of the flattened contact)

Energies. U(a; R) = 8 E* a^5 / (15 R^2) - (4/3) sqrt(2 pi w E*) a^(7/2) / R + pi w a^2 is the
potential of (TN1), dU = F d delta along the curve (the package's JKR potential in SI form)::

    (TN8)  W_load(delta) = U(a(delta); R) - U(a_0; R)            (delta <= delta_y)
                         = W_load(delta_y) + F_y (delta - delta_y) + pi R p_y (delta - delta_y)^2 / 2
    (TN9)  plastic dissipation  W_p = W_load(delta_max) - [U(a_max; R_p) - U(a_0p; R_p)],  a_0p = 4^(2/3) a_cp
    (TN10) adhesive hysteresis  H = U(a_cp; R_p) - U(a_0p; R_p) = (2/5 + (12/5) 4^(1/3)) pi w a_cp^2

so that an undamped impact at V_i leaves with (1/2) m V_r^2 = (1/2) m V_i^2 - W_p - H, or is
captured when that is <= 0 (it then stays on the unloading curve (TN6)). W_p is the work absorbed
between the loading and the unloading curves over delta >= delta_p; H is the work of the
adhesive neck between delta_p and the break (the JKR hysteresis of a contact of radius R_p).

Yield velocity (Thornton 1997; Thornton & Ning 1998, for a sphere on a flat with m = 4/3 pi R^3
rho): the impact speed whose Hertz (non-adhesive) loading just reaches p_y,

    (TN11) (1/2) m V_y^2 = (8/15) E* sqrt(R) delta_y^(5/2),  delta_y = pi^2 R p_y^2 / (4 E*^2)
           ->  V_y = (pi^2 / sqrt(40)) sqrt(p_y^5 / (E*^4 rho)) = 1.5605 sqrt(p_y^5 / (E*^4 rho))

(the paper's 1.56). V_y is defined without adhesion; with adhesion the loading yields at a
slightly different speed (:func:`adhesive_yield_velocity`).

Restitution without adhesion (Thornton 1997, J. Appl. Mech. 64:383, his closed form as PyGran's
elasto-plastic example writes it), for V_i >= V_y::

    (TN12) e = sqrt(6 sqrt(3) / 5) sqrt(1 - (V_y/V_i)^2 / 6)
               [ (V_y/V_i) / ((V_y/V_i) + 2 sqrt(6/5 - (V_y/V_i)^2 / 5)) ]^(1/4)

and e = 1 for V_i < V_y. (TN12) is a published result; :func:`restitution_coefficient` computes
e from the energies (TN8)-(TN10) instead, and the tests compare the two.

Rate effects (the paper's damping, Eqs. (14)-(15), (27)) are not part of this law: it is the
rate-independent Thornton & Ning contact.

References
----------
Thornton, C. (1997), Coefficient of restitution for collinear collisions of elastic-perfectly
plastic spheres, J. Appl. Mech. 64:383-386, doi:10.1115/1.2787319.
Thornton, C. and Ning, Z. (1998), A theoretical model for the stick/bounce behaviour of adhesive,
elastic-plastic spheres, Powder Technol. 99:154-162, doi:10.1016/S0032-5910(98)00099-0.
Johnson, K. L., Kendall, K. and Roberts, A. D. (1971), Proc. R. Soc. Lond. A 324:301-313,
doi:10.1098/rspa.1971.0141.
Johnson, K. L. and Pollock, H. M. (1994), J. Adhesion Sci. Technol. 8:1323-1332,
doi:10.1163/156856194X00627.
Abi-Mansour, A., PyGran (DEM toolkit), ``simulation.models.ThorntonNing`` and
``tests/scripts/Contact-Models/elasto-plastic``, github.com/Andrew-AbiMansour/PyGran.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from microimpact._numba import njit
from microimpact.model.adhesion_models import jkr_q_from_approach

__all__ = [
    "YIELD_VELOCITY_COEFFICIENT",
    "TENSILE_YIELD_LIMIT",
    "PlasticContact",
    "YieldPoint",
    "UnloadingState",
    "ImpactEnergies",
    "RestitutionSample",
    "jkr_curve_approach",
    "jkr_curve_force",
    "jkr_curve_potential",
    "jkr_curve_contact_radius",
    "first_contact_pressure",
    "yield_point",
    "loading_force",
    "loading_work",
    "loading_contact_radius",
    "unloading_state",
    "unloading_force",
    "largest_approach",
    "impact_energies",
    "restitution_coefficient",
    "capture_velocity",
    "yield_velocity",
    "yield_pressure",
    "adhesive_yield_velocity",
    "thornton_restitution",
    "synthetic_restitution",
]

#: V_y / sqrt(p_y^5 / (E*^4 rho)) = pi^2 / sqrt(40), (TN11); Thornton & Ning (1998) print 1.56. [-]
YIELD_VELOCITY_COEFFICIENT = math.pi**2 / math.sqrt(40.0)
#: a_0 / a_c = 4^(2/3): JKR contact radius at delta = 0 on the stable branch, in units of a_c. [-]
_A0_OVER_AC = 4.0 ** (2.0 / 3.0)
#: the factor of the adhesive pressure p_2 in the yield criterion (TN2): 3/2, the JKR increment
#: dF / d(pi a^2) = p_1 - (3/2) p_2 (the paper's centre pressure would be 1). [-]
_YIELD_ADHESIVE_FACTOR = 1.5
#: p_y / (first-contact centre pressure) at which the yield force F_y of (TN2) is 0: (9/4)^(1/3),
#: the JKR increment at the zero-load radius a^3 = 9 pi w R^2 / (2 E*). At and above it W_p >= 0
#: (module docstring, "Yield"). [-]
TENSILE_YIELD_LIMIT = (9.0 / 4.0) ** (1.0 / 3.0)


@dataclass(frozen=True)
class PlasticContact:
    """Parameters of the Thornton & Ning contact of a sphere on a flat. SI units.

    Attributes
    ----------
    radius : float
        Sphere radius R. [m]
    mass : float
        Sphere mass m. [kg]
    stiffness : float
        K = (4/3) E*, Eq. (3) of Cheng, Brach & Dunn (2002). [Pa]
    work_of_adhesion : float
        w (0: no adhesion). [J/m^2]
    yield_pressure : float
        Limiting contact pressure p_y. [Pa]

    Examples
    --------
    From a package ``Contact`` (its w follows from f0 by Eq. (7)):

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> pc = PlasticContact.from_contact(c, yield_pressure=2e8)
    >>> f"{pc.e_star:.4e} Pa", f"{pc.work_of_adhesion:.4f} J/m^2"
    ('1.3320e+09 Pa', '0.2158 J/m^2')
    """

    radius: float
    mass: float
    stiffness: float
    work_of_adhesion: float
    yield_pressure: float

    def __post_init__(self) -> None:
        for name in ("radius", "mass", "stiffness", "yield_pressure"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
                raise ValueError(f"PlasticContact.{name} must be a finite number > 0, got {v!r}")
        w = self.work_of_adhesion
        if not (isinstance(w, (int, float)) and math.isfinite(w) and w >= 0.0):
            raise ValueError(f"PlasticContact.work_of_adhesion must be a finite number >= 0, got {w!r}")

    @classmethod
    def from_contact(cls, contact, yield_pressure: float, work_of_adhesion: float | None = None) -> "PlasticContact":
        """From a :class:`~microimpact.model.contact.Contact` (R, m, K and, unless given, its w)."""
        w = contact.work_of_adhesion if work_of_adhesion is None else work_of_adhesion
        return cls(contact.radius, contact.mass, contact.stiffness, float(w), float(yield_pressure))

    @property
    def e_star(self) -> float:
        """E* = 3 K / 4. [Pa]"""
        return 0.75 * self.stiffness

    @property
    def density(self) -> float:
        """rho = m / (4/3 pi R^3). [kg/m^3]"""
        return self.mass / (4.0 / 3.0 * math.pi * self.radius**3)


@dataclass(frozen=True)
class YieldPoint:
    """Where the loading curve yields, (TN2): contact radius [m], approach [m], force [N]."""

    contact_radius: float
    approach: float
    force: float


@dataclass(frozen=True)
class UnloadingState:
    """The state a plastic law carries from its largest approach, (TN4)-(TN7).

    Attributes
    ----------
    max_approach, max_contact_radius, max_force : float
        delta_max [m], a_max [m], F_max [N] at the turning point.
    plastic_radius : float
        R_p, the radius of curvature of the unloading curve (R below yield). [m]
    plastic_approach : float
        delta_p, the shift of the unloading curve (0 below yield). [m]
    break_approach, break_contact_radius, break_force : float
        delta_break [m], a_cp [m], F_break [N] where the contact is lost (TN7).
    yielded : bool
        True if delta_max > delta_y.
    """

    max_approach: float
    max_contact_radius: float
    max_force: float
    plastic_radius: float
    plastic_approach: float
    break_approach: float
    break_contact_radius: float
    break_force: float
    yielded: bool

    @property
    def pull_off_force(self) -> float:
        """Pull-off force of the flattened contact F_cp = (3/2) pi w R_p, from F_break = -(5/9) F_cp (TN7). [N]"""
        return -1.8 * self.break_force  # F_break = -(5/9) F_cp, (TN7)


@dataclass(frozen=True)
class ImpactEnergies:
    """Energy account of one undamped impact, (TN8)-(TN10). [J]

    ``incident`` = (1/2) m V_i^2; ``rebound`` = incident - plastic - hysteresis (negative: captured).
    """

    incident: float
    plastic: float
    hysteresis: float
    rebound: float

    @property
    def captured(self) -> bool:
        """True if the rebound energy is <= 0."""
        return self.rebound <= 0.0


@dataclass(frozen=True)
class RestitutionSample:
    """SYNTHETIC e_n(v) data made from the Thornton & Ning law (:func:`synthetic_restitution`).

    Arrays of one length: radius [m], normal_speed [m/s], e_n [-] (with noise), e_n_true [-]
    (the law), e_n_uncertainty [-] (the stated noise sd); ``parameters`` the generating values.
    """

    radius: np.ndarray
    normal_speed: np.ndarray
    e_n: np.ndarray
    e_n_true: np.ndarray
    e_n_uncertainty: np.ndarray
    parameters: dict


# =============================================================================== the formulas, compiled
# Each formula the compiled law (solvers/thornton_ning_law.py) needs is written once, here, as a
# numba kernel of scalars (in np.sqrt and np.maximum, so that NumPy arrays pass too). The Python
# functions below run the same source with NumPy (``kernel.py_func``), not the compiled kernel: an
# array call then compiles nothing, and each side rounds powers its own way (numba's x**3 is x*x*x,
# NumPy's array power a SIMD pow; they differ in the last bit for about a quarter of random x), so
# a power that enters a formula is passed in by the caller (a^3) and neither side's numbers move.
@njit(cache=True)
def critical_radius(radius, e_star, work_of_adhesion):
    """a_c = (pi w R^2 / (8 E*))^(1/3), where d delta / d a = 0 on (TN1) (a_cp of (TN7) at R = R_p). [m]

    Parameters: radius of curvature R [m], E* [Pa], w [J/m^2].
    """
    return (math.pi * work_of_adhesion * radius * radius / (8.0 * e_star)) ** (1.0 / 3.0)


@njit(cache=True)
def curve_approach(contact_radius, radius, e_star, work_of_adhesion):
    """delta(a; R) = a^2 / R - sqrt(2 pi w a / E*), (TN1), on the curve of radius of curvature R. [m]"""
    a = contact_radius
    return a * a / radius - np.sqrt(2.0 * math.pi * work_of_adhesion * a / e_star)


@njit(cache=True)
def curve_force_of_cube(contact_radius_cubed, radius, e_star, work_of_adhesion):
    """F(a; R) = 4 E* a^3 / (3 R) - sqrt(8 pi w E* a^3), (TN1), of a^3 [m^3]; positive = repulsive. [N]"""
    a3 = contact_radius_cubed
    return 4.0 * e_star * a3 / (3.0 * radius) - np.sqrt(8.0 * math.pi * work_of_adhesion * e_star * a3)


@njit(cache=True)
def curve_approach_ratio(approach, radius, critical_radius_):
    """delta / L_J = delta R / a_c^2 on the JKR curve of radius of curvature R, a_c [m]: q^4 - 4 q. [-]"""
    return approach * radius / (critical_radius_ * critical_radius_)


@njit(cache=True)
def hertz_contact_radius(approach, radius):
    """a = sqrt(R max(delta, 0)), (TN1) without adhesion (Hertz). [m]"""
    return np.sqrt(radius * np.maximum(approach, 0.0))


@njit(cache=True)
def curve_q(approach_ratio):
    """q = sqrt(a / a_c) >= 1 with q^4 - 4 q = delta / L_J on the stable branch of (TN1); 1 at and
    beyond the break (ratio <= -3). [-]

    The scalar form, for compiled code, of :func:`microimpact.model.adhesion_models.jkr_q_from_approach`
    (the same Newton iteration from above the root; that one is vectorised with NumPy and cannot be
    called from a numba kernel). Scalar ``approach_ratio`` [-] only.

    Examples
    --------
    >>> q = curve_q(10.0)
    >>> round(q, 8), round(q**4 - 4 * q, 12), curve_q(-3.5)
    (2.06744159, 10.0, 1.0)
    """
    if approach_ratio <= -3.0:
        return 1.0
    q = math.sqrt(math.sqrt(max(approach_ratio, 0.0) + 4.0)) + 1.0  # q^4 - 4q > ratio here
    for _ in range(80):
        step = (q**4 - 4.0 * q - approach_ratio) / (4.0 * q**3 - 4.0)
        q = max(q - step, 1.0)
        if abs(step) <= 4e-16 * q:
            break
    return q


@njit(cache=True)
def curve_force(approach, radius, e_star, work_of_adhesion):
    """F on the JKR curve (TN1) of radius of curvature R at the approach delta [m] from its origin. [N]

    Scalars only (the compiled law's loading (TN1) and unloading (TN6), delta - delta_p there):
    a = a_c q^2 by :func:`curve_q` (a^3 = a_c^3 q^6), a = sqrt(R delta) without adhesion; beyond the
    break a = a_c. The Python functions' equivalent is :func:`jkr_curve_force` of
    :func:`jkr_curve_contact_radius`.

    Examples
    --------
    It is that equivalent (to rounding), and Hertz's K sqrt(R) delta^(3/2) without adhesion:

    >>> r, es, w = 1e-6, 1e9, 0.1
    >>> a = float(jkr_curve_contact_radius(2e-9, r, es, w))
    >>> round(float(curve_force(2e-9, r, es, w)) / float(jkr_curve_force(a, r, es, w)), 12)
    1.0
    >>> round(float(curve_force(1e-8, r, es, 0.0)) / (4e9 / 3 * 1e-3 * 1e-12), 12)
    1.0
    """
    if work_of_adhesion == 0.0:
        a = hertz_contact_radius(approach, radius)
        return curve_force_of_cube(a**3, radius, e_star, work_of_adhesion)
    a_c = critical_radius(radius, e_star, work_of_adhesion)
    q = curve_q(curve_approach_ratio(approach, radius, a_c))
    return curve_force_of_cube(a_c**3 * q**6, radius, e_star, work_of_adhesion)


@njit(cache=True)
def plastic_force(approach, radius, yield_pressure, yield_approach, yield_force):
    """F = F_y + pi R p_y (delta - delta_y), the plastic loading line (TN3). [N]

    Parameters: delta [m], R [m], p_y [Pa], delta_y [m], F_y [N] (:func:`yield_point`).
    """
    return yield_force + math.pi * radius * yield_pressure * (approach - yield_approach)


@njit(cache=True)
def plastic_contact_radius(approach, radius, yield_radius, yield_approach):
    """a = sqrt(a_y^2 + R max(delta - delta_y, 0)), the contact radius on the plastic line (TN3). [m]"""
    return np.sqrt(yield_radius * yield_radius + radius * np.maximum(approach - yield_approach, 0.0))


@njit(cache=True)
def plastic_radius(max_contact_radius_cubed, max_force, e_star, work_of_adhesion):
    """R_p = 4 E* a_max^3 / (3 (F_max + sqrt(8 pi w E* a_max^3))), (TN4), of a_max^3 [m^3], F_max [N]. [m]"""
    a3 = max_contact_radius_cubed
    return 4.0 * e_star * a3 / (3.0 * (max_force + np.sqrt(8.0 * math.pi * work_of_adhesion * e_star * a3)))


@njit(cache=True)
def unloading_curve(max_approach, max_contact_radius, max_contact_radius_cubed, max_force, yielded, radius, e_star,
                    work_of_adhesion):
    """(R_p, delta_p, a_cp, delta_break) of the unloading curve from delta_max, (TN4), (TN5), (TN7).

    Parameters: delta_max [m], a_max [m], a_max^3 [m^3] and F_max [N] on the loading curve, whether
    it yielded (delta_max > delta_y; else R_p = R, delta_p = 0), R [m], E* [Pa], w [J/m^2]. Returns
    [m] each; a_cp = 0 and delta_break = delta_p without adhesion.

    Examples
    --------
    Below yield the curve is the loading curve, broken at -(3/4) (pi^2 w^2 R / E*^2)^(1/3), (TN7):

    >>> r_p, d_p, a_cp, d_break = unloading_curve(1e-8, 0.0, 0.0, 0.0, False, 1e-6, 1e9, 0.1)
    >>> r_p, d_p, round(float(d_break) / (-0.75 * (math.pi**2 * 0.01 * 1e-6 / 1e18) ** (1 / 3)), 12)
    (1e-06, 0.0, 1.0)
    """
    if yielded:
        r_p = plastic_radius(max_contact_radius_cubed, max_force, e_star, work_of_adhesion)
        d_p = max_approach - curve_approach(max_contact_radius, r_p, e_star, work_of_adhesion)  # (TN5)
    else:
        r_p, d_p = radius, 0.0
    if work_of_adhesion > 0.0:
        a_cp = critical_radius(r_p, e_star, work_of_adhesion)
        d_break = d_p + curve_approach(a_cp, r_p, e_star, work_of_adhesion)  # (TN7)
    else:
        a_cp, d_break = 0.0, d_p
    return r_p, d_p, a_cp, d_break


# =============================================================================== the JKR curve (TN1), (TN8)
def jkr_curve_approach(contact_radius, radius, e_star, work_of_adhesion):
    """delta(a; R) = a^2 / R - sqrt(2 pi w a / E*), (TN1). [m]

    Parameters: contact radius a [m], radius of curvature R [m], E* [Pa], w [J/m^2].

    References
    ----------
    Johnson, Kendall & Roberts (1971), Proc. R. Soc. Lond. A 324:301-313.

    Examples
    --------
    Without adhesion, Hertz's a^2 = R delta:

    >>> round(float(jkr_curve_approach(1e-7, 1e-6, 1e9, 0.0)) / 1e-8, 12)
    1.0
    """
    return curve_approach.py_func(np.asarray(contact_radius, dtype=float), radius, e_star, work_of_adhesion)


def jkr_curve_force(contact_radius, radius, e_star, work_of_adhesion):
    """F(a; R) = 4 E* a^3 / (3 R) - sqrt(8 pi w E* a^3), (TN1); positive = repulsive. [N]

    References
    ----------
    Johnson, Kendall & Roberts (1971), Proc. R. Soc. Lond. A 324:301-313.

    Examples
    --------
    Without adhesion, Hertz: F = (4/3) E* a^3 / R:

    >>> round(float(jkr_curve_force(1e-7, 1e-6, 1e9, 0.0)) / (4e9 * 1e-21 / 3e-6), 12)
    1.0
    """
    a = np.asarray(contact_radius, dtype=float)
    return curve_force_of_cube.py_func(a**3, radius, e_star, work_of_adhesion)


def jkr_curve_potential(contact_radius, radius, e_star, work_of_adhesion):
    """U(a; R) = 8 E* a^5 / (15 R^2) - (4/3) sqrt(2 pi w E*) a^(7/2) / R + pi w a^2, dU = F d delta. [J]

    The integral of (TN1) along the curve (module docstring); in the units pi w a_c^2 it is the
    package's JKR potential q^10 / 15 - 2 q^7 / 3 + q^4 (a = a_c q^2).

    References
    ----------
    Johnson, K. L. and Pollock, H. M. (1994), J. Adhesion Sci. Technol. 8:1323-1332.

    Examples
    --------
    The JKR hysteresis U(a_c) - U(a_0) = 4.2098 pi w a_c^2:

    >>> import math
    >>> r, es, w = 1e-6, 1e9, 0.1
    >>> a_c = (math.pi * w * r * r / (8 * es)) ** (1 / 3)
    >>> u = lambda a: float(jkr_curve_potential(a, r, es, w))
    >>> round((u(a_c) - u(4 ** (2 / 3) * a_c)) / (math.pi * w * a_c**2), 4)
    4.2098
    """
    a = np.asarray(contact_radius, dtype=float)
    return (8.0 * e_star * a**5 / (15.0 * radius * radius)
            - 4.0 / 3.0 * math.sqrt(2.0 * math.pi * work_of_adhesion * e_star) * a**3.5 / radius
            + math.pi * work_of_adhesion * a * a)


_critical_radius = critical_radius.py_func  # a_c of (TN1) for the Python functions, scalars or arrays


def jkr_curve_contact_radius(approach, radius, e_star, work_of_adhesion):
    """a(delta; R) on the stable branch of (TN1) (a >= a_c), delta >= -(3/4)(pi^2 w^2 R / E*^2)^(1/3). [m]

    Below the break approach it returns a_c (an integrator may probe there before its event);
    without adhesion a = sqrt(R max(delta, 0)).

    References
    ----------
    Johnson, Kendall & Roberts (1971), Proc. R. Soc. Lond. A 324:301-313.

    Examples
    --------
    >>> r, es, w = 1e-6, 1e9, 0.1
    >>> a = float(jkr_curve_contact_radius(2e-9, r, es, w))
    >>> round(float(jkr_curve_approach(a, r, es, w)) / 2e-9, 12)
    1.0
    """
    d = np.asarray(approach, dtype=float)
    if work_of_adhesion == 0.0:
        return hertz_contact_radius.py_func(d, radius)
    a_c = _critical_radius(radius, e_star, work_of_adhesion)
    ratio = curve_approach_ratio.py_func(d, radius, a_c)  # the break (fold) is at -3, where q = 1
    inside = ratio > -3.0
    return a_c * np.where(inside, jkr_q_from_approach(np.where(inside, ratio, 0.0)), 1.0) ** 2


# =============================================================================== yield, loading (TN2), (TN3), (TN8)
def first_contact_pressure(radius, e_star, work_of_adhesion):
    """The JKR centre pressure as the contact forms (delta = 0, a = a_0): E* a_0 / (pi R). [Pa]

    A yield pressure at or below it would yield the contact as it forms by the paper's
    centre-pressure criterion, which (TN2)-(TN3) do not describe (:func:`yield_point` refuses it);
    it is 0 without adhesion. Parameters: R [m], E* [Pa], w [J/m^2].

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    It is the centre pressure 2 E* a / (pi R) - sqrt(2 w E* / (pi a)) at a = a_0:

    >>> import math
    >>> r, es, w = 1e-6, 1e9, 0.1
    >>> a0 = 4 ** (2 / 3) * (math.pi * w * r * r / (8 * es)) ** (1 / 3)
    >>> centre = 2 * es * a0 / (math.pi * r) - math.sqrt(2 * w * es / (math.pi * a0))
    >>> round(first_contact_pressure(r, es, w) / centre, 12)
    1.0
    """
    return e_star * _first_contact_radius(radius, e_star, work_of_adhesion) / (math.pi * radius)


@functools.lru_cache(maxsize=1024)  # a pure function of a frozen record, asked for by every branch
def yield_point(pc: PlasticContact) -> YieldPoint:
    """Contact radius, approach and force at which the loading yields, (TN2).

    The JKR increment dF / d(pi a^2) = 2 E* a / (pi R) - (3/2) sqrt(2 w E* / (pi a)) reaches p_y
    (not the paper's centre pressure, the module docstring says why): solves
    (2 E* / (pi R)) s^3 - p_y s - (3/2) sqrt(2 w E* / pi) = 0 for s = sqrt(a_y) (one positive root,
    the increment grows with a) by Newton's method from above; a_y = pi R p_y / (2 E*) without
    adhesion.

    Raises
    ------
    ValueError
        If p_y is at or below the centre pressure at first contact, E* a_0 / (pi R): by the paper's
        criterion the contact would yield as it forms, which (TN2)-(TN3) do not describe. The law
        keeps the paper's domain (at first contact the JKR increment of (TN2) is half that pressure).

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162; Thornton (1997), J. Appl. Mech. 64:383.

    Examples
    --------
    Without adhesion, delta_y = pi^2 R p_y^2 / (4 E*^2) and F_y = pi^3 R^2 p_y^3 / (6 E*^2):

    >>> import math
    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> y = yield_point(pc)
    >>> round(y.approach / (math.pi**2 * 1e-6 * 1e16 / 4e18), 12), round(y.force / (math.pi**3 * 1e-12 * 1e24 / 6e18), 12)
    (1.0, 1.0)

    With adhesion the elastic curve's force per contact area, dF / d(pi a^2), is p_y at a_y (a
    central difference, to 1e-6):

    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.05, 1e8)
    >>> a, h = yield_point(pc).contact_radius, 1e-6 * yield_point(pc).contact_radius
    >>> f = lambda a: float(jkr_curve_force(a, pc.radius, pc.e_star, pc.work_of_adhesion))
    >>> round((f(a + h) - f(a - h)) / (math.pi * ((a + h)**2 - (a - h)**2)) / pc.yield_pressure, 6)
    1.0
    """
    r, es, w, py = pc.radius, pc.e_star, pc.work_of_adhesion, pc.yield_pressure
    if w == 0.0:
        a_y = math.pi * r * py / (2.0 * es)
    else:
        p_first = first_contact_pressure(r, es, w)
        if py <= p_first:
            raise ValueError(f"yield_pressure={py!r} Pa is below the JKR centre pressure at first contact "
                             f"({p_first:.4g} Pa): the contact would yield as it forms")
        # (TN2): the JKR increment dF / d(pi a^2) = p_1 - (3/2) p_2, not the centre pressure p_1 - p_2
        # (module docstring, "Yield")
        c3, c1, c0 = 2.0 * es / (math.pi * r), py, _YIELD_ADHESIVE_FACTOR * math.sqrt(2.0 * w * es / math.pi)
        s = math.sqrt(c1 / c3) + (c0 / c3) ** (1.0 / 3.0)  # above the root (convex, increasing there)
        for _ in range(100):
            step = (c3 * s**3 - c1 * s - c0) / (3.0 * c3 * s * s - c1)
            s -= step
            if abs(step) <= 1e-16 * s:
                break
        a_y = s * s
    return YieldPoint(a_y, float(jkr_curve_approach(a_y, r, es, w)), float(jkr_curve_force(a_y, r, es, w)))


def loading_contact_radius(pc: PlasticContact, approach):
    """a on the loading curve: (TN1) below yield, a^2 = a_y^2 + R (delta - delta_y) above, (TN3). [m]

    Examples
    --------
    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> y = yield_point(pc)
    >>> round(float(loading_contact_radius(pc, 2 * y.approach)) ** 2 / (1e-6 * 2 * y.approach), 12)
    1.0
    """
    y = yield_point(pc)
    d = np.asarray(approach, dtype=float)
    elastic = jkr_curve_contact_radius(np.minimum(d, y.approach), pc.radius, pc.e_star, pc.work_of_adhesion)
    plastic = plastic_contact_radius.py_func(d, pc.radius, y.contact_radius, y.approach)
    return np.where(d > y.approach, plastic, elastic)


def loading_force(pc: PlasticContact, approach):
    """F on the loading curve: JKR (TN1) up to delta_y, F_y + pi R p_y (delta - delta_y) above, (TN3). [N]

    Valid for delta >= 0 (the contact forms at delta = 0).

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    The plastic branch is straight, of slope pi R p_y:

    >>> import math
    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.05, 1e8)
    >>> d = yield_point(pc).approach
    >>> f = loading_force(pc, [2 * d, 3 * d])
    >>> round(float(f[1] - f[0]) / (math.pi * 1e-6 * 1e8 * d), 12)
    1.0
    """
    y = yield_point(pc)
    d = np.asarray(approach, dtype=float)
    a = jkr_curve_contact_radius(np.minimum(d, y.approach), pc.radius, pc.e_star, pc.work_of_adhesion)
    elastic = jkr_curve_force(a, pc.radius, pc.e_star, pc.work_of_adhesion)
    plastic = plastic_force.py_func(d, pc.radius, pc.yield_pressure, y.approach, y.force)
    return np.where(d > y.approach, plastic, elastic)


def _first_contact_radius(radius, e_star, work_of_adhesion) -> float:
    """a_0, the contact radius of (TN1) at delta = 0 (0 without adhesion). [m]"""
    return _A0_OVER_AC * _critical_radius(radius, e_star, work_of_adhesion) if work_of_adhesion > 0.0 else 0.0


def loading_work(pc: PlasticContact, approach):
    """W_load(delta) = integral_0^delta F d delta along the loading curve, (TN8). [J]

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    Without adhesion the work to yield is (2/5) F_y delta_y:

    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> y = yield_point(pc)
    >>> round(float(loading_work(pc, y.approach)) / (0.4 * y.force * y.approach), 12)
    1.0
    """
    r, es, w = pc.radius, pc.e_star, pc.work_of_adhesion
    y = yield_point(pc)
    d = np.asarray(approach, dtype=float)
    u0 = jkr_curve_potential(_first_contact_radius(r, es, w), r, es, w)
    a = jkr_curve_contact_radius(np.minimum(d, y.approach), r, es, w)
    elastic = jkr_curve_potential(a, r, es, w) - u0
    s = np.maximum(d - y.approach, 0.0)
    w_y = jkr_curve_potential(y.contact_radius, r, es, w) - u0
    plastic = w_y + y.force * s + 0.5 * math.pi * r * pc.yield_pressure * s * s
    return np.where(d > y.approach, plastic, elastic)


def largest_approach(pc: PlasticContact, normal_speed):
    """delta_max of an undamped impact at V_i: W_load(delta_max) = (1/2) m V_i^2, (TN8). [m]

    Closed form on the plastic branch (a quadratic); Newton's method on the JKR branch, for all
    speeds at once. A float for a scalar ``normal_speed`` [m/s], else an array of its shape.

    Examples
    --------
    Without adhesion and below yield, the Hertz largest approach (5 m V^2 / (4 K sqrt(R)))^(2/5):

    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e9)
    >>> d = largest_approach(pc, 0.1)
    >>> round(d / (1.25 * 1e-14 * 0.01 / (4e9 / 3 * 1e-3)) ** 0.4, 12)
    1.0
    """
    v = np.asarray(normal_speed, dtype=float)
    ke = 0.5 * pc.mass * v * v
    y = yield_point(pc)
    w_y = float(loading_work(pc, y.approach))
    # plastic branch: (1/2) k s^2 + F_y s = ke - w_y, k = pi R p_y (the root written without cancellation)
    k = math.pi * pc.radius * pc.yield_pressure
    rest = np.maximum(ke - w_y, 0.0)
    plastic = y.approach + 2.0 * rest / (y.force + np.sqrt(y.force * y.force + 2.0 * k * rest))
    r, es, w = pc.radius, pc.e_star, pc.work_of_adhesion
    # JKR branch (the plastic rows aim at a_y itself, where the step is 0): beyond the adhesive well
    # U(a) is increasing and convex, so Newton from a_y (above the root) converges monotonically to
    # it; dU/da = F(a) d delta/da
    u_target = np.minimum(ke, w_y) + float(jkr_curve_potential(_first_contact_radius(r, es, w), r, es, w))
    a = np.full(v.shape, y.contact_radius)
    for _ in range(200):
        dda = 2.0 * a / r - (0.5 * np.sqrt(2.0 * math.pi * w / (es * a)) if w > 0.0 else 0.0)
        slope = jkr_curve_force(a, r, es, w) * dda
        # a plastic row sits at a_y, where F_y may be 0 (p_y = TENSILE_YIELD_LIMIT): its step is 0, not 0/0
        step = np.where(slope != 0.0, (jkr_curve_potential(a, r, es, w) - u_target) / np.where(slope != 0.0, slope, 1.0), 0.0)
        a = a - step
        if np.all(np.abs(step) <= 1e-15 * a):
            break
    out = np.where(ke > w_y, plastic, jkr_curve_approach(a, r, es, w))
    return float(out) if out.ndim == 0 else out


# =============================================================================== unloading (TN4)-(TN7)
def _plastic_radius(pc: PlasticContact, max_contact_radius, max_force):
    """R_p = 4 E* a_max^3 / (3 (F_max + sqrt(8 pi w E* a_max^3))), (TN4). [m]"""
    a3 = np.asarray(max_contact_radius, dtype=float) ** 3
    return plastic_radius.py_func(a3, max_force, pc.e_star, pc.work_of_adhesion)


def unloading_state(pc: PlasticContact, max_approach: float) -> UnloadingState:
    """R_p, delta_p and the break of the unloading curve from delta_max, (TN4)-(TN7).

    References
    ----------
    Thornton (1997), J. Appl. Mech. 64:383-386; Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    Below yield the unloading retraces the loading (R_p = R, delta_p = 0); above, R_p > R and the
    pull-off force is (3/2) pi w R_p:

    >>> import math
    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.05, 1e8)
    >>> d_y = yield_point(pc).approach
    >>> s = unloading_state(pc, 0.5 * d_y)
    >>> s.plastic_radius / 1e-6, s.plastic_approach, s.yielded
    (1.0, 0.0, False)
    >>> s = unloading_state(pc, 4 * d_y)
    >>> s.plastic_radius > 1e-6, round(s.pull_off_force / (1.5 * math.pi * 0.05 * s.plastic_radius), 12)
    (True, 1.0)
    """
    r, es, w = pc.radius, pc.e_star, pc.work_of_adhesion
    y = yield_point(pc)
    d_max = float(max_approach)
    a_max = float(loading_contact_radius(pc, d_max))
    f_max = float(loading_force(pc, d_max))
    a3 = float(np.asarray(a_max) ** 3)  # by NumPy, as _energy_account (_plastic_radius) takes it: one R_p for both
    r_p, d_p, a_cp, d_break = (float(x) for x in unloading_curve.py_func(d_max, a_max, a3, f_max, d_max > y.approach,
                                                                          r, es, w))
    f_break = float(jkr_curve_force(a_cp, r_p, es, w))
    return UnloadingState(d_max, a_max, f_max, r_p, d_p, d_break, a_cp, f_break, d_max > y.approach)


def unloading_force(pc: PlasticContact, state: UnloadingState, approach):
    """F on the unloading (and elastic reloading) curve (TN6), for delta_break <= delta <= delta_max. [N]

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    The unloading curve starts at the loading curve's F_max and ends at -(5/9) (3/2) pi w R_p (to 1e-6:
    a(delta) has a square-root fold at the break, so a rounding of delta moves a by its square root):

    >>> import math
    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.05, 1e8)
    >>> s = unloading_state(pc, 4 * yield_point(pc).approach)
    >>> round(float(unloading_force(pc, s, s.max_approach)) / s.max_force, 12)
    1.0
    >>> round(float(unloading_force(pc, s, s.break_approach)) / (-5 / 9 * 1.5 * math.pi * 0.05 * s.plastic_radius), 6)
    1.0
    """
    a = jkr_curve_contact_radius(np.asarray(approach, dtype=float) - state.plastic_approach,
                                 state.plastic_radius, pc.e_star, pc.work_of_adhesion)
    return jkr_curve_force(a, state.plastic_radius, pc.e_star, pc.work_of_adhesion)


# =============================================================================== energies, restitution (TN9)-(TN10)
def impact_energies(pc: PlasticContact, normal_speed: float) -> ImpactEnergies:
    """Incident energy, plastic dissipation (TN9), adhesive hysteresis (TN10), rebound energy. [J]

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162; Johnson & Pollock (1994).

    Examples
    --------
    Below yield without adhesion nothing is lost:

    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e9)
    >>> e = impact_energies(pc, 0.1)
    >>> e.plastic, e.hysteresis, round(e.rebound / e.incident, 12)
    (0.0, 0.0, 1.0)
    """
    ke, plastic, hysteresis = _energy_account(pc, float(normal_speed))
    return ImpactEnergies(float(ke), float(plastic), float(hysteresis), float(ke - plastic - hysteresis))


def _energy_account(pc: PlasticContact, normal_speed):
    """(incident energy, W_p (TN9), H (TN10)) of undamped impacts at the speeds ``normal_speed``,
    as arrays of its shape, all speeds at once. [J]"""
    r, es, w = pc.radius, pc.e_star, pc.work_of_adhesion
    v = np.asarray(normal_speed, dtype=float)
    ke = 0.5 * pc.mass * v * v
    d_max = np.asarray(largest_approach(pc, v))
    yielded = d_max > yield_point(pc).approach
    a_max = loading_contact_radius(pc, d_max)
    r_p = np.where(yielded, _plastic_radius(pc, a_max, loading_force(pc, d_max)), r)  # below yield R_p = R
    a0p = _first_contact_radius(r_p, es, w)

    def u(a):
        return jkr_curve_potential(a, r_p, es, w)

    plastic = np.where(yielded, ke - (u(a_max) - u(a0p)), 0.0)  # (TN9), W_load(delta_max) = ke
    hysteresis = u(_critical_radius(r_p, es, w)) - u(a0p) if w > 0.0 else np.zeros(v.shape)  # (TN10)
    return ke, plastic, hysteresis


def restitution_coefficient(pc: PlasticContact, normal_speed) -> np.ndarray:
    """Normal restitution e = sqrt(1 - (W_p + H) / (1/2 m V_i^2)) of the undamped law; 0 if captured. [-]

    From the energy account (TN8)-(TN10), no time integration
    (:func:`microimpact.solvers.plastic_reference.plastic_impact` integrates the motion).

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    Without adhesion it is Thornton's closed form (TN12):

    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> v_y = yield_velocity(pc)
    >>> e = restitution_coefficient(pc, [0.5 * v_y, 10 * v_y])
    >>> [round(float(x), 9) for x in e], round(float(thornton_restitution(0.1)), 9)
    ([1.0, 0.658558337], 0.658558337)
    """
    ke, plastic, hysteresis = _energy_account(pc, normal_speed)
    rebound = ke - plastic - hysteresis
    return np.where(rebound > 0.0, np.sqrt(np.maximum(rebound, 0.0) / np.where(ke > 0.0, ke, 1.0)), 0.0)


def capture_velocity(pc: PlasticContact, upper: float = 1e3, rtol: float = 1e-14, bracket=None) -> float:
    """The largest normal speed that is captured, (1/2) m V^2 = W_p + H, by Brent's method. [m/s]

    ``rtol`` is the relative tolerance of the root [-]; ``bracket`` (lo, hi) [m/s], optional, a
    first bracket to try (the whole [0, upper] where the sign does not change over it). 0 without
    adhesion. In the elastic limit
    (p_y large) it is the JKR sticking velocity
    (:func:`microimpact.model.adhesion_models.jkr_sticking_velocity`, displacement-controlled break).

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> round(capture_velocity(PlasticContact.from_contact(c, 1e12)), 4)
    0.452
    """
    if pc.work_of_adhesion == 0.0:
        return 0.0
    if impact_energies(pc, upper).captured:
        raise ValueError(f"capture_velocity: an impact at {upper!r} m/s is still captured; raise upper")
    def rebound(v):
        return impact_energies(pc, v).rebound

    lo, hi = 0.0, upper  # the rebound energy is -H < 0 at V = 0 and > 0 at ``upper``
    if bracket is not None and rebound(bracket[0]) <= 0.0 < rebound(bracket[1]):
        lo, hi = bracket
    return float(brentq(rebound, lo, hi, xtol=1e-300, rtol=rtol, maxiter=400))


# =============================================================================== yield velocity (TN11), (TN12)
def yield_velocity(pc: PlasticContact) -> float:
    """V_y = (pi^2 / sqrt(40)) sqrt(p_y^5 / (E*^4 rho)), (TN11): the speed at which a non-adhesive impact yields. [m/s]

    References
    ----------
    Thornton (1997), J. Appl. Mech. 64:383; Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    >>> pc = PlasticContact(1e-6, 4 / 3 * 3.141592653589793e-18 * 2000, 4e9 / 3, 0.0, 1e8)
    >>> round(yield_velocity(pc) / (1e40 / (1e36 * 2000)) ** 0.5, 4)
    1.5605
    """
    return YIELD_VELOCITY_COEFFICIENT * math.sqrt(pc.yield_pressure**5 / (pc.e_star**4 * pc.density))


def yield_pressure(yield_velocity_: float, stiffness: float, density: float) -> float:
    """p_y from V_y, (TN11) inverted: p_y = (V_y^2 E*^4 rho / (pi^4 / 40))^(1/5), E* = 3 K / 4. [Pa]

    Parameters: V_y [m/s], K [Pa], rho [kg/m^3].

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> round(yield_pressure(yield_velocity(pc), pc.stiffness, pc.density) / 1e8, 12)
    1.0
    """
    e_star = 0.75 * stiffness
    return (yield_velocity_**2 * e_star**4 * density / YIELD_VELOCITY_COEFFICIENT**2) ** 0.2


def adhesive_yield_velocity(pc: PlasticContact) -> float:
    """The speed at which the adhesive loading curve reaches yield: (1/2) m V^2 = W_load(delta_y), (TN8). [m/s]

    Equals :func:`yield_velocity` without adhesion. It is 0 where W_load(delta_y) <= 0: the contact
    yields inside the adhesive well, so the adhesion alone pulls every impact past yield.

    Examples
    --------
    >>> pc = PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> round(adhesive_yield_velocity(pc) / yield_velocity(pc), 12)
    1.0
    """
    return math.sqrt(2.0 * max(float(loading_work(pc, yield_point(pc).approach)), 0.0) / pc.mass)


def thornton_restitution(yield_ratio):
    """Thornton's (1997) closed form e(V_y / V_i) of an elastic-perfectly plastic impact, (TN12). [-]

    Parameters
    ----------
    yield_ratio : array_like
        V_y / V_i >= 0; e = 1 where it is >= 1 (no yield). [-]

    References
    ----------
    Thornton, C. (1997), J. Appl. Mech. 64:383-386, doi:10.1115/1.2787319.

    Examples
    --------
    >>> [round(float(x), 6) for x in thornton_restitution([1.0, 0.5, 0.1])]
    [1.0, 0.930626, 0.658558]
    """
    r = np.minimum(np.asarray(yield_ratio, dtype=float), 1.0)
    return (math.sqrt(6.0 * math.sqrt(3.0) / 5.0) * np.sqrt(1.0 - r * r / 6.0)
            * (r / (r + 2.0 * np.sqrt(6.0 / 5.0 - r * r / 5.0))) ** 0.25)


# =============================================================================== synthetic data
def synthetic_restitution(pc: PlasticContact, radii=(1.0e-6, 2.0e-6, 3.45e-6), speeds_per_radius: int = 20,
                          max_speed: float = 50.0, noise: float = 0.02, seed: int = 52) -> RestitutionSample:
    """SYNTHETIC e_n(v) data from the Thornton & Ning law at several sizes (not measurements).

    The material (density, K, w, p_y) is that of ``pc``; each radius gets its own mass. For each
    radius, ``speeds_per_radius`` speeds are log-spaced from 1.05 times its capture velocity (or
    V_y / 2 without adhesion) to ``max_speed``; e_n = e_true (1 + noise N(0, 1)), clipped to
    [0, 1], from ``numpy.random.default_rng(seed)`` in that order; e_n_uncertainty = noise e_true.

    Parameters
    ----------
    pc : PlasticContact
        The material; its radius and mass are replaced per size.
    radii : sequence of float
        Sphere radii. [m]
    speeds_per_radius : int
    max_speed : float
        [m/s]
    noise : float
        Relative sd of e_n. [-]
    seed : int

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> s = synthetic_restitution(PlasticContact.from_contact(c, 2e8), speeds_per_radius=3, noise=0.0)
    >>> s.radius.size, bool(abs(s.e_n - s.e_n_true).max() == 0.0), bool((s.e_n_true > 0).all())
    (9, True, True)
    """
    rng = np.random.default_rng(seed)
    out = {k: [] for k in ("radius", "normal_speed", "e_n", "e_n_true", "e_n_uncertainty")}
    for r in radii:
        sized = PlasticContact(float(r), pc.density * 4.0 / 3.0 * math.pi * r**3, pc.stiffness,
                               pc.work_of_adhesion, pc.yield_pressure)
        v_lo = 1.05 * capture_velocity(sized) if sized.work_of_adhesion > 0.0 else 0.5 * yield_velocity(sized)
        v = np.geomspace(v_lo, max_speed, speeds_per_radius)
        e_true = restitution_coefficient(sized, v)
        e_obs = np.clip(e_true * (1.0 + noise * rng.standard_normal(v.size)), 0.0, 1.0)
        for key, val in zip(out, (np.full(v.size, float(r)), v, e_obs, e_true, noise * e_true)):
            out[key].extend(np.asarray(val).tolist())
    params = dict(density=pc.density, stiffness=pc.stiffness, work_of_adhesion=pc.work_of_adhesion,
                  yield_pressure=pc.yield_pressure, radii=tuple(float(r) for r in radii), noise=noise, seed=seed,
                  max_speed=max_speed, speeds_per_radius=speeds_per_radius)
    return RestitutionSample(*(np.asarray(out[k]) for k in out), parameters=params)
