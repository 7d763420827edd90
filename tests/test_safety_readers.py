"""Readers of result files (issue 55, item 4): a variable of another shape or type, or a missing
one, is one line naming the file (and the variable), never a TypeError from deep in the reader.

A fuzz over every variable of a fit file (the file every ``--fit`` option reads): each variable
in turn made two-dimensional, made text, or dropped."""

import numpy as np
import pytest
import xarray as xr

from microimpact.analysis.fit_result import DampingFit
from microimpact.cli import main

from test_safety_outputs import small_csv  # noqa: F401 - the fixture


@pytest.fixture(scope="module")
def fit_file(small_csv, tmp_path_factory):  # noqa: F811
    out = tmp_path_factory.mktemp("fit") / "fit.nc"
    assert main(["fit", str(small_csv), "--out", str(out), "--no-confidence-intervals"]) == 0
    return out


def _mutations(ds):
    for name in list(ds.data_vars):
        v = ds[name]
        yield name, "two-dimensional", lambda d, n=name, v=v: d.assign(
            {n: (("extra_a", "extra_b"), np.ones((2, 3)))})
        yield name, "text", lambda d, n=name, v=v: d.assign({n: (v.dims, np.full(v.shape, "x", dtype=object))})
        yield name, "dropped", lambda d, n=name: d.drop_vars(n)


def test_every_variable_of_a_fit_file_mutated_is_one_line_naming_the_file(fit_file, tmp_path):
    with xr.open_dataset(fit_file) as ds:
        good = ds.load()
    scalars = {n for n in good.data_vars if good[n].ndim == 0}
    tried = failed_quietly = 0
    for name, how, mutate in _mutations(good):
        bad = tmp_path / f"{name}-{how}.nc"  # the reader's part after the NetCDF read, in memory (fast)
        tried += 1
        try:
            DampingFit._from_file(mutate(good.copy()), bad)
        except ValueError as exc:
            message = str(exc)
            assert "\n" not in message and str(bad) in message, (name, how, message)
            if name in scalars or how == "dropped":
                assert repr(name) in message, (name, how, message)
        except Exception as exc:  # noqa: BLE001 - the point of the test
            pytest.fail(f"{name} {how}: {type(exc).__name__}: {exc}")
        else:
            failed_quietly += 1  # a variable the reader does not need
    assert tried >= 3 * 10 and failed_quietly < tried


@pytest.mark.parametrize("command", [["simulate", "--speed", "1"], ["sweep", "--case", "2.1"],
                                     ["target", "--e-n", "0.5", "--speed", "1"], ["flags"], ["plot"]])
def test_a_fit_whose_parameter_is_not_a_scalar_is_one_line_with_status_2(command, fit_file, small_csv, tmp_path,  # noqa: F811
                                                                         capsys):
    # was: TypeError: only 0-dimensional arrays can be converted to Python scalars (exit 1, traceback)
    with xr.open_dataset(fit_file) as ds:
        bad = ds.load().assign(zeta_hertz=("extra", [0.5, 0.6]))
    path = tmp_path / "bad.nc"
    bad.to_netcdf(path)
    argv = [*command, "--fit", str(path)] + (["--out", str(tmp_path / "s.nc")] if command[0] == "sweep" else [])
    if command == ["flags"]:
        argv = ["flags", str(small_csv), "--fit", str(path), "--out", str(tmp_path / "s.csv")]
    if command == ["plot"]:  # the fit is plot's RESULT (a TypeError traceback deep in the figure's caption)
        argv = ["plot", str(path), "--out", str(tmp_path / "s.png")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(path) in err[0] and "'zeta_hertz'" in err[0], err
    assert not any((tmp_path / f"s.{suffix}").exists() for suffix in ("nc", "png", "csv"))
