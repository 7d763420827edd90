"""Stress and property tests of the impact engine: invariants over decades of every input.

Engine bugs found by the sweep are kept as regression tests with their reproducers. The property
tests draw over the full ranges of the issue; the seeded sweep at the end covers them too, with
the worst errors in its summary.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from microimpact.studies import stress
from microimpact.solvers.dem_tangential import solve_dem_tangential
from microimpact.solvers.impact import simulate_impact
from microimpact.solvers.reference import simulate_reference
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
    contact = stress.contact_of({
        "radius": radius,
        "density": draw(log_uniform(*r["density"])),
        "stiffness": draw(log_uniform(*r["stiffness"])),
        "work_of_adhesion": draw(with_zero(log_uniform(*r["work_of_adhesion"]))),
        "zeta_hertz": draw(with_zero(log_uniform(*r["zeta_hertz"]))),
        "zeta_adhesion": draw(with_zero(log_uniform(*r["zeta_adhesion"]))),
        "friction": draw(with_zero(st.floats(0.0, 2.0))),
    })
    inc = draw(with_zero(st.floats(0.0, 89.9)))
    az = draw(st.floats(0.0, 360.0))
    spin_max = r["spin_ratio"][1]  # 100 x the rolling spin
    spin = tuple(draw(st.floats(-spin_max, spin_max)) * speed / radius for _ in range(3))
    return contact, speed, inc, az, spin


@PROFILE
@given(impacts())
def test_invariants(case):
    contact, speed, inc, az, spin = case
    # rtol 1e-10 as in the sweep, whose energy tolerance (1e-8) is set for it
    res = simulate_impact(contact, speed, inc, az, spin, rtol=1e-10)
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
MISSED_SEPARATION = stress.contact_of({
    "radius": 0.0004436954785754723, "density": 4733.544875582984, "stiffness": 94267726701.7395,
    "work_of_adhesion": 0.0011948335784818724, "zeta_hertz": 141.12729602871758,
    "zeta_adhesion": 0.005715222866944042, "friction": 1.6324934088437917})


# Regression (found by the stress sweep, fixed): an extremum-of-y event located in the same step as
# separation landed on s = 0 without being declared a separation, and the impact was reported as a
# capture (15.55 m/s -> capture while 15.5 and 16.0 m/s rebound with e_n = 0.3323).
def test_separation_through_an_extremum_event():
    res = simulate_impact(MISSED_SEPARATION, 15.553686347910835)
    assert res.outcome == "rebound"
    # the independent 3-D reference solver (10 ms here) gives the expected value, not a pin of the
    # engine's own output; at the engine's default rtol 1e-8 the two agree to 4e-9 (measured)
    ref = simulate_reference(MISSED_SEPARATION, 15.553686347910835, rtol=1e-10)
    assert ref.outcome == "rebound"
    assert res.e_n == pytest.approx(ref.e_n, abs=1e-7)


# Regression (fixed): strongly overdamped captures (C ~ 1e3) crept into the equilibrium with ~C^2
# explicit steps and hit the step limit; the engine now stops once the motion is inertia-free.
def test_strongly_overdamped_capture_ends():
    for changes in ({"zeta_adhesion": 3e4, "friction": 0.0}, {"zeta_hertz": 1e5, "zeta_adhesion": 0.0}, {"zeta_adhesion": 3e4}):
        res = simulate_impact(WALL_1990.with_(**changes), 1e-4, 30.0, 0.0, (1e3, 0.0, 0.0))
        assert res.outcome == "capture"
        # it creeps up to the equilibrium X without overshoot
        assert res.max_penetration == pytest.approx(WALL_1990.length_scale, rel=1e-9, abs=0)


# Regression (fixed): without damping, round-off in E relative to the depth of the well trapped a
# slow sphere (1e-6 m/s reported as a capture); the engine now mirrors the time-reversible motion.
def test_undamped_low_speed_rebounds_elastically():
    for v in (1e-6, 1e-5, 1e-4):
        res = simulate_impact(WALL_1990.with_(zeta_hertz=0.0, zeta_adhesion=0.0, friction=0.0), v)
        assert res.outcome == "rebound"
        assert res.e_n == 1.0  # exact by the mirror symmetry


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


def test_sweep_has_no_failures(sweep):
    assert sweep.summary["cases_failed"] == 0, sweep.summary["failed_cases"]


def test_sweep_is_reproducible():
    assert stress.draw_cases(5, seed=3) == stress.draw_cases(5, seed=3)
    assert stress.draw_cases(5, seed=3) != stress.draw_cases(5, seed=4)


# ------------------------------------------------------------------ findings that do not fail the sweep
def test_slow_convergence_is_a_note_not_a_failure():
    """Case 12612 of seed 0 (extended domain): a strongly damped capture whose result differs by
    2.9e-4 of the speed scale between rtol 1e-8 and 1e-10 (above the 1e-4 tolerance) and by 2.9e-6
    between 1e-10 and 1e-12 (measured): it converges (a hundredfold reduction), so it is noted, not
    failed."""
    case = stress.draw_cases(12613, seed=0)[12612]
    row = stress.check_case(case)
    assert row["failures"] == []
    assert [k for k, _ in row["notes"]] == ["slow_convergence"]
    assert row["convergence_error"] > stress.TOLERANCES["convergence"]
    assert row["convergence_error_tight"] <= row["convergence_error"] / stress.CONVERGENCE_REDUCTION


def test_convergence_failure_when_the_error_does_not_shrink():
    """The same case fails when the tolerance is below what rtol 1e-12 reaches (2.9e-6)."""
    case = stress.draw_cases(12613, seed=0)[12612]
    row = stress.check_case(case, tolerances={"convergence": 1e-7})
    assert [k for k, _ in row["failures"]] == ["convergence"]
    assert row["notes"] == []


def test_reference_timeout_is_a_note_not_a_failure():
    """A reference solve cut by the time box is reported apart and leaves the case passing."""
    case = stress.draw_cases(1, seed=0)[0]  # a strongly damped capture: the reference needs seconds
    row = stress.check_case(case, reference=True, case_time_limit=0.05)
    assert [k for k, _ in row["notes"]] == ["reference_timeout"]
    assert not [k for k, _ in row["failures"] if k != "timeout"]  # the engine itself may exceed 0.05 s
    assert math.isnan(row["reference_error"])


def test_summary_counts_notes_apart(tmp_path):
    report = stress.stress_sweep(2, seed=0, reference_every=1, case_time_limit=0.05)
    s = report.summary
    assert s["notes_by_kind"]["reference_timeout"] >= 1
    assert set(s["failures_by_kind"]) == set(stress.FAILURE_KINDS)
    assert "noted" in stress.summary_line(s)
    assert report.dataset["notes"].dims == ("case",)
    assert report.dataset["energy_error"].attrs["units"] == "1"
    stress.write_stress_summary(s, tmp_path / "s.json")
    assert (tmp_path / "s.json").read_text().startswith("{")


# ------------------------------------------------------------------ every law
#: cases of the every-law sweep in the default run (the first of seed 0: damping up to 9e5 in cases 0, 1,
#: 7 and 9, f = 0 with the pulloff limit in case 2); the extended run takes all 40
DEFAULT_CASES, EXTENDED_CASES = 10, 40


@pytest.mark.parametrize("law", [law for law in stress.LAWS if law != "ring"])
@pytest.mark.parametrize("n_cases", [DEFAULT_CASES, pytest.param(EXTENDED_CASES, marks=pytest.mark.extended)])
def test_every_law_passes_the_sweep(law, n_cases):
    """The first 40 cases of seed 0 (10 in the default run) under every contact law: all checks of the sweep (finite
    results, e_n, the energy balance to 1e-8 of the case's scale, convergence in rtol). They
    include damping up to 9e5 (cases 0, 1, 7, 9, 22, 36), which ended in the step limit for every
    law but the ring law before the JKR/DMT and coupled solvers took the inertia-free limit and the
    closed-form tails; and f = 0 with the pulloff limit (cases 2, 35, 36: omega_out was NaN).

    With rolling resistance every case now gets a result (10 of these 40 ended in the step limit
    before the coupled solver took the closed-form tails under the pulloff friction too), and the
    two captured spheres held by friction that missed the convergence tolerance (cases 20 and 33)
    converge since omega_r is held at rest within a step. A result the solver cannot settle it
    must report (``not_determined``, a note of the sweep, not a failure): none of these 40.

    Under the sds rolling law cases 30, 37, 38 and 39 had no result (the rolling velocity across the
    slip: Radau alone failed or took ~56 s; friction 0 without spin: a 0 / 0 frame) before the DEM
    tangential solver tried LAMMPS's rolling across the slip by LSODA, BDF, then Radau
    (tests/test_dem_tangential_stress.py)."""
    report = stress.stress_sweep(n_cases, seed=0, reference_every=0, law=law)
    s = report.summary
    assert s["law"] == law and s["cases_run"] == n_cases
    assert s["cases_failed"] == 0, s["failed_cases"]
    noted = {c["inputs"]["case"] for c in s["noted_cases"] if any(n["kind"] == "not_determined" for n in c["notes"])}
    assert noted == set()


def test_compliant_law_gets_the_shear_modulus_of_its_stiffness():
    """G* of two equal bodies with Poisson's ratio 0.3 from K = (4/3) E* (Eq. (3)): E = 3 K (1 - nu^2)
    / 2, G = E / (2 (1 + nu)), 1/G* = 2 (2 - nu) / G, so G* / K = 3 (1 - nu) / (8 (2 - nu))."""
    case = stress.draw_cases(1, seed=0)[0]
    c = stress.contact_of(case, "mindlin")
    nu = 0.3
    assert c.shear_modulus / case["stiffness"] == pytest.approx(3 * (1 - nu) / (8 * (2 - nu)), rel=1e-12, abs=0.0)
    assert c.tangential_model == "mindlin" and stress.contact_of(case).tangential_model == "rigid"


def test_dem_laws_get_stiffnesses_of_the_hertz_contact():
    """The LAMMPS tangential, rolling and twisting laws of the sweep take their stiffnesses from the
    case's Hertz contact, k_n = K a at the largest undamped approach (a = sqrt(R L), L from
    m v^2 / 2 = (2/5) K sqrt(R) L^(5/2), Hertz's energy balance): k_t = 2 k_n / 7, k_roll = k_n,
    k_twist = k_n a^2, mu_twist = 0.1 a."""
    case = stress.draw_cases(1, seed=0)[0]
    c = stress.contact_of(case, "jkr_force_viscoelastic_lammps_mindlin_rescale_force_sds")
    v_n = case["speed"] * math.cos(math.radians(case["incidence_deg"]))
    L = (5.0 * c.mass * v_n**2 / (4.0 * case["stiffness"] * math.sqrt(case["radius"]))) ** 0.4
    a = math.sqrt(case["radius"] * L)
    k_n = case["stiffness"] * a
    assert c.rolling_stiffness == pytest.approx(k_n, rel=1e-12, abs=0.0)
    assert c.twisting_stiffness == pytest.approx(k_n * a * a, rel=1e-12, abs=0.0)
    assert c.twisting_friction == pytest.approx(0.1 * a, rel=1e-12, abs=0.0)
    assert c.shear_modulus == stress.contact_of(case, "mindlin").shear_modulus
    linear = stress.contact_of(case, "hertz_mass_velocity_linear_history")
    assert linear.tangential_stiffness == pytest.approx(2.0 * k_n / 7.0, rel=1e-12, abs=0.0)


#: case 7862 of seed 0 (its drawn inputs): undamped, 3.7 um/s normal, captured under JKR
_UNDAMPED_CAPTURE = {"case": 7862, "radius": 0.0009803992464730937, "density": 1073.9470354582918,
                     "stiffness": 588658941940.8593, "work_of_adhesion": 0.0017090875359990095, "zeta_hertz": 0.0,
                     "zeta_adhesion": 0.0, "friction": 1.1207900486717566, "speed": 2.6221135443355426e-05,
                     "incidence_deg": 81.9718597289655, "azimuth_deg": 284.2371258060548,
                     "omega_n": 2.4352806166089525, "omega_t": 2.012758367333998, "omega_tp": 2.2898412336100913}


@pytest.mark.parametrize("law", ["jkr", "jkr_force"])
def test_undamped_capture_ends_rolling(law):
    """An undamped captured sphere oscillates in the well for ever, its friction impulse growing
    each period without end: its slip stops and it rolls, slip u = 0, reached by the impulse
    -u_in / kappa (kappa = 1 + m R^2 / I = 7/2; the contact force acts at the contact point). The
    JKR solvers ran into their step limit (EngineError) on this case."""
    case = _UNDAMPED_CAPTURE
    c = stress.contact_of(case, law)
    with stress._model_warnings_ignored():
        r = simulate_impact(c, case["speed"], case["incidence_deg"], case["azimuth_deg"],
                            (case["omega_n"], case["omega_t"], case["omega_tp"]), rtol=1e-10)
    assert r.outcome == "capture"
    rad, (_, vt, vtp), (_, wt, wtp) = c.radius, r.velocity_in, r.omega_in
    slip_in = (vt + rad * wtp, vtp - rad * wt)
    kappa = 1.0 + c.mass * rad**2 / c.moment_of_inertia
    scale = case["speed"]  # [m/s]: the tolerance's scale
    _, vt_out, vtp_out = r.velocity_out
    _, wt_out, wtp_out = r.omega_out
    assert vt_out + rad * wtp_out == pytest.approx(0.0, abs=1e-9 * scale)
    assert vtp_out - rad * wt_out == pytest.approx(0.0, abs=1e-9 * scale)
    assert (vt_out, vtp_out) == pytest.approx((vt - slip_in[0] / kappa, vtp - slip_in[1] / kappa), rel=0.0,
                                              abs=1e-9 * scale)


#: case 15 of seed 0 (its drawn inputs), friction 0, under the sweep's sds rolling law
_FRICTIONLESS_ROLLING = {"case": 15, "radius": 0.006574925465721917, "density": 9555.568867562728,
                         "stiffness": 452220942393.6395, "work_of_adhesion": 2.08416071500343,
                         "zeta_hertz": 0.44189420246502636, "zeta_adhesion": 136.8242488950831, "friction": 0.0,
                         "speed": 0.011069391567538374, "incidence_deg": 6.629317104462753,
                         "azimuth_deg": 171.4201067581184, "omega_n": -25.678773397597887,
                         "omega_t": 29.058653555657266, "omega_tp": -127.04584550425349}


def test_frictionless_rolling_across_the_slip_gets_a_result():
    """Without friction the slip carries no force: the tangential velocity keeps its value, and the
    rolling outcome is that of the same spin without slip. The slip across the rolling velocity sent
    this case (the sweep's sds law) to Radau, which stopped after 2e4 evaluations
    (DemTangentialError, after about 40 s)."""
    case = _FRICTIONLESS_ROLLING
    c = stress.contact_of(case, "jkr_force_viscoelastic_lammps_mindlin_rescale_force_sds")
    r, w = c.radius, (case["omega_n"], case["omega_t"], case["omega_tp"])
    v_n = case["speed"] * math.cos(math.radians(case["incidence_deg"]))
    v_t = case["speed"] * math.sin(math.radians(case["incidence_deg"]))
    across = solve_dem_tangential(c, (-v_n, v_t, 0.0), w, rtol=1e-10).state
    no_slip = solve_dem_tangential(c, (-v_n, -r * w[2], r * w[1]), w, rtol=1e-10).state
    assert across["velocity_out"][1:] == pytest.approx((v_t, 0.0), rel=0.0, abs=1e-12 * v_t)
    spin = r * math.hypot(w[1], w[2])  # the tolerance's scale: the rolling speed [m/s]
    for got, want in zip(across["omega_out"], no_slip["omega_out"]):
        assert r * got == pytest.approx(r * want, rel=0.0, abs=1e-12 * spin)
    assert max(abs(a - b) for a, b in zip(across["omega_out"][1:], w[1:])) * r > 1e-4 * spin  # the rolling law acted


# ------------------------------------------------------------------ the plastic law
def test_plastic_law_sweep_against_its_closed_form():
    """The Thornton & Ning law over 60 cases of seed 0 of the extended domain, each compared with
    the law's closed-form energy account (reference_every=1): every check passes, captures and
    rebounds both occur, and the driver meets the closed form to 1e-7 of the energy scale (measured
    worst 3.6e-9 over 200 cases; TOLERANCES["reference"] is 1e-5)."""
    s = stress.stress_sweep(60, seed=0, reference_every=1, law="thornton_ning").summary
    assert s["cases_failed"] == 0, s["failed_cases"]
    assert s["reference_cases"] == 60 and 0 < s["captures"] < 60
    assert s["worst_reference_error"]["value"] < 1e-7
    assert s["worst_energy_error"]["value"] < 1e-8


def test_plastic_law_case_yields_over_its_drawn_decades():
    """The drawn yield velocity spans V_y / v_n from 1e-3 to 1e2 (above 1: no yield), and a
    mis-scaled p_y would show as a wrong V_y by (TN11)."""
    cases = stress.draw_cases(200, seed=0)
    ratios = []
    for case in cases:
        pc = stress.plastic_contact_of(case)
        v_n = case["speed"] * math.cos(math.radians(case["incidence_deg"]))
        ratios.append(math.log10(stress.tn.yield_velocity(pc) / v_n))
        if case["work_of_adhesion"] == 0.0:  # no first-contact floor: V_y exactly as drawn
            assert ratios[-1] == pytest.approx(-3.0 + 5.0 * case["azimuth_deg"] / 360.0, abs=1e-9)
    assert min(ratios) < -2.5 and max(ratios) > 1.5
    with pytest.raises(ValueError, match="not a Contact choice"):
        stress.contact_of(cases[0], "thornton_ning")
