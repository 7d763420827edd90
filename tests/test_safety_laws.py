"""Every law on every path (issue 55, item 2): each law x sub-model combination of the registry
(:func:`microimpact.model.laws.combinations`, with the defaults each sub-model documents) run
through the library (``simulate_impact`` on every path the combination lists, ``simulate_many``),
``microimpact simulate`` (every path), ``sweep``, ``lammps export``, ``lammps verify`` of what was
exported and ``lammps fit`` where the law is one of LAMMPS's, gives a result or a one-line refusal
(``microimpact: error: ...``, exit 2; 1 for "LAMMPS and microimpact disagree" or "the data do not
determine it"), never a traceback.

The default run takes a sample that holds every sub-model of every field, the Hertz (f0 = 0) twin
and every solver path at least once; ``-m slow`` runs all of them (docs/studies.md)."""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
import runpy
import signal
import sys
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
import xarray as xr
import yaml

from microimpact.cli import main
from microimpact.io.lammps import LammpsExportError, lammps_wall_model
from microimpact.model import laws
from microimpact.model.parameters import TABLE2_CASES
from microimpact.solvers.impact import simulate_impact, simulate_many
from microimpact.studies import sweeps

COMBINATIONS = list(laws.combinations())
PAIR = "ammonium_fluorescein_on_silicon"  # Table 1 row 2's material: the registry's base contact
#: a small Table 2 grid for the sweep path (the path, not the grid, is under test): 2 speeds x 2 angles
TINY_CASE = {"description": "two speeds, two angles", "speed": {"start": 0.5, "stop": 2.0, "num": 2},
             "incidence_deg": {"start": 0.0, "stop": 30.0, "step": 30.0}}
#: the sample's impact: oblique (the tangential, rolling and twisting laws act), above capture for every law
SPEED, ANGLE = 1.0, 30.0


def _label(c) -> str:
    return "+".join(c.choices.values()) + ("" if c.contact.adhesion_line_force > 0.0 else "+f0=0")


def _sample() -> list:
    """Combinations (greedy) until every (field, name), f0 > 0 and f0 = 0 and every path is held."""
    def keys(c):
        return set(c.choices.items()) | {("f0", c.contact.adhesion_line_force > 0.0)} | {("method", m) for m in c.methods}

    wanted = set().union(*map(keys, COMBINATIONS))
    chosen = []
    while wanted:
        best = max(COMBINATIONS, key=lambda c: len(keys(c) & wanted))
        chosen.append(best)
        wanted -= keys(best)
    return chosen


SAMPLE = _sample()


def contact_argv(contact) -> list[str]:
    """The command-line options of every field of ``contact`` (None fields left out)."""
    argv = []
    for name in (f.name for f in dataclasses.fields(contact)):
        value = getattr(contact, name)
        if value is not None:
            argv += [f"--{name.replace('_', '-')}", value if isinstance(value, str) else repr(float(value))]
    return argv


def one_result_or_one_line(argv, capsys, allowed=(0, 2)) -> tuple[int, str]:
    """Run ``microimpact ARGV`` in-process: (status, stdout), after checking that it is a result (0,
    no error line) or one line ``microimpact: error: ...``; a traceback fails the test by itself."""
    capsys.readouterr()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the regime warnings of JKR and DMT are not what is under test
        status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    errors = [line for line in err.splitlines() if line.startswith("microimpact: error:")]
    assert status in allowed, (argv, status, err)
    assert "Traceback" not in err, (argv, err)
    assert len(errors) == (status != 0), (argv, status, err)
    return status, out


