"""Impacts with a DEM tangential law (LAMMPS's ``linear_history`` and ``mindlin``,
:mod:`microimpact.model.dem_tangential`): the normal law of :mod:`microimpact.solvers.normal_models` and the history
spring with its Coulomb limit, integrated together.

The normal motion does not feel the tangential force (LAMMPS's wall contact has no coupling back),
so the normal outcome is the compiled normal solver's (:func:`microimpact.solvers.normal_models.solve_normal`:
e_n, capture, contact time, largest penetration). What it leaves is the tangential state, whose
force depends on the normal state at every instant; it is integrated here with the normal motion.

Formulation. The normal law in its own units and Sundman variable (:mod:`microimpact.solvers.normal_models`: state
q = sqrt(a / a_c) for JKR, s = sqrt(delta / L) for DMT and Hertz, rate y), with the tangential
state in the same units: the slip velocity u (2 components, units L / T) and, in stick, the
history H (the displacement xi, units L, or for the ``/force`` variants the elastic force, units F),
in slide the direction e of the force (a unit vector), the force being mu F_n0 e there. With
kappa = 1 + m r^2 / I (the slip responds to a tangential force F as du/dt = kappa F / m):

* stick: F = F_e(H) - eta_t u, dH/dt of the law (:func:`~microimpact.model.dem_tangential.lammps_history_rate`:
  u, or -k u; plus (da/dt / a) H while a falls for the rescaled variants), du / dt = kappa F;
* slide: F = mu F_n0 e, du / dt = kappa F, de / dt = (1 - e e^T) G' / (mu F_n0), G' the rate of the
  trial force F_e(H) - eta_t u with H the history of the elastic part F + eta_t u.

With LAMMPS's rolling law (:mod:`microimpact.model.dem_rolling`) a second spring of the same kind
(constant stiffness k_roll, damping gamma_roll, limit mu_roll F_n0) acts on the rolling velocity
w = R omega x n_w; its state (history or direction, and w) follows the slip's in the state vector,
and the slip feels its torque: du/dt = kappa F / m - (kappa - 1) F_r / m, dw/dt = (kappa - 1)
(F_r - F) / m. Each spring sticks and slides on its own, with its own events.

With LAMMPS's twisting law (:mod:`microimpact.model.dem_twisting`) the spin about the normal has a
spring of its own, scalar, on the twist rate Omega: it feels neither the slip nor the rolling, nor
they it, so it is integrated on its own with the normal law (``_twist``): state (xi, Omega) in
stick, Omega in slide (torque -mu_twist F_n0 sgn(Omega)); events where |M| reaches the limit, where
the sliding trial torque turns inside it, and where the sliding twist stops (Omega = 0).

Without rolling resistance the tangential problem is one-dimensional: the wall is isotropic, the
history starts at 0 and the force acts on the slip alone, so xi, u and F stay on the line of the
initial slip u_in. (So does it with the rolling law where w_in is parallel to u_in: spin about t'
only, the planar impact.) It is integrated in a frame whose first axis is u_in, where the components
across are exactly 0 and the direction e is +-1 (in the wall's frame rounding noise across the slip,
divided by a vanishing limit, made the steps fail near a Hertz separation); the solver keeps the
two-component form, which is exact for any direction.

Quasi-static directions. A sliding direction relaxes to its rest point P / |P| (P the part of G' not
along e) at the rate r = |P| / (mu F_n0), which a creeping contact (a limit mu F_n0 made small by
damping, rolling across the slip) takes to 5e6-3e8 per unit of the Sundman variable while the
creep spans ~5e5 of it: scipy's implicit methods then held their steps far below 1 and ran out of
their budgets. Where the lag of the direction behind its rest point, phi' / r (phi' the rate at
which P / |P| turns, the first term of the singular-perturbation expansion), falls below a quarter
of the tolerance and the direction is within the tolerance of it, the direction follows it: it is
P / |P| at every instant, an algebraic variable, and only the slow variables are integrated
(``_FOLLOW``, ``_quasi_static``). Events on the lag start and stop it (it stops where the lag
reaches the tolerance, and the direction is written back to the state); the stick-slip events are
those of slide. It is used in the 2-D rolling integration only, where at most one of the two
springs' damping couples their directions.

Events (located by scipy's root finding on the dense output): stick ends where |F| reaches the
limit; slide ends where e . G' falls below the rate of the limit (the trial force turns inwards);
the contact ends where the normal law separates (s = 0, or q^3 = 3 for LAMMPS's JKR). At a switch
the state is mapped (e = F / |F|; xi = -(F + eta_t u) / k) and the integration restarts.

Method: scipy's DOP853 (Hairer et al. 1993) at the toolkit's rtol, per impact in Python; implicit
methods where the problem is stiff. Where the rolling velocity has a part across the slip, the
force directions turn at rates |G'| / (mu F_n0) that an explicit method cannot follow where a limit
is small: LSODA, BDF and Radau are tried in turn (``_ACROSS_METHODS``; none of them alone solved
every case of the stress sweep). A rolling limit far below the friction's (mu_roll <= 1e-6 beside
mu 0.3) may still fail, with a :class:`DemTangentialError`; a rolling law whose largest effect is
below the tolerance is dropped. Where the normal damping rate dwarfs the elastic one
(``_STIFF_DAMPING``, ~50 critical dampings) the normal motion itself is stiff, and a sphere that
creeps (tens of thousands of critical dampings) took DOP853 past its budget: the slip and the
twist are then integrated by Radau, which follows the creep along its slow manifold in ~1e4
evaluations (the same outcome as BDF's to 1e-9 of the speed scale, tests/test_dem_tangential_stress.py).
It is an integrator of its own beside the compiled ones (the one-core issue, docs/guide/lammps.md),
slower (tens of ms per impact, seconds where it is implicit).

Events are located by sign changes between the ends of a step, and after a switch the state
starts on the limit (the switch function is 0 to rounding): a crossing inside one step, in the
step that ends the contact, or after a restart rounded to the wrong side was lost, and the
outcome then depended on the tolerance (4 of 300 random impacts moved by up to 0.25 between rtol
1e-8 and 1e-10, LAMMPS siding with the finer). Each phase is therefore integrated with dense
output, and the extrema of its switch function towards leaving (maxima of |F| - mu F_n0 in stick,
minima of the trial force's excess rate in slide) and its last instant are checked
(``_crossing_inside_a_step``); 600 random impacts now move by less than 1e-7
(tests/test_dem_tangential.py). A switch undone at once is ridden through (``_CHATTER_SPAN``).

A captured sphere (JKR, DMT) ends at rest on the wall, with the limit 2 mu F_po > 0 there: the
slip stops in finite time and the sphere rolls, so its tangential outcome is the rolling state,
slip u = 0, reached by the impulse -u_in / kappa (the contact force acts at the contact point,
which conserves the angular momentum about it). A stuck elastic vibration of the history spring
may be left; it averages to zero.

References
----------
Hairer, E., Norsett, S. P. and Wanner, G. (1993), Solving Ordinary Differential Equations I,
2nd ed., Springer, Sec. II.10 (DOP853).

LAMMPS documentation, ``pair_style granular``, https://docs.lammps.org/pair_granular.html.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from microimpact.model import adhesion_models as am
from microimpact.model.dem_rolling import DEM_ROLLING_MODELS, lammps_rolling_velocity
from microimpact.model.dem_twisting import DEM_TWISTING_MODELS, lammps_marshall_twisting_coefficients
from microimpact.model.dem_tangential import (DEM_TANGENTIAL_MODELS, FORCE_HISTORY_MODELS, lammps_critical_normal_force,
                                              lammps_critical_normal_force_rate, lammps_elastic_force,
                                              lammps_pulloff_force, lammps_history_of_force, lammps_history_rate,
                                              lammps_tangential_stiffness)
from microimpact.solvers import SolverError
from microimpact.solvers.normal_models import _DMT, _JKR_FORCE, _setup, solve_normal
from microimpact.solvers.solution import NormalSolution

__all__ = ["DemTangentialError", "solve_dem_tangential", "uses_dem_tangential", "TANGENTIAL_RTOL"]

#: the modes of a spring: stuck, sliding, and sliding with its direction at its quasi-static value
#: (``_followed``): where the direction relaxes far faster than it turns (the 2-D rolling law under a
#: limit mu F_n0 that a creeping contact makes small: the stress sweep's sds law, seed 0, cases 59,
#: 66, 77, 144: case 77's relaxed at 5e6 and 3e8 per unit of the Sundman variable over a creep of
#: ~5e5 of it, and held the median step of LSODA, Radau, BDF to 8e-3, 3e-7, 9e-9 there, past their
#: budgets), the fast variable is replaced by its rest point
_STICK, _SLIDE, _FOLLOW = 0, 1, 2
#: the direction state of each spring (tangential, rolling) in the state vector
_DIRECTIONS = (slice(2, 4), slice(7, 9))
#: a sliding direction starts to follow where its lag behind the quasi-static value is this part
#: of the tolerance (and the direction within the tolerance of it), stops where the lag reaches
#: the tolerance: the margin keeps one crossing of the lag from switching back and forth
_FOLLOW_ENTRY = 0.25
#: relative rounding of a quasi-static direction (``_lag``), and the part of the tolerance that the
#: lag it leaves unresolved must stay below for the follow event to be decided
_LAG_ROUNDING, _LAG_MARGIN = 1e-14, 1e-2
#: largest relative tolerance of the tangential integration (DOP853 is cheap at it)
TANGENTIAL_RTOL = 1e-10
#: largest number of stick-slip events (switches and grazes) of one impact before it is reported as a failure
_MAX_EVENTS = 1000
#: largest number of right-hand side evaluations of one impact
_MAX_EVALUATIONS = 2_000_000
#: stretch of the Sundman variable (relative) kept in one mode where the switches chatter
_CHATTER_SPAN = 1e-7
#: span of the Sundman variable given to scipy: the contact ends by its event long before. A Hertz
#: sphere that creeps out under a damping ~ a (``viscoelastic``) reaches s ~ 1 / eta^2 before it
#: leaves, at sigma ~ eta^3 (s = 2 eta / sigma on the slow manifold y = -s^2 / eta): 1e19 at the
#: extended domain's 1e6 critical dampings, which 1e7 cut short
_SIGMA_SPAN = 1e30
#: damping rate of the normal law at its largest contact (eta = c3 a^p3, in its units, where the
#: elastic rate is ~1) above which the integration is implicit (Radau): an explicit method is held
#: to steps ~1 / eta by its stability and needs ~eta^2 of them (DOP853: 4e4 evaluations at 160,
#: past 2e6 at 4e4), Radau ~2e4 at any eta (the stress sweep's jkr_force_viscoelastic_lammps_mindlin,
#: seed 0: cases 59, 126, 144 at 1e5, 2e6, 4e4 ended in the evaluation budget); at eta 34 to 160
#: both agree to 5e-10 of the outcome and DOP853 is the faster below ~100
_STIFF_DAMPING = 100.0
#: step (relative to the Sundman variable) of the central difference of slide's switch function
_RATE_STEP = 1e-7
#: the implicit methods tried in turn where the rolling velocity has a part across the slip, each
#: from touch with its own evaluation budget where the one before failed: none of scipy's three
#: solves every case. Over the stress sweep's sds law (seed 0, 40 cases, rtol 1e-10) Radau failed
#: to locate an event (case 37), ran out of its budget (38) and took 4725 steps, ~10x the time of
#: BDF and LSODA (39); BDF took 15094 steps where LSODA took 1294 (38); LSODA failed to locate an
#: event where BDF took 424 steps (37). Each is an integration of the same equations to the same tolerance, so
#: that the first that reaches the end of contact gives the outcome
_ACROSS_METHODS = ("LSODA", "BDF", "Radau")
#: points of the dense output scanned for the force inside the limit after a restart on it
_SCAN_POINTS = 257
#: JKR's state where LAMMPS's contact breaks, q^3 = 3 (F = -F_c)
_Q_BREAK = am.JKR_Q_BREAK["jkr_force"]


class DemTangentialError(SolverError):
    """The DEM tangential integration did not reach the end of the contact (step budget, chattering).

    Examples
    --------
    One ``except`` catches the failure of any solver:

    >>> issubclass(DemTangentialError, SolverError), issubclass(DemTangentialError, RuntimeError)
    (True, True)
    """


def uses_dem_tangential(contact) -> bool:
    """Whether ``contact`` selects a DEM tangential law (:data:`~microimpact.model.dem_tangential.DEM_TANGENTIAL_MODELS`).

    Examples
    --------
    >>> from microimpact.model.contact import Contact
    >>> c = Contact(1e-6, 2000.0, 1e9, 0.0)
    >>> uses_dem_tangential(c), uses_dem_tangential(c.with_(tangential_model="lammps_mindlin", shear_modulus=3e8))
    (False, True)
    """
    return contact.tangential_model in DEM_TANGENTIAL_MODELS


class _Law:
    """The normal law, the tangential law and the scales of one impact, in the normal law's units."""

    def __init__(self, contact, normal_speed):
        model, sc, y0, c1, c2, c3, p3 = _setup(contact, normal_speed)
        if c1 != 0.0 or c2 != 0.0:  # Contact's checks refuse the paper's damping with these laws
            raise ValueError("the DEM tangential laws run without the paper's damping (zeta_H = zeta_A = 0)")
        self.jkr = model == _JKR_FORCE
        self.dmt = model == _DMT
        self.scales = sc
        self.y0 = float(y0)
        self.c3, self.p3 = float(c3), float(p3)
        force = float(sc.force)
        # LAMMPS's pull-off force in the law's force unit (1.5 for JKR, 1 for DMT)
        self.pulloff = lammps_pulloff_force(contact.normal_model, contact.radius, contact.work_of_adhesion) / force
        length = float(sc.length)
        # k in the law's units, F / L, from the model's k(a) in SI: k = k0 + k1 a (a in its unit)
        self.model = contact.tangential_model
        self.force_history = self.model in FORCE_HISTORY_MODELS
        self.k_param = (contact.tangential_stiffness if self.model == "linear_history" else 8.0 * contact.shear_modulus)
        self.k_unit, self.a_unit = force / length, float(sc.radius)
        self.k0 = lammps_tangential_stiffness(self.model, self.k_param, 0.0) / self.k_unit
        self.k1 = lammps_tangential_stiffness(self.model, self.k_param, self.a_unit) / self.k_unit - self.k0
        self.x_t = contact.tangential_damping
        self.mu = contact.friction
        self.spin = contact.mass * contact.radius**2 / contact.moment_of_inertia
        self.kappa = 1.0 + self.spin
        # LAMMPS's rolling law (model.dem_rolling): k_roll in F / L, gamma_roll in F / (L / T); with
        # mu_roll = 0 (LAMMPS's default) its limit mu_roll F_n0 is 0 and so is its force at every step:
        # the slip is integrated without it (``_slip``), and its state (w, the spring) is not carried
        self.rolling = contact.rolling_model in DEM_ROLLING_MODELS and contact.rolling_friction > 0.0
        self.k_r = contact.rolling_stiffness / self.k_unit if self.rolling else 0.0
        self.gamma_r = contact.rolling_damping * float(sc.speed) / force
        self.mu_r = contact.rolling_friction if self.rolling else 0.0
        self.cap_floor = self.cap_floor_r = 0.0  # set by _integrate from its tolerance
        self.method = "DOP853"
        self.across = False  # the 2-D rolling integration (_with_rolling), where directions may follow

    def normal(self, z, y):
        """(g = dtau/dsigma, dz/dsigma, a, da/dsigma, eta_n, deta_n/dsigma, dy/dsigma, F_n0, dF_n0/dsigma)
        in the law's units; the elastic force is the model's (model.adhesion_models), its rate here."""
        if self.jkr:
            g, dz, a = 4.0 * (z * z * z - 1.0), y, z * z
            da = 2.0 * z * dz
            fe = am.jkr_nondimensional_force(z, 0.0, 0.0, 0.0)
            dfe = (z * z * z * z * z - 3.0 * z * z) * dz  # d(q^6/6 - q^3)/dq dq/dsigma
        else:
            g, dz, a = z, 0.5 * y, z
            da = dz
            fe = am.dmt_nondimensional_force(z, 0.0, 0.0, 0.0) if self.dmt else am.hertz_nondimensional_force(z, 0.0, 0.0)
            dfe = 3.0 * z * z * dz  # d(s^3 [- 1])/ds ds/dsigma
        c3, p3 = self.c3, self.p3
        if c3 != 0.0 and a > 0.0:
            eta = c3 * a**p3
            deta = c3 * p3 * a ** (p3 - 1.0) * da if p3 != 0.0 else 0.0
        else:
            eta, deta = (c3, 0.0) if p3 == 0.0 else (0.0, 0.0)
        fd = eta * y
        dy = -g * (fe + fd)
        n0 = lammps_critical_normal_force(fe, fd, self.pulloff)
        dn0 = lammps_critical_normal_force_rate(fe, fd, self.pulloff, dfe, deta * y + eta * dy)
        return g, dz, a, da, eta, deta, dy, n0, dn0

    def stiffness(self, a):
        """k(a) of the tangential law (model.dem_tangential), in F / L. [-]"""
        return lammps_tangential_stiffness(self.model, self.k_param, a * self.a_unit) / self.k_unit


