"""What to measure next (issue 54): the recommended impacts narrow the named parameter more than a
uniform design of the same size -- by the Fisher computation and by a refit of simulated data --,
never lie where the parameter has no effect, and come as a template that reads back."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from pypdf import PdfReader

from microimpact.analysis.design import (FRICTION_RANGE, OBLIQUE_ANGLES_DEG, DesignSpace, design_friction,
                                         design_impacts, design_next_impacts, design_record, fisher_widths,
                                         restitution_sensitivities, tangential_sensitivities, uniform_design)
from microimpact.analysis.fitting import FitProblem, fit_damping, model_restitution
from microimpact.analysis.oblique import fit_friction, normal_impulses, rebound_state
from microimpact.analysis.posterior import sample_posterior
from microimpact.cli import main
from microimpact.io import default_materials_path, read_impacts, read_materials
from microimpact.report.pdf import build_report

#: the hidden truth of the simulations: Table 1 row 2 of the paper (zeta_H, zeta_A, w_A)
TRUTH = {"zeta_hertz": 0.5, "zeta_adhesion": 29.0, "work_of_adhesion": 0.215834}
RADIUS = 3.45e-6  # [m], Table 1
SIGMA = 0.02  # [-] standard uncertainty of every simulated e_n
START_SPEEDS = (1.6, 2.5, 4.0, 8.0)  # [m/s] the starting design: few rebounds, zeta_H loosely determined


@pytest.fixture(scope="module")
def material():
    return read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]


def _simulate(material, radius, speed, rng):
    """e_n from the toolkit's solver at TRUTH plus Gaussian noise SIGMA, clipped to [0, 1]."""
    e = model_restitution(FitProblem.from_arrays(radius, speed, material), TRUTH["zeta_hertz"], TRUTH["zeta_adhesion"],
                          TRUTH["work_of_adhesion"])
    return np.clip(e + rng.normal(0.0, SIGMA, e.size), 0.0, 1.0)


def _fit(material, radius, speed, e_n):
    table = pd.DataFrame({"radius": radius, "normal_speed": speed, "e_n": e_n, "e_n_uncertainty": SIGMA})
    return fit_damping(table, material, confidence_intervals=False)


@pytest.fixture(scope="module")
def start_fit(material):
    rng = np.random.default_rng(54)
    r = np.full(len(START_SPEEDS), RADIUS)
    v = np.array(START_SPEEDS)
    return _fit(material, r, v, _simulate(material, r, v, rng))


#: the simulated speeds are exact (speed_sigma 0), so the new points weigh 1 / SIGMA^2
SPACE = DesignSpace(radii=(RADIUS,), speed_range=(0.5, 20.0), e_n_sigma=SIGMA, speed_sigma=0.0, n_speeds=25)


def test_fisher_widths_match_the_gauss_markov_variance_of_a_straight_line():
    # e = a + b x with sigma = 1 at x = -1, 1: var(b) = 1/2, so the 95 % width of b = 1 is 2 * 1.96 / sqrt(2)
    g = np.array([[1.0, -1.0], [1.0, 1.0]])
    w = fisher_widths(g.T @ g, {"a": 1.0, "b": 1.0}, ("a", "b"))
    assert w["b"] == pytest.approx(2 * 1.959964 / np.sqrt(2), rel=1e-6, abs=0)


def test_design_narrows_zeta_hertz_more_than_uniform_by_fisher(start_fit, material):
    d = design_impacts(start_fit, SPACE, 6, parameters=("zeta_hertz",))
    assert "Fisher information" in d.criterion
    # zeta_H of these four impacts is only bounded above: the design linearises inside the bound
    assert start_fit.identifiability["zeta_hertz"].status == "upper_bound"
    assert 0 < d.values["zeta_hertz"] < start_fit.identifiability["zeta_hertz"].upper
    # the widths recomputed here from the sensitivities, independently of the design's table
    varied = ("zeta_hertz", "zeta_adhesion")

    def information(radius, speed, sigma):
        _, g, _ = restitution_sensitivities(material, radius, speed, d.values, varied)
        return (g / np.asarray(sigma)[:, None]).T @ (g / np.asarray(sigma)[:, None])

    data = start_fit.data
    m0 = np.diag([1e-2, 1e-2]) + information(data["radius"], data["normal_speed"], data["sigma"])  # weak prior sd 10
    uni = uniform_design(SPACE, 6)
    new = np.full(6, SIGMA)
    w_uni = fisher_widths(m0 + information(uni["radius"], uni["normal_speed"], new), d.values, varied)["zeta_hertz"]
    w_rec = fisher_widths(m0 + information(d.rows["radius"], d.rows["normal_speed"], new), d.values, varied)["zeta_hertz"]
    assert w_rec == pytest.approx(d.width("zeta_hertz"), rel=1e-6, abs=0)
    assert w_uni == pytest.approx(d.width("zeta_hertz", which="uniform"), rel=1e-6, abs=0)
    assert w_rec < 0.9 * w_uni  # at least 10 % narrower, the design's purpose