def check_library(c) -> None:
    """simulate_impact on every path the combination lists, simulate_many on the engine: a result
    (a ValueError, one line, is a refusal: rkg's captured-impact limit)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for method in c.methods:
            try:
                r = simulate_impact(c.contact, SPEED, ANGLE, method=method)
            except ValueError as exc:
                assert "\n" not in str(exc), (_label(c), method, exc)
                continue
            assert r.outcome in ("rebound", "capture") and math.isfinite(r.e_n), (_label(c), method, r)
        many = simulate_many(c.contact, [SPEED, 2.0 * SPEED], ANGLE)
    assert np.all(np.isfinite(many["e_n"])), _label(c)


def check_simulate(c, capsys) -> None:
    for method in c.methods:
        status, out = one_result_or_one_line(["simulate", *contact_argv(c.contact), "--speed", SPEED,
                                              "--incidence-deg", ANGLE, "--method", method, "--json"], capsys)
        if status == 0 and method == "engine":  # the command's contact is the combination's, so its result too
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                expected = simulate_impact(c.contact, SPEED, ANGLE).e_n
            assert json.loads(out)["e_n"] == expected, _label(c)


def check_sweep(c, tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.setattr(sweeps, "TABLE2_CASES", {**TABLE2_CASES, "2.1": TINY_CASE})
    out = tmp_path / "sweep.nc"
    status, _ = one_result_or_one_line(["sweep", *contact_argv(c.contact), "--case", "2.1", "--out", out], capsys)
    assert (status == 0) == out.exists()
    out.unlink(missing_ok=True)


def lammps_law(c) -> str | None:
    """The ``lammps fit --law`` of the combination (NORMAL+DAMPING), or None where LAMMPS has none of
    its laws (:func:`microimpact.io.lammps.lammps_wall_model` refuses it)."""
    try:
        lammps_wall_model(c.contact)
    except LammpsExportError:
        return None
    return f"{'hertz' if c.contact.adhesion_line_force == 0.0 else c.contact.normal_model}+{c.contact.damping_model}"


def impacts_csv(c, path) -> None:
    """Noise-free impacts of the combination (4 speeds x 3 angles at its radius) as a lab CSV with
    stated uncertainties: what ``lammps fit`` fits."""
    speeds, angles = np.repeat([0.5, 1.0, 2.0, 4.0], 3), np.tile([20.0, 35.0, 50.0], 4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = [simulate_impact(c.contact, v, a) for v, a in zip(speeds, angles)]
    pd.DataFrame({"material_pair": PAIR, "radius [um]": c.contact.radius * 1e6, "speed [m/s]": speeds,
                  "incidence_angle [deg]": angles, "e_n [1]": [max(r.e_n, 0.0) for r in results],
                  "e_n_uncertainty [1]": 0.01}).to_csv(path, index=False)


def check_lammps(c, tmp_path, capsys, verify=True, fit=True) -> dict:
    """export (0 or one line), verify what was written (0 agree, 1 disagree), ``lammps fit --law`` of
    its normal law where it is LAMMPS's (0, 1 not determined, or one line): the statuses.

    The fit is of the normal law (``--law``) only: a fit of the tangential laws' friction to the
    oblique columns takes minutes per law (tests/test_dem_tangential.py runs those, slow)."""
    lmp = tmp_path / "c.lmp"
    found = {"export": one_result_or_one_line(["lammps", "export", *contact_argv(c.contact), "--out", lmp], capsys)[0]}
    assert (found["export"] == 0) == lmp.exists()
    if found["export"] == 0 and verify:
        found["verify"] = one_result_or_one_line(["lammps", "verify", lmp, "--speeds", SPEED, "--incidence-deg", ANGLE],
                                                 capsys, allowed=(0, 1, 2))[0]
    lmp.unlink(missing_ok=True)
    law = lammps_law(c)
    assert (law is None) == (found["export"] != 0)  # export and fit agree on what is LAMMPS's
    if law is not None and fit:
        data = tmp_path / "impacts.csv"
        impacts_csv(c, data)
        found["fit"] = one_result_or_one_line(["lammps", "fit", data, "--material-pair", PAIR, "--law", law, "--out",
                                               lmp], capsys, allowed=(0, 1, 2))[0]
        assert (found["fit"] == 0) == lmp.exists()
        lmp.unlink(missing_ok=True)
    return found


def test_the_sample_holds_every_sub_model_and_every_path():
    held = {item for c in SAMPLE for item in c.choices.items()}
    assert held == {(f, n) for f in laws.fields() for n in laws.names(f)}
    assert {m for c in SAMPLE for m in c.methods} == {"engine", "reference", "rkg"}
    assert {c.contact.adhesion_line_force > 0.0 for c in SAMPLE} == {True, False}
    assert len(COMBINATIONS) == 394 and len(SAMPLE) < 20  # the registry as declared; a sample, not all


@pytest.mark.parametrize("c", SAMPLE, ids=_label)
def test_a_law_gives_a_result_or_one_line_in_the_library_simulate_and_sweep(c, tmp_path, capsys, monkeypatch):
    check_library(c)
    check_simulate(c, capsys)
    check_sweep(c, tmp_path, capsys, monkeypatch)


@pytest.mark.parametrize("c", SAMPLE, ids=_label)
def test_a_law_is_exported_or_refused_in_one_line(c, tmp_path, capsys):
    check_lammps(c, tmp_path, capsys, verify=False, fit=False)


def test_what_lammps_expresses_is_verified_and_fitted(needs_lammps, tmp_path, capsys):
    lammps_laws = [c for c in SAMPLE if lammps_law(c) is not None]
    assert lammps_laws, "the sample holds a LAMMPS law"
    c = lammps_laws[0]
    found = check_lammps(c, tmp_path, capsys)
    assert found["verify"] == 0, (_label(c), found)  # LAMMPS's own law: LAMMPS agrees
    assert found["fit"] in (0, 1), (_label(c), found)  # a fit, determined or not, not a refusal


@pytest.mark.slow  # every combination on every path: 20-40 min (`pytest -m slow -s` prints the tally)
def test_every_law_on_every_path(tmp_path, capsys, monkeypatch):
    tally, fitted, failed = {}, set(), {}
    for c in COMBINATIONS:
        law = lammps_law(c)  # the normal fit depends on the law alone: once per law
        try:
            check_library(c)
            check_simulate(c, capsys)
            check_sweep(c, tmp_path, capsys, monkeypatch)
            found = check_lammps(c, tmp_path, capsys, fit=law not in fitted)
        except Exception as exc:  # noqa: BLE001 - every combination is tried; the failures are named at the end
            failed[_label(c)] = f"{type(exc).__name__}: {str(exc)[:300]}"
            continue
        fitted.add(law)
        for path, status in found.items():
            tally[f"{path} {status}"] = tally.get(f"{path} {status}", 0) + 1
    with capsys.disabled():
        print(json.dumps({"combinations": len(COMBINATIONS), "passed": len(COMBINATIONS) - len(failed), **tally,
                          "failed": failed}, indent=1))
    assert not failed


#: LAMMPS's rolling sds at its documented default mu_roll = 0 (the registry documents 0.1): it crashed
#: every path (TypeError in solvers.dem_tangential, issue 55); a LAMMPS law of the sample, so that
#: export, verify and fit are on its paths
ROLLING_SDS_MU_0 = next(c for c in SAMPLE if c.contact.rolling_model == "lammps_sds" and lammps_law(c) is not None)
ROLLING_SDS_MU_0 = dataclasses.replace(ROLLING_SDS_MU_0, contact=ROLLING_SDS_MU_0.contact.with_(rolling_friction=0.0))


def test_rolling_sds_with_mu_roll_0_gives_a_result_in_the_library_simulate_sweep_and_export(tmp_path, capsys,
                                                                                              monkeypatch):
    c = ROLLING_SDS_MU_0
    check_library(c)
    # a result, not a refusal: the law is valid, so a one-line error would hide the crash's fix
    assert one_result_or_one_line(["simulate", *contact_argv(c.contact), "--speed", SPEED, "--incidence-deg", ANGLE,
                                   "--json"], capsys, allowed=(0,))[0] == 0
    check_simulate(c, capsys)
    monkeypatch.setattr(sweeps, "TABLE2_CASES", {**TABLE2_CASES, "2.1": TINY_CASE})
    assert one_result_or_one_line(["sweep", *contact_argv(c.contact), "--case", "2.1", "--out", tmp_path / "s.nc"],
                                  capsys, allowed=(0,))[0] == 0
    assert check_lammps(c, tmp_path, capsys, verify=False, fit=False) == {"export": 0}


def test_rolling_sds_with_mu_roll_0_is_verified_by_lammps(needs_lammps, tmp_path, capsys):
    # (the normal fit of check_lammps does not hold the rolling law: left out here)
    found = check_lammps(ROLLING_SDS_MU_0, tmp_path, capsys, fit=False)
    assert found == {"export": 0, "verify": 0}, found  # LAMMPS's own law at its default: LAMMPS agrees


@pytest.mark.extended  # a friction fit with its profile over the scipy tangential solver: ~1 min
def test_rolling_sds_with_mu_roll_0_is_fitted_by_lammps_fit(tmp_path, capsys, monkeypatch):
    """``lammps fit`` with LAMMPS's rolling sds at its default mu_roll 0 (--rolling-stiffness without
    --rolling-friction): the friction of the Mindlin law is fitted to impacts of the law without
    rolling (mu_roll 0 is that law, to the bit: tests/test_dem_rolling.py), its 95 % interval holds
    the true 0.3, and the rolling law is written with mu_roll 0 (the one path of issue 55's list the
    tests above leave out). The data: noise-free e_t at 6 speeds and angles, e_n with 1 % noise."""
    from microimpact.analysis.dem_fit import dem_law_contact
    from microimpact.io.materials import read_materials

    pair = read_materials()[PAIR]
    truth = dem_law_contact(pair, 2e-6, "hertz", "coeff_restitution", 0.6).with_(
        friction=0.3, tangential_model="lammps_mindlin", shear_modulus=1e9)
    speed, angle = np.geomspace(0.3, 10.0, 6), np.linspace(15.0, 60.0, 6)
    e_t = [simulate_impact(truth, v, a).velocity_out[1] / (v * math.sin(math.radians(a))) for v, a in zip(speed, angle)]
    rng = np.random.default_rng(2)
    monkeypatch.chdir(tmp_path)
    pd.DataFrame({"material_pair": PAIR, "radius [um]": 2.0, "speed [m/s]": speed, "incidence_angle [deg]": angle,
                  "e_n [1]": 0.6 + rng.normal(0.0, 0.01, 6), "e_n_uncertainty [1]": 0.01,
                  "tangential_restitution [1]": e_t,
                  "tangential_restitution_uncertainty [1]": 0.01}).to_csv("impacts.csv", index=False)
    status, _ = one_result_or_one_line(["lammps", "fit", "impacts.csv", "--material-pair", PAIR, "--law",
                                        "hertz+coeff_restitution", "--tangential-model", "lammps_mindlin",
                                        "--shear-modulus", "1e9", "--rolling-stiffness", "200", "--out", "c.lmp"],
                                       capsys, allowed=(0,))
    assert status == 0
    text = (tmp_path / "c.lmp").read_text()
    assert text.splitlines()[-1].split(" rolling sds ")[1].split()[:3] == ["200", "0", "0"]
    interval = text.split("# fitted friction: ")[1].split("95% profile-likelihood interval ")[1].split(";")[0]
    low, high = (float(x) for x in interval.split(" to "))
    assert low < 0.3 < high


# ---------------------------------------------------------------- the pipeline's path
# The pipeline chooses a law in one place only: the config key contact_models, the sub-models of the
# Kharaz comparison's "selected" model (rule kharaz, workflow/scripts/kharaz.py). paper_contact takes
# a contact's numbers but no sub-model, and the model comparison's normal laws are the rule's fixed
# list (tests/test_model_comparison_rule.py runs it). The tests below read the choices from the
# schema the Snakefile validates the config against, so that a law choice added to it is under test.

REPO = Path(__file__).resolve().parents[1]
SCHEMA = REPO / "workflow" / "schemas" / "config.schema.yaml"
KHARAZ_SCRIPT = REPO / "workflow" / "scripts" / "kharaz.py"
#: rolling resistance of the selected model: Contact's default (none) and one that acts
PIPELINE_ROLLING_FRICTION = (0.0, 0.1)


def _schema_properties(key: str) -> dict:
    found = yaml.safe_load(SCHEMA.read_text())["properties"][key]
    return next((s for s in found.get("oneOf", []) if s.get("type") == "object"), found)["properties"]


def _pipeline_choices() -> list[dict]:
    """Every ``contact_models`` the schema allows: each enumerated sub-model pair, and rolling
    resistance off and on."""
    enums = {k: v["enum"] for k, v in _schema_properties("contact_models").items() if "enum" in v}
    return [{**dict(zip(enums, names)), "rolling_friction": mu}
            for names in itertools.product(*enums.values()) for mu in PIPELINE_ROLLING_FRICTION]


def test_the_pipeline_chooses_only_the_sub_models_of_its_schema():
    contact_models = _schema_properties("contact_models")
    assert set(contact_models) == {"tangential_model", "friction_model", "rolling_friction"}
    for field in ("tangential_model", "friction_model"):  # names of the registry, each one its own
        assert set(contact_models[field]["enum"]) <= set(laws.names(field)), field
    # the paper's contact: numbers only, no sub-model (a law field there would be a choice untested here)
    assert not {f for f in _schema_properties("paper_contact") if f.endswith("_model")}
    assert len(_pipeline_choices()) == 3 * 2 * len(PIPELINE_ROLLING_FRICTION)


def _run_kharaz_rule(tmp_path, contact_models: dict, capsys) -> tuple[Path, str]:
    """The rule's script as Snakemake runs it (in-process, a stand-in for its ``snakemake`` object),
    after the config check of the Snakefile; (output, the terminal's stderr). An uncaught exception
    goes, as in a job, to the hook log_job installed (one line on the terminal, the traceback in the log)."""
    from snakemake.utils import validate

    config = {**yaml.safe_load((REPO / "workflow" / "config" / "config.yaml").read_text()),
              "contact_models": contact_models}
    validate(config, str(SCHEMA))  # the pipeline accepts this choice at start-up
    out = tmp_path / "kharaz.nc"
    job = SimpleNamespace(rule="kharaz", log=[str(tmp_path / "kharaz.log")], threads=1,
                          input=[str(REPO / config["kharaz_data"])],
                          params=SimpleNamespace(contact_models=config["contact_models"]), output=[str(out)])
    saved = (sys.stdout, sys.stderr, sys.excepthook, sys.unraisablehook, signal.getsignal(signal.SIGTERM))
    capsys.readouterr()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            runpy.run_path(str(KHARAZ_SCRIPT), init_globals={"snakemake": job}, run_name="__main__")
    except Exception as exc:  # noqa: BLE001 - what a job does with it: the hook log_job installed
        sys.excepthook(type(exc), exc, exc.__traceback__)
    finally:
        if sys.stdout is not saved[0]:
            sys.stdout.close()
        sys.stdout, sys.stderr, sys.excepthook, sys.unraisablehook = saved[:4]
        signal.signal(signal.SIGTERM, saved[4])
    return out, capsys.readouterr().err


@pytest.mark.extended  # the rule's whole comparison (its friction fit, its curves) per choice: ~1 s CPU each
@pytest.mark.parametrize("contact_models", _pipeline_choices(), ids=lambda m: "+".join(map(str, m.values())))
def test_every_law_the_pipeline_chooses_gives_a_result_or_one_line(contact_models, tmp_path, capsys):
    out, err = _run_kharaz_rule(tmp_path, contact_models, capsys)
    compliant = contact_models["tangential_model"] != "rigid"
    if compliant or contact_models["rolling_friction"] == 0.0:  # a valid contact: a result
        assert out.exists() and err == "", err
        with xr.open_dataset(out, engine="netcdf4") as ds:
            assert ds.attrs["selected_contact_models"] == ", ".join(f"{k}={v}" for k, v in sorted(contact_models.items()))
            assert all(math.isfinite(float(ds.attrs[f"rms_tangential_restitution_{regime}_selected"]))
                       for regime in ("sliding", "below"))
    else:  # rolling resistance without a compliant tangential law: refused in one line, nothing written
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("microimpact: rule kharaz failed: ValueError: rolling_friction"), err
        assert "needs a compliant tangential model" in lines[0] and not out.exists()
