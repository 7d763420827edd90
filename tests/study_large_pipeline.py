"""The whole pipeline on the bundled 100-row data and on a 100,000-row CSV of its shape, side by side.

Issue 53's target: the pipeline on a 100,000-row CSV within 3x its run on the bundled data. The
large CSV is made by the generator of the bundled data
(:func:`microimpact.analysis.synthetic.make_synthetic_impacts`, its defaults, 25,000 impacts per
radius, seed 53: the table of tests/study_large_fit.py). Each run copies Snakefile, workflow/ and
data/ into a fresh directory and runs the README's ``snakemake --cores 2``, the large one with
``--config data=data/large.csv``; both use the numba cache of the environment (``NUMBA_CACHE_DIR``),
which a first, uncounted bundled run fills, so that the pair compares warm runs. The order of the
pair alternates. Measured per run: the CPU time (user + system) of Snakemake and all its jobs, and
of every job on its own: a ``sitecustomize`` module on the jobs' ``PYTHONPATH`` writes each Python
process's ``resource.getrusage`` (itself and its children) at exit, keyed by the rule's script
(Snakemake's ``benchmark:`` files sample the CPU only every 30 s). Wall times are recorded too
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
from collections import defaultdict
from pathlib import Path

from microimpact.analysis.synthetic import write_synthetic_impacts

REPO = Path(__file__).resolve().parents[1]
#: impacts per radius of the large table (four radii: 100,000 rows) and its seed (tests/study_large_fit.py's)
LARGE_PER_RADIUS, LARGE_SEED = 25_000, 53

#: written into the jobs' PYTHONPATH: each process appends its CPU time to $STUDY_CPU_LOG at exit
SITECUSTOMIZE = '''
import atexit, json, os, resource, sys, time
_start = time.perf_counter()
def _record():
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime
    with open(os.environ["STUDY_CPU_LOG"], "a") as f:
        f.write(json.dumps({"argv": sys.argv[:3], "cpu_s": cpu, "wall_s": time.perf_counter() - _start}) + "\\n")
if os.environ.get("STUDY_CPU_LOG"):
    atexit.register(_record)
'''


def _copy(root: Path, large: Path | None) -> Path:
    root.mkdir(parents=True)
    shutil.copy(REPO / "Snakefile", root / "Snakefile")
    for folder in ("workflow", "data"):
        shutil.copytree(REPO / folder, root / folder, ignore=shutil.ignore_patterns("__pycache__"))
    if large is not None:
        shutil.copy(large, root / "data" / "large.csv")
    return root


def _job_name(argv) -> str:
    """The rule's script of a recorded process ('fit', 'flags', ...), or its program."""
    name = Path(argv[0]).name if argv else "?"
    if name.startswith("tmp") and name.endswith(".py") and "." in name[:-3]:
        return name[:-3].split(".", 1)[1]  # .snakemake/scripts/tmpXXXX.fit.py
    return name


def _pipeline(root: Path, config: list, keep: Path | None) -> dict:
    """One run: its CPU and wall time [s] and every job's CPU and wall time [s]."""
    site = root / ".study_site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(SITECUSTOMIZE)
    log = root / "cpu.jsonl"
    env = dict(os.environ, PYTHONWARNINGS="ignore", MPLBACKEND="Agg", STUDY_CPU_LOG=str(log),
               PYTHONPATH=os.pathsep.join([str(site)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "2", "--quiet", *config], cwd=root, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        sys.exit(f"study_large_pipeline: snakemake failed in {root} (status {done.returncode}):\n{done.stdout[-3000:]}")
    jobs = defaultdict(lambda: {"cpu_s": 0.0, "wall_s": 0.0, "processes": 0})
    for line in log.read_text().splitlines():
        rec = json.loads(line)
        name = _job_name(rec["argv"])
        if name in ("snakemake", "__main__.py", "-m"):
            continue  # Snakemake itself: its total includes its jobs
        jobs[name]["cpu_s"] += rec["cpu_s"]
        jobs[name]["wall_s"] += rec["wall_s"]
        jobs[name]["processes"] += 1
    if keep is not None:
        shutil.copytree(root, keep / root.name, ignore=shutil.ignore_patterns("results", ".snakemake", "data"))
    return {"cpu_s": round((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), 2),
            "wall_s": round(wall, 2), "jobs": {k: {q: round(x, 2) for q, x in v.items()} for k, v in sorted(jobs.items())}}


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
