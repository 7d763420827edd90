"""What to measure next, issue 54: several size classes, the measurable oblique columns (e_n only,
rebound angle, rebound spin) and the command line's ranges.

The oblique sensitivities are checked against closed forms of the sliding impact (Cheng, Brach &
Dunn 2002, Eqs. (16)-(20), no incident spin): while the sphere slides throughout the contact,
v_t,out = v_t,in - f J / m and |omega_out| = 5 f J / (2 m R), so 1 - e_t and |omega_out| are both
proportional to f: d e_t / d ln f = -(1 - e_t) and d |omega| / d ln f = |omega|; the rebound angle
theta = atan(v_t,out / v_n,out) follows by the chain rule.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from pypdf import PdfReader

from microimpact.analysis.design import (DesignSpace, design_friction, design_impacts, design_next_impacts,
                                         design_record, design_template, tangential_sensitivities, uniform_design)
from microimpact.analysis.fitting import fit_damping
from microimpact.cli import main
from microimpact.io import default_materials_path, read_impacts, read_materials
from microimpact.io.materials import material_contact
from microimpact.report.design import _rows_table
from microimpact.report.pdf import build_report

VALUES = {"zeta_hertz": 0.5, "zeta_adhesion": 29.0}  # Table 1 row 2
RADII = (1.29e-6, 3.45e-6, 10.0e-6)  # [m] three size classes
#: 60 deg at 10 m/s slides throughout for f = 0.1 (tests/test_design.py's doctest of the same impact)
SPEED, ANGLE = np.array([10.0, 15.0]), np.array([60.0, 70.0])


@pytest.fixture(scope="module")
def material():
    return read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]


@pytest.fixture(scope="module")
def start_fit(material):
    # four rebounds at one size class (e_n of the solver at Table 1 row 2, rounded): a loose zeta_H
    table = pd.DataFrame({"radius": 3.45e-6, "normal_speed": [2.0, 4.0, 8.0, 16.0], "e_n": [0.3, 0.55, 0.68, 0.7],
                          "e_n_uncertainty": 0.02})
    return fit_damping(table, material, confidence_intervals=False)


def test_sliding_sensitivities_match_the_closed_forms(material):
    c = material_contact(material, 3.45e-6, **VALUES)
    f = [0.1]
    _, e_t, g_t = tangential_sensitivities(c, SPEED, ANGLE, f)
    _, w, g_w = tangential_sensitivities(c, SPEED, ANGLE, f, quantity="rebound_spin")
    e_n, th, g_th = tangential_sensitivities(c, SPEED, ANGLE, f, quantity="rebound_angle")
    assert np.all(g_t < 0)  # both slide throughout at f = 0.1
    # central difference of a function linear in f, step 1e-4 in ln f: error O(1e-8) relative
    assert g_t[:, 0] == pytest.approx(-(1.0 - e_t[:, 0]), rel=1e-6, abs=0)
    assert g_w[:, 0] == pytest.approx(w[:, 0], rel=1e-6, abs=0)
    vt_in, vn_out = SPEED * np.sin(np.radians(ANGLE)), e_n * SPEED * np.cos(np.radians(ANGLE))
    vt_out = e_t[:, 0] * vt_in
    assert th[:, 0] == pytest.approx(np.degrees(np.arctan2(vt_out, vn_out)), rel=1e-12, abs=0)
    chain = np.degrees(vn_out * vt_in * g_t[:, 0] / (vn_out ** 2 + vt_out ** 2))
    assert g_th[:, 0] == pytest.approx(chain, rel=1e-5, abs=0)


def test_rolling_impacts_carry_no_information_in_any_column(material):
    c = material_contact(material, 3.45e-6, **VALUES)
    for q in ("tangential_restitution", "rebound_angle", "rebound_spin"):
        _, _, g = tangential_sensitivities(c, SPEED, ANGLE, [1.0], quantity=q)  # f = 1: both end rolling
        assert np.all(g == 0), q


def test_e_n_only_refuses_friction_and_says_so(material, start_fit, tmp_path, capsys):
    space = DesignSpace(radii=(3.45e-6,), speed_range=(2.0, 20.0), incidence_deg=(0.0, 60.0), n_speeds=4,
                        oblique_quantity="none")
    with pytest.raises(ValueError, match="e_n only"):
        design_friction(None, space, 2, material=material, values=VALUES)
    d = design_impacts(start_fit, space, 2, parameters=("zeta_hertz", "friction"))
    assert "measures e_n only" in d.notes["friction"]
    fit = tmp_path / "fit.nc"
    start_fit.save(fit)
    assert main(["design", str(fit), "--parameters", "zeta_hertz,friction", "--measure", "none",
                 "--out", str(tmp_path / "d.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--measure none" in err[0]
    assert not (tmp_path / "d.csv").exists()


@pytest.mark.parametrize("quantity, column, value", [("rebound_angle", "rebound_angle [deg]", 40.0),
                                                     ("rebound_spin", "rebound_spin [rad/s]", 2.0e5)])
def test_template_of_each_column_reads_back_once_filled_in(tmp_path, start_fit, capsys, quantity, column, value):
    fit = tmp_path / "fit.nc"
    start_fit.save(fit)
    out = tmp_path / "design.csv"
    assert main(["design", str(fit), "--parameters", "zeta_hertz,friction", "--n", "1", "--n-friction", "2",
                 "--n-speeds", "6", "--speeds", "2,20", "--measure", quantity, "--out", str(out)]) == 0
    assert quantity.replace("_", " ") in capsys.readouterr().out  # the criterion names what is measured
    t = pd.read_csv(out)
    oblique = t["incidence_angle [deg]"].to_numpy() > 0
    assert column in t.columns and oblique.sum() == 2
    assert t[column.replace(" [", "_uncertainty [")].notna().to_numpy().tolist() == oblique.tolist()
    t["e_n [1]"] = 0.5
    t.loc[oblique, column] = value
    filled = tmp_path / "filled.csv"
    t.to_csv(filled, index=False)
    back = read_impacts(filled)
    name = "rebound_angle_deg" if quantity == "rebound_angle" else quantity
    assert list(back["id"]) == list(t["id"])
    got = back[name].to_numpy()[oblique]
    assert got == pytest.approx(np.full(2, value), rel=1e-6, abs=0)  # [deg] or [rad/s], as written


def test_several_size_classes_are_candidates_and_named(material):
    space = DesignSpace(radii=RADII, speed_range=(0.5, 20.0), n_speeds=12)
    d = design_impacts(None, space, 6, prior={"zeta_hertz": (0.1, 2.0), "zeta_adhesion": (10.0, 80.0)},
                       material=material, parameters=("zeta_hertz", "zeta_adhesion"))
    assert set(d.rows["radius"]) <= set(RADII) and (d.rows["e_n_expected"] > 0).all()
    assert all(r.startswith("d = ") for r in d.rows["reason"])  # the size class is in each reason
    assert set(uniform_design(space, 6)["radius"]) == set(RADII)
    # zeta_A moves e_n most near capture, where the small spheres rebound at speeds the large ones do
    # not: the note names the sizes and speeds where e_n responds
    assert "um" in d.notes["zeta_adhesion"] and d.width("zeta_adhesion") < d.width("zeta_adhesion", 0)


def test_a_range_with_a_negative_speed_is_refused_by_name(tmp_path, start_fit, capsys):
    fit = tmp_path / "fit.nc"
    start_fit.save(fit)
    for value in ("-1,2", "-1:2"):
        assert main(["design", str(fit), "--speeds", value, "--out", str(tmp_path / "d.csv")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith(f"microimpact: error: --speeds '{value}'"), err
    assert main(["design", str(tmp_path / "missing.nc"), "--speeds", "-1,2"]) == 2  # the option first
    assert "--speeds" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fit.nc"]


def test_repeats_are_one_line_of_the_page(tmp_path, start_fit):
    space = DesignSpace(radii=(3.45e-6,), speed_range=(0.5, 20.0), n_speeds=8)
    d = design_next_impacts(start_fit, space, 6, ("zeta_hertz",))
    record = json.loads(json.dumps(design_record(d, space, source="fit.nc")))
    table = _rows_table(record)
    assert table["n"].astype(int).sum() == 6 and len(table) < 6  # the most informative speed repeated
    pdf = PdfReader(build_report(tmp_path / "report.pdf", {"fit": start_fit.to_dataset(), "design": record}))
    page = next(t for t in (p.extract_text() for p in pdf.pages) if "What to measure next" in t and "Criterion" in t)
    assert table["id"].iloc[0] in page


def test_template_columns_follow_the_space(start_fit):
    space = DesignSpace(radii=(3.45e-6,), speed_range=(0.5, 20.0), n_speeds=8, oblique_quantity="none")
    d = design_next_impacts(start_fit, space, 2, ("zeta_hertz",))
    t = design_template(d, space)
    assert not any("tangential" in c or "rebound" in c for c in t.columns)
