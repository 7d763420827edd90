"""The coupled solver's inertia-free limit before the capture (issue 55's corner of the stress domain).

A nanometre sphere (r = 1e-9 m, K = 1e8 Pa, w_A = 10 J/m^2) under zeta_A = 1e6 at 10 m/s and 89 deg
(normal speed 0.1745 m/s): C2 ~ 2e9, so the sphere creeps from first contact into the well at
y_m ~ 1 / C2 and is not captured within the step budget by the energy test. Every compliant law
ended in "step limit reached after 2000000 steps" there (8 of the 128 corners of the stress domain
per law, whatever the density, zeta_H or friction). Now the normal motion takes the engine's
inertia-free path into the equilibrium (microimpact.solvers.coupled._law_creep) and the tangential
tail is the creeping captured sphere's closed form. The other such corner: no adhesion, zeta_H =
1e6, K = 1e8 Pa, 1e4 m/s, which now leaves on the engine's invariant line.
"""

from __future__ import annotations

import math

import pytest

from microimpact.model import law as _law
from microimpact.solvers.impact import simulate_impact
from microimpact.studies import stress

#: the corner of issue 55 (f = 2, zeta_H = 1e-3, rho = 1e3; the other seven differ only in them)
CORNER = dict(radius=1e-9, density=1e3, stiffness=1e8, work_of_adhesion=10.0, zeta_hertz=1e-3, zeta_adhesion=1e6,
              friction=2.0, speed=10.0, incidence_deg=89.0, azimuth_deg=0.0, omega_n=0.0, omega_t=0.0, omega_tp=0.0)
COUPLED_LAWS = ("mindlin", "mindlin_deresiewicz", "mindlin_pulloff", "mindlin_deresiewicz_pulloff_rolling")


@pytest.mark.parametrize("law", COUPLED_LAWS)
@pytest.mark.parametrize("zeta_hertz, friction", [(1e-3, 2.0), (1e6, 0.0)])
def test_the_corner_is_captured_and_passes_the_stress_checks(law, zeta_hertz, friction):
    """Each compliant law gives the corner a result (it raised CoupledError, step limit) that passes
    every check of the stress sweep: energy balance, convergence in rtol, finite fields."""
    case = dict(CORNER, zeta_hertz=zeta_hertz, friction=friction)
    row = stress.check_case(case, law=law)
    assert row["failures"] == [], row["failures"]
    assert row["outcome"] == "capture"


def _tail_bound(contact, rtol):
    """Bound on |v_t error| [m/s] of the closed-form tail from the inertia-free entry: the friction
    impulse still to come is taken as |y| (the total variation of y if it falls monotonically to 0),
    and the state enters within 2 eps |y_m| + 10 atol_y of the manifold (eps <= 1e-6 the inertia
    ratio, atol_y = rtol max(1, y0), |y_m| <= 1 / C2 on the inward path in the paper's scales): the
    variation is off by at most twice that, and v_t changes by f times it (u = L / T_c)."""
    sc, y0, _, c2 = _law.nondimensional_impact(contact, CORNER["speed"] * math.cos(math.radians(89.0)))
    u = sc.length / sc.time
    return 2.0 * contact.friction * (10.0 * rtol * max(1.0, float(y0)) + 2e-6 / float(c2)) * u


@pytest.mark.parametrize("zeta_adhesion", [1e3, 1e6])
def test_the_creeping_tail_converges_within_its_bound(zeta_adhesion):
    """Mindlin contact, f = 2: v_t at rtol 1e-8 (and at the corner 1e-10) lies within the tail's
    bound (:func:`_tail_bound`) of the solve at rtol 1e-12, and the error falls with rtol. (At
    zeta_A = 1e3 and rtol 1e-10 the integration before the entry, 4.1e-3 m/s off without the limit,
    adds its own error to the tail's, so only the fall is asserted there.)

    At zeta_A = 1e3 the solve at rtol 1e-12 is the explicit integration to the creeping captured
    stop: measured bit for bit the same v_t (9.918912113834361 m/s) as the code without the limit,
    an independent solve of the tail. Measured errors: 3.6e-3 and 1.6e-3 m/s at zeta_A = 1e3, 4.6e-3
    and 1.4e-4 m/s at 1e6, against bounds of 3.3e-2 and 3.3e-4 m/s (the code without the limit was
    off by 5.7 m/s at zeta_A = 1e3, rtol 1e-8: the friction impulse summed the integration noise of
    the normal rate, 600 times the incident momentum; at 1e6 it had no result)."""
    contact = stress.contact_of(dict(CORNER, zeta_adhesion=zeta_adhesion), "mindlin")
    results = {rtol: simulate_impact(contact, 10.0, 89.0, rtol=rtol) for rtol in (1e-8, 1e-10, 1e-12)}
    assert all(r.outcome == "capture" for r in results.values())
    v_t = {rtol: r.velocity_out[1] for rtol, r in results.items()}
    errors = {rtol: abs(v_t[rtol] - v_t[1e-12]) for rtol in (1e-8, 1e-10)}
    assert errors[1e-8] <= _tail_bound(contact, 1e-8)
    if zeta_adhesion == 1e6:  # from the entry on (step 8) the tail's error dominates
        assert errors[1e-10] <= _tail_bound(contact, 1e-10)
    assert errors[1e-10] < errors[1e-8]
    # a sliding sphere is slowed, never sped up, and by at most the paper's full-sliding impulse f m v_n
    v_n = 10.0 * math.cos(math.radians(89.0))
    v_in = 10.0 * math.sin(math.radians(89.0))
    assert all(v_in - 2.0 * v_n * (1.0 + 1e-9) <= v <= v_in for v in v_t.values())


#: the other corner with no result under every compliant law: no adhesion, zeta_H = 1e6, K = 1e8 Pa,
#: 1e4 m/s (whatever the radius, zeta_A or friction)
HERTZ_CORNER = dict(CORNER, work_of_adhesion=0.0, zeta_hertz=1e6, speed=1e4)


@pytest.mark.parametrize("law", COUPLED_LAWS)
@pytest.mark.parametrize("incidence_deg, friction", [(0.0, 0.0), (45.0, 2.0)])
def test_an_overdamped_hertz_exit_leaves_on_the_invariant_line(law, incidence_deg, friction):
    """Without adhesion under zeta_H = 1e6 the sphere leaves along y = -1/C1, the exact invariant
    line of the Hertz law with its damping (the engine's inertia-free exit; e_n = 1 / (C_H v_n),
    tests/test_inertia_free.py checks it against the exact exit speed). Each compliant law raised
    CoupledError (step limit) here; now it passes the stress checks and its e_n is the ring law's:
    both end on the same line, where e_n is 1 / (C1 y0) in closed form, so they agree to rounding
    (rel 1e-12)."""
    case = dict(HERTZ_CORNER, incidence_deg=incidence_deg, friction=friction)
    row = stress.check_case(case, law=law)
    assert row["failures"] == [], row["failures"]
    assert row["outcome"] == "rebound"
    ring = simulate_impact(stress.contact_of(case, "ring"), case["speed"], incidence_deg)
    assert row["e_n"] == pytest.approx(ring.e_n, rel=1e-12, abs=0.0)
