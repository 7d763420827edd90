"""Expected values derived here, independently of the toolkit's own formulas and earlier output.

Each test computes its expectation from first principles in the test itself (hand arithmetic of
Table 1 row 2, a quadrature of the energy integral, a scipy integration of Eq. (27) written out in
SI units, closed-form rigid-body limits) so that a wrong factor in a shared toolkit function fails
it. Tolerances say where they come from.
"""

from __future__ import annotations

import math

import pytest
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq

import microimpact as mi
from microimpact.dynamics import asymptotic_frequency, capture_velocity
from microimpact.model.contact import Contact

# Table 1 row 2 of Cheng, Brach & Dunn (2002), typed here again on purpose (not taken from presets)
R, RHO, K, F0 = 3.45e-6, 1350.0, 1.776e9, 7.422
ZETA_H, ZETA_A = 0.50, 29.0
MASS = 4.0 / 3.0 * math.pi * R**3 * RHO
PAPER = Contact(radius=R, density=RHO, stiffness=K, adhesion_line_force=F0, zeta_hertz=ZETA_H,
                zeta_adhesion=ZETA_A)


def _damping(v_n: float) -> tuple[float, float]:
    """C_H, C_A [s/m] from Eqs. (14)-(15) with the impact's own normal speed as v_n."""
    bracket = (R**3 * K * math.sqrt(v_n) / MASS) ** 0.4
    return ZETA_H / bracket, ZETA_A / bracket


def _rhs(_t, z, c_h, c_a, f0):
    """Eq. (27) in SI: z = (x, x'), x the penetration; F_H = sqrt(r) K x^1.5, F_A = 2 pi f0 sqrt(r x)."""
    x, xd = z
    xp = max(x, 0.0)
    f_h = math.sqrt(R) * K * xp**1.5
    f_a = 2.0 * math.pi * f0 * math.sqrt(R * xp)
    return [xd, (-f_h * (1.0 + c_h * xd) + f_a * (1.0 - c_a * xd)) / MASS]


def _potential(x, f0):
    return 0.4 * math.sqrt(R) * K * x**2.5 - 4.0 / 3.0 * math.pi * f0 * math.sqrt(R) * x**1.5


def _captured(v: float) -> bool:
    """Outcome of a normal impact at v by scipy DOP853 on Eq. (27): captured once E < 0."""
    c_h, c_a = _damping(v)

    def energy(_t, z, *_):
        return 0.5 * MASS * z[1] ** 2 + _potential(max(z[0], 0.0), F0)

    def separated(_t, z, *_):
        return z[0]  # x falls back through 0: rebound

    energy.terminal, energy.direction = True, -1
    separated.terminal, separated.direction = True, -1
    sol = solve_ivp(_rhs, (0.0, 1e-6), [1e-16, v], args=(c_h, c_a, F0), method="DOP853", rtol=1e-10,
                    atol=1e-18, events=(energy, separated), max_step=2e-9)
    return sol.t_events[0].size > 0


# ----------------------------------------------------------------------------- dynamics pins
def test_asymptotic_frequency_from_hand_arithmetic():
    """omega_f = sqrt(4 - C^2) / (2 T), Eq. (37) corrected, with X = 2 pi f0 / K (Eq. 29),
    T = sqrt(m / sqrt(2 pi r f0 K)) (Eq. 30 corrected) and C = (C_H + C_A) X / T: all typed here."""
    v = 0.5
    x_scale = 2.0 * math.pi * F0 / K
    t_scale = math.sqrt(MASS / math.sqrt(2.0 * math.pi * R * F0 * K))
    c_h, c_a = _damping(v)
    c = (c_h + c_a) * x_scale / t_scale
    expected = math.sqrt(4.0 - c * c) / (2.0 * t_scale)
    assert asymptotic_frequency(PAPER, v) == pytest.approx(expected, rel=1e-12)  # same arithmetic, round-off
    assert expected == pytest.approx(4.7539e7, rel=1e-4)  # the value the report quotes


def test_capture_velocity_against_a_scipy_integration_of_eq27():
    """Bisection on the outcome of an independent SI integration of Eq. (27) (DOP853, rtol 1e-10)
    brackets the toolkit's capture velocity; the bracket is closed to 2e-4 relative (12 halvings of
    [1.40, 1.50] m/s is 2.4e-5 m/s; the scipy outcome itself is sharp to ~1e-6 at rtol 1e-10)."""
    lo, hi = 1.40, 1.50
    assert _captured(lo) and not _captured(hi)
    for _ in range(12):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _captured(mid) else (lo, mid)
    assert capture_velocity(PAPER) == pytest.approx(0.5 * (lo + hi), rel=2e-4)


