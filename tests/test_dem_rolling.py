"""LAMMPS's rolling resistance ``rolling sds`` (microimpact.model.dem_rolling) in the DEM
tangential solver (microimpact.solvers.dem_tangential).

Independent checks: an impact on which both springs slide throughout has impulses fixed by the two
limits (Coulomb's law, no integration); a rolling limit far below the tolerance leaves the impact
of the law without rolling; the kinematics of v_rl and the torque from the definitions (Wang et al.
2015, Eq. 31, LAMMPS's granular_model.cpp). LAMMPS itself: tests/test_lammps.py.
"""

import math

import numpy as np
import pytest

from microimpact import Contact
from microimpact.model.dem_rolling import lammps_rolling_force, lammps_rolling_torque, lammps_rolling_velocity
from microimpact.solvers.dem_tangential import DemTangentialError
from microimpact.solvers.impact import simulate_impact, simulate_many

SPHERE = {"radius": 1e-6, "density": 2000.0, "stiffness": 1e9, "adhesion_line_force": 0.0}
MINDLIN = {"tangential_model": "lammps_mindlin", "shear_modulus": 3e8}
SDS = {"rolling_model": "lammps_sds", "rolling_stiffness": 50.0, "rolling_damping": 2e-7}


def test_rolling_velocity_is_the_speed_of_the_contact_point_of_a_sphere_rolling_without_slip():
    # rolling forward without slip: v_t = -R omega_t' (microimpact's n into the wall, t' = n x t), and
    # the contact point's velocity v + omega x (R n) is then 0; v_rl is the speed of the contact
    r, v_t = 2e-6, 0.3
    omega = np.array([0.0, 0.0, -v_t / r])
    n, t, tp = np.eye(3)
    assert np.allclose(np.array([0.0, v_t, 0.0]) + np.cross(omega, r * n), 0.0, rtol=0.0, atol=1e-15)
    w = lammps_rolling_velocity(r, omega[1], omega[2])
    assert w[0] == pytest.approx(v_t, rel=1e-15, abs=0.0) and w[1] == 0.0
    # and LAMMPS's v_rl = R omega x n_w, n_w = -n, for a spin about t
    w = lammps_rolling_velocity(r, 1e5, 0.0)
    assert np.allclose(w, (r * np.cross([0.0, 1e5, 0.0], -n))[1:], rtol=1e-15, atol=0.0)


def test_the_rolling_torque_slows_the_rolling():
    # d v_rl / dt = R (d omega / dt) x n_w with I d omega / dt the torque: R^2 / I F_r
    r, inertia = 1e-6, 0.4 * 8e-15 * 1e-12
    f = np.array([-3e-9, 1e-9])
    torque = lammps_rolling_torque(r, f)
    rate = r * np.cross(torque / inertia, [-1.0, 0.0, 0.0])
    assert np.allclose(rate[1:] / (r * r / inertia * f), 1.0, rtol=1e-14, atol=0.0)


def test_the_sds_spring_slides_at_its_limit_and_keeps_the_elastic_part_as_history():
    f, xi = lammps_rolling_force([2e-9, 0.0], [1.0, 0.0], 100.0, 5e-8, 1e-7)
    # trial -100 * 2e-9 - 5e-8 * 1 = -2.5e-7 N, over the limit 1e-7: scaled to it; xi = -(F + gamma w) / k
    assert f[0] == pytest.approx(-1e-7, rel=1e-14, abs=0.0) and f[1] == 0.0
    assert xi[0] == pytest.approx(-(-1e-7 + 5e-8) / 100.0, rel=1e-14, abs=0.0)
    # LAMMPS's special case: over the limit with no history, no force
    f, xi = lammps_rolling_force([0.0, 0.0], [1.0, 0.0], 100.0, 5e-8, 1e-9)
    assert (f == 0.0).all() and (xi == 0.0).all()