def _spring(model, mode, s1, s2, v1, v2, k, eta, cap):
    """(force, direction e, history, stick's switch) of one history spring with its Coulomb limit
    (the tangential law on the slip u, or the rolling law on the rolling velocity), from its state
    (s1, s2): the history H in stick, the direction e in slide. Slide's switch is its rate's
    (``_spring_rates``); ``None`` is returned for it here."""
    if mode == _STICK:
        h1, h2 = s1, s2
        f1 = lammps_elastic_force(model, h1, k) - eta * v1
        f2 = lammps_elastic_force(model, h2, k) - eta * v2
        size = math.hypot(f1, f2)
        e1, e2 = (f1 / size, f2 / size) if size > 0.0 else (0.0, 0.0)
        switch = (size - cap) / (size + cap) if size + cap > 0.0 else -1.0
        return f1, f2, e1, e2, h1, h2, switch
    norm = math.hypot(s1, s2)
    e1, e2 = (s1 / norm, s2 / norm) if norm > 0.0 else (0.0, 0.0)  # 0: the rate P of _followed
    f1, f2 = cap * e1, cap * e2
    # the history the force on the limit leaves (model.dem_tangential: LAMMPS resets it to the
    # elastic part of the scaled force)
    fe1, fe2 = f1 + eta * v1, f2 + eta * v2
    if model in FORCE_HISTORY_MODELS or k > 0.0:
        h1, h2 = lammps_history_of_force(model, fe1, k), lammps_history_of_force(model, fe2, k)
    else:  # first touch of a Mindlin spring (a = 0): no history yet
        h1 = h2 = 0.0
    return f1, f2, e1, e2, h1, h2, None


