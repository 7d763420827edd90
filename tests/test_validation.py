"""Tests of microimpact.analysis.kharaz: the model against the Kharaz et al. (2001) oblique impacts.

This is real measured data (data/kharaz2001_oblique.csv), so the tests pin the agreement where the
model's physics applies (rigid-body sliding, incidence above 30 deg) and the disagreement where the
tangentially rigid assumption shows (small angles), computed, never hard-coded.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from microimpact.analysis.kharaz import (
    default_kharaz_path,
    kharaz_comparison,
    kharaz_summary,
    kharaz_table,
    read_kharaz,
)

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data" / "kharaz2001_oblique.csv"  # beside the repo


@pytest.fixture(scope="module")
def ds():
    return kharaz_comparison()


def test_uses_the_bundled_copy(ds):
    # the package's copy (importlib.resources), byte-identical to the repository's data/ copy
    # (tests/test_packaging.py), so the comparison works from an installed wheel
    import microimpact

    assert default_kharaz_path() == Path(microimpact.__file__).parent / "data" / "kharaz2001_oblique.csv"
    assert ds.attrs["source"] == str(default_kharaz_path())
    if SHARED.is_file():  # the copy is unchanged
        assert default_kharaz_path().read_bytes() == SHARED.read_bytes()


def test_sliding_regime_agreement(ds):
    # Above 30 deg the measured tangential restitution follows rigid-body sliding theory (Kharaz
    # et al.). Bound 0.03: the digitized values are read to about +-0.01, and the 30.1 deg point
    # lies next to the model's sliding/rolling boundary (32.8 deg for f = 0.092, e_n = 1), where the
    # rigid model has a kink that the real (compliant) contact rounds off by ~0.03.
    assert ds.attrs["rms_tangential_restitution_sliding"] < 0.03
    assert ds.attrs["rms_tangential_restitution_sliding_fitted"] < 0.03
    # rebound angle: digitized to about 0.5 deg; 1 deg bound
    assert ds.attrs["rms_rebound_angle_sliding"] < 1.0
    # rebound spin above 30 deg within 10 % of the measured ~400-600 rad/s
    meas = ds["rebound_spin_measured"].values[ds["rebound_spin_sliding"].values == 1]
    assert ds.attrs["rms_rebound_spin_sliding"] < 0.1 * meas.mean()


def test_small_angles_show_tangential_compliance(ds):
    # below 30 deg the errors are several times larger than in the sliding regime
    assert ds.attrs["rms_tangential_restitution_below"] > 3 * ds.attrs["rms_tangential_restitution_sliding"]
    a = ds["tangential_restitution_incidence_deg"].values
    model = ds["tangential_restitution_model"].values
    meas = ds["tangential_restitution_measured"].values
    rolling = float(ds["rolling_limit"])
    below = a < float(ds["transition_angle"])
    # the rigid model ends rolling: exactly 5/7 below the transition angle
    np.testing.assert_allclose(model[below], 5.0 / 7.0, rtol=1e-9)
    # measured ABOVE the rolling limit at the smallest angles (elastic tangential recovery) ...
    assert np.all(meas[a < 5.0] > rolling)
    # ... and below it around 10-20 deg (microslip), which the rigid model cannot give either
    assert np.all(meas[(a > 8.0) & (a < 25.0)] < rolling)


def test_sliding_formula(ds):
    # rigid-body sliding: v_t,out / v_t,in = 1 - f (1 + e_n) / tan(alpha) above the transition
    a = ds["tangential_restitution_incidence_deg"].values
    above = a > float(ds["transition_angle"])
    f, e = float(ds["friction"]), float(ds["e_n_model"])
    expected = 1.0 - f * (1.0 + e) / np.tan(np.radians(a[above]))
    np.testing.assert_allclose(ds["tangential_restitution_model"].values[above], expected, rtol=1e-6)
    assert math.degrees(math.atan(3.5 * f * (1 + e))) == pytest.approx(float(ds["transition_angle"]))


def test_fitted_friction(ds):
    f, s = float(ds["fitted_friction"]), float(ds["fitted_friction_stderr"])
    assert np.isfinite(s) and 0 < s < 0.02
    # the source's 0.092 is consistent with the sliding-regime data
    assert abs(f - 0.092) < 3 * s


def test_spin_sign_convention(ds):
    # forward (top-spin) rolling in +t is omega_t' < 0 in the toolkit frame; compared as |omega|
    w = ds["omega_out_tp_model"].values
    assert np.all(w < 0)
    np.testing.assert_allclose(np.abs(w), ds["rebound_spin_model"].values, rtol=1e-12)


def test_normal_restitution_option():
    d = kharaz_comparison(normal_restitution=0.95, fit_friction=False)
    assert float(d["e_n_model"]) == pytest.approx(0.95, abs=1e-8)
    assert float(d["zeta_hertz"]) > 0
    assert "rebound_angle_model_fitted" not in d
    assert float(kharaz_comparison(fit_friction=False)["e_n_model"]) == pytest.approx(1.0, abs=1e-8)


def test_tables(ds):
    t = kharaz_table(ds)
    assert len(t) == 24 and set(t["quantity"]) == {"tangential_restitution", "rebound_spin", "rebound_angle"}
    np.testing.assert_allclose(t["difference"], t["model"] - t["measured"])
    s = kharaz_summary(ds)
    # three regimes (above and below the threshold, all angles) per quantity; the compliant model
    # (issue 14) has an RMS in each
    assert len(s) == 9 and s["rms_nominal_friction"].notna().all() and s["rms_compliant"].notna().all()


def test_read_errors_name_the_line(tmp_path):
    text = default_kharaz_path().read_text().replace("0.79344,1", "0.79344,percent", 1)
    bad = tmp_path / "k.csv"
    bad.write_text(text)
    with pytest.raises(ValueError, match=r"line 2, column 'units'"):
        read_kharaz(bad)


def test_model_curves_rigid_body_limits(tmp_path):
    # non-adhesive, undamped (e_n = 1), Coulomb f = 0.092: rolling ends the impact below
    # tan(alpha) = (7/2) f (1 + e_n), where v_t,out / v_t,in = 5/7 exactly
    import pandas as pd

    path = tmp_path / "k.csv"
    pd.DataFrame({"quantity": ["rebound_spin"], "incidence_angle_deg": [10.0], "value": [200.0],
                  "units": ["rad s-1"]}).to_csv(path, index=False)
    ds = kharaz_comparison(path, fit_friction=False, curve_incidence_deg=[10.0, 20.0, 60.0])
    tr = ds["tangential_restitution_curve"]
    np.testing.assert_allclose(tr.sel(curve_incidence_deg=[10.0, 20.0]), 5 / 7, rtol=1e-6)
    # sliding throughout at 60 deg: v_t,out = v_t,in - f (1 + e) v_n
    a = math.radians(60.0)
    expect = 1 - 0.092 * 2 * math.cos(a) / math.sin(a)
    assert float(tr.sel(curve_incidence_deg=60.0)) == pytest.approx(expect, rel=1e-6)
    assert ds["rebound_spin_measured"].values.tolist() == [200.0]


def test_model_curves_default_grid(ds):
    grid = ds["curve_incidence_deg"]
    assert grid.attrs["units"] == "degree" and grid.attrs["long_name"]
    np.testing.assert_allclose(grid.values, np.arange(0.25, 85.0001, 0.25))
    for q in ("tangential_restitution", "rebound_spin", "rebound_angle"):
        for name in (f"{q}_curve", f"{q}_curve_fitted"):
            assert ds[name].dims == ("curve_incidence_deg",)
            assert ds[name].attrs["units"] == ds[f"{q}_measured"].attrs["units"] and ds[name].attrs["long_name"]
        # the curve passes through the model values at the measured angles inside the grid; linear
        # interpolation on its 0.25 deg grid errs by ~(h^2/8)|f''| (measured: 3.4e-6 relative at
        # most); 1e-4 keeps a 30x margin while a wrong curve would be off by percents
        a = ds[f"{q}_incidence_deg"].values
        inside = (a >= grid.values[0]) & (a <= grid.values[-1])
        assert inside.sum() >= 5
        np.testing.assert_allclose(np.interp(a[inside], grid.values, ds[f"{q}_curve"].values),
                                   ds[f"{q}_model"].values[inside], rtol=1e-4)