@pytest.mark.parametrize("mu, mu_r", [(0.1, 0.1), (0.05, 0.2)])
def test_both_springs_sliding_throughout_give_the_impulses_of_their_limits(mu, mu_r):
    # Hertz without damping: F_n0 = F_n, so the friction impulse is mu J_n against the slip and the
    # rolling pseudo-impulse mu_r J_n against the rolling, with J_n = m v_n (1 + e_n). Top-spin at
    # 70 deg: slip backwards (v_t - v_rl < 0) and rolling forwards, neither reverses in the contact.
    # (5e-9: the event location at the default tolerance, 5e-7 at rtol 1e-8 per the solver's docs,
    # is not involved here; what is left is the integration's ~1e-10 relative)
    c = Contact(**SPHERE, friction=mu, **MINDLIN, **SDS, rolling_friction=mu_r)
    speed, angle, spin = 2.0, 70.0, -3e6
    res = simulate_impact(c, speed, angle, omega=(0.0, 0.0, spin))
    v_n, v_t = speed * math.cos(math.radians(angle)), speed * math.sin(math.radians(angle))
    r, m, inertia = c.radius, c.mass, c.moment_of_inertia
    j_n = m * v_n * (1.0 + res.e_n)
    w_in = -r * spin
    j, j_r = mu * j_n, -mu_r * j_n  # slip < 0: friction along +t; rolling > 0: pseudo-force along -t
    assert v_t - w_in < 0.0
    expected_v = v_t + j / m
    expected_w = w_in + r * r / inertia * (j_r - j)
    assert expected_w > 0.0 and expected_v - expected_w < 0.0  # neither reversed: sliding throughout holds
    assert (res.velocity_out[1] - expected_v) / speed == pytest.approx(0.0, abs=5e-9)
    assert (-r * res.omega_out[2] - expected_w) / speed == pytest.approx(0.0, abs=5e-9)
    assert res.velocity_out[2] == 0.0 and res.omega_out[1] == 0.0  # planar stays planar


@pytest.mark.parametrize("omega", [(0.0, 0.0, 3e5), (0.0, 0.0, -2e6), (0.0, 0.0, 0.0), (0.0, 2e5, -1e5)])
def test_a_rolling_limit_far_below_the_tolerance_changes_nothing(omega):
    # the solver drops a law whose largest effect is below its tolerance; a limit just above it is
    # integrated, and must agree with the law without rolling to its effect (mu_r 1e-9 at rtol 1e-8..1e-10)
    plain = Contact(**SPHERE, friction=0.3, **MINDLIN)
    base = simulate_impact(plain, 2.0, 30.0, omega=omega)
    for mu_r, bound in ((1e-13, 0.0), (1e-9, 1e-7)):
        if bound == 0.0:
            res = simulate_impact(plain.with_(**SDS, rolling_friction=mu_r), 2.0, 30.0, omega=omega)
            assert res.velocity_out == base.velocity_out and res.omega_out == base.omega_out
        elif omega[1] != 0.0:  # across the slip a limit this small is the solver's documented failure
            with pytest.raises(DemTangentialError):
                simulate_impact(plain.with_(**SDS, rolling_friction=mu_r), 2.0, 30.0, omega=omega)
        else:
            res = simulate_impact(plain.with_(**SDS, rolling_friction=mu_r), 2.0, 30.0, omega=omega)
            assert np.allclose(res.velocity_out, base.velocity_out, rtol=0.0, atol=bound * 2.0)
            assert np.allclose(np.array(res.omega_out) * plain.radius, np.array(base.omega_out) * plain.radius,
                               rtol=0.0, atol=bound * 2.0)


def test_rolling_resistance_takes_spin_out_that_friction_alone_leaves():
    # JKR, 0.7 m/s, 20 deg, no incident spin: the friction's torque spins the sphere up; the rolling
    # law resists it, so |omega| out is smaller, and v_t larger (less of the tangential momentum
    # goes into rolling)
    jkr = Contact.from_work_of_adhesion(radius=1e-6, density=2000.0, stiffness=1e9, work_of_adhesion=0.02,
                                        normal_model="jkr_force", friction=0.3, **MINDLIN)
    free = simulate_impact(jkr, 0.7, 20.0)
    held = simulate_impact(jkr.with_(**SDS, rolling_friction=0.1), 0.7, 20.0)
    assert abs(held.omega_out[2]) < abs(free.omega_out[2])
    assert held.velocity_out[0] == free.velocity_out[0]  # the normal motion does not feel it


