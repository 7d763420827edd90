"""Tests of microimpact.analysis.flags: per-measurement rotation/angle/capture flags."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from microimpact.analysis.flags import DEFAULT_THRESHOLDS, fibonacci_sphere, flag_measurements, write_flags
from microimpact.dynamics.nonlinear import capture_velocity
from microimpact.io import default_materials_path, read_impacts, read_materials

DATA = Path(__file__).resolve().parents[1] / "data" / "synthetic_microspheres.csv"  # SYNTHETIC data


@pytest.fixture(scope="module")
def pair():
    return read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]


@pytest.fixture(scope="module")
def table():
    df = read_impacts(DATA)
    sub = df[df["radius"] > 2e-6].iloc[::4].reset_index(drop=True)  # 2 radii, 13 impacts
    sub.attrs = dict(df.attrs)
    return sub


@pytest.fixture(scope="module")
def flags(table, pair):
    return flag_measurements(table, pair)


def test_fibonacci_sphere():
    d = fibonacci_sphere(12)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0)
    assert np.all(np.abs(d.mean(axis=0)) < 0.1)  # nearly balanced
    for k in range(3):
        assert d[:, k].min() < -0.5 and d[:, k].max() > 0.5  # every spin component occurs


def test_keys_point_back_to_rows(flags, table):
    np.testing.assert_array_equal(flags["row"].values, table["row"].values)
    df = flags.to_dataframe()
    assert len(df) == len(table)
    for v in ("rotation_sensitive", "angle_sensitive", "near_capture", "mu_t_min_spin", "K_L_max_angle"):
        assert v in df.columns
    for k, v in DEFAULT_THRESHOLDS.items():
        assert flags.attrs[f"threshold_{k}"] == v


def test_spreads(flags):
    # e_n does not depend on spin (the normal motion decouples): zero spread over spin
    np.testing.assert_allclose(flags["e_n_min_spin"], flags["e_n_max_spin"], rtol=1e-12)
    # sampled ranges contain the nominal value
    for c in ("mu_t", "mu_tp", "K_L", "K_t", "e_n"):
        assert np.all(flags[f"{c}_min"] <= flags[c] + 1e-12) and np.all(flags[c] <= flags[f"{c}_max"] + 1e-12)
    # spin up to the rolling spin makes the impulse ratio swing by about +-f or more
    assert np.all(flags["mu_t_max_spin"] - flags["mu_t_min_spin"] > 0.15)


def test_rotation_flag_needs_a_measured_quantity_that_moves(flags, table, pair):
    # e_n-only rows: spin changes mu_t, mu_t' and K_L a lot (the paper's point, kept in the spreads),
    # but e_n not at all (the normal motion decouples), and e_n is all these rows measured
    assert (flags["mu_t_max_spin"] - flags["mu_t_min_spin"] > 0.05).all()
    assert not flags["rotation_sensitive"].any()
    np.testing.assert_allclose(flags["e_n_max_spin"], flags["e_n_min_spin"], rtol=1e-12)
    small = flag_measurements(table, pair, spin_bound=1.0)
    assert not small["rotation_sensitive"].any()
    assert small.attrs["spin_bound_source"] == "argument"


def test_near_capture(flags, table, pair):
    vc = np.array([capture_velocity(pair.contact(r)) for r in table["radius"]])
    np.testing.assert_allclose(flags["capture_velocity"], vc)
    ratio = table["normal_speed"].to_numpy() / vc
    np.testing.assert_allclose(flags["capture_speed_ratio"], ratio)
    np.testing.assert_array_equal(flags["near_capture"].values, (ratio < 1.5).astype(np.int8))
    assert flags["near_capture"].any() and not flags["near_capture"].all()


def test_angle_uncertainty_sources(flags, table, pair):
    np.testing.assert_allclose(flags["angle_uncertainty_deg"], 1.0)  # the file's column
    assert "table column" in flags.attrs["angle_uncertainty_source"]
    # with 1 deg around normal incidence e_n hardly moves: not angle sensitive
    assert not flags["angle_sensitive"].any()
    # a 40 deg uncertainty cuts v_n by 23 %: flagged exactly where that moves e_n by more than the row's
    # uncertainty, by an engine solve at v cos(40 deg) written here (not the flags' own samples)
    from microimpact.solvers import engine

    wide = flag_measurements(table, pair, angle_uncertainty_deg=40.0, spin_bound=0.0)
    expected = []
    for _, row in table.iterrows():
        c = pair.contact(row["radius"])
        vn = row["speed"] * np.cos(np.radians(row["incidence_deg"]))
        e = engine.solve_normal_many(c, np.array([vn, vn * np.cos(np.radians(40.0))]))["e_n"]
        expected.append(abs(e[1] - e[0]) > row["e_n_uncertainty"])
    np.testing.assert_array_equal(wide["angle_sensitive"].values.astype(bool), np.array(expected))
    assert 0 < sum(expected) < len(expected)  # near capture e_n is steep, far above it flat
    low = wide["e_n_shift_low_angle"].values
    assert (low <= 0).all() and (low[np.array(expected)] < 0).all()  # a larger angle lowers v_n and e_n
    no_col = table.drop(columns=["incidence_deg_uncertainty"])
    d = flag_measurements(no_col.iloc[:2], pair, spin_bound=0.0)
    np.testing.assert_allclose(d["angle_uncertainty_deg"], 2.0)


def test_thresholds(table, pair):
    d = flag_measurements(table.iloc[:3], pair, thresholds={"near_capture_ratio": 1e9, "mu": 10.0, "K_L": 10.0})
    assert d["near_capture"].all() and not d["rotation_sensitive"].any()
    assert d.attrs["threshold_near_capture_ratio"] == 1e9
    with pytest.raises(ValueError, match="unknown threshold"):
        flag_measurements(table, pair, thresholds={"bogus": 1})


def test_fit_or_contact_accepted(table, pair):
    c = pair.contact(3.45e-6)
    a = flag_measurements(table.iloc[:3], c, spin_bound=0.0)
    b = flag_measurements(table.iloc[:3], pair, spin_bound=0.0)
    np.testing.assert_allclose(a["e_n"], b["e_n"], rtol=1e-9)


def test_write_flags(flags, tmp_path):
    csv, nc = write_flags(flags, tmp_path / "flags.csv", tmp_path / "flags.nc")
    back = pd.read_csv(csv)
    assert list(back.columns)[0] == "row"
    np.testing.assert_array_equal(back["row"], flags["row"].values)
    np.testing.assert_array_equal(back["rotation_sensitive"], flags["rotation_sensitive"].values)
    with xr.open_dataset(nc) as ds:
        assert ds["near_capture"].attrs["flag_meanings"] == "far near_capture"
        assert ds.attrs["threshold_mu"] == DEFAULT_THRESHOLDS["mu"]
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
