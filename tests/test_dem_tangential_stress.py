"""Cases of the stress sweep (microimpact.studies.stress, seed 0) that the DEM tangential solver
(microimpact.solvers.dem_tangential) gave no result for: a normal motion that creeps, and LAMMPS's
rolling law with the rolling velocity across the slip (issue 52). Each case is stored as its drawn
inputs, so that the tests do not depend on the sweep's draw. Extended (implicit integrations of
creeping contacts, seconds each): ``pytest -n auto -m extended``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from microimpact.solvers import dem_tangential as dt
from microimpact.solvers.impact import simulate_impact
from microimpact.studies import stress

pytestmark = pytest.mark.extended

#: case 144 of seed 0 (its drawn inputs): 2e4 critical dampings, Hertz (w = 0) with LAMMPS's
#: viscoelastic damping and Mindlin spring; the sphere stops within a tiny approach and creeps out
CREEPING = {"case": 144, "radius": 1.7997127709464948e-06, "density": 1712.0868787697586,
            "stiffness": 40881552905.33151, "work_of_adhesion": 0.0, "zeta_hertz": 20313.310477231757,
            "zeta_adhesion": 0.0, "friction": 0.9782743606506044, "speed": 3.5066943833971655,
            "incidence_deg": 77.76794096243492, "azimuth_deg": 127.22531434980345, "omega_n": 148679115.65995255,
            "omega_t": 194435205.14096683, "omega_tp": -96104272.44143586}
CREEPING_LAW = "jkr_force_viscoelastic_lammps_mindlin"

#: cases 37 and 39 of seed 0 under the sds law (rolling and twisting sds, mu_roll 0.1): spin about
#: both tangential axes, so the rolling velocity has a part across the slip (the 2-D integration)
ROLLING_LAW = "jkr_force_viscoelastic_lammps_mindlin_rescale_force_sds"
ACROSS = {
    37: {"case": 37, "radius": 2.1023132650924136e-07, "density": 8785.739678688615, "stiffness": 8009237520.234533,
         "work_of_adhesion": 0.0, "zeta_hertz": 0.0, "zeta_adhesion": 55425.67794152211,
         "friction": 1.0201780149694073, "speed": 8.874214307987035e-06, "incidence_deg": 20.286601363835175,
         "azimuth_deg": 163.26860004753664, "omega_n": 1268.0166228148419, "omega_t": -1906.220054374877,
         "omega_tp": 2160.7192349363277},
    39: {"case": 39, "radius": 0.00010381373973286107, "density": 16828.26410461325, "stiffness": 161802275600.40628,
         "work_of_adhesion": 0.0, "zeta_hertz": 0.0, "zeta_adhesion": 0.2759689014968223,
         "friction": 0.34765635324725475, "speed": 881.582847623106, "incidence_deg": 76.81934355773468,
         "azimuth_deg": 47.80966574314375, "omega_n": -178309345.90064955, "omega_t": 492560099.53546435,
         "omega_tp": -59456846.03878812},
}
#: cases 59, 66, 77, 144 of seed 0 under the sds law: strongly damped Hertz (w = 0; 5e4, 82, 35, 2e4
#: critical dampings) with the rolling velocity across the slip, both springs sliding while the
#: contact creeps out under a limit mu F_n0 that the creep makes small
CREEPING_ACROSS = {
    59: {"case": 59, "radius": 7.537583662907485e-08, "density": 12696.39478145593, "stiffness": 25168375931.34155,
         "work_of_adhesion": 0.0, "zeta_hertz": 53866.94726311807, "zeta_adhesion": 1.075662579503529,
         "friction": 1.6492884044679355, "speed": 3.850683338837365e-06, "incidence_deg": 85.25697989585188,
         "azimuth_deg": 112.39205432456642, "omega_n": -2189.5088022997493, "omega_t": 2736.586307725606,
         "omega_tp": -4928.840640911031},
    66: {"case": 66, "radius": 5.100200811703422e-06, "density": 10526.045015677177, "stiffness": 1493322871.9453182,
         "work_of_adhesion": 0.0, "zeta_hertz": 81.94506314825647, "zeta_adhesion": 827.7588262520777,
         "friction": 0.06354485013678346, "speed": 0.6543988953056982, "incidence_deg": 29.748071645910084,
         "azimuth_deg": 125.06991359390722, "omega_n": -8635995.583417682, "omega_t": -10563180.577238051,
         "omega_tp": -5001741.799806437},
    77: {"case": 77, "radius": 0.0061335186205668185, "density": 7233.1128210722045, "stiffness": 109425002655.36348,
         "work_of_adhesion": 0.0, "zeta_hertz": 35.2420534447018, "zeta_adhesion": 101676.45962384863,
         "friction": 0.36563589012591713, "speed": 1.5372724652026466e-05, "incidence_deg": 77.56745939564323,
         "azimuth_deg": 341.02019280493505, "omega_n": -0.06590084823403418, "omega_t": 0.0435563403355653,
         "omega_tp": -0.17149322163346814},
    144: CREEPING,
}

#: case 30 of seed 0 under the sds law: friction 0, no spin, an oblique Hertz impact
FRICTIONLESS_NO_SPIN = {"case": 30, "radius": 7.844021395095683e-08, "density": 5485.6060025035895,
                        "stiffness": 32646392031.90497, "work_of_adhesion": 0.0007078516640303486, "zeta_hertz": 0.0,
                        "zeta_adhesion": 0.0, "friction": 0.0, "speed": 1.2031383626416219,
                        "incidence_deg": 14.899230560509269, "azimuth_deg": 290.58045483365635, "omega_n": -0.0,
                        "omega_t": -0.0, "omega_tp": -0.0}

#: case 55 of seed 0 under the sds law: friction 0 with spin about both tangential axes, undamped Hertz;
#: the rolling law alone acts, on the rolling velocity's line
FRICTIONLESS_ROLLING = {"case": 55, "radius": 1.0935158284878615e-07, "density": 1159.8276255322578,
                        "stiffness": 1163044615.3256333, "work_of_adhesion": 0.0, "zeta_hertz": 0.0,
                        "zeta_adhesion": 0.04513505610369088, "friction": 0.0, "speed": 1.6225708477193366e-05,
                        "incidence_deg": 13.371176933109036, "azimuth_deg": 34.13908466062842,
                        "omega_n": 4954.948453441776, "omega_t": 6699.526741644243, "omega_tp": 1875.6557226800574}

#: evaluations of the law's right-hand side and switch functions allowed in these tests: the
#: solves below take 2e4 to 4e4 (events included); DOP853 on the creeping case stopped at its
#: budget of 2e6 and Radau alone on case 39 took 2.3e5, so a regression fails here in seconds
_EVALUATIONS = 100_000


@pytest.fixture
def counted(monkeypatch):
    """Count the law's evaluations (``[0]``); fail once they pass ``[1]``, ``_EVALUATIONS`` unless set."""
    seen = [0, _EVALUATIONS]
    inner = dt._rhs_and_switch

    def rhs_and_switch(*args):
        seen[0] += 1
        if seen[0] > seen[1]:
            raise AssertionError(f"more than {seen[1]} evaluations of the law")
        return inner(*args)

    monkeypatch.setattr(dt, "_rhs_and_switch", rhs_and_switch)
    return seen


