"""The interpolated family of normal solves (microimpact.solvers.family) and simulate_many's use of it.

Every expected value comes from direct engine solves at a tighter tolerance than the family's, at
speeds that are not family nodes (random speeds), so an interpolation error cannot hide.
"""

import math

import numpy as np
import pytest

from microimpact import simulate_many
from microimpact.presets import get_preset
from microimpact.solvers import engine
from microimpact.solvers.family import NODE_RTOL_FLOOR, FamilyBudgetExceeded, normal_family
from microimpact.solvers.impact import FAMILY_MIN_SPEEDS

WALL = get_preset("wall1990")
#: the direct solves the family is judged against: 1e-13 is 10,000x tighter than the family's 1e-9,
#: and within 1e-12 of DOP853 at 1e-13 (docs/benchmark.md); near the capture speed, where e_n is
#: ill-conditioned, the engine at 1e-12 is still 4e-10 from its 1e-13 value, too loose a yardstick
TIGHT = 1e-13


@pytest.fixture(scope="module")
def family():
    return normal_family(WALL, 0.05, 20.0, rtol=1e-9)


def _tight(contact, v):
    return engine.solve_normal_many(contact, v, np.ones(v.size, dtype=bool), rtol=TIGHT, tail_tolerance=TIGHT)


def test_family_matches_direct_solves_at_non_node_speeds(family):
    v = np.sort(np.random.default_rng(7).uniform(0.05, 20.0, 3000))
    got, want = family.evaluate(v), _tight(WALL, v)
    assert np.array_equal(got["captured"], want["captured"])
    # the family's tolerance rtol is checked at half its value on every piece; between check
    # points the error may be larger, so the bound asserted is rtol itself (absolute for e_n)
    assert np.max(np.abs(got["e_n"] - want["e_n"])) <= 1e-9
    for key in ("max_penetration", "friction_impulse", "twist_impulse"):
        assert np.max(np.abs(got[key] / want[key] - 1.0)) <= 1e-9, key
    rebound = ~want["captured"]
    assert np.max(np.abs(got["contact_time"][rebound] / want["contact_time"][rebound] - 1.0)) <= 1e-9
    assert np.all(np.isinf(got["contact_time"][~rebound]))


def test_capture_speed_is_the_outcome_change_of_direct_solves(family):
    (v_c,) = family.capture_speeds
    below, above = v_c * (1 - 1e-9), v_c * (1 + 1e-9)
    out = engine.solve_normal_many(WALL, np.array([below, above]), rtol=1e-11)["captured"]
    assert out.tolist() == [True, False]
    # the same capture speed as the reproduction table's bisection (1.449241 m/s, Fig. 4 check)
    assert v_c == pytest.approx(1.449241, abs=1e-6)


def test_impacts_in_the_guard_band_are_solved_directly(family):
    assert family.direct.any()  # at least the bracket of the capture speed
    left, right = np.exp(family.edges[:-1][family.direct]), np.exp(family.edges[1:][family.direct])
    v = np.sort(np.concatenate([0.5 * (left + right), left + 0.25 * (right - left)]))
    got = family.evaluate(v)
    want = engine.solve_normal_many(WALL, v, np.ones(v.size, dtype=bool), rtol=NODE_RTOL_FLOOR,
                                    tail_tolerance=NODE_RTOL_FLOOR)
    for key in ("captured", "e_n", "friction_impulse", "twist_impulse"):
        assert np.array_equal(got[key], want[key]), key  # the same direct solves, bit for bit


def test_family_without_adhesion_has_no_capture_speed():
    hertz = WALL.with_(adhesion_line_force=0.0, zeta_adhesion=0.0)
    fam = normal_family(hertz, 0.1, 10.0, rtol=1e-8)
    assert fam.capture_speeds == ()
    v = np.geomspace(0.1, 10.0, 37)[1:-1] * 1.0001
    got, want = fam.evaluate(v), _tight(hertz, v)
    assert np.max(np.abs(got["e_n"] - want["e_n"])) <= 1e-8
    assert not got["captured"].any()


