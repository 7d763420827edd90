"""Damping from a target (issue 15, item 5) and the flags that explain (item 4), through the library
and the CLI (``microimpact target``, ``fit --posterior``, ``flags --posterior``)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from microimpact.analysis.fitting import FitProblem, model_restitution
from microimpact.analysis.target import damping_from_target
from microimpact.cli import main
from microimpact.presets import get_preset


@pytest.fixture(scope="module")
def wall():
    return get_preset("wall1990")


def _e_n(contact, speed, zh, za):
    return model_restitution(FitProblem.from_arrays([contact.radius], [speed], contact), zh, za,
                             contact.work_of_adhesion)[0]


def test_one_target_gives_a_curve_that_reproduces_it(wall):
    res = damping_from_target(0.6, 2.0, wall, n_points=9)
    zh, za = res.curves["zeta_hertz"].values[0], res.curves["zeta_adhesion"].values[0]
    assert res.best is None  # one equation, two unknowns: a curve, no point
    assert za[0] == 0.0 and zh[-1] == 0.0  # the curve runs from the zeta_H axis to the zeta_A axis
    assert np.all(np.diff(zh) < 0) and np.all(np.diff(za) > 0)  # both damp: trading one for the other
    for h, a in zip(zh, za):
        # each point solves e_n = 0.6 by Brent to xtol 1e-10 in zeta; e_n to 1e-8 (engine rtol)
        assert _e_n(wall, 2.0, h, a) == pytest.approx(0.6, abs=1e-7)


def test_two_targets_give_the_generating_point(wall):
    # e_n made by known zetas at two speeds: the least-squares point is those zetas
    truth = {"zeta_hertz": 0.8, "zeta_adhesion": 20.0}
    speeds = [1.5, 10.0]
    e = [_e_n(wall, v, truth["zeta_hertz"], truth["zeta_adhesion"]) for v in speeds]
    res = damping_from_target(e, speeds, wall, n_points=7)
    for k, v in truth.items():
        # exact data, two equations: recovered to the solver tolerance (1e-8 in e_n -> ~1e-5 in zeta)
        assert res.best[k] == pytest.approx(v, rel=1e-4), k


@pytest.mark.parametrize("e_n,speed,match", [(1.0, 2.0, r"must lie in \(0, 1\)"), (0.5, -1.0, "must be finite and > 0"),
                                             ([0.5, 0.6], [1.0], "same length")])
def test_bad_targets(wall, e_n, speed, match):
    with pytest.raises(ValueError, match=match):
        damping_from_target(e_n, speed, wall)


def test_cli_target_writes_csv_and_refuses_bad_input(tmp_path, capsys):
    out = tmp_path / "curve.csv"
    assert main(["target", "--e-n", "0.6", "--speed", "2.0", "--points", "5", "--out", str(out)]) == 0
    df = pd.read_csv(out)
    assert list(df.columns) == ["target", "speed", "e_n", "zeta_hertz", "zeta_adhesion"] and len(df) == 5
    assert main(["target", "--e-n", "0.6", "--speed", "2.0", "--out", str(tmp_path / "curve.txt")]) == 2
    assert main(["target", "--e-n", "0.6", "0.7", "--speed", "2.0"]) == 2
    err = capsys.readouterr().err
    assert "must end in .csv or .nc" in err and "as many --speed" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["curve.csv"]  # nothing written on error


# ----------------------------------------------------------------------------- flags that explain
SPUN = 8  # 0-based: a sliding row (50 deg at 30 m/s); its e_t raised as top-spin would


def _spun_csv(d):
    """A synthetic oblique CSV in ``d`` with one row edited as if spun."""
    from microimpact.analysis.synthetic import make_synthetic_oblique
    from microimpact.io.files import write_csv

    df = make_synthetic_oblique(radii=(3.45e-6,), seed=4)
    df.loc[SPUN, "tangential_restitution [1]"] = 1.0
    write_csv(df, d / "obl.csv", float_format="%.6g")


@pytest.fixture(scope="module")
def oblique_run(tmp_path_factory):
    """The spun CSV; fit, posterior and flags by the CLI."""
    d = tmp_path_factory.mktemp("spun")
    _spun_csv(d)
    spun = SPUN
    fit, post, obl, flags = d / "fit.nc", d / "post.nc", d / "obl.nc", d / "flags.csv"
    assert main(["fit", str(d / "obl.csv"), "--out", str(fit), "--posterior", str(post), "--oblique-out", str(obl),
                 "--no-confidence-intervals"]) == 0  # the default chain: run until converged
    assert main(["flags", str(d / "obl.csv"), "--fit", str(fit), "--posterior", str(post), "--out", str(flags)]) == 0
    return pd.read_csv(flags), spun + 1, d


@pytest.mark.slow  # 20 s or more: `pytest -m slow` (README, Tests), not the default run
def test_flags_say_which_row_was_spun_and_by_how_much(oblique_run):
    flags, spun_row, _ = oblique_run
    r = flags.set_index("row")
    assert r.loc[spun_row, "probably_spun"] == 1  # zero spin cannot give e_t = 1 at 50 deg
    assert r.loc[spun_row, "spin_low"] > 0  # top-spin explains it
    others = r.drop(index=spun_row)
    # the unedited rows are model data with 2 % noise (the spun row biases the fit a little): at most
    # one in twenty may look spun or unexplained by chance, and the others admit zero spin
    assert others["probably_spun"].sum() + others["spin_unexplained"].sum() <= 1
    ok = others[(others["probably_spun"] == 0) & (others["spin_unexplained"] == 0)]
    assert ((ok["spin_low"] <= 0) & (ok["spin_high"] >= 0)).all()
    # an oblique measurement moves with spin by far more than its uncertainty at every angle
    assert (r["spin_moves_prediction"] == 1).all()


@pytest.mark.extended
def test_normal_only_rows_admit_every_spin(tmp_path):
    # e_n does not depend on spin (decoupling): rows that measured only e_n are never spin-flagged
    from microimpact.analysis.fitting import fit_damping
    from microimpact.analysis.flags import flag_measurements
    from microimpact.io import default_materials_path, read_impacts, read_materials
    from test_fitting import DATA

    table = read_impacts(DATA).head(12)
    table.attrs = {"source": str(DATA)}
    fit = fit_damping(read_impacts(DATA), read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"],
                      confidence_intervals=False)
    ds = flag_measurements(table, fit, n_spin=4, spin_fractions=(1.0,))
    assert (ds["spin_moves_prediction"] == 0).all() and (ds["probably_spun"] == 0).all()
    np.testing.assert_allclose(ds["spin_high"].values, table["speed"] / table["radius"], rtol=1e-12)
    np.testing.assert_allclose(ds["spin_low"].values, -table["speed"] / table["radius"], rtol=1e-12)


def test_fit_cli_wrote_friction_into_the_fit(tmp_path):
    from microimpact.analysis.fit_result import DampingFit

    _spun_csv(tmp_path)  # (without --posterior: the friction fit is the same, the chain is not needed)
    assert main(["fit", str(tmp_path / "obl.csv"), "--out", str(tmp_path / "fit.nc"), "--no-confidence-intervals"]) == 0
    fit = DampingFit.load(tmp_path / "fit.nc")
    assert fit.friction != 0.15 and abs(fit.friction - 0.15) < 0.02  # fitted, not the config's 0.15
    assert "friction_stderr" in fit.info


@pytest.mark.slow  # a converged chain through the CLI: tens of seconds (the CLI files' form: test_report.py)
def test_report_shows_posterior_oblique_fit_and_spin_ranges(oblique_run):
    # the analyst section of the PDF from the CLI's files: posterior table and figures, measured vs
    # fitted per angle, and the per-row spin ranges naming the spun row
    pypdf = pytest.importorskip("pypdf")
    from microimpact.report.pdf import build_report

    _, spun_row, d = oblique_run
    path = build_report(d / "report.pdf", {"fit": d / "fit.nc", "posterior": d / "post.nc", "oblique": d / "obl.nc",
                                           "flags": d / "flags.csv"})
    text = "\n".join(p.extract_text() or "" for p in pypdf.PdfReader(path).pages)
    for heading in ("Posterior of the fitted parameters", "Capture velocity with its credible interval",
                    "Friction from the oblique columns", "Which rows were probably spun"):
        assert heading in text, heading
    assert "95 % credible band" in text and "Corner plot" in text and "per incidence angle" in text
    assert "1 P" in text  # one probably-spun row counted in the spin-range paragraph
