"""CF-1.10 compliance of every kind of result file the pipeline writes (issue 13, part 4).

A small but complete set of real result files is built with the library - a paper sweep, the fit,
a sweep of the fitted material (with a radius dimension), the fitted curves and the material's
dynamics, the measurement flags, the paper's dynamics summary, bifurcation plane and grouped phase
portraits, the Kharaz et al. (2001) comparison, a stress sweep and a small benchmark - each written
by the writer the pipeline uses, and the IOOS compliance-checker's CF-1.10 suite must report no
failed check on any of them. The checker is a test dependency; without it these tests are skipped.

The grouped phase-portrait file must also open as an ``xarray.DataTree``.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from microimpact.io.files import CONVENTIONS, read_netcdf_groups, write_netcdf
from microimpact.io.variables import VARIABLES, udunits

# the result files of every kind take a module fixture of many solves and fits, the checker seconds
# per file: with the extended tests (.ci/run runs them), not the default run
pytestmark = pytest.mark.extended

SUITE = "cf:1.10"

# Reduced grids: the CF form of a file does not depend on its size, and the whole module must stay
# within about 30 s (most of it the numba compile when the cache is cold).
SPEEDS = [0.5, 1.0, 2.0]


@pytest.fixture(scope="module")
def result_files(tmp_path_factory):
    """name -> path of one written result file of each kind."""
    from microimpact.analysis.fitting import fit_damping
    from microimpact.analysis.flags import flag_measurements, write_flags
    from microimpact.analysis.kharaz import kharaz_comparison
    from microimpact.dynamics.nonlinear import (bifurcation_plane, dynamics_summary, phase_portraits,
                                                save_phase_portraits, table1_cases)
    from microimpact.io import read_impacts, read_materials
    from microimpact.io.materials import default_materials_path
    from microimpact.io.provenance import stamp_parameters
    from microimpact.presets import named_contact
    from microimpact.studies import benchmark
    from microimpact.studies.benchmark import BenchmarkConfig, ObliqueCase
    from microimpact.studies.material import material_dynamics, material_sweep, stamp_fitted
    from microimpact.studies.stress import stress_sweep
    from microimpact.studies.sweeps import case_spec, restitution_curves, run_sweep, save_sweep

    from test_fitting import DATA  # the bundled synthetic data (one definition of its path)

    out = tmp_path_factory.mktemp("cf")
    files = {}
    contact, source = named_contact("wall1990")

    sweep = run_sweep(contact, case_spec("2.2", {"speed": SPEEDS, "incidence_deg": [0.0, 45.0]}), case="2.2")
    files["sweep"] = save_sweep(stamp_parameters(sweep, contact, source), out / "sweep.nc")

    materials = read_materials(default_materials_path())
    table = read_impacts(DATA, materials=materials)
    radii = np.unique(table["radius"])[:2]
    table = table[table["radius"].isin(radii)].groupby("radius").head(6).reset_index(drop=True)
    fit = fit_damping(table, materials["ammonium_fluorescein_on_silicon"], confidence_intervals=False)
    files["fit"] = fit.save(out / "fit.nc")
    fit_ds = xr.load_dataset(files["fit"])
    files["fit_curves"] = write_netcdf(stamp_fitted(restitution_curves(fit_ds, SPEEDS), fit_ds),
                                       out / "fit_curves.nc")
    files["material_dynamics"] = write_netcdf(material_dynamics(fit_ds), out / "material_dynamics.nc")
    material = material_sweep(fit_ds, case_spec("2.1", {"speed": SPEEDS}), case="2.1")
    assert "radius" in material.dims
    files["material_sweep"] = save_sweep(material, out / "material_sweep.nc")
    flags = stamp_fitted(flag_measurements(table.head(3), fit, n_spin=4, spin_fractions=(1.0,)), fit_ds)
    write_flags(flags, out / "flags.csv", out / "flags.nc")
    files["flags"] = out / "flags.nc"

    portraits = [stamp_parameters(ds, contact, source) for ds in phase_portraits(contact, [1.0e-5, 1.0])]
    files["phase_portraits"] = save_phase_portraits(portraits, out / "phase_portraits.nc")
    files["dynamics"] = write_netcdf(stamp_parameters(dynamics_summary(contact, SPEEDS), contact, source),
                                     out / "dynamics.nc")
    cases = [(f"simulation, v={v:g} m/s", contact, v) for v in SPEEDS] + table1_cases()
    files["bifurcation"] = write_netcdf(stamp_parameters(bifurcation_plane(cases, n_c1=21, n_c2=21), contact,
                                                         source), out / "bifurcation.nc")

    files["kharaz"] = write_netcdf(kharaz_comparison(curve_incidence_deg=[10.0, 45.0, 80.0]), out / "kharaz.nc")

    stress = stress_sweep(4, 0, reference_every=0).dataset
    stress.attrs["parameter_source"] = "stress: seeded random draw, seed 0, 4 cases"
    files["stress"] = write_netcdf(stress, out / "stress.nc")

    cfg = BenchmarkConfig(
        quick=True, n_speeds=2, max_speed=50.0, capture_margin=1.05,
        engine_levels=(0, 2), scipy_levels=(0,), rkg_levels=(0,),
        oblique=(ObliqueCase(5.0, 30.0, 0.0, 0.0, 0.0, 1.0, 0.5),),
        repeats_single=1, repeats_scipy=1, repeats_batch=1, batch_size=10,
        throughput_impacts=100, throughput_repeats=1, memory_sizes=(50, 100), time_limit=5.0,
        reference_rtols=(1e-10, 1e-11), family_size=10, family_impacts=200, family_check=20,
        family_memory_sizes=(10, 20), fit_rows=20,  # (the class defaults are the full run's millions)
    )
    files["benchmark"] = write_netcdf(benchmark.run_benchmark(config=cfg), out / "benchmark.nc")
    return files


KINDS = ["sweep", "fit", "fit_curves", "material_dynamics", "material_sweep", "flags", "phase_portraits",
         "dynamics", "bifurcation", "kharaz", "stress", "benchmark"]


def _failures(path) -> list[str]:
    """Failed checks of the CF suite on ``path``, as 'priority section: message' lines."""
    runner = pytest.importorskip("compliance_checker.runner",
                                 reason="compliance-checker is not installed (test extra: compliance-checker)")
    suite = runner.CheckSuite()
    suite.load_all_available_checkers()
    if SUITE not in suite.checkers:
        pytest.skip(f"this compliance-checker has no {SUITE} suite")
    dataset = suite.load_dataset(str(path))
    try:
        results, exceptions = suite.run_all(dataset, [SUITE], skip_checks=[])[SUITE]
    finally:  # an HDF5 file left open here crashed a later reader of the same file in this process
        dataset.close()
    # a check that raised did not run: the command-line checker then exits 2 (issue 28: text
    # coordinate variables broke check_coordinate_variables_strict_monotonicity)
    failed = [f"checker exception: {e}" for e in exceptions]
    for r in results:
        score, out_of = r.value if isinstance(r.value, tuple) else (int(bool(r.value)), 1)
        if score < out_of:
            priority = {3: "high", 2: "medium", 1: "low"}[r.weight]
            failed += [f"{priority} {r.name}: {m}" for m in (r.msgs or ["(no message)"])]
    return failed


@pytest.mark.parametrize("kind", KINDS)
def test_result_file_passes_cf_checker(result_files, kind):
    failed = _failures(result_files[kind])
    assert not failed, f"{kind}: " + "\n".join(failed)


def _groups(nc, path=""):
    yield path or "/", nc
    for name, child in nc.groups.items():
        yield from _groups(child, f"{path}/{name}")


@pytest.mark.parametrize("kind", KINDS)
def test_every_variable_in_every_group_is_described(result_files, kind):
    """What the checker looks at only in the root group, checked in every group: long_name, units in
    one UDUNITS style, no _FillValue on coordinates, no int64, text as NetCDF strings; and the
    global Conventions and history."""
    import netCDF4

    with netCDF4.Dataset(result_files[kind]) as nc:
        assert nc.getncattr("Conventions").split()[0] == CONVENTIONS
        assert "microimpact.io.files.write_netcdf" in nc.getncattr("history").splitlines()[-1]
        for where, group in _groups(nc):
            for name, var in group.variables.items():
                what = f"{kind}: {where} {name}"
                attrs = var.ncattrs()
                assert "long_name" in attrs, f"{what} has no long_name"
                if "units" in attrs:
                    assert var.units == udunits(var.units), f"{what}: units {var.units!r}"
                if name in group.dimensions:
                    assert "_FillValue" not in attrs, f"{what}: coordinate variable with _FillValue"
                assert var.dtype not in (np.int64, np.uint64), f"{what} is 64-bit integer"
                assert var.dtype != np.dtype("S1"), f"{what} is a character array, not a NetCDF string"
                if "flag_values" in attrs:
                    assert var.dtype == np.int8 and len(var.flag_values) == len(var.flag_meanings.split())


def test_phase_portraits_open_as_datatree_and_read_back(result_files):
    path = result_files["phase_portraits"]
    tree = xr.open_datatree(path)
    try:
        leaves = [node for node in tree.subtree if node.has_data]
        assert len(leaves) == 2
        assert all("time" in node.dims and "penetration" in node.data_vars for node in leaves)
        assert tree.attrs["Conventions"].startswith(CONVENTIONS)
    finally:
        tree.close()
    portraits = read_netcdf_groups(path)
    assert [ds.sizes["time"] for ds in portraits] == [node.sizes["time"] for node in leaves]


def test_writer_keeps_values_and_input(tmp_path):
    """The CF form changes encodings and attributes only: values read back equal, the Dataset given
    is left as it was, history is appended to, other Conventions are kept."""
    ds = xr.Dataset(
        {"outcome": ("speed", np.array([0, 1, 1], dtype=np.int64)),
         "e_n": ("speed", np.array([0.5, np.nan, 0.25]), {"units": "-"}),
         "label": ("speed", np.array(["a", "bb", "ccc"]))},
        coords={"speed": ("speed", [0.5, 1.0, 2.0], {"units": "m/s"})},
        attrs={"history": "2020-01-01T00:00:00Z made", "Conventions": "CF-1.8 ACDD-1.3", "count": np.int64(3)},
    )
    before = ds.copy(deep=True)
    write_netcdf(ds, tmp_path / "x.nc")
    xr.testing.assert_identical(ds, before)
    back = xr.load_dataset(tmp_path / "x.nc")
    np.testing.assert_array_equal(back["outcome"].values, [0, 1, 1])
    np.testing.assert_array_equal(back["e_n"].values, ds["e_n"].values)
    assert list(back["label"].values) == ["a", "bb", "ccc"]
    assert back["speed"].attrs["units"] == "m s-1" and back["e_n"].attrs["units"] == "1"
    assert back["e_n"].attrs["long_name"] == VARIABLES["e_n"][1]
    assert back.attrs["Conventions"] == "CF-1.10 ACDD-1.3"
    assert back.attrs["history"].splitlines()[0] == "2020-01-01T00:00:00Z made"
    assert len(back.attrs["history"].splitlines()) == 2


def test_writer_refuses_integers_outside_int32(tmp_path):
    ds = xr.Dataset({"n_impacts": ("k", np.array([1, 2**40], dtype=np.int64))})
    with pytest.raises(ValueError, match="int32"):
        write_netcdf(ds, tmp_path / "big.nc")
    assert not (tmp_path / "big.nc").exists()


@pytest.mark.slow  # 20 s or more: `pytest -m slow` (README, Tests), not the default run
def test_every_netcdf_the_cli_writes_passes_the_cf_checker_to_the_end(tmp_path):
    """fit, flags, sweep and target as the CLI writes them: no failed check and no exception of the
    checker (the fit's text coordinate 'parameter' made compliance-checker exit 2)."""
    from pathlib import Path

    from microimpact.cli import main

    lines = (Path(__file__).resolve().parents[1] / "data" / "synthetic_microspheres.csv").read_text().splitlines()
    data = tmp_path / "data.csv"
    data.write_text("\n".join([lines[0]] + lines[1::5]) + "\n")
    fit, flags, sweep, target = (tmp_path / n for n in ("fit.nc", "flags.nc", "sweep.nc", "target.nc"))
    assert main(["fit", str(data), "--out", str(fit), "--no-confidence-intervals"]) == 0
    assert main(["flags", str(data), "--fit", str(fit), "--out", str(tmp_path / "f.csv"), "--nc", str(flags)]) == 0
    assert main(["sweep", "--case", "2.2", "--out", str(sweep)]) == 0
    assert main(["target", "--e-n", "0.5", "0.6", "--speed", "2", "3", "--points", "5", "--out", str(target)]) == 0
    failed = {p.name: f for p in (fit, flags, sweep, target) if (f := _failures(p))}
    assert not failed, failed
