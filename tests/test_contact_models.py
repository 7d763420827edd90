"""Sub-models beyond the paper: tangential compliance ("mindlin") and adhesion-aware friction
("pulloff"), :mod:`microimpact.model.tangential_compliance` and :mod:`microimpact.solvers.coupled`.

Checks: the analytic limits (rigid limit of an infinitely stiff tangential contact, the rigid
gross-sliding line of Maw, Barber & Fawcett (1976) at large non-dimensional incidence, the coupled
solver against the engine's closed form for the paper's model), an independent scipy integration
of the compliant equations, the captured sphere with adhesion-aware friction, the materials config
and the Kharaz et al. (2001) comparison.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from microimpact.analysis.kharaz import KHARAZ_CONDITIONS, _base_contact, kharaz_comparison
from microimpact.io import default_materials_path, read_materials
from microimpact.model import tangential_compliance as tc
from microimpact.presets import WALL_1990
from microimpact.solvers import check_sub_models
from microimpact.solvers.hysteretic_reference import hysteretic_reference
from microimpact.solvers.impact import simulate_impact, simulate_many

V = KHARAZ_CONDITIONS["speed"]


@pytest.fixture(scope="module")
def alumina():
    return _base_contact(None)  # Kharaz conditions, e_n = 1, G* from the materials config


def test_effective_shear_modulus_from_the_materials_config():
    pair = read_materials(default_materials_path())["alumina_on_soda_lime_glass"]
    g1, g2 = 380e9 / (2 * 1.23), 70e9 / (2 * 1.25)  # G = E / (2 (1 + nu))
    expected = 1.0 / ((2 - 0.23) / g1 + (2 - 0.25) / g2)
    # the config stores G1 rounded to 5 digits (154.47 GPa): relative 1e-5
    assert pair.effective_shear_modulus == pytest.approx(expected, rel=1e-5)
    assert pair.contact(2.5e-3).shear_modulus == pytest.approx(expected, rel=1e-5)
    # a pair given by its stiffness alone has no Poisson ratios, hence no G*
    assert read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"].effective_shear_modulus is None


def test_mindlin_force_curve():
    # small displacement: -k_t delta (to first order; relative error ~ (3/4) q = 7.5e-7 at q = 1e-6)
    k, lim = 2.0, 3.0
    dstar = tc.mindlin_stuck_displacement(k, lim)
    assert dstar == 1.5 * lim / k
    ft, fp = tc.mindlin_force(1e-6 * dstar, 0.0, dstar, lim)
    assert ft == pytest.approx(-k * 1e-6 * dstar, rel=1e-6) and fp == 0.0
    # gross slip: the limit, against the displacement (exact)
    assert tc.mindlin_force(0.0, 2 * dstar, dstar, lim) == (-0.0, -lim)
    # no limit, no force
    assert tc.mindlin_force(1.0, 1.0, 0.0, 0.0) == (0.0, 0.0)


def test_pulloff_force_is_the_largest_tension_of_the_static_law():
    c = WALL_1990
    x = np.linspace(1e-4, 1.0, 200001) * c.length_scale
    static = math.sqrt(c.radius) * (c.stiffness * x**1.5 - 2 * math.pi * c.adhesion_line_force * np.sqrt(x))
    # grid spacing 5e-6 X around a quadratic minimum: relative error ~1e-10
    assert tc.pulloff_force(c) == pytest.approx(-static.min(), rel=1e-8)
    assert tc.nondimensional_pulloff_force(1.0, 1.0) == pytest.approx(2 / (3 * math.sqrt(3)), rel=1e-15)


def test_stiff_tangential_contact_gives_the_rigid_closed_form(alumina):
    angles = np.array([5.0, 20.0, 45.0])
    rigid = simulate_many(alumina, V, angles)
    stiff = simulate_many(alumina.with_(tangential_model="mindlin", shear_modulus=1e3 * alumina.shear_modulus), V, angles)
    ratio = lambda ds: ds["velocity_out_t"].values / (V * np.sin(np.radians(angles)))  # noqa: E731
    # the elastic energy still stored at the end of stick scales as 1/sqrt(stiffness ratio): at
    # 1000 x G* the rolling limit 5/7 is reached to 1e-3 (measured 7e-4); sliding throughout
    # (45 deg) is the same Coulomb impulse, to the solver tolerance
    np.testing.assert_allclose(ratio(stiff), ratio(rigid), atol=1.5e-3)
    assert ratio(stiff)[2] == pytest.approx(ratio(rigid)[2], abs=1e-6)
    assert ratio(rigid)[0] == pytest.approx(5 / 7, abs=1e-9)


def test_maw_barber_fawcett_shape(alumina):
    """Contact-point rebound u_out / u_in against psi = tan(alpha) / (f (1 + e_n)) * k_t/k_n."""
    c = alumina.with_(tangential_model="mindlin")
    ratio_kt_kn = 4 * c.shear_modulus / (0.75 * c.stiffness)  # 8 G* a / (2 E* a), E* = 3 K / 4
    f = c.friction
    psi = np.array([0.05, 1.0, 5.0, 10.0])
    alpha = np.degrees(np.arctan(psi * f * 2 / ratio_kt_kn))
    assert tc.maw_incidence_parameter(alpha, f, 0.25) == pytest.approx(psi * tc.stiffness_ratio(0.25) / ratio_kt_kn, rel=1e-12)
    ds = simulate_many(c, V, alpha)
    u_in = V * np.sin(np.radians(alpha))
    u_out = (ds["velocity_out_t"] + c.radius * ds["omega_out_tp"]).values
    r = u_out / u_in
    # small psi: the contact sticks and the tangential spring returns the contact point forward
    # (u_out / u_in close to 1: the rebound spin is below the rolling spin)
    assert r[0] > 0.9
    # psi ~ 1: the elastic recoil reverses the contact point (spin reversal relative to rolling)
    assert r[1] < -0.3
    # large psi: gross sliding all through, the rigid line 1 - (7/2) f (1 + e_n) / tan(alpha),
    # to the solver tolerance (rtol 1e-8)
    rigid_line = 1 - 3.5 * f * 2 / np.tan(np.radians(alpha))
    np.testing.assert_allclose(r[2:], rigid_line[2:], atol=1e-6)


def test_compliant_equations_against_an_independent_scipy_integration(alumina):
    """Hertz normal force, Mindlin tangential force, rigid-body tangential motion, integrated in
    time with scipy (no Sundman form, no projection) for an impact that sticks (f = 10)."""
    c = alumina.with_(tangential_model="mindlin", friction=10.0)
    alpha = math.radians(10.0)
    m, r, inertia = c.mass, c.radius, c.moment_of_inertia
    k_h = math.sqrt(r) * c.stiffness

    def rhs(_t, z):
        x, xd, vt, wtp, d = z
        xp = max(x, 0.0)
        fn = k_h * xp**1.5
        a = math.sqrt(r * xp)
        kt = float(tc.tangential_stiffness(c.shear_modulus, a))
        ft, _ = tc.mindlin_force(d, 0.0, tc.mindlin_stuck_displacement(kt, c.friction * fn), c.friction * fn)
        return [xd, -fn / m, ft / m, r * ft / inertia, vt + r * wtp]

    def sep(_t, z):
        return z[0]

    sep.terminal, sep.direction = True, -1
    z0 = [0.0, V * math.cos(alpha), V * math.sin(alpha), 0.0, 0.0]
    sol = solve_ivp(rhs, (0.0, 1e-3), z0, method="DOP853", rtol=1e-11, atol=1e-15, events=sep)
    vt_ref = sol.y[2, -1]
    res = simulate_impact(c, V, 10.0, rtol=1e-10)
    # both to ~1e-9 relative; 1e-6 allows for the non-smooth start of contact in the scipy run
    assert res.velocity_out[1] == pytest.approx(vt_ref, rel=1e-6)
    assert res.e_n == pytest.approx(1.0, abs=1e-6)


def test_coupled_solver_reproduces_the_engine_for_the_paper_model():
    """The coupled path with the paper's friction law, forced, against the closed form."""
    from microimpact.solvers.impact import _coupled_results

    v_in = (np.array([-3.0, -0.5]), np.array([2.0, 4.0]), np.array([0.5, 0.0]))
    w_in = (np.array([1e5, 0.0]), np.array([0.0, 0.0]), np.array([0.0, 0.0]))
    got = _coupled_results(WALL_1990, v_in, w_in, np.array([0.15, 0.15]), 1e-10)
    for i in range(2):
        v = float(np.sqrt(sum(x[i] ** 2 for x in v_in)))
        inc = math.degrees(math.acos(-v_in[0][i] / v))
        az = math.degrees(math.atan2(v_in[2][i], v_in[1][i]))
        ref = simulate_impact(WALL_1990, v, inc, az, omega=tuple(w[i] for w in w_in), rtol=1e-10)
        assert bool(got["outcome"][i]) == (ref.outcome == "capture")
        # two integrators at rtol 1e-10 each: 1e-7 on e_n; the coupled solver stops a captured
        # sphere at an oscillation amplitude of 1e-6 X and takes the rest of the tail as linear
        # (the engine integrates it to rtol): 1e-6 on the tangential outcome (measured 6e-7)
        assert got["e_n"][i] == pytest.approx(ref.e_n, abs=1e-7)
        assert got["velocity_out_t"][i] == pytest.approx(ref.velocity_out[1], rel=1e-6)
        assert got["omega_out_n"][i] == pytest.approx(ref.omega_out[0], rel=1e-6, abs=1e-3)