def test_never_recommends_captured_impacts_for_zeta_hertz(material):
    d = design_impacts(None, SPACE, 8, parameters=("zeta_hertz",), prior={"zeta_hertz": (0.1, 2.0),
                                                                           "zeta_adhesion": (10.0, 80.0)},
                       material=material)
    e = model_restitution(FitProblem.from_arrays(d.rows["radius"], d.rows["normal_speed"], material), *d.values.values())
    assert np.all(e > 0)  # the solver says each recommended impact rebounds at the design's values
    # and the space does hold captured speeds (so the test can fail): the lowest candidate is captured
    assert model_restitution(FitProblem.from_arrays([RADIUS], [0.5], material), *d.values.values())[0] == 0.0
    assert "no impact is recommended where it has no effect" in d.notes["zeta_hertz"]


def test_friction_gets_a_note_not_rows(start_fit):
    space = DesignSpace(radii=(RADIUS,), speed_range=(2.0, 20.0), incidence_deg=(0.0, 60.0), n_speeds=5)
    d = design_impacts(start_fit, space, 3, parameters=("friction",))
    assert len(d.rows) == 0 and "slide" in d.notes["friction"] and "60-60 deg" in d.notes["friction"]


def test_design_narrows_zeta_hertz_more_than_uniform_on_a_refit(start_fit, material):
    n = 6
    d = design_impacts(start_fit, SPACE, n, parameters=("zeta_hertz",))
    uni = uniform_design(SPACE, n)
    widths = {}
    for name, rows in (("design", d.rows), ("uniform", uni)):
        rng = np.random.default_rng(7)  # the same noise draws for both designs
        r = np.concatenate([start_fit.data["radius"], rows["radius"]])
        v = np.concatenate([start_fit.data["normal_speed"], rows["normal_speed"]])
        e = np.concatenate([start_fit.data["e_n"], _simulate(material, rows["radius"], rows["normal_speed"], rng)])
        st = _fit(material, r, v, e).identifiability["zeta_hertz"]
        widths[name] = st.upper - st.lower
        assert st.lower <= TRUTH["zeta_hertz"] <= st.upper
    assert widths["design"] < widths["uniform"]


def test_template_reads_back_once_filled_in(tmp_path, start_fit, capsys):
    fit = tmp_path / "fit.nc"
    start_fit.save(fit)
    out = tmp_path / "design.csv"
    assert main(["design", str(fit), "--n", "3", "--speeds", "0.5:20", "--n-speeds", "12", "--out", str(out)]) == 0
    assert "Fisher information" in capsys.readouterr().out
    template = pd.read_csv(out)
    assert template["e_n [1]"].isna().all()
    template["e_n [1]"] = 0.5  # the laboratory's measurement
    filled = tmp_path / "filled.csv"
    template.to_csv(filled, index=False)
    back = read_impacts(filled)
    assert list(back["id"]) == list(template["id"])
    assert np.allclose(back["radius"], RADIUS, rtol=1e-6) and np.allclose(back["e_n"], 0.5)


@pytest.mark.parametrize("option, value, words", [
    ("--speeds", "20:0.5", "--speeds"), ("--speeds", "fast", "--speeds"), ("--radii", "3e-6,x", "--radii"),
    ("--parameters", "zeta_x", "--parameters"), ("--angles", "95", "--angles"), ("--out", "d.txt", "--out")])
def test_cli_refuses_bad_options(tmp_path, start_fit, capsys, option, value, words):
    fit = tmp_path / "fit.nc"
    start_fit.save(fit)
    args = ["design", str(fit), "--n", "2", option, str(tmp_path / value) if option == "--out" else value]
    if option != "--out":
        args += ["--out", str(tmp_path / "d.csv")]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fit.nc"]  # nothing written


