"""Command line of the benchmark: ``python -m microimpact.studies.benchmark [--out DIR] [--quick] [--docs DIR]``.

``python -m`` runs ``__main__``; :func:`main` is also importable as ``microimpact.studies.benchmark.main``.
"""

from __future__ import annotations

import argparse

from microimpact.studies.benchmark.output import write_benchmark
from microimpact.studies.benchmark.run import run_benchmark

__all__ = ["main"]


def main(argv=None) -> int:
    """Run the benchmark, write its files and print their paths; exit status 0."""
    parser = argparse.ArgumentParser(prog="python -m microimpact.studies.benchmark",
                                     description="Work-precision benchmark of the impact solvers.")
    parser.add_argument("--out", default="results/benchmark", help="output directory (default results/benchmark)")
    parser.add_argument("--quick", action="store_true", help="small, fast run (< 60 s) for CI and the workflow")
    parser.add_argument("--docs", default=None, help="also write benchmark.md and work_precision.png here")
    parser.add_argument("--no-throughput", action="store_true", help="skip the 100k throughput and memory runs")
    args = parser.parse_args(argv)
    ds = run_benchmark(quick=args.quick, verbose=True, throughput=not args.no_throughput)
    for p in write_benchmark(ds, args.out, docs_dir=args.docs).values():
        print(p)
    return 0

