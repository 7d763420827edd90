"""The fitted material drives the simulations (microimpact.studies.material) and every result says
which parameters made it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import microimpact as mi
from microimpact.analysis.fit_result import DampingFit
from microimpact.model.parameters import TABLE1_ROW2, TABLE2_CASES
from microimpact.presets import WALL_1990
from microimpact.io.provenance import source_of_fit, stamp_parameters
from microimpact.presets import named_contact
from microimpact.studies.material import material_dynamics, material_sweep, measured_speed_range
from microimpact.studies.sweeps import case_spec

#: a fit of the bundled synthetic data, from the regression baseline (a real fit.nc file)
FIT = Path(__file__).parent / "regression" / "baseline" / "fit.nc"


@pytest.fixture(scope="module")
def fit():
    return xr.load_dataset(FIT)


def test_named_contact_by_preset_and_by_fields():
    contact, source = named_contact("wall1990")
    assert contact is WALL_1990 is TABLE1_ROW2 and source == "preset: wall1990"
    fields = {"radius": 2e-6, "density": 1000.0, "stiffness": 1e9, "adhesion_line_force": 1.0}
    contact, source = named_contact(fields)
    assert contact.radius == 2e-6 and source == "config"
    with pytest.raises(ValueError, match="unknown preset"):
        named_contact("wall1991")


def test_case_spec_keeps_the_one_grid_and_says_what_the_config_changed():
    assert case_spec("2.1") == dict(TABLE2_CASES["2.1"])
    changed = case_spec("2.1", {"speed": [1.0, 2.0]})
    assert changed["speed"] == [1.0, 2.0] and changed["incidence_deg"] == TABLE2_CASES["2.1"]["incidence_deg"]
    assert "grid changed by the configuration: speed" in changed["description"]
    assert TABLE2_CASES["2.1"]["speed"] == {"start": 0.2, "stop": 10.0, "num": 50}  # not mutated
    with pytest.raises(ValueError, match="known cases"):
        case_spec("2.9")


def test_stamp_parameters_one_contact_and_one_per_size():
    ds = xr.Dataset({"x": ("radius", [1.0, 2.0])})
    one = stamp_parameters(ds, WALL_1990, "preset: wall1990")
    assert one.attrs["contact_zeta_adhesion"] == 29.0 and one.attrs["parameter_source"] == "preset: wall1990"
    assert one.attrs["contact_damping_reference_speed"] == "per-impact normal speed"
    two = stamp_parameters(ds, [WALL_1990.at_radius(1e-6), WALL_1990], "config")
    np.testing.assert_array_equal(two.attrs["contact_radius"], [1e-6, 3.45e-6])
    assert "parameter_source" not in ds.attrs  # the input is not modified


def test_material_sweep_uses_the_fitted_contact_at_every_measured_size(fit):
    model = DampingFit.from_dataset(fit)
    spec = dict(case_spec("2.1"), incidence_deg=[0.0, 20.0])
    ds = material_sweep(fit, spec, case="2.1")
    radii = np.unique(fit["radius"].values)
    np.testing.assert_array_equal(ds["radius"].values, radii)
    lo, hi = measured_speed_range(fit)
    assert ds["speed"].values[[0, -1]].tolist() == pytest.approx([lo, hi], rel=1e-14)
    assert ds.sizes["speed"] == 50  # the case's number of speeds, moved onto the measured range
    assert ds.attrs["parameter_source"] == source_of_fit(fit) == f"fit: synthetic_microspheres.csv {fit.attrs['fit_sha256']}"
    assert fit.attrs["fit_sha256"] in ds.attrs["parameter_source"]
    np.testing.assert_allclose(ds.attrs["contact_zeta_hertz"], model.zeta_hertz, rtol=0)
    # each size's values are those of a direct simulation of that size's fitted contact
    r = float(radii[1])
    direct = mi.simulate_many(model.contact(r), ds["speed"].values, 20.0)
    np.testing.assert_array_equal(ds["e_n"].sel(radius=r, incidence_deg=20.0).values, direct["e_n"].values)
    # f0 follows the radius from one work of adhesion (Eq. 7)
    f0 = np.asarray(ds.attrs["contact_adhesion_line_force"])
    np.testing.assert_allclose(f0 / f0[-1], (radii / radii[-1]) ** (1 / 3), rtol=1e-12)


def test_material_dynamics_per_size(fit):
    ds = material_dynamics(fit)
    assert ds["capture_velocity"].attrs["units"] == "m s-1"
    # smaller spheres stick at higher speeds (f0 ~ r^(1/3) against m ~ r^3)
    assert np.all(np.diff(ds["capture_velocity"].values) < 0)
    assert ds.attrs["parameter_source"].startswith("fit: ")
