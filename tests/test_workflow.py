"""Integration tests of the Snakemake pipeline (Snakefile, workflow/).

The workflow is copied into a temporary directory with a TINY configuration (two speeds per
sweep, two phase portraits, benchmark off, a 20-case stress sweep) and run with ``snakemake --cores 2`` as a subprocess,
once per test session; the outputs are then checked by content (NetCDF variables, units and
attributes with xarray; the PDF's pages and their text with pypdf). Further tests use dry runs
(``snakemake -n``) on the finished copy: nothing to do on a second run, only the dependants of
the data after touching it, the SLURM profile, the linter, and the config validation.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

REPO = Path(__file__).resolve().parents[1]
SNAKEMAKE = [sys.executable, "-m", "snakemake"]

pytestmark = pytest.mark.skipif(shutil.which("snakemake") is None and not (REPO / "Snakefile").exists(),
                                reason="snakemake or the Snakefile is missing")

TINY_SWEEPS = {
    "2.1": {"speed": [0.5, 3.0], "incidence_deg": [0.0, 30.0]},
    "2.2": {"speed": [0.5, 3.0], "incidence_deg": 0.0, "omega_tp": [0.0, 1.8e5]},
    "2.3": {"speed": [0.5, 3.0], "incidence_deg": [0.0, 30.0], "omega_t": 2.9e5},
    "2.4": {"speed": [0.5, 3.0], "incidence_deg": 0.0, "omega_t": 2.9e5, "omega_tp": 2.9e5, "friction": [0.0, 0.9]},
    "2.5": {"speed": [0.5, 3.0], "incidence_deg": 0.0, "omega_t": 2.9e6, "omega_tp": 2.9e6, "friction": [0.1, 0.9]},
}

#: 20 cases; seed 3 because its cases 0 and 10 (those compared with the reference solver) are quick
TINY_STRESS = {"enabled": True, "cases": 20, "seed": 3, "reference_every": 10, "case_time_limit": 30.0}

#: the section titles build_report writes as text (searchable in the PDF)
EXPECTED_TITLES = [
    "1. Damping fit",
    "2. Nonlinear dynamics of the normal contact",
    "3. Phase portraits",
    "Table 2 case 2.1",
    "Table 2 case 2.5",
    "Measurement flags",
    "Validation: oblique impacts of Kharaz",
    "Work-precision benchmark",
    "Numerical stability (stress sweep)",
    "Reproduction of the paper",
    "Appendix: configuration",
]


def snakemake(workdir: Path, *args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    """Run snakemake in ``workdir``; stdout and stderr together in ``.stdout``."""
    env = dict(os.environ, PYTHONWARNINGS="ignore", MPLBACKEND="Agg")
    return subprocess.run([*SNAKEMAKE, *args], cwd=workdir, env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=timeout)


def make_copy(root: Path) -> Path:
    """Snakefile, workflow/ and the two data files in ``root`` with the tiny configuration."""
    root.mkdir(parents=True, exist_ok=True)
    shutil.copy(REPO / "Snakefile", root / "Snakefile")
    shutil.copytree(REPO / "workflow", root / "workflow", ignore=shutil.ignore_patterns("__pycache__"))
    (root / "data").mkdir()
    for name in ("synthetic_microspheres.csv", "kharaz2001_oblique.csv"):
        shutil.copy(REPO / "data" / name, root / "data" / name)
    cfg_path = root / "workflow" / "config" / "config.yaml"
    cfg = yaml.safe_load(cfg_path.read_text())
    cfg["sweeps"] = TINY_SWEEPS
    cfg["phase_portrait_speeds"] = [1.0e-5, 2.0]
    cfg["benchmark"] = {"enabled": False, "quick": True}
    cfg["stress"] = dict(TINY_STRESS)
    cfg_path.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return root


def job_counts(dry_run_output: str) -> dict[str, int]:
    """rule -> number of jobs from the 'Job stats' table of a dry run."""
    counts = {}
    block = dry_run_output.split("Job stats:", 1)[-1] if "Job stats:" in dry_run_output else ""
    for line in block.splitlines()[3:]:
        m = re.match(r"^(\w+)\s+(\d+)$", line.strip())
        if not m:
            break
        counts[m.group(1)] = int(m.group(2))
    counts.pop("total", None)
    return counts


@pytest.fixture(scope="module")
def pipeline(tmp_path_factory):
    """The tiny pipeline, run once: (directory, completed process)."""
    root = make_copy(tmp_path_factory.mktemp("workflow"))
    proc = snakemake(root, "--cores", "2")
    assert proc.returncode == 0, proc.stdout[-5000:]
    return root, proc


# --------------------------------------------------------------------------- full run
@pytest.mark.slow
def test_outputs_logs_and_benchmarks_exist(pipeline):
    root, _ = pipeline
    for rel in ["results/impacts_validated.csv", "results/fit.nc", "results/phase_portraits.nc",
                "results/dynamics.nc", "results/bifurcation.nc", "results/reproduction.csv",
                "results/reproduction.md", "results/flags.csv", "results/flags.nc", "results/kharaz.nc",
                "results/stress_summary.json", "results/stress.nc", "reports/report.pdf", *[f"results/sweeps/case_{c}.nc" for c in TINY_SWEEPS]]:
        assert (root / rel).stat().st_size > 0, rel
    assert not (root / "results" / "benchmark").exists()  # benchmark switched off
    for rule in ["validate_data", "fit", "flags", "phase_portraits", "dynamics_summary", "bifurcation",
                 "reproduction", "kharaz", "stress", "report"]:
        assert (root / "logs" / f"{rule}.log").exists(), rule
        bench = (root / "benchmarks" / f"{rule}.tsv").read_text().splitlines()
        assert bench[0].split("\t")[0] == "s" and len(bench) == 2, rule
    assert (root / "logs" / "sweeps" / "case_2.1.log").exists()
    # no temporary files of the atomic writers left behind
    assert not list(root.rglob(".*.tmp"))


@pytest.mark.slow
def test_fit_netcdf(pipeline):
    root, _ = pipeline
    with xr.open_dataset(root / "results" / "fit.nc") as ds:
        for name in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion"):
            assert ds[name].attrs["units"] in ("1", "J m-2", "J/m^2", "J/m2"), name
            assert np.isfinite(float(ds[name]))
        assert ds["normal_speed"].attrs["units"] in ("m s-1", "m/s")
        assert ds.sizes["point"] == 100
        # synthetic data were made with Table 1 row 2: zeta_H = 0.5, zeta_A = 29
        assert abs(float(ds["zeta_adhesion"]) - 29.0) < 5 * float(ds["zeta_adhesion_stderr"]) + 1.0
        assert "synthetic_microspheres.csv" in ds.attrs["fit_source"]


@pytest.mark.slow
def test_sweep_and_dynamics_netcdf(pipeline):
    root, _ = pipeline
    with xr.open_dataset(root / "results" / "sweeps" / "case_2.1.nc") as ds:
        assert ds.attrs["case"] == "2.1"
        assert dict(ds.sizes) == {"speed": 2, "incidence_deg": 2}
        assert ds["speed"].attrs["units"] == "m s-1"
        for name in ("e_n", "mu_t", "K_L", "K_t", "outcome"):
            assert "units" in ds[name].attrs and "long_name" in ds[name].attrs, name
        # 0.5 m/s is captured with Table 1 row 2, 3 m/s rebounds
        assert ds["e_n"].sel(speed=0.5, incidence_deg=0.0) == 0.0
        assert 0.0 < float(ds["e_n"].sel(speed=3.0, incidence_deg=0.0)) < 1.0
    with xr.open_dataset(root / "results" / "sweeps" / "case_2.4.nc") as ds:
        assert list(ds["friction"].values) == [0.0, 0.9]
    with xr.open_dataset(root / "results" / "dynamics.nc") as ds:
        assert ds["critical_velocity"].attrs["units"] == "m/s"
        assert float(ds["critical_velocity"]) == pytest.approx(2.246e-5, rel=2e-3)  # Eq. (38), paper 2.25e-5
        assert list(ds["equilibrium_type"].values) == ["sink", "spiral sink"]
    with xr.open_dataset(root / "results" / "bifurcation.nc") as ds:
        assert "case_C1" in ds and ds["case_speed"].attrs["units"] == "m/s"
    from microimpact.dynamics.nonlinear import load_phase_portraits

    portraits = load_phase_portraits(root / "results" / "phase_portraits.nc")
    assert [p.attrs["outcome"] for p in portraits] == ["capture", "rebound"]
    assert portraits[0]["time"].attrs["units"] == "s"


@pytest.mark.slow
def test_flags_kharaz_reproduction(pipeline):
    import pandas as pd

    root, _ = pipeline
    flags = pd.read_csv(root / "results" / "flags.csv")
    assert len(flags) == 100 and {"row", "rotation_sensitive", "angle_sensitive", "near_capture"} <= set(flags)
    with xr.open_dataset(root / "results" / "flags.nc") as ds:
        assert ds.sizes["impact"] == 100
    with xr.open_dataset(root / "results" / "kharaz.nc") as ds:
        assert any(name.startswith("tangential_restitution") for name in ds.data_vars)
    repro = pd.read_csv(root / "results" / "reproduction.csv")
    assert {"id", "claim", "paper_value", "toolkit_value", "agree"} <= set(repro)
    assert (root / "results" / "reproduction.md").read_text().startswith("# Reproduction")


@pytest.mark.slow
def test_stress_summary_and_netcdf(pipeline):
    import json

    root, _ = pipeline
    summary = json.loads((root / "results" / "stress_summary.json").read_text())
    assert summary["cases_run"] == TINY_STRESS["cases"] and summary["seed"] == TINY_STRESS["seed"]
    assert summary["reference_cases"] == 2  # cases 0 and 10
    assert set(summary["failures_by_kind"]) >= {"exception", "nonfinite", "restitution", "energy", "convergence",
                                                "reference", "timeout"}
    assert summary["cases_failed"] == len(summary["failed_cases"]) == 0, summary["failed_cases"]
    assert 0.0 <= summary["worst_energy_error"]["value"] <= summary["tolerances"]["energy"]
    assert summary["worst_reference_error"]["value"] is not None
    with xr.open_dataset(root / "results" / "stress.nc") as ds:
        assert ds.sizes["case"] == TINY_STRESS["cases"]
        assert ds["radius"].attrs["units"] == "m"
        assert int(np.isfinite(ds["reference_error"].values).sum()) == 2


@pytest.mark.slow
def test_report_pdf_pages_and_titles(pipeline):
    pypdf = pytest.importorskip("pypdf")
    root, _ = pipeline
    reader = pypdf.PdfReader(root / "reports" / "report.pdf")
    texts = [page.extract_text() or "" for page in reader.pages]
    assert 12 <= len(texts) <= 40
    everything = "\n".join(texts)
    for title in EXPECTED_TITLES:
        assert title in everything, title
    assert "SYNTHETIC" in texts[0] and "Provenance" in texts[0] and "Contents" in texts[0]
    assert "switched off" in everything  # the benchmark page says why it is empty
    stress_page = next(t for t in texts if "Numerical stability (stress sweep)" in t and "Seeded random" in t)
    assert "all 20 cases passed every check" in stress_page and "energy balance" in stress_page
    assert "stress sweep" in texts[0]  # provenance and contents
    assert f"page {len(texts)} of {len(texts)}" in texts[-1]
    assert reader.metadata.title.startswith("Microsphere")


# --------------------------------------------------------------------------- incremental behaviour
@pytest.mark.slow
def test_second_run_has_nothing_to_do(pipeline):
    root, _ = pipeline
    proc = snakemake(root, "-n", "--cores", "2")
    assert proc.returncode == 0, proc.stdout
    assert "Nothing to be done" in proc.stdout, proc.stdout[-3000:]


@pytest.mark.slow
def test_changing_data_reruns_only_its_dependants(pipeline):
    root, _ = pipeline
    data = root / "data" / "synthetic_microspheres.csv"
    original = data.read_bytes()
    st = data.stat()
    try:
        # a newer modification time alone does not rerun anything: Snakemake (>= 8) also compares
        # the checksum it recorded for the input, and the content is unchanged
        os.utime(data, (st.st_atime, st.st_mtime + 100))
        touched = snakemake(root, "-n", "--cores", "2")
        assert touched.returncode == 0 and "Nothing to be done" in touched.stdout, touched.stdout[-3000:]
        # changing one measured value reruns the data validation, the fit and what uses the fit
        text = original.decode()
        first_row = text.splitlines()[1]
        changed = first_row.rsplit(",", 4)
        changed[1] = f"{float(changed[1]) * 1.001:.6g}"  # e_n of the first impact
        data.write_text(text.replace(first_row, ",".join(changed), 1))
        proc = snakemake(root, "-n", "--cores", "2")
    finally:
        data.write_bytes(original)
        os.utime(data, (st.st_atime, st.st_mtime))
    assert proc.returncode == 0, proc.stdout
    jobs = job_counts(proc.stdout)
    assert set(jobs) == {"validate_data", "fit", "flags", "report", "all"}, jobs


# --------------------------------------------------------------------------- profile, lint, config
@pytest.mark.slow
def test_slurm_profile_dry_run(pipeline):
    root, _ = pipeline
    pytest.importorskip("snakemake_executor_plugin_slurm")
    proc = snakemake(root, "-n", "--profile", "workflow/profiles/slurm", "--config", "sweep_chunks=2")
    assert proc.returncode == 0, proc.stdout[-5000:]
    jobs = job_counts(proc.stdout)
    assert jobs.get("sweep_chunk") == 2 * len(TINY_SWEEPS) and jobs.get("gather_sweep") == len(TINY_SWEEPS), jobs


@pytest.mark.slow
def test_chunked_sweep_equals_unchunked(pipeline, tmp_path):
    root, _ = pipeline
    other = make_copy(tmp_path / "chunked")
    target = "results/sweeps/case_2.1.nc"
    proc = snakemake(other, target, "--cores", "2", "--config", "sweep_chunks=2")
    assert proc.returncode == 0, proc.stdout[-5000:]
    assert len(list((other / "results" / "sweeps" / "chunks" / "case_2.1").glob("chunk_*_of_2.nc"))) == 2
    with xr.open_dataset(root / target) as a, xr.open_dataset(other / target) as b:
        for name in ("e_n", "mu_t", "K_L", "outcome"):
            np.testing.assert_array_equal(a[name].values, b[name].values)
        assert a.attrs["sweep_spec"] == b.attrs["sweep_spec"]


def test_lint_is_clean(tmp_path):
    root = make_copy(tmp_path / "lint")
    proc = snakemake(root, "--lint")
    assert proc.returncode == 0, proc.stdout
    assert "Lints for" not in proc.stdout, proc.stdout


@pytest.mark.parametrize(
    ("override", "key"),
    [
        ("sweep_chunks=0", "sweep_chunks"),  # below the minimum
        ("sweepchunks=4", "sweepchunks"),  # unknown key (additionalProperties: false)
        ("benchmark={enabled: maybe}", "enabled"),  # not a flag
        ("stress={cases: 0}", "cases"),  # no cases
    ],
)
def test_bad_config_is_refused_naming_the_key(tmp_path, override, key):
    root = make_copy(tmp_path / "bad")
    proc = snakemake(root, "-n", "--cores", "1", "--config", override)
    assert proc.returncode != 0
    assert "Error validating config file" in proc.stdout, proc.stdout
    assert key in proc.stdout.split("Error validating config file", 1)[1], proc.stdout


def test_bad_value_in_config_file_is_refused_naming_the_key(tmp_path):
    root = make_copy(tmp_path / "bad_file")
    cfg = root / "workflow" / "config" / "config.yaml"
    cfg.write_text(cfg.read_text().replace("density: 1350.0", "density: -1350.0"))
    proc = snakemake(root, "-n", "--cores", "1")
    assert proc.returncode != 0
    assert "density" in proc.stdout and "simulation" in proc.stdout, proc.stdout


def test_bad_data_file_stops_at_validation_with_every_problem(tmp_path):
    root = make_copy(tmp_path / "bad_data")
    bad = root / "data" / "bad.csv"
    bad.write_text("radius [um],speed [m/s],incidence_angle [deg],e_n [1]\n"
                   "3.45,2.0,0,0.5\n"
                   "3.45,2.0,90,0.5\n"
                   "3.45,-1,0,1.5\n")
    # target the fit (only validate_data runs before it) so that no unrelated job starts
    proc = snakemake(root, "results/fit.nc", "--cores", "1", "--config", "data=data/bad.csv")
    assert proc.returncode != 0
    assert "Error in rule validate_data" in proc.stdout
    assert "ImpactDataError" in proc.stdout
    for text in ("row 2 (line 3)", "incidence_angle", "row 3 (line 4)", "speed"):
        assert text in proc.stdout, text
    assert not (root / "results" / "fit.nc").exists()