@pytest.mark.parametrize("selection", [("rigid", "pulloff"), ("mindlin", "net"), ("mindlin_deresiewicz", "pulloff")])
def test_coupled_normal_events_are_the_normal_motions(selection):
    """The tangential sub-models leave the normal motion alone, so the coupled solver's largest
    penetration is the engine's, which locates it with its own event machinery (an independent
    code path). Tolerance: both solvers' error at rtol 1e-9, about 5 rtol each (docs/benchmark.md;
    measured 6e-10 over 300 impacts), against a tight engine solve. Before the coupled solver
    located it, it was the largest step end: 3.7e-4 short at rtol 1e-9, and 50 % short where a
    captured rigid pulloff impact stopped before its largest penetration."""
    from microimpact.model.kinematics import incident_velocity
    from microimpact.solvers.coupled import solve_coupled
    from microimpact.solvers.engine import solve_normal_many

    rng = np.random.default_rng(11)
    n = 40
    speed = np.exp(rng.uniform(np.log(0.05), np.log(50.0), n))
    v = tuple(np.array([incident_velocity(s, a, b) for s, a, b in
                        zip(speed, rng.uniform(0, 88, n), rng.uniform(0, 360, n))]).T)
    w = tuple(rng.normal(0.0, 2e5, n) for _ in range(3))
    c = WALL_1990.with_(tangential_model=selection[0], friction_model=selection[1], shear_modulus=1e10)
    got = solve_coupled(c, v, w, np.full(n, 0.15), rtol=1e-9)
    assert 0 < got["captured"].sum() < n  # both outcomes are checked
    ref = solve_normal_many(WALL_1990, -v[0], rtol=1e-12)
    np.testing.assert_allclose(got["max_penetration"], ref["max_penetration"], rtol=1e-8)
    # the capture time (energy below the capture test's margin, 10 rtol of the well depth) is
    # located in its step too, as the engine's: the margin moves it by up to 1e-6 at rtol 1e-9
    # (measured 8e-7); before, it was the step's end, 4e-2 off
    cap = got["captured"]
    np.testing.assert_allclose(got["capture_time"][cap], ref["capture_time"][cap], rtol=5e-6)
    if selection[0] == "rigid":  # the end of sliding (J = J*), located: 4e-9 of rtol 1e-12's (1e-4 before)
        tight = solve_coupled(c, v, w, np.full(n, 0.15), rtol=1e-12)
        ends = np.isfinite(tight["slip_end_time"])
        assert ends.sum() > n // 2
        np.testing.assert_allclose(got["slip_end_time"][ends], tight["slip_end_time"][ends], rtol=1e-7)


@pytest.mark.parametrize("incidence", [82.0, 87.0, 89.9])  # captured: v_n < 1.45 m/s
def test_adhesion_aware_friction_stops_a_captured_sphere(incidence):
    paper = simulate_impact(WALL_1990, 10.0, incidence, omega=(2.6e5, 0.0, 0.0))
    aware = simulate_impact(WALL_1990.with_(friction_model="pulloff"), 10.0, incidence, omega=(2.6e5, 0.0, 0.0))
    assert aware.outcome == "capture"
    v_t0 = 10.0 * math.sin(math.radians(incidence))
    # slip ended: rolling at 5/7 of the incident tangential speed (exact for a rigid contact), no twist
    assert aware.slip_ended
    assert aware.velocity_out[1] == pytest.approx(5 / 7 * v_t0, rel=1e-9)
    # twist stopped: zero up to the round-off of omega_0 - k J_a at the stop (2.6e5 rad/s x 1e-16)
    assert abs(aware.omega_out[0]) < 1e-9
    assert aware.omega_out[2] == pytest.approx(-5 / 7 * v_t0 / WALL_1990.radius, rel=1e-9)
    if incidence == 89.9:  # the paper's law leaves the grazing sphere sliding and twisting
        assert paper.velocity_out[1] == pytest.approx(9.66, abs=0.01)
        assert not paper.slip_ended and paper.omega_out[0] > 1e5


def test_sub_model_coverage():
    c = WALL_1990.with_(tangential_model="mindlin", shear_modulus=1e9)
    check_sub_models(c, "engine")
    with pytest.raises(ValueError, match="method='engine'"):
        check_sub_models(c, "reference")


def test_kharaz_rigid_and_compliant():
    ds = kharaz_comparison(fit_friction=False, curve_incidence_deg=[10.0, 45.0])
    rms = {k: v for k, v in ds.attrs.items() if k.startswith("rms_tangential_restitution")}
    # the rigid model's figures of issue 14 (0.075 RMS below 30 deg with the fitted friction; 0.054
    # over all angles with the nominal friction); compliant above 30 deg within the target 0.03
    assert rms["rms_tangential_restitution_sliding_compliant"] < 0.03
    d = ds["tangential_restitution_difference_compliant"].values
    a = ds["tangential_restitution_incidence_deg"].values
    # from 9 deg on the compliant model is within 0.08 of every measurement (measured: 0.075 at 9.5 deg)
    assert np.all(np.abs(d[a > 9.0]) < 0.08)
    # rebound spin and angle: the compliant model is closer than the rigid one below 30 deg
    for q in ("rebound_spin", "rebound_angle"):
        assert ds.attrs[f"rms_{q}_below_compliant"] < ds.attrs[f"rms_{q}_below"]
    assert float(ds["effective_shear_modulus"]) == pytest.approx(1.352e10, rel=1e-3)


