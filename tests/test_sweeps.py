"""Sweeps of Table 2 (Cheng, Brach & Dunn 2002, doi:10.1080/02786820290092221): layout, files, chunks, physics."""

import json
import math

import numpy as np
import pytest
import xarray as xr

import microimpact
from microimpact import presets
from microimpact.studies import sweeps
from microimpact.solvers.impact import RESULT_VARIABLES

C = presets.WALL_1990
SPEEDS = [0.5, 1.2, 1.6, 3.0, 10.0]  # spans the capture velocity (about 1.45 m/s for Table 1 row 2)


def small(case, **changes):
    """The Table 2 case with a few speeds only (keeps the tests fast)."""
    spec = dict(sweeps.TABLE2_CASES[case])
    spec["speed"] = list(SPEEDS)
    spec.update(changes)
    return spec


@pytest.fixture(scope="module")
def case21():
    return sweeps.run_sweep(C, small("2.1", incidence_deg={"start": 0, "stop": 30, "step": 15}), case="2.1")


# ----------------------------------------------------------------------------- specs
def test_table2_cases_expand_to_the_paper_grids():
    r = sweeps.resolve_spec(sweeps.TABLE2_CASES["2.1"])
    assert r["speed"][0] == 0.2 and r["speed"][-1] == 10.0
    np.testing.assert_allclose(r["incidence_deg"], [0, 5, 10, 15, 20, 25, 30])
    r = sweeps.resolve_spec(sweeps.TABLE2_CASES["2.5"])
    np.testing.assert_allclose(r["friction"], np.arange(10) / 10, atol=1e-12)
    assert r["omega_t"] == r["omega_tp"] == 2.9e6
    r = sweeps.resolve_spec(sweeps.TABLE2_CASES["2.2"])
    assert r["omega_tp"][-1] == pytest.approx(1.8e5) and r["incidence_deg"] == 0.0


def test_spec_forms():
    r = sweeps.resolve_spec({"speed": {"start": 0.1, "stop": 10, "num": 3, "spacing": "log"}, "omega_t": "2.9e5",
                             "friction": [0.1, 0.5]})
    np.testing.assert_allclose(r["speed"], [0.1, 1.0, 10.0])
    assert r["omega_t"] == 2.9e5  # PyYAML reads 2.9e5 as text
    np.testing.assert_allclose(r["friction"], [0.1, 0.5])


@pytest.mark.parametrize(
    "spec, words",
    [
        ({}, ["'speed'", "required"]),
        ({"speed": 1, "sped": 2}, ["sped", "accepted"]),
        ({"speed": {"start": 1, "stop": 2}}, ["'speed'", "num", "step"]),
        ({"speed": {"start": 1, "stop": 2, "num": 0}}, ["'speed'", "'num'"]),
        ({"speed": {"start": 0, "stop": 2, "num": 3, "spacing": "log"}}, ["'speed'", "log"]),
        ({"speed": {"start": 1, "stop": 2, "num": 3, "spacing": "cubic"}}, ["'spacing'"]),
        ({"speed": [1, -1]}, ["'speed'", "> 0"]),
        ({"speed": 1, "incidence_deg": 90}, ["'incidence_deg'", "[0, 90)"]),
        ({"speed": 1, "friction": "lots"}, ["'friction'", "lots"]),
        ({"speed": [1, 1]}, ["'speed'", "distinct"]),
        ({"speed": 1, "omega_t": True}, ["'omega_t'", "number"]),
        ({"speed": 1, "omega_t": [[1, 2]]}, ["'omega_t'", "flat"]),
    ],
)
def test_bad_specs_name_the_key(spec, words):
    with pytest.raises(sweeps.SweepSpecError) as err:
        sweeps.resolve_spec(spec)
    for w in words:
        assert w in str(err.value)


# ----------------------------------------------------------------------------- layout
def test_one_dimension_per_swept_quantity(case21):
    ds = case21
    assert dict(ds.sizes) == {"speed": len(SPEEDS), "incidence_deg": 3}
    assert ds["e_n"].dims == ("speed", "incidence_deg")
    np.testing.assert_allclose(ds["speed"], SPEEDS)
    np.testing.assert_allclose(ds["incidence_deg"], [0, 15, 30])
    for fixed in ("azimuth_deg", "omega_n", "omega_t", "omega_tp", "friction"):
        assert ds[fixed].ndim == 0
    assert float(ds["friction"]) == C.friction
    assert set(RESULT_VARIABLES) <= set(ds.data_vars)


def test_every_variable_has_units_and_long_name(case21):
    for name, var in case21.variables.items():
        assert var.attrs.get("units"), name
        assert var.attrs.get("long_name"), name
    assert case21["speed"].attrs["units"] == "m s-1"
    assert case21["incidence_deg"].attrs["units"] == "degree"