def _impact(case, law, rtol):
    c = stress.contact_of(dict(case), law)
    return c, simulate_impact(c, case["speed"], case["incidence_deg"], case["azimuth_deg"], stress._omega(case),
                              rtol=rtol)


def _with_method(monkeypatch, method):
    """Every implicit solve of the tangential solver by ``method`` instead (an independent integration)."""
    def solve(*args, **kwargs):
        if kwargs["method"] != "DOP853":
            kwargs["method"] = method
        return solve_ivp(*args, **kwargs)

    monkeypatch.setattr(dt, "solve_ivp", solve)


def test_a_creeping_normal_motion_gets_the_tangential_result_of_an_independent_integration(counted, monkeypatch):
    """2e4 critical dampings: the normal motion is stiff (the rate relaxes at eta ~ 4e4 in the law's
    units, elastic rate ~1) and creeps out; DOP853 ended in its 2e6 evaluations (DemTangentialError
    after ~180 s). Radau's outcome is that of BDF, another implicit method, to 1e-8 of the speed
    scale (measured 5e-10; the sweep's reference tolerance is 1e-5); the impact takes energy out
    (the tangential and rotational kinetic energy falls) and converges in rtol."""
    c, fine = _impact(CREEPING, CREEPING_LAW, 1e-10)
    assert fine.outcome == "rebound" and fine.e_n < 1e-20  # creeps out: inertia-free to the exit
    assert counted[0] > 0  # the tangential solver ran (a slip, not the frictionless shortcut)
    _, coarse = _impact(CREEPING, CREEPING_LAW, 1e-8)
    assert stress.result_distance(c, fine, coarse) < 1e-6  # the sweep's convergence tolerance is 1e-4
    ke_in = stress.kinetic_energy(c, fine.velocity_in, fine.omega_in)
    assert stress.kinetic_energy(c, fine.velocity_out, fine.omega_out) < ke_in
    counted[0] = 0
    _with_method(monkeypatch, "BDF")
    _, other = _impact(CREEPING, CREEPING_LAW, 1e-10)
    assert stress.result_distance(c, fine, other) < 1e-8


