"""The fast engine (1-D normal solve + closed-form tangential map) against the full 3-D reference.

The two are independent formulations: the reference integrates all ten states (normal, tangential,
spins, dissipation) with scipy and switches modes at located slip-end and twist-end events; the
engine solves only the normal motion and maps the rest in closed form. Agreement over angles
0-89 deg, spins up to 10x the rolling spin, friction 0-1, rebounds and captures is the test of the
decoupling argument (model notes, section 4).
"""

import math

import numpy as np
import pytest

import microimpact as mi
from microimpact.presets import WALL_1990

RTOL = 1e-10
# Tolerance: both solvers are run at rtol 1e-10 and the benchmark measures each within ~1e-9 of an
# rtol 1e-13 solve in e_n and mu. A captured sphere's friction impulse tail is truncated by both at
# a bound of ~rtol relative to J. 1e-7 leaves a factor 100 for the sensitivity of the outputs to
# the impulses (mu and the energy ratios are linear in J, with factors of order f (1+e) <= 2).
ATOL = 1e-7

rng = np.random.default_rng(20021101)


def _cases():
    cases = []
    rolling = 1.0 / WALL_1990.radius  # rolling spin per unit speed [rad/s per m/s]
    for speed, alpha in [(0.5, 30.0), (1.2, 10.0), (1.6, 45.0), (3.0, 0.0), (3.0, 60.0), (10.0, 89.0), (25.0, 75.0)]:
        for f in (0.0, 0.15, 1.0):
            # spin in any direction, magnitude up to 10x the rolling spin of the incident speed
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            magnitude = rng.uniform(0.0, 10.0) * rolling * speed
            cases.append((speed, alpha, float(rng.uniform(0, 360)), tuple(magnitude * direction), f))
    return cases


@pytest.mark.parametrize("speed, alpha, azimuth, omega, f", _cases())
def test_engine_matches_reference(speed, alpha, azimuth, omega, f):
    c = WALL_1990.with_(friction=f)
    a = mi.simulate_impact(c, speed, alpha, azimuth, omega, rtol=RTOL)
    b = mi.simulate_impact(c, speed, alpha, azimuth, omega, rtol=RTOL, method="reference")
    assert a.outcome == b.outcome
    assert a.slip_ended == b.slip_ended
    for name in ("e_n", "mu_t", "mu_tp", "K_L", "K_t"):
        x, y = getattr(a, name), getattr(b, name)
        if math.isnan(y):
            assert math.isnan(x), name
        else:
            assert x == pytest.approx(y, abs=ATOL), name
    v_scale = speed
    np.testing.assert_allclose(a.velocity_out, b.velocity_out, rtol=0, atol=ATOL * v_scale)
    w_scale = max(speed / c.radius, max(abs(w) for w in omega))
    np.testing.assert_allclose(a.omega_out, b.omega_out, rtol=0, atol=ATOL * w_scale)
    assert a.max_penetration == pytest.approx(b.max_penetration, rel=1e-7, abs=0)
    if a.outcome == "rebound":
        assert a.contact_time == pytest.approx(b.contact_time, rel=1e-7, abs=0)


def test_strongly_overdamped_capture_matches_reference():
    # C ~ 10: the engine stops once the motion creeps towards the equilibrium (inertia-free,
    # monotone); the reference integrates the creep (it restarts at every sign change of F_n, which
    # becomes impractical beyond C ~ 30, so this is the largest C compared here).
    c = WALL_1990.with_(zeta_adhesion=600.0)
    a = mi.simulate_impact(c, 1e-3, 30.0, 0.0, (2e2, 0.0, 0.0), rtol=RTOL)
    b = mi.simulate_impact(c, 1e-3, 30.0, 0.0, (2e2, 0.0, 0.0), rtol=RTOL, method="reference")
    assert a.outcome == b.outcome == "capture"
    np.testing.assert_allclose(a.velocity_out, b.velocity_out, rtol=0, atol=ATOL * 1e-3)
    np.testing.assert_allclose(a.omega_out, b.omega_out, rtol=0, atol=ATOL * 1e-3 / c.radius)
    # the creeping sphere approaches the equilibrium X monotonically: its supremum, up to the
    # integration noise near the equilibrium (~10 atol, 1e-9 relative at rtol 1e-10)
    assert a.max_penetration == pytest.approx(c.length_scale, rel=1e-7, abs=0)
    assert a.max_penetration <= c.length_scale * (1 + 1e-9)
