"""CF-1.10 compliance of the issue-15 result files: posterior (chain, summary, bands), the oblique
friction fit, the damping target curves, and the flags with the spin explanation. The same checks as
tests/test_cf.py (the compliance-checker suite and the per-group description rules)."""

from __future__ import annotations

import functools

import pytest

from microimpact.analysis import analyst_fit, posterior

from test_cf import _failures, test_every_variable_in_every_group_is_described as _described

# the real CF checker over the posterior's files, like tests/test_cf.py: with the extended tests
pytestmark = pytest.mark.extended

KINDS = ["posterior", "posterior_empty", "oblique", "oblique_empty", "target", "flags_explained"]


@pytest.fixture(scope="module")
def issue15_files(tmp_path_factory):
    from microimpact.analysis.analyst_fit import AnalystFit, analyse_impacts
    from microimpact.analysis.flags import flag_measurements, write_flags
    from microimpact.analysis.synthetic import make_synthetic_oblique
    from microimpact.analysis.target import damping_from_target
    from microimpact.io import default_materials_path, read_impacts, read_materials
    from microimpact.io.files import write_csv
    from microimpact.presets import get_preset

    out = tmp_path_factory.mktemp("cf15")
    pair = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    write_csv(make_synthetic_oblique(radii=(3.45e-6,), speeds=(15.0, 60.0), incidence_deg=(20.0, 50.0, 70.0)),
              out / "obl.csv", float_format="%.6g")
    table = read_impacts(out / "obl.csv")
    # the form of the files, not their numbers: a short chain (a converged one takes tens of seconds),
    # accepted unconverged, through the same assembly of the posterior file as the pipeline's
    short = functools.partial(posterior.sample_posterior, require_convergence=False)
    with pytest.MonkeyPatch.context() as mp:
        for module in (posterior, analyst_fit):
            if hasattr(module, "sample_posterior"):
                mp.setattr(module, "sample_posterior", short)
        res = analyse_impacts(table, pair, posterior={"n_draws": 4, "walkers": 8, "steps": 40})
    files = dict(zip(("fit", "posterior", "oblique"),
                     res.save(out / "fit.nc", out / "posterior.nc", out / "oblique.nc")))
    empty = AnalystFit(res.damping)
    _, files["posterior_empty"], files["oblique_empty"] = empty.save(out / "f2.nc", out / "p2.nc", out / "o2.nc")
    files["target"] = damping_from_target([0.3, 0.6], [1.5, 10.0], get_preset("wall1990"), n_points=5).save(out / "t.nc")
    ds = flag_measurements(table, res.damping, posterior=res.posterior, n_draws=3, n_spin=4, spin_fractions=(1.0,))
    write_flags(ds, out / "flags.csv", out / "flags.nc")
    files["flags_explained"] = out / "flags.nc"
    return files


@pytest.mark.parametrize("kind", KINDS)
def test_issue15_file_passes_cf_checker(issue15_files, kind):
    failed = _failures(issue15_files[kind])
    assert not failed, f"{kind}: " + "\n".join(failed)


@pytest.mark.parametrize("kind", KINDS)
def test_issue15_file_variables_are_described(issue15_files, kind):
    _described(issue15_files, kind)