def test_rolling_across_the_slip_is_solved_alike_at_two_tolerances():
    # spin about t as well as t': the rolling velocity has a part across the slip, the 2-D case
    # (Radau); the outcome moves by the tolerance's order between rtol 1e-8 and 1e-10
    c = Contact(**SPHERE, friction=0.3, **MINDLIN, **SDS, rolling_friction=0.1)
    a = simulate_impact(c, 2.0, 5.0, omega=(0.0, 2e5, -1e5), rtol=1e-8)
    b = simulate_impact(c, 2.0, 5.0, omega=(0.0, 2e5, -1e5), rtol=1e-10)
    assert a.velocity_out[2] != 0.0 and a.omega_out[1] != 0.0
    assert np.allclose(a.velocity_out, b.velocity_out, rtol=0.0, atol=2e-9 * 2.0)
    assert np.allclose(np.array(a.omega_out) * c.radius, np.array(b.omega_out) * c.radius, rtol=0.0, atol=2e-9 * 2.0)


def test_a_captured_sphere_ends_at_rest_when_both_limits_hold_it():
    jkr = Contact.from_work_of_adhesion(radius=1e-6, density=2000.0, stiffness=1e9, work_of_adhesion=0.02,
                                        normal_model="jkr_force", friction=0.3, **MINDLIN, **SDS, rolling_friction=0.1)
    res = simulate_impact(jkr, 0.01, 30.0, omega=(0.0, 0.0, 2e4))
    assert res.outcome == "capture"
    assert res.velocity_out[1] == 0.0 and res.omega_out[2] == 0.0


@pytest.mark.parametrize("changes, named", [
    ({"rolling_stiffness": 50.0}, "rolling_stiffness"),
    ({"rolling_model": "lammps_sds"}, "rolling_stiffness"),
    ({"rolling_damping": 1e-7}, "rolling_damping"),
    ({"rolling_model": "lammps_sds", "rolling_stiffness": 50.0, "tangential_model": "rigid"}, "tangential_model='rigid'"),
    ({"rolling_friction": 0.1}, "rolling_model='lammps_sds'"),
])
def test_rolling_parameters_out_of_place_are_refused_by_name(changes, named):
    with pytest.raises(ValueError, match=named):
        Contact(**SPHERE, friction=0.3, **(MINDLIN | changes))