@pytest.mark.parametrize("number", [37, 39])
def test_rolling_across_the_slip_gets_a_result_that_converges(number, counted):
    """Radau alone failed to locate an event (case 37) or took 2.3e5 evaluations and ~56 s (39, the
    sweep's time box); LSODA, then BDF where it fails, solve them. The outcome moves by less than
    1e-6 of the speed scale between rtol 1e-8 and 1e-10 (measured 1.4e-10 and 2.4e-11) and the
    kinetic energy falls."""
    case = ACROSS[number]
    c, fine = _impact(case, ROLLING_LAW, 1e-10)
    _, coarse = _impact(case, ROLLING_LAW, 1e-8)
    assert fine.outcome == "rebound"
    assert stress.result_distance(c, fine, coarse) < 1e-6
    ke_in = stress.kinetic_energy(c, fine.velocity_in, fine.omega_in)
    assert stress.kinetic_energy(c, fine.velocity_out, fine.omega_out) < ke_in


def test_rolling_across_the_slip_is_the_same_by_another_implicit_method(monkeypatch):
    """Case 39 by BDF alone against the default sequence (LSODA first): the same outcome to 1e-8 of
    the speed scale (measured 3e-11)."""
    c, first = _impact(ACROSS[39], ROLLING_LAW, 1e-10)
    _with_method(monkeypatch, "BDF")
    _, other = _impact(ACROSS[39], ROLLING_LAW, 1e-10)
    assert stress.result_distance(c, first, other) < 1e-8


def test_frictionless_rolling_without_spin_leaves_the_tangential_motion_alone():
    """No friction and no rolling velocity: nothing acts tangentially (the rolling frame was 0 / 0:
    a NaN state and DemTangentialError)."""
    c, r = _impact(FRICTIONLESS_NO_SPIN, ROLLING_LAW, 1e-10)
    assert r.velocity_out[1:] == pytest.approx(r.velocity_in[1:], rel=0.0, abs=0.0)
    assert r.omega_out == (0.0, 0.0, 0.0) and math.isfinite(r.e_n)


def test_frictionless_rolling_does_not_chatter_on_the_slips_zero_limit(counted):
    """Case 55: the frictionless slip spring, stuck, met its zero limit at once and went back by
    rounding, so that it switched across the whole contact (3.6e5 evaluations, 38 s per solve; the
    sweep's time box is 30 s). It now slides on its zero limit throughout (measured ~650
    evaluations; the cap is ``_EVALUATIONS / 20`` so that a return of the chatter fails at once).
    Without friction nothing acts on the sphere along the wall: v_t is unchanged (to 1e-12 of it,
    rounding of the sums du + dw), the spin changes by the rolling torque alone, converges in rtol
    and the kinetic energy falls."""
    counted[1] = _EVALUATIONS // 20
    c, fine = _impact(FRICTIONLESS_ROLLING, ROLLING_LAW, 1e-10)
    assert counted[0] > 0  # the rolling integration ran
    counted[0] = 0
    _, coarse = _impact(FRICTIONLESS_ROLLING, ROLLING_LAW, 1e-8)
    assert fine.outcome == "rebound"
    # abs=0: a purely relative comparison (a component of 0 in must stay exactly 0 out)
    assert fine.velocity_out[1:] == pytest.approx(fine.velocity_in[1:], rel=1e-12, abs=0.0)
    assert fine.omega_out[1:] != pytest.approx(fine.omega_in[1:], rel=1e-6, abs=0.0)  # the rolling torque acted
    assert stress.result_distance(c, fine, coarse) < 1e-6
    ke_in = stress.kinetic_energy(c, fine.velocity_in, fine.omega_in)
    assert stress.kinetic_energy(c, fine.velocity_out, fine.omega_out) < ke_in