# =============================================================================== hysteretic law
def test_md_branch_is_mindlin_deresiewicz_at_constant_load():
    """At constant F_lim the branch coordinate grows as u / (c delta*), so the force of a branch
    from gross slip (c = 2) is the Mindlin-Deresiewicz unloading curve
    T = -F_lim + 2 F_lim [1 - (1 - Delta / (2 delta*))^(3/2)] (Johnson 1985, Eq. 7.56)."""
    k, lim = 2.0, 3.0
    dstar = tc.mindlin_stuck_displacement(k, lim)
    c = tc.md_turning_span(-1.0, 1.0)  # turning point at the limit -F_lim, new branch s = +1
    assert c == 2.0
    rate = tc.md_branch_rate(0.3, c, 1.0, k, lim, 0.0)
    assert rate == pytest.approx(1.0 / (c * dstar), rel=1e-15)  # exact arithmetic, round-off only
    delta = np.linspace(0.0, 2 * dstar, 9)
    md = [-lim + 2 * lim * (1 - (1 - d / (2 * dstar)) ** 1.5) for d in delta]
    ours = [lim * tc.md_force_ratio(d * rate, 1.0, c) for d in delta]
    np.testing.assert_allclose(ours, md, rtol=1e-12, atol=1e-12)  # same formula, round-off only
    # full stiffness at the turning point: dT/ddelta = k_t (finite difference, relative step 1e-7)
    e = 1e-7 * dstar
    assert (lim * tc.md_force_ratio(e * rate, 1.0, c) + lim) / e == pytest.approx(k, rel=1e-6)
    # held in gross slip and at the turning point
    assert tc.md_branch_rate(1.0, 2.0, 1.0, k, lim, 0.0) == 0.0
    assert tc.md_branch_rate(0.0, 2.0, -1.0, k, lim, 0.0) == 0.0


def _scipy_hysteretic(c, alpha_deg):
    """Independent time integration (scipy, in seconds) of Hertz + the hysteretic law, with the
    turning points as terminal events: returns v_t after separation."""
    m, r, inertia = c.mass, c.radius, c.moment_of_inertia
    k_h = math.sqrt(r) * c.stiffness
    f = c.friction
    alpha = math.radians(alpha_deg)
    branch = {"s": 1.0, "c": 1.0}

    def rhs(_t, z):
        x, xd, vt, wtp, p = z
        xp = max(x, 0.0)
        fn = k_h * xp**1.5
        lim = f * fn
        dlim = f * 1.5 * k_h * math.sqrt(xp) * xd
        kt = float(tc.tangential_stiffness(c.shear_modulus, math.sqrt(r * xp)))
        t = lim * tc.md_force_ratio(p, branch["s"], branch["c"])
        u = vt + r * wtp
        dp = tc.md_branch_rate(p, branch["c"], branch["s"] * u, kt, lim, dlim)
        return [xd, -fn / m, -t / m, -r * t / inertia, dp]

    def sep(_t, z):
        return z[0]

    def turn(_t, z):
        return branch["s"] * (z[2] + r * z[3])

    sep.terminal, sep.direction = True, -1
    turn.terminal, turn.direction = True, -1
    # start just inside contact (x = 1e-6 of the maximum penetration, in gross slip, p = 1)
    xmax = (1.25 * m * (V * math.cos(alpha)) ** 2 / k_h) ** 0.4
    t0, z = 0.0, [1e-6 * xmax, V * math.cos(alpha), V * math.sin(alpha), 0.0, 1.0]
    while True:
        sol = solve_ivp(rhs, (t0, 1e-3), z, method="DOP853", rtol=1e-11, atol=1e-14, events=(sep, turn))
        z, t0 = list(sol.y[:, -1]), sol.t[-1]
        if sol.t_events[0].size or sol.status == 0:
            return z[2]
        ratio = tc.md_force_ratio(z[4], branch["s"], branch["c"])
        branch["s"] = -branch["s"]
        branch["c"] = tc.md_turning_span(ratio, branch["s"])
        z[4] = 0.0


@pytest.mark.parametrize("alpha", [9.5, 20.0])  # one and two turning points... and gross slip at the start
def test_hysteretic_law_against_an_independent_scipy_integration(alumina, alpha):
    c = alumina.with_(tangential_model="mindlin_deresiewicz")
    ref = _scipy_hysteretic(c, alpha)
    res = simulate_impact(c, V, alpha, rtol=1e-10)
    # both integrations to ~1e-9; the scipy run starts at x = 1e-6 x_max (gross slip, where the
    # missed part of the impulse is ~(1e-6)^(5/2) of it) and locates turning points in seconds:
    # 1e-6 relative
    assert res.velocity_out[1] == pytest.approx(ref, rel=1e-6)
    assert res.e_n == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("k", [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0])
def test_held_turning_point_follows_the_limit_to_the_power_k(k):
    """md_held_span_rate integrated while the limit falls linearly: T = s F_lim (1 - c) must follow
    F_lim^k (closed form), until it reaches the opposite limit (c = 2), then the limit."""
    f0, c0 = 2.0, 1.5  # T starts at -F_lim / 2

    def lim(t):
        return f0 * (1.0 - t)

    sol = solve_ivp(lambda t, c: [tc.md_held_span_rate(c[0], lim(t), -f0, k)], (0.0, 0.9), [c0],
                    rtol=1e-11, atol=1e-13, dense_output=True, max_step=1e-3)
    for t in (0.2, 0.5, 0.9):
        force = lim(t) * (1.0 - sol.sol(t)[0])
        expect = max(-lim(t), -0.5 * f0 * (lim(t) / f0) ** k)  # held as F^k, bounded by the limit
        # max_step 1e-3 puts the kink where c reaches 2 within ~1e-3 F_lim
        assert force == pytest.approx(expect, abs=2e-3 * f0), (k, t)


@pytest.mark.parametrize("alpha", [0.5, 1.8, 5.0, 9.5, 20.0, 45.0])
def test_hysteretic_reference_agrees_with_the_coupled_solver(alumina, alpha):
    """The scipy integration (own state, event handling and step control) with the solvers'
    reading against the compiled coupled solver: stick and turning points at small angles, gross
    slip throughout at 45 deg."""
    c = alumina.with_(tangential_model="mindlin_deresiewicz")
    ref = hysteretic_reference(c, V, alpha, rtol=1e-11)
    res = simulate_impact(c, V, alpha, rtol=1e-10)
    vt_in = V * math.sin(math.radians(alpha))
    # both near 1e-9 relative (measured 1.7e-9 at rtol 1e-10, Kharaz angles); 2e-8 of v_t,in and of the
    # rim speed
    assert res.velocity_out[1] / vt_in == pytest.approx(ref.velocity_out[1] / vt_in, abs=2e-8)
    assert res.omega_out[2] * c.radius / vt_in == pytest.approx(ref.omega_out[2] * c.radius / vt_in, abs=2e-8)
    assert ref.e_n == pytest.approx(1.0, abs=1e-9)


@pytest.mark.parametrize("unloading", list(tc.MD_UNLOADING_EXPONENTS))
def test_hysteretic_reference_energy_balance(alumina, unloading):
    """The kinetic energy lost equals the friction work int T u dt integrated as a separate state
    (the tangential energy stored at separation is zero): both sides computed independently."""
    c = alumina.with_(tangential_model="mindlin_deresiewicz")
    for alpha in (0.5, 3.7, 20.0):
        r = hysteretic_reference(c, V, alpha, unloading=unloading, rtol=1e-12)
        ke_in = 0.5 * c.mass * V**2
        ke_out = 0.5 * c.mass * sum(v * v for v in r.velocity_out) + 0.5 * c.moment_of_inertia * r.omega_out[2] ** 2
        # in units of the incident energy; rtol 1e-12 closes the balance to ~1e-9 of the work
        assert (ke_in - ke_out) / ke_in == pytest.approx(r.dissipated_energy / ke_in, abs=1e-9)


