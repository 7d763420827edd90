"""``microimpact benchmark``: the work-precision study of the solvers."""

from __future__ import annotations

from microimpact._runtime.progress import wants_progress
from microimpact.io.files import all_or_nothing
from microimpact.io.paths import PathError, check_output_dir, reporting_os_errors, same_file
from microimpact.report.figures import plot_work_precision
from microimpact.studies.benchmark import run_benchmark, write_benchmark



def run(args) -> int:
    out = check_output_dir("--out", args.out)
    docs = check_output_dir("--docs", args.docs) if args.docs is not None else None
    if docs is not None and same_file(out, docs):
        raise PathError("--out and --docs", args.docs, "two outputs on one path (both write benchmark.md); "
                                                       "give --docs another directory")

    # on a terminal a bar of the stages; elsewhere (a pipe, a log) one line per stage
    ds = run_benchmark(quick=args.quick, verbose=not wants_progress(True), throughput=not args.no_throughput,
                       progress=True, time_budget=args.time_budget)
    # all five (seven with --docs) files or none: a disk that fills up after benchmark.nc left it alone
    with reporting_os_errors({"--out": out, "--docs": docs}), all_or_nothing():
        paths = write_benchmark(ds, out, figure=plot_work_precision(ds).figure, docs_dir=docs)
    for path in paths.values():
        print(path)
    return 0
