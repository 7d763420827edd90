"""Files of the benchmark: NetCDF, JSON, Markdown and, when the caller draws it, the figure.

The work-precision figure belongs to the report (:func:`microimpact.report.figures.plot_work_precision`);
a study never imports the report, so the entry points (the CLI, the workflow script) draw it and
hand it to :func:`write_benchmark` to be saved beside the other files.
"""

from __future__ import annotations

import json
from pathlib import Path

import xarray as xr

from microimpact.io.files import atomic_path, atomic_write, write_netcdf
from microimpact.studies.benchmark.markdown import benchmark_json, benchmark_markdown

__all__ = ["write_benchmark"]


def write_benchmark(ds: xr.Dataset, out_dir, *, figure=None, docs_dir=None) -> dict:
    """Write benchmark.nc, benchmark.json, benchmark.md and, given a ``figure``, work_precision.pdf/png.

    All writes are atomic (:mod:`microimpact.io.files`). With ``docs_dir`` the markdown summary and
    the PNG are also written there (as ``benchmark.md`` and ``work_precision.png``).

    Parameters
    ----------
    ds : xarray.Dataset
        :func:`run_benchmark` output.
    out_dir : str or os.PathLike
    figure : matplotlib.figure.Figure, optional
        The work-precision figure to save (``plot_work_precision(ds).figure``).
    docs_dir : str or os.PathLike, optional

    Returns
    -------
    dict of name -> pathlib.Path

    Examples
    --------
    The files of a tiny benchmark (two normal speeds, one oblique case, the loosest setting of
    each method, no throughput runs; about a second) with an empty figure: the NetCDF file reads
    back the Dataset's numbers, the JSON file has one record per method run, and the docs copy of
    the summary is the summary:

    >>> import json, tempfile
    >>> import numpy as np
    >>> from matplotlib.figure import Figure
    >>> from microimpact.studies.benchmark import BenchmarkConfig, run_benchmark
    >>> ds = run_benchmark(config=BenchmarkConfig.tiny_(), throughput=False)
    >>> figure = Figure(figsize=(1, 1))  # an empty stand-in for plot_work_precision(ds).figure
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     paths = write_benchmark(ds, Path(tmp) / "out", figure=figure, docs_dir=Path(tmp) / "docs")
    ...     with xr.open_dataset(paths["netcdf"]) as back:
    ...         same = np.array_equal(back["time_per_impact"].values, ds["time_per_impact"].values, equal_nan=True)
    ...     records = json.loads(paths["json"].read_text())["results"]
    ...     docs_same = paths["docs_markdown"].read_text() == paths["markdown"].read_text()
    ...     written = all(path.stat().st_size > 0 for path in paths.values())
    >>> sorted(paths), written
    (['docs_markdown', 'docs_png', 'json', 'markdown', 'netcdf', 'pdf', 'png'], True)
    >>> same, [r["method"] for r in records] == ds["method"].values.tolist(), docs_same
    (True, True, True)
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"netcdf": out / "benchmark.nc", "json": out / "benchmark.json", "markdown": out / "benchmark.md"}
    if figure is not None:
        paths.update(pdf=out / "work_precision.pdf", png=out / "work_precision.png")
    write_netcdf(ds, paths["netcdf"])
    with atomic_write(paths["json"]) as f:
        json.dump(benchmark_json(ds), f, indent=1)
        f.write("\n")
    md = benchmark_markdown(ds)
    targets = [(paths["markdown"], paths.get("pdf"), paths.get("png"))]
    if docs_dir is not None:
        d = Path(docs_dir)
        d.mkdir(parents=True, exist_ok=True)
        paths["docs_markdown"] = d / "benchmark.md"
        if figure is not None:
            paths["docs_png"] = d / "work_precision.png"
        targets.append((paths["docs_markdown"], None, paths.get("docs_png")))
    for markdown, pdf, png in targets:
        with atomic_write(markdown) as f:
            f.write(md)
        for path, kind in ((pdf, "pdf"), (png, "png")):
            if path is not None:
                with atomic_path(path) as tmp:
                    figure.savefig(tmp, format=kind, dpi=150, bbox_inches="tight")
    return paths
