"""The same material at every size, a fit as the material, and outputs that say which contact (issue 25, part 6).

Eq. (7) of Cheng, Brach & Dunn (2002), f0 = (9/(2 pi) K r w_A^2)^(1/3), makes f0 scale as r^(1/3) for
one material (one w_A): the test writes that scaling out with the paper's Table 1 row 2 numbers
(f0 = 7.422 N/m at r = 3.45 um) instead of reading the code's constant.
"""

from __future__ import annotations

import json

import pytest
import xarray as xr

from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.synthetic import make_synthetic_impacts
from microimpact.cli import main
from microimpact.io import default_materials_path, read_impacts, read_materials
from microimpact.io.files import write_csv

F0_PAPER, R_PAPER = 7.422, 3.45e-6  # Table 1 row 2 [N/m], [m]


def _json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_a_new_radius_keeps_the_material(capsys):
    d = _json(capsys, ["simulate", "--preset", "wall1990", "--radius", "1.29e-6", "--speed", "2", "--json"])
    expected = F0_PAPER * (1.29e-6 / R_PAPER) ** (1 / 3)  # 5.347 N/m
    # Eq. (7) evaluated by the code from the preset's w_A (itself from 7.422 N/m at 3.45 um): the same
    # number to round-off of a cube root and a square root (1e-12 N/m)
    assert d["contact"]["adhesion_line_force"] == pytest.approx(expected, abs=1e-12)
    assert d["contact"]["adhesion_line_force"] == pytest.approx(5.347, abs=5e-4)
    assert "by Eq. (7) at r = 1.29e-06 m" in d["contact"]["source"]
    assert d["contact"]["radius"] == 1.29e-6


@pytest.mark.parametrize("speed, outcome", [(5.45, "capture"), (5.55, "rebound")])
def test_the_capture_speed_at_the_new_size_is_the_materials(capsys, speed, outcome):
    # the scipy reference solver (independent of the engine) puts the capture speed of the wall1990
    # material at 1.29 um at 5.50 m/s; with the 3.45 um sphere's f0 kept it would be 11.4 m/s
    d = _json(capsys, ["simulate", "--radius", "1.29e-6", "--speed", str(speed), "--json", "--method", "reference"])
    assert d["outcome"] == outcome


def test_an_explicit_line_force_is_kept_and_said(capsys):
    d = _json(capsys, ["simulate", "--radius", "1.29e-6", "--adhesion-line-force", "7.422", "--speed", "2", "--json"])
    assert d["contact"]["adhesion_line_force"] == 7.422
    assert "given on the command line" in d["contact"]["source"]
    w = _json(capsys, ["simulate", "--radius", "1.29e-6", "--work-of-adhesion", "0.1", "--speed", "2", "--json"])
    k = w["contact"]["stiffness"]
    # Eq. (7) with w_A = 0.1 J/m2 written out
    assert w["contact"]["adhesion_line_force"] == pytest.approx((9 / (2 * 3.141592653589793) * k * 1.29e-6 * 0.01) ** (1 / 3),
                                                                rel=1e-12)


@pytest.fixture(scope="module")
def fit_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("fit")
    path = d / "data.csv"
    write_csv(make_synthetic_impacts(seed=2, radii=(1.29e-6, 3.45e-6), n_per_radius=10), path, float_format="%.6g")
    pair = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    fit = fit_damping(read_impacts(path), pair, confidence_intervals=False)
    return fit.save(d / "fit.nc"), fit


def test_simulate_with_a_fit_uses_the_fitted_material_at_the_radius(capsys, fit_file):
    path, fit = fit_file
    d = _json(capsys, ["simulate", "--fit", str(path), "--radius", "2e-6", "--speed", "3", "--json"])
    c = d["contact"]
    assert c["zeta_hertz"] == pytest.approx(fit.zeta_hertz, rel=1e-15)
    assert c["zeta_adhesion"] == pytest.approx(fit.zeta_adhesion, rel=1e-15)
    assert c["work_of_adhesion"] == pytest.approx(fit.work_of_adhesion, rel=1e-12)
    assert c["radius"] == 2e-6 and "fit fit.nc" in c["source"]


def test_a_fit_with_several_sizes_needs_a_radius(capsys, fit_file):
    path, _ = fit_file
    assert main(["simulate", "--fit", str(path), "--speed", "3"]) == 2
    assert "give --radius with --fit (the fit's sizes" in capsys.readouterr().err


def test_conflicting_or_wrong_material_sources_are_refused(capsys, fit_file, tmp_path):
    path, _ = fit_file
    assert main(["simulate", "--preset", "wall1990", "--fit", str(path), "--speed", "3"]) == 2
    assert "--preset and --fit both name the material" in capsys.readouterr().err
    sweep = tmp_path / "sweep.nc"
    assert main(["sweep", "--case", "2.1", "--out", str(sweep)]) == 0
    capsys.readouterr()
    assert main(["simulate", "--fit", str(sweep), "--radius", "2e-6", "--speed", "3"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--fit" in err[0] and "not a damping fit" in err[0]


def test_sweep_and_target_keep_the_material_and_record_it(capsys, tmp_path):
    out = tmp_path / "s.nc"
    assert main(["sweep", "--case", "2.1", "--radius", "1.29e-6", "--out", str(out)]) == 0
    assert "by Eq. (7)" in capsys.readouterr().out
    with xr.open_dataset(out) as ds:
        assert "by Eq. (7) at r = 1.29e-06 m" in ds.attrs["contact_source"]
        f0 = [float(v) for k, v in ds.attrs.items() if k.endswith("adhesion_line_force")]
    assert f0 and f0[0] == pytest.approx(F0_PAPER * (1.29e-6 / R_PAPER) ** (1 / 3), abs=1e-9)
    assert main(["target", "--e-n", "0.6", "--speed", "20", "--radius", "1.29e-6", "--points", "5"]) == 0
    assert "f0 = 5.34701 N/m from w_A" in capsys.readouterr().err