def test_global_attributes(case21):
    a = case21.attrs
    assert a["Conventions"] == "CF-1.10"
    assert a["source"] == f"microimpact {microimpact.__version__}"
    assert "10.1080/02786820290092221" in a["references"]
    assert "run_sweep" in a["history"] and a["history"][:4].isdigit()
    assert "2.1" in a["title"]
    assert a["contact_radius"] == C.radius and a["contact_zeta_adhesion"] == C.zeta_adhesion
    spec = json.loads(a["sweep_spec"])
    assert spec["speed"] == SPEEDS and spec["incidence_deg"] == {"start": 0, "stop": 30, "step": 15}


def test_run_sweep_by_case_name_uses_the_default_grid():
    ds = sweeps.run_sweep(C, case="2.4", capture_speed=False)
    assert dict(ds.sizes) == {"speed": 50, "friction": 10}
    with pytest.raises(sweeps.SweepSpecError, match="case"):
        sweeps.run_sweep(C, case="9.9")


# ----------------------------------------------------------------------------- files
def test_netcdf_round_trip(case21, tmp_path):
    path = tmp_path / "case21.nc"
    assert sweeps.save_sweep(case21, path) == path
    assert not [p for p in tmp_path.iterdir() if p.name != "case21.nc"]  # no temporary file left
    with xr.open_dataset(path) as back:
        back = back.load()
        assert back["e_n"].encoding.get("zlib") is True
    written = back.attrs["history"].splitlines()  # the writer appends a line for the write
    assert written[:-1] == case21.attrs["history"].splitlines() and "write_netcdf" in written[-1]
    back.attrs["history"] = case21.attrs["history"]
    xr.testing.assert_identical(back, case21)  # values (NaN, inf), coordinates, all attributes
    assert back.attrs["sweep_spec"] == case21.attrs["sweep_spec"]
    xr.testing.assert_identical(sweeps.load_sweep(path).assign_attrs(history=case21.attrs["history"]), case21)


# ----------------------------------------------------------------------------- chunks
@pytest.mark.parametrize("along, n", [("speed", 3), ("speed", 5), ("friction", 2)])
def test_chunked_equals_unchunked(along, n):
    spec = small("2.5", friction=[0.0, 0.3, 0.9])
    whole = sweeps.run_sweep(C, spec, case="2.5", capture_speed=False)
    chunks = sweeps.split_spec(spec, n, along=along)
    assert len(chunks) == n
    json.dumps(chunks)  # a chunk spec is plain data (can go to a job's config file)
    parts = [sweeps.run_sweep(C, s, case="2.5", capture_speed=False) for s in chunks]
    combined = sweeps.combine_sweeps(parts[::-1])  # order does not matter
    assert "combine_sweeps" in combined.attrs["history"]
    a, b = combined.copy(), whole.copy()
    for key in ("history", "normal_solves"):  # when and how much work: normal_solves adds up over
        a.attrs.pop(key), b.attrs.pop(key)  # the chunks (split along friction, each chunk solves every speed)
    if along != "speed":
        # The engine follows a captured sphere's tail only as far as the batch's tangential outcomes
        # need, so the tail integrals of *captured* impacts (friction impulse, dissipated energy) depend
        # on which friction values share the batch. Every coefficient and final velocity is identical.
        cap = whole["outcome"] == 1
        for name in ("friction_impulse", "dissipated_energy"):
            xr.testing.assert_identical(a[name].where(~cap), b[name].where(~cap))
            a, b = a.drop_vars(name), b.drop_vars(name)
    xr.testing.assert_identical(a, b)


def test_split_and_combine_errors():
    spec = small("2.1")
    with pytest.raises(sweeps.SweepSpecError, match="friction"):
        sweeps.split_spec(spec, 2, along="friction")
    with pytest.raises(sweeps.SweepSpecError, match="n_chunks"):
        sweeps.split_spec(spec, 99)
    parts = [sweeps.run_sweep(C, s, capture_speed=False) for s in sweeps.split_spec(spec, 2)]
    with pytest.raises(ValueError, match="chunks 0..1"):
        sweeps.combine_sweeps(parts[:1])


# ----------------------------------------------------------------------------- physics across sweeps
def test_case21_normal_impact_has_no_tangential_effect(case21):
    # alpha = 0 without spin: no slip, no friction force, so mu_t = 0 and, for a rebound,
    # K_L = K_t = 1 - e_n^2 (Eqs. (24)-(25) with only the normal velocity changing)
    ds = case21.sel(incidence_deg=0.0)
    reb = ds["outcome"] == 0
    np.testing.assert_array_equal(ds["mu_t"].where(reb, 0.0), 0.0)
    np.testing.assert_allclose(ds["K_L"].where(reb, drop=True), (1 - ds["e_n"] ** 2).where(reb, drop=True), rtol=1e-12)
    np.testing.assert_allclose(ds["K_L"], ds["K_t"], rtol=1e-12)


