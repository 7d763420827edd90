"""Files of the benchmark: NetCDF, JSON, Markdown and the work-precision figure."""

from __future__ import annotations

import json
from pathlib import Path

import xarray as xr

from microimpact.io.files import atomic_path, atomic_write, write_netcdf
from microimpact.studies.benchmark.markdown import benchmark_json, benchmark_markdown

__all__ = ["write_benchmark"]


def _figure(ds: xr.Dataset):
    """The work-precision figure of :func:`microimpact.report.figures.plot_work_precision`."""
    # deferred: matplotlib costs about a second at start-up and only the writer needs the figure;
    # the plot lives with the report's figures (one home), the benchmark only saves it
    from microimpact.report.figures import plot_work_precision

    return plot_work_precision(ds).figure


def write_benchmark(ds: xr.Dataset, out_dir, *, docs_dir=None) -> dict:
    """Write benchmark.nc, benchmark.json, benchmark.md and work_precision.pdf/png to ``out_dir``.

    All writes are atomic (:mod:`microimpact.io.files`). With ``docs_dir`` the markdown summary and
    the PNG are also written there (as ``benchmark.md`` and ``work_precision.png``).

    Returns
    -------
    dict of name -> pathlib.Path
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"netcdf": out / "benchmark.nc", "json": out / "benchmark.json", "markdown": out / "benchmark.md",
             "pdf": out / "work_precision.pdf", "png": out / "work_precision.png"}
    write_netcdf(ds, paths["netcdf"])
    with atomic_write(paths["json"]) as f:
        json.dump(benchmark_json(ds), f, indent=1)
        f.write("\n")
    md = benchmark_markdown(ds)
    fig = _figure(ds)
    targets = [(paths["markdown"], paths["pdf"], paths["png"])]
    if docs_dir is not None:
        d = Path(docs_dir)
        d.mkdir(parents=True, exist_ok=True)
        paths["docs_markdown"], paths["docs_png"] = d / "benchmark.md", d / "work_precision.png"
        targets.append((paths["docs_markdown"], None, paths["docs_png"]))
    for markdown, pdf, png in targets:
        with atomic_write(markdown) as f:
            f.write(md)
        for path, kind in ((pdf, "pdf"), (png, "png")):
            if path is not None:
                with atomic_path(path) as tmp:
                    fig.savefig(tmp, format=kind, dpi=150, bbox_inches="tight")
    return paths
