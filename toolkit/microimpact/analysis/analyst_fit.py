"""The analyst's whole fit in one call: damping, friction from oblique columns, posterior and bands.

:func:`analyse_impacts` is what the CLI's ``fit`` command and the pipeline's fit rule run:

1. :func:`~microimpact.analysis.fitting.fit_damping` (zeta_H, zeta_A, optionally w_A, from e_n(v_n));
2. when the table has oblique columns, :func:`~microimpact.analysis.oblique.fit_friction` after it
   (why after: :mod:`microimpact.analysis.oblique`); the fitted friction replaces the material's in
   the returned :class:`DampingFit` (so flags and simulations of the fitted material use it);
3. optionally the posterior (:func:`~microimpact.analysis.posterior.sample_posterior`), with the
   e_n bands, the capture velocity interval and the sweep bands of the analyst's material.

Its result, :class:`AnalystFit`, saves and loads through the protocol of every fit result
(:class:`~microimpact.analysis.fit_result.FitResult`): its main result, the damping fit, at
``path``, and each part it holds at a path of its own (the pipeline's ``fit.nc``, ``posterior.nc``,
``oblique.nc``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import xarray as xr

from microimpact.analysis.fit_result import DampingFit, FitResult
from microimpact.analysis.oblique import FrictionFit
from microimpact.analysis.posterior import Posterior
from microimpact.io.formatting import ReportHTML
from microimpact.io.files import all_or_nothing, write_netcdf
from microimpact.analysis.fitting import DEFAULT_LOSS, FitProblem, fit_damping, model_restitution
from microimpact.analysis.sampling_defaults import DEFAULT_FIT_METHOD
from microimpact.analysis.oblique import ObliqueProblem, fit_friction
from microimpact.analysis.posterior import (DEFAULT_MAX_STEPS, DEFAULT_METHOD, DEFAULT_N_DRAWS, DEFAULT_NU, DEFAULT_SEED,
                                            DEFAULT_WALKERS, capture_velocity_interval, restitution_bands, sample_posterior,
                                            sweep_bands)
from microimpact.io.provenance import stamp_parameters
from microimpact.solvers import DEFAULT_RTOL, Deadline

__all__ = ["AnalystFit", "analyse_impacts", "POSTERIOR_DEFAULTS", "exclude_rows", "side_by_side"]

def _posterior_defaults() -> dict:
    return dict(walkers=DEFAULT_WALKERS, max_steps=DEFAULT_MAX_STEPS, steps=None, burn=None, seed=DEFAULT_SEED,
                n_draws=DEFAULT_N_DRAWS, method=DEFAULT_METHOD)


#: the posterior settings of the pipeline and the CLI: the library's one home of each
#: (:mod:`microimpact.analysis.posterior`); the chain runs until it converges (or fails loudly)
POSTERIOR_DEFAULTS = _posterior_defaults()


@dataclass(frozen=True, eq=False)
class AnalystFit(ReportHTML, FitResult):
    """Result of :func:`analyse_impacts`.

    Attributes
    ----------
    damping : DampingFit
        The damping fit (friction: the fitted one when oblique data were fitted).
    friction : FrictionFit or None
    posterior : Posterior or None
    posterior_dataset : xarray.Dataset or None
        Chain, summary, diagnostics and bands (:meth:`Posterior.to_dataset
        <microimpact.analysis.posterior.Posterior.to_dataset>` with the band Datasets).

    Notes
    -----
    The protocol of :class:`~microimpact.analysis.fit_result.FitResult`, for a result of three
    parts. Its main result is the damping fit: :meth:`to_dataset` and :meth:`from_dataset` are the
    damping fit's, and ``save(path)`` / ``load(path)`` write and read it alone. The other parts
    have files of their own, given as ``posterior_path`` and ``oblique_path`` (the mapping of
    :meth:`datasets`): the posterior file holds ``posterior_dataset`` and the oblique file the
    :class:`~microimpact.analysis.oblique.FrictionFit`'s Dataset, each stamped with the fitted
    contacts (:func:`microimpact.io.provenance.stamp_parameters`); a part that was not computed is
    written as its kind's :meth:`~microimpact.analysis.fit_result.FitResult.placeholder` saying why,
    and loaded as None.

    Examples
    --------
    Six synthetic impacts without oblique columns: no friction fit, and the oblique file says why:

    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> result = analyse_impacts(table, material)
    >>> result.friction is None, result.posterior is None
    (True, True)
    >>> result.datasets()["oblique"].attrs["comment"]
    'the impact table has no oblique columns: no friction fit'
    >>> [p.name for p in result.save("fit.nc", oblique_path="oblique.nc")]
    ['fit.nc', 'oblique.nc']
    >>> back = AnalystFit.load("fit.nc", oblique_path="oblique.nc")
    >>> back.damping.values == result.damping.values, back.friction
    (True, None)
    """

    TITLE = DampingFit.TITLE
    KIND = DampingFit.KIND
    WRITTEN_BY = DampingFit.WRITTEN_BY
    #: why a part was not computed: the comment of its placeholder file
    NO_POSTERIOR = "posterior not computed"
    NO_FRICTION = "the impact table has no oblique columns: no friction fit"

    damping: object
    friction: object = None
    posterior: object = None
    posterior_dataset: xr.Dataset | None = None
    #: the damping fit without the outliers its verdict names (None when it names none)
    without_outliers: object = None

    def __repr__(self) -> str:
        parts = [repr(self.damping)] + [repr(x) for x in (self.friction, self.posterior) if x is not None]
        return f"AnalystFit({', '.join(parts)})"

    def report(self) -> str:
        """The text reports of the parts that were computed."""
        parts = [self.damping.report()]
        if self.without_outliers is not None:
            parts.append(side_by_side(self.damping, self.without_outliers))
        if self.friction is not None:
            parts.append(self.friction.report())
        if self.posterior is not None:
            parts.append(self.posterior.report())
        return "\n".join(parts)

    def to_dataset(self) -> xr.Dataset:
        """The main result's Dataset: the damping fit's (:meth:`DampingFit.to_dataset`), with the
        refit without the outliers as ``without_outliers_<name>`` attributes (value, interval)."""
        ds = self.damping.to_dataset()
        w = self.without_outliers
        if w is not None:
            for name in w.varied:
                lo, hi = w.interval(name)
                ds.attrs.update({f"without_outliers_{name}": float(w.values[name]),
                                 f"without_outliers_{name}_interval_low": lo,
                                 f"without_outliers_{name}_interval_high": hi})
            ds.attrs["without_outliers_chi_square"] = float(w.verdict.chi_square)
        return ds

    @classmethod
    def from_dataset(cls, ds: xr.Dataset) -> "AnalystFit":
        """An AnalystFit of the damping fit ``ds`` alone (no friction, no posterior)."""
        return cls(DampingFit.from_dataset(ds))

    def datasets(self) -> dict:
        """``{"fit": ..., "posterior": ..., "oblique": ...}``: the Dataset of each file, the parts
        stamped with the fitted contacts, a part not computed as its placeholder."""
        post = self.posterior_dataset if self.posterior_dataset is not None else Posterior.placeholder(self.NO_POSTERIOR)
        oblique = self.friction.to_dataset() if self.friction is not None else FrictionFit.placeholder(self.NO_FRICTION)
        return {"fit": self.to_dataset(), "posterior": self._stamped(post), "oblique": self._stamped(oblique)}

    def save(self, path, posterior_path=None, oblique_path=None) -> tuple:
        """Write the damping fit to ``path`` and, where given, the posterior and the oblique fit
        (:meth:`datasets`) as NetCDF: all of them or, if one cannot be written, none
        (:func:`microimpact.io.files.all_or_nothing`). Returns the paths written."""
        paths = {"fit": path, "posterior": posterior_path, "oblique": oblique_path}
        datasets = self.datasets()
        with all_or_nothing():
            return tuple(write_netcdf(datasets[k], p) for k, p in paths.items() if p is not None)

    @classmethod
    def load(cls, path, posterior_path=None, oblique_path=None) -> "AnalystFit":
        """Read what :meth:`save` wrote: the damping fit at ``path`` and, where given, the parts (a
        placeholder file as None).

        Raises
        ------
        FileNotFoundError, ValueError
            As :meth:`FitResult.load <microimpact.analysis.fit_result.FitResult.load>`, for each file.
        """
        posterior, posterior_ds = (None, None) if posterior_path is None else Posterior._read_part(posterior_path)
        friction = None if oblique_path is None else FrictionFit.load_optional(oblique_path)
        return cls(DampingFit.load(path), friction, posterior, posterior_ds)

    def _stamped(self, ds: xr.Dataset) -> xr.Dataset:
        """``ds`` with the fit's ``parameter_source`` and the fitted contact of every measured size
        (:func:`microimpact.io.provenance.stamp_parameters`), like every result file."""
        fit = self.damping
        return stamp_parameters(ds, [fit.contact(float(r)) for r in fit.radii], fit.parameter_source)


def analyse_impacts(table, base, *, fit_work_of_adhesion: bool = False, weights="auto", confidence_intervals: bool = False,
                    friction: bool = True, posterior: bool | dict = False, errors_in_variables: str = "auto",
                    rtol: float = DEFAULT_RTOL, progress: bool = False, time_budget: float | None = None,
                    exclude=(), outlier_refit: bool = True, loss: str = DEFAULT_LOSS, likelihood: str = "normal",
                    nu: float = DEFAULT_NU, method: str = DEFAULT_FIT_METHOD) -> AnalystFit:
    """Fit the damping, the friction (if oblique columns) and optionally sample the posterior.

    Parameters
    ----------
    table : pandas.DataFrame
        From :func:`microimpact.io.read_impacts` (one material pair).
    base : MaterialPair, Contact or DampingFit
        The material (density, stiffness, w_A, friction start, damping reference speed).
    fit_work_of_adhesion, weights, confidence_intervals
        As :func:`~microimpact.analysis.fitting.fit_damping`.
    friction : bool
        Fit the friction when the table has oblique columns.
    posterior : bool or dict
        False: no posterior; True: :data:`POSTERIOR_DEFAULTS` (run until converged); a dict overrides
        them (``walkers``, ``max_steps``, ``steps`` (a fixed length), ``burn``, ``seed``, ``n_draws``,
        ``method`` (the likelihood's e_n: "emulator" or "solve", :func:`sample_posterior
        <microimpact.analysis.posterior.sample_posterior>`); None values keep the default).
    errors_in_variables, likelihood, nu
        Speed-error treatment, e_n likelihood ("normal" or "student-t") and its degrees of freedom
        [-] of the posterior (:func:`~microimpact.analysis.posterior.sample_posterior`).
    rtol : float
        Relative tolerance of the normal solves. [-]
    progress : bool
        Progress bars on stderr (a terminal only).
    time_budget : float, optional
        Wall-clock budget of the whole analysis (all stages share it); None: no limit. [s]
    exclude : sequence of str
        CSV ids of rows to leave out (the fit's verdict lists them).
    outlier_refit : bool
        Where the verdict names outliers, refit without them and keep both fits
        (:attr:`AnalystFit.without_outliers`); the outliers named are those the refit confirms.
    loss : {"linear", "soft_l1", "huber"}
        Loss of the damping fit (:func:`~microimpact.analysis.fitting.fit_damping`) and its refit.
    method : {"emulator", "solve"}
        How the damping fit evaluates the model e_n (:func:`~microimpact.analysis.fitting.fit_damping`).

    Returns
    -------
    AnalystFit

    Raises
    ------
    TimeBudgetExceeded
        A stage ran past ``time_budget`` (the message names the stage and how far it got).
    PosteriorError
        The posterior collapsed or did not converge.

    Examples
    --------
    Six synthetic impacts of zeta_H = 0.5, zeta_A = 29: the fit is within two standard errors of them:

    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = analyse_impacts(table, material).damping
    >>> {k: bool(abs(fit.values[k] - truth) < 2 * fit.stderr[k])
    ...  for k, truth in (("zeta_hertz", 0.5), ("zeta_adhesion", 29.0))}
    {'zeta_hertz': True, 'zeta_adhesion': True}

    A misspelt posterior option is refused, naming the known ones:

    >>> analyse_impacts(table, material, posterior={"wlakers": 8})
    Traceback (most recent call last):
    ...
    ValueError: unknown posterior option(s) ['wlakers']; known: ['burn', 'max_steps', 'method', 'n_draws', 'seed', 'steps', 'walkers']
    """
    deadline = Deadline.start(time_budget, "analyst fit")
    table, excluded = exclude_rows(table, exclude)

    def damping_fit(rows):
        return fit_damping(rows, base, fit_work_of_adhesion=fit_work_of_adhesion, weights=weights,
                           confidence_intervals=confidence_intervals, rtol=rtol, progress=progress,
                           time_budget=deadline, loss=loss, method=method)

    damping = damping_fit(table)
    without = None
    if outlier_refit and damping.verdict.outlier_ids:
        damping, without = _refit_without_outliers(table, damping, damping_fit, rtol)
    if excluded:
        damping = dataclasses.replace(damping, info=damping.info | {"excluded_ids": ",".join(excluded)})
    damping, ff = _with_friction(table, damping, rtol, progress, deadline) if friction else (damping, None)
    if not posterior:
        return AnalystFit(damping, ff, without_outliers=without)
    opts = _posterior_options(posterior)

    post = sample_posterior(table, damping, ff, walkers=opts["walkers"], steps=opts["steps"], max_steps=opts["max_steps"],
                            burn=opts["burn"], seed=opts["seed"], errors_in_variables=errors_in_variables, rtol=rtol,
                            progress=progress, time_budget=deadline, likelihood=likelihood, nu=nu,
                            method=opts["method"])
    nd = opts["n_draws"]
    ds = post.to_dataset(restitution_bands(post, damping, n_draws=nd, rtol=rtol, time_budget=deadline),
                         capture_velocity_interval(post, damping, n_draws=nd, time_budget=deadline),
                         sweep_bands(post, damping, n_draws=max(nd // 2, 4), rtol=rtol, time_budget=deadline))
    return AnalystFit(damping, ff, post, ds, without)


def _with_friction(table, damping, rtol, progress, deadline):
    """(damping fit carrying the friction the simulations use, FrictionFit) where ``table`` has
    oblique columns; (damping, None) where it has none."""
    try:
        ObliqueProblem.from_table(table)
    except ValueError:
        return damping, None
    ff = fit_friction(table, damping, rtol=rtol, progress=progress, time_budget=deadline)
    friction, source = _friction_for_simulations(ff, damping.friction)
    return dataclasses.replace(damping, friction=friction, info=damping.info | {
        "friction_stderr": ff.stderr["friction"], "friction_source": source, "friction_n_points": ff.n_points,
        "friction_status": ff.identifiability["friction"].status}), ff


def _table_ids(table) -> list[str]:
    """The CSV's id of each row of ``table`` ('row N' where the file has none), as DampingFit.row_ids."""
    rows = table["row"].tolist() if "row" in table.columns else list(range(1, len(table) + 1))
    if "id" in table.columns:
        return [str(i) if str(i) not in ("", "nan") else f"row {r}" for i, r in zip(table["id"].tolist(), rows)]
    return [f"row {r}" for r in rows]


def exclude_rows(table, ids) -> tuple:
    """(``table`` without the rows of the CSV ids ``ids``, the ids excluded); an id the table does not
    hold is refused, naming it.

    Examples
    --------
    >>> import pandas as pd
    >>> t = pd.DataFrame({"id": ["a", "b", "c"], "e_n": [0.5, 0.6, 0.7]})
    >>> kept, gone = exclude_rows(t, ["b"])
    >>> kept["id"].tolist(), gone
    (['a', 'c'], ('b',))
    >>> exclude_rows(t, ["x"])
    Traceback (most recent call last):
    ...
    ValueError: --exclude: id 'x' is not a row of the impact table (ids: a, b, c)
    """
    ids = tuple(str(i).strip() for i in (ids or ()) if str(i).strip())
    if not ids:
        return table, ()
    known = _table_ids(table)
    unknown = [i for i in ids if i not in known]
    if unknown:
        shown = ", ".join(known[:8]) + (", ..." if len(known) > 8 else "")
        raise ValueError(f"--exclude: id {unknown[0]!r} is not a row of the impact table (ids: {shown})")
    keep = [i not in ids for i in known]
    out = table.loc[keep].reset_index(drop=True)
    out.attrs = dict(table.attrs)
    return out, ids


def _refit_without_outliers(table, damping, damping_fit, rtol):
    """(the fit with its confirmed outliers in its info, the refit without them).

    The rows the first fit names are refitted without; an outlier is confirmed where its
    standardized residual against the refit is still beyond the threshold (a row named only
    because the outliers pulled the fit is not). Never drops a row silently: both fits are kept."""
    verdict = damping.verdict
    ids = _table_ids(table)
    named = [i for i in ids if i in verdict.outlier_ids]
    for _ in range(2):  # at most once more, without the confirmed rows only
        kept, _gone = exclude_rows(table, named)
        refit = damping_fit(kept)
        at = [ids.index(i) for i in named]
        d = damping.data.iloc[at]
        model = model_restitution(FitProblem.from_arrays(d["radius"], d["normal_speed"], refit),
                                  refit.zeta_hertz, refit.zeta_adhesion, refit.work_of_adhesion, rtol=rtol)
        z = (model - d["e_n"].to_numpy(float)) / d["sigma"].to_numpy(float)
        confirmed = [i for i, zi in zip(named, z) if not abs(zi) <= verdict.outlier_threshold]
        if confirmed == named or not confirmed:
            break
        named = confirmed
    info = damping.info | {"outlier_ids": ",".join(confirmed),
                           "without_outliers": (f"without {', '.join(confirmed)}: {refit.verdict.text()}"
                                                if confirmed else "")}
    return dataclasses.replace(damping, info=info), (refit if confirmed else None)


def side_by_side(fit, refit) -> str:
    """The fit with and without its outliers, one line per parameter: value and 95 % interval."""
    lines = [f"Fit with and without the outliers ({fit.verdict.outlier_ids and ', '.join(fit.verdict.outlier_ids)})",
             f"  {'':<17}{'all ' + str(fit.n_points) + ' rows':<36}without the outliers ({refit.n_points} rows)"]
    for name in fit.varied:
        cells = []
        for f in (fit, refit):
            lo, hi = f.interval(name)
            cells.append(f"{f.values[name]:.5g} [{lo:.5g}, {hi:.5g}]" if lo == lo else f"{f.values[name]:.5g} (bound)")
        lines.append(f"  {name:<17}{cells[0]:<36}{cells[1]}")
    lines.append(f"  {'verdict':<17}{fit.verdict.verdict:<36}{refit.verdict.text()}")
    return "\n".join(lines)


def _friction_for_simulations(ff, configured: float) -> tuple[float, str]:
    """(f, why) for the fitted material's simulations: the fitted f where the data determine it;
    else the materials config's f if the data allow it, else the end of what they allow -- and say so."""
    st = ff.identifiability["friction"]
    if st.determined:
        return ff.friction, "fit to the oblique columns (after the damping fit, microimpact.analysis.oblique)"
    if st.contains(configured):
        value, which = configured, "the materials config's value, which the data allow"
    else:
        value = st.lower if configured < st.lower else st.upper
        which = f"the end of the range the data allow nearest to the materials config's {configured:g}"
    return float(value), (f"NOT determined by the oblique data ({st.describe()}); the fitted material's "
                          f"simulations use f = {value:.4g}, {which}")


def _posterior_options(posterior) -> dict:
    """The sampler settings from ``True`` or a dict (see :func:`analyse_impacts`); None keeps a default."""
    if posterior is True:
        return dict(POSTERIOR_DEFAULTS)
    opts = dict(posterior)
    opts.pop("enabled", None)
    if "full" in opts:
        raise ValueError("posterior option 'full' was removed: the default chain now runs until it converges "
                         "(50 autocorrelation times, R-hat < 1.01); set max_steps to bound it")
    unknown = set(opts) - set(POSTERIOR_DEFAULTS)
    if unknown:
        raise ValueError(f"unknown posterior option(s) {sorted(unknown)}; known: {sorted(POSTERIOR_DEFAULTS)}")
    method = opts.pop("method", None)  # a name, checked by the sampler (sample_posterior)
    base = dict(POSTERIOR_DEFAULTS)
    base.update({k: int(v) for k, v in opts.items() if v is not None})
    if method is not None:
        base["method"] = method
    return base