def _spring_rates(model, mode, spring, v1, v2, dv1, dv2, g, k, dk, eta, deta, cap, dcap, radius_rate, floor):
    """(d/dsigma of the spring's state, the rate of slide's switch) from ``_spring``'s ``spring``.

    G' is the rate of the trial force F_e(H) - eta v; slide's switch is (e . G' - (mu F_n0)') /
    (|e . G'| + |(mu F_n0)'|), which stays well conditioned where force and limit both vanish
    (Hertz at touch and separation, like s^3). In stick the state moves at dH/dsigma; in slide the
    direction turns at (1 - e e^T) G' / (mu F_n0), where the limit is below ``floor`` (a
    tolerance's part of the largest limit) at ``floor``: a force that small moves the outcome by
    less than the tolerance whatever its direction, while 1 / (mu F_n0) near a Hertz separation
    (F_n0 ~ s^3) turned rounding noise into steps below the spacing of doubles (23 of 120 random
    planar impacts before)."""
    _, _, e1, e2, h1, h2, _ = spring
    dh1 = lammps_history_rate(model, h1, g * v1, k, radius_rate)
    dh2 = lammps_history_rate(model, h2, g * v2, k, radius_rate)
    if model in FORCE_HISTORY_MODELS:
        dfe1, dfe2 = dh1, dh2
    else:
        dfe1, dfe2 = -dk * h1 - k * dh1, -dk * h2 - k * dh2
    g1 = dfe1 - deta * v1 - eta * dv1
    g2 = dfe2 - deta * v2 - eta * dv2
    along = e1 * g1 + e2 * g2
    rate = (along - dcap) / (abs(along) + abs(dcap)) if abs(along) + abs(dcap) > 0.0 else 1.0
    if mode == _STICK:
        return dh1, dh2, rate
    turn = max(cap, floor)
    if turn == 0.0:  # a spring without friction (mu = 0 beside a rolling law): no force, whatever e is
        return 0.0, 0.0, rate
    return (g1 - along * e1) / turn, (g2 - along * e2) / turn, rate


def _rhs_and_switch(law, x, mode):
    """(d/dsigma of the state, the switch functions of ``mode``, the rates of stick's switches) at x:
    those of ``_rates``, with a following spring's direction at its quasi-static value
    (``_followed``) and held there (its rate 0)."""
    if _FOLLOW not in mode:
        return _rates(law, x, mode)
    out, switch, rate = _rates(law, _followed(law, x, mode), mode)
    for i in (0, 1):
        if mode[i] == _FOLLOW:
            out[_DIRECTIONS[i]] = 0.0
    return out, switch, rate


def _followed(law, x, mode):
    """x with the direction of each following spring (``_FOLLOW``) at its quasi-static value P / |P|
    (``_quasi_static``)."""
    return _quasi_static(law, x, mode)[0]


def _quasi_static(law, x, mode):
    """(x with the direction of each following spring at its quasi-static value P / |P|, the rates
    P / max(mu F_n0, floor) of the springs, None for one that does not follow).

    In slide the trial force's rate is G' = P + c e (``_spring_rates``), affine in the spring's own
    direction e with a scalar c (its history, the velocity's response to the spring's own force and
    the rescaling are all along e), so P is G' at e = 0, and the direction's equation
    de/dsigma = (1 - e e^T) G' / (mu F_n0) has the stable rest point e = P / |P|, relaxed to at the
    rate |P| / (mu F_n0). P of one spring depends on the other's direction only through a damping
    (eta_t of the slip, gamma_roll of the rolling); with one of them 0 (``_may_follow``) the
    independent spring is set first, so that the other's P is that of its final direction, and with
    both 0 one evaluation gives both."""
    y, rates = x.copy(), [None, None]
    following = [i for i in ((1, 0) if law.x_t != 0.0 else (0, 1)) if mode[i] == _FOLLOW]
    together = len(following) == 2 and law.x_t == 0.0 and law.gamma_r == 0.0
    for group in ([following] if together else [[i] for i in following]):
        zeroed = y.copy()
        for i in group:
            zeroed[_DIRECTIONS[i]] = 0.0
        out = _rates(law, zeroed, mode)[0]
        for i in group:
            rates[i] = out[_DIRECTIONS[i]]
            size = math.hypot(rates[i][0], rates[i][1])
            if size > 0.0:  # else (no rest point) the state's direction stays; the lag (_lag) is inf there
                y[_DIRECTIONS[i]] = rates[i] / size
    return y, rates


def _lag(law, x, mode, i, sigma, entry=None):
    """How far spring ``i``'s direction is from following its quasi-static value P / |P|
    (``_quasi_static``), in radians: the lag phi' / r of a direction that relaxes at the rate
    r = |P| / (mu F_n0) behind a value that turns at the rate phi' (the first term of the
    singular-perturbation expansion). Where ``entry`` is given (a sliding spring that may start
    following) the larger of that lag over ``_FOLLOW_ENTRY`` and the distance of the state's
    direction from P / |P|, the distance alone where it is above ``entry``. phi' is a central
    difference along the motion over a step that changes the contact and the velocities by
    a ``_RATE_STEP`` part of themselves at most. Returned with the lag that the rounding of that
    difference leaves unresolved (on the same scale). inf without a rest point (|P| = 0), None where
    the difference reaches past the end of contact (there the relaxation only quickens: r ~ 1 / s,
    and 1 / s^2 for the rolling spring, at a Hertz separation)."""
    if _separation(law, x) <= 0.0:
        return None
    follow = tuple(_FOLLOW if j == i else m for j, m in enumerate(mode))
    p = _quasi_static(law, x, follow)[1][i]
    rate = math.hypot(p[0], p[1])
    if rate == 0.0:
        return math.inf, 0.0
    distance = 0.0
    if entry is not None:
        distance = math.hypot(*(x[_DIRECTIONS[i]] / math.hypot(*x[_DIRECTIONS[i]]) - p / rate))
        if distance > entry:
            return distance, 0.0
    motion = _rhs_and_switch(law, x, mode)[0]
    # the step moves the contact (z) and the velocities (u, w) by a _RATE_STEP part of themselves at
    # most (a step ~ sigma reached past the end of a fast impact's contact, where the lag is not
    # determined, and held a direction that no longer followed)
    speed = math.hypot(x[4], x[5]) + math.hypot(x[9], x[10])
    turning = math.hypot(motion[4], motion[5]) + math.hypot(motion[9], motion[10])
    change = max(abs(motion[0]) / abs(x[0]) if x[0] != 0.0 else math.inf, 1.0 / max(1.0, abs(sigma)),
                 turning / speed if speed > 0.0 else 0.0)
    h = _RATE_STEP / change
    ends = []
    for step in (h, -h):
        end = x + step * motion
        if _separation(law, end) <= 0.0:
            return None
        q = _quasi_static(law, end, follow)[1][i]
        size = math.hypot(q[0], q[1])
        if size == 0.0:
            return math.inf, 0.0
        ends.append(q / size)
    lag = math.hypot(*(ends[0] - ends[1])) / (2.0 * h) / rate
    # the rounding of the two directions, ~1e-14 each (P is a sum of terms of either sign), over the
    # step: a lag below it is not resolved (just after a Hertz touch the step is ~1e-13 and the
    # difference noise, which took the event function across 0 and back at one state)
    unresolved = _LAG_ROUNDING / (2.0 * h) / rate
    if entry is None:
        return lag, unresolved
    return max(lag / _FOLLOW_ENTRY, distance), unresolved / _FOLLOW_ENTRY