def test_only_the_force_reading_creates_energy(alumina):
    """A stuck contact stores energy ~ T^2 / k_t ~ a^(6k - 1) as it shrinks: holding the force
    (k = 0) makes it grow. The tangential kinetic energy after the impact (translation + spin)
    exceeds the incident one at grazing incidence for k = 0 only; and the more of the force is held
    (smaller k), the more tangential speed comes back at 1.8 deg."""
    c = alumina.with_(tangential_model="mindlin_deresiewicz")

    def gain(r):
        e_in = 0.5 * c.mass * r.velocity_in[1] ** 2
        e_out = 0.5 * c.mass * r.velocity_out[1] ** 2 + 0.5 * c.moment_of_inertia * r.omega_out[2] ** 2
        return (e_out - e_in) / e_in

    for alpha in (0.1, 0.5, 1.0, 2.0, 5.0):
        gains = {u: gain(hysteretic_reference(c, V, alpha, unloading=u)) for u in tc.MD_UNLOADING_EXPONENTS}
        for u in ("limit", "rescaled_displacement", "displacement"):
            assert gains[u] < 0.0, (alpha, u, gains[u])
    assert gain(hysteretic_reference(c, V, 0.1, unloading="force")) > 0.2  # measured +0.218
    ratio = [hysteretic_reference(c, V, 1.8, unloading=u).velocity_out[1] for u in tc.MD_UNLOADING_EXPONENTS]
    assert ratio == sorted(ratio) and ratio[0] < ratio[-1] * 0.95  # limit < rescaled < displacement < force
    slide = {hysteretic_reference(c, V, 45.0, unloading=u).velocity_out[1] for u in tc.MD_UNLOADING_EXPONENTS}
    assert len(slide) == 1  # no turning point, the reading is never consulted


def test_hysteretic_reference_refuses_what_it_does_not_cover(alumina):
    c = alumina.with_(tangential_model="mindlin_deresiewicz")
    with pytest.raises(ValueError, match="zeta_hertz=0 only"):
        hysteretic_reference(c.with_(zeta_hertz=0.1), V, 10.0)
    with pytest.raises(ValueError, match="tangential_model='mindlin_deresiewicz' only"):
        hysteretic_reference(alumina, V, 10.0)
    with pytest.raises(ValueError, match="unloading must be one of limit"):
        hysteretic_reference(c, V, 10.0, unloading="held")


def test_stiff_hysteretic_contact_gives_the_rigid_closed_form(alumina):
    angles = np.array([5.0, 20.0, 45.0])
    rigid = simulate_many(alumina, V, angles)
    stiff = simulate_many(alumina.with_(tangential_model="mindlin_deresiewicz", shear_modulus=1e3 * alumina.shear_modulus),
                          V, angles)
    ratio = lambda ds: ds["velocity_out_t"].values / (V * np.sin(np.radians(angles)))  # noqa: E731
    # as for the elastic law: the energy still stored at the end of stick scales as
    # 1/sqrt(stiffness ratio), 1e-3 at 1000 x G*; sliding throughout is the same Coulomb impulse
    np.testing.assert_allclose(ratio(stiff), ratio(rigid), atol=1.5e-3)
    assert ratio(stiff)[2] == pytest.approx(ratio(rigid)[2], abs=1e-6)


def test_hysteretic_maw_barber_fawcett_shape(alumina):
    """As test_maw_barber_fawcett_shape; hysteresis only removes energy: at small psi the
    contact point comes back with less speed than with the elastic micro-slip law."""
    ratio_kt_kn = 4 * alumina.shear_modulus / (0.75 * alumina.stiffness)
    f = alumina.friction
    psi = np.array([0.05, 1.0, 5.0, 10.0])
    alpha = np.degrees(np.arctan(psi * f * 2 / ratio_kt_kn))
    u_in = V * np.sin(np.radians(alpha))
    r = {}
    for tm in ("mindlin", "mindlin_deresiewicz"):
        c = alumina.with_(tangential_model=tm)
        ds = simulate_many(c, V, alpha)
        r[tm] = (ds["velocity_out_t"] + c.radius * ds["omega_out_tp"]).values / u_in
    h = r["mindlin_deresiewicz"]
    assert 0.5 < h[0] < r["mindlin"][0]
    assert h[1] < -0.2  # recoil of the contact point near psi = 1
    rigid_line = 1 - 3.5 * f * 2 / np.tan(np.radians(alpha))
    np.testing.assert_allclose(h[2:], rigid_line[2:], atol=1e-6)  # gross sliding: solver tolerance


def test_hysteretic_kharaz_target():
    ds = kharaz_comparison(fit_friction=False, curve_incidence_deg=[10.0, 45.0],
                           contact_models={"tangential_model": "mindlin_deresiewicz"})
    # issue 14's target: within 0.03 RMS over all measured angles, material constants and the
    # source's friction (nothing fitted); measured 0.0271
    assert ds.attrs["rms_tangential_restitution_all_hysteretic"] < 0.03
    assert ds.attrs["rms_tangential_restitution_all_selected"] == ds.attrs["rms_tangential_restitution_all_hysteretic"]
    # and better than the elastic micro-slip law and the rigid model over all angles
    assert ds.attrs["rms_tangential_restitution_all_hysteretic"] < ds.attrs["rms_tangential_restitution_all"]
    assert ds.attrs["rms_tangential_restitution_all_hysteretic"] < ds.attrs["rms_tangential_restitution_all_compliant"]
    # the other readings of a held turning point (scipy integration), measured 0.038 / 0.051 / 0.064;
    # the "limit" reading of that integration reproduces the compiled solver (rtol 1e-8 each)
    rms = [ds.attrs[f"rms_tangential_restitution_all{s}"]
           for s in ("_hysteretic", "_md_rescaled_displacement", "_md_displacement", "_md_force")]
    assert rms == sorted(rms) and rms[-1] > 0.06
    assert ds.attrs["hysteretic_reference_difference"] < 1e-6


# =============================================================================== rolling resistance
def test_rolling_resistance_zero_gives_the_existing_result(alumina):
    c = alumina.with_(tangential_model="mindlin_deresiewicz")
    a = simulate_many(c, V, [5.0, 40.0])
    b = simulate_many(c.with_(rolling_friction=0.0), V, [5.0, 40.0])
    np.testing.assert_array_equal(a["velocity_out_t"].values, b["velocity_out_t"].values)
    with pytest.raises(ValueError, match="compliant tangential model"):
        check_sub_models(alumina.with_(rolling_friction=0.01), "engine")
    with pytest.raises(ValueError, match="method='engine'"):
        check_sub_models(c.with_(rolling_friction=0.01), "reference")


@pytest.mark.parametrize("model", ["mindlin", "mindlin_deresiewicz"])
def test_rolling_sphere_decelerates_at_the_analytic_rate(alumina, model):
    """A sphere arriving rolling (omega_t' = -v_t / r) keeps rolling; the torque mu_r r |F_n|
    takes (5/7) mu_r |F_n| / m off v_t, so over the impact Delta v_t = (5/7) mu_r (1 + e_n) v_n."""
    mu_r = 0.01
    c = alumina.with_(tangential_model=model, rolling_friction=mu_r, shear_modulus=1e3 * alumina.shear_modulus)
    alpha = 45.0
    vt, vn = V * math.sin(math.radians(alpha)), V * math.cos(math.radians(alpha))
    res = simulate_impact(c, V, alpha, omega=(0.0, 0.0, -vt / c.radius), rtol=1e-10)
    dv = float(tc.rolling_deceleration(mu_r, 1.0, 1.0)) * (1 + res.e_n) * vn
    assert dv == pytest.approx(5 / 7 * mu_r * 2 * vn, rel=1e-12)
    # stiff tangential contact (1000 x G*): the lag of the tangential spring behind the rolling
    # torque stores ~ (F_t / k_t) energy; measured relative error well below 1e-3
    assert vt - res.velocity_out[1] == pytest.approx(dv, rel=2e-3)
    assert res.velocity_out[1] + c.radius * res.omega_out[2] == pytest.approx(0.0, abs=1e-3 * vt)


# =============================================================================== captured, hysteretic
_CAPTURED_VARIANTS = [{}, {"rolling_friction": 0.01}, {"friction_model": "pulloff"},
                      {"friction_model": "pulloff", "rolling_friction": 0.01}]


