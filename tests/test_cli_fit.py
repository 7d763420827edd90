"""Tests of the ``microimpact fit`` and ``microimpact flags`` subcommands (real files in tmp_path)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from microimpact.cli import main
from microimpact.analysis.fit_result import DampingFit

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "data" / "synthetic_microspheres.csv"  # SYNTHETIC data (data/README.md)


def files(d):
    return sorted(p.name for p in Path(d).iterdir())


@pytest.fixture(scope="module")
def small_csv(tmp_path_factory):
    """Every fifth impact of the synthetic file: 20 points over 4 radii (a fast fit)."""
    d = tmp_path_factory.mktemp("data")
    lines = DATA.read_text().splitlines()
    path = d / "small.csv"
    path.write_text("\n".join([lines[0]] + lines[1::5]) + "\n")
    return path


@pytest.fixture(scope="module")
def fitted(small_csv, tmp_path_factory):
    out = tmp_path_factory.mktemp("fit") / "fit.nc"
    rc = main(["fit", str(small_csv), "--out", str(out), "--no-confidence-intervals"])
    assert rc == 0
    return out


def test_fit_writes_and_prints_report(fitted, capsys):
    fit = DampingFit.load(fitted)
    assert fit.n_points == 20
    assert fit.info["material_pair"] == "ammonium_fluorescein_on_silicon"
    # the synthetic file was made with zeta_H = 0.50, zeta_A = 29.0 (data/README.md) and noise drawn
    # from its stated uncertainties: the fit of 20 of its points lands within 3 standard errors
    # (measured: 0.54 +- 0.16, 28.69 +- 0.30), and the errors are informative
    for name, truth in (("zeta_hertz", 0.50), ("zeta_adhesion", 29.0)):
        assert abs(fit.values[name] - truth) < 3.0 * fit.stderr[name], name
        assert fit.stderr[name] < 0.5 * truth, name
    assert files(fitted.parent) == ["fit.nc"]  # no temporary files left


def test_fit_report_on_stdout(small_csv, tmp_path, capsys):
    out = tmp_path / "f.nc"
    assert main(["fit", str(small_csv), "--out", str(out), "--no-confidence-intervals",
                 "--material-pair", "ammonium_fluorescein_on_silicon", "--weights", "e_n"]) == 0
    captured = capsys.readouterr()
    assert "zeta_adhesion" in captured.out and "reduced" in captured.out
    assert "fitting 20 impacts" in captured.err


def test_flags(small_csv, fitted, tmp_path, capsys):
    out, nc = tmp_path / "flags.csv", tmp_path / "flags.nc"
    rc = main(["flags", str(small_csv), "--fit", str(fitted), "--out", str(out), "--nc", str(nc),
               "--angle-uncertainty-deg", "1.5"])
    assert rc == 0
    captured = capsys.readouterr()
    assert "flags: radius" in captured.err  # progress on stderr
    assert "near_capture" in captured.out
    table = pd.read_csv(out)
    assert len(table) == 20 and table.columns[0] == "row"
    np.testing.assert_allclose(table["angle_uncertainty_deg"], 1.5)
    with xr.open_dataset(nc) as ds:
        assert ds.sizes["impact"] == 20
    assert files(tmp_path) == ["flags.csv", "flags.nc"]


def _fails(argv, tmp_path, capsys, match):
    before = files(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("microimpact: error: ") and match in err
    assert files(tmp_path) == before  # nothing written


def test_bad_input_fit(small_csv, tmp_path, capsys):
    out = str(tmp_path / "fit.nc")
    _fails(["fit", str(tmp_path / "missing.csv"), "--out", out], tmp_path, capsys, "does not exist")
    _fails(["fit", str(ROOT / "tests" / "data" / "bad_csv" / "semicolon.csv"), "--out", out], tmp_path, capsys, "semicolon")
    _fails(["fit", str(small_csv), "--out", str(tmp_path / "no" / "fit.nc")], tmp_path, capsys, "directory")
    _fails(["fit", str(small_csv), "--out", out, "--material-pair", "unobtainium"], tmp_path, capsys, "unknown material pair")
    _fails(["fit", str(small_csv), "--out", out, "--material-pair", "alumina_on_soda_lime_glass"], tmp_path, capsys,
           "no impacts of material pair")
    _fails(["fit", str(small_csv)], tmp_path, capsys, "--out")
    bad_cfg = tmp_path / "m.yaml"
    bad_cfg.write_text("pairs: {x: {density: -1}}\n")
    before = files(tmp_path)
    assert main(["fit", str(small_csv), "--out", out, "--config", str(bad_cfg)]) == 2
    assert files(tmp_path) == before


def test_bad_input_flags(small_csv, fitted, tmp_path, capsys):
    out = str(tmp_path / "flags.csv")
    _fails(["flags", str(small_csv), "--fit", str(small_csv), "--out", out], tmp_path, capsys, "not a damping fit")
    _fails(["flags", str(small_csv), "--fit", str(tmp_path / "none.nc"), "--out", out], tmp_path, capsys, "does not exist")
    _fails(["flags", str(small_csv), "--fit", str(fitted), "--out", out, "--spin-bound", "nan"], tmp_path, capsys, "finite")
    _fails(["flags", str(small_csv), "--fit", str(fitted), "--out", out, "--nc", str(tmp_path / "x" / "f.nc")],
           tmp_path, capsys, "directory")


def test_entry_point_exit_status(tmp_path):
    r = subprocess.run([sys.executable, "-m", "microimpact", "fit", str(tmp_path / "missing.csv"), "--out",
                        str(tmp_path / "f.nc")], capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "does not exist" in r.stderr
    assert files(tmp_path) == []


def test_fit_json_is_the_report_as_numbers(small_csv, tmp_path, capsys):
    """fit --json (issue 28): the parameters as the report gives them (value, 95 % interval and a
    meaningful standard error where determined; the fixed w_A as fixed), equal to the fit file's."""
    import json

    from microimpact.analysis import DampingFit

    out = tmp_path / "fit.nc"
    assert main(["fit", str(small_csv), "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    fit = DampingFit.load(out)
    params = summary["damping"]["parameters"]
    for name in fit.varied:
        rec, st = params[name], fit.identifiability[name]
        assert rec["status"] == st.status
        if st.status == "determined":
            assert rec["value"] == pytest.approx(fit.values[name], rel=1e-12, abs=0.0)
            assert rec["interval"] == pytest.approx([st.lower, st.upper], rel=1e-12, abs=0.0)
            assert rec["interval"][0] <= rec["value"] <= rec["interval"][1]
        else:
            assert "value" not in rec and "stderr" not in rec
    assert params["work_of_adhesion"] == {"status": "fixed", "value": pytest.approx(fit.values["work_of_adhesion"])}
    assert summary["n_points"] == len(fit.data) and summary["written"] == [str(out)]


def test_fit_help_names_the_format_document_an_installed_package_has(capsys):
    """``fit --help`` points at the packaged copy of data/README.md (an installed user has no
    repository), by a path that exists and holds the CSV format's section."""
    assert main(["fit", "--help"]) == 0
    words = capsys.readouterr().out.split()
    named = [Path(w.rstrip(",")) for w in words if w.rstrip(",").endswith("README.md")]
    assert named and named[0].is_absolute() and named[0].is_file(), named
    assert "Measured-impact CSV format" in named[0].read_text()


def test_fit_help_keeps_a_hyphenated_install_path_in_one_piece(capsys, monkeypatch):
    """An installed package's path holds ``site-packages``; argparse's own wrapping broke it after
    the hyphen, so the help named ``packages/microimpact/data/README.md`` (seen on the installed
    wheel). The path is long so that it must wrap somewhere."""
    import microimpact.cli as cli

    path = Path("/opt/a-long-virtual-environment-name/lib/python3.11/site-packages/microimpact/data/README.md")
    monkeypatch.setattr(cli, "DATA_README", path)
    assert main(["fit", "--help"]) == 0
    assert str(path) in [w.rstrip(",") for w in capsys.readouterr().out.split()]
