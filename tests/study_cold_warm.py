"""The full pipeline with a cold numba cache against the same pipeline with a warm one, side by side.

Issue 26's targets: a cold run (every compiled kernel compiled on the way) costs at most 1.3 times
a warm one (every kernel loaded from the cache), and both give the same result values, bit for bit.

Each pair copies Snakefile, workflow/ and data/ into two fresh directories, gives them one new,
empty ``NUMBA_CACHE_DIR``, runs the README's ``snakemake --cores 2`` in the first (cold: the
run fills the cache) and then in the second (warm), and compares every result of the two runs
with ``.ci/compare_runs.py`` at a relative tolerance of 0 (the machine's measurements, such as
wall times, left out as there). The ratio is the median over pairs of cold over warm wall time:
a loaded machine slows both runs of a pair alike, and the median discards one disturbed pair.
Each pair also gives the CPU time of both runs (Snakemake and all its jobs) and their ratio, which
other load of a shared machine disturbs far less, and the CPU time of every job (its own process
and forked workers, recorded at its exit); ``--keep DIR`` keeps every run's logs and
``benchmark:`` files (each job's wall time) there::

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
import resource
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


#: a ``sitecustomize`` module for the jobs' processes: at exit, a job's script (Snakemake's copy of it
#: in .snakemake/scripts/) appends its rule, wildcards and CPU time (user + system, all threads, and
#: its forked workers) to the file $STUDY_JOB_CPU. Snakemake's ``benchmark:`` files cannot give it
#: (see _rule_seconds)
_JOB_CPU_HOOK = """\
import atexit, os, resource, sys


def _job_cpu():
    job = getattr(sys.modules.get("__main__"), "snakemake", None)
    if job is None or ".snakemake" not in sys.argv[0]:
        return
    usage, forked = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    name = "/".join([job.rule, *map(str, job.wildcards)])
    with open(os.environ["STUDY_JOB_CPU"], "a") as f:
        f.write(f"{name}\\t{usage.ru_utime + usage.ru_stime + forked.ru_utime + forked.ru_stime}\\n")


if os.environ.get("STUDY_JOB_CPU"):
    atexit.register(_job_cpu)
"""


def _job_cpu(root: Path) -> dict:
    """CPU time of every job of a run [s], summed over its processes (the hook above)."""
    seconds = {}
    path = root / "job_cpu.tsv"
    for line in path.read_text().splitlines() if path.exists() else []:
        name, cpu = line.split("\t")
        seconds[name] = round(seconds.get(name, 0.0) + float(cpu), 2)
    return seconds


def _pipeline(root: Path, cache: Path) -> tuple[float, float]:
    """(wall time, CPU time) of one run [s]; the CPU time is that of Snakemake and every job it ran
    (user and system, all threads), which a shared machine's other load disturbs far less than the
    wall time: on 2 cores a run whose jobs keep both busy takes about half its CPU time. Each job's
    own CPU time goes to root/job_cpu.tsv (:func:`_job_cpu`)."""
    hook = root / "study_hook"
    hook.mkdir()
    (hook / "sitecustomize.py").write_text(_JOB_CPU_HOOK)
    path = os.pathsep.join(p for p in (str(hook), os.environ.get("PYTHONPATH", "")) if p)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONWARNINGS="ignore", MPLBACKEND="Agg",
               PYTHONPATH=path, STUDY_JOB_CPU=str(root / "job_cpu.tsv"))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "2", "--quiet"], cwd=root, env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode:
        sys.exit(f"study_cold_warm: snakemake failed in {root} (status {done.returncode}):\n{done.stdout[-3000:]}")
    return seconds, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _rule_seconds(root: Path) -> dict:
    """Wall time of every job of a run, from Snakemake's ``benchmark:`` files [s]: where a cold
    run's extra time goes (the critical path of fit, flags, figures and report, or the other core).
    Their ``cpu_time`` column is left out: Snakemake samples it every 30 s once a job has run 15 s,
    so it misses up to 30 s of a job's last stretch."""
    seconds = {}
    for path in sorted((root / "benchmarks").rglob("*.tsv")):
        last = path.read_text().strip().splitlines()[-1]
        seconds[path.relative_to(root / "benchmarks").with_suffix("").as_posix()] = float(last.split("\t")[0])
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
            cold, cold_cpu = _pipeline(_copy(Path(tmp) / f"cold{i}"), cache)
            warm, warm_cpu = _pipeline(_copy(Path(tmp) / f"warm{i}"), cache)
            compare.LARGEST[0] = 0.0
            problems, files, values = compare.compare(Path(tmp) / f"cold{i}" / "results", Path(tmp) / f"warm{i}" / "results")
            jobs_cold, jobs_warm = (_rule_seconds(Path(tmp) / f"{kind}{i}") for kind in ("cold", "warm"))
            cpu_cold, cpu_warm = (_job_cpu(Path(tmp) / f"{kind}{i}") for kind in ("cold", "warm"))
            pairs.append({"cold_seconds": round(cold, 2), "warm_seconds": round(warm, 2), "ratio": round(cold / warm, 3),
                          "cold_cpu_seconds": round(cold_cpu, 2), "warm_cpu_seconds": round(warm_cpu, 2),
                          "cpu_ratio": round(cold_cpu / warm_cpu, 3),
                          "files_compared": files, "values_compared": values,
                          "largest_relative_difference": compare.LARGEST[0], "differences": problems[:20],
                          "job_seconds_cold_warm": {k: [jobs_cold[k], jobs_warm.get(k)] for k in jobs_cold},
                          "job_cpu_seconds_cold_warm": {k: [cpu_cold[k], cpu_warm.get(k)] for k in cpu_cold}})
            if args.keep:
                for kind in ("cold", "warm"):
                    shutil.copytree(Path(tmp) / f"{kind}{i}", args.keep / f"{kind}{i}",
                                    ignore=shutil.ignore_patterns("results", "reports", ".snakemake"))
            print(f"pair {i}: cold {cold:.1f} s, warm {warm:.1f} s, ratio {cold / warm:.3f} (CPU {cold_cpu:.1f} and "
                  f"{warm_cpu:.1f} s, {cold_cpu / warm_cpu:.3f}); "
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