@pytest.mark.parametrize("number", [59, 66, 77, 144])
def test_rolling_across_the_slip_of_a_creeping_contact_gets_a_result(number, counted):
    """The directions of both sliding forces relaxed at 5e6 to 3e8 per unit of the Sundman variable
    while the creep spans ~5e5 of it: LSODA, BDF and Radau each took steps below 1e-6 there and
    ended in their evaluation budgets (DemTangentialError after ~40 s). Each direction now follows
    its quasi-static value where it relaxes far faster than it turns (dem_tangential._FOLLOW):
    2.0e4 to 2.9e4 evaluations at rtol 1e-8 (the cap here is 5e4, so a return fails in seconds). The normal
    outcome is the creeping rebound, and the kinetic energy falls."""
    counted[1] = _EVALUATIONS // 2
    c, r = _impact(CREEPING_ACROSS[number], ROLLING_LAW, 1e-8)
    assert r.outcome == "rebound" and counted[0] > 0
    ke_in = stress.kinetic_energy(c, r.velocity_in, r.omega_in)
    assert stress.kinetic_energy(c, r.velocity_out, r.omega_out) < ke_in


@pytest.mark.parametrize("number", [59, 66, 77, 144])
def test_rolling_across_the_slip_of_a_creeping_contact_passes_the_sweeps_checks(number):
    """The sweep's checks of these cases (stress.check_case): no failure, the energy balance to 1e-8
    of the case's scale (measured 0: the normal solve's) and rtol 1e-8 against 1e-10 within 1e-6 of
    the speed scale (the sweep's tolerance is 1e-4; measured 8e-16 to 2.2e-10)."""
    row = stress.check_case(dict(CREEPING_ACROSS[number]), law=ROLLING_LAW)
    assert row["failures"] == [] and row["outcome"] == "rebound"
    assert row["energy_error"] <= 1e-8 and row["convergence_error"] < 1e-6


@pytest.mark.parametrize("number", [77])
def test_a_following_direction_agrees_with_another_implicit_method(number, monkeypatch):
    """Case 77 by BDF alone against the default sequence (LSODA first), each following the
    directions where they may: the same outcome to 1e-8 of the speed scale."""
    c, first = _impact(CREEPING_ACROSS[number], ROLLING_LAW, 1e-10)
    _with_method(monkeypatch, "BDF")
    _, other = _impact(CREEPING_ACROSS[number], ROLLING_LAW, 1e-10)
    assert stress.result_distance(c, first, other) < 1e-8


@pytest.mark.parametrize("damped", ["tangential", "rolling", "neither"])
def test_the_quasi_static_direction_is_the_rest_point_of_the_direction_equation(damped):
    """dem_tangential._quasi_static puts a following direction at P / |P|: there the sliding
    direction's equation de/dsigma = (1 - e e^T) G' / (mu F_n0) is at rest (to 1e-12 of the rate
    |P| / (mu F_n0) it relaxes at), with the slip's damping (P_t depends on the rolling direction),
    the rolling's (P_r on the slip's) or neither, from a state whose directions are off by 0.3 rad."""
    c = stress.contact_of(dict(CREEPING_ACROSS[77]), ROLLING_LAW)
    c = c.with_(tangential_damping=1e-3 if damped == "tangential" else 0.0,
                rolling_damping=1e-4 if damped == "rolling" else 0.0)
    law = dt._Law(c, 1e-3)
    law.method, law.across = "LSODA", True
    law.cap_floor = law.cap_floor_r = 1e-20
    x = np.array([0.2, -1e-3, -math.cos(0.3), math.sin(0.3), 289.0, 2e-3, 1.0, math.cos(0.3), math.sin(0.3),
                  -292.0, 2.2])
    both = (dt._FOLLOW, dt._FOLLOW)
    assert dt._may_follow(law)
    y, rates = dt._quasi_static(law, x, both)
    slide = dt._rates(law, y, (dt._SLIDE, dt._SLIDE))[0]
    for i in (0, 1):
        size = math.hypot(*rates[i])
        assert size > 0.0
        assert math.hypot(*slide[dt._DIRECTIONS[i]]) <= 1e-12 * size
        assert math.hypot(*y[dt._DIRECTIONS[i]]) == pytest.approx(1.0, rel=1e-15, abs=0.0)
        assert dt._rhs_and_switch(law, x, both)[0][dt._DIRECTIONS[i]].tolist() == [0.0, 0.0]  # held there
