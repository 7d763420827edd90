"""Reader fuzz over every result-file kind the toolkit reads back (issue 55, item 4): each variable
of each kind's file dropped, made text or given another shape is read as the kind, or refused in
one line that names the file and that variable, never a TypeError or IndexError from deep inside.

The kinds are the :class:`~microimpact.analysis.fit_result.FitResult` files (damping fit,
friction fit, DEM-law fit, posterior, damping target: what ``--fit``, ``--posterior`` and the
report read); the commands that read them (``simulate --fit``, ``flags --posterior``) answer a
damaged one with that line and exit status 2, writing nothing."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from microimpact.analysis.fit_result import DampingFit
from microimpact.analysis.posterior import Posterior
from microimpact.cli import main

from test_fit_results import KINDS, results  # noqa: F401 - the fixture: one result of every kind
from test_safety_outputs import small_csv  # noqa: F401 - the fixture

# every variable of every result kind damaged, hundreds of reads and CLI runs: with the extended tests
pytestmark = pytest.mark.extended

HOW = ("dropped", "text", "another shape")


def mutate(ds: xr.Dataset, name: str, how: str) -> xr.Dataset:
    """``ds`` with variable ``name`` dropped, made text (object strings) or given a shape it does not
    have (one more dimension, of length 2: a scalar becomes a vector, a vector a matrix)."""
    v = ds[name]
    if how == "dropped":
        return ds.drop_vars(name)
    if how == "text":
        return ds.assign({name: (v.dims, np.full(v.shape, "x", dtype=object))})
    return ds.assign({name: ((*v.dims, "fuzz_extra"), np.stack([v.values, v.values], axis=-1))})


def _fuzz(kind, good: xr.Dataset, path) -> dict:
    """how -> number of variables the reader took anyway; fails on any message that is not one line
    naming the file and the variable, and on any other exception."""
    took = dict.fromkeys(HOW, 0)
    for name in map(str, good.data_vars):
        for how in HOW:
            try:
                kind._from_file(mutate(good.copy(), name, how), path)  # the reader after the NetCDF read
            except ValueError as exc:
                message = str(exc)
                assert "\n" not in message and message.startswith(f"{path}: "), (kind.__name__, name, how, message)
                assert repr(name) in message, (kind.__name__, name, how, message)
            except Exception as exc:  # noqa: BLE001 - the point of the test
                pytest.fail(f"{kind.__name__} {name} {how}: {type(exc).__name__}: {exc}")
            else:
                took[how] += 1
    return took


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.__name__)
def test_every_variable_of_every_result_kind_damaged_is_one_line_naming_it(kind, results, tmp_path):  # noqa: F811
    path = results[kind].save(tmp_path / f"{kind.__name__}.nc")
    good = kind.read_dataset(path)
    took = _fuzz(kind, good, path)
    n = len(good.data_vars)
    assert n >= 3 and took["dropped"] < n, (kind.__name__, took)  # the reader needs some of them


@pytest.fixture(scope="module")
def fit_nc(small_csv, tmp_path_factory):  # noqa: F811
    out = tmp_path_factory.mktemp("fuzz-fit") / "fit.nc"
    assert main(["fit", str(small_csv), "--out", str(out), "--no-confidence-intervals"]) == 0
    return out


@pytest.mark.parametrize("how", HOW)
@pytest.mark.parametrize("name", ["zeta_hertz", "work_of_adhesion", "radius"])
def test_simulate_with_a_damaged_fit_file_is_one_line_and_status_2(name, how, fit_nc, tmp_path, capsys):
    good = DampingFit.read_dataset(fit_nc)
    if name not in good.variables:
        pytest.skip(f"{name} is not a variable of this fit file")
    bad = tmp_path / "bad.nc"
    mutate(good, name, how).to_netcdf(bad)
    capsys.readouterr()
    status = main(["simulate", "--fit", str(bad), "--radius", "3e-6", "--speed", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and str(bad) in err[0] and repr(name) in err[0], (status, err)


@pytest.mark.parametrize("how", HOW)
def test_flags_with_a_damaged_posterior_is_one_line_status_2_and_writes_nothing(how, results, small_csv,  # noqa: F811
                                                                                 fit_nc, tmp_path, capsys):
    good = Posterior.read_dataset(results[Posterior].save(tmp_path / "post.nc"))
    name = next(n for n in map(str, good.data_vars) if good[n].ndim >= 1)  # the chain or its draws
    bad = tmp_path / "bad_post.nc"
    mutate(good, name, how).to_netcdf(bad)
    capsys.readouterr()
    out = tmp_path / "flags.csv"
    status = main(["flags", str(small_csv), "--fit", str(fit_nc), "--posterior", str(bad), "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and str(bad) in err[0], (status, err)
    assert not out.exists()