def test_undamped_family_restitution_is_one():
    # zeta_H = zeta_A = 0 and no adhesion: energy is conserved, e_n = 1 at every speed (analytic)
    elastic = WALL.with_(adhesion_line_force=0.0, zeta_adhesion=0.0, zeta_hertz=0.0)
    fam = normal_family(elastic, 0.5, 5.0, rtol=1e-8)
    out = fam.evaluate(np.linspace(0.5, 5.0, 101))
    assert np.max(np.abs(out["e_n"] - 1.0)) <= 1e-8
    # Hertz contact time 2.9432 delta_max / v with delta_max = (15 m v^2 / (16 E* r^(1/2)))^(2/5) and
    # E* = 3 K / 4 (Johnson 1985, Contact Mechanics, Eq. 11.24)
    m, r, e_star = elastic.mass, elastic.radius, 0.75 * elastic.stiffness
    v = np.linspace(0.5, 5.0, 101)
    t_hertz = 2.9432 * (15.0 * m * v * v / (16.0 * e_star * math.sqrt(r))) ** 0.4 / v
    assert np.max(np.abs(out["contact_time"] / t_hertz - 1.0)) < 1e-4  # the constant 2.9432 has 5 digits


def test_budget_is_enforced():
    with pytest.raises(FamilyBudgetExceeded):
        normal_family(WALL, 0.05, 20.0, rtol=1e-9, max_solves=100)


@pytest.fixture(scope="module")
def oblique_batch():
    rng = np.random.default_rng(3)
    n = 4000
    return dict(
        speed=rng.uniform(0.3, 8.0, n),
        incidence_deg=rng.uniform(0.0, 85.0, n),
        azimuth_deg=rng.uniform(0.0, 360.0, n),
        omega=(rng.uniform(-2e5, 2e5, n), rng.uniform(-2e5, 2e5, n), rng.uniform(-2e5, 2e5, n)),
    )


def test_simulate_many_family_path_matches_direct_path(oblique_batch):
    fam = simulate_many(WALL, **oblique_batch, rtol=1e-9, family=True)
    ref = simulate_many(WALL, **oblique_batch, rtol=TIGHT, family=False)
    assert fam.attrs["normal_solve_path"].startswith("family")
    assert ref.attrs["normal_solve_path"].startswith("direct")
    assert np.array_equal(fam["outcome"].values, ref["outcome"].values)
    assert float(np.abs(fam["e_n"] - ref["e_n"]).max()) <= 1e-9
    # tangential outcome, captured impacts included: the family's J and J_a are totals over the
    # settling, the direct path stops once sliding and twist are over; min(J, J*) makes them agree
    scale = {"velocity_out_t": 8.0, "velocity_out_tp": 8.0, "omega_out_n": 2e5, "omega_out_t": 2e5, "omega_out_tp": 2e5}
    for key, s in scale.items():
        # a relative error rtol in J moves a velocity by at most f J rtol / m <= rtol * speed
        assert float(np.abs(fam[key] - ref[key]).max()) <= 1e-8 * s, key
    for key in ("K_L", "K_t"):
        assert float(np.abs(fam[key] - ref[key]).max()) <= 1e-8, key
    assert np.array_equal(fam["slip_ended"].values, ref["slip_ended"].values)


def test_simulate_many_chooses_the_path(oblique_batch):
    small = simulate_many(WALL, oblique_batch["speed"][:100], 30.0)
    assert small.attrs["normal_solve_path"].startswith("direct") and small.attrs["normal_solves"] == 100
    grid = simulate_many(WALL, np.repeat(np.linspace(0.5, 5.0, 10), 500), 30.0)  # 5000 impacts, 10 speeds
    assert grid.attrs["normal_solve_path"].startswith("direct") and grid.attrs["normal_solves"] == 10
    n = 3 * FAMILY_MIN_SPEEDS
    many = simulate_many(WALL, np.random.default_rng(0).uniform(0.3, 8.0, n), 30.0)
    if many.attrs["normal_solve_path"].startswith("family"):
        assert many.attrs["normal_solves"] < n // 2
    else:  # the family would have cost more than half the direct solves: the budget refused it
        assert many.attrs["normal_solves"] == n
    with pytest.raises(TypeError, match="family"):
        simulate_many(WALL, 1.0, family="yes")


def test_single_speed_family():
    fam = normal_family(WALL, 2.0, 2.0, rtol=1e-8)
    got = fam.evaluate([2.0])
    want = _tight(WALL, np.array([2.0]))
    assert abs(got["e_n"][0] - want["e_n"][0]) <= 1e-8
    assert math.isfinite(got["contact_time"][0])