@pytest.mark.slow  # 20 s or more: `pytest -m slow` (README, Tests), not the default run
def test_lammps_fit_holds_a_given_rolling_law_while_it_fits_mu_and_writes_both(tmp_path, capsys, monkeypatch):
    # data made with LAMMPS's rolling sds beside mindlin: 'lammps fit' given the same rolling law fits
    # mu around the true 0.3 and writes 'rolling sds' with the given values; rolling options without
    # --rolling-stiffness, or without --tangential-model, are refused with status 2, nothing written
    import pandas as pd

    from microimpact.analysis.dem_fit import dem_law_contact
    from microimpact.cli import main
    from microimpact.io.materials import read_materials

    pair = read_materials()["ammonium_fluorescein_on_silicon"]
    rng = np.random.default_rng(5)
    base = dem_law_contact(pair, 2e-6, "hertz", "coeff_restitution", 0.6)
    c = base.with_(friction=0.3, tangential_model="lammps_mindlin", shear_modulus=1e9, rolling_model="lammps_sds",
                   rolling_stiffness=200.0, rolling_damping=0.0, rolling_friction=0.2)
    speed, angle = np.geomspace(0.3, 10.0, 8), np.linspace(10.0, 60.0, 8)
    e_t = [simulate_impact(c, v, a).velocity_out[1] / (v * math.sin(math.radians(a))) for v, a in zip(speed, angle)]
    monkeypatch.chdir(tmp_path)
    pd.DataFrame({"material_pair": "ammonium_fluorescein_on_silicon", "radius [um]": 2.0, "speed [m/s]": speed,
                  "incidence_angle [deg]": angle, "e_n [1]": 0.6 + rng.normal(0.0, 0.01, 8), "e_n_uncertainty [1]": 0.01,
                  "tangential_restitution [1]": np.array(e_t) + rng.normal(0.0, 0.01, 8),
                  "tangential_restitution_uncertainty [1]": 0.01}).to_csv("impacts.csv", index=False)
    argv = ["lammps", "fit", "impacts.csv", "--material-pair", "ammonium_fluorescein_on_silicon", "--law",
            "hertz+coeff_restitution", "--tangential-model", "lammps_mindlin", "--shear-modulus", "1e9",
            "--twisting-model", "lammps_sds", "--twisting-stiffness", "1e-12", "--twisting-friction", "3e-8",
            "--rolling-stiffness", "200", "--rolling-friction", "0.2", "--out", "contact.lmp"]
    assert main(argv) == 0
    text = (tmp_path / "contact.lmp").read_text()
    # a twisting law given with it is written beside it (it changes neither e_n nor e_t: not fitted)
    assert text.splitlines()[-1].split(" twisting sds ")[1].split()[:3] == ["1e-12", "0", "3e-08"]
    friction_line = text.split("# fitted friction: ")[1]  # the damping's line states a 95 % interval too
    low, high = (float(x) for x in friction_line.split("95% profile-likelihood interval ")[1].split(";")[0].split(" to "))
    assert low < 0.3 < high
    assert text.splitlines()[-1].split(" rolling sds ")[1].split()[:3] == ["200", "0", "0.2"]
    capsys.readouterr()
    assert main(argv[:-6] + ["--rolling-friction", "0.2", "--out", "c2.lmp"]) == 2  # no --rolling-stiffness
    assert "give --rolling-stiffness too" in capsys.readouterr().err
    assert main(argv[:7] + ["--rolling-stiffness", "200", "--out", "c3.lmp"]) == 2  # no --tangential-model
    assert "give --tangential-model too" in capsys.readouterr().err
    assert not (tmp_path / "c2.lmp").exists() and not (tmp_path / "c3.lmp").exists()


@pytest.mark.parametrize("omega", [(0.0, 0.0, 0.0), (0.0, 0.0, -2e6), (0.0, 2e5, -1e5)])
def test_rolling_sds_with_its_default_mu_roll_0_is_the_law_without_rolling(omega):
    # LAMMPS's rolling sds limits its force to mu_roll F_n0 (model.dem_rolling): with mu_roll 0, its
    # documented default, that force is 0 at every step, so the impact is the tangential law's alone,
    # to the bit (it crashed: TypeError in solvers.dem_tangential, issue 55)
    plain = Contact(**SPHERE, friction=0.3, **MINDLIN)
    sds = plain.with_(rolling_model="lammps_sds", rolling_stiffness=50.0, rolling_damping=2e-7)
    assert sds.rolling_friction == 0.0
    base, res = (simulate_impact(c, 2.0, 30.0, omega=omega) for c in (plain, sds))
    assert res.velocity_out == base.velocity_out and res.omega_out == base.omega_out
    assert base.omega_out != (0.0, 0.0, 0.0)  # the friction's torque acts, so a dropped tangential law would show


def test_rolling_sds_with_mu_roll_0_runs_in_a_batch_and_when_captured():
    jkr = Contact.from_work_of_adhesion(radius=1e-6, density=2000.0, stiffness=1e9, work_of_adhesion=0.02,
                                        normal_model="jkr_force", friction=0.3, **MINDLIN)
    sds = jkr.with_(rolling_model="lammps_sds", rolling_stiffness=50.0)
    batch = simulate_many(sds, [0.01, 0.7], 30.0)
    plain = simulate_many(jkr, [0.01, 0.7], 30.0)
    assert list(batch["outcome"].values) == [1, 0]  # capture, rebound (the outcome codes of simulate_many)
    np.testing.assert_array_equal(batch["velocity_out_t"].values, plain["velocity_out_t"].values)
