"""Every stated uncertainty is used, and correlated where one error enters twice (issue 51 item 4).

* The reader: e_n = v_r / v_n, e_t = v_t,out / v_t,in and the rebound angle from every stated
  uncertainty; the incident and rebound speed errors independent (SPEED_CORRELATION = 0, why: the
  module docstring of microimpact.io.impacts) and :func:`ratio_uncertainty` for a known correlation,
  checked against a Monte Carlo of correlated normal draws (independent of the formula).
* The fit: where e_n was derived from the two speeds, the incident-speed error moves the measured
  e_n and the model together; the effective sigma counts it once, correlated, checked against a
  Monte Carlo through the engine itself.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from microimpact.analysis.fitting import FitProblem, _effective_sigma, _SpeedErrors, model_restitution
from microimpact.dynamics.nonlinear import capture_velocity
from microimpact.io import default_materials_path, read_impacts, read_materials
from microimpact.io.impacts import SPEED_CORRELATION, ratio_uncertainty


def _write(tmp_path, text):
    p = tmp_path / "t.csv"
    p.write_text(text)
    return p


@pytest.mark.parametrize("rho", [-0.5, 0.0, 0.6, 1.0])
def test_ratio_uncertainty_against_a_monte_carlo(rho):
    """sd of a / b over 400,000 correlated normal draws (relative errors 1-2 %, where first order holds
    to ~1e-4) within 1 % of the formula (the Monte Carlo's own error on an sd is 0.11 %)."""
    rng = np.random.default_rng(51)
    a, sa, b, sb = 0.6, 0.012, 1.5, 0.02
    cov = [[sa**2, rho * sa * sb], [rho * sa * sb, sb**2]]
    x = rng.multivariate_normal([a, b], cov, size=400_000)
    assert float(ratio_uncertainty(a, sa, b, sb, rho)) == pytest.approx(np.std(x[:, 0] / x[:, 1]), rel=0.01)


def test_ratio_uncertainty_limits():
    assert SPEED_CORRELATION == 0.0
    assert float(ratio_uncertainty(0.6, 0.02, 1.0, 0.02)) == pytest.approx(math.hypot(0.02, 0.6 * 0.02), rel=1e-14)
    # fully correlated with equal relative errors: the ratio is exact (a common scale cancels)
    assert float(ratio_uncertainty(0.6, 0.006, 1.0, 0.01, 1.0)) == pytest.approx(0.0, abs=1e-15)
    assert math.isnan(float(ratio_uncertainty(0.6, math.nan, 1.0, math.nan)))
    assert float(ratio_uncertainty(0.6, math.nan, 1.5, 0.03)) == pytest.approx(0.6 * 0.03 / 1.5**2, rel=1e-14)
    with pytest.raises(ValueError, match=r"correlation must lie in \[-1, 1\]"):
        ratio_uncertainty(0.6, 0.02, 1.0, 0.02, 1.5)


def test_both_speed_uncertainties_give_e_n_and_either_alone_too(tmp_path):
    text = ("radius [um],normal_speed [m/s],rebound_normal_speed [m/s],normal_speed_uncertainty [m/s],"
            "rebound_normal_speed_uncertainty [m/s]\n3,2.0,1.0,0.04,0.03\n3,2.0,1.0,,0.03\n3,2.0,1.0,0.04,\n3,2.0,1.0,,\n")
    s = read_impacts(_write(tmp_path, text))["e_n_uncertainty"].to_numpy()
    np.testing.assert_allclose(s[:3], [math.hypot(0.03 / 2, 1.0 * 0.04 / 4), 0.03 / 2, 1.0 * 0.04 / 4], rtol=1e-14)
    assert math.isnan(s[3])


def test_oblique_columns_use_every_stated_uncertainty(tmp_path):
    """e_t = v_t / (v sin a) with only the rebound tangential speed's uncertainty stated: st / v_t,in
    (the incident speed and angle then exact; was NaN); the rebound angle with only one of its two
    speeds' uncertainties: that speed's term alone; a given e_t's uncertainty gives the rebound
    tangential speed's without an incident-speed uncertainty."""
    text = ("radius [um],speed [m/s],incidence_angle [deg],rebound_normal_speed [m/s],rebound_tangential_speed [m/s],"
            "rebound_tangential_speed_uncertainty [m/s],rebound_normal_speed_uncertainty [m/s]\n"
            "3,2.0,30,0.5,0.5,0.02,\n3,2.0,30,0.5,0.5,,0.03\n")
    df = read_impacts(_write(tmp_path, text))
    vt_in = 2.0 * math.sin(math.radians(30))
    assert df["tangential_restitution_uncertainty"].iloc[0] == pytest.approx(0.02 / vt_in, rel=1e-12)
    h2 = 0.5**2 + 0.5**2
    np.testing.assert_allclose(df["rebound_angle_deg_uncertainty"],
                               np.degrees([0.5 * 0.02 / h2, 0.5 * 0.03 / h2]), rtol=1e-12)
    text = ("radius [um],speed [m/s],incidence_angle [deg],e_n [1],tangential_restitution [1],"
            "tangential_restitution_uncertainty [1]\n3,2.0,30,0.5,0.4,0.05\n")
    df = read_impacts(_write(tmp_path, text))
    assert df["rebound_tangential_speed_uncertainty"].iloc[0] == pytest.approx(vt_in * 0.05, rel=1e-12)


def test_effective_sigma_of_a_derived_e_n_against_a_monte_carlo():
    """One row at 1.3 v_c (steep e_n(v)) whose e_n = v_r / v_n: sd of model(v + dv) - (v_r + dr)/(v + dv)
    over 20,000 draws of independent normal dv (1 %), dr, through the engine, within 3 % of the
    effective sigma with the correlation (MC error on an sd ~0.5 %; first order at 1 % speed
    error ~1 %); the sigma without the cross term is off by more than 10 % here."""
    material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    p = {"zeta_hertz": 0.5, "zeta_adhesion": 29.0, "work_of_adhesion": 0.215834}
    r0 = 3.45e-6
    problem = FitProblem.from_arrays([r0], [1.0], material)
    vc = capture_velocity(problem.contact(r0, p["zeta_hertz"], p["zeta_adhesion"], p["work_of_adhesion"]))
    v = 1.3 * vc
    problem = FitProblem.from_arrays([r0], [v], material)
    e = float(model_restitution(problem, *p.values())[0])
    sv, sr = 0.01 * v, 0.01 * e * v
    sigma_e = ratio_uncertainty(e * v, sr, v, sv)
    eff = float(_effective_sigma(problem, p, np.atleast_1d(sigma_e), _SpeedErrors(np.array([sv]), np.array([e / v])),
                                 1e-8)[0])
    plain = float(_effective_sigma(problem, p, np.atleast_1d(sigma_e), _SpeedErrors(np.array([sv])), 1e-8)[0])
    rng = np.random.default_rng(4)
    dv, dr = sv * rng.standard_normal(20_000), sr * rng.standard_normal(20_000)
    many = FitProblem.from_arrays(np.full(dv.size, r0), v + dv, material)
    resid = model_restitution(many, *p.values()) - (e * v + dr) / (v + dv)
    assert eff == pytest.approx(np.std(resid), rel=0.03)
    assert abs(plain / np.std(resid) - 1) > 0.10
