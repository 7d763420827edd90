# Helpers shared by the rules (no rules here). The config was validated by the Snakefile.
import importlib.util
from snakemake.exceptions import WorkflowError
from pathlib import Path


wildcard_constraints:
    case=r"2\.[1-5]",
    chunk=r"\d+",
    nchunks=r"\d+",


SWEEP_CASES = list(config["sweeps"])
SWEEP_CHUNKS = int(config["sweep_chunks"])
BENCHMARK_ENABLED = bool(config["benchmark"]["enabled"])


def materials_path():
    """Materials config: the bundled one for "default" (located without importing the package)."""
    if config["materials"] != "default":
        return config["materials"]
    spec = importlib.util.find_spec("microimpact")
    if spec is None or spec.origin is None:
        raise WorkflowError("materials: 'default' needs the microimpact package installed (pip install -e .)")
    return str(Path(spec.origin).parent / "io" / "materials.yaml")


def simulation_contact():
    """Contact parameters of the simulations, as keyword arguments of microimpact.Contact."""
    return dict(config["simulation"])


def sweep_file(case):
    return f"results/sweeps/case_{case}.nc"


def sweep_chunk_files(wildcards):
    n = SWEEP_CHUNKS
    return [
        f"results/sweeps/chunks/case_{wildcards.case}/chunk_{i}_of_{n}.nc" for i in range(n)
    ]


def benchmark_outputs():
    """Work-precision results for the report; none when the benchmark is switched off."""
    return {"work_precision": "results/work_precision.nc"} if BENCHMARK_ENABLED else {}
