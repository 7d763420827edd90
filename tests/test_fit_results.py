"""The one save/load protocol of every fit result (microimpact.analysis.fit_result.FitResult):
each type survives save -> load with every field equal, and refuses a file of another kind with a
message that names the file and the kind it expected."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from microimpact.analysis.analyst_fit import AnalystFit
from microimpact.analysis.dem_fit import INTERVAL_LEVEL, DemLawFit, fit_dem_law
from microimpact.analysis.fit_result import DampingFit, FitResult
from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.oblique import FrictionFit, fit_friction
from microimpact.analysis.posterior import Posterior, restitution_bands, sample_posterior
from microimpact.analysis.synthetic import make_synthetic_oblique
from microimpact.analysis.target import DampingTarget, damping_from_target
from microimpact.io import default_materials_path, read_impacts, read_materials, write_csv
from microimpact.presets import WALL_1990

KINDS = (DampingFit, FrictionFit, DemLawFit, Posterior, DampingTarget)


def assert_same(a, b, where="result"):
    """Field by field: numbers equal (NaN equal to NaN), arrays, frames and Datasets by value;
    a None-valued dict entry is an entry not recorded (the fit file skips it)."""
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        assert type(a) is type(b), where
        for f in dataclasses.fields(a):
            assert_same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif type(a).__module__.startswith("microimpact.") and hasattr(a, "__dict__"):  # e.g. a DEM fit's e_n model
        assert type(a) is type(b), where
        assert_same(vars(a), vars(b), f"{where} ({type(a).__name__})")
    elif isinstance(a, dict):
        a, b = ({k: v for k, v in d.items() if v is not None} for d in (a, b))
        assert set(a) == set(b), f"{where}: keys {sorted(a)} != {sorted(b)}"
        for k in a:
            assert_same(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, pd.DataFrame):
        pd.testing.assert_frame_equal(b, a, obj=where)
    elif isinstance(a, xr.Dataset):
        assert set(a.data_vars) <= set(b.data_vars), where
        for name in a.data_vars:
            np.testing.assert_array_equal(b[name].values, a[name].values, err_msg=f"{where}[{name}]")
    elif isinstance(a, np.ndarray):
        np.testing.assert_array_equal(b, a, err_msg=where)
    elif isinstance(a, (tuple, list)) and not isinstance(a, str):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, f"{where}[{i}]")
    elif isinstance(a, (float, np.floating)) and math.isnan(a):
        assert math.isnan(b), f"{where}: {b!r} is not NaN"
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """One result of every kind (the composite with all its parts), each fitted once."""
    d = tmp_path_factory.mktemp("fit_results")
    material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    data = make_synthetic_oblique(radii=(3.45e-6,), speeds=(15.0, 30.0), incidence_deg=(35.0, 50.0, 60.0, 70.0))
    table = read_impacts(write_csv(data, d / "oblique.csv"))
    damping = fit_damping(table, material, confidence_intervals=False)
    friction = fit_friction(table, damping)
    post = sample_posterior(table, damping, walkers=8, steps=40, require_convergence=False)  # the form, not the numbers
    dem = fit_dem_law(pd.DataFrame({"radius": [3.45e-6] * 3, "normal_speed": [0.5, 1.0, 2.0], "e_n": [0.70, 0.72, 0.71],
                                    "e_n_uncertainty": [0.01] * 3}),
                      {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0})
    target = damping_from_target([0.3, 0.6], [1.5, 10.0], WALL_1990, n_points=5)
    analyst = AnalystFit(damping, friction, post, post.to_dataset(restitution_bands(post, damping, [15.0, 30.0], n_draws=4)))
    return {"dir": d, DampingFit: damping, FrictionFit: friction, Posterior: post, DemLawFit: dem, DampingTarget: target,
            AnalystFit: analyst}


@pytest.mark.parametrize("kind", KINDS, ids=lambda k: k.__name__)
def test_save_load_gives_every_field_back(results, kind):
    result = results[kind]
    assert isinstance(result, FitResult)
    path = result.save(results["dir"] / f"{kind.__name__}.nc")
    back = kind.load(path)
    assert_same(result, back, kind.__name__)
    assert_same(result, kind.from_dataset(result.to_dataset()), f"{kind.__name__} in memory")


def test_the_friction_fit_keeps_its_report(results):
    result = results[FrictionFit]
    back = FrictionFit.load(result.save(results["dir"] / "friction_report.nc"))
    assert back.report() == result.report() and repr(back) == repr(result)


def test_a_loaded_dem_law_fit_still_gives_its_region(results):
    fit = results[DemLawFit]
    back = DemLawFit.load(fit.save(results["dir"] / "dem_region.nc"))
    assert back.confidence_region(INTERVAL_LEVEL) == fit.confidence_region(INTERVAL_LEVEL)
    assert back.describe() == fit.describe()


@pytest.mark.parametrize("kind", KINDS + (AnalystFit,), ids=lambda k: k.__name__)
def test_a_file_of_another_kind_is_refused_naming_it(results, kind):
    other = DampingTarget if kind is not DampingTarget else DampingFit
    path = results[other].save(results["dir"] / f"other_than_{kind.__name__}.nc")
    with pytest.raises(ValueError, match=rf"^{path}: not a {kind.KIND} \(the file that '{kind.WRITTEN_BY}' writes\): "
                                         rf"it is a NetCDF file titled '{other.TITLE[:20]}"):
        kind.load(path)


def test_a_file_that_is_not_netcdf_is_refused_naming_it(tmp_path):
    bad = tmp_path / "impacts.nc"
    bad.write_text("radius [um],speed [m/s]\n1.0,2.0\n")
    for kind in KINDS:
        with pytest.raises(ValueError, match=rf"^{bad}: not a {kind.KIND} .*: it is a text file$"):
            kind.load(bad)
    with pytest.raises(FileNotFoundError):
        Posterior.load(tmp_path / "no_such_file.nc")


def test_the_composite_round_trips_through_its_three_files(results):
    result, d = results[AnalystFit], results["dir"]
    paths = result.save(d / "fit.nc", d / "posterior.nc", d / "oblique.nc")
    assert [p.name for p in paths] == ["fit.nc", "posterior.nc", "oblique.nc"]
    back = AnalystFit.load(*paths)
    assert_same(result, back, "AnalystFit")
    # each part file is its kind's file, stamped with the fitted contacts like every result file
    assert_same(result.friction, FrictionFit.load(paths[2]), "oblique.nc")
    with xr.open_dataset(paths[1]) as ds:
        assert ds.attrs["parameter_source"] == result.damping.parameter_source


def test_parts_not_computed_are_placeholders_read_as_none(results):
    d = results["dir"]
    paths = AnalystFit(results[DampingFit]).save(d / "f2.nc", d / "p2.nc", d / "o2.nc")
    back = AnalystFit.load(*paths)
    assert (back.friction, back.posterior, back.posterior_dataset) == (None, None, None)
    assert Posterior.load_optional(paths[1]) is None and FrictionFit.load_optional(paths[2]) is None
    with pytest.raises(ValueError, match=rf"^{paths[1]}: holds no posterior \(posterior not computed\)$"):
        Posterior.load(paths[1])
    with pytest.raises(ValueError, match=rf"^{paths[0]}: not a posterior "):
        Posterior.load_optional(paths[0])  # another kind is an error, not "no posterior"


def test_a_damping_target_also_writes_its_curves_as_csv(results, tmp_path):
    target = results[DampingTarget]
    frame = pd.read_csv(target.save(tmp_path / "curves.csv"))
    np.testing.assert_allclose(frame["zeta_hertz"], target.to_frame()["zeta_hertz"], rtol=1e-7)
    with pytest.raises(ValueError, match="must end in .csv or .nc"):
        target.save(tmp_path / "curves.txt")
