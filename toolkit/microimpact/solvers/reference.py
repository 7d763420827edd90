"""Reference solver: the full 3-D contact equations integrated with :func:`scipy.integrate.solve_ivp`.

This module integrates every degree of freedom of the model of Cheng, Brach & Dunn (2002),
Aerosol Sci. Technol. 36:1081-1093, doi:10.1080/02786820290092221 -- the normal motion, Eq. (27),
the two tangential translations, Eqs. (16)-(17), and the three spins, Eqs. (18)-(20) -- with event
location for separation, capture, the end of sliding and the end of twisting. It makes no use of
the decoupling of the normal motion from the rest, so it can be used to verify the fast engine and
as the accurate end of a work-precision benchmark. It is slow (pure-Python right-hand side).

Equations (nondimensional, see *Scales* below; primes are d/dtau)
------------------------------------------------------------------
Physical state: xi = x / L the penetration (x = -n), y = xi', v = (v_t, v_t') the centre velocity
in units of V = L / T_c, w = r omega / V the spins (omega_n, omega_t, omega_t') as rim speeds, D the
dissipated energy in units of m V^2 and J = int |F_n| dtau the friction impulse in units of m V.
With s = sqrt(xi):

* normal, Eq. (27):       xi'' = -a_H s^3 (1 + c_1 y) + a_A s (1 - c_2 y) =: -F_n
* slip of the contact point (coefficients.slip_velocity): u_t = v_t + w_t', u_t' = v_t' - w_t
* friction, Eqs. (16)-(17): v' = F = -f |F_n| u / |u| while sliding, also while F_n < 0
  ("pulling" friction); F = 0 once sliding has ended (rolling, no rolling resistance)
* Eqs. (19)-(20) as printed: w_t'' = k F_t, w_t' = -k F_t', with k = m r^2 / I (5/2 for a
  homogeneous sphere), so that u' = (1 + k) F
* twist, Eq. (18) in a derived form (see :func:`microimpact.model.law.twist_friction_torque`):
  w_n' = -k (3 pi / 16) f sqrt(L / r) s |F_n| sign(w_n) until w_n reaches 0, then w_n = 0
* dissipation: D' = (a_H c_1 s^3 + a_A c_2 s) y^2 + f |F_n| |u| + (3 pi / 16) f sqrt(L / r) s |F_n| |w_n|
* J' = |F_n|

The nondimensional contact energy E = y^2 / 2 + (2/5) a_H xi^(5/2) - (2/3) a_A xi^(3/2) obeys
E' = -(a_H c_1 s^3 + a_A c_2 s) y^2 <= 0, so E < 0 is an exact capture test.

Integration variable (Sundman transformation)
---------------------------------------------
In tau the force ~ sqrt(xi) ~ sqrt(tau) is not smooth where contact starts and ends, which costs
adaptive solvers order and accuracy exactly where e_n is decided. The solver therefore integrates
the state ``(s, y, v_t, v_t', w_n, w_t, w_t', D, J, tau)`` in a new independent variable sigma
with dtau/dsigma = s: then ds/dsigma = y / 2, dy/dsigma = s xi'' and every other derivative is
s times its tau-derivative. All right-hand sides are polynomials in (s, y) (times the friction
direction), smooth through s = 0, so first contact (s = y0 sigma / 2) and separation (a transversal
zero of s) are resolved at full order; tau is carried as a state.

Kinks of |F_n|: F_n changes sign (adhesion pulling vs. Hertz pushing) two or more times per
contact, and |F_n| drives J, friction and twist. Each sign change is located as an event on
xi'' / s (the trivial root s = 0 removed) and the integration restarts with the new sign; inside a
phase |F_n| = fn_sign * xi'' is smooth (this cut the error of J from ~4e-8 to ~4e-12 at
rtol = 1e-10 in a conservative adhesive impact).

Scales
------
* Adhesive contact (f0 > 0): the paper's scales, Eqs. (29)-(32) with T corrected (see
  :mod:`microimpact.model.contact`): L = X = 2 pi f0 / K, T_c = T, so a_H = a_A = 1 and (c_1, c_2) =
  (C1, C2) = ``contact.nondimensional_damping(v_n)``; Eq. (28) exactly.
* No adhesion (f0 = 0): X = 0 and T is infinite, so the Hertz impact scales are used instead:
  L = x* = (5 m v_n^2 / (4 K sqrt(r)))^(2/5) (the undamped maximum penetration) and T_c = x* / v_n,
  giving a_H = 5/4, a_A = 0, c_1 = C_H v_n, c_2 = C_A v_n, y(0) = 1. (Departure: the paper only
  gives the adhesive scaling.)

Events and switching
--------------------
* separation: s = 0 with s decreasing (terminal; outcome "rebound").
* capture: E = 0 with E decreasing (terminal). If nothing tangential is left (f = 0, or no slip and
  no twist left) the run stops there ("capture"); otherwise the captured oscillation is integrated
  until sliding and twisting have both ended ("slip and twist ended") or the motion has settled
  ("settled", see :func:`_tail_constants`).
* end of sliding: the slip direction is constant (u' is parallel to u, the inertia being isotropic
  in the tangent plane), so the signed projection p = u . e0 of the slip on its initial direction
  e0 = u0 / |u0| falls through zero *transversally* (p' = -(1 + k) f |F_n| < 0 whenever F_n != 0)
  at the instant sliding stops. That root is well conditioned, unlike the tangential zero of |u|
  or the ill-conditioned crossing of |u|^2 - eps (slope ~ sqrt(eps)). To keep the right-hand side
  smooth across the root inside the step that locates it, the friction direction is written
  sign(p) u / |u|: identical to u / |u| while sliding (p > 0), and the smooth continuation of the
  pre-root motion past it. After the event the integration restarts from the event state with
  F = 0; sliding never restarts.
* end of twisting: w_n = 0, handled in the same way with sign(w_n(0)) in place of sign(w_n); after
  the event w_n is set to exactly 0.
* sign changes of F_n (terminal, restart; see above).
* turning points y = 0 (non-terminal) give the maximum penetration.

Cost: a captured impact whose sliding or twisting outlasts capture costs several times a rebound
(one restart per sign change of F_n in the tail).

Everything at the interface is SI; everything inside is nondimensional.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from scipy.integrate import solve_ivp

from microimpact.model import law
from microimpact.solvers import DEFAULT_RTOL, Deadline, SolverError, TimeBudgetExceeded
from microimpact.model.coefficients import impact_coefficients
from microimpact.model.kinematics import ImpactResult, incident_velocity
from microimpact.model.contact import Contact
from microimpact.solvers.solution import NormalSolution

__all__ = [
    "ReferenceSolverError",
    "TimeBudgetExceeded",
    "simulate_reference",
    "reference_trajectory",
]

#: Longest nondimensional time allowed before an outcome (rebound or capture). A rebound lasts
#: O(1)-O(10) time units in either scaling; 1e4 is generous.
_MAX_TAU_CONTACT = 1.0e4

#: Right-hand-side evaluations allowed per impact (a few thousand are typical; a captured tail
#: with weak damping takes up to ~1e6). Guards against a stalled step-size sequence.
_MAX_RHS_EVALS = 20_000_000

#: Restarts allowed (F_n changes sign twice per cycle of a captured oscillation).
_MAX_PHASES = 200_000

#: Phase-space radius below which the linearised settle bound is trusted (|xi - 1|, |y| < 0.05).
_LINEAR_RADIUS = 0.05

#: Safety factor on the linearised tail bound, covering the O(radius) nonlinear corrections of
#: force and damping within the radius above (at most ~10 %) with a wide margin.
_TAIL_SAFETY = 2.0

# State indices.
_S, _Y, _VT, _VTP, _WN, _WT, _WTP, _D, _J, _TAU = range(10)


class ReferenceSolverError(SolverError):
    """The reference integration failed or ran out of time without an outcome.

    Examples
    --------
    One ``except`` catches the failure of any solver:

    >>> issubclass(ReferenceSolverError, SolverError)
    True
    >>> issubclass(ReferenceSolverError, RuntimeError)
    True
    """


# --------------------------------------------------------------------------- validation
def _as_real(name: str, value) -> float:
    if isinstance(value, bool):
        raise ValueError(f"{name} must be a real number, got {value!r}")
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(out):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return out


def _validate_speed(name: str, speed) -> float:
    v = _as_real(name, speed)
    if v <= 0.0:
        raise ValueError(f"{name} must be > 0, got {speed!r}")
    return v


def _validate_common(rtol, atol, settle_tolerance):
    rtol = _as_real("rtol", rtol)
    atol = _as_real("atol", atol)
    if rtol <= 0.0:
        raise ValueError(f"rtol must be > 0, got {rtol!r}")
    if atol <= 0.0:
        raise ValueError(f"atol must be > 0, got {atol!r}")
    if settle_tolerance is None:
        settle_tolerance = rtol
    settle_tolerance = _as_real("settle_tolerance", settle_tolerance)
    if settle_tolerance <= 0.0:
        raise ValueError(f"settle_tolerance must be > 0, got {settle_tolerance!r}")
    return rtol, atol, settle_tolerance


# --------------------------------------------------------------------------- scales
@dataclass(frozen=True)
class _Scales:
    """Nondimensionalisation of one impact (see the module docstring)."""

    length: float  # L [m]
    time: float  # T_c [s]
    a_h: float  # Hertz coefficient [-]
    a_a: float  # adhesion coefficient [-]
    c1: float  # Hertz damping, C_H L / T_c [-]
    c2: float  # adhesion damping, C_A L / T_c [-]
    k_rot: float  # m r^2 / I [-]
    twist: float  # (3 pi / 16) sqrt(L / r) [-], times f gives the twist torque factor
    mass: float  # [kg]
    radius: float  # [m]

    @property
    def speed(self) -> float:
        """Velocity scale V = L / T_c. [m/s]"""
        return self.length / self.time

    @property
    def adhesive(self) -> bool:
        return self.a_a > 0.0


def _scales(contact: Contact, normal_speed: float) -> _Scales:
    """Scales for an impact with incident normal speed ``normal_speed`` [m/s]."""
    base, _, c1, c2 = law.nondimensional_impact(contact, normal_speed)
    return _Scales(
        length=base.length,
        time=base.time,
        a_h=base.a_hertz,
        a_a=base.a_adhesion,
        c1=c1,
        c2=c2,
        k_rot=contact.mass * contact.radius * contact.radius / contact.moment_of_inertia,
        twist=law.TWIST_TORQUE_FACTOR * math.sqrt(base.length / contact.radius),
        mass=contact.mass,
        radius=contact.radius,
    )


def _energy(sc: _Scales, s: float, y: float) -> float:
    """Nondimensional normal contact energy (:func:`microimpact.model.law.nondimensional_energy`)."""
    return law.nondimensional_energy(s, y, sc.a_h, sc.a_a)


def _tail_constants(c: float) -> tuple[float, float, float]:
    """Constants (b, sqrt(kappa), sigma) of the linearised settle bound about (xi, y) = (1, 0).

    Near the adhesive equilibrium the motion is z' = J z with z = (x, y), x = xi - 1,
    J = [[0, 1], [-1, -c]] (Eq. 35), c = C1 + C2, and -F_n = y' = -x - c y, so the friction
    impulse to come, int |F_n| dtau, is exactly the total variation of y to come. Take the quadratic
    form W = x^2 + b x y + y^2 (positive definite for |b| < 2). Then

        -W' = z^T P z,  P = [[b, b c / 2], [b c / 2, 2 c - b]],

    and W' <= -2 sigma W with 2 sigma = lambda_min(Q^-1 P), Q = [[1, b/2], [b/2, 1]]. Also
    |F_n| = |x + c y| <= sqrt(kappa W) with kappa = a^T Q^-1 a, a = (1, c). Hence the friction
    impulse still to come obeys

        int_tau^inf |F_n| dtau <= sqrt(kappa W(tau)) / sigma.

    For c < 2 the choice b = c gives W' = -c W exactly (2 sigma = c, the decay of the envelope
    A e^(-c tau / 2) of the damped oscillation) and kappa = 1 / (1 - c^2/4) = 1 / omega_f^2. For
    c >= 2 (over-damped, incident speeds below the critical speed of Eq. 38) b = 4c / (4 + c^2),
    half the largest b that keeps P positive definite; sigma then is of the order of the slow
    eigenvalue 1/c.

    The nonlinear terms change force and damping by O(|z|) relative, so the bound is used only
    for |z| < 0.05 and with a safety factor 2. Checked against runs continued to a 1e-12
    tolerance: the impulse actually missing is ~0.3 of the requested fraction.
    """
    # b = c up to 1.9 (beyond, Q -> singular and kappa -> inf near critical damping).
    b = min(c, 1.9) if c < 2.0 else 4.0 * c / (4.0 + c * c)
    q = np.array([[1.0, 0.5 * b], [0.5 * b, 1.0]])
    p = np.array([[b, 0.5 * b * c], [0.5 * b * c, 2.0 * c - b]])
    lam = np.linalg.eigvals(np.linalg.solve(q, p)).real.min()
    sigma = 0.5 * float(lam)
    a = np.array([1.0, c])
    kappa = float(a @ np.linalg.solve(q, a))
    if not sigma > 0.0:  # pragma: no cover - cannot happen for c > 0
        raise ReferenceSolverError(f"no decay rate for the settle bound at C = {c!r}")
    return b, math.sqrt(kappa), sigma


# --------------------------------------------------------------------------- right-hand side
def _make_rhs(
    sc: _Scales,
    f: float,
    e0: tuple[float, float],
    sliding: bool,
    twist_sign: float,
    fn_sign: float,
    counter: list[int],
):
    """Right-hand side d/dsigma for one mode (Sundman form; see :func:`simulate_reference`).

    ``twist_sign`` is sign(w_n(0)) while twisting, else 0; ``fn_sign`` is the sign of xi'' = -F_n
    in this phase, so that |F_n| = fn_sign * xi'' is smooth within the phase. The state is
    (s, y, v_t, v_t', w_n, w_t, w_t', D, J, tau) with s = sqrt(xi) and dtau/dsigma = s.
    ``counter`` is [evaluations so far across phases, deadline (time.perf_counter) [s], budget [s]];
    past the deadline the right-hand side raises :class:`TimeBudgetExceeded`.
    """
    a_h, a_a, c1, c2, k = sc.a_h, sc.a_a, sc.c1, sc.c2, sc.k_rot
    tw = f * sc.twist
    e0t, e0p = e0
    sqrt = math.sqrt

    def rhs(_sigma, z):
        counter[0] += 1
        if counter[0] % 512 == 0 and time.perf_counter() > counter[1]:
            raise TimeBudgetExceeded(
                f"reference solver exceeded its time budget of {counter[2]:g} s after {counter[0]} "
                f"right-hand-side evaluations, at tau = {z[_TAU]:.6g} (a stiff case: the engine's "
                "inertia-free limit covers it)")
        if counter[0] > _MAX_RHS_EVALS:
            raise ReferenceSolverError(
                f"more than {_MAX_RHS_EVALS} right-hand-side evaluations (stalled step size?) at "
                f"tau = {z[_TAU]:.6g}"
            )
        s, y = z[0], z[1]
        s3 = s * s * s
        acc = law.nondimensional_acceleration(s, s3, y, c1, c2, a_h, a_a)  # xi'' = -F_n
        abs_fn = fn_sign * acc  # |F_n| on the physical side, smooth across the phase's end
        d_rate = law.nondimensional_dissipation_rate(s, s3, y, c1, c2, a_h, a_a)
        ft = fp = 0.0
        if sliding:
            ut = z[2] + z[6]
            up = z[3] - z[5]
            nu = sqrt(ut * ut + up * up)
            if nu > 0.0:
                g = -f * abs_fn / nu
                if ut * e0t + up * e0p < 0.0:  # smooth continuation past the slip-end root
                    g = -g
                ft, fp = g * ut, g * up
            else:
                ft, fp = -f * abs_fn * e0t, -f * abs_fn * e0p
            d_rate -= ft * ut + fp * up  # friction power -F . u
        dwn = 0.0
        if twist_sign != 0.0:
            torque = tw * s * abs_fn * twist_sign  # >= 0 on the physical side
            dwn = -k * torque
            d_rate += torque * z[4]
        # d/dsigma = s d/dtau, except ds/dsigma = y / 2.
        return [0.5 * y, s * acc, s * ft, s * fp, s * dwn, -k * s * fp, k * s * ft, s * d_rate, s * abs_fn, s]

    return rhs


def _event(fun, terminal: bool, direction: float):
    fun.terminal = terminal
    fun.direction = direction
    return fun


# --------------------------------------------------------------------------- public API
def _check_paper_law(contact) -> None:
    """ValueError naming the field if ``contact`` selects a law this integration does not contain."""
    if not isinstance(contact, Contact):
        return  # (the type is checked where the contact is first used, with its own message)
    chosen = {"tangential_model": "rigid", "friction_model": "net"}
    if contact.adhesion_line_force > 0.0:
        chosen["normal_model"] = "ring"
    for field, paper in chosen.items():
        if getattr(contact, field) != paper:
            raise ValueError(f"simulate_reference integrates the paper's law ({field}={paper!r}); the contact selects "
                             f"{field}={getattr(contact, field)!r}: use simulate_impact(..., method='reference')"
                             + ("" if field == "normal_model" else ", which covers the paper's tangential contact only"))
    if contact.rolling_friction > 0.0:
        raise ValueError(f"simulate_reference has no rolling resistance; the contact selects "
                         f"rolling_friction={contact.rolling_friction!r}")


def simulate_reference(contact: Contact, speed: float, incidence_deg: float = 0.0, azimuth_deg: float = 0.0,
                       omega: Sequence[float] = (0.0, 0.0, 0.0), *, rtol: float = DEFAULT_RTOL, atol: float = 1e-13,
                       method: str = "DOP853", max_step: float = math.inf, settle_tolerance: float | None = None,
                       time_budget: float | None = None) -> ImpactResult:
    """Integrate one impact with the full 3-D equations (reference solution).

    Parameters
    ----------
    contact : Contact
        Contact parameters. The damping coefficients use the incident normal speed as the
        reference speed of Eqs. (14)-(15) unless ``contact.damping_reference_speed`` is set.
    speed : float
        Magnitude of the incident velocity, > 0. [m/s]
    incidence_deg : float
        Incidence angle alpha from the surface normal, in [0, 90). [deg]
    azimuth_deg : float
        Azimuth theta of the tangential velocity, from t towards t'. [deg]
    omega : sequence of 3 floats
        Incident spin (omega_n, omega_t, omega_t'). [rad/s]
    rtol, atol : float
        Tolerances passed to :func:`scipy.integrate.solve_ivp`; they apply to the
        nondimensional state (all components O(1) for an adhesive impact). [-]
    method : str
        A :func:`scipy.integrate.solve_ivp` method; explicit ones ("DOP853", "RK45") are
        appropriate (the problem is not stiff).
    max_step : float
        Largest step in the integration variable sigma (dtau = s dsigma with s = sqrt(x / X), which
        is O(1) in contact; see the module docstring). [-]
    settle_tolerance : float, optional
        After capture with sliding or twisting still going on: stop when the friction impulse
        still to come is bounded by ``settle_tolerance`` times the impulse so far. Default
        ``rtol``. [-]
    time_budget : float or Deadline, optional
        Wall-clock budget of the integration; None: no budget; a
        :class:`~microimpact.solvers.Deadline`: the budget of an enclosing computation. [s]

    Returns
    -------
    ImpactResult
        All fields in SI units; ``method`` is ``"reference:<method>"``. ``stop_reason`` is
        "separation" (rebound), "capture" (captured, nothing tangential left to integrate),
        "slip and twist ended" or "settled" (captured, tail integrated). For a captured sphere the
        reported normal velocity is 0, ``contact_time`` is inf and ``final_contact_energy`` is V(X),
        the contact energy at rest at the equilibrium (what was left of the oscillation where the
        integration stopped is counted as dissipated).

    Raises
    ------
    ValueError
        For a non-finite or non-positive speed, an incidence outside [0, 90), a non-finite
        azimuth or spin, or bad tolerances; the message names the argument and the value. For a
        contact that selects a sub-model this integration does not contain (an adhesive JKR or DMT
        law, tangential compliance, the pulloff limit, rolling resistance): it would otherwise
        answer for the paper's law; :func:`microimpact.simulate_impact` with ``method="reference"``
        covers the JKR and DMT laws.
    ReferenceSolverError
        If solve_ivp fails or no outcome is reached within a generous time.
    TimeBudgetExceeded
        If the integration runs past ``time_budget`` seconds (checked every 512 right-hand-side
        evaluations, i.e. every few milliseconds); the message gives the budget and the progress.

    Notes
    -----
    Departures from the printed paper: Eq. (30) corrected (T, not T^2); Eq. (18) replaced by the
    derived twist torque (3 pi / 16) f a |F_n|; with f0 = 0 the Hertz scales replace X, T. The
    paper used a fixed-step Runge-Kutta-Gill method; this uses adaptive solve_ivp with events.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (8)-(20) and (27)

    Virtanen, P. et al. (2020), SciPy 1.0: fundamental algorithms for scientific computing in
    Python, Nat. Methods 17:261-272, doi:10.1038/s41592-019-0686-2 (``solve_ivp``, DOP853,
    ``brentq``)

    Examples
    --------
    The independent yardstick of the compiled solvers (scipy): they agree to ~1e-8 at the default
    tolerances:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> from microimpact.solvers.impact import simulate_impact
    >>> abs(simulate_reference(c, 10.0, 30.0).e_n - simulate_impact(c, 10.0, 30.0).e_n) < 1e-7
    True
    """
    _check_paper_law(contact)
    speed, incidence, azimuth, omega_in = _validate_impact(speed, incidence_deg, azimuth_deg, omega)
    rtol, atol, settle_tol = _validate_common(rtol, atol, settle_tolerance)
    max_step = _validate_max_step(max_step)
    vel_in = incident_velocity(speed, incidence, azimuth)
    sc = _scales(contact, -vel_in[0])
    deadline = Deadline.start(time_budget, "reference solver")
    run = _Run.start(sc, contact.friction, vel_in, omega_in, settle_tol)
    if deadline.limited:
        run.counter[1:] = [deadline.end, deadline.budget]
    _run_to_outcome(run, {"method": method, "rtol": rtol, "atol": atol, "max_step": max_step})
    return _reference_result(contact, sc, run, vel_in, omega_in, method)


def _validate_max_step(max_step) -> float:
    """``max_step`` as a float, checked to be > 0 (ValueError)."""
    max_step = float(max_step)
    if not max_step > 0.0:
        raise ValueError(f"max_step must be > 0, got {max_step!r}")
    return max_step


def _run_to_outcome(run: _Run, solver: dict) -> None:
    """Integrate ``run`` phase by phase (:func:`_run_phase`, with the ``solve_ivp`` options ``solver``),
    applying each fired event, until it has a stop reason (ReferenceSolverError after
    :data:`_MAX_PHASES` restarts)."""
    while run.stop_reason is None:
        run.n_phases += 1
        if run.n_phases > _MAX_PHASES:
            raise ReferenceSolverError(f"more than {_MAX_PHASES} restarts without an outcome")
        fired = _run_phase(run, solver)
        if fired is not None:
            run.apply(fired)


def _validate_impact(speed, incidence_deg, azimuth_deg, omega):
    """(speed [m/s], incidence [deg], azimuth [deg], spin (3,) [rad/s]) as floats, checked."""
    speed = _validate_speed("speed", speed)
    incidence = _as_real("incidence_deg", incidence_deg)
    if not 0.0 <= incidence < 90.0:
        raise ValueError(f"incidence_deg must lie in [0, 90), got {incidence_deg!r}")
    azimuth = _as_real("azimuth_deg", azimuth_deg)
    try:
        omega_list = list(omega)
    except TypeError:
        raise ValueError(f"omega must be a sequence of 3 spins, got {omega!r}") from None
    if len(omega_list) != 3:
        raise ValueError(f"omega must have 3 components (omega_n, omega_t, omega_t'), got {omega!r}")
    return speed, incidence, azimuth, tuple(_as_real(f"omega[{i}]", w) for i, w in enumerate(omega_list))


@dataclass
class _Run:
    """State of one reference integration across its phases (restarts at events).

    ``z`` is the state (s, y, v_t, v_t', w_n, w_t, w_t', D, J, tau) at the start of the next
    phase, ``sigma0`` its integration variable; the flags say which modes are active.
    """

    sc: _Scales
    friction: float
    z: np.ndarray
    e0: tuple[float, float]  # initial slip direction
    sliding: bool
    twisting: bool
    twist_sign: float  # sign(w_n(0)) while twisting
    fn_sign: float  # sign of xi'' = -F_n in the current phase
    settle: object  # settle event (adhesive, damped) or None
    tail_time: float
    sigma0: float = 0.0
    sigma_limit: float = math.inf  # set by start() (read at run time, tests shrink it)
    captured: bool = False
    await_turn: bool = False
    tau_capture: float = math.nan
    tau_slip: float = math.nan
    slip_ended: bool = False
    stop_reason: str | None = None
    n_phases: int = 0
    counter: list = field(default_factory=lambda: [0, math.inf, math.inf])
    turn_xi: list = field(default_factory=list)

    @classmethod
    def start(cls, sc: _Scales, friction: float, vel_in, omega_in, settle_tol: float) -> "_Run":
        """The state at first contact (nondimensional, see the module docstring)."""
        v, r = sc.speed, sc.radius
        z0 = np.array([0.0, -vel_in[0] / v, vel_in[1] / v, vel_in[2] / v, r * omega_in[0] / v,
                       r * omega_in[1] / v, r * omega_in[2] / v, 0.0, 0.0, 0.0])
        u0 = (z0[_VT] + z0[_WTP], z0[_VTP] - z0[_WT])
        u0_norm = math.hypot(*u0)
        twisting = friction > 0.0 and z0[_WN] != 0.0
        # Sign of xi'' = -F_n just after first contact: xi''/s -> a_A (1 - c2 y0) as s -> 0;
        # without adhesion (or if that vanishes) the Hertz term -a_H s^2 (1 + c1 y0) < 0 decides.
        g0 = law.nondimensional_acceleration(1.0, 0.0, z0[_Y], sc.c1, sc.c2, sc.a_h, sc.a_a)
        settle, tail_time = _settle_event(sc, settle_tol)
        return cls(
            sc=sc, friction=friction, z=z0,
            e0=(u0[0] / u0_norm, u0[1] / u0_norm) if u0_norm > 0.0 else (1.0, 0.0),
            sliding=friction > 0.0 and u0_norm > 0.0, twisting=twisting,
            twist_sign=math.copysign(1.0, z0[_WN]) if twisting else 0.0,
            fn_sign=1.0 if g0 > 0.0 else -1.0, settle=settle, tail_time=tail_time,
            sigma_limit=_MAX_TAU_CONTACT,
        )

    def events(self) -> dict:
        """The events of the next phase by name (all on the nondimensional state)."""
        sc, e0, tsign = self.sc, self.e0, self.twist_sign
        # after a capture with nothing tangential left, run on to the first turning point only:
        # the largest penetration (the energy falls afterwards)
        ev = {"separation": _event(lambda _t, z: z[_S], True, -1.0),
              "turn": _event(lambda _t, z: z[_Y], self.await_turn, -1.0)}
        if not self.captured and sc.adhesive:
            ev["capture"] = _event(lambda _t, z: _energy(sc, z[_S], z[_Y]), True, -1.0)
        if self.sliding:
            ev["slip"] = _event(lambda _t, z: (z[_VT] + z[_WTP]) * e0[0] + (z[_VTP] - z[_WT]) * e0[1], True, -1.0)
        if self.twisting:
            ev["twist"] = _event(lambda _t, z: z[_WN] * tsign, True, -1.0)
        if self.captured and self.settle is not None:
            ev["settle"] = _event(self.settle, True, -1.0)
        # xi'' / s: changes sign with F_n, without the trivial root s = 0 at first contact
        ev["force"] = _event(lambda _t, z: law.nondimensional_acceleration(
            1.0, z[_S] * z[_S], z[_Y], sc.c1, sc.c2, sc.a_h, sc.a_a), True, -self.fn_sign)
        return ev

    def apply(self, fired: str) -> None:
        """Update the modes after the terminal event ``fired`` (the state z is at the event)."""
        tau_end = self.z[_TAU]
        if fired == "separation":
            if self.captured:
                raise ReferenceSolverError(
                    "separation after capture (E < 0): numerical error exceeds the energy margin; "
                    "tighten rtol/atol"
                )
            self.stop_reason = "separation"
        elif fired == "turn":
            self.stop_reason = "capture"
        elif fired == "capture":
            self.captured = True
            self.tau_capture = tau_end
            if not (self.sliding or self.twisting) or self.settle is None:
                if self.turn_xi or self.z[_Y] <= 0.0:
                    self.stop_reason = "capture"
                else:
                    self.await_turn = True
                    # an overdamped sphere may creep to the equilibrium without turning: bounded
                    self.sigma_limit = self.sigma0 + _MAX_TAU_CONTACT
            else:
                # s = sqrt(xi) -> 1 in the tail, so sigma and tau advance alike there.
                self.sigma_limit = self.sigma0 + self.tail_time + _MAX_TAU_CONTACT
        elif fired == "slip":
            self.sliding = False
            self.slip_ended = True
            self.tau_slip = tau_end
        elif fired == "twist":
            self.twisting = False
            self.z[_WN] = 0.0
        elif fired == "settle":
            self.stop_reason = "settled"
        elif fired == "force":
            self.fn_sign = -self.fn_sign
        if self.stop_reason is None and self.captured and not (self.sliding or self.twisting) and not self.await_turn:
            self.stop_reason = "slip and twist ended"


def _settle_event(sc: _Scales, settle_tol: float):
    """(settle event, time to allow for the tail) of a damped adhesive contact, else (None, nan).

    The event crosses zero once the linearised bound of :func:`_tail_constants` on the friction
    impulse still to come is below ``settle_tol`` times the impulse so far.
    """
    c_tot = sc.c1 + sc.c2
    if not (sc.adhesive and c_tot > 0.0):
        return None, math.nan
    b_w, sqrt_kappa, sigma = _tail_constants(c_tot)

    def ev_settle(_t, z):
        x = z[_S] * z[_S] - 1.0
        y = z[_Y]
        w = x * x + b_w * x * y + y * y
        tail = _TAIL_SAFETY * sqrt_kappa * math.sqrt(max(w, 0.0)) / sigma
        return max(tail - settle_tol * z[_J], math.hypot(x, y) - _LINEAR_RADIUS)

    return ev_settle, 10.0 * (math.log(1.0 / settle_tol) + 10.0) / sigma


def _run_phase(run: _Run, solver: dict) -> str | None:
    """Integrate one phase with solve_ivp; returns the terminal event that ended it (run.z, run.sigma0
    then hold its state), or None when the run ends without one (run.stop_reason set)."""
    events = run.events()
    rhs = _make_rhs(run.sc, run.friction, run.e0, run.sliding, run.twist_sign if run.twisting else 0.0,
                    run.fn_sign, run.counter)
    sol = solve_ivp(rhs, (run.sigma0, run.sigma_limit), run.z, events=list(events.values()), **solver)
    tau_last = sol.y[_TAU, -1]
    if sol.status == -1:
        raise ReferenceSolverError(
            f"solve_ivp ({solver['method']}) failed at tau = {tau_last:.6g} "
            f"(t = {tau_last * run.sc.time:.6g} s): {sol.message}"
        )
    run.turn_xi.extend(float(v[_S]) ** 2 for v in sol.y_events[1])
    if sol.status == 0 and run.await_turn:
        # crept to the equilibrium without turning: the supremum of xi is its limit, 1
        run.turn_xi.append(max(1.0, float(sol.y[_S, -1]) ** 2))
        run.z = sol.y[:, -1]
        run.stop_reason = "capture"
        return None
    if sol.status == 0:
        what = "captured tail did not settle" if run.captured else "no separation and no capture"
        raise ReferenceSolverError(
            f"{what} by nondimensional time {tau_last:.6g} ({tau_last * run.sc.time:.6g} s); state {sol.y[:, -1]!r}"
        )
    # Which terminal event stopped the run: the one whose last event time is the end time.
    run.sigma0 = sol.t[-1]
    for (name, ev), t_ev, y_ev in zip(events.items(), sol.t_events, sol.y_events):
        if ev.terminal and len(t_ev) and t_ev[-1] == run.sigma0:
            run.z = np.array(y_ev[-1], dtype=float)
            return name
    raise ReferenceSolverError(f"solve_ivp stopped without a recognised event: {sol.message}")  # pragma: no cover


def _reference_result(contact: Contact, sc: _Scales, run: _Run, vel_in, omega_in, method: str) -> ImpactResult:
    """The ImpactResult in SI units of a finished reference run."""
    z, T, V, r, m = run.z, sc.time, sc.speed, sc.radius, sc.mass
    vt, vtp = z[_VT] * V, z[_VTP] * V
    omega_out = (z[_WN] * V / r, z[_WT] * V / r, z[_WTP] * V / r)
    dissipated = float(z[_D] * m * V * V)
    captured = run.captured
    if captured:
        vel_out = (0.0, vt, vtp)
        contact_time = math.inf
        capture_time = run.tau_capture * T
        # settled at rest at the equilibrium: the normal energy left at the stop is dissipated too
        final_contact = _energy(sc, 1.0, 0.0) * m * V * V
        dissipated += (_energy(sc, z[_S], z[_Y]) - _energy(sc, 1.0, 0.0)) * m * V * V
    else:
        vel_out = (-z[_Y] * V, vt, vtp)
        contact_time = z[_TAU] * T
        capture_time = math.nan
        final_contact = 0.0
    coeffs = impact_coefficients(m, contact.moment_of_inertia, vel_in, omega_in, vel_out, omega_out, captured)
    max_xi = max(run.turn_xi) if run.turn_xi else float(z[_S]) ** 2
    return ImpactResult(
        outcome="capture" if captured else "rebound",
        **{k: float(coeffs[k]) for k in ("e_n", "mu_t", "mu_tp", "K_L", "K_t")},
        velocity_in=tuple(float(v) for v in vel_in),
        omega_in=omega_in,
        velocity_out=tuple(float(v) for v in vel_out),
        omega_out=tuple(float(w) for w in omega_out),
        contact_time=float(contact_time),
        capture_time=float(capture_time),
        max_penetration=float(max_xi * sc.length),
        slip_ended=run.slip_ended,
        slip_end_time=float(run.tau_slip * T),
        friction_impulse=float(z[_J] * m * V),
        dissipated_energy=dissipated,
        final_contact_energy=float(final_contact),
        method=f"reference:{method}",
        stop_reason=run.stop_reason,
    )


def reference_trajectory(contact: Contact, normal_speed: float, *, duration: float | None = None,
                         rtol: float = DEFAULT_RTOL, atol: float = 1e-13, method: str = "DOP853",
                         max_step: float = math.inf) -> NormalSolution:
    """Normal motion, Eq. (27), of an impact at the solver's steps.

    The normal motion does not depend on the tangential state, so only (xi, y, D) are integrated.

    Parameters
    ----------
    contact : Contact
    normal_speed : float
        Incident normal speed, > 0. [m/s]
    duration : float, optional
        None: stop at separation or at capture. A float: stop at separation or after this much
        time, whichever comes first (so the captured oscillation can be followed). [s]
    rtol, atol, method, max_step
        As for :func:`simulate_reference`.

    Returns
    -------
    NormalSolution
        With the trajectory at the solver's steps: ``time`` since first contact [s],
        ``penetration`` x = -n [m], ``penetration_rate`` x' [m/s]; ``outcome`` "rebound",
        "capture" or "in contact" (the duration ended first, ``stop_reason`` "duration");
        ``state["energy"]``, the normal contact energy E = m x'^2 / 2 + V(x) along it, and
        ``state["dissipated"]``, the energy dissipated by the normal damping so far (integrated
        independently of E) [J]. J and J_a are not integrated (NaN); ``e_n`` is NaN in contact.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (27)

    Virtanen, P. et al. (2020), SciPy 1.0: fundamental algorithms for scientific computing in
    Python, Nat. Methods 17:261-272, doi:10.1038/s41592-019-0686-2 (``solve_ivp``, DOP853,
    ``brentq``)

    Examples
    --------
    An elastic Hertz impact: no energy dissipated, contact time 2.94328 x_max / v (x_max =
    (5 m v^2 / (4 k))^(2/5)); the largest penetration among the solver's steps is a little short of
    x_max (the steps do not land on it):

    >>> import math
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> h = c.with_(zeta_hertz=0.0, zeta_adhesion=0.0, adhesion_line_force=0.0)
    >>> tr = reference_trajectory(h, 1.0)
    >>> x_max = (1.25 * h.mass / (math.sqrt(h.radius) * h.stiffness)) ** 0.4
    >>> tr.outcome, round(float(tr.time[-1]) / x_max, 6), tr.dissipated_energy
    ('rebound', 2.943275, 0.0)
    >>> bool(tr.penetration.max() <= x_max)
    True

    The arrays share the solver's time points:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> tr = reference_trajectory(c, 1.0)  # below the capture velocity, 1.449 m/s
    >>> len(tr.time) == len(tr.penetration) == len(tr.state["energy"]), tr.outcome, tr.stop_reason
    (True, 'capture', 'capture')
    """
    normal_speed = _validate_speed("normal_speed", normal_speed)
    rtol, atol, _ = _validate_common(rtol, atol, None)
    sc = _scales(contact, normal_speed)
    tau_end = math.inf if duration is None else _validate_speed("duration", duration) / sc.time
    rhs10 = _make_rhs(sc, 0.0, (1.0, 0.0), False, 0.0, 1.0, [0, math.inf, math.inf])

    # State (s, y, D, tau), independent variable sigma (dtau/dsigma = s), as in simulate_reference.
    def rhs(t, z):
        out = rhs10(t, z)
        return [out[_S], out[_Y], out[_D], out[_TAU]]

    sigma_limit = _MAX_TAU_CONTACT if duration is None else 2.0 * tau_end + _MAX_TAU_CONTACT
    sol = solve_ivp(
        rhs,
        (0.0, sigma_limit),
        [0.0, normal_speed / sc.speed, 0.0, 0.0],
        method=method,
        rtol=rtol,
        atol=atol,
        max_step=max_step,
        events=_normal_events(sc, tau_end, duration),
    )
    if sol.status == -1:
        raise ReferenceSolverError(f"solve_ivp ({method}) failed: {sol.message}")
    return _normal_solution(sc, sol, normal_speed, duration)


def _normal_events(sc: _Scales, tau_end: float, duration: float | None) -> list:
    """The events of :func:`reference_trajectory` on the state (s, y, D, tau): separation, capture
    (terminal without a ``duration``; never without adhesion) and the end of the duration."""
    def ev_sep(_t, z):
        return z[0]

    def ev_cap(_t, z):
        return _energy(sc, z[0], z[1])

    def ev_end(_t, z):
        return z[3] - tau_end

    events = [_event(ev_sep, True, -1.0), _event(ev_cap, duration is None, -1.0), _event(ev_end, True, 1.0)]
    if not sc.adhesive:
        events[1] = _event(lambda _t, z: 1.0, False, 0.0)  # no capture without adhesion
    return events


def _normal_solution(sc: _Scales, sol, normal_speed: float, duration: float | None) -> NormalSolution:
    """The NormalSolution of :func:`reference_trajectory` from its ``solve_ivp`` result ``sol``: the
    outcome of its events (ReferenceSolverError where none ended the run) and the trajectory in SI."""
    captured = sc.adhesive and len(sol.t_events[1]) > 0
    if len(sol.t_events[0]):
        outcome = "rebound"
    elif captured and (duration is None or len(sol.t_events[2])):
        outcome = "capture"
    elif duration is not None and len(sol.t_events[2]):
        outcome = "in contact"
    else:
        raise ReferenceSolverError(
            f"no separation and no capture by nondimensional time {sol.y[3, -1]:.6g}: {sol.message}"
        )
    # Include the terminal event state (solve_ivp already appends it as the last point).
    V, m = sc.speed, sc.mass
    s_, y, d, tau = sol.y
    energy = np.array([_energy(sc, a, b) for a, b in zip(s_, y)]) * m * V * V
    rebound = outcome == "rebound"
    return NormalSolution(
        outcome=outcome,
        e_n=-float(y[-1]) * V / normal_speed if rebound else (0.0 if outcome == "capture" else math.nan),
        contact_time=float(tau[-1] * sc.time) if rebound else math.inf,
        capture_time=float(sol.y_events[1][0][3] * sc.time) if captured else math.nan,
        max_penetration=float(np.max(s_ * s_)) * sc.length,
        friction_impulse=math.nan,
        twist_impulse=math.nan,
        dissipated_energy=float(d[-1] * m * V * V),
        final_energy=float(energy[-1]),
        slip_end_time=math.nan,
        n_steps=int(sol.t.size),
        n_rejected=0,
        stop_reason="separation" if rebound else ("duration" if len(sol.t_events[2]) else "capture"),
        time=tau * sc.time,
        penetration=s_ * s_ * sc.length,
        penetration_rate=y * V,
        state={"energy": energy, "dissipated": d * m * V * V},
    )