def test_cli_refuses_a_file_that_is_not_a_fit(tmp_path, capsys):
    bad = tmp_path / "notafit.nc"
    bad.write_text("x")
    assert main(["design", str(bad), "--out", str(tmp_path / "d.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "notafit.nc" in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notafit.nc"]


# --------------------------------------------------------------------------- friction (oblique designs)
#: the oblique space of the friction tests: the design's default angles, 2-20 m/s
OBLIQUE = DesignSpace(radii=(RADIUS,), speed_range=(2.0, 20.0), incidence_deg=OBLIQUE_ANGLES_DEG, n_speeds=6,
                      e_t_sigma=SIGMA)


def _contact(material, friction=0.3):
    return material.contact(RADIUS).with_(zeta_hertz=TRUTH["zeta_hertz"], zeta_adhesion=TRUTH["zeta_adhesion"],
                                          friction=friction)


def test_tangential_sensitivity_is_the_sliding_impulse_and_zero_when_rolling(material):
    # sliding throughout, v_t,out = v_t,in - f J / m (Cheng, Brach & Dunn 2002, Eqs. (16)-(20)), so
    # d e_t / d ln f = -f J / (m v_t,in); once the sphere ends rolling e_t = 5/7 and does not move
    c = _contact(material)
    speed, angle = np.array([10.0, 10.0]), np.array([75.0, 20.0])
    imp = normal_impulses(c, speed, angle)
    _, e_t, g = tangential_sensitivities(c, speed, angle, [0.3])
    expected = -0.3 * imp["friction_impulse"][0] / (c.mass * imp["velocity_in_t"][0])
    assert g[0, 0] == pytest.approx(expected, rel=1e-6, abs=0)  # linear in f: only rounding
    assert e_t[0, 0] == pytest.approx(1 + expected, rel=1e-9, abs=0)
    assert e_t[1, 0] == pytest.approx(5 / 7, rel=1e-9, abs=0) and g[1, 0] == 0.0


def test_friction_design_only_picks_impacts_that_slide_for_some_f(material):
    d = design_friction(None, OBLIQUE, 6, material=material, values=TRUTH)
    assert d.parameters == ("friction",) and len(d.rows) == 6
    # checked with the solver's rebound map, not the design's sensitivities: at the range's smallest
    # f each recommended impact rebounds and still slides (e_t above the rolling 5/7)
    out = rebound_state(_contact(material, FRICTION_RANGE[0]), d.rows["speed"].to_numpy(),
                        d.rows["incidence_deg"].to_numpy(), np.zeros(6))
    e_t = out["velocity_out_t"] / (d.rows["speed"] * np.sin(np.radians(d.rows["incidence_deg"])))
    assert not out["captured"].any() and np.all(e_t > 5 / 7 + 1e-6)
    # and the design reaches the top of the range: some impact slides at f = 1 (steep angles)
    top = rebound_state(_contact(material, FRICTION_RANGE[1]), d.rows["speed"].to_numpy(),
                        d.rows["incidence_deg"].to_numpy(), np.zeros(6))
    assert np.any(top["velocity_out_t"] / (d.rows["speed"] * np.sin(np.radians(d.rows["incidence_deg"]))) > 5 / 7 + 1e-6)
    assert d.width("friction") < d.width("friction", 0)


def test_friction_design_refuses_a_space_where_everything_rolls(material):
    space = DesignSpace(radii=(RADIUS,), speed_range=(5.0, 20.0), incidence_deg=(5.0,), n_speeds=3)
    with pytest.raises(ValueError, match="steeper incidence angles"):
        design_friction(None, space, 2, material=material, values=TRUTH)


def _oblique_table(material, friction, rows, rng):
    speed, angle = rows["speed"].to_numpy(float), rows["incidence_deg"].to_numpy(float)
    out = rebound_state(_contact(material, friction), speed, angle, np.zeros(speed.size))
    return pd.DataFrame({"radius": RADIUS, "speed": speed, "incidence_deg": angle,
                         "e_n": out["velocity_out_n"] / (speed * np.cos(np.radians(angle))),
                         "tangential_restitution": out["velocity_out_t"] / (speed * np.sin(np.radians(angle)))
                         + rng.normal(0.0, SIGMA, speed.size), "tangential_restitution_uncertainty": SIGMA})


def test_friction_design_determines_f_where_the_start_does_not(start_fit, material):
    rng = np.random.default_rng(3)
    start = _oblique_table(material, 0.3, pd.DataFrame({"speed": [8.0, 12.0, 16.0], "incidence_deg": [10.0, 20.0, 30.0]}),
                           rng)
    before = fit_friction(start, start_fit, propagate_damping=False).identifiability["friction"]
    assert not before.determined  # every start impact ends rolling at f = 0.3
    d = design_friction(start_fit, OBLIQUE, 4, existing=start)
    after = fit_friction(pd.concat([start, _oblique_table(material, 0.3, d.rows, rng)]), start_fit,
                         propagate_damping=False).identifiability["friction"]
    assert after.determined and after.lower <= 0.3 <= after.upper


def test_friction_template_reads_back_once_filled_in(tmp_path, start_fit, capsys):
    fit = tmp_path / "fit.nc"
    start_fit.save(fit)
    out = tmp_path / "design.csv"
    assert main(["design", str(fit), "--parameters", "zeta_hertz,friction", "--n", "2", "--n-friction", "3",
                 "--n-speeds", "8", "--speeds", "2:20", "--out", str(out)]) == 0
    assert "slides throughout" in capsys.readouterr().out
    t = pd.read_csv(out)
    assert len(t) == 5 and (t["incidence_angle [deg]"] > 0).sum() == 3
    t["e_n [1]"] = 0.5
    t.loc[t["incidence_angle [deg]"] > 0, "tangential_restitution [1]"] = 0.8
    filled = tmp_path / "filled.csv"
    t.to_csv(filled, index=False)
    back = read_impacts(filled)
    assert list(back["id"]) == list(t["id"])
    assert np.allclose(back["tangential_restitution"].to_numpy()[t["incidence_angle [deg]"].to_numpy() > 0], 0.8)


def test_cli_without_a_command_lists_design(capsys):
    assert main([]) == 2
    err = capsys.readouterr().err
    assert "design" in err and "lammps" in err


def test_report_has_the_design_page(tmp_path, start_fit):
    # the page the pipeline's design rule feeds (its JSON, made here in-process), in the PDF report
    space = DesignSpace(radii=(RADIUS,), speed_range=(0.5, 20.0), e_n_sigma=SIGMA, n_speeds=12)
    d = design_next_impacts(start_fit, space, 3, ("zeta_hertz", "friction"), n_friction=2)
    record = json.loads(json.dumps(design_record(d, space, source="fit.nc")))  # what the rule writes and the page reads
    pdf = PdfReader(build_report(tmp_path / "report.pdf", {"fit": start_fit.to_dataset(), "design": record}))
    page = next(t for t in (p.extract_text() for p in pdf.pages) if "What to measure next" in t and "Criterion" in t)
    assert "design-001" in page and "design-005" in page
    assert "zeta_hertz" in page and "friction" in page  # the notes of both named parameters
    assert "recommended" in page and "uniform" in page  # the width figure's caption


@pytest.mark.extended
def test_design_from_a_posterior_uses_its_covariance(tmp_path, start_fit, material, capsys):
    # a short chain (an illustration, not converged): its sample covariance of ln zeta is M_0
    table = pd.DataFrame({"radius": RADIUS, "normal_speed": np.array(START_SPEEDS),
                          "e_n": start_fit.data["e_n"].to_numpy(), "e_n_uncertainty": SIGMA})
    post = sample_posterior(table, start_fit, walkers=8, steps=60, require_convergence=False, seed=5)
    d = design_impacts(start_fit, SPACE, 3, posterior=post)
    assert post.names == ("zeta_hertz", "zeta_adhesion")
    # every parameter sampled: the width now is 2 z sd(ln zeta_H) zeta_H of the samples
    now = 2 * 1.959964 * np.std(np.log(post.samples[:, 0]), ddof=1) * d.values["zeta_hertz"]
    assert d.width("zeta_hertz", 0) == pytest.approx(now, rel=1e-5, abs=0)  # the posterior's spread, not the fit's
    assert d.values["zeta_hertz"] == pytest.approx(float(np.median(post.samples[:, 0])), rel=1e-12, abs=0)
    fit, pf = tmp_path / "fit.nc", tmp_path / "post.nc"
    start_fit.save(fit)
    post.save(pf)
    assert main(["design", str(fit), "--posterior", str(pf), "--n", "2", "--n-speeds", "8"]) == 0
    assert main(["design", str(fit), "--posterior", str(fit), "--n", "2"]) == 2  # a fit is not a posterior
    assert "not a posterior" in capsys.readouterr().err
