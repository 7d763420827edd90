"""The whole pipeline on the bundled 100-row data and on a 100,000-row CSV of its shape, side by side.

Issue 53's target: the pipeline on a 100,000-row CSV within 3x its run on the bundled data. The
large CSV is made by the generator of the bundled data
(:func:`microimpact.analysis.synthetic.make_synthetic_impacts`, its defaults, 25,000 impacts per
radius, seed 53: the table of tests/study_large_fit.py). Each run copies Snakefile, workflow/ and
data/ into a fresh directory and runs the README's ``snakemake --cores 2``, the large one with
``--config data=data/large.csv``; both use the numba cache of the environment (``NUMBA_CACHE_DIR``),
which a first, uncounted bundled run fills, so that the pair compares warm runs. The order of the
pair alternates. Measured per run: the CPU time (user + system) of Snakemake and all its jobs, and
of every job on its own, by tests/study_cold_warm.py's ``sitecustomize`` hook (Snakemake's
``benchmark:`` files sample the CPU only every 30 s). Wall times are recorded too
(the machine is shared). Printed and written as JSON::

    python tests/study_large_pipeline.py --pairs 1 --out docs/large-pipeline.json

Exit status 0. Nothing is asserted: timings are not tests.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from microimpact.analysis.synthetic import write_synthetic_impacts
from study_cold_warm import _JOB_CPU_HOOK, _copy as _copy_workflow, _job_cpu, _rule_seconds

REPO = Path(__file__).resolve().parents[1]
#: impacts per radius of the large table (four radii: 100,000 rows) and its seed (tests/study_large_fit.py's)
LARGE_PER_RADIUS, LARGE_SEED = 25_000, 53

def _copy(root: Path, large: Path | None) -> Path:
    """A fresh copy of the workflow (study_cold_warm's), with the large CSV as data/large.csv."""
    _copy_workflow(root)
    if large is not None:
        shutil.copy(large, root / "data" / "large.csv")
    return root


def _pipeline(root: Path, config: list, keep: Path | None) -> dict:
    """One run: its CPU and wall time [s], every job's CPU time (study_cold_warm's hook) and wall
    time (its ``benchmark:`` file) [s]."""
    hook = root / "study_hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(_JOB_CPU_HOOK)
    env = dict(os.environ, PYTHONWARNINGS="ignore", MPLBACKEND="Agg", STUDY_JOB_CPU=str(root / "job_cpu.tsv"),
               PYTHONPATH=os.pathsep.join(p for p in (str(hook), os.environ.get("PYTHONPATH", "")) if p))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "2", "--quiet", *config], cwd=root, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        sys.exit(f"study_large_pipeline: snakemake failed in {root} (status {done.returncode}):\n{done.stdout[-3000:]}")
    walls = _rule_seconds(root)
    jobs = {name: {"cpu_s": cpu, "wall_s": walls.get(name)} for name, cpu in sorted(_job_cpu(root).items())}
    if keep is not None:
        shutil.copytree(root, keep / root.name, ignore=shutil.ignore_patterns("results", ".snakemake", "data"))
    return {"cpu_s": round((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), 2),
            "wall_s": round(wall, 2), "jobs": jobs}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pairs", type=int, default=1, help="bundled/large pairs (default 1)")
    parser.add_argument("--out", type=Path, help="write the summary as JSON here")
    parser.add_argument("--large", type=Path, help="write (or reuse) the large CSV here")
    parser.add_argument("--keep", type=Path, help="copy every run's logs/ and benchmarks/ into this new directory")
    args = parser.parse_args(argv)
    runs = {"bundled": [], "large": []}
    with tempfile.TemporaryDirectory(prefix="large_pipeline_") as tmp:
        tmp = Path(tmp)
        large = args.large or tmp / "large.csv"
        if not large.exists():
            write_synthetic_impacts(large, n_per_radius=LARGE_PER_RADIUS, seed=LARGE_SEED)
        _pipeline(_copy(tmp / "warmup", None), [], None)  # fills numba's cache: not counted
        for i in range(args.pairs):
            for which in (("bundled", "large") if i % 2 == 0 else ("large", "bundled")):
                root = _copy(tmp / f"{which}{i}", large if which == "large" else None)
                config = ["--config", "data=data/large.csv"] if which == "large" else []
                runs[which].append(_pipeline(root, config, args.keep))
                print(f"pair {i} {which}: CPU {runs[which][-1]['cpu_s']:.1f} s, wall {runs[which][-1]['wall_s']:.1f} s",
                      flush=True)
    cpu = [b["cpu_s"] / a["cpu_s"] for a, b in zip(runs["bundled"], runs["large"])]
    wall = [b["wall_s"] / a["wall_s"] for a, b in zip(runs["bundled"], runs["large"])]
    summary = {"bundled": {"data": "data/synthetic_microspheres.csv", "rows": 100},
               "large": {"data": f"make_synthetic_impacts(n_per_radius={LARGE_PER_RADIUS}, seed={LARGE_SEED})",
                         "rows": 4 * LARGE_PER_RADIUS},
               "runs": runs, "ratio_cpu": cpu, "ratio_wall": wall, "median_ratio_cpu": statistics.median(cpu),
               "median_ratio_wall": statistics.median(wall), "target_ratio": 3.0,
               "load_average_1min_at_end": os.getloadavg()[0], "machine_cpus": os.cpu_count(),
               "machine_platform": platform.platform(),
               "command": "python tests/study_large_pipeline.py --pairs " + str(args.pairs)
                          + (f" --out {args.out}" if args.out else "")}
    text = json.dumps(summary, indent=1)
    print(text)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit("study_large_pipeline: interrupted")
