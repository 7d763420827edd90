"""Outputs all or nothing and options that read as they were meant (issue 55, items 3, 5, 7)."""

import subprocess
import sys
from pathlib import Path

import pytest

from microimpact.cli import main

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "data" / "synthetic_microspheres.csv"  # SYNTHETIC data (data/README.md)


@pytest.fixture(scope="module")
def small_csv(tmp_path_factory):
    """Every fifth impact of the synthetic file: 20 points over 4 radii (a fast fit)."""
    lines = DATA.read_text().splitlines()
    path = tmp_path_factory.mktemp("data") / "small.csv"
    path.write_text("\n".join([lines[0]] + lines[1::5]) + "\n")
    return path


def test_out_dash_is_a_value_again(tmp_path, monkeypatch, capsys):
    # "--out -" was answered "unrecognized option - (did you mean -h?)": a lone "-" is a value
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--speed", "2", "--out", "-"]) == 2  # simulate has no --out: still refused
    assert "unrecognized option --out" in capsys.readouterr().err
    assert main(["reproduce", "--out", "-", "--time-budget", "1e-9"]) == 3  # parsed; stopped by the budget
    err = capsys.readouterr().err
    assert "unrecognized option" not in err and "time budget" in err


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_fit_to_a_full_stdout_writes_no_file(small_csv, tmp_path):
    # `fit > /dev/full` exited 2 after writing its NetCDF; the report is now printed first
    out = tmp_path / "fit.nc"
    with open("/dev/full", "w") as full:
        done = subprocess.run([sys.executable, "-m", "microimpact._entry", "fit", str(small_csv), "--out", str(out),
                               "--no-confidence-intervals"], stdout=full, stderr=subprocess.PIPE, text=True,
                              timeout=300)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert lines[-1].startswith("microimpact: error: stdout") and "No space left" in lines[-1], done.stderr
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == []
