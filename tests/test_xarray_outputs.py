"""simulate_many's Dataset is xarray-correct (issue 28, part 3): every dimension has an index
coordinate and can be ``.sel``-ed, DataArray inputs keep their dimensions, plain arrays get
dimensions named after the input that varies along them, and a contact field (the radius) can
vary along a dimension of its own. The values are checked against single simulate_impact calls
(a different code path: one impact, no batching, no family)."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import microimpact as mi
from microimpact.presets import WALL_1990


def _single(contact, speed, incidence_deg=0.0):
    return mi.simulate_impact(contact, speed=float(speed), incidence_deg=float(incidence_deg))


def test_the_readmes_plain_array_example_has_named_selectable_dimensions():
    ds = mi.simulate_many(WALL_1990, speed=[0.5, 1, 2, 5, 10], incidence_deg=[[0], [15], [30]])
    assert dict(ds.sizes) == {"incidence_deg": 3, "speed": 5}
    assert ds.indexes["speed"].tolist() == [0.5, 1, 2, 5, 10]
    assert ds.indexes["incidence_deg"].tolist() == [0, 15, 30]
    cell = ds.sel(speed=2, incidence_deg=15)
    r = _single(WALL_1990, 2, 15)
    # same engine and tolerance; the batch shares the normal solve of one speed: 1e-12 of round-off
    assert float(cell["mu_t"]) == pytest.approx(r.mu_t, rel=1e-12, abs=0.0)
    assert float(cell["e_n"]) == pytest.approx(r.e_n, rel=1e-12, abs=0.0)
    assert ds["speed"].attrs["units"] == "m s-1"


def test_the_readmes_dataarray_example_without_coordinates_gets_an_index():
    """speed=xr.DataArray(v, dims="speed") with no coordinate made a 2-D variable named speed and
    .sel(speed=10, method="nearest") failed."""
    v, a = np.array([0.5, 2.0, 10.0]), np.array([0.0, 30.0])
    ds = mi.simulate_many(WALL_1990, speed=xr.DataArray(v, dims="speed"), incidence_deg=xr.DataArray(a, dims="alpha"))
    assert dict(ds.sizes) == {"speed": 3, "alpha": 2}
    assert ds["speed"].dims == ("speed",) and ds.indexes["alpha"].tolist() == [0.0, 30.0]
    near = ds.sel(speed=9.0, method="nearest").sel(alpha=30.0)
    assert float(near["e_n"]) == pytest.approx(_single(WALL_1990, 10.0, 30.0).e_n, rel=1e-12, abs=0.0)


def test_dimensions_without_distinct_values_get_a_plain_index():
    ds = mi.simulate_many(WALL_1990, speed=[1.0, 1.0, 2.0])
    assert list(ds.sizes) == ["impact"] and ds.indexes["impact"].tolist() == [0, 1, 2]
    ds = mi.simulate_many(WALL_1990, speed=[1.0, 2.0], incidence_deg=[10.0, 20.0])  # paired, not a grid
    assert list(ds.sizes) == ["impact"] and float(ds["incidence_deg"].sel(impact=1)) == 20.0


def test_a_dataarray_coordinate_is_kept():
    ds = mi.simulate_many(WALL_1990, speed=xr.DataArray([1.0, 2.0], dims="run", coords={"run": [7, 9]}))
    assert ds.indexes["run"].tolist() == [7, 9]


@pytest.mark.parametrize("radius", [xr.DataArray([1e-6, 3e-6, 5e-6], dims="radius"), [1e-6, 3e-6, 5e-6]])
def test_the_radius_varies_along_its_own_dimension(radius, tmp_path):
    ds = mi.simulate_many(WALL_1990, speed=xr.DataArray([0.5, 2.0], dims="speed"), radius=radius)
    assert dict(ds.sizes) == {"radius": 3, "speed": 2}
    for r in (1e-6, 5e-6):
        for v in (0.5, 2.0):
            expected = _single(WALL_1990.with_(radius=r), v).e_n
            assert float(ds["e_n"].sel(radius=r, speed=v)) == pytest.approx(expected, rel=1e-12, abs=0.0)
    assert ds.attrs["contact_radius"].tolist() == [1e-6, 3e-6, 5e-6]
    from microimpact.io import write_netcdf

    back = xr.open_dataset(write_netcdf(ds, tmp_path / "r.nc"))
    assert float(back["e_n"].sel(radius=3e-6, speed=2.0)) == float(ds["e_n"].sel(radius=3e-6, speed=2.0))
    back.close()


def test_contact_fields_are_checked():
    with pytest.raises(TypeError, match="not a Contact field"):
        mi.simulate_many(WALL_1990, speed=1.0, raduis=[1e-6])
    with pytest.raises(ValueError, match="one dimension"):
        mi.simulate_many(WALL_1990, speed=1.0, radius=[[1e-6, 2e-6]])
