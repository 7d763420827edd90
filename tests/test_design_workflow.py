"""The pipeline's optional design step (issue 54) in a real Snakemake run: with ``design: {enabled:
true}`` the tiny pipeline of tests/test_workflow.py writes each material pair's design.json and
measured-impact template, and the PDF report has a "What to measure next" page per pair; with the
step off (the default) no design job runs. Slow: one run of the tiny pipeline (stress sweep off)."""

from __future__ import annotations

import json

import pandas as pd
import pytest
import yaml
from pypdf import PdfReader

from microimpact.io import read_impacts
from test_workflow import CHAIN, SECOND, job_counts, make_copy, snakemake

pytestmark = pytest.mark.slow

PAIRS = (CHAIN["pair"], SECOND["pair"])


def _configure(root, design):
    path = root / "workflow" / "config" / "config.yaml"
    cfg = yaml.safe_load(path.read_text())
    cfg["stress"]["enabled"] = False  # not what this test is about; it halves the run
    if design is not None:
        cfg["design"] = design
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return root


def test_design_is_off_by_default(tmp_path):
    root = _configure(make_copy(tmp_path / "off"), None)
    proc = snakemake(root, "-n", "--cores", "1")
    assert proc.returncode == 0, proc.stdout[-3000:]
    assert "design" not in job_counts(proc.stdout)


def test_pipeline_writes_the_design_and_its_report_page(tmp_path):
    root = _configure(make_copy(tmp_path / "on"), {"enabled": True, "parameters": ["zeta_hertz", "friction"],
                                                    "n": 4, "n_friction": 2})
    proc = snakemake(root, "--cores", "2", timeout=1200)
    assert proc.returncode == 0, proc.stdout[-5000:]
    for pair in PAIRS:
        base = root / "results" / "analyst" / pair
        record = json.loads((base / "design.json").read_text())
        assert record["parameters"] == ["zeta_hertz", "friction"] and len(record["rows"]) == 4 + 2
        template = pd.read_csv(base / "design.csv")
        template["e_n [1]"] = 0.5  # the laboratory fills in its measurements
        oblique = template["incidence_angle [deg]"] > 0
        template.loc[oblique, "tangential_restitution [1]"] = 0.8
        template.to_csv(tmp_path / "filled.csv", index=False)
        assert list(read_impacts(tmp_path / "filled.csv")["id"]) == list(template["id"])
    pages = [p.extract_text() for p in PdfReader(root / "reports" / "report.pdf").pages]
    design_pages = [t for t in pages if "What to measure next" in t and "Criterion" in t]
    assert len(design_pages) == len(PAIRS)
    for pair in PAIRS:
        assert any(f"results/analyst/{pair}/fit.nc" in t.replace("\n", "") for t in design_pages), pair
