"""The full pipeline with a cold numba cache against the same pipeline with a warm one, side by side.

Issue 26's targets: a cold run (every compiled kernel compiled on the way) costs at most 1.3 times
a warm one (every kernel loaded from the cache), and both give the same result values, bit for bit.

Each pair copies Snakefile, workflow/ and data/ into two fresh directories, gives them one new,
empty ``NUMBA_CACHE_DIR``, runs the README's ``snakemake --cores 2`` in the first (cold: the
run fills the cache) and then in the second (warm), and compares every result of the two runs
with ``.ci/compare_runs.py`` at a relative tolerance of 0 (the machine's measurements, such as
wall times, left out as there). The ratio is the median over pairs of cold over warm wall time:
a loaded machine slows both runs of a pair alike, and the median discards one disturbed pair::

    python tests/study_cold_warm.py --pairs 3 --out docs/cold-warm.json

CI's smaller form is not this script: its first pipeline runs on an empty cache and its SLURM run,
warm, is compared with it bit for bit (.ci/run).

Exit status 0 when the median ratio is at most ``--target`` and every pair's results are equal;
1 otherwise; Ctrl-C stops the run in progress and ends with one line.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TARGET = 1.3  # issue 26


def _compare_module():
    spec = importlib.util.spec_from_file_location("compare_runs", REPO / ".ci" / "compare_runs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.RTOL = 0.0  # bit for bit
    return module


def _copy(root: Path) -> Path:
    root.mkdir(parents=True)
    shutil.copy(REPO / "Snakefile", root / "Snakefile")
    for folder in ("workflow", "data"):
        shutil.copytree(REPO / folder, root / folder, ignore=shutil.ignore_patterns("__pycache__"))
    return root


def _pipeline(root: Path, cache: Path) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONWARNINGS="ignore", MPLBACKEND="Agg")
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "2", "--quiet"], cwd=root, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    seconds = time.perf_counter() - start
    if done.returncode:
        sys.exit(f"study_cold_warm: snakemake failed in {root} (status {done.returncode}):\n{done.stdout[-3000:]}")
    return seconds


def _rule_seconds(root: Path, column: str = "s") -> dict:
    """One column of every job's Snakemake ``benchmark:`` file: ``s``, the wall time [s], or
    ``cpu_time``, the CPU time of the job's processes [s] (less disturbed by other load of a shared
    machine than the wall time): where a cold run's extra time goes (the critical path of fit,
    flags, figures and report, or the other core)."""
    seconds = {}
    for path in sorted((root / "benchmarks").rglob("*.tsv")):
        header, *rows = path.read_text().strip().splitlines()
        value = rows[-1].split("\t")[header.split("\t").index(column)]
        seconds[path.relative_to(root / "benchmarks").with_suffix("").as_posix()] = float(value)
    return seconds


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pairs", type=int, default=2, help="cold/warm pairs (default 2)")
    parser.add_argument("--target", type=float, default=TARGET, help=f"largest median ratio (default {TARGET})")
    parser.add_argument("--out", type=Path, help="write the summary as JSON here")
    parser.add_argument("--keep", type=Path, help="copy every run's logs/ and benchmarks/ into this new directory")
    args = parser.parse_args(argv)
    if args.pairs < 1:
        parser.error(f"--pairs must be at least 1, got {args.pairs}")
    compare = _compare_module()
    pairs = []
    with tempfile.TemporaryDirectory(prefix="cold_warm_") as tmp:
        for i in range(args.pairs):
            cache = Path(tmp) / f"cache{i}"
            cold = _pipeline(_copy(Path(tmp) / f"cold{i}"), cache)
            warm = _pipeline(_copy(Path(tmp) / f"warm{i}"), cache)
            compare.LARGEST[0] = 0.0
            problems, files, values = compare.compare(Path(tmp) / f"cold{i}" / "results", Path(tmp) / f"warm{i}" / "results")
            jobs_cold, jobs_warm = (_rule_seconds(Path(tmp) / f"{kind}{i}") for kind in ("cold", "warm"))
            cpu_cold, cpu_warm = (_rule_seconds(Path(tmp) / f"{kind}{i}", "cpu_time") for kind in ("cold", "warm"))
            pairs.append({"cold_seconds": round(cold, 2), "warm_seconds": round(warm, 2), "ratio": round(cold / warm, 3),
                          "files_compared": files, "values_compared": values,
                          "largest_relative_difference": compare.LARGEST[0], "differences": problems[:20],
                          "job_seconds_cold_warm": {k: [jobs_cold[k], jobs_warm.get(k)] for k in jobs_cold},
                          "job_cpu_seconds_cold_warm": {k: [cpu_cold[k], cpu_warm.get(k)] for k in cpu_cold}})
            if args.keep:
                for kind in ("cold", "warm"):
                    shutil.copytree(Path(tmp) / f"{kind}{i}", args.keep / f"{kind}{i}",
                                    ignore=shutil.ignore_patterns("results", "reports", ".snakemake"))
            print(f"pair {i}: cold {cold:.1f} s, warm {warm:.1f} s, ratio {cold / warm:.3f}; "
                  f"{values} values in {files} files, {len(problems)} differ")
    ratio = statistics.median(p["ratio"] for p in pairs)
    equal = all(not p["differences"] for p in pairs)
    summary = {"pairs": pairs, "median_ratio": ratio, "target_ratio": args.target, "bitwise_equal": equal,
               "machine_cpus": os.cpu_count(), "machine_platform": platform.platform()}
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(summary, indent=1) + "\n")
    print(f"median cold/warm ratio {ratio:.3f} (target at most {args.target}); results "
          f"{'bitwise equal' if equal else 'DIFFER'}")
    return 0 if ratio <= args.target and equal else 1


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit("study_cold_warm: interrupted")