# ----------------------------------------------------------------------------- the integration itself
@pytest.mark.parametrize("v", [0.05, 1.0, 20.0])
def test_undamped_adhesive_contact_time_from_the_energy_integral(v):
    """With no damping the engine exploits time reversibility (mirrors the way in), so e_n = 1 can't
    fail; the way in is tested here. Energy conservation gives t(x) = int dx / sqrt(v^2 - 2 V(x)/m):
    the largest penetration is the root of m v^2 / 2 = V(x_max), and the contact time is twice the
    quadrature to it (the 1/sqrt singularity removed by x = x_max (1 - u^2))."""
    contact = PAPER.with_(zeta_hertz=0.0, zeta_adhesion=0.0)
    x_max = brentq(lambda x: _potential(x, F0) - 0.5 * MASS * v * v, 1e-15, 1e-5, xtol=1e-25, rtol=1e-15)

    def integrand(u):
        x = x_max * (1.0 - u * u)
        return 2.0 * u * x_max / math.sqrt(max(v * v - 2.0 * _potential(x, F0) / MASS, 1e-300))

    t_half, err = quad(integrand, 0.0, 1.0, epsabs=0.0, epsrel=1e-12, limit=200)
    res = mi.simulate_impact(contact, v, rtol=1e-10)
    assert res.e_n == 1.0
    # the quadrature is good to ~1e-11; the engine's events to ~its rtol (1e-10): 1e-8 margin
    assert res.max_penetration == pytest.approx(x_max, rel=1e-8)
    assert res.contact_time == pytest.approx(2.0 * t_half, rel=1e-8)


# ----------------------------------------------------------------------------- energy ratios
@pytest.mark.parametrize("alpha", [10.0, 30.0, 60.0, 85.0])
def test_rolling_after_capture_energy_ratios(alpha):
    """A sphere captured at low speed with high friction ends rolling with v_t = (5/7) v sin(alpha)
    (the 2/7 rule) and omega = v_t / r, so K_L = 1 - (25/49) sin^2 and K_t = 1 - (5/7) sin^2
    (translational 25/49, rotational (2/5)(25/49) of the incident energy v^2 sin^2)."""
    contact = PAPER.with_(friction=1.0)
    res = mi.simulate_impact(contact, 0.3, incidence_deg=alpha, rtol=1e-10)
    s2 = math.sin(math.radians(alpha)) ** 2
    assert res.outcome == "capture" and res.slip_ended
    # the slip ends while adhesion holds the sphere: the friction impulse up to there is resolved
    # to the solver's tolerance, so the ratios agree to ~1e-9
    assert res.K_L == pytest.approx(1.0 - 25.0 / 49.0 * s2, abs=1e-9)
    assert res.K_t == pytest.approx(1.0 - 5.0 / 7.0 * s2, abs=1e-9)


@pytest.mark.parametrize("method", ["engine", "reference"])
@pytest.mark.parametrize("case", [
    dict(speed=3.0, incidence_deg=0.0),
    dict(speed=3.0, incidence_deg=40.0, omega=(1e5, 2e5, -3e5)),
    dict(speed=8.0, incidence_deg=70.0, azimuth_deg=30.0, omega=(0.0, 0.0, 4e5)),
])
def test_total_energy_loss_ratio_is_the_dissipated_fraction(method, case):
    """For a rebound the kinetic energy lost is the energy dissipated by damping and friction,
    which the solvers integrate along the motion: K_t = D / KE_in checks Eq. (24) (translational and
    rotational terms) against a quantity the formula does not use. The tracked D has the solver's
    accuracy (rtol 1e-10: ~1e-9 of KE_in)."""
    contact = PAPER.with_(friction=0.3)
    res = mi.simulate_impact(contact, rtol=1e-10, method=method, **case)
    assert res.outcome == "rebound"
    inertia = 0.4 * MASS * R * R
    ke_in = 0.5 * MASS * sum(u * u for u in res.velocity_in) + 0.5 * inertia * sum(w * w for w in res.omega_in)
    ke_out = 0.5 * MASS * sum(u * u for u in res.velocity_out) + 0.5 * inertia * sum(w * w for w in res.omega_out)
    assert res.K_t == pytest.approx(1.0 - ke_out / ke_in, abs=1e-12)  # Eq. (24) written out here
    assert res.K_t == pytest.approx(res.dissipated_energy / ke_in, abs=1e-8)
    v2_in = sum(u * u for u in res.velocity_in)
    assert res.K_L == pytest.approx(1.0 - sum(u * u for u in res.velocity_out) / v2_in, abs=1e-12)  # Eq. (25)
