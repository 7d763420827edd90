"""``microimpact plot``: the standard figure of a result file."""

from __future__ import annotations

import sys

import xarray as xr

from microimpact._commands.common import FIGURE_FORMATS, UsageError
from microimpact.analysis.fit_result import DampingFit
from microimpact.io.paths import PathError, check_input_file, check_outputs, reporting_os_errors
from microimpact.io.resources import check_memory
from microimpact.report.standard import FigureFile, result_kind, save_standard_figure


def run(args) -> int:
    inputs = {"RESULT": check_input_file("RESULT", args.result)}
    if args.curves is not None:
        inputs["--curves"] = check_input_file("--curves", args.curves)
    out = check_outputs({"--out": args.out}, inputs)["--out"]
    fmt = out.suffix.lower().lstrip(".")
    if fmt not in FIGURE_FORMATS:
        raise PathError("--out", args.out, f"has no figure suffix; give a file ending in "
                                           f"{', '.join('.' + f for f in FIGURE_FORMATS)}")
    if fmt == "png":  # the raster: RGBA bytes of the largest standard figure (8 x 10.5 in), and its encoding

        try:
            check_memory(f"--dpi {args.dpi:g}", 2 * 4 * (8.0 * args.dpi) * (10.5 * args.dpi))
        except ValueError as exc:
            raise UsageError(str(exc)) from None
    if result_kind(inputs["RESULT"]) == "fit":
        # read as the --fit options read it: a parameter that is not a scalar ended in a TypeError
        # traceback deep in the figure's caption (issue 55); the reader names the file and variable
        DampingFit.load(inputs["RESULT"])
    figure = FigureFile(str(inputs["RESULT"]), str(out), inputs.get("--curves"), args.variant)
    with reporting_os_errors({"--out": out}):
        caption = save_standard_figure(figure, dpi=args.dpi)
    print(caption)
    verdict = _verdict_line(inputs["RESULT"])
    if verdict:
        print(verdict)
    print(f"wrote {out}", file=sys.stderr)
    return 0


def _verdict_line(path) -> str:
    """The fit's verdict and outliers from a fit file's attributes ("" for a file that has none)."""
    try:
        with xr.open_dataset(path) as ds:
            a = dict(ds.attrs)
    except (OSError, ValueError):
        return ""
    if not a.get("verdict_text"):
        return ""
    outliers = f"; outliers: {a['outlier_ids']}" if a.get("outlier_ids") else ""
    return f"verdict: {a['verdict_text']}{outliers}"
