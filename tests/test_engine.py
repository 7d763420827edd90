"""The compiled engine and the closed-form tangential map against exact solutions."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import beta

import microimpact as mi
from microimpact.solvers.engine import solve_normal, solve_normal_many
from microimpact.model.law import contact_potential_energy
from microimpact.presets import WALL_1990

HERTZ = mi.Contact(radius=5e-6, density=2500.0, stiffness=5e10, adhesion_line_force=0.0)


def hertz_max_penetration(c, v):
    """x_max = (5 m v^2 / (4 K sqrt r))^(2/5) from energy conservation."""
    return (5.0 * c.mass * v**2 / (4.0 * c.stiffness * math.sqrt(c.radius))) ** 0.4


@pytest.mark.parametrize("v", [1e-3, 0.7, 30.0])
def test_hertz_elastic_impact(v):
    # t_c = 2 (x_max / v) int_0^1 du / sqrt(1 - u^(5/2)) = (4/5) B(2/5, 1/2) x_max / v
    sol = solve_normal(HERTZ, v, rtol=1e-12)
    x_max = hertz_max_penetration(HERTZ, v)
    # tolerance: a few hundred times rtol, for the accumulated local errors over ~100 steps
    assert sol.outcome == "rebound"
    assert sol.e_n == pytest.approx(1.0, abs=1e-10)
    assert sol.max_penetration == pytest.approx(x_max, rel=1e-10)
    assert sol.contact_time == pytest.approx(0.8 * beta(0.4, 0.5) * x_max / v, rel=1e-10)


@pytest.mark.parametrize("zeta_h", [0.05, 0.5, 2.0])
def test_hertz_with_hertzian_damping_exact_restitution(zeta_h):
    # m x'' = -sqrt(r) K x^(3/2) (1 + c x') is separable in x': m x' dx'/(1 + c x') = -sqrt(r) K x^(3/2) dx,
    # and the right side integrates to zero over the contact, so
    # c v0 - ln(1 + c v0) = -c v1 - ln(1 - c v1)   (exact, Hunt & Crossley type damping)
    c = HERTZ.with_(zeta_hertz=zeta_h)
    v0 = 2.0
    ch, _ = c.damping_coefficients(v0)
    lhs = ch * v0 - math.log1p(ch * v0)
    v1 = brentq(lambda v1: -ch * v1 - math.log1p(-ch * v1) - lhs, 0.0, min(v0, (1 - 1e-15) / ch))
    sol = solve_normal(c, v0, rtol=1e-12)
    assert sol.e_n == pytest.approx(v1 / v0, rel=1e-9)  # integration error, ~1e3 rtol over the steps
    # and the energy balance closes with the dissipation tracked by the solver
    e0 = 0.5 * c.mass * v0**2
    assert sol.final_energy + sol.dissipated_energy == pytest.approx(e0, rel=1e-9)


@pytest.mark.parametrize("v", [1e-4, 0.3, 5.0, 100.0])
def test_conservative_adhesive_impact_rebounds_elastically(v):
    # with no damping E is conserved, so the sphere always leaves with its incident speed
    c = WALL_1990.with_(zeta_hertz=0.0, zeta_adhesion=0.0)
    sol = solve_normal(c, v, rtol=1e-12)
    assert sol.outcome == "rebound"
    # Conditioning: the sphere falls into a well of depth (4/15) m (X/T)^2 and climbs out with its
    # small incident energy, so an energy error of ~rtol x depth per step becomes a relative error
    # of rtol x depth / KE0 in the exit energy (measured 1e-4 at 1e-4 m/s with rtol 1e-12).
    well = 4.0 / 15.0 * c.mass * (c.length_scale / c.time_scale) ** 2
    ke0 = 0.5 * c.mass * v**2
    assert sol.e_n == pytest.approx(1.0, abs=1e-9 * max(1.0, well / ke0) * 1e-1)
    assert sol.dissipated_energy == 0.0


@pytest.mark.parametrize("v", [1e-5, 0.5, 1.2, 1.6, 3.0, 50.0])
def test_energy_balance_closes(v):
    sol = solve_normal(WALL_1990, v, rtol=1e-11, need_tail=True)
    e0 = 0.5 * WALL_1990.mass * v**2
    # the scale of the energies involved is the larger of e0 and the depth of the contact well
    well = 4.0 / 15.0 * WALL_1990.mass * (WALL_1990.length_scale / WALL_1990.time_scale) ** 2
    assert abs(sol.final_energy + sol.dissipated_energy - e0) <= 1e-8 * max(e0, well)


def test_energy_never_increases_along_trajectory():
    sol = solve_normal(WALL_1990, 0.5, trajectory=True, follow_capture=True, rtol=1e-10)
    c = WALL_1990
    x = sol.penetration
    energy = 0.5 * c.mass * sol.penetration_rate**2 + contact_potential_energy(c, x)
    scale = 0.5 * c.mass * 0.5**2
    # increases of more than the integration tolerance would be a sign error in the damping
    assert np.all(np.diff(energy) <= 1e-9 * scale)
    assert energy[-1] < 0.0  # captured


def test_restitution_converges_with_tolerance():
    errs = []
    ref = solve_normal(WALL_1990, 2.0, rtol=1e-13).e_n
    for rtol in (1e-4, 1e-6, 1e-8, 1e-10):
        errs.append(abs(solve_normal(WALL_1990, 2.0, rtol=rtol).e_n - ref))
    assert errs[-1] < 1e-9
    assert all(b < a for a, b in zip(errs, errs[1:]))


def test_capture_stops_at_the_energy_test():
    quick = solve_normal(WALL_1990, 0.5)
    followed = solve_normal(WALL_1990, 0.5, need_tail=True)
    assert quick.outcome == followed.outcome == "capture"
    assert quick.n_steps < followed.n_steps / 3
    assert quick.max_penetration == pytest.approx(followed.max_penetration, rel=1e-9)
    assert math.isinf(quick.contact_time) and quick.capture_time > 0


def test_batch_equals_single():
    v = np.array([0.3, 1.0, 1.5, 4.0, 40.0])
    many = solve_normal_many(WALL_1990, v, rtol=1e-10)
    for i, vi in enumerate(v):
        one = solve_normal(WALL_1990, vi, rtol=1e-10)
        # same kernel; fastmath lets LLVM fuse multiply-adds differently where it is inlined
        # into the parallel loop, so only round-off may differ
        assert many["e_n"][i] == pytest.approx(one.e_n, rel=1e-12, abs=0)
        assert many["captured"][i] == (one.outcome == "capture")


# ----------------------------------------------------------------- rigid-body limit with friction
@pytest.mark.parametrize("alpha", [10.0, 25.0, 50.0, 75.0])
def test_rigid_body_oblique_impact_with_coulomb_friction(alpha):
    # Without adhesion or damping the friction impulse is exactly the normal impulse m (1 + e) v_n
    # with e = 1, so the classical rigid-body results hold: sliding throughout when
    # tan(alpha) > (7/2) f (1 + e), giving mu_t = -f, else rolling with v_t,out = (5/7) v_t,in.
    f = 0.1
    c = HERTZ.with_(friction=f)
    v = 3.0
    r = mi.simulate_impact(c, v, alpha, 0.0, rtol=1e-12)
    vt_in = v * math.sin(math.radians(alpha))
    if math.tan(math.radians(alpha)) > 7.0 * f:
        assert not r.slip_ended
        assert r.mu_t == pytest.approx(-f, rel=1e-9)
    else:
        assert r.slip_ended
        assert r.velocity_out[1] == pytest.approx(5.0 / 7.0 * vt_in, rel=1e-9)
        # rolling: the contact point is at rest, u_t = v_t + r omega_t' = 0
        assert r.velocity_out[1] + c.radius * r.omega_out[2] == pytest.approx(0.0, abs=1e-9 * vt_in)
    assert r.e_n == pytest.approx(1.0, abs=1e-9)


def test_azimuth_invariance():
    c = WALL_1990
    w = (1e5, -2e5, 1.5e5)
    a = mi.simulate_impact(c, 2.0, 35.0, 0.0, w)
    phi = math.radians(70.0)
    rot = np.array([[math.cos(phi), -math.sin(phi)], [math.sin(phi), math.cos(phi)]])
    wt, wtp = rot @ np.array(w[1:])
    b = mi.simulate_impact(c, 2.0, 35.0, 70.0, (w[0], wt, wtp))
    # rotating the whole tangential state rotates the outcome; only round-off differs
    np.testing.assert_allclose(rot @ np.array(a.velocity_out[1:]), b.velocity_out[1:], rtol=0, atol=1e-12)
    np.testing.assert_allclose(rot @ np.array(a.omega_out[1:]), b.omega_out[1:], rtol=0, atol=1e-6)
    assert a.e_n == b.e_n and a.K_L == pytest.approx(b.K_L, abs=1e-13) and a.K_t == pytest.approx(b.K_t, abs=1e-13)


def test_normal_motion_independent_of_spin_and_friction():
    base = mi.simulate_impact(WALL_1990, 3.0, 20.0)
    for w, f in [((3e5, 1e5, -2e5), 0.15), ((0.0, 0.0, 0.0), 0.9)]:
        r = mi.simulate_impact(WALL_1990.with_(friction=f), 3.0, 20.0, 0.0, w)
        assert r.e_n == base.e_n


def test_simulate_many_matches_simulate_impact_and_reuses_normal_solves():
    c = WALL_1990
    speeds = np.array([0.4, 2.0, 8.0])
    angles = np.array([0.0, 15.0, 30.0, 60.0])
    ds = mi.simulate_many(c, speeds[:, None], angles[None, :], 0.0, (0.0, 1e5, 2e5), rtol=1e-10)
    # distinct normal speeds: speeds x cos(angles), except that 0 deg repeats nothing here
    assert ds.attrs["normal_solves"] == len(np.unique(speeds[:, None] * np.cos(np.radians(angles))))
    for i, v in enumerate(speeds):
        for j, a in enumerate(angles):
            r = mi.simulate_impact(c, v, a, 0.0, (0.0, 1e5, 2e5), rtol=1e-10)
            assert int(ds.outcome[i, j]) == (r.outcome == "capture")
            for name in ("e_n", "K_L", "K_t", "mu_t", "mu_tp"):
                # the batch may follow a captured tail further (the longest need of its group)
                np.testing.assert_allclose(float(ds[name][i, j]), getattr(r, name), rtol=1e-8, atol=1e-10)
    for name, var in ds.data_vars.items():
        assert "units" in var.attrs and "long_name" in var.attrs, name


def test_repeated_normal_speed_solved_once():
    ds = mi.simulate_many(WALL_1990, 2.0, 30.0, np.linspace(0, 360, 50), (0.0, 0.0, 0.0))
    assert ds.attrs["normal_solves"] == 1


def test_no_tangential_work_without_slip_spin_or_friction():
    r = mi.simulate_impact(WALL_1990.with_(friction=0.0), 2.0, 40.0, 0.0, (1e5, 1e5, 1e5))
    assert r.velocity_out[1:] == pytest.approx(r.velocity_in[1:], rel=0, abs=0)
    assert r.omega_out == r.omega_in


def test_captured_impact_reports_final_rolling_state():
    r = mi.simulate_impact(WALL_1990, 0.5, 30.0)
    assert r.outcome == "capture" and r.e_n == 0.0
    assert math.isnan(r.mu_t) and math.isnan(r.mu_tp)
    assert r.slip_ended
    assert r.velocity_out[0] == 0.0
    # rolling at the end: 5/7 of the tangential speed remains
    assert r.velocity_out[1] == pytest.approx(5.0 / 7.0 * r.velocity_in[1], rel=1e-12)
    assert 0.0 < r.K_t < 1.0 and r.K_L > r.K_t


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf])
def test_bad_speed(bad):
    with pytest.raises(ValueError, match="speed"):
        mi.simulate_impact(WALL_1990, bad)


@pytest.mark.parametrize("bad", [-1.0, 90.0, 120.0, math.nan])
def test_bad_incidence(bad):
    with pytest.raises(ValueError, match="incidence_deg"):
        mi.simulate_impact(WALL_1990, 1.0, bad)


# ----------------------------------------------------------------------------- one interface
def test_every_method_returns_the_one_result_type():
    """engine, rkg and reference agree on an oblique spinning rebound (rkg: fixed step, ~1e-6)."""
    args = (WALL_1990, 3.0, 30.0, 20.0, (1e5, 2e5, -1e5))
    res = {m: mi.simulate_impact(*args, method=m, rtol=1e-10) for m in ("engine", "rkg", "reference")}
    assert {type(r) for r in res.values()} == {mi.ImpactResult}
    assert [r.method for r in res.values()] == ["engine", "rkg", "reference:DOP853"]
    assert {r.stop_reason for r in res.values()} == {"separation"}
    for name in ("e_n", "mu_t", "mu_tp", "K_L", "K_t"):
        # measured: reference - engine 1e-10, rkg - engine 1e-6 (order ~2 from first contact)
        assert getattr(res["reference"], name) == pytest.approx(getattr(res["engine"], name), abs=1e-8), name
        assert getattr(res["rkg"], name) == pytest.approx(getattr(res["engine"], name), abs=1e-5), name
    assert res["rkg"].slip_end_time == pytest.approx(res["engine"].slip_end_time, rel=1e-5)
    assert res["rkg"].friction_impulse == pytest.approx(res["engine"].friction_impulse, rel=1e-5)


def test_rkg_steps_control_its_error():
    # with adhesion the convergence is irregular (order < 2.5 from first contact): measured e_n error
    # 2.2e-5 at 100 steps, 1.1e-7 at 6400
    ref = mi.simulate_impact(WALL_1990, 3.0, 30.0, rtol=1e-12)
    err = [abs(mi.simulate_impact(WALL_1990, 3.0, 30.0, method="rkg", steps=n).e_n - ref.e_n) for n in (100, 6400)]
    assert err[1] < err[0] / 50.0


def test_rkg_raises_where_it_cannot_give_the_tangential_outcome():
    # captured: the RKG stops at the energy test, the map would need the whole captured tail
    with pytest.raises(ValueError, match="rkg.*captured"):
        mi.simulate_impact(WALL_1990, 0.5, 30.0, method="rkg")
    r = mi.simulate_impact(WALL_1990.with_(friction=0.0), 0.5, 30.0, method="rkg")  # nothing tangential
    assert r.outcome == "capture" and r.stop_reason == "capture"


@pytest.mark.parametrize("speed", [0.01, 0.05, 0.5, 1.44])  # all captured (v_c = 1.449 m/s)
def test_captured_impacts_reach_their_largest_penetration(speed):
    """Every normal solver reports the largest penetration of a captured sphere, even where the
    capture test fires on the way in (a slow impact): the engine locates the turning point, and
    the RKG and the JKR/DMT solvers now go on to it before they stop (the RKG reported the xi of
    its capture step: 1/73 of it at 0.01 m/s). Against the scipy reference at rtol 1e-10: the
    engine to 1e-8 (its error at the default rtol 1e-8, about 5 rtol), the fixed-step RKG to
    1e-4 (measured 4e-6 to 7e-5; its maximum is the largest of its steps)."""
    c = WALL_1990.with_(friction=0.0)  # nothing tangential: the RKG may stop at the capture
    ref = mi.simulate_impact(c, speed, 0.0, method="reference", rtol=1e-10)
    assert ref.outcome == "capture"
    assert mi.simulate_impact(c, speed, 0.0).max_penetration == pytest.approx(ref.max_penetration, rel=1e-8)
    assert mi.simulate_impact(c, speed, 0.0, method="rkg").max_penetration == pytest.approx(ref.max_penetration,
                                                                                            rel=1e-4)


@pytest.mark.parametrize("speed, incidence", [(0.001, 75.0), (0.3, 0.0), (1.0, 40.0), (1.4, 10.0), (1.449, 0.0)])
def test_capture_time_is_where_the_energy_first_fell_below_zero(speed, incidence):
    """The capture time, by its definition (ImpactResult), against the scipy reference, which has it
    as an event. The engine's capture test keeps a margin below zero (10 rtol of the well depth,
    against integration drift) and used to report where E crossed the margin, on the step's
    interpolant: 2x late for a 0.001 m/s impact, 1e-6 near the capture speed at rtol 1e-9. Now
    the first zero of E, located on the step itself: 1e-6 at rtol 1e-9 (measured 7e-7 at 0.001
    m/s and 3.5e-7 at 1.449 m/s, where E falls slowest, 5e-9 elsewhere), 1e-8 at rtol 1e-12."""
    args = (WALL_1990, speed, incidence, 20.0, (1e5, 0.0, 0.0))
    ref = mi.simulate_impact(*args, method="reference", rtol=1e-12)
    assert ref.outcome == "capture"
    # the coupled solver: 1.11e-6 at rtol 1e-9 and 0.001 m/s (measured; this comparison passed only
    # through pytest's hidden abs=1e-12 on a time of 7e-9 s until tests/conftest.py removed it)
    for rtol, tol, tol_coupled in ((1e-9, 1e-6, 2e-6), (1e-12, 1e-8, 1e-8)):
        got = mi.simulate_impact(*args, rtol=rtol)
        assert got.capture_time == pytest.approx(ref.capture_time, rel=tol)
        coupled = mi.simulate_impact(WALL_1990.with_(tangential_model="mindlin", shear_modulus=1e10), *args[1:],
                                     rtol=rtol)
        assert coupled.capture_time == pytest.approx(ref.capture_time, rel=tol_coupled, abs=0)


def test_method_arguments_are_checked():
    with pytest.raises(ValueError, match="method"):
        mi.simulate_impact(WALL_1990, 1.0, method="RK4")
    with pytest.raises(ValueError, match="steps"):
        mi.simulate_impact(WALL_1990, 1.0, steps=100)
    with pytest.raises(ValueError, match="engine"):
        mi.simulate_many(WALL_1990, [1.0, 2.0], method="rkg")


def test_one_default_rtol():
    import inspect

    from microimpact.solvers import DEFAULT_RTOL, engine, reference

    for func in (mi.simulate_impact, mi.simulate_many, engine.solve_normal, engine.solve_normal_many,
                 reference.simulate_reference, reference.reference_trajectory):
        assert inspect.signature(func).parameters["rtol"].default == DEFAULT_RTOL == 1e-8, func.__name__


# ----------------------------------------------------------------------------- the contact law
def test_nondimensional_law_is_the_si_law():
    """The solvers' nondimensional forms times their units equal the SI forms of model.law."""
    from microimpact.model import law

    c = WALL_1990
    v = 2.0
    sc, _, c1, c2 = law.nondimensional_impact(c, v)
    c_h, c_a = c.damping_coefficients(v)
    xi = np.array([0.0, 0.3, 1.0, 2.5])
    y = np.array([1.5, -0.7, 0.2, -2.0])
    s = np.sqrt(xi)
    x, xdot = xi * sc.length, y * sc.speed
    m = c.mass
    acc = law.nondimensional_acceleration(s, s**3, y, c1, c2, sc.a_hertz, sc.a_adhesion)
    np.testing.assert_allclose(acc * m * sc.length / sc.time**2, -law.normal_force(c, x, xdot, c_h, c_a),
                               rtol=1e-12, atol=1e-12 * m * sc.length / sc.time**2)
    e = law.nondimensional_energy(s, y, sc.a_hertz, sc.a_adhesion)
    np.testing.assert_allclose(e * m * sc.speed**2, 0.5 * m * xdot**2 + law.contact_potential_energy(c, x), rtol=1e-12)
    d = law.nondimensional_dissipation_rate(s, s**3, y, c1, c2, sc.a_hertz, sc.a_adhesion)
    np.testing.assert_allclose(d * m * sc.speed**2 / sc.time, law.damping_dissipation_rate(c, x, xdot, c_h, c_a),
                               rtol=1e-12, atol=1e-30)
    # V(X) at the equilibrium, and F_H + F_A = 0 there
    assert law.contact_potential_energy(c, c.length_scale) == pytest.approx(-4 / 15 * m * sc.speed**2, rel=1e-14)
    assert float(law.normal_force(c, c.length_scale, 0.0, c_h, c_a)) == pytest.approx(0.0, abs=1e-12 * c.stiffness * c.length_scale**1.5)


