"""LAMMPS's twisting laws ``twisting sds`` and ``twisting marshall`` (microimpact.model.dem_twisting)
in the DEM tangential solver (microimpact.solvers.dem_tangential).

Independent checks, none through the solver's own constants: a twist that slides throughout loses
mu_twist int F_n0 dt / I (Coulomb's law; for Hertz without damping int F dt = 2 m v, and Marshall's
int a F dt by quadrature over the energy integral of the Hertz impact); a twist that sticks
throughout is a damped torsional oscillator with its closed-form solution over the contact time;
the torque of one LAMMPS evaluation from its source (gran_sub_mod_twisting.cpp). LAMMPS itself:
tests/test_lammps.py.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from microimpact import Contact
from microimpact.io.lammps import lammps_input, lammps_wall_model, read_lammps_contact
from microimpact.model.dem_twisting import lammps_marshall_twisting_coefficients, lammps_twisting_torque
from microimpact.solvers.impact import simulate_impact

SPHERE = {"radius": 1e-6, "density": 2000.0, "stiffness": 1e9, "adhesion_line_force": 0.0}
MINDLIN = {"friction": 0.3, "tangential_model": "lammps_mindlin", "shear_modulus": 3e8}
SDS = {"twisting_model": "lammps_sds", "twisting_stiffness": 1e-13}


def _twist_ratio(contact, speed, omega_n, incidence=0.0):
    return simulate_impact(contact, speed, incidence, omega=(omega_n, 0.0, 0.0)).omega_out[0] / omega_n


# ------------------------------------------------------------------ one evaluation (LAMMPS's code)
def test_inside_the_limit_the_torque_is_the_spring_and_dashpot():
    m, xi = lammps_twisting_torque(0.002, -3.0, 1e-12, 1e-16, 1e-14)
    assert float(m) == pytest.approx(-1e-12 * 0.002 + 1e-16 * 3.0, rel=1e-15, abs=0)
    assert float(xi) == 0.002


def test_beyond_the_limit_the_torque_opposes_the_twist_rate_even_against_the_spring():
    # the spring unwinding (xi < 0 pushes Omega > 0) faster than the limit: LAMMPS's torque is
    # -limit sgn(Omega), of the other sign than the trial torque, and the history is reset to
    # (limit sgn(Omega) - gamma Omega) / k
    k, gamma, limit = 1e-12, 1e-16, 1e-15
    m, xi = lammps_twisting_torque(-0.01, 2.0, k, gamma, limit)
    assert -k * -0.01 - gamma * 2.0 > limit  # the trial torque is positive, beyond the limit
    assert float(m) == -limit
    assert float(xi) == pytest.approx((limit - gamma * 2.0) / k, rel=1e-14, abs=0)


def test_marshall_coefficients_are_half_k_a2_half_eta_a2_and_two_thirds_a_mu():
    a, k_t, eta_t, mu = 2e-8, 700.0, 3e-7, 0.4
    k, g, m = lammps_marshall_twisting_coefficients(a, k_t, eta_t, mu)
    assert (k, g, m) == pytest.approx((700.0 * 4e-16 / 2, 3e-7 * 4e-16 / 2, 2.0 * 2e-8 * 0.4 / 3), rel=1e-14, abs=0)


# ------------------------------------------------------------------ whole impacts, closed forms
@pytest.mark.parametrize("speed, omega_n", [(1.0, 1e7), (0.3, -5e6)])
def test_a_twist_sliding_throughout_loses_mu_twist_times_the_normal_impulse(speed, omega_n):
    # Hertz, no damping (e_n = 1): int F_n0 dt = 2 m v; the twist slides all through (large spin)
    mu_tw = 1e-9
    c = Contact(**SPHERE, **MINDLIN, **SDS, twisting_friction=mu_tw)
    loss = (1.0 - _twist_ratio(c, speed, omega_n)) * omega_n * c.moment_of_inertia
    # the tolerance: the spin is integrated to 1e-10 of itself, 1e-8 of this loss
    assert loss / (math.copysign(1.0, omega_n) * mu_tw * 2.0 * c.mass * speed) == pytest.approx(1.0, rel=1e-7, abs=0)


def test_marshall_sliding_throughout_loses_two_thirds_mu_int_a_f_dt():
    # Hertz, no damping: F = K sqrt(r) d^1.5, a = sqrt(r d); int a F dt = 2 int_0^d_max a F / v dd with
    # v(d) from the energy, m v^2 / 2 = m v0^2 / 2 - (2/5) K sqrt(r) d^2.5; d = d_max (1 - u^2) takes
    # the 1 / sqrt at the turning point out of the quadrature
    c = Contact(**SPHERE, **MINDLIN, twisting_model="lammps_marshall")
    speed, omega_n = 1.0, 1e6
    m, r, k = c.mass, c.radius, c.stiffness * math.sqrt(c.radius)
    d_max = (1.25 * m * speed**2 / k) ** 0.4

    def integrand(u):  # a F / v dd/du; d_max^2.5 - d^2.5 = d_max^2.5 (1 - (1 - u^2)^2.5), without cancellation
        d = d_max * (1.0 - u * u)
        if u == 0.0:
            u_over_v = 1.0 / math.sqrt(2.0 * k / m * d_max**2.5)
        else:
            u_over_v = u / math.sqrt(0.8 * k / m * d_max**2.5 * -math.expm1(2.5 * math.log1p(-u * u)))
        return math.sqrt(r * d) * k * d**1.5 * 2.0 * d_max * u_over_v

    impulse_moment = 2.0 * quad(integrand, 0.0, 1.0, epsabs=0, epsrel=1e-12, limit=200)[0]
    expected = 2.0 / 3.0 * c.friction * impulse_moment / c.moment_of_inertia
    ratio = _twist_ratio(c, speed, omega_n)
    assert ratio > 0.5  # slid throughout (it would stop, ratio 0, otherwise)
    assert (1.0 - ratio) * omega_n / expected == pytest.approx(1.0, rel=1e-7, abs=0)


@pytest.mark.parametrize("gamma", [0.0, 1e-19])
def test_a_twist_stuck_throughout_is_a_damped_torsional_oscillator(gamma):
    # DMT: F_n0 = F_po > 0 from touch, and a limit of 1 m * F_n0 never slides. I xi'' + gamma xi' + k xi = 0
    # with xi(0) = 0, Omega(0) = Omega_0: Omega(t) = Omega_0 exp(-alpha t) (cos w_d t - alpha / w_d sin w_d t)
    c = Contact.from_work_of_adhesion(1e-6, 2000.0, 1e9, 0.01, normal_model="dmt", **MINDLIN, twisting_model="lammps_sds",
                                      twisting_stiffness=1e-10, twisting_damping=gamma, twisting_friction=1.0)
    r = simulate_impact(c, 1.0, 0.0, omega=(1e4, 0.0, 0.0))
    assert r.outcome == "rebound"
    inertia, k = c.moment_of_inertia, 1e-10
    alpha = gamma / (2.0 * inertia)
    w_d = math.sqrt(k / inertia - alpha**2)
    t = r.contact_time
    assert w_d * t > 3.0  # several radians of oscillation in the contact
    expected = math.exp(-alpha * t) * (math.cos(w_d * t) - alpha / w_d * math.sin(w_d * t))
    # the contact time carries the normal solve's error (~1e-9): the phase w_d t moves by less than 1e-8
    assert r.omega_out[0] / 1e4 == pytest.approx(expected, rel=0, abs=1e-7)


def test_the_twisting_law_leaves_the_slip_and_the_rolling_alone():
    c = Contact(**SPHERE, **MINDLIN, **SDS, twisting_friction=1e-8)
    free = c.with_(twisting_model="none", twisting_stiffness=None, twisting_friction=0.0)
    a = simulate_impact(c, 2.0, 40.0, omega=(3e5, 1e4, -2e4))
    b = simulate_impact(free, 2.0, 40.0, omega=(3e5, 1e4, -2e4))
    assert a.velocity_out == b.velocity_out and a.omega_out[1:] == b.omega_out[1:]
    assert b.omega_out[0] == 3e5 and abs(a.omega_out[0] - 3e5) > 1e3


def test_a_captured_sphere_stops_twisting_and_a_sphere_without_twist_gets_none():
    c = Contact.from_work_of_adhesion(1e-6, 2000.0, 1e9, 0.05, normal_model="jkr_force", **MINDLIN, **SDS,
                                      twisting_friction=1e-8)
    captured = simulate_impact(c, 0.01, 0.0, omega=(1e5, 0.0, 0.0))
    assert captured.outcome == "capture" and captured.omega_out[0] == 0.0
    assert simulate_impact(c, 2.0, 30.0).omega_out[0] == 0.0


def test_a_sliding_twist_stopped_while_the_limit_falls_stays_stopped():
    # Marshall on Hertz, a slow twist: the slide stops during the unloading, where the limit 2 a mu F / 3
    # falls faster than a stuck spring can follow: the spin ends at 0 (LAMMPS: 2e-6, 1e-11 at 2000, 8000
    # steps per contact, tests/test_lammps.py)
    c = Contact(**SPHERE, **MINDLIN, twisting_model="lammps_marshall")
    assert _twist_ratio(c, 1.0, 1e4) == 0.0


# ------------------------------------------------------------------ parameters and export
@pytest.mark.parametrize("changes, named", [
    ({"twisting_model": "lammps_sds"}, "twisting_stiffness"),
    ({"twisting_stiffness": 1e-13}, "twisting_stiffness"),
    ({"twisting_model": "lammps_marshall", "twisting_friction": 1e-8}, "twisting_friction"),
    ({"twisting_damping": 1e-20}, "twisting_damping"),
    ({"twisting_model": "lammps_sds", "twisting_stiffness": -1.0}, "twisting_stiffness"),
])
def test_twisting_parameters_out_of_place_are_refused_by_name(changes, named):
    with pytest.raises(ValueError, match=named):
        Contact(**SPHERE, **MINDLIN, **changes)


def test_a_twisting_law_needs_a_dem_tangential_law():
    with pytest.raises(ValueError, match="tangential_model='rigid'"):
        Contact(**SPHERE, twisting_model="lammps_marshall")


def test_twisting_sds_is_written_in_the_units_of_its_coefficients():
    c = Contact(**SPHERE, **MINDLIN, **(SDS | {"twisting_damping": 2e-21, "twisting_friction": 3e-8}))
    # k_twist a torque: 1 N m = 1e7 erg (cgs), 1e15 pg um^2 / us^2 (micro); gamma_twist a torque x time:
    # 1 N m s = 1e7 erg s, 1e21 (micro); mu_twist a length: 1 m = 100 cm, 1e6 um
    assert lammps_wall_model(c).granular_args("si").endswith(" twisting sds 1e-13 2e-21 3e-08")
    assert lammps_wall_model(c).granular_args("cgs").endswith(" twisting sds 1e-06 2e-14 3e-06")
    assert lammps_wall_model(c).granular_args("micro").endswith(" twisting sds 100 2 0.03")
    assert read_lammps_contact(lammps_input(c))[0] == c


def test_marshall_is_written_by_name_and_not_without_friction():
    c = Contact(**SPHERE, **MINDLIN, twisting_model="lammps_marshall")
    assert lammps_wall_model(c).granular_args().endswith(" twisting marshall")
    # without friction the limit 2 a mu / 3 is 0 and LAMMPS's tangential law is linear_nohistory: nothing
    assert "twisting" not in lammps_wall_model(c.with_(friction=0.0)).granular_args()
    assert _twist_ratio(c.with_(friction=0.0), 1.0, 1e5) == 1.0


def test_lammps_fit_refuses_twisting_options_out_of_place_with_status_2(tmp_path, capsys):
    from microimpact.cli import main

    data = tmp_path / "impacts.csv"
    data.write_text("speed [m/s],e_n [1]\n1.0,0.5\n")
    base = ["lammps", "fit", str(data), "--material-pair", "ammonium_fluorescein_on_silicon", "--out",
            str(tmp_path / "c.lmp")]
    for extra, named in [(["--tangential-model", "lammps_mindlin", "--shear-modulus", "1e9", "--twisting-model",
                           "lammps_sds"], "--twisting-stiffness"),
                         (["--tangential-model", "lammps_mindlin", "--shear-modulus", "1e9", "--twisting-friction",
                           "1e-8"], "--twisting-friction"),
                         (["--twisting-model", "lammps_marshall"], "--twisting-model")]:
        assert main(base + extra) == 2
        err = capsys.readouterr().err
        assert named in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "c.lmp").exists()