def test_case21_capture_boundary_and_gaps(case21):
    # captured below the capture velocity (e_n = 0 and mu undefined, as the paper leaves them out);
    # the boundary in v moves to v_c / cos(alpha)
    v_c = float(case21["capture_normal_speed"])
    assert 1.3 < v_c < 1.6
    alpha = np.radians(case21["incidence_deg"])
    expect = case21["speed"] * np.cos(alpha) < v_c
    np.testing.assert_array_equal(case21["outcome"].values == 1, expect.transpose(*case21["outcome"].dims).values)
    cap = case21["outcome"] == 1
    assert (case21["e_n"].where(cap, 0.0) == 0.0).all()
    assert np.isnan(case21["mu_t"].values[cap.values]).all()
    assert np.isfinite(case21["mu_t"].values[~cap.values]).all()


def test_case22_restitution_does_not_depend_on_spin():
    # Fig. 10 claim: e_n falls on one curve for every omega_t'. In this model the normal motion is
    # decoupled from the tangential and rotational state, and each normal speed is solved once,
    # so e_n is the same number, not just close.
    ds = sweeps.run_sweep(C, small("2.2"), case="2.2", capture_speed=False)
    e = ds["e_n"].values
    assert (e == e[:, :1]).all()
    # ... while mu_t does depend on it (rebounds only): zero without spin, growing with spin
    reb = ds.isel(speed=slice(2, None))
    mu = np.abs(reb["mu_t"].values)
    assert (mu[:, 0] == 0).all() and (np.diff(mu, axis=1) > 0).all()


def test_case24_mu_curves_coincide_when_the_sphere_ends_rolling():
    # Fig. 13 claim: with f > 0 the sphere ends rolling, so the tangential velocity change is
    # -(2/7) of the initial slip whatever f is: mu_t, mu_t' are the same for every f > 0.
    ds = sweeps.run_sweep(C, small("2.4", friction=[0.0, 0.1, 0.5, 0.9]), case="2.4", capture_speed=False)
    reb = ds.where(ds["outcome"] == 0, drop=True)
    rolling = reb.sel(friction=[0.1, 0.5, 0.9])
    ends_rolling = rolling["slip_ended"] == 1
    assert ends_rolling.sel(friction=[0.5, 0.9]).all()
    # Not quite the paper's "all curves": just above capture (1.6 m/s) f = 0.1 cannot stop the
    # 1.41 m/s slip ((7/2) f J / m < |u0|), so that curve leaves the common one there.
    assert not bool(ends_rolling.sel(speed=1.6, friction=0.1))
    for name in ("mu_t", "mu_tp"):
        ref = rolling[name].sel(friction=0.9).broadcast_like(rolling[name])
        np.testing.assert_allclose(rolling[name].where(ends_rolling), ref.where(ends_rolling), rtol=1e-9, atol=1e-15)
    assert (np.abs(rolling["mu_t"].sel(speed=1.6, friction=0.1)) < np.abs(rolling["mu_t"].sel(speed=1.6, friction=0.9)))
    # the slip (r omega_t', -r omega_t) = (1, -1) m/s is symmetric, so mu_t' = -mu_t
    np.testing.assert_allclose(rolling["mu_tp"], -rolling["mu_t"], rtol=1e-12)
    # f = 0: no tangential impulse at all
    assert (reb["mu_t"].sel(friction=0.0) == 0).all()
    # and e_n does not depend on f (decoupled normal motion)
    assert (ds["e_n"] == ds["e_n"].isel(friction=0)).all()


def test_case25_high_spin_keeps_sliding_at_low_friction():
    # Fig. 14: with omega = 2.9e6 rad/s (slip about 14 m/s) small f cannot stop the slip; the
    # impulse ratio then grows with f (|mu_t| = f / sqrt(2) for a rebound at high speed, where
    # snap-on/off add little)
    ds = sweeps.run_sweep(C, small("2.5", friction=[0.1, 0.2]), case="2.5", capture_speed=False)
    fast = ds.sel(speed=10.0)
    assert (fast["slip_ended"] == 0).all()
    mu = np.abs(fast["mu_t"].values)
    assert mu[1] > mu[0]
    np.testing.assert_allclose(mu / fast["friction"].values, 1 / math.sqrt(2), rtol=0.1)