def test_hertz_impact_scales():
    from microimpact.model import law

    hertz = WALL_1990.with_(adhesion_line_force=0.0)
    sc = law.nondimensional_scales(hertz, 2.0)
    assert (sc.a_hertz, sc.a_adhesion) == (1.25, 0.0)
    # x* is the largest penetration of the undamped Hertz impact: m v^2 / 2 = V(x*)
    assert float(law.contact_potential_energy(hertz, sc.length)) == pytest.approx(0.5 * hertz.mass * 4.0, rel=1e-14)
    assert sc.speed == pytest.approx(2.0, rel=1e-15)


def test_twist_torque_is_coulomb_friction_over_the_hertz_pressure():
    """(3 pi / 16) f a |F_n| (Eq. (18) corrected) = int f p(rho) rho dA over the Hertz pressure."""
    from scipy.integrate import quad

    from microimpact.model import law

    f, a, fn = 0.3, 2e-7, 1e-6
    p0 = 3.0 * fn / (2.0 * np.pi * a * a)
    # rho = a sin(theta) removes the square-root edge of the pressure, which left quad 3.5e-5 short
    # (this comparison passed only through pytest's hidden abs=1e-12 on a torque of 3.5e-14 N m)
    torque = quad(lambda t: f * p0 * np.cos(t) * (a * np.sin(t)) ** 2 * 2.0 * np.pi * a * np.cos(t), 0.0, np.pi / 2,
                  epsabs=0.0, epsrel=1e-13)[0]
    assert float(law.twist_friction_torque(f, a, -fn)) == pytest.approx(torque, rel=1e-10)