@pytest.mark.parametrize("changes", _CAPTURED_VARIANTS, ids=lambda d: ",".join(f"{k}={v}" for k, v in d.items()) or "net")
def test_hysteretic_captured_impacts_finish(changes):
    """Captured spheres (1 m/s < the capture speed) end: the branch restarts where F_lim vanishes and
    the settle criterion (normal at rest, tangential state stuck or friction-free) is met."""
    c = WALL_1990.with_(shear_modulus=1e10, tangential_model="mindlin_deresiewicz", **changes)
    angles = np.array([0.0, 45.0, 85.0])
    ds = simulate_many(c, 1.0, angles)
    assert np.all(ds["outcome"].values == 1)
    for q in ("velocity_out_t", "omega_out_tp", "omega_out_n", "friction_impulse", "dissipated_energy"):
        assert np.all(np.isfinite(ds[q].values)), q
    # final kinetic + contact energy V(X) <= initial kinetic: dissipated >= 0, to 1e-9 of the
    # incident energy (solver rtol 1e-8 on velocities, squared; measured >= 0)
    assert np.all(ds["dissipated_energy"].values >= -1e-9 * 0.5 * c.mass)
    # normal incidence: no tangential motion at all (exact)
    assert ds["velocity_out_t"].values[0] == 0.0
    v_t0 = np.sin(np.radians(angles[1:]))
    assert np.all(ds["velocity_out_t"].values[1:] <= v_t0)  # friction only slows the centre
    if changes.get("friction_model") == "pulloff":
        # friction at rest: the sphere ends stuck, reported at its rolling mean (u = 0 exactly)
        assert np.all(ds["slip_ended"].values == 1)
        u = ds["velocity_out_t"].values + c.radius * ds["omega_out_tp"].values
        np.testing.assert_allclose(u, 0.0, atol=1e-12)  # round-off of the projection


def test_elastic_mindlin_converges_through_its_slip_changes():
    """The "mindlin" path of the coupled solver at rtol 1e-10 against its rtol-1e-12 solution (values
    below, this build). The steps end where gross slip starts and ends (events); before, a step
    across either lost order and at 10 deg v_t crept by ~5e-5 per decade of rtol (0.372557,
    0.372655, 0.372704 at rtol 1e-8, 1e-10, 1e-11). Now rtol 1e-10 is 6e-8 from rtol 1e-12
    (relative), so 1e-6 leaves room for the rounding of another build, and rtol 1e-8 is within
    5e-5 (measured 4.9e-5 at 10 deg)."""
    from microimpact.solvers.coupled import solve_coupled

    c = WALL_1990.with_(shear_modulus=1e10, tangential_model="mindlin")
    a = np.radians([0.0, 10.0, 45.0, 85.0])
    v = np.array([1.0, 3.0, 10.0, 20.0])
    converged_v_t = [0.37278455602485816, 5.1835189749590205, 19.33823892686223]
    converged_e_n = [0.5830009377398442, 0.6973413431916224, 0.3505601252800281]
    for rtol, tol in ((1e-10, 1e-6), (1e-8, 1e-4)):
        got = solve_coupled(c, (-v * np.cos(a), v * np.sin(a), 0 * a), (0 * a, 0 * a, 0 * a), np.full(4, c.friction),
                            rtol=rtol)
        assert list(got["captured"]) == [True, False, False, False]
        np.testing.assert_allclose(got["v_t"][1:], converged_v_t, rtol=tol)
        np.testing.assert_allclose(got["e_n"][1:], converged_e_n, rtol=1e-6)


@pytest.mark.parametrize("which", ["wall1990_net", "wall1990_pulloff_rolling", "kharaz"])
def test_hysteretic_sweep_finishes(which, alumina):
    """Property-style sweep: 0.05-50 m/s x 0-89 deg ends without error, with finite results and no
    energy created (dissipated >= -1e-9 of the incident energy, as above)."""
    if which == "kharaz":
        c = alumina.with_(tangential_model="mindlin_deresiewicz")
    else:
        extra = {"friction_model": "pulloff", "rolling_friction": 0.01} if which.endswith("rolling") else {}
        c = WALL_1990.with_(shear_modulus=1e10, tangential_model="mindlin_deresiewicz", **extra)
    speeds = np.geomspace(0.05, 50.0, 12)
    ds = simulate_many(c, speeds[:, None], np.linspace(0.0, 89.0, 12)[None, :])
    for q in ("e_n", "velocity_out_t", "omega_out_tp", "dissipated_energy"):
        assert np.all(np.isfinite(ds[q].values)), q
    incident = 0.5 * c.mass * speeds[:, None] ** 2
    assert np.all(ds["dissipated_energy"].values >= -1e-9 * incident)


# =============================================================================== held rolling: said when undetermined
def _held_rolling_case(index):
    """Case ``index`` of the stress sweep (seed 0) under the hysteretic law with the pulloff limit
    and rolling resistance mu_r = 0.01, and its simulate_impact arguments."""
    from microimpact.studies import stress

    case = stress.draw_cases(index + 1, seed=0)[index]
    contact = stress.contact_of(case, "mindlin_deresiewicz_pulloff_rolling")
    return contact, (case["speed"], case["incidence_deg"], case["azimuth_deg"],
                     (case["omega_n"], case["omega_t"], case["omega_tp"]))


def _tangential_speeds(res, r):
    return np.array([res.velocity_out[1], res.velocity_out[2], r * res.omega_out[1], r * res.omega_out[2]])


def test_held_rolling_that_the_tolerance_does_not_settle_is_said():
    """Case 100 (a 2.8 um sphere at 23 nm/s spinning at 100 x its rolling spin, captured and held by
    friction f = 0.126): its final rolling moves with rtol (measured v_t / v = -2775, 16620, 13016
    at rtol 1e-8, 1e-10, 1e-12): omega_r circles rest in the plane until the step budget stops the
    integration. The solver must say so (a warning and ``not_determined``), and the saying must be
    true: an independent run at rtol 1e-10 differs from the rtol-1e-8 result by more than the
    tolerance it states, HELD_ROLLING_TOLERANCE of the speed scale."""
    from microimpact.solvers import UndeterminedOutcomeWarning
    from microimpact.solvers.coupled import HELD_ROLLING_TOLERANCE

    contact, args = _held_rolling_case(100)
    with pytest.warns(UndeterminedOutcomeWarning, match="held by friction with rolling resistance"):
        res = simulate_impact(contact, *args, rtol=1e-8)
    assert res.outcome == "capture" and "error estimate" in res.not_determined
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UndeterminedOutcomeWarning)
        tight = simulate_impact(contact, *args, rtol=1e-10)
    r = contact.radius
    scale = args[0] * math.sin(math.radians(args[1])) + r * math.hypot(args[3][1], args[3][2])
    moved = np.max(np.abs(_tangential_speeds(res, r) - _tangential_speeds(tight, r)))
    assert moved > HELD_ROLLING_TOLERANCE * scale  # measured 180 x the scale
    # the batch path says how many, and which: a per-impact flag (the second impact, at 0.05 m/s, rebounds)
    with pytest.warns(UndeterminedOutcomeWarning, match="1 of 2 impacts"):
        ds = simulate_many(contact, [args[0], 0.05], args[1], args[2], args[3])
    assert ds["not_determined"].values.tolist() == [1, 0] and ds["outcome"].values.tolist() == [1, 0]
    assert ds["not_determined"].attrs["flag_meanings"] == "determined not_determined"
    assert ds.attrs["not_determined"].startswith("1 impacts: final tangential velocity and spin not settled")


