# Helpers shared by the rules (no rules here). The config was validated by the Snakefile.
import importlib.util
import os
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
config["fit"] = {k: (as_bool(v) if k != "weights" else v) for k, v in config["fit"].items()}
config["benchmark"] = {"quick": True, "throughput": False, **config["benchmark"]}
config["benchmark"] = {k: as_bool(v) for k, v in config["benchmark"].items()}
config["rtol"] = float(config["rtol"])
# the stress sweep section is optional; its numbers may arrive as text from snakemake --config
config["stress"] = {"enabled": True, "cases": 20000, "seed": 0, "reference_every": 0, "case_time_limit": 30.0,
                    **config.get("stress", {})}
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
RTOL = config["rtol"]


def materials_path():
    """Materials config: the bundled one for "default" (located without importing the package)."""
    if config["materials"] != "default":
        return config["materials"]
    spec = importlib.util.find_spec("microimpact")
    if spec is None or spec.origin is None:
        raise WorkflowError("materials: 'default' needs the microimpact package installed (pip install -e .)")
    return str(Path(spec.origin).parent / "io" / "materials.yaml")


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
    return {"work_precision": "results/benchmark/benchmark.nc"} if BENCHMARK_ENABLED else {}


def stress_outputs(wildcards):
    """Stress-sweep summary for the report; none when the sweep is switched off."""
    return {"stress": "results/stress_summary.json"} if STRESS_ENABLED else {}