def _rates(law, x, mode):
    """(d/dsigma of the state, the switch functions of ``mode``, the rates of stick's switches) at x,
    a following spring taken as sliding along the direction in x.

    ``mode`` is (tangential, rolling), each _STICK or _SLIDE; the switch functions and rates are
    pairs in that order (the rolling ones -1 without a rolling law). The switch functions are
    relative, in [-1, 1]: (|F| - mu F_n0) / (|F| + mu F_n0) in stick, the rate of ``_spring_rates``
    in slide. The rate of stick's switch is that of slide with e = F / |F|: the sign of the rate
    of |F| - mu F_n0, whose maxima ``_integrate`` watches for a crossing of the limit inside one
    step.

    With LAMMPS's rolling law (model.dem_rolling) the state carries the rolling history and the
    rolling velocity w after the slip u; the slip responds to both pseudo-forces, du/dtau =
    kappa F - (kappa - 1) F_r, and dw/dtau = (kappa - 1) (F_r - F) (unit mass; the rolling
    pseudo-force acts through its torque R n_w x F_r only)."""
    z, y, u1, u2 = x[0], x[1], x[4], x[5]
    g, dz, a, da, eta, deta, dy, n0, dn0 = law.normal(z, y)
    cap, dcap = law.mu * n0, law.mu * dn0
    eta_t, deta_t = law.x_t * eta, law.x_t * deta
    k = law.stiffness(a)
    tangential = _spring(law.model, mode[0], x[2], x[3], u1, u2, k, eta_t, cap)
    f1, f2 = tangential[0], tangential[1]
    out = np.empty(11 if law.rolling else 7)
    out[0], out[1], out[6] = dz, dy, g
    # (da/dsigma) / a, for the rescaled histories (model.dem_tangential.lammps_history_rate)
    radius_rate = da / a if a > 0.0 else 0.0
    if law.rolling:
        w1, w2 = x[9], x[10]
        rcap, drcap = law.mu_r * n0, law.mu_r * dn0
        rolling = _spring("linear_history", mode[1], x[7], x[8], w1, w2, law.k_r, law.gamma_r, rcap)
        r1, r2 = rolling[0], rolling[1]
        du1, du2 = g * (law.kappa * f1 - law.spin * r1), g * (law.kappa * f2 - law.spin * r2)
        dw1, dw2 = g * law.spin * (r1 - f1), g * law.spin * (r2 - f2)
        out[7], out[8], rate_r = _spring_rates("linear_history", mode[1], rolling, w1, w2, dw1, dw2, g, law.k_r,
                                               0.0, law.gamma_r, 0.0, rcap, drcap, 0.0, law.cap_floor_r)
        out[9], out[10] = dw1, dw2
        switch_r = rolling[6] if mode[1] == _STICK else rate_r
    else:
        du1, du2 = g * law.kappa * f1, g * law.kappa * f2
        switch_r = rate_r = -1.0
    out[2], out[3], rate = _spring_rates(law.model, mode[0], tangential, u1, u2, du1, du2, g, k, law.k1 * da,
                                         eta_t, deta_t, cap, dcap, radius_rate, law.cap_floor)
    out[4], out[5] = du1, du2
    if law.mu == 0.0:  # a frictionless slip (beside the rolling law): no force in either mode, it stays in
        out[2], out[3], rate = 0.0, 0.0, 1.0  # slide (_start_mode), its direction idle
    switch = tangential[6] if mode[0] == _STICK else rate
    return out, (switch, switch_r), (rate, rate_r)


def _separation(law, x):
    """Zero where the contact ends: s = 0 (Hertz, DMT), q = 3^(1/3) (LAMMPS's JKR break)."""
    return x[0] - _Q_BREAK if law.jkr else x[0]


def _just_after_touch(law, z0, y0):
    """(z, tau) a short way (sigma = 1e-6) after first touch, from the leading terms of the normal
    motion: s = y sigma / 2, tau = y sigma^2 / 4; JKR: q = q0 + y sigma, tau = g sigma."""
    sigma = 1e-6
    if law.jkr:
        return z0 + y0 * sigma, 4.0 * (z0**3 - 1.0) * sigma
    return 0.5 * y0 * sigma, 0.25 * y0 * sigma * sigma


def _start_mode(law, x):
    """(mode, initial state) at first touch: each spring sticks or slides as its stuck trial force
    compares with its limit just after touch.

    At touch the history is 0 and, for Hertz, force and limit both vanish, while their ratio does
    not (for the Mindlin spring it is k u / (mu y) with k = dk/da, the incidence parameter of Maw et
    al. 1976); so they are compared at a state a short way in, from the leading terms of the motion
    (:func:`_just_after_touch`) and xi = u tau (the rolling history: w tau).
    """
    probe = x.copy()
    probe[0], tau = _just_after_touch(law, x[0], x[1])
    probe[2:4] = x[4:6] * tau
    if law.force_history:  # H = -int k u dt, with k ~ a ~ t^(1/2) for Hertz and DMT, ~ const for JKR
        k = law.stiffness(law.normal(probe[0], probe[1])[2])
        probe[2:4] *= -k * (1.0 if law.jkr else 2.0 / 3.0)
    if law.rolling:
        probe[7:9] = x[9:11] * tau
    switch = _rhs_and_switch(law, probe, (_STICK, _STICK))[1]
    x = x.copy()
    tangential = rolling = _STICK
    if law.mu == 0.0:
        # without friction the slip's spring carries no force: it slides on its zero limit from touch and
        # never switches (stuck, its force F_e(H) - eta_t u grew past the zero limit at once, and back
        # inside it by rounding, so that it chattered across a whole contact: the sds law's case 55 of
        # seed 0 took 32 s, the sweep's time box)
        tangential = _SLIDE
        x[2:4] = (1.0, 0.0)
    elif switch[0] > 0.0:
        # sliding from touch; against the slip, except where LAMMPS's Mindlin spring starts at a = 0
        # under a damping that does not vanish as fast as a (mass_velocity, tsuji, coeff_restitution):
        # its history, reset to -(mu F_n0 e + eta_t u) / (k a), is then ~ a^(p - 1) and the spring
        # force k a xi it gives grows with a / a_touch, which carries the trial force across the limit
        # at once: the force starts at the limit along the slip (LAMMPS converges to this as its step
        # falls: e_t 0.73763, 0.73631, 0.73628 at 500, 8000, 128000 steps per contact, DMT, 60 deg)
        # (a force history is reset to the elastic force itself, without the 1 / a: no such start)
        forward = (law.k1 > 0.0 and not law.force_history and not law.jkr and law.c3 > 0.0 and law.p3 < 1.0
                   and law.x_t > 0.0)
        tangential = _SLIDE
        x[2:4] = (1.0 if forward else -1.0) * x[4:6] / math.hypot(x[4], x[5])
    if law.rolling and switch[1] > 0.0:  # the rolling spring (constant k) slides against the rolling
        rolling = _SLIDE
        x[7:9] = -x[9:11] / math.hypot(x[9], x[10])
    return (tangential, rolling), x