def test_a_rolling_held_at_rest_within_a_step_converges_at_tight_tolerances():
    """Table 1 row 2 with Mindlin contact (G* = 0.3 K), the pulloff limit and mu_r = 0.2, captured
    at 0.05 m/s and 40 deg, ends at rest at every tolerance (v_t = 0 to 1e-4 v; measured 4e-6,
    0, 0 at rtol 1e-8, 1e-10, 1e-12). Before omega_r was set to rest within the step that the torques
    hold it in (_hold_rolling), at rtol 1e-11 and 1e-12 a stage of every step fell on the other side
    of omega_r = 0, omega_r hovered at 1e-10, and the integration stopped at its step budget at
    v_t = 0.148 v (flagged not determined, but wrong). Case 20 of the stress sweep converges too
    (v_t / v = -0.0333 at rtol 1e-10 and 1e-12; -3.14, -0.78, -2.16 before)."""
    from microimpact.model.parameters import TABLE1_ROW2

    c = TABLE1_ROW2.with_(tangential_model="mindlin", shear_modulus=0.3 * TABLE1_ROW2.stiffness,
                          friction_model="pulloff", rolling_friction=0.2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for rtol in (1e-8, 1e-11, 1e-12):
            res = simulate_impact(c, 0.05, 40.0, rtol=rtol)
            assert res.outcome == "capture" and res.not_determined == ""
            assert abs(res.velocity_out[1]) < 1e-4 * 0.05, rtol
        contact, args = _held_rolling_case(20)
        a, b = (simulate_impact(contact, *args, rtol=rtol) for rtol in (1e-10, 1e-12))
    assert a.velocity_out[1] / args[0] == pytest.approx(-0.0333, abs=5e-4)
    assert abs(a.velocity_out[1] - b.velocity_out[1]) < 1e-4 * args[0]


def test_a_failed_check_leaves_the_result_and_says_it_is_not_determined(monkeypatch):
    """If the check's second solve fails (a CoupledError), the impact still gets its result (valid
    input always does), flagged not determined with an infinite error estimate; the other impacts
    of the batch keep their own checks."""
    from microimpact.model.parameters import TABLE1_ROW2
    from microimpact.solvers import UndeterminedOutcomeWarning
    from microimpact.solvers import coupled

    c = TABLE1_ROW2.with_(tangential_model="mindlin_deresiewicz", shear_modulus=0.3 * TABLE1_ROW2.stiffness,
                          friction_model="pulloff", rolling_friction=0.01)
    v = np.array([0.05, 0.05])
    a = np.radians([40.0, 41.0])
    args = ((-v * np.cos(a), v * np.sin(a), 0 * v), (0 * v, 0 * v, 0 * v), np.full(2, c.friction))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        good = coupled.solve_coupled(c, *args, rtol=1e-8)
    assert not good["not_determined"].any() and np.all(np.isfinite(good["tangential_error"]))
    real = coupled.solve_coupled

    def failing_check(contact, velocity_in, omega_in, friction, *, rtol, max_steps=2_000_000, check_held_rolling=True):
        if not check_held_rolling and np.any(np.abs(velocity_in[1] - 0.05 * math.sin(math.radians(41.0))) < 1e-12):
            raise coupled.CoupledError("step limit reached (test)")
        return real(contact, velocity_in, omega_in, friction, rtol=rtol, max_steps=max_steps,
                    check_held_rolling=check_held_rolling)

    monkeypatch.setattr(coupled, "solve_coupled", failing_check)
    with pytest.warns(UndeterminedOutcomeWarning, match="1 of 2 impacts"):
        res = failing_check(c, *args, rtol=1e-8)
    assert list(res["not_determined"]) == [False, True] and math.isinf(res["tangential_error"][1])
    np.testing.assert_array_equal(res["v_t"], good["v_t"])  # the results stand


def test_held_rolling_that_converges_is_not_flagged():
    """The paper's microsphere (Table 1 row 2) with Mindlin-Deresiewicz contact (G* = 0.3 K), the
    pulloff limit and mu_r = 0.01, captured at 0.05 m/s and 40 deg: its rolling reverses on the
    held contact too, but converges (v_t / v = 0.301155, 0.301151 at rtol 1e-8, 1e-10, measured):
    no warning, ``not_determined`` empty, and the two tolerances agree within what it claims."""
    from microimpact.model.parameters import TABLE1_ROW2
    from microimpact.solvers.coupled import HELD_ROLLING_TOLERANCE

    c = TABLE1_ROW2.with_(tangential_model="mindlin_deresiewicz", shear_modulus=0.3 * TABLE1_ROW2.stiffness,
                          friction_model="pulloff", rolling_friction=0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a = simulate_impact(c, 0.05, 40.0, rtol=1e-8)
        b = simulate_impact(c, 0.05, 40.0, rtol=1e-10)
    assert a.outcome == "capture" and a.not_determined == "" and b.not_determined == ""
    assert a.velocity_out[1] / 0.05 == pytest.approx(0.3011, abs=2e-4)  # rolls on: not a trivial rest
    moved = np.max(np.abs(_tangential_speeds(a, c.radius) - _tangential_speeds(b, c.radius)))
    assert moved < HELD_ROLLING_TOLERANCE * 0.05 * math.sin(math.radians(40.0))


# =============================================================================== the settled state
def _rolling_at_incident_angular_momentum(c, v_t, v_tp, w_t, w_tp):
    """(v_t, v_t', omega_t, omega_t') rolling at the incident angular momentum about the contact
    point (m v_t - I omega_t' / r, m v_t' + I omega_t / r), which a force acting at the contact
    point cannot change."""
    k = c.mass * c.radius**2 / c.moment_of_inertia
    vt = (k * v_t - c.radius * w_tp) / (k + 1.0)
    vtp = (k * v_tp + c.radius * w_t) / (k + 1.0)
    return vt, vtp, vtp / c.radius, -vt / c.radius


@pytest.mark.parametrize("model", ["mindlin", "mindlin_deresiewicz"])
def test_captured_sphere_with_friction_at_rest_ends_rolling_at_its_angular_momentum(model):
    """With a friction limit at rest ("pulloff") a captured sphere ends rolling at the angular
    momentum about the contact point it came in with, and without twist: the same at every rtol.
    Before, a stuck elastic contact was reported at the phase of its vibration where the integration
    stopped (K_L up to 5e-2 apart between rtol 1e-8 and 1e-10)."""
    c = WALL_1990.with_(shear_modulus=1e10, tangential_model=model, friction_model="pulloff")
    speed, inc, az = np.array([1.0, 1.2, 2.0]), np.array([30.0, 60.0, 75.0]), np.array([0.0, 120.0, 250.0])
    w = (np.array([1e5, -2e5, 0.0]), np.array([-3e5, 0.0, 1e5]), np.array([2e5, 1e5, -1e5]))
    a, b = np.radians(inc), np.radians(az)
    v_t, v_tp = speed * np.sin(a) * np.cos(b), speed * np.sin(a) * np.sin(b)
    expected = _rolling_at_incident_angular_momentum(c, v_t, v_tp, w[1], w[2])
    for rtol in (1e-6, 1e-8, 1e-10):
        ds = simulate_many(c, speed, inc, az, w, rtol=rtol)
        assert np.all(ds["outcome"].values == 1)
        got = (ds["velocity_out_t"].values, ds["velocity_out_tp"].values,
               ds["omega_out_t"].values * c.radius, ds["omega_out_tp"].values * c.radius)
        # velocities and rim speeds r omega [m/s]: the Runge-Kutta steps keep linear invariants to
        # round-off, so 1e-12 m/s (the speeds are ~1 m/s)
        for g, e in zip(got, (expected[0], expected[1], expected[2] * c.radius, expected[3] * c.radius)):
            np.testing.assert_allclose(g, e, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(ds["omega_out_n"].values, 0.0)
        assert np.all(ds["slip_ended"].values == 1)


@pytest.mark.parametrize("rolling, reason", [(0.0, "capture"), (0.01, "settled")])
def test_captured_pulloff_impact_says_where_it_stopped(rolling, reason):
    """Without rolling resistance a captured compliant impact with the pulloff limit ends at its
    capture (past the largest penetration): nothing after it changes the result, which its
    stop_reason says; with rolling resistance the oscillation is followed until it settles."""
    c = WALL_1990.with_(tangential_model="mindlin", friction_model="pulloff", rolling_friction=rolling,
                        shear_modulus=1e10)
    res = simulate_impact(c, 0.5, 30.0, 0.0, (1e5, 0.0, 0.0))
    assert res.outcome == "capture" and res.stop_reason == reason
    assert res.capture_time < math.inf and res.max_penetration > 0.0


def test_captured_mindlin_contact_at_a_loose_tolerance_finishes():
    """At rtol 1e-6 and 1e-7 this captured Mindlin impact hit the step limit (CoupledError): the
    integration error held its oscillation at 15-40 rtol, above the fixed settle amplitude 1e-6.
    Now the settle amplitude is at least 1e3 rtol and the tail follows in closed form. 1e-3 m/s on
    the velocities and rim speeds at rtol 1e-6 against 1e-10 (measured here: 1.1e-4 and 2.8e-4;
    4e-4 over 117 captured impacts before the slip changes were located)."""
    c = WALL_1990.with_(tangential_model="mindlin", shear_modulus=1e10)
    args = (4.379709717163171, 79.51539780042283, 166.48616281071642, (-60739.49, 83466.37, -94193.93))
    ref = simulate_impact(c, *args, rtol=1e-10)
    assert ref.outcome == "capture"
    for rtol in (1e-6, 1e-7):
        got = simulate_impact(c, *args, rtol=rtol)
        assert got.outcome == "capture"
        np.testing.assert_allclose(got.velocity_out, ref.velocity_out, rtol=0, atol=1e-3)
        np.testing.assert_allclose(np.multiply(got.omega_out, c.radius), np.multiply(ref.omega_out, c.radius),
                                   rtol=0, atol=1e-3)


@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-9])
def test_every_sub_model_selection_finishes_at_any_tolerance(rtol):
    """Property sweep of the coupled solver: each tangential model x friction model x rolling
    resistance, random speeds 0.02-80 m/s (captures and rebounds), incidences 0-89.9 deg and spins
    up to 3e5 rad/s, at a loose, a middle and a tight rtol: a result for every impact, finite, and
    no energy created (dissipated >= -1e-9 of the incident energy). At rtol 1e-6 and 1e-7 captured
    Mindlin impacts used to end in the step limit."""
    rng = np.random.default_rng(11)
    n = 40
    speed = np.exp(rng.uniform(np.log(0.02), np.log(80.0), n))
    inc, az = rng.uniform(0.0, 89.9, n), rng.uniform(0.0, 360.0, n)
    w = tuple(rng.normal(0.0, 3e5, n) for _ in range(3))
    for model, friction, mu_r in [("rigid", "pulloff", 0.0), ("mindlin", "net", 0.0), ("mindlin", "pulloff", 0.01),
                                  ("mindlin_deresiewicz", "net", 0.01), ("mindlin_deresiewicz", "pulloff", 0.0)]:
        c = WALL_1990.with_(tangential_model=model, friction_model=friction, rolling_friction=mu_r, shear_modulus=1e10)
        ds = simulate_many(c, speed, inc, az, w, rtol=rtol)
        for q in ("e_n", "K_L", "velocity_out_t", "omega_out_tp", "omega_out_n", "dissipated_energy"):
            assert np.all(np.isfinite(ds[q].values)), (model, friction, q)
        incident = 0.5 * c.mass * speed**2 + 0.5 * c.moment_of_inertia * sum(x**2 for x in w)
        assert np.all(ds["dissipated_energy"].values >= -1e-9 * incident), (model, friction)
        assert 0 < int(np.sum(ds["outcome"].values == 1)) < n  # both outcomes are exercised


@pytest.mark.parametrize("case", [
    (5.120989775476088, 41.0423805833474, 204.95180149856506, (-77586.41806462026, -67684.8711981814, -48221.98341320109)),
    (6.26935337612752, 18.515442171505104, 13.809345099300675, (134493.4251735448, 881.6112855536344, -88898.5623834793)),
])
def test_hysteretic_rebound_converges_through_the_zeros_of_the_coulomb_limit(case):
    """Two rebounds of the hysteretic law whose v_t jumped by 3e-5 and 1.4e-5 m/s between
    tolerances: a root of F_lim found a rounding error short of the zero was found again and again
    (up to 56 restarts), or a step with the zero inside was accepted without a restart. Now the
    error falls with rtol: within 100 rtol x speed of rtol 1e-12 (measured 1.5e-8 m/s at rtol 1e-9,
    4e-9 at 1e-10)."""
    c = WALL_1990.with_(tangential_model="mindlin_deresiewicz", shear_modulus=1e10)
    speed, inc, az, w = case
    ref = simulate_impact(c, speed, inc, az, w, rtol=1e-12)
    assert ref.outcome == "rebound"
    for rtol in (1e-9, 1e-10):
        got = simulate_impact(c, speed, inc, az, w, rtol=rtol)
        np.testing.assert_allclose(got.velocity_out, ref.velocity_out, rtol=0, atol=100 * rtol * speed)


# =============================================================================== rolling to rest
@pytest.mark.parametrize("model", ["mindlin", "mindlin_deresiewicz"])
@pytest.mark.parametrize("friction", ["net", "pulloff"])
def test_rolling_resistance_brings_rolling_to_rest_without_chatter(model, friction):
    """A sphere arriving rolling at 1/20 of the rolling decrement (5/7) mu_r (1 + e_n) v_n: the
    torque stops the rolling early in the impact and then holds it (set-valued at rest). Before,
    the torque flipped at every crossing of omega_r = 0: 184,000 steps at rtol 1e-8 and the
    2,000,000-step limit (CoupledError) at 1e-10 for the elastic model; now a few thousand."""
    from microimpact.solvers.coupled import solve_coupled

    c = WALL_1990.with_(tangential_model=model, friction_model=friction, rolling_friction=0.01, shear_modulus=1e13)
    vn = 20.0
    vt = 0.05 * (5 / 7) * 0.01 * 2 * vn
    for rtol in (1e-8, 1e-10):
        r = solve_coupled(c, (np.array([-vn]), np.array([vt]), 0.0), (0.0, 0.0, np.array([-vt / c.radius])),
                          np.array([0.3]), rtol=rtol)
        assert not r["captured"][0]
        # at rest: what is left is the lag of the stiff tangential spring (1000 x a typical G*),
        # measured <= 1.3e-4 vt at both tolerances
        assert abs(r["v_t"][0]) < 1e-3 * vt
        assert abs(r["omega_tp"][0] * c.radius) < 1e-3 * vt
        assert r["omega_t"][0] == 0.0  # no torque about the other axis ever acts
        # the stiff spring's vibration while held costs steps (measured <= 6,400, against ~140
        # without rolling resistance); chattering cost 184,000 and more
        assert r["n_steps"][0] < 20_000


@pytest.mark.parametrize("friction", ["net", "pulloff"])
def test_hysteretic_rolling_to_rest_converges(friction):
    """The same impact with a compliant contact (G 1e10 Pa): the spring's recoil after the rolling
    stopped sends the sphere back (v_t ~ -0.4 of the incident). The hysteretic law converges:
    rtol 1e-9 and 1e-11 agree to 3e-4 of the incident speed (measured: v_t 2e-5, r omega_t' 1.2e-4;
    the difference falls about fourfold per decade of rtol)."""
    from microimpact.solvers.coupled import solve_coupled

    c = WALL_1990.with_(tangential_model="mindlin_deresiewicz", friction_model=friction, rolling_friction=0.01,
                        shear_modulus=1e10)
    vn = 20.0
    vt = 0.05 * (5 / 7) * 0.01 * 2 * vn
    got = [solve_coupled(c, (np.array([-vn]), np.array([vt]), 0.0), (0.0, 0.0, np.array([-vt / c.radius])),
                         np.array([0.3]), rtol=rtol) for rtol in (1e-9, 1e-11)]
    for q, scale in (("v_t", 1.0), ("omega_tp", c.radius)):
        assert got[0][q][0] * scale == pytest.approx(got[1][q][0] * scale, abs=3e-4 * vt)
    assert got[1]["v_t"][0] < -0.3 * vt


# --------------------------------------------------------------------------- strong and weak damping
def _energy_residual(contact, r):
    """(KE_in - KE_out - dissipated - final contact energy) / the case's energy scale. [-]"""
    def ke(v, w):
        return 0.5 * contact.mass * float(np.dot(v, v)) + 0.5 * contact.moment_of_inertia * float(np.dot(w, w))
    ke_in = ke(r.velocity_in, r.omega_in)
    scale = max(ke_in, abs(r.final_contact_energy))
    return (ke_in - ke(r.velocity_out, r.omega_out) - r.dissipated_energy - r.final_contact_energy) / scale


@pytest.mark.parametrize("tangential", ["mindlin", "mindlin_deresiewicz"])
@pytest.mark.parametrize("friction_model", ["net", "pulloff"])
@pytest.mark.parametrize("weak", [False, True])
@pytest.mark.parametrize("zeta_h, zeta_a, speed", [(1e6, 0.0, 0.05), (0.0, 1e6, 2e-5)])
def test_compliant_contact_finishes_strongly_and_weakly_damped_captures(tangential, friction_model, zeta_h, zeta_a,
                                                                         speed, weak):
    """The coupled solver reached its step limit on strongly damped captures (zeta 1e6: ~C^2 steps
    of creep) and on weakly damped ones (case 25 of the stress sweep's seed 0: a 2 um/s impact whose
    damping rate is 7e-6 of the contact's, whose oscillation outlives the budget). Now the
    first stops where the engine's creeping test holds and the second after a twentieth of the
    budget, with the engine's closed-form tails; a capture, finite outputs and a closed energy
    balance (the tangential map conserves it to round-off)."""
    from microimpact import Contact

    if weak:
        c = Contact.from_work_of_adhesion(1.765e-05, 1423.0, 1.057e10, 0.001217, zeta_adhesion=0.05325, friction=0.3,
                                          tangential_model=tangential, friction_model=friction_model,
                                          shear_modulus=1.6e9)
        r = simulate_impact(c, 1.991e-06, 73.83, 143.4)
    else:
        c = WALL_1990.with_(tangential_model=tangential, friction_model=friction_model, shear_modulus=1e10,
                            zeta_hertz=zeta_h, zeta_adhesion=zeta_a, friction=0.3)
        r = simulate_impact(c, speed, 30.0, omega=(10.0, 20.0, -30.0))
    assert r.outcome == "capture"
    assert np.all(np.isfinite(r.velocity_out)) and np.all(np.isfinite(r.omega_out))
    assert _energy_residual(c, r) == pytest.approx(0.0, abs=1e-8)


@pytest.mark.parametrize("index", [123, 255])
@pytest.mark.parametrize("tangential, friction_model", [("mindlin", "net"), ("mindlin_deresiewicz", "net"),
                                                        ("mindlin", "pulloff")])
def test_undamped_slow_compliant_impact_rebounds_elastically(index, tangential, friction_model):
    """Undamped adhesive impacts of the stress sweep (seed 0, cases 123 and 255: 7 nm and 3 um
    spheres, normal speeds giving y0 ~ 1e-5 and 4e-7 of the speed scale). Their normal motion
    does not feel the tangential state, so it is the rigid contact's: an elastic rebound (e_n = 1)
    after the engine's contact time. The coupled solver ran into its step limit (round-off of
    rtol x the well's depth trapped the sphere); with the normal energy held it rebounds."""
    from microimpact.studies import stress

    case = stress.draw_cases(300, seed=0)[index]
    c = stress.contact_of(case, "mindlin").with_(tangential_model=tangential, friction_model=friction_model)
    args = (case["speed"], case["incidence_deg"], case["azimuth_deg"], (case["omega_n"], case["omega_t"], case["omega_tp"]))
    r = simulate_impact(c, *args, rtol=1e-10)
    rigid = simulate_impact(c.with_(tangential_model="rigid", friction_model="net"), *args, rtol=1e-10)
    assert r.outcome == rigid.outcome == "rebound"
    assert r.e_n == 1.0
    assert r.contact_time == pytest.approx(rigid.contact_time, rel=1e-7, abs=0.0)


# ------------------------------------------------------------------ frictionless captures
@pytest.mark.parametrize("model", ["mindlin", "mindlin_deresiewicz"])
def test_a_frictionless_captured_sphere_keeps_its_tangential_motion(model):
    """f = 0 with the pulloff limit: no tangential force acts, so a captured sphere keeps its
    tangential velocity and its spin exactly (the closed form of a held sphere, rolling at its
    angular momentum about the contact point, was applied to it until 2026-11-28)."""
    from microimpact.model.parameters import TABLE1_ROW2 as c

    c = c.with_(tangential_model=model, shear_modulus=0.3 * c.stiffness, friction_model="pulloff", friction=0.0)
    v, angle, omega = 0.05, 30.0, (50.0, -300.0, 1000.0)
    r = simulate_impact(c, v, angle, 0.0, omega)
    assert r.outcome == "capture"
    v_t = v * math.sin(math.radians(angle))
    # nondimensional: velocities in units of v_t, spins in units of 1000 rad/s; round-off only
    assert np.array(r.velocity_out[1:]) / v_t == pytest.approx([1.0, 0.0], abs=1e-12)
    assert np.array(r.omega_out) / 1000.0 == pytest.approx(np.array(omega) / 1000.0, abs=1e-12)


@pytest.mark.parametrize("model", ["mindlin", "mindlin_deresiewicz"])
def test_rolling_resistance_of_a_frictionless_captured_tail_does_not_depend_on_where_it_stops(model, monkeypatch):
    """Rolling resistance under the pulloff friction with f = 0: the rim speed falls by
    k mu_r int |F_n| dt over the whole captured oscillation. The integration stops at a settle
    amplitude and the tail's part follows in closed form (coupled._rolling_tail), so the final
    spin must not depend on that amplitude. Measured: 1e-2 and 1e-6 of the equilibrium give rim
    speeds 1.4e-4 apart (relative to the final one), where leaving the tail out gives 0.34;
    the tolerance, 1e-3, is the linear tail's error from an amplitude of 1e-2 (first order) with
    a margin of 7."""
    from microimpact.model.parameters import TABLE1_ROW2 as c
    from microimpact.solvers import coupled

    c = c.with_(tangential_model=model, shear_modulus=0.3 * c.stiffness, friction_model="pulloff", friction=0.0,
                rolling_friction=0.01)
    rims = []
    for settle in (1e-2, 1e-6):
        monkeypatch.setattr(coupled, "SETTLE_AMPLITUDE", settle)
        r = simulate_impact(c, 0.05, 40.0, 0.0, (0.0, 0.0, 2e4), rtol=1e-10)
        assert r.outcome == "capture"
        rims.append(c.radius * np.array(r.omega_out[1:]))
    w0, w1 = c.radius * 2e4, np.hypot(*rims[1])
    assert 0.01 < w1 / w0 < 0.95  # slowed, not stopped: the test can see the tail
    assert rims[0] / w1 == pytest.approx(rims[1] / w1, abs=1e-3)
