"""Stress and property tests of the impact engine: invariants over decades of every input.

Known engine bugs found by the sweep are documented by strict xfail tests with their reproducers
(remove the mark when fixed). The property tests run on the domain where the engine is expected
to work today (nondimensional damping 1e-3 <= C1 + C2 <= 200 when adhesive), so that they guard
against regressions; the full ranges are covered by the seeded sweep at the end.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from microimpact import stress
from microimpact.impact import simulate_impact
from microimpact.params import Contact
from microimpact.presets import WALL_1990

# deterministic (derandomize) and fast: each example costs a few engine solves (~ms)
PROFILE = settings(max_examples=60, deadline=None, derandomize=True,
                   suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])


def log_uniform(lo, hi):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


def with_zero(strategy):
    return st.one_of(st.just(0.0), strategy)


@st.composite
def impacts(draw):
    r = stress.INPUT_RANGES
    radius = draw(log_uniform(*r["radius"]))
    speed = draw(log_uniform(*r["speed"]))
    contact = Contact.from_work_of_adhesion(
        radius, draw(log_uniform(*r["density"])), draw(log_uniform(*r["stiffness"])),
        draw(with_zero(log_uniform(*r["work_of_adhesion"]))),
        zeta_hertz=draw(with_zero(log_uniform(*r["zeta_hertz"]))),
        zeta_adhesion=draw(with_zero(log_uniform(*r["zeta_adhesion"]))),
        friction=draw(with_zero(st.floats(0.0, 2.0))),
    )
    inc = draw(with_zero(st.floats(0.0, 89.9)))
    az = draw(st.floats(0.0, 360.0))
    spin = tuple(draw(st.floats(-10.0, 10.0)) * speed / radius for _ in range(3))
    vn = speed * math.cos(math.radians(inc))
    if contact.adhesion_line_force > 0.0:
        c1, c2 = contact.nondimensional_damping(vn)
        # outside this band the engine hits the known bugs documented below (stiff overdamped
        # creep: step limit; undamped: spurious capture / ZeroDivisionError)
        assume(1e-3 <= c1 + c2 <= 200.0)
    return contact, speed, inc, az, spin


@PROFILE
@given(impacts())
def test_invariants(case):
    contact, speed, inc, az, spin = case
    res = simulate_impact(contact, speed, inc, az, spin)
    assert stress._nonfinite_fields(res) == []
    assert 0.0 <= res.e_n <= 1.0
    if res.outcome == "capture":
        assert res.e_n == 0.0
    assert stress.energy_error(contact, res) <= stress.TOLERANCES["energy"]
    coarse = simulate_impact(contact, speed, inc, az, spin, rtol=1e-8)
    assert stress.result_distance(contact, res, coarse) <= stress.TOLERANCES["convergence"]


@PROFILE
@given(impacts())
def test_continuity_in_speed(case):
    """e_n(v) and e_n(v (1 + 1e-6)) agree, compared as energies (see stress.result_distance).

    Tolerance 1e-5: d(e_n^2)/d(ln v) is O(1), so a 1e-6 speed change moves the rebound energy by
    ~1e-6 of the energy scale; 1e-5 adds room for the integration error (<= 1e-7 at rtol 1e-10).
    A capture/rebound switch passes only if the rebound energy is itself below 1e-5 (threshold).
    """
    contact, speed, inc, az, spin = case
    a = simulate_impact(contact, speed, inc, az, spin)
    b = simulate_impact(contact, speed * (1 + 1e-6), inc, az, spin)
    ke_in = stress.kinetic_energy(contact, a.velocity_in, a.omega_in)
    scale = stress.energy_scale(contact, ke_in)
    ea = 0.5 * contact.mass * a.velocity_out[0] ** 2
    eb = 0.5 * contact.mass * b.velocity_out[0] ** 2 / (1 + 1e-6) ** 2  # same incident energy
    assert abs(ea - eb) / scale <= 1e-5


# ------------------------------------------------------------------ known engine bugs (reproducers)
MISSED_SEPARATION = Contact.from_work_of_adhesion(
    0.0004436954785754723, 4733.544875582984, 94267726701.7395, 0.0011948335784818724,
    zeta_hertz=141.12729602871758, zeta_adhesion=0.005715222866944042, friction=1.6324934088437917)


@pytest.mark.xfail(strict=True, reason=(
    "engine bug: separation missed when an extremum-of-y event (code 2) is located in the same "
    "step as separation; the state lands on s = 0 but the step is not declared a separation, the "
    "integration continues with s < 0 (tau runs backwards) and the impact is reported as a "
    "capture. Reproducer: MISSED_SEPARATION contact, normal speed 15.553686347910835 m/s -> "
    "capture; 15.5 and 16.0 m/s (and rtol 1e-8, 1e-12) -> rebound with e_n = 0.3323. With "
    "friction and 12.19 deg incidence, spin (2.5e5, 7.2e4, -2.5e5) rad/s, the same speed ends in "
    "EngineError (step limit) instead."))
def test_bug_missed_separation_gives_spurious_capture():
    res = simulate_impact(MISSED_SEPARATION, 15.553686347910835)
    assert res.outcome == "rebound"
    assert res.e_n == pytest.approx(0.332349, abs=1e-5)  # rtol 1e-8 and 1e-12 agree on this


@pytest.mark.xfail(strict=True, raises=Exception, reason=(
    "engine bug: strongly overdamped capture (C1 or C2 >~ 600) exceeds the 2e6-step limit: the "
    "explicit DP5 creeps into equilibrium with h ~ 1/C over a time ~ C (steps ~ C^2), to find the "
    "largest penetration. Reproducer: simulate_impact(WALL_1990.with_(zeta_adhesion=3e4, "
    "friction=0), 1e-4) -> EngineError step limit (C2 = 1.5e3); zeta_hertz=1e5, zeta_adhesion=0 "
    "likewise (C1 = 5e3)."))
def test_bug_overdamped_capture_step_limit():
    res = simulate_impact(WALL_1990.with_(zeta_adhesion=3e4, friction=0.0), 1e-4)
    assert res.outcome == "capture"


@pytest.mark.xfail(strict=True, reason=(
    "engine bug: with zero damping (zeta_H = zeta_A = 0) the energy is conserved and e_n = 1 at "
    "every speed (model notes sec. 4), but at low speed the integration error (relative to the "
    "well depth) makes E < 0 and the engine reports a capture. Reproducer: "
    "simulate_impact(WALL_1990.with_(zeta_hertz=0, zeta_adhesion=0, friction=0), 1e-6) -> "
    "capture (also 1e-5 m/s; 1e-4 m/s gives e_n = 0.9897)."))
def test_bug_undamped_low_speed_capture():
    res = simulate_impact(WALL_1990.with_(zeta_hertz=0.0, zeta_adhesion=0.0, friction=0.0), 1e-6)
    assert res.outcome == "rebound"


# ------------------------------------------------------------------ seeded sweep
@pytest.fixture(scope="module")
def sweep():
    # 300 cases over the full ranges, no reference solver (it is slow: seconds per hard case)
    return stress.stress_sweep(300, seed=0, reference_every=0)


def test_sweep_invariants_that_hold_today(sweep):
    s = sweep.summary
    assert s["cases_run"] == 300
    for kind in ("nonfinite", "restitution", "energy", "timeout"):
        assert s["failures_by_kind"][kind] == 0, s["failed_cases"]
    assert s["worst_energy_error"]["value"] <= stress.TOLERANCES["energy"]
    assert sweep.dataset.sizes["case"] == 300


@pytest.mark.xfail(strict=True, reason=(
    "seed 0, 300 cases: EngineError step limit (overdamped, case 136) and capture-vs-rebound disagreements between rtol "
    "1e-8 and 1e-10 far from the capture threshold (missed separation, e.g. cases 236, 250); "
    "see the bug tests above"))
def test_sweep_has_no_failures(sweep):
    assert sweep.summary["cases_failed"] == 0, sweep.summary["failed_cases"]


def test_sweep_is_reproducible():
    assert stress.draw_cases(5, seed=3) == stress.draw_cases(5, seed=3)
    assert stress.draw_cases(5, seed=3) != stress.draw_cases(5, seed=4)