def _integrate(law, u0, rtol, tau_scale, z_scale, w0=None):
    """(state at separation, end of the last tangential slide or NaN, switches, whether the
    tangential spring ends stuck), in the law's units; ``w0`` the rolling velocity (with a rolling
    law)."""
    peak = z_scale**6 / 6.0 + 3.0 if law.jkr else z_scale**3 + 2.0 * law.pulloff  # F_n0 at the largest approach
    # the direction's floor (_spring_rates) is a tolerance's part of the larger of the two limits: a
    # rolling limit far below the friction's (mu_roll 1e-12) moves the outcome by less than the
    # tolerance, while 1 / (mu_roll F_n0) made its direction turn too fast to follow (2-D rolling)
    law.cap_floor = law.cap_floor_r = rtol * max(law.mu, law.mu_r) * max(peak, 1.0)
    z0 = am.JKR_Q_FORMATION if law.jkr else 0.0
    x = np.array([z0, law.y0, 0.0, 0.0, u0[0], u0[1], 0.0] + ([0.0, 0.0, w0[0], w0[1]] if law.rolling else []))
    mode, x = _start_mode(law, x)
    speed = max(math.hypot(*u0), math.hypot(*w0) if law.rolling else 0.0, 1e-300)
    history = speed * tau_scale  # a displacement's scale; a force history's is k at the largest contact
    if law.force_history:
        history *= law.stiffness(z_scale**2 if law.jkr else z_scale)
    springs = (0, 1) if law.rolling else (0,)
    if law.method == "DOP853" and _normal_damping_rate(law, z_scale) > _STIFF_DAMPING:  # strongly damped: stiff
        law.method = "Radau"
    evaluations = [0]
    budget = _MAX_EVALUATIONS if law.method == "DOP853" else _MAX_EVALUATIONS // 10  # Radau's cost ~10 DOP853's
    sigma, switches, events, slide_end = 0.0, 0, 0, math.nan

    def rhs(_, state):
        evaluations[0] += 1
        if evaluations[0] > budget:
            raise DemTangentialError(f"DEM tangential integration ({law.method}): more than {budget} evaluations")
        return _rhs_and_switch(law, state, mode)[0]

    def separation(_, state):
        return _separation(law, state)

    def switch_of(i):
        def switch(_, state):
            if _separation(law, state) <= 0.0:  # past the end of contact: the law is not defined there
                return -1.0 if mode[i] == _STICK else 1.0
            return _rhs_and_switch(law, state, mode)[1][i]
        switch.terminal = True
        return switch

    separation.terminal, separation.direction = True, -1.0
    switches_ = [switch_of(i) for i in springs]
    now = [mode, sigma]  # the mode and the start of the solve, for the events defined outside
    follows = [_follow_event(law, i, now, rtol) for i in springs] if _may_follow(law) else []
    # scipy's order of events: separation, then (switch, peak) of each spring, then their follow events
    watched = [separation] + [f for i in springs for f in (switches_[i], _peak_event(law, i, now))]
    watched += follows
    last, repeats = -math.inf, 0
    while True:
        if follows:  # a direction already at (or already off) its quasi-static value (_follow_event)
            mode, x = _follow_at_restart(law, x, mode, sigma, rtol)
        if events > _MAX_EVENTS:
            raise DemTangentialError(f"DEM tangential integration: more than {_MAX_EVENTS} stick-slip events")
        now[:] = mode, sigma
        for i in springs:
            switches_[i].direction = 1.0 if mode[i] == _STICK else -1.0
            if follows:
                follows[i].direction = 1.0 if mode[i] == _FOLLOW else -1.0
        atol = [z_scale, law.y0, *[history if mode[0] == _STICK else 1.0] * 2, speed, speed, tau_scale]
        if law.rolling:
            atol += [speed * tau_scale if mode[1] == _STICK else 1.0] * 2 + [speed, speed]
        atol = rtol * np.array(atol)
        # a switch that is undone at once (both modes ask to leave where the trial force's rate equals
        # the limit's, h = 0 touched without crossing): the motion is the same in both to first
        # order, so the new mode is kept over a short stretch with its switch event off
        span = _CHATTER_SPAN * max(sigma, 1.0) if repeats >= 2 else _SIGMA_SPAN
        watch = repeats < 2
        try:
            with np.errstate(over="ignore"):  # Radau's difference Jacobian probes far steps; it recovers
                sol = solve_ivp(rhs, (sigma, sigma + span), x, method=law.method, rtol=rtol, atol=atol,
                                dense_output=watch, events=watched if watch else (separation,))
        except ValueError as exc:  # scipy's event location on a switch function that jumps (2-D, tiny limit)
            raise DemTangentialError(f"DEM tangential integration ({law.method}) failed to locate an event: {exc}") from None
        if sol.status == 0 and repeats >= 2:  # the stretch is done: watch for switches again
            sigma, x, repeats = float(sol.t[-1]), sol.y[:, -1].copy(), 0
            continue
        if sol.status != 1:
            raise DemTangentialError(_stopped("tangential", sol))
        first = _first_switch(sol, sigma, switches_, mode) if watch else None
        hit = _first_follow(sol, len(springs)) if watch and follows else None
        if hit is not None and (first is None or hit[0] < first[0]):  # a direction starts or stops following
            sigma, x, mode = hit[0], *_follow_switch(law, hit[1], mode, hit[2])
            events += 1
            continue
        if first is None:  # the contact ended
            return sol.y_events[0][0], (slide_end if mode[0] == _STICK else math.nan), switches, mode[0] == _STICK
        sigma, x, spring = first
        repeats = repeats + 1 if sigma - last <= 1e-12 * max(sigma, 1.0) else 0
        last = sigma
        events += 1
        mode, x, switched = _switch(law, x, mode, spring)
        switches += switched and spring == 0
        if switched and spring == 0 and mode[0] == _STICK:
            slide_end = x[6]


def _peak_event(law, i, now):
    """The event that falls through 0 where spring ``i``'s switch function is farthest towards
    leaving: a maximum of |F| - mu F_n0 in stick (its rate, exact), a minimum of slide's switch
    function (its rate along the motion, a central difference over ``_RATE_STEP`` along the
    right-hand side); ``now`` holds the mode and the start of the solve."""
    def peak(_, state):
        mode, sigma = now
        if _separation(law, state) <= 0.0 or (i == 0 and law.mu == 0.0):  # past the end; no friction
            return 1.0
        if mode[i] == _STICK:
            return _rhs_and_switch(law, state, mode)[2][i]
        rate = _rhs_and_switch(law, state, mode)[0]
        h = _RATE_STEP * max(1.0, abs(sigma))
        ahead, behind = state + h * rate, state - h * rate
        if _separation(law, ahead) <= 0.0 or _separation(law, behind) <= 0.0:
            return 1.0
        change = _rhs_and_switch(law, ahead, mode)[1][i] - _rhs_and_switch(law, behind, mode)[1][i]
        # a following spring's switch function held at exactly 1 (its limit falls, F_n0' < 0) has no
        # extremum: 0 there read as a crossing at every step, and a root search in each (a creep)
        return 1.0 if change == 0.0 and mode[i] == _FOLLOW else -change
    peak.direction = -1.0
    return peak


def _may_follow(law):
    """Whether a sliding direction of this integration may follow its quasi-static value
    (``_FOLLOW``): with the rolling law in 2-D (``_Law.across``: in 1-D the directions do not turn,
    and a strongly damped 1-D impact integrated by Radau is left as it was), where at most one of
    the two springs' P depends on the other's direction (``_quasi_static``)."""
    return law.rolling and law.across and (law.x_t == 0.0 or law.gamma_r == 0.0)


def _follow_value(law, state, mode, i, sigma, rtol):
    """The follow event's function of spring ``i`` (``_follow_event``) at ``state``, relative, in
    [-1, 1]: (lag - rtol) / (lag + rtol) of ``_lag``; 1 where the spring cannot follow or the lag is
    not resolved to a ``_LAG_MARGIN`` part of rtol (its sign would then be rounding's), and on the
    side of the mode it is in where the lag is not determined (the end of contact)."""
    if mode[i] == _STICK or (i == 0 and law.mu == 0.0):
        return 1.0
    found = _lag(law, state, mode, i, sigma, None if mode[i] == _FOLLOW else rtol)
    if found is None:
        return -1.0 if mode[i] == _FOLLOW else 1.0
    lag, unresolved = found
    if not math.isfinite(lag) or unresolved > _LAG_MARGIN * rtol:  # no rest point, or a lag not resolved
        return 1.0
    return (lag - rtol) / (lag + rtol)


def _follow_event(law, i, now, rtol):
    """The terminal event where spring ``i``'s sliding direction starts (falling through 0) or stops
    (rising through 0) following its quasi-static value; ``now`` holds the mode."""
    def follow(t, state):
        return _follow_value(law, state, now[0], i, t, rtol)
    follow.terminal = True
    return follow


def _follow_at_restart(law, x, mode, sigma, rtol):
    """(mode, state) at a restart: each sliding direction that may follow and is already within the
    tolerance of its quasi-static value follows it, each following one already past its lag stops
    (the events see only sign changes after the start)."""
    for i in range(len(mode) if law.rolling else 1):
        if (mode[i] == _FOLLOW) == (_follow_value(law, x, mode, i, sigma, rtol) >= 0.0):
            x, mode = _follow_switch(law, x, mode, i)
    return mode, x


def _follow_switch(law, x, mode, i):
    """(state, mode) once spring ``i`` starts or stops following: its direction is set to the
    quasi-static value either way (the state held the direction of the start while following)."""
    new = tuple((_SLIDE if m == _FOLLOW else _FOLLOW) if j == i else m for j, m in enumerate(mode))
    x = _followed(law, x, mode if mode[i] == _FOLLOW else new)
    return x, new


def _first_follow(sol, n_springs):
    """(sigma, state, spring) of the first follow event of the solve ``sol``, or None (its events are
    separation, then (switch, peak) of each spring, then the follow event of each)."""
    hits = [(float(sol.t_events[1 + 2 * n_springs + i][0]), sol.y_events[1 + 2 * n_springs + i][0].copy(), i)
            for i in range(n_springs) if sol.t_events[1 + 2 * n_springs + i].size]
    return min(hits, key=lambda hit: hit[0]) if hits else None


