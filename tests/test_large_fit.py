"""The damping fit's emulator path (method "emulator", the default) against the solver (method "solve").

Radii with at least EMULATOR_MIN_ROWS rows take e_n from the ring law's table (absolute tolerance
EMULATOR_TOLERANCE); the fit checks that the tolerance cannot move an estimate by more than
EMULATOR_MAX_SHIFT standard errors, else refits by the solver. docs/large-fit.json holds the
100,000-row comparison (tests/study_large_fit.py).
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from microimpact.analysis import fitting
from microimpact.analysis.fitting import (EMULATOR_MAX_SHIFT, EMULATOR_MIN_ROWS, EMULATOR_TOLERANCE, FitProblem,
                                          emulator_shift_bound, fit_damping, model_restitution)
from microimpact.analysis.synthetic import make_synthetic_impacts, write_synthetic_impacts
from microimpact.cli import main
from microimpact.io import default_materials_path, read_materials
from microimpact.solvers import DEFAULT_RTOL

MATERIAL = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
#: the solve path's own error: a restitution family at rtol (absolute on e_n), verified at half of
#: it (solvers/family.py), with a factor 10 for the direct solves' rtol-level error near capture
SOLVE_ERROR = 10 * DEFAULT_RTOL


def _table(n_per_radius, radii=(1.29e-6, 3.45e-6), e_n_rel_sd=0.03, seed=7):
    raw = make_synthetic_impacts(radii=radii, n_per_radius=n_per_radius, e_n_rel_sd=e_n_rel_sd, seed=seed,
                                 angle_sd_deg=0.0)
    return pd.DataFrame({"radius": raw["radius [um]"].to_numpy() * 1e-6, "normal_speed": raw["speed [m/s]"].to_numpy(),
                         "e_n": raw["e_n [1]"].to_numpy(),
                         "e_n_uncertainty": raw.get("e_n_uncertainty [1]", pd.Series(np.nan, raw.index)).to_numpy()})


@pytest.mark.parametrize("params", [(0.5, 29.0), (0.3, 20.0), (0.8, 40.0)])
def test_emulated_model_agrees_with_the_solver(params):
    """On EMULATOR_MIN_ROWS speeds per radius the table's e_n is within its tolerance of the solver's
    (plus the solver's own error), at the bundled data's parameters and away from them."""
    table = _table(EMULATOR_MIN_ROWS)
    r, v = table["radius"].to_numpy(), table["normal_speed"].to_numpy()
    emulated = FitProblem.from_arrays(r, v, MATERIAL, "emulator")
    assert emulated.emulated_rows().all()
    e = model_restitution(emulated, *params, MATERIAL.work_of_adhesion)
    s = model_restitution(FitProblem.from_arrays(r, v, MATERIAL), *params, MATERIAL.work_of_adhesion)
    assert np.max(np.abs(e - s)) <= EMULATOR_TOLERANCE + SOLVE_ERROR
    assert np.count_nonzero(s > 0) > 0.9 * s.size  # rebounds: e_n is compared where it is not 0


def test_small_radius_groups_are_solved_exactly():
    """Below EMULATOR_MIN_ROWS rows a radius is solved as by "solve": the same numbers to the bit."""
    table = _table(25)
    r, v = table["radius"].to_numpy(), table["normal_speed"].to_numpy()
    emulated = FitProblem.from_arrays(r, v, MATERIAL, "emulator")
    assert not emulated.emulated_rows().any()
    np.testing.assert_array_equal(model_restitution(emulated, 0.5, 29.0, MATERIAL.work_of_adhesion),
                                  model_restitution(FitProblem.from_arrays(r, v, MATERIAL), 0.5, 29.0,
                                                    MATERIAL.work_of_adhesion))


def test_shift_bound_formula():
    """tol sqrt(sum 1 / sigma^2) / sqrt(scale) over the emulated rows, 0 without them."""
    problem = FitProblem.from_arrays(np.full(EMULATOR_MIN_ROWS, 2e-6), np.geomspace(2.0, 50.0, EMULATOR_MIN_ROWS),
                                     MATERIAL, "emulator")
    sigma = np.full(EMULATOR_MIN_ROWS, 0.02)
    assert emulator_shift_bound(problem, sigma) == pytest.approx(
        EMULATOR_TOLERANCE * np.sqrt(EMULATOR_MIN_ROWS) / 0.02, rel=1e-12, abs=0)
    assert emulator_shift_bound(problem, None, scale=4.0) == pytest.approx(
        EMULATOR_TOLERANCE * np.sqrt(EMULATOR_MIN_ROWS) / 2.0, rel=1e-12, abs=0)
    assert emulator_shift_bound(FitProblem.from_arrays([2e-6] * 3, [1.0, 2.0, 3.0], MATERIAL, "emulator"), None) == 0.0


@pytest.mark.extended  # fits of thousands of rows: seconds each
@pytest.mark.parametrize("work_of_adhesion", [False, True])
def test_fit_by_the_table_agrees_with_the_solver_within_the_bound(monkeypatch, work_of_adhesion):
    """With the row threshold lowered so that a small fit is served by the table, its estimates and
    interval ends differ from the solver's by less than the bound the fit states (in standard
    errors), plus 1e-3 for the solver's rtol and the least squares' convergence; also with w_A
    fitted (the table's groups recomputed for every w_A)."""
    monkeypatch.setattr(fitting, "EMULATOR_MIN_ROWS", 30)
    table = _table(40, seed=11)
    emu = fit_damping(table, MATERIAL, confidence_intervals=False, fit_work_of_adhesion=work_of_adhesion)
    solve = fit_damping(table, MATERIAL, confidence_intervals=False, method="solve",
                        fit_work_of_adhesion=work_of_adhesion)
    assert emu.info["model_evaluation"].startswith("the ring-law emulator")
    assert solve.info["model_evaluation"].startswith("the solver")
    bound = fitting.emulator_shift_bound(FitProblem.from_arrays(table["radius"], table["normal_speed"], MATERIAL,
                                                                "emulator"), table["e_n_uncertainty"].to_numpy())
    assert 0 < bound < EMULATOR_MAX_SHIFT
    for name in emu.varied:
        se = solve.stderr[name]
        assert abs(emu.values[name] - solve.values[name]) / se <= bound + 1e-3, name
        assert emu.stderr[name] == pytest.approx(se, rel=0.01, abs=0), name  # the Jacobian of the same law
        a, b = emu.identifiability[name], solve.identifiability[name]
        assert abs(a.lower - b.lower) / se <= bound + 0.02, name  # + the profile's tolerance, 0.01 se per end
        assert abs(a.upper - b.upper) / se <= bound + 0.02, name


@pytest.mark.extended  # fits of thousands of rows: seconds each
def test_too_precise_data_are_fitted_by_the_solver(monkeypatch):
    """Where the table's tolerance could move an estimate by more than EMULATOR_MAX_SHIFT standard
    errors (stated e_n uncertainties of 5e-5: a bound of ~0.18), the fit is made by the solver instead."""
    monkeypatch.setattr(fitting, "EMULATOR_MIN_ROWS", 30)
    table = _table(40, seed=11, e_n_rel_sd=0.0)
    table["e_n_uncertainty"] = 5e-5
    problem = FitProblem.from_arrays(table["radius"], table["normal_speed"], MATERIAL, "emulator")
    assert emulator_shift_bound(problem, table["e_n_uncertainty"].to_numpy()) > EMULATOR_MAX_SHIFT
    fit = fit_damping(table, MATERIAL, confidence_intervals=False)
    assert fit.info["model_evaluation"].startswith("the solver")


def test_unknown_method_is_refused():
    with pytest.raises(ValueError, match="method must be one of"):
        fit_damping(_table(5), MATERIAL, method="table")


@pytest.mark.extended  # fits of thousands of rows: seconds each
def test_precise_parameters_get_their_profile_interval():
    """Where the data determine a parameter to better than the profile's relative tolerance (here
    stated e_n uncertainties of 1e-4: relative standard errors ~1e-4), the interval is located in
    standard errors: it brackets the estimate and is 2 x 1.96 standard errors wide to 5 % (a nearly
    linear model over so narrow a range). Located to the relative tolerance alone, the interval of
    such a parameter can shrink to the estimate itself."""
    table = _table(40, seed=3, e_n_rel_sd=0.0)
    table["e_n_uncertainty"] = 1e-4
    fit = fit_damping(table, MATERIAL, confidence_intervals=False, method="solve")
    for name in fit.varied:
        st, se, value = fit.identifiability[name], fit.stderr[name], fit.values[name]
        assert fitting.PROFILE_XTOL * abs(value) > fitting.PROFILE_PRECISE * se  # the case tested
        assert st.lower < value < st.upper, name
        assert (st.upper - st.lower) / (2 * 1.96 * se) == pytest.approx(1.0, rel=0.05, abs=0), name


@pytest.mark.extended  # fits of thousands of rows: seconds each
def test_the_cli_takes_the_fit_method_and_says_which_one_ran(tmp_path, capsys):
    """``fit --fit-method`` reaches the damping fit: on a radius of EMULATOR_MIN_ROWS rows the JSON
    summary names the table by default and the solver with ``solve``; a wrong name is refused."""
    path = write_synthetic_impacts(tmp_path / "big.csv", radii=(3.45e-6,), n_per_radius=fitting.EMULATOR_MIN_ROWS, seed=5)
    said = {}
    for method in ("emulator", "solve"):
        out = tmp_path / f"{method}.nc"
        argv = ["fit", str(path), "--out", str(out), "--no-confidence-intervals", "--json", "--fit-method", method]
        assert main(argv) == 0
        said[method] = json.loads(capsys.readouterr().out)["damping"]["model_evaluation"]
    assert said["emulator"].startswith("the ring-law emulator") and said["solve"].startswith("the solver at rtol")
    assert main(["fit", str(path), "--out", str(tmp_path / "x.nc"), "--fit-method", "table"]) == 2
    assert "--fit-method: invalid choice: 'table'" in capsys.readouterr().err and not (tmp_path / "x.nc").exists()
