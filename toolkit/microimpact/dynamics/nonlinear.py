"""Nonlinear dynamics of the normal contact: phase plane, equilibria, bifurcation, v_c, omega_f.

Implements Eqs. (28)-(38) of Cheng, Brach & Dunn (2002), "Three-Dimensional Modeling of Microsphere
Contact/Impact with Smooth, Flat Surfaces", Aerosol Sci. Technol. 36(11):1081-1093,
doi:10.1080/02786820290092221, and the capture velocity that the paper mentions but does not give.

Nondimensional variables: xi = x / X (penetration x = -n over the length scale X = 2 pi f0 / K,
Eq. (29)), time over T = sqrt(m / sqrt(2 pi r f0 K)) (Eq. (30) corrected, see
:class:`microimpact.model.contact.Contact`), y = d xi / d tau = x' T / X. The normal motion of Eq. (27)
becomes Eq. (28)/(33)::

    xi' = y
    y'  = -xi^(3/2) (1 + C1 y) + xi^(1/2) (1 - C2 y)

with C1 = C_H X / T and C2 = C_A X / T (Eqs. (31)-(32)); C = C1 + C2 decides the nature of the
equilibrium (1, 0): spiral sink (C < 2), critical (C = 2), sink (C > 2), Eqs. (35)-(36).

Departures from the printed paper (each also noted where it is used):

* Eqs. (31)-(32): the right-hand forms C_H sqrt(r/K) (2 pi f0)^(3/2) / m use the misprinted T of
  Eq. (30) and are not dimensionless; C1 = C_H X / T with the corrected T is used, which is what
  the paper's own conditions on C_T (and Eq. (38)) imply.
* Eq. (37) is garbled. The asymptotic angular frequency used here is the imaginary part of the
  eigenvalues of Eq. (36) in dimensional time, omega_f = sqrt(4 - C^2) / (2 T) [rad/s].
* The paper's "2.0e7 Hz" for Fig. 5b is not reproduced by r = 3.45 um (omega_f = 4.75e7 rad/s,
  7.6 MHz at 0.5 m/s); omega_f in rad/s with r = 6.89 um (the diameter) gives 2.0e7.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence

import numpy as np
import xarray as xr
from scipy.optimize import brentq

from microimpact.io.files import write_netcdf_groups
from microimpact.io.provenance import contact_attributes
from microimpact.model import law
from microimpact.model.contact import PAPER_REFERENCE, Contact, check_positive
from microimpact.model.law import contact_potential_energy
from microimpact.solvers import DEFAULT_RTOL
from microimpact.solvers.engine import solve_normal

__all__ = [
    "nondimensional_rhs",
    "jacobian",
    "equilibria",
    "equilibrium_eigenvalues",
    "nondimensional_energy",
    "total_damping",
    "classify",
    "equilibrium_type",
    "critical_velocity",
    "critical_velocity_closed_form",
    "critical_velocity_numeric",
    "asymptotic_frequency",
    "CaptureBracket",
    "capture_bracket",
    "capture_velocity",
    "motion_type",
    "phase_portrait",
    "phase_portraits",
    "dynamics_summary",
    "save_phase_portraits",
    "table1_cases",
    "bifurcation_plane",
    "SPIRAL_SINK",
    "CRITICAL",
    "SINK",
    "MOTION_TYPES",
]

SPIRAL_SINK = "spiral sink"
CRITICAL = "critical"
SINK = "sink"

MOTION_REBOUND = "rebound"
MOTION_CAPTURE_OSCILLATION = "capture with oscillation"
MOTION_CAPTURE_NO_OSCILLATION = "capture without oscillation"
MOTION_TYPES = (MOTION_REBOUND, MOTION_CAPTURE_OSCILLATION, MOTION_CAPTURE_NO_OSCILLATION)

#: Relative half-width of the band |C - 2| <= CRITICAL_RTOL * 2 classified as "critical". C is a
#: product of powers of the inputs, computed to ~1e-15 relative; 1e-9 absorbs round-off in
#: C(critical_velocity(contact)) while a speed 1e-6 relative away from v_c (C changes by 2e-7
#: relative, since C ~ v^(-1/5)) is already classified off the line.
CRITICAL_RTOL = 1e-9


# ----------------------------------------------------------------------------- phase plane
def nondimensional_rhs(xi, y, c1, c2):
    """Right-hand side of the nondimensional normal motion, Eq. (33) (Eq. (28) as a system).

    Parameters
    ----------
    xi : array_like
        Nondimensional penetration x / X; xi > 0 in contact. [-]
    y : array_like
        Nondimensional penetration rate d xi / d tau = x' T / X. [-]
    c1, c2 : float or array_like
        Nondimensional Hertzian and adhesion damping C1, C2, Eqs. (31)-(32). [-]

    Returns
    -------
    (dxi, dy) : tuple of ndarray
        d xi / d tau = y and d y / d tau = -xi^(3/2) (1 + C1 y) + xi^(1/2) (1 - C2 y). [-]
        For xi <= 0 (no contact) the contact force is zero and dy = 0 (free flight).

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (33).

    Examples
    --------
    At rest at the equilibrium nothing moves; at xi = 4 the Hertz term (4^(3/2) = 8) beats the
    adhesion (4^(1/2) = 2), and in free flight the rate is constant:

    >>> dxi, dy = nondimensional_rhs([-0.5, 1.0, 4.0], [1.0, 0.0, 1.0], 0.0, 0.0)
    >>> dxi.tolist(), dy.tolist()
    ([1.0, 0.0, 1.0], [0.0, 0.0, -6.0])
    """
    y = np.asarray(y, dtype=float)
    xp = np.maximum(np.asarray(xi, dtype=float), 0.0)
    dy = law.nondimensional_acceleration(np.sqrt(xp), xp**1.5, y, c1, c2, 1.0, 1.0)
    return np.broadcast_to(y, dy.shape).copy(), dy


def jacobian(xi, y, c1, c2):
    """Jacobian of Eq. (33), Eq. (34).

    Parameters
    ----------
    xi : array_like
        Nondimensional penetration, xi > 0 in contact. [-]
    y : array_like
        Nondimensional penetration rate. [-]
    c1, c2 : float or array_like
        Nondimensional damping C1, C2. [-]

    Returns
    -------
    ndarray, shape broadcast(xi, y) + (2, 2)
        [[0, 1], [-(3/2) xi^(1/2) (1 + C1 y) + (1/2) xi^(-1/2) (1 - C2 y), -C1 xi^(3/2) - C2 xi^(1/2)]]. [-]

    Notes
    -----
    The field is not differentiable at xi = 0 (the x^(1/2) adhesion term): there the (2, 1) entry
    is returned as +inf when 1 - C2 y > 0 (its limit from inside the contact). For xi < 0 (free
    flight) the Jacobian is [[0, 1], [0, 0]].

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (34).

    Examples
    --------
    At the equilibrium (1, 0): [[0, 1], [-1, -(C1 + C2)]]:

    >>> jacobian(1.0, 0.0, 0.3, 0.2).tolist()
    [[0.0, 1.0], [-1.0, -0.5]]
    """
    xi = np.asarray(xi, dtype=float)
    y = np.asarray(y, dtype=float)
    xi, y = np.broadcast_arrays(xi, y)
    xp = np.maximum(xi, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_sqrt = np.where(xp > 0.0, 1.0 / np.sqrt(np.where(xp > 0.0, xp, 1.0)), np.inf)
        adhesion_term = 0.5 * (1.0 - c2 * y)
        j21_adh = np.where(adhesion_term == 0.0, 0.0, adhesion_term * inv_sqrt)
        j21 = -1.5 * np.sqrt(xp) * (1.0 + c1 * y) + j21_adh
    j22 = -c1 * xp**1.5 - c2 * np.sqrt(xp)
    contact = xi >= 0.0
    j21 = np.where(contact, j21, 0.0)
    j22 = np.where(contact, j22, 0.0)
    out = np.zeros(xi.shape + (2, 2))
    out[..., 0, 1] = 1.0
    out[..., 1, 0] = j21
    out[..., 1, 1] = j22
    return out


def equilibria():
    """The two equilibrium points (xi, y) of Eq. (33): (0, 0) and (1, 0). [-]

    Returns
    -------
    ndarray, shape (2, 2)
        Rows (xi, y). (0, 0) is the point of first touch, where the field is not differentiable
        (see :func:`jacobian`); (1, 0) is the static adhesive equilibrium x = X, whose nature
        depends on C = C1 + C2 (:func:`equilibrium_eigenvalues`).

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (33) and its equilibria

    Examples
    --------
    >>> equilibria().tolist()
    [[0.0, 0.0], [1.0, 0.0]]
    """
    return np.array([[0.0, 0.0], [1.0, 0.0]])


def equilibrium_eigenvalues(c):
    """Eigenvalues of the Jacobian at the equilibrium (1, 0), Eqs. (35)-(36).

    Parameters
    ----------
    c : float or array_like
        Total nondimensional damping C = C1 + C2. [-]

    Returns
    -------
    ndarray of complex, shape shape(c) + (2,)
        lambda = (-C + sqrt(C^2 - 4)) / 2 and (-C - sqrt(C^2 - 4)) / 2 (for C < 2 the one with
        positive imaginary part first), in units of 1/T. [-]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (35)-(36).

    Examples
    --------
    >>> equilibrium_eigenvalues([2.0, 2.5]).real.tolist()
    [[-1.0, -1.0], [-0.5, -2.0]]
    >>> round(float(equilibrium_eigenvalues(1.0)[0].imag), 12) == round(3**0.5 / 2, 12)
    True
    """
    c = np.asarray(c, dtype=float)
    root = np.sqrt((c * c - 4.0).astype(complex))
    return np.stack([(-c + root) / 2.0, (-c - root) / 2.0], axis=-1)


def nondimensional_energy(xi, y):
    """Nondimensional contact energy e = y^2 / 2 + (2/5) xi^(5/2) - (2/3) xi^(3/2). [-]

    The dimensional energy of :func:`microimpact.model.law.contact_potential_energy` plus the normal
    kinetic energy is e m X^2 / T^2. e < 0 means captured (the sphere can no longer reach xi = 0);
    e = -4/15 at the equilibrium (1, 0).

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (33) (its first integral without damping)

    Examples
    --------
    >>> round(float(nondimensional_energy(1.0, 0.0)), 12) == round(-4.0 / 15.0, 12)
    True
    """
    s = np.sqrt(np.maximum(np.asarray(xi, dtype=float), 0.0))
    return law.nondimensional_energy(s, np.asarray(y, dtype=float), 1.0, 1.0)


# ----------------------------------------------------------------------------- damping vs speed
def _per_speed(func, speed):
    speed_arr = np.asarray(speed, dtype=float)
    if speed_arr.ndim == 0:
        return func(float(speed_arr))
    return np.vectorize(func, otypes=[float])(speed_arr)


def _check_adhesive(contact: Contact) -> None:
    if contact.adhesion_line_force <= 0.0:
        raise ValueError(
            "contact.adhesion_line_force (f0) is 0: without adhesion there is no equilibrium at "
            "x = X > 0 and the nondimensionalisation of Eqs. (29)-(30) does not exist"
        )


def total_damping(contact: Contact, speed):
    """Total nondimensional damping C = C1 + C2 = (C_H + C_A) X / T, Eqs. (31)-(32), (35).

    Parameters
    ----------
    contact : Contact
    speed : float or array_like
        Incident normal speed of the impact; through Eqs. (14)-(15) C ~ speed^(-1/5), unless
        ``contact.damping_reference_speed`` is fixed. [m/s]

    Returns
    -------
    float or ndarray
        C. [-]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (14)-(15), (31)-(32).

    Examples
    --------
    C ~ v^(-1/5): 32 times the speed halves it.

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> round(float(total_damping(c, 0.5) / total_damping(c, 16.0)), 12)
    2.0
    """
    _check_adhesive(contact)

    def one(v: float) -> float:
        check_positive("normal speed [m/s]", v)
        c1, c2 = contact.nondimensional_damping(v)
        return c1 + c2

    return _per_speed(one, speed)


def _type_of_c(c: float, critical_rtol: float) -> str:
    if abs(c - 2.0) <= critical_rtol * 2.0:
        return CRITICAL
    return SPIRAL_SINK if c < 2.0 else SINK


def equilibrium_type(c, *, critical_rtol: float = CRITICAL_RTOL):
    """Nature of the equilibrium (1, 0) for total damping C, Eq. (36).

    Returns "spiral sink" (C < 2, complex eigenvalues with negative real part), "critical"
    (|C - 2| <= critical_rtol * 2, double eigenvalue -1) or "sink" (C > 2, two negative real
    eigenvalues). Arrays give an object array of these strings.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (36).

    Examples
    --------
    >>> equilibrium_type(1.0), equilibrium_type(2.0), equilibrium_type(3.0)
    ('spiral sink', 'critical', 'sink')
    """
    c_arr = np.asarray(c, dtype=float)
    if c_arr.ndim == 0:
        return _type_of_c(float(c_arr), critical_rtol)
    return np.vectorize(lambda v: _type_of_c(v, critical_rtol), otypes=[object])(c_arr)


def classify(contact: Contact, speed, *, critical_rtol: float = CRITICAL_RTOL):
    """Nature of the adhesive equilibrium (1, 0) after an impact at this normal speed, Eqs. (35)-(36).

    Parameters
    ----------
    contact : Contact
    speed : float or array_like
        Incident normal speed; it sets C through Eqs. (14)-(15) unless
        ``contact.damping_reference_speed`` is fixed. [m/s]
    critical_rtol : float, optional
        Relative band around C = 2 reported as "critical" (default :data:`CRITICAL_RTOL`). [-]

    Returns
    -------
    str or ndarray of str
        "spiral sink" (C < 2, speed > v_c), "critical" (C = 2, speed = v_c) or "sink"
        (C > 2, speed < v_c).

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (35)-(36), (38).

    Examples
    --------
    Table 1 row 2: below v_c = 2.25e-5 m/s a sink, above a spiral sink:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> classify(c, [1e-6, 1.0]).tolist()
    ['sink', 'spiral sink']
    """
    return equilibrium_type(total_damping(contact, speed), critical_rtol=critical_rtol)


# ----------------------------------------------------------------------------- critical velocity
def _check_speed_dependent(contact: Contact) -> None:
    if contact.damping_reference_speed is not None:
        c = total_damping(contact, contact.damping_reference_speed)
        raise ValueError(
            f"contact.damping_reference_speed is fixed at {contact.damping_reference_speed!r} m/s, so "
            f"C = C1 + C2 = {c:.6g} does not depend on the impact speed and there is no critical "
            f"velocity: the equilibrium is a {equilibrium_type(c)} at every speed. Use "
            "contact.with_(damping_reference_speed=None) for the paper's speed-dependent damping, "
            "or call classify(contact, speed) directly."
        )
    _check_adhesive(contact)
    if contact.zeta_hertz + contact.zeta_adhesion <= 0.0:
        raise ValueError("zeta_hertz + zeta_adhesion is 0: C = 0 at every speed, there is no critical velocity")


def critical_velocity_closed_form(contact: Contact) -> float:
    """Critical velocity v_c of Eq. (38), where C(v_c) = 2. [m/s]

    v_c = 2^(5/4) pi^(25/4) f0^(25/4) r^(-19/4) K^(-23/4) m^(-1/2) (zeta_H + zeta_A)^5.

    Raises
    ------
    ValueError
        If ``contact.damping_reference_speed`` is fixed (C then does not depend on the speed), if
        f0 = 0 or if zeta_H + zeta_A = 0.

    Notes
    -----
    Derivation (a check of the printed Eq. (38)): with C_H + C_A = (zeta_H + zeta_A) /
    ((r^3 K / m)^(2/5) v^(1/5)) (Eqs. (14)-(15)) and X / T = (2 pi f0)^(5/4) r^(1/4) K^(-3/4)
    m^(-1/2), C = 2 gives v_c = ((zeta_H + zeta_A) X / (2 T (r^3 K / m)^(2/5)))^5, which
    simplifies to Eq. (38) as printed. For Table 1 row 2 it gives 2.246e-5 m/s; the paper prints
    2.25e-5 (three significant figures).

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (38).

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> f"{critical_velocity_closed_form(c):.4e} m/s"
    '2.2463e-05 m/s'
    """
    _check_speed_dependent(contact)
    f0, r, k, m = contact.adhesion_line_force, contact.radius, contact.stiffness, contact.mass
    zeta = contact.zeta_hertz + contact.zeta_adhesion
    return (
        2.0**1.25 * math.pi**6.25 * f0**6.25 * r**-4.75 * k**-5.75 * m**-0.5 * zeta**5
    )


def critical_velocity_numeric(contact: Contact, *, xtol: float = 1e-14) -> float:
    """Critical velocity as the root of C(v) = 2, found with scipy's brentq. [m/s]

    The root is searched in u = ln(v) on ln C(e^u) - ln 2, with ``xtol`` absolute in u, i.e. the
    relative accuracy of v_c. C(v) comes from :meth:`Contact.nondimensional_damping`, so this
    checks Eq. (38) against Eqs. (14)-(15) and (29)-(32) independently of the closed form.

    Raises
    ------
    ValueError
        As :func:`critical_velocity_closed_form`.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (34)-(38)

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> round(critical_velocity_numeric(c) / critical_velocity_closed_form(c), 12)
    1.0
    """
    _check_speed_dependent(contact)

    def g(u: float) -> float:
        return math.log(total_damping(contact, math.exp(u)) / 2.0)

    lo, hi = -30.0, 30.0
    while g(lo) < 0.0:  # C(v) decreases with v: g(lo) must be > 0
        lo -= 30.0
        if lo < -700.0:
            raise ValueError("no speed above 1e-304 m/s gives C >= 2")
    while g(hi) > 0.0:
        hi += 30.0
        if hi > 700.0:
            raise ValueError("no speed below 1e304 m/s gives C <= 2")
    return math.exp(brentq(g, lo, hi, xtol=xtol, rtol=4 * np.finfo(float).eps))


def critical_velocity(contact: Contact, *, method: str = "closed_form") -> float:
    """Critical velocity v_c: normal impact speed at which C = C1 + C2 = 2, Eq. (38). [m/s]

    Above v_c the adhesive equilibrium is a spiral sink (a captured sphere oscillates), below it a
    sink (a captured sphere settles without oscillation).

    Parameters
    ----------
    contact : Contact
        Must have ``damping_reference_speed=None`` (damping from each impact's own speed).
    method : {"closed_form", "root"}
        "closed_form": Eq. (38) (:func:`critical_velocity_closed_form`); "root": brentq root of
        C(v) = 2 (:func:`critical_velocity_numeric`). Both agree to ~1e-15 relative.

    Returns
    -------
    float
        v_c. [m/s]

    Raises
    ------
    ValueError
        If ``contact.damping_reference_speed`` is fixed: C then does not depend on the speed, so
        no critical velocity exists (a raise rather than NaN, so that a sweep cannot silently
        plot a meaningless number; the message gives the speed-independent C and its type).
        Also if f0 = 0 or zeta_H + zeta_A = 0, or for an unknown method.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (38).

    Examples
    --------
    The paper prints 2.25e-5 m/s for Table 1 row 2; the two methods agree:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> round(critical_velocity(c, method="root") / critical_velocity(c), 12)
    1.0
    """
    if method == "closed_form":
        return critical_velocity_closed_form(contact)
    if method == "root":
        return critical_velocity_numeric(contact)
    raise ValueError(f"method must be 'closed_form' or 'root', got {method!r}")


def asymptotic_frequency(contact: Contact, speed):
    """Asymptotic angular frequency omega_f of the oscillation about the equilibrium, Eq. (37) corrected. [rad/s]

    omega_f = sqrt(4 - C^2) / (2 T) for C < 2, and 0 for C >= 2 (critical or over-damped: no
    oscillation), with C = (C_H + C_A) X / T at this impact speed.

    Parameters
    ----------
    contact : Contact
    speed : float or array_like
        Incident normal speed (sets C via Eqs. (14)-(15)). [m/s]

    Returns
    -------
    float or ndarray
        omega_f. [rad/s] Divide by 2 pi for Hz.

    Notes
    -----
    Eq. (37) as printed, sqrt(4 X^(1/2) - C_T^2 X^2 / T X^3) / (2 T), is dimensionally
    inconsistent. The imaginary part of the eigenvalues of Eq. (36) is sqrt(4 - C^2) / 2 in units
    of 1/T, which gives the form used here. The paper's "2.0e7 Hz" (Fig. 5b, 0.5 m/s) is this
    omega_f in rad/s evaluated with r = 6.89 um; for the Table 1 radius r = 3.45 um it is
    4.75e7 rad/s (7.57 MHz).

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (36)-(37).

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> f"{float(asymptotic_frequency(c, 0.5)):.3e} rad/s"
    '4.754e+07 rad/s'
    """
    _check_adhesive(contact)
    t_scale = contact.time_scale

    def one(v: float) -> float:
        c = total_damping(contact, v)
        return math.sqrt(4.0 - c * c) / (2.0 * t_scale) if c < 2.0 else 0.0

    return _per_speed(one, speed)


# ----------------------------------------------------------------------------- capture velocity
@dataclass(frozen=True)
class CaptureBracket:
    """Bracket of the capture velocity found by bisection on the outcome of a normal impact.

    Attributes
    ----------
    captured_speed : float
        Largest speed tried whose impact is captured. [m/s]
    rebound_speed : float
        Smallest speed tried whose impact rebounds. [m/s]
    rebound_e_n : float
        Restitution coefficient at ``rebound_speed`` (tends to 0 as the bracket closes). [-]
    xtol, rtol : float
        Stopping rule: rebound_speed - captured_speed <= xtol + rtol * rebound_speed. [m/s], [-]
    evaluations : int
        Number of normal solves.

    Examples
    --------
    The bracket of the paper's microsphere closes within its stopping rule, and the rebound at its
    upper end barely leaves (e_n tends to 0 at the capture velocity):

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> b = capture_bracket(c)
    >>> width = b.rebound_speed - b.captured_speed
    >>> width <= b.xtol + b.rtol * b.rebound_speed, b.rebound_e_n < 1e-3
    (True, True)
    >>> round(b.captured_speed, 6)
    1.449241
    """

    captured_speed: float
    rebound_speed: float
    rebound_e_n: float
    xtol: float
    rtol: float
    evaluations: int

    @property
    def speed(self) -> float:
        """Midpoint of the bracket: the capture velocity within +- half_width. [m/s]"""
        return 0.5 * (self.captured_speed + self.rebound_speed)

    @property
    def half_width(self) -> float:
        """Half the bracket width: the absolute uncertainty of :attr:`speed`. [m/s]"""
        return 0.5 * (self.rebound_speed - self.captured_speed)


def capture_bracket(
    contact: Contact,
    *,
    xtol: float = 1e-9,
    rtol: float = 1e-7,
    solver_rtol: float = DEFAULT_RTOL,
    initial_guess: float = 1.0,
    max_evaluations: int = 200,
) -> CaptureBracket:
    """Bracket the capture velocity of a normal impact by bisection on the outcome (engine solves).

    Parameters
    ----------
    contact : Contact
    xtol : float, optional
        Absolute tolerance on the bracket width. [m/s]
    rtol : float, optional
        Relative tolerance on the bracket width. [-] The search stops when
        rebound_speed - captured_speed <= xtol + rtol * rebound_speed.
    solver_rtol : float, optional
        Relative tolerance passed to :func:`microimpact.solvers.engine.solve_normal`. [-]
    initial_guess : float, optional
        Speed at which the search for a bracket starts; doubled/halved until the outcomes
        differ. [m/s]
    max_evaluations : int, optional
        Safety limit on the number of normal solves.

    Returns
    -------
    CaptureBracket

    Raises
    ------
    ValueError
        If no capture (or no rebound) is found between 1e-12 and 1e6 m/s. Without adhesion
        (f0 = 0) or without damping (zeta_H = zeta_A = 0) no impact is ever captured (the contact
        energy can only become negative by dissipation, and only with adhesion): use
        :func:`capture_velocity`, which returns 0 then.

    Notes
    -----
    The outcome is a step function of the speed, so a bisection is used rather than brentq on a
    continuous residual. e_n tends to 0 continuously as the speed falls to the capture velocity
    (roughly as the square root of the distance), so the rebound side of the bracket shows
    e_n -> 0; the energy criterion of the engine (contact energy < 0 means captured) makes the
    outcome exact up to the solver tolerance, which only matters within a band much narrower than
    the default tolerances (e_n is ~1e-3 at 1e-7 relative above the capture velocity).

    References
    ----------
    Cheng, Brach & Dunn (2002), the capture of Fig. 5 and the Conclusions

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> b = capture_bracket(c)
    >>> b.captured_speed < b.rebound_speed, b.rebound_e_n < 1e-3
    (True, True)
    """
    if initial_guess <= 0.0 or not math.isfinite(initial_guess):
        raise ValueError(f"initial_guess must be a finite speed > 0 [m/s], got {initial_guess!r}")
    evaluations = 0
    cache: dict[float, object] = {}

    def solve(v: float):
        nonlocal evaluations
        if v not in cache:
            evaluations += 1
            if evaluations > max_evaluations:
                raise RuntimeError(f"capture_bracket: more than {max_evaluations} normal solves")
            cache[v] = solve_normal(contact, v, rtol=solver_rtol)
        return cache[v]

    v = initial_guess
    if solve(v).outcome == "capture":
        lo = v
        hi = v * 2.0
        while solve(hi).outcome == "capture":
            lo, hi = hi, hi * 2.0
            if hi > 1e6:
                raise ValueError(f"every normal impact up to 1e6 m/s is captured (sphere radius {contact.radius:.4g} m, "
                                 f"f0 = {contact.adhesion_line_force:.4g} N/m, zeta_H = {contact.zeta_hertz:.4g}, "
                                 f"zeta_A = {contact.zeta_adhesion:.4g})")
    else:
        hi = v
        lo = v / 2.0
        while solve(lo).outcome != "capture":
            hi, lo = lo, lo / 2.0
            if lo < 1e-12:
                raise ValueError(f"no normal impact down to 1e-12 m/s is captured (sphere radius {contact.radius:.4g} m, "
                                 f"f0 = {contact.adhesion_line_force:.4g} N/m)")
    while hi - lo > xtol + rtol * hi:
        mid = 0.5 * (lo + hi)
        if solve(mid).outcome == "capture":
            lo = mid
        else:
            hi = mid
    return CaptureBracket(lo, hi, float(solve(hi).e_n), xtol, rtol, evaluations)


def capture_velocity(contact: Contact, *, xtol: float = 1e-9, rtol: float = 1e-7, **kwargs) -> float:
    """Normal impact speed below which the sphere is captured (the capture velocity). [m/s]

    Bisection on the outcome of :func:`microimpact.solvers.engine.solve_normal`; see
    :func:`capture_bracket` for the parameters. The result is the bracket midpoint, within
    (xtol + rtol * v) / 2 of the outcome boundary: by default 5e-10 m/s + 5e-8 relative.

    Returns 0.0 when no impact can be captured: f0 = 0 (no adhesion, the contact energy stays
    >= 0) or zeta_H = zeta_A = 0 (energy conserved, e_n = 1 at every speed).

    References
    ----------
    Cheng, Brach & Dunn (2002), the capture of Fig. 5 and the Conclusions

    Examples
    --------
    Table 1 row 2 (the paper's microsphere):

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> f"{capture_velocity(c):.4f} m/s"
    '1.4492 m/s'
    """
    if contact.adhesion_line_force <= 0.0 or contact.zeta_hertz + contact.zeta_adhesion <= 0.0:
        return 0.0
    return capture_bracket(contact, xtol=xtol, rtol=rtol, **kwargs).speed


# ----------------------------------------------------------------------------- phase portraits
def motion_type(outcome: str, equilibrium: str) -> str:
    """The paper's three types of motion (Fig. 5, Conclusions) from outcome and equilibrium type.

    "rebound"; "capture with oscillation" (captured, spiral sink); "capture without oscillation"
    (captured, sink or critical).

    References
    ----------
    Cheng, Brach & Dunn (2002), Fig. 5 and the Conclusions (three types of motion)

    Examples
    --------
    >>> motion_type("capture", "spiral sink"), motion_type("capture", "sink")
    ('capture with oscillation', 'capture without oscillation')
    """
    if outcome == "rebound":
        return MOTION_REBOUND
    if outcome != "capture":
        raise ValueError(f"outcome must be 'rebound' or 'capture', got {outcome!r}")
    return MOTION_CAPTURE_OSCILLATION if equilibrium == SPIRAL_SINK else MOTION_CAPTURE_NO_OSCILLATION


def phase_portrait(contact: Contact, speed: float, *, rtol: float = 1e-10, settle_amplitude: float = 1e-4) -> xr.Dataset:
    """Phase-plane trajectory of a normal impact (Fig. 5), from first touch until the sphere leaves or settles.

    Parameters
    ----------
    contact : Contact
    speed : float
        Incident normal speed. [m/s]
    rtol : float, optional
        Relative tolerance of :func:`microimpact.solvers.engine.solve_normal`. [-] The one
        exception to :data:`microimpact.solvers.DEFAULT_RTOL`: the accepted steps are the points
        of the drawn trajectory, and at 1e-8 a captured oscillation gets about 13 of them per
        period (273 over Fig. 5b's trajectory, against 663 at 1e-10), which draws as a polygon.
    settle_amplitude : float, optional
        A captured sphere is followed until its oscillation amplitude about the equilibrium is
        below this fraction of X (passed to the engine). [-]

    Returns
    -------
    xarray.Dataset
        Coordinate ``time`` [s]; variables ``penetration`` x = -n [m], ``penetration_rate``
        x' [m/s], ``xi`` = x / X [-], ``y`` = x' T / X [-], ``energy`` = m x'^2/2 + V(x) [J] and
        ``energy_nondimensional`` e [-] (:func:`nondimensional_energy`). Attributes: outcome,
        motion_type (rebound / capture with oscillation / capture without oscillation),
        equilibrium_type, normal_speed, C1, C2, C, e_n, length_scale X, time_scale T,
        asymptotic_frequency omega_f and ``rate_sign_changes_after_capture`` (how often x'
        changed sign after the energy fell below 0: many for a spiral sink, at most one for a
        sink). A captured impact is followed until it settles at (1, 0).

    References
    ----------
    Cheng, Brach & Dunn (2002), Fig. 5.

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> p = phase_portrait(c, 0.5)
    >>> p.attrs["outcome"], p.attrs["motion_type"]
    ('capture', 'capture with oscillation')
    """
    check_positive("normal speed [m/s]", speed)
    _check_adhesive(contact)
    sol = solve_normal(
        contact, float(speed), rtol=rtol, trajectory=True, follow_capture=True, settle_amplitude=settle_amplitude
    )
    t = np.asarray(sol.time, dtype=float)
    x = np.asarray(sol.penetration, dtype=float)
    xdot = np.asarray(sol.penetration_rate, dtype=float)
    big_x, big_t = contact.length_scale, contact.time_scale
    xi = x / big_x
    y = xdot * big_t / big_x
    energy = 0.5 * contact.mass * xdot**2 + contact_potential_energy(contact, x)
    c1, c2 = contact.nondimensional_damping(float(speed))
    c = c1 + c2
    eq_type = equilibrium_type(c)
    if sol.outcome == "capture" and math.isfinite(sol.capture_time):
        after = y[t >= sol.capture_time]
        s = np.sign(after[after != 0.0])
        sign_changes = int(np.count_nonzero(s[1:] != s[:-1]))
    else:
        sign_changes = 0
    ds = xr.Dataset(
        data_vars={
            "penetration": ("time", x, {"units": "m", "long_name": "penetration x = -n of the sphere centre"}),
            "penetration_rate": ("time", xdot, {"units": "m s-1", "long_name": "penetration rate dx/dt"}),
            "xi": ("time", xi, {"units": "1", "long_name": "nondimensional penetration x / X, Eq. (33)"}),
            "y": ("time", y, {"units": "1", "long_name": "nondimensional penetration rate (dx/dt) T / X, Eq. (33)"}),
            "energy": ("time", energy, {"units": "J", "long_name": "normal kinetic plus contact potential energy"}),
            "energy_nondimensional": (
                "time",
                nondimensional_energy(xi, y),
                {"units": "1", "long_name": "contact energy in units of m X^2 / T^2 (< 0: captured)"},
            ),
        },
        coords={"time": ("time", t, {"units": "s", "long_name": "time since first contact"})},
        attrs={
            "title": "Phase portrait of a normal impact (Cheng, Brach & Dunn 2002, Fig. 5)",
            "outcome": sol.outcome,
            "motion_type": motion_type(sol.outcome, eq_type),
            "equilibrium_type": eq_type,
            "normal_speed": float(speed),
            "normal_speed_units": "m s-1",
            "C1": c1,
            "C2": c2,
            "C": c,
            "e_n": float(sol.e_n),
            "capture_time": float(sol.capture_time),
            "length_scale": big_x,
            "length_scale_units": "m",
            "time_scale": big_t,
            "time_scale_units": "s",
            "asymptotic_frequency": float(asymptotic_frequency(contact, float(speed))),
            "asymptotic_frequency_units": "rad s-1",
            "rate_sign_changes_after_capture": sign_changes,
            "solver": "microimpact.solvers.engine.solve_normal",
            "rtol": rtol,
        },
    )
    return ds


# ----------------------------------------------------------------------------- bifurcation plane
def table1_cases(
    speeds: Sequence[float] = (1.0e-5, 0.5, 1.0, 10.0),
) -> list[tuple[str, Contact, float]]:
    """The parameter sets of Table 1 at a few normal speeds, as (label, contact, speed) triples.

    Row 1 is given as its two ends (r = 1.29 um, f0 = 5.340 N/m and r = 3.45 um, f0 = 7.390 N/m);
    rows 2 and 3 share r = 3.45 um, f0 = 7.422 N/m (row 3 only changes the friction coefficient,
    which does not enter the normal motion, so its points coincide with row 2). Density
    1350 kg/m^3, K = 1.776e9 Pa, zeta_A = 29, zeta_H = 0.5, f = 0.15.

    References
    ----------
    Cheng, Brach & Dunn (2002), Table 1.

    Examples
    --------
    >>> cases = table1_cases()
    >>> len(cases), cases[0][0]
    (12, 'row 1, r=1.29 um, v=1e-05 m/s')
    """
    common = dict(density=1350.0, stiffness=1.776e9, zeta_hertz=0.5, zeta_adhesion=29.0, friction=0.15)
    rows = [
        ("row 1, r=1.29 um", Contact(radius=1.29e-6, adhesion_line_force=5.340, **common)),
        ("row 1, r=3.45 um", Contact(radius=3.45e-6, adhesion_line_force=7.390, **common)),
        ("rows 2-3, r=3.45 um", Contact(radius=3.45e-6, adhesion_line_force=7.422, **common)),
    ]
    return [(f"{label}, v={v:g} m/s", contact, float(v)) for label, contact in rows for v in speeds]


def bifurcation_plane(
    cases: Iterable[tuple[str, Contact, float]] | None = None,
    c1_range: tuple[float, float] | None = None,
    c2_range: tuple[float, float] | None = None,
    *,
    n_c1: int = 201,
    n_c2: int = 201,
) -> xr.Dataset:
    """The (C1, C2) parameter plane of Fig. 4 with the Table 1 cases placed on it.

    Parameters
    ----------
    cases : iterable of (label, Contact, speed), optional
        Points to place; default :func:`table1_cases`. speed is the normal impact speed [m/s].
    c1_range, c2_range : (float, float), optional
        Extent of the grid in C1 and C2. [-] Default: from 0 to 1.1 times the largest of 2.2 and
        the cases' values, so that the line C = 2 and every point are inside.
    n_c1, n_c2 : int
        Grid size.

    Returns
    -------
    xarray.Dataset
        Grid coordinates ``C1``, ``C2`` with ``total_damping`` C = C1 + C2 and ``region``
        (0: C < 2 spiral sink, 1: C = 2 critical line, the grid cells it crosses, 2: C > 2 sink;
        see attrs ``region_meanings``); ``critical_line_C2`` = 2 - C1 along ``C1``; per ``case``
        (labels as coordinate): ``case_C1``, ``case_C2``, ``case_C``, ``case_speed`` [m/s],
        ``case_radius`` [m], ``case_f0`` [N/m], ``case_critical_velocity`` [m/s] (NaN if the
        contact has a fixed damping reference speed) and ``case_equilibrium_type``.

    References
    ----------
    Cheng, Brach & Dunn (2002), Fig. 4.

    Examples
    --------
    >>> bp = bifurcation_plane(n_c1=11, n_c2=11)
    >>> bp["case_equilibrium_type"].values[:3].tolist()
    ['sink', 'spiral sink', 'spiral sink']
    """
    if cases is None:
        cases = table1_cases()
    cases = list(cases)
    labels, p1, p2, speeds, radii, f0s, vcs, types = [], [], [], [], [], [], [], []
    for label, contact, v in cases:
        c1, c2 = contact.nondimensional_damping(float(v))
        labels.append(str(label))
        p1.append(c1)
        p2.append(c2)
        speeds.append(float(v))
        radii.append(contact.radius)
        f0s.append(contact.adhesion_line_force)
        vcs.append(critical_velocity(contact) if contact.damping_reference_speed is None else math.nan)
        types.append(equilibrium_type(c1 + c2))
    top = 1.1 * max([2.2] + p1 + p2)
    c1_range = c1_range or (0.0, top)
    c2_range = c2_range or (0.0, top)
    g1 = np.linspace(c1_range[0], c1_range[1], n_c1)
    g2 = np.linspace(c2_range[0], c2_range[1], n_c2)
    cc = g1[:, None] + g2[None, :]
    h = 0.5 * (abs(g1[1] - g1[0]) if n_c1 > 1 else 0.0) + 0.5 * (abs(g2[1] - g2[0]) if n_c2 > 1 else 0.0)
    region = np.where(cc < 2.0, 0, 2)
    region = np.where(np.abs(cc - 2.0) <= h, 1, region).astype(np.int8)
    ds = xr.Dataset(
        data_vars={
            "total_damping": (("C1", "C2"), cc, {"units": "1", "long_name": "C = C1 + C2, Eq. (35)"}),
            "region": (
                ("C1", "C2"),
                region,
                {
                    "units": "1",
                    "long_name": "nature of the equilibrium (1, 0), Eq. (36)",
                    "flag_values": np.array([0, 1, 2], dtype=np.int8),
                    "flag_meanings": "spiral_sink critical sink",
                },
            ),
            "critical_line_C2": ("C1", 2.0 - g1, {"units": "1", "long_name": "C2 on the bifurcation line C = 2"}),
            "case_C1": ("case", np.array(p1), {"units": "1", "long_name": "C1 = C_H X / T, Eq. (31)"}),
            "case_C2": ("case", np.array(p2), {"units": "1", "long_name": "C2 = C_A X / T, Eq. (32)"}),
            "case_C": ("case", np.array(p1) + np.array(p2), {"units": "1", "long_name": "C = C1 + C2"}),
            "case_speed": ("case", np.array(speeds), {"units": "m s-1", "long_name": "normal impact speed"}),
            "case_radius": ("case", np.array(radii), {"units": "m", "long_name": "sphere radius"}),
            "case_f0": ("case", np.array(f0s), {"units": "N m-1", "long_name": "adhesion line force f0"}),
            "case_critical_velocity": ("case", np.array(vcs), {"units": "m s-1", "long_name": "critical velocity v_c, Eq. (38)"}),
            "case_equilibrium_type": ("case", np.array(types, dtype=object), {"long_name": "nature of (1, 0) at this speed"}),
        },
        coords={
            "C1": ("C1", g1, {"units": "1", "long_name": "nondimensional Hertzian damping C1"}),
            "C2": ("C2", g2, {"units": "1", "long_name": "nondimensional adhesion damping C2"}),
            "case": ("case", np.array(labels, dtype=object), {"long_name": "case label"}),
        },
        attrs={
            "title": "Bifurcation on the (C1, C2) parameter plane (Cheng, Brach & Dunn 2002, Fig. 4)",
            "region_meanings": "0: C < 2 spiral sink (damped oscillation); 1: C = 2 critical; 2: C > 2 sink (no oscillation)",
        },
    )
    return ds


# ----------------------------------------------------------------------------- pipeline products
def phase_portraits(contact: Contact, speeds: Sequence[float], **kwargs) -> list[xr.Dataset]:
    """Fig. 5 trajectories: :func:`phase_portrait` at each normal speed.

    Parameters
    ----------
    contact : Contact
    speeds : sequence of float
        Incident normal speeds. [m/s]
    **kwargs
        Passed to :func:`phase_portrait` (``rtol``, ``settle_amplitude``).

    Returns
    -------
    list of xarray.Dataset
        One trajectory per speed, in the order given.

    References
    ----------
    Cheng, Brach & Dunn (2002), Fig. 5

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> [p.attrs["outcome"] for p in phase_portraits(c, [0.5, 2.0])]
    ['capture', 'rebound']
    """
    return [phase_portrait(contact, float(v), **kwargs) for v in speeds]


def save_phase_portraits(portraits: Sequence[xr.Dataset], path) -> Path:
    """Write several phase portraits to one NetCDF-4 file atomically, one group per trajectory.

    Groups are ``portraits/portrait_0``, ``portraits/portrait_1``, ... in the order given (each
    keeps its own ``time`` coordinate and attributes); the root group lists them in the attribute
    ``portraits`` and their speeds in ``normal_speeds`` [m/s], and carries the provenance
    attributes (``parameter_source``, ``contact_*``) that all trajectories share. Read back with
    :func:`microimpact.io.files.read_netcdf_groups`, or as a tree with ``xarray.open_datatree``.

    The trajectories sit in one parent group ``portraits`` rather than side by side at the root:
    each has a ``time`` dimension of its own length, which is valid CF (CF 2.7.1 only asks that a
    variable referring to a dimension outside its group finds the same dimension; none does), but
    compliance-checker 6.1's ``check_invalid_same_named_dimension_across_groups`` compares the
    ``time`` dimensions of the root's child groups and flags any two (ioos/compliance-checker#1215
    reports the same check failing on files without groups).

    References
    ----------
    Cheng, Brach & Dunn (2002), Fig. 5

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> save_phase_portraits(phase_portraits(c, [0.5]), "portraits.nc").exists()
    True
    """
    names = [f"portraits/portrait_{i}" for i in range(len(portraits))]
    shared = {k: v for k, v in portraits[0].attrs.items() if (k == "parameter_source" or k.startswith("contact_"))
              and all(np.array_equal(ds.attrs.get(k), v) for ds in portraits)} if portraits else {}
    root = xr.Dataset(attrs={
        "title": "Phase portraits of normal impacts (Cheng, Brach & Dunn 2002, Fig. 5)",
        "portraits": " ".join(names),
        "normal_speeds": np.array([float(ds.attrs.get("normal_speed", math.nan)) for ds in portraits]),
        "normal_speeds_units": "m s-1",
        "references": PAPER_REFERENCE,
        **shared,
    })
    return write_netcdf_groups({None: root, **dict(zip(names, portraits))}, path)


def dynamics_summary(contact: Contact, speeds: Sequence[float]) -> xr.Dataset:
    """The numbers of the nonlinear analysis (Eqs. (29)-(38)) for a contact at some normal speeds.

    Parameters
    ----------
    contact : Contact
        Must be adhesive (f0 > 0) for the nondimensional analysis.
    speeds : sequence of float
        Incident normal speeds. [m/s]

    Returns
    -------
    xarray.Dataset
        Scalars ``mass`` [kg], ``length_scale`` X [m], ``time_scale`` T [s],
        ``critical_velocity`` v_c (Eq. (38), NaN with a fixed damping reference speed) [m/s] and
        ``capture_velocity`` (largest captured normal speed, by bisection) [m/s]; along ``speed``
        [m/s]: ``C1``, ``C2``, ``C`` (Eqs. (31)-(35)) [-], ``equilibrium_type`` (text) and
        ``asymptotic_frequency`` omega_f (NaN for C >= 2) [rad/s].

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (29)-(38)

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> ds = dynamics_summary(c, [1e-6, 0.5, 10.0])
    >>> ds["equilibrium_type"].values.tolist(), round(float(ds["capture_velocity"]), 4)
    (['sink', 'spiral sink', 'spiral sink'], 1.4492)
    """
    speeds = np.asarray([float(v) for v in speeds])
    c12 = np.array([contact.nondimensional_damping(v) for v in speeds]).reshape(-1, 2)
    c = c12.sum(axis=1)
    omega_f = np.array([float(asymptotic_frequency(contact, v)) for v in speeds])
    try:
        v_c = float(critical_velocity(contact))
    except ValueError:
        v_c = math.nan
    ds = xr.Dataset(
        {
            "mass": ((), contact.mass, {"units": "kg", "long_name": "sphere mass m"}),
            "length_scale": ((), contact.length_scale, {"units": "m", "long_name": "length scale X = 2 pi f0 / K, Eq. (29)"}),
            "time_scale": ((), contact.time_scale, {"units": "s", "long_name": "time scale T, Eq. (30) corrected"}),
            "critical_velocity": ((), v_c, {"units": "m s-1", "long_name": "critical velocity v_c (C = 2), Eq. (38)"}),
            "capture_velocity": ((), float(capture_velocity(contact)), {
                "units": "m s-1", "long_name": "normal capture velocity (below it the sphere is captured)"}),
            "C1": ("speed", c12[:, 0], {"units": "1", "long_name": "C1 = C_H X / T, Eq. (31)"}),
            "C2": ("speed", c12[:, 1], {"units": "1", "long_name": "C2 = C_A X / T, Eq. (32)"}),
            "C": ("speed", c, {"units": "1", "long_name": "total damping C = C1 + C2, Eq. (35)"}),
            "equilibrium_type": ("speed", np.array([equilibrium_type(x) for x in c], dtype=object), {
                "long_name": "nature of the equilibrium (1, 0), Eq. (36)"}),
            "asymptotic_frequency": ("speed", omega_f, {
                "units": "rad s-1", "long_name": "asymptotic angular frequency sqrt(4 - C^2) / (2 T) (Eq. (37) corrected)"}),
        },
        coords={"speed": ("speed", speeds, {"units": "m s-1", "long_name": "incident normal speed"})},
        attrs={"title": "Nonlinear dynamics of the normal contact (Cheng, Brach & Dunn 2002, Eqs. 28-38)",
               "references": PAPER_REFERENCE},
    )
    ds.attrs.update(contact_attributes(contact))
    return ds