def _normal_damping_rate(law, z_scale):
    """eta = c3 a^p3 of the normal law at its largest contact radius (z_scale), in its units. [-]"""
    a = z_scale * z_scale if law.jkr else z_scale
    return law.c3 * a**law.p3 if law.c3 > 0.0 else 0.0


def _stopped(what, sol) -> str:
    """The message of an integration that ended without the contact's end: scipy's own where it
    failed; where it ran through its whole span (status 0, which scipy calls a success) the contact
    did not end, which is a normal motion creeping into its equilibrium (module docstring)."""
    if sol.status == 0:
        return (f"DEM {what} integration: the contact did not end within {_SIGMA_SPAN:g} units of the Sundman "
                "variable (a strongly damped normal motion creeping to rest; the DEM laws have no overdamped limit yet)")
    return f"DEM {what} integration failed: {sol.message}"


def _first_switch(sol, start, switch_events, mode):
    """(sigma, state, spring) of the first switch in the solve ``sol`` from ``start``: a crossing
    the events missed inside a step (``_crossing_inside_a_step``), else the first switch event;
    None where the contact ended first. ``sol``'s events are separation, then (switch, peak) of
    each spring."""
    end = float(sol.t_events[0][0]) if sol.t_events[0].size else None
    springs = range(len(switch_events))
    stopped_by = next((j for j in springs if sol.t_events[1 + 2 * j].size), None)
    first = None
    for i in springs:
        # the last instant is checked where the contact ended or the other spring switched (a
        # restart on this spring's limit, rounded outside it, showed no sign change: the rolling
        # force stayed above its limit for half a contact, 2-D rolling at 30 deg)
        last_instant = end if end is not None else (sol.t[-1] if stopped_by not in (None, i) else None)
        missed = _crossing_inside_a_step(sol, start, switch_events[i], 1.0 if mode[i] == _STICK else -1.0,
                                         sol.t_events[2 + 2 * i], last_instant)
        if missed is not None and (first is None or missed[0] < first[0]):
            first = (*missed, i)
    if first is None and stopped_by is not None:
        first = (float(sol.t_events[1 + 2 * stopped_by][0]), sol.y_events[1 + 2 * stopped_by][0].copy(), stopped_by)
    return first


def _switch(law, x, mode, spring):
    """(mode, state, whether it changed) after spring ``spring`` (0 tangential, 1 rolling) reached
    its switch: from stick to slide along the force unless it only grazes the limit; from slide to
    stick with the history of the force on the limit."""
    _, _, a, _, eta, _, _, n0, _ = law.normal(x[0], x[1])
    x = _followed(law, x, mode) if _FOLLOW in mode else x.copy()  # a following direction is not in x
    if spring == 0:
        model, k, eta_v, mu, state, velocity = law.model, law.stiffness(a), law.x_t * eta, law.mu, slice(2, 4), slice(4, 6)
    else:
        model, k, eta_v, mu, state, velocity = "linear_history", law.k_r, law.gamma_r, law.mu_r, slice(7, 9), slice(9, 11)
    if mode[spring] == _STICK:
        f = lammps_elastic_force(model, x[state], k) - eta_v * x[velocity]
        if not math.hypot(*f) > 0.0:  # no force, no direction to slide along: the limit only grazed (0 = 0)
            return mode, x, False
        sliding = x.copy()
        sliding[state] = f / math.hypot(*f)
        new = (_SLIDE, mode[1]) if spring == 0 else (mode[0], _SLIDE)
        if _rhs_and_switch(law, sliding, new)[1][spring] > 0.0:
            return new, sliding, True
        return mode, x, False
    e = x[state] / math.hypot(*x[state])
    x[state] = lammps_history_of_force(model, mu * n0 * e + eta_v * x[velocity], k)
    return ((_STICK, mode[1]) if spring == 0 else (mode[0], _STICK)), x, True


def _crossing_inside_a_step(sol, start, switch, sign, tops, end):
    """(sigma, state) where the mode should first have been left unseen by the events, or None.

    ``sign`` is +1 in stick (left where the switch function rises through 0: |F| reaches the limit)
    and -1 in slide (left where it falls through 0: the trial force turns inwards); ``tops`` the
    extrema of the switch function towards leaving (the ``peak`` events), ``end`` the end of
    contact (None if the solve stopped at a switch). scipy's events see a sign change only between
    the ends of a step, and past the end of contact the switch function is held on the side of
    staying (``end`` is also the instant where the other spring switched). A crossing in the step that ends the contact, or an excursion that begins and ends
    inside one step, was therefore lost (LAMMPS's JKR with mindlin/force, 0.13 m/s, 20 deg: stuck
    to the end with |F| 9 % above the limit there, e_t 0.8998 against LAMMPS's 0.9029; DMT +
    mass_velocity mindlin, 27 m/s, 47 deg: a stick inside one slide step missed at rtol 1e-10, e_t
    6e-6 off). Each extremum and the last instant of contact are therefore checked on the dense
    output; where one lies past 0, the first crossing before it is the switch."""
    def leaving(t):
        return sign * switch(t, sol.sol(t))

    tops = list(tops)
    if end is not None:  # the contact ended: look just inside its end
        tops = [t for t in tops if t < end] + [end - 1e-9 * (end - start)]
    lo = start
    for top in tops:
        if top <= lo or leaving(top) <= 0.0:
            lo = max(lo, top)
            continue
        if leaving(lo) > 0.0:
            # on the switch at the start (a restart on the limit), past it by rounding: the events
            # saw no sign change. Where the motion went back inside, the crossing is after that;
            # where it never did, the mode is left at once (DMT, mass_velocity, 47 deg: the
            # crossing 0.4 contact times in was lost this way, e_t 0.8070 at rtol 1e-8 against
            # 0.7344, LAMMPS's 0.73441 at 2000 and 16000 steps)
            inside = next((t for t in np.linspace(lo, top, _SCAN_POINTS)[1:-1] if leaving(t) < 0.0), None)
            if inside is None:
                return lo, sol.sol(lo)
            lo = inside
        try:
            root = brentq(leaving, lo, top, xtol=1e-15 * max(abs(top), 1.0), rtol=1e-15)
        except ValueError:  # the switch function gave both signs at lo (2-D rolling with a tiny limit)
            raise DemTangentialError("DEM tangential integration: a stick-slip switch could not be located "
                                     f"(switch function {leaving(lo):.3g} and {leaving(top):.3g} at its ends)") from None
        return root, sol.sol(root)
    return None


def solve_dem_tangential(contact, velocity_in, omega_in, *, rtol: float) -> NormalSolution:
    """One impact of a contact with a DEM tangential law.

    Parameters
    ----------
    contact : Contact
        ``tangential_model`` one of :data:`~microimpact.model.dem_tangential.DEM_TANGENTIAL_MODELS`.
    velocity_in : tuple of 3 float
        (v_n, v_t, v_t') before contact, v_n < 0. [m/s]
    omega_in : tuple of 3 float
        (omega_n, omega_t, omega_t') before contact. [rad/s]
    rtol : float
        Relative tolerance of the normal solve; the tangential integration takes at most
        :data:`TANGENTIAL_RTOL` (its event location makes its error a few times its tolerance:
        5e-7 in e_t at rtol 1e-8, 2e-10 at 1e-10, measured at 5 deg). [-]

    Returns
    -------
    NormalSolution
        The normal solve, with ``slip_end_time`` [s] the end of the last slide if it ends stuck
        (else NaN) and the tangential outcome in its ``state``: ``velocity_out``, ``omega_out``
        (3-tuples, [m/s], [rad/s]), ``slip_ended`` (bool: the contact is stuck at separation, or
        the captured sphere rolls), ``tangential_impulse`` (2-tuple, [N s]), ``switches``
        (stick-slip changes) and, with a twisting law, ``twist_switches``.

    Raises
    ------
    DemTangentialError
        If the tangential integration does not reach the end of the contact.

    References
    ----------
    LAMMPS documentation, ``pair_style granular``, https://docs.lammps.org/pair_granular.html.

    Examples
    --------
    A Hertz sphere with LAMMPS's Mindlin law at 70 deg slides throughout: the tangential impulse is
    mu times the normal one, mu_t = -mu:

    >>> from microimpact.model.contact import Contact
    >>> c = Contact(1e-6, 2000.0, 1e9, 0.0, friction=0.2, tangential_model="lammps_mindlin",
    ...             shear_modulus=3e8)
    >>> v = (-math.cos(math.radians(70.0)), math.sin(math.radians(70.0)), 0.0)
    >>> r = solve_dem_tangential(c, v, (0.0, 0.0, 0.0), rtol=1e-10)
    >>> v_out = r.state["velocity_out"]
    >>> round((v_out[1] - v[1]) / (v_out[0] - v[0]), 8), r.stop_reason
    (-0.2, 'separation')
    """
    normal = solve_normal(contact, -float(velocity_in[0]), rtol=rtol)
    result = _slip(contact, normal, velocity_in, omega_in, rtol)
    if contact.twisting_model in DEM_TWISTING_MODELS:
        twist, twist_switches = _twist(contact, normal, float(velocity_in[0]), float(omega_in[0]), rtol)
        result["omega_out"] = (twist, *result["omega_out"][1:])
        result["twist_switches"] = twist_switches
    del result["normal"]
    return dataclasses.replace(normal, slip_end_time=result.pop("slip_end_time"), state=result)


def _slip(contact, normal, velocity_in, omega_in, rtol):
    """``solve_dem_tangential`` without the twisting law: the slip (and the rolling) of one impact."""
    m, inertia, r = contact.mass, contact.moment_of_inertia, contact.radius
    v_n, v_t, v_tp = (float(v) for v in velocity_in)
    w_n, w_t, w_tp = (float(w) for w in omega_in)
    slip = (v_t + r * w_tp, v_tp - r * w_t)
    kappa = 1.0 / m + r * r / inertia
    switches, slip_ended, slip_end_time = 0, False, math.nan
    if contact.rolling_model in DEM_ROLLING_MODELS and contact.rolling_friction > 0.0:  # mu_roll = 0: no torque
        return _with_rolling(contact, normal, (v_n, v_t, v_tp), (w_n, w_t, w_tp), rtol)
    if contact.friction == 0.0 or slip == (0.0, 0.0):
        impulse = (0.0, 0.0)
    elif normal.outcome == "capture":  # the sphere ends rolling (module docstring)
        impulse = (-slip[0] / kappa, -slip[1] / kappa)
        slip_ended = True
    else:
        law, unit, tau_scale, z_scale = _impact_law(contact, normal, v_n)
        sc = law.scales
        # integrated along the initial slip (module docstring): its components across stay exactly 0
        size = math.hypot(*slip)
        end, slide_end, switches, slip_ended = _integrate(law, (size / unit, 0.0), min(rtol, TANGENTIAL_RTOL),
                                                          tau_scale, z_scale)
        along = float(end[4]) * unit / size  # u_out / u_in
        impulse = ((along - 1.0) * slip[0] / kappa, (along - 1.0) * slip[1] / kappa)
        slip_end_time = slide_end * float(sc.time) if math.isfinite(slide_end) else math.nan
    j_t, j_tp = impulse
    return {
        "normal": normal,
        "velocity_out": (normal.e_n * -v_n if normal.outcome == "rebound" else 0.0, v_t + j_t / m, v_tp + j_tp / m),
        "omega_out": (w_n, w_t - r * j_tp / inertia, w_tp + r * j_t / inertia),
        "slip_ended": slip_ended,
        "slip_end_time": slip_end_time,
        "tangential_impulse": (j_t, j_tp),
        "switches": switches,
    }


def _impact_law(contact, normal, v_n):
    """(the law, its speed unit [m/s], the contact time and the largest approach's z, in its units)."""
    law = _Law(contact, -v_n)
    sc = law.scales
    peak = normal.max_penetration / float(sc.length)
    z_scale = max(1.0, am.jkr_q_from_approach(peak) if law.jkr else math.sqrt(peak))
    return law, float(sc.speed), normal.contact_time / float(sc.time), z_scale


def _with_rolling(contact, normal, velocity_in, omega_in, rtol):
    """``solve_dem_tangential`` with LAMMPS's rolling law: slip u and rolling velocity w together.

    Integrated in the frame of the initial slip (of the rolling velocity where the sphere does not
    slip); a rolling velocity parallel to it to rounding (1e-13) is put exactly on it, so that a
    planar impact stays exactly planar. Outcome: v_t changes by the tangential impulse over m,
    du + dw; w by dw, and the spin by w = (-R omega_t', R omega_t) (model.dem_rolling)."""
    m, inertia, r = contact.mass, contact.moment_of_inertia, contact.radius
    v_n, v_t, v_tp = velocity_in
    w_n, w_t, w_tp = omega_in
    slip = np.array([v_t + r * w_tp, v_tp - r * w_t])
    roll = np.array(lammps_rolling_velocity(r, w_t, w_tp), dtype=float)
    spin = m * r * r / inertia  # kappa - 1
    switches, slip_ended, slip_end_time = 0, False, math.nan
    mu, mu_r = contact.friction, contact.rolling_friction
    # without friction the slip carries no force, and a rolling velocity 0 leaves the rolling spring
    # unloaded: nothing acts (the rolling velocity's frame below was 0 / 0, the stress sweep's sds
    # law, case 30 of seed 0)
    if (mu == 0.0 and (mu_r == 0.0 or not roll.any())) or not (slip.any() or roll.any()):
        du, dw = np.zeros(2), np.zeros(2)
    elif normal.outcome == "capture":
        # at rest on the wall both limits stay > 0 (2 mu F_po): the slip stops, and the rolling where
        # mu_roll > 0 (as the slip alone does without it, module docstring); a stuck vibration of the
        # springs is left, which averages to zero. du = kappa J - (kappa - 1) J_r, dw = (kappa - 1) (J_r - J)
        # per unit mass: with one of the impulses 0 the other follows from the velocity that stops
        if mu > 0.0 and mu_r > 0.0:
            du, dw = -slip, -roll
        elif mu > 0.0:
            du = -slip
            dw = -spin / (1.0 + spin) * du
        else:
            dw = -roll
            du = -dw
        slip_ended = mu > 0.0
    else:
        law, unit, tau_scale, z_scale = _impact_law(contact, normal, v_n)
        sc = law.scales
        # without friction (mu = 0) the slip carries no force whatever its value (du = -dw), and the
        # rolling law alone moves the rolling velocity, on its own line: solved from zero slip in the
        # rolling velocity's frame (a slip across it sent a 1-D rolling problem to Radau, and the
        # frictionless spring's stick-slide switching of DOP853 past 2e6 evaluations: the stress
        # sweep's sds law, case 15 of seed 0)
        slip_solved = slip if mu > 0.0 else np.zeros(2)
        first = slip_solved if slip_solved.any() else roll
        e1 = first / math.hypot(*first)
        e2 = np.array([-e1[1], e1[0]])
        u0 = np.array([slip_solved @ e1, slip_solved @ e2]) / unit
        w0 = np.array([roll @ e1, roll @ e2]) / unit
        u0[1] = 0.0  # the frame's first axis is the slip (or the slip is 0)
        if abs(w0[1]) <= 1e-13 * abs(w0[0]):
            w0[1] = 0.0
        tol = min(rtol, TANGENTIAL_RTOL)
        # the rolling pseudo-force changes w by at most (kappa - 1) mu_roll int F_n0 dt, F_n0 at most
        # twice its elastic peak (damping): below the tolerance of the impact's speeds it is dropped (LAMMPS's
        # rolling law with mu_roll 1e-12 beside friction 0.3 moved nothing, but made a 2-D solve fail)
        most = 2.0 * law.spin * law.mu_r * (z_scale**6 / 6.0 + 3.0 if law.jkr else z_scale**3 + 2.0 * law.pulloff) * tau_scale
        if most <= tol * max(math.hypot(*u0), math.hypot(*w0), law.y0):
            return _slip(contact.with_(rolling_model="torque", rolling_stiffness=None, rolling_friction=0.0,
                                       rolling_damping=0.0), normal, velocity_in, omega_in, rtol)
        # rolling across the slip: the directions of both forces turn, at rates |G'| / (mu F_n0) that
        # made DOP853 take millions of steps where a limit is small; an implicit method follows them
        # (_ACROSS_METHODS)
        methods = _ACROSS_METHODS if w0[1] != 0.0 else ("DOP853",)
        law.across = w0[1] != 0.0
        failed = []
        for method in methods:
            law.method = method
            try:
                end, slide_end, switches, slip_ended = _integrate(law, tuple(u0), tol, tau_scale, z_scale,
                                                                  w0=tuple(w0))
                break
            except DemTangentialError as exc:
                failed.append(str(exc))
        else:
            raise DemTangentialError("; ".join(failed))
        du_f, dw_f = (end[4:6] - u0) * unit, (end[9:11] - w0) * unit
        du, dw = du_f[0] * e1 + du_f[1] * e2, dw_f[0] * e1 + dw_f[1] * e2
        slip_end_time = slide_end * float(sc.time) if math.isfinite(slide_end) else math.nan
    impulse = m * (du + dw)
    v_out, w_out = np.array([v_t, v_tp]) + du + dw, roll + dw
    if normal.outcome == "capture" and mu > 0.0 and mu_r > 0.0:
        v_out, w_out = np.zeros(2), np.zeros(2)  # at rest (above), free of the sums' rounding
    return {
        "normal": normal,
        "velocity_out": (normal.e_n * -v_n if normal.outcome == "rebound" else 0.0, float(v_out[0]), float(v_out[1])),
        "omega_out": (w_n, float(w_out[1] / r), float(-w_out[0] / r) + 0.0),
        "slip_ended": slip_ended,
        "slip_end_time": slip_end_time,
        "tangential_impulse": (float(impulse[0]), float(impulse[1])),
        "switches": switches,
    }


class _Twist:
    """LAMMPS's twisting law of one impact (model.dem_twisting) in the normal law's units: torque
    unit F L, twist rate unit 1 / T; ``gain`` turns a torque into d Omega / d tau (F L T^2 / I)."""

    def __init__(self, contact, law):
        sc = law.scales
        force, length, time = float(sc.force), float(sc.length), float(sc.time)
        torque = force * length
        self.law = law
        self.gain = torque * time * time / contact.moment_of_inertia
        self.sds = contact.twisting_model == "lammps_sds"
        if self.sds:
            self.k = contact.twisting_stiffness / torque
            self.gamma = contact.twisting_damping / (torque * time)
            self.mu = contact.twisting_friction / length  # the limit mu_twist F_n0 in F L
        else:  # Marshall: the coefficients at a = 1 law unit of radius, scaled by a^2, a^2, a below
            a_unit = law.a_unit
            k1, g1, m1 = lammps_marshall_twisting_coefficients(a_unit, law.k_param, 1.0, law.mu)
            self.k = float(k1) / torque
            self.gamma = float(g1) * force / (float(sc.speed) * torque * time)  # per unit eta_t in F / (L / T)
            self.mu = float(m1) / length

    def coefficients(self, z, y):
        """(g, dz, dy, k, dk, gamma, dgamma, limit, dlimit), d/dsigma, at the normal state (z, y)."""
        law = self.law
        g, dz, a, da, eta, deta, dy, n0, dn0 = law.normal(z, y)
        if self.sds:
            return g, dz, dy, self.k, 0.0, self.gamma, 0.0, self.mu * n0, self.mu * dn0
        # k ~ a^2, gamma ~ eta_t a^2 (eta_t = x_t eta), limit ~ a F_n0 (lammps_marshall_twisting_coefficients)
        eta_t, deta_t = law.x_t * eta, law.x_t * deta
        return (g, dz, dy, self.k * a * a, 2.0 * self.k * a * da, self.gamma * eta_t * a * a,
                self.gamma * (deta_t * a * a + 2.0 * eta_t * a * da), self.mu * a * n0, self.mu * (da * n0 + a * dn0))


def _twist_rates(twist, x, mode, sign):
    """(d/dsigma of [z, y, tau, xi, Omega], the switch function of ``mode``) at x.

    Stick: torque -k xi - gamma Omega, switch (|M| - limit) / (|M| + limit), leaving upwards. Slide:
    torque -limit sgn(Omega) (``sign``), switch the rate of the trial torque's size (its history at
    the reset value) less that of the limit, leaving downwards (the trial torque turns inside)."""
    g, dz, dy, k, dk, gamma, dgamma, limit, dlimit = twist.coefficients(x[0], x[1])
    w = x[4]
    out = np.empty(5)
    out[0], out[1], out[2] = dz, dy, g
    if mode == _STICK:
        torque = -k * x[3] - gamma * w
        out[3], out[4] = g * w, g * twist.gain * torque
        size = abs(torque) + limit
        return out, ((abs(torque) - limit) / size if size > 0.0 else -1.0)
    torque = -limit * sign
    out[3], out[4] = 0.0, g * twist.gain * torque
    if k <= 0.0:  # a = 0 (Marshall at a Hertz touch): no spring to stick with
        return out, 1.0
    xi = (limit * sign - gamma * w) / k
    trial_rate = -(dk * xi + k * g * w) - (dgamma * w + gamma * out[4])
    return out, -sign * trial_rate - dlimit


def _twist(contact, normal, v_n, omega_n, rtol):
    """(spin about the normal after the impact [rad/s], twisting stick-slip switches) of LAMMPS's
    twisting law (model.dem_twisting), integrated with the normal law in its Sundman variable.

    The sliding twist may stop (Omega = 0) while the limit falls faster than the dashpot can hold the
    spring at it: neither mode holds, and LAMMPS's torque -mu_twist F_n0 sgn(Omega) chatters about
    Omega = 0 at its step. Where the limit ends at 0 (Hertz) LAMMPS converges to Omega = 0; where it
    does not (JKR, DMT) its chattering leaves a stuck vibration, of amplitude up to
    mu_twist F_n0 / sqrt(k_twist I), whose phase at separation depends on its step
    (docs/guide/lammps.md). microimpact takes the mean, Omega = 0 from there on (a spring at rest,
    xi = 0, Omega = 0, solves the stuck law). A captured sphere ends with Omega = 0 where the limit
    at rest is > 0 (its stuck elastic vibration averages to zero), as the slip does."""
    if omega_n == 0.0:
        return 0.0, 0
    law, unit, tau_scale, z_scale = _impact_law(contact, normal, v_n)
    twist = _Twist(contact, law)
    if normal.outcome == "capture":  # at rest on the wall: held where the limit is > 0
        return (0.0 if twist.mu > 0.0 else omega_n), 0
    time = float(law.scales.time)
    w0 = omega_n * time
    tol = min(rtol, TANGENTIAL_RTOL)
    x = np.array([am.JKR_Q_FORMATION if law.jkr else 0.0, law.y0, 0.0, 0.0, w0])
    # stick or slide from touch: compared a short way in (as _start_mode), xi = Omega tau
    probe = x.copy()
    probe[0], probe[2] = _just_after_touch(law, x[0], x[1])
    probe[3] = w0 * probe[2]
    mode = _SLIDE if _twist_rates(twist, probe, _STICK, 0.0)[1] > 0.0 else _STICK
    sign = math.copysign(1.0, w0)
    sigma, switches = 0.0, 0
    atol = tol * np.array([z_scale, law.y0, tau_scale, abs(w0) * tau_scale, abs(w0)])

    # a strongly damped normal motion is stiff here as in the slip's integration (_STIFF_DAMPING)
    method = "Radau" if _normal_damping_rate(law, z_scale) > _STIFF_DAMPING else "DOP853"
    budget = _MAX_EVALUATIONS if method == "DOP853" else _MAX_EVALUATIONS // 10
    evaluations = [0]

    def rhs(_, state):
        evaluations[0] += 1
        if evaluations[0] > budget:
            raise DemTangentialError(f"DEM twisting integration ({method}): more than {budget} evaluations")
        return _twist_rates(twist, state, mode, sign)[0]

    def separation(_, state):
        return _separation(law, state)

    def switch(_, state):
        if _separation(law, state) <= 0.0:
            return -1.0 if mode == _STICK else 1.0
        return _twist_rates(twist, state, mode, sign)[1]

    def stopped(_, state):  # the sliding twist reaches Omega = 0
        return state[4] * sign if mode == _SLIDE else 1.0

    separation.terminal, separation.direction = True, -1.0
    switch.terminal = stopped.terminal = True
    stopped.direction = -1.0
    while True:
        switch.direction = 1.0 if mode == _STICK else -1.0
        with np.errstate(over="ignore"):  # Radau's difference Jacobian probes far steps; it recovers
            sol = solve_ivp(rhs, (sigma, sigma + _SIGMA_SPAN), x, method=method, rtol=tol, atol=atol,
                            events=(separation, switch, stopped))
        if sol.status != 1:
            raise DemTangentialError(_stopped("twisting", sol))
        hits = [(float(t[0]), i) for i, t in enumerate(sol.t_events) if len(t)]
        t_hit, which = min(hits)
        x = sol.y_events[which][0].copy()
        sigma = t_hit
        if which == 0:
            return float(x[4]) / time, switches
        switches += 1
        if switches > _MAX_EVENTS:
            raise DemTangentialError(f"DEM twisting integration: more than {_MAX_EVENTS} stick-slip events")
        if which == 2:
            # Omega = 0 in slide, the slide's switch function still > 0: it is continuous in Omega and at
            # Omega = 0 it is the rate at which a stuck spring held at the limit would leave it, so
            # neither mode holds: the chattering end of the docstring, Omega = 0 from here on
            return 0.0, switches
        g, dz, dy, k, dk, gamma, dgamma, limit, dlimit = twist.coefficients(x[0], x[1])
        if mode == _STICK:  # the torque reaches the limit: slide against the twist rate
            mode = _SLIDE
            sign = math.copysign(1.0, x[4]) if x[4] != 0.0 else math.copysign(1.0, x[3])  # at rest: the spring's way
        else:  # the trial torque turns inside the limit: stick with the history at the reset value
            mode = _STICK
            x[3] = (limit * sign - gamma * x[4]) / k
