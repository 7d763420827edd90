"""Impossible oblique measurements (issue 55, item 6): a tangential restitution beyond the bound
|e_t| <= 1 of an impact without incident spin by more than its stated uncertainty allows is refused
by the reader, naming file, row and column, so that every fit (``fit``, ``flags``, ``lammps fit``,
the pipeline) refuses it alike; ``lammps fit`` called 5 +- 0.01 "consistent with no friction".

The bound: without incident spin the tangential impulses only take tangential and rotational kinetic
energy (Maw, Barber & Fawcett 1976, Wear 38:101-114), so |v_t,out| <= v_t,in."""

import math
import warnings

import pytest

from microimpact.cli import main
from microimpact.io import ImpactDataError, ImpactDataWarning, read_impacts

HEAD = "radius [um],speed [m/s],incidence_angle [deg],e_n [1],"
V_T_IN = 10.0 * math.sin(math.radians(30.0))  # the incident tangential speed of the rows below [m/s]


@pytest.mark.parametrize("columns, row, column", [
    ("tangential_restitution [1],tangential_restitution_uncertainty [1]", "5,0.01", "tangential_restitution [1]"),
    ("tangential_restitution [1],tangential_restitution_uncertainty [1]", "-1.3,0.05", "tangential_restitution [1]"),
    # |v_t,out| = 2 v_t,in, +- 0.1 m/s
    ("rebound_tangential_speed [m/s],rebound_tangential_speed_uncertainty [m/s]", f"{2 * V_T_IN},0.1",
     "rebound_tangential_speed [m/s]"),
])
def test_an_impossible_tangential_rebound_is_refused_naming_file_row_and_column(tmp_path, columns, row, column):
    path = tmp_path / "impossible.csv"
    path.write_text(HEAD + columns + "\n3,10,30,0.5,0.8,0.01\n3,10,30,0.5," + row + "\n")
    before = path.read_bytes()
    with pytest.raises(ImpactDataError) as exc:
        read_impacts(path)
    assert len(exc.value.problems) == 1, exc.value
    p = exc.value.problems[0]
    assert (p.row, p.line, p.column) == (2, 3, column) and "|e_t| > 1" in p.message, p
    assert "impossible.csv" in str(exc.value)
    assert path.read_bytes() == before


def test_a_tangential_rebound_above_the_bound_within_its_errors_is_kept(tmp_path):
    # 1.02 +- 0.01 is 2 sigma above 1 (< 4): a measurement, kept and named in a warning
    path = tmp_path / "noisy.csv"
    path.write_text(HEAD + "tangential_restitution [1],tangential_restitution_uncertainty [1]\n3,10,30,0.5,1.02,0.01\n")
    with pytest.warns(ImpactDataWarning, match="row 1"):
        df = read_impacts(path)
    assert df["tangential_restitution"].tolist() == [1.02]


def test_a_tangential_rebound_above_one_with_stated_spin_is_no_problem(tmp_path):
    # incident top-spin can make the rebound faster along the surface: the bound is the spin-free one
    path = tmp_path / "spun.csv"
    path.write_text(HEAD + "tangential_restitution [1],tangential_restitution_uncertainty [1],spin [rad/s]\n"
                    "3,10,30,0.5,1.5,0.01,1e6\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error", ImpactDataWarning)
        assert read_impacts(path)["tangential_restitution"].tolist() == [1.5]


@pytest.mark.parametrize("command", [["fit", "{csv}", "--out", "{out}"], ["lammps", "fit", "{csv}", "--out", "{out}"]])
def test_every_fit_refuses_impossible_oblique_rows_naming_the_row(tmp_path, command, capsys):
    csv = tmp_path / "impossible.csv"
    csv.write_text(HEAD + "tangential_restitution [1],tangential_restitution_uncertainty [1]\n"
                   "3,10,30,0.5,0.8,0.01\n3,10,30,0.6,5,0.01\n3,5,45,0.7,0.7,0.01\n")
    out = tmp_path / "out.nc"
    assert main([w.format(csv=csv, out=out) for w in command]) == 2
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert any("impossible.csv" in line and "row 2" in line and "tangential_restitution [1]" in line
               for line in err), err
    assert "Traceback" not in "\n".join(err) and not out.exists()
