"""The standard figure of one result file (``microimpact plot RESULT.nc --out fig.png``).

:func:`result_kind` recognises a result NetCDF by its content (variables, dimensions, groups), not
by its name; :func:`standard_figure` draws the figure of that kind with the report's own figure
functions (:mod:`.figures`), so a file plotted alone looks as it does in the PDF report.

==================== =============================================== ==========================
kind                 recognised by                                   figure
==================== =============================================== ==========================
``phase_portraits``  a group ``portraits``                           :func:`.plot_phase_portraits`
``fit``              ``e_n_measured`` and ``zeta_hertz``             :func:`.plot_fit`
``flags``            ``rotation_sensitive``                          :func:`.plot_flags`
``material_sweep``   attribute ``sweep_spec``, a ``radius`` dim      :func:`.plot_size_dependence`
``sweep``            attribute ``sweep_spec``                        :func:`.plot_restitution_and_impulse`
``bifurcation``      dimensions ``C1`` and ``C2``                    :func:`.plot_bifurcation_plane`
``benchmark``        ``time_per_impact``                             :func:`.plot_work_precision`
``kharaz``           ``tangential_restitution_curve``                :func:`.plot_kharaz`
``model_comparison`` ``aic`` and a ``normal_model`` dim              :func:`.plot_model_comparison`
``posterior``        ``acceptance_fraction``                         :func:`.plot_corner`
``oblique``          title "friction fit from oblique impacts"       :func:`.plot_oblique`
==================== =============================================== ==========================

A sweep has further figures, as in the PDF report (``variant``, :data:`VARIANTS`): the energy-loss
ratios (Figs. 7, 9, 11), the posterior's bands on the sweeps, and for a sweep of the fitted material at several sizes e_n and the
impulse ratios at the median size.

Files of the pipeline that hold numbers rather than curves (``fit_curves``, the dynamics summaries,
the stress sweep) are recognised too, and refused with a message that says where they are drawn.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import netCDF4
import xarray as xr

from microimpact.io.kinds import file_kind
from microimpact.report import figures, models, posterior_figures
from microimpact.io.files import atomic_path
from microimpact.report.inputs import at_radius, read_dataset, read_portraits
from microimpact.report.layout import fork_map

__all__ = ["FIGURE_KINDS", "VARIANTS", "FigureFile", "UnknownResultError", "result_kind", "save_standard_figure",
           "save_standard_figures", "standard_figure"]

#: kinds that have a standard figure, and what it shows
FIGURE_KINDS = {
    "phase_portraits": "phase portraits of normal impacts (Fig. 5)",
    "fit": "e_n(v_n) of the data with the fitted model (Fig. 3)",
    "flags": "model e_n of each measured impact with its range under spin and angle error, flags marked",
    "material_sweep": "e_n(v) per sphere size and the capture velocity against the size",
    "sweep": "e_n and impulse ratios against the speed, one curve per swept value (Figs. 8-14)",
    "bifurcation": "bifurcation plane (C1, C2) (Fig. 4)",
    "benchmark": "work-precision diagram of the solvers",
    "kharaz": "model against the oblique impacts of Kharaz et al. (2001)",
    "model_comparison": "e_n(v_n) of the data with each normal model's fitted curve (AIC/BIC in the report)",
    "posterior": "corner plot of the posterior of the fitted parameters",
    "oblique": "measured against fitted tangential outcome per incidence angle",
}

#: kind -> its figures; the first is the standard one (``microimpact plot --variant``)
VARIANTS = {
    "sweep": ("restitution", "energy_loss"),
    "material_sweep": ("sizes", "restitution", "energy_loss"),
    "posterior": ("corner", "sweep_bands"),
}

#: result files without a figure of their own -> where their numbers are shown
NO_FIGURE = {
    "fit_curves": "the model curves of a fit: draw them with the fit (microimpact plot fit.nc --curves FILE)",
    "dynamics": "numbers of the nonlinear analysis: tables in the report (reports/report.pdf)",
    "stress": "the stress sweep: its summary is a table in the report (reports/report.pdf)",
    "oblique_without_rows": "a friction fit of data without oblique columns: nothing to draw",
}


class UnknownResultError(ValueError):
    """A file that is not a microimpact result file, or one without a standard figure.

    Examples
    --------
    >>> from pathlib import Path
    >>> _ = Path("x.nc").write_text("not netcdf")
    >>> result_kind("x.nc")
    Traceback (most recent call last):
    ...
    microimpact.report.standard.UnknownResultError: x.nc: not a readable NetCDF result file: it is a text file
    """


def _unreadable(path) -> str:
    return f"{path}: not a readable NetCDF result file: it is {file_kind(path)}"


def _open(path) -> xr.Dataset:
    path = Path(path)
    try:
        return read_dataset(path)
    except (OSError, ValueError):  # not NetCDF, or not readable as one
        raise UnknownResultError(_unreadable(path)) from None


def result_kind(path) -> str:
    """The kind of a result NetCDF file (a key of :data:`FIGURE_KINDS` or of :data:`NO_FIGURE`).

    Parameters
    ----------
    path : str or os.PathLike
        A NetCDF file written by microimpact.

    Raises
    ------
    UnknownResultError
        The file cannot be read as NetCDF, or its content is none of the known kinds; the message
        names the file.

    Examples
    --------
    A file with a ``time_per_impact`` variable is a work-precision benchmark.

    >>> import xarray as xr
    >>> xr.Dataset({"time_per_impact": ("solver", [1e-3])}).to_netcdf("bench.nc")
    >>> result_kind("bench.nc")
    'benchmark'
    """
    try:
        with netCDF4.Dataset(os.fspath(path)) as nc:
            if "portraits" in nc.groups:
                return "phase_portraits"
    except OSError:
        raise UnknownResultError(_unreadable(path)) from None
    ds = _open(path)
    if "e_n_measured" in ds and "zeta_hertz" in ds:
        return "fit"
    if "rotation_sensitive" in ds:
        return "flags"
    if "sweep_spec" in ds.attrs:
        return "material_sweep" if "radius" in ds.dims else "sweep"
    if "C1" in ds.dims and "C2" in ds.dims:
        return "bifurcation"
    if "time_per_impact" in ds:
        return "benchmark"
    if "tangential_restitution_curve" in ds:
        return "kharaz"
    if "e_n" in ds and set(ds["e_n"].dims) == {"radius", "speed"}:
        return "fit_curves"
    if "capture_velocity" in ds and "critical_velocity" in ds:
        return "dynamics"
    if "case" in ds.dims and "stress" in str(ds.attrs.get("title", "")).lower():
        return "stress"
    if "aic" in ds and "normal_model" in ds.dims:
        return "model_comparison"
    if "acceptance_fraction" in ds:
        return "posterior"
    if "friction fit from oblique" in str(ds.attrs.get("title", "")).lower():
        return "oblique" if ds.data_vars else "oblique_without_rows"
    raise UnknownResultError(f"{path}: not a microimpact result file of a known kind (the kinds with a figure: "
                             f"{', '.join(FIGURE_KINDS)})")


def standard_figure(path, *, curves=None, variant: str | None = None) -> figures.Plot:
    """The standard figure of a result file, drawn by the report's figure functions.

    Parameters
    ----------
    path : str or os.PathLike
        A result NetCDF of a kind in :data:`FIGURE_KINDS`.
    curves : str or os.PathLike, optional
        For a ``fit``: its smooth model curves (``fit_curves.nc`` of the pipeline); without them
        the model is drawn through the data points.
    variant : str, optional
        For a sweep, which of its figures (:data:`VARIANTS`): ``restitution`` (e_n and the
        impulse ratios, the standard figure of a paper sweep), ``energy_loss`` (K_L, K_t), or
        ``sizes`` (e_n per size and the capture velocity, the standard figure of a sweep at several
        sizes); a sweep at several sizes is drawn at its median size for the first two.

    Returns
    -------
    Plot
        The figure and its caption.

    Raises
    ------
    UnknownResultError
        For an unknown file, a file of a kind without a figure, or ``curves`` given for another
        kind; the message names the file.

    Examples
    --------
    The standard figure of a small sweep, with its caption:

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.studies.sweeps import run_sweep, save_sweep
    >>> path = save_sweep(run_sweep(WALL_1990, {"speed": [2.0, 4.0, 8.0]}), "sweep.nc")
    >>> standard_figure(path).caption.split(".")[0]
    'Restitution coefficient and tangential impulse ratios'
    >>> standard_figure(path, variant="energy_loss").caption.split(".")[0]
    'Kinetic energy loss ratios'
    """
    kind = result_kind(path)
    if kind in NO_FIGURE:
        raise UnknownResultError(f"{path}: a '{kind}' result file has no standard figure ({NO_FIGURE[kind]})")
    if curves is not None and kind != "fit":
        raise UnknownResultError(f"{curves}: model curves go with a fit file, but {path} is a '{kind}' file")
    if variant is not None and variant not in VARIANTS.get(kind, ()):
        choices = f"its figures: {', '.join(VARIANTS[kind])}" if kind in VARIANTS else "it has one figure"
        raise UnknownResultError(f"{path}: a '{kind}' result file has no figure {variant!r} ({choices})")
    if kind == "phase_portraits":
        return figures.plot_phase_portraits(read_portraits(path))
    ds = _open(path)
    if kind == "fit":
        curve_ds = None
        if curves is not None:
            if result_kind(curves) != "fit_curves":
                raise UnknownResultError(f"{curves}: not a file of model curves (e_n on radius x speed)")
            curve_ds = _open(curves)
        return figures.plot_fit(ds, curve_ds)
    if kind == "posterior":
        variant = variant or VARIANTS[kind][0]
        return posterior_figures.plot_corner(ds) if variant == "corner" else posterior_figures.plot_sweep_bands(ds)
    if kind in VARIANTS:
        variant = variant or VARIANTS[kind][0]
        if variant == "sizes":
            return figures.plot_size_dependence(ds)
        if kind == "material_sweep":
            ds = at_radius(ds, ds.sizes["radius"] // 2)
        return figures.plot_energy_loss(ds) if variant == "energy_loss" else figures.plot_restitution_and_impulse(ds)
    draw = {
        "flags": figures.plot_flags,
        "bifurcation": figures.plot_bifurcation_plane,
        "benchmark": figures.plot_work_precision,
        "kharaz": figures.plot_kharaz,
        "model_comparison": models.plot_model_comparison,
        "oblique": posterior_figures.plot_oblique,
    }[kind]
    return draw(ds)


@dataclass(frozen=True)
class FigureFile:
    """One standard figure to save: the result file, the figure file (its suffix gives the format:
    png, pdf or svg) and the options of :func:`standard_figure`.

    Examples
    --------
    >>> FigureFile("fit.nc", "fig/fit.png")
    FigureFile(result='fit.nc', out='fig/fit.png', curves=None, variant=None)
    """

    result: str
    out: str
    curves: str | None = None
    variant: str | None = None


def save_standard_figure(file: FigureFile, dpi: float = 150.0) -> str:
    """Draw the standard figure of ``file.result`` and write it to ``file.out`` atomically (its
    directory is made if missing); returns the caption.

    Examples
    --------
    >>> import os
    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.studies.sweeps import run_sweep, save_sweep
    >>> path = save_sweep(run_sweep(WALL_1990, {"speed": [2.0, 4.0]}), "sweep.nc")
    >>> caption = save_standard_figure(FigureFile(str(path), "fig/sweep.png"))
    >>> os.path.getsize("fig/sweep.png") > 0, caption.startswith("Restitution coefficient")
    (True, True)
    """
    plot = standard_figure(file.result, curves=file.curves, variant=file.variant)
    out = Path(file.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(out) as tmp:
        plot.figure.savefig(tmp, format=out.suffix.lower().lstrip("."), dpi=dpi)
    return plot.caption


def save_standard_figures(files, *, workers: int = 1, dpi: float = 150.0) -> list[str]:
    """:func:`save_standard_figure` for each of ``files``, by ``workers`` forked processes (one
    process start and one import for a whole set of figures, rather than one job, process and
    import per figure). Returns the captions in order.

    Examples
    --------
    Two figures of one file (a PNG and a PDF), their captions in order:

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.studies.sweeps import run_sweep, save_sweep
    >>> path = str(save_sweep(run_sweep(WALL_1990, {"speed": [2.0, 4.0]}), "sweep.nc"))
    >>> files = [FigureFile(path, "fig/a.png"), FigureFile(path, "fig/b.pdf", variant="energy_loss")]
    >>> captions = save_standard_figures(files)
    >>> [c.split(".")[0] for c in captions]
    ['Restitution coefficient and tangential impulse ratios', 'Kinetic energy loss ratios']
    """
    return fork_map(lambda f: save_standard_figure(f, dpi), list(files), workers)
