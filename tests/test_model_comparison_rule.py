"""The pipeline's model comparison (workflow/rules/models.smk) ranks the Thornton-Ning law too.

The rule's script (workflow/scripts/model_comparison.py) runs in-process with a stand-in for
Snakemake's ``snakemake`` object, on a subset of the bundled synthetic data, with the models the
rule lists (read from the rule file itself, so that the test follows the rule).
"""

from __future__ import annotations

import ast
import re
import runpy
import signal
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from microimpact.analysis.model_comparison import PLASTIC_MODELS
from microimpact.io.materials import default_materials_path

ROOT = Path(__file__).resolve().parents[1]
RULE = ROOT / "workflow" / "rules" / "models.smk"
SCRIPT = ROOT / "workflow" / "scripts" / "model_comparison.py"
PAIR = "ammonium_fluorescein_on_silicon"


def rule_models() -> list[str]:
    """The ``models=[...]`` parameter of the model_comparison rule."""
    found = re.search(r"^\s*models=(\[[^\]]*\]),", RULE.read_text(), flags=re.M)
    assert found, f"{RULE.name}: no models=[...] parameter"
    return ast.literal_eval(found.group(1))


def test_the_rule_lists_the_plastic_law_beside_the_damped_ones():
    models = rule_models()
    assert models[:3] == ["ring", "jkr", "dmt"]
    assert "thornton_ning" in models and "thornton_ning" in PLASTIC_MODELS


def _run_rule_script(tmp_path, data, models):
    """Run the rule's script as Snakemake would, restoring what log_job redirects."""
    out = tmp_path / "model_comparison.nc"
    job = SimpleNamespace(rule="model_comparison", log=[str(tmp_path / "job.log")], threads=1,
                          wildcards=SimpleNamespace(pair=PAIR),
                          input=SimpleNamespace(data=str(data), validated=str(data), materials=str(default_materials_path())),
                          params=SimpleNamespace(material_pair=PAIR, models=models, rtol=1e-8), output=[str(out)])
    saved = (sys.stdout, sys.stderr, sys.excepthook, sys.unraisablehook, signal.getsignal(signal.SIGTERM))
    try:
        runpy.run_path(str(SCRIPT), init_globals={"snakemake": job}, run_name="__main__")
    finally:
        if sys.stdout is not saved[0]:
            sys.stdout.close()
        sys.stdout, sys.stderr, sys.excepthook, sys.unraisablehook = saved[:4]
        signal.signal(signal.SIGTERM, saved[4])
    return out


def _subset(tmp_path):
    """Every fifth row of the bundled synthetic data (20 impacts, three sizes)."""
    data = tmp_path / "impacts.csv"
    pd.read_csv(ROOT / "data" / "synthetic_microspheres.csv").iloc[::5].to_csv(data, index=False)
    return data


@pytest.mark.extended
def test_the_rule_script_fits_the_plastic_law(tmp_path):
    """The script's path for a rate-independent law (fit_thornton_ning, no damping fit), in a
    subprocess as the pipeline runs it (extended); the whole list of the rule is the slow test below."""
    out = _run_rule_script(tmp_path, _subset(tmp_path), ["thornton_ning"])
    with xr.open_dataset(out, engine="netcdf4") as ds:
        assert [str(m) for m in ds["normal_model_label"].values] == ["thornton_ning"]
        assert float(ds["yield_velocity"].squeeze()) > 0.0 and np.isfinite(ds["aic"].values).all()


@pytest.mark.slow
def test_the_rule_script_ranks_every_listed_model(tmp_path):
    """One row of AIC per model the rule lists, the Thornton-Ning law with its fitted yield
    velocity, the best model at Delta AIC 0 (40 s: three damping fits)."""
    models = rule_models()
    out = _run_rule_script(tmp_path, _subset(tmp_path), models)
    with xr.open_dataset(out, engine="netcdf4") as ds:
        labels = [str(m) for m in ds["normal_model_label"].values]  # the writer's CF label of a text dimension
        assert labels == models
        assert np.isfinite(ds["aic"].values).all()
        assert float(ds["delta_aic"].min()) == 0.0
        tn = ds.isel(normal_model=labels.index("thornton_ning"))
        assert float(tn["yield_velocity"]) > 0.0
        assert int(tn["n_parameters"]) == 2  # V_y and w (the law is rate-independent: no damping)
    assert "thornton_ning" in (tmp_path / "job.log").read_text()
