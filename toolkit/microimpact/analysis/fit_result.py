"""The one save/load protocol of every fit result (:class:`FitResult`), and the result of a
damping fit: :class:`DampingFit`, its NetCDF form and its one formatter.

Every fit result -- :class:`DampingFit`, :class:`~microimpact.analysis.oblique.FrictionFit`,
:class:`~microimpact.analysis.dem_fit.DemLawFit`, :class:`~microimpact.analysis.posterior.Posterior`,
:class:`~microimpact.analysis.target.DampingTarget` and the composite
:class:`~microimpact.analysis.analyst_fit.AnalystFit` -- is a frozen dataclass with ``to_dataset()``,
``from_dataset(ds)``, ``save(path)`` and ``load(path)`` of :class:`FitResult`: one way to write a
result and one to read it back, and one message for a file of another kind.

Kept apart from the fitting procedure (:mod:`microimpact.analysis.fitting`, which needs lmfit) so that
everything that only reads a fit -- the fitted material's simulations, the flags, the CLI -- starts
without importing lmfit (slow to import) or the compiled engine.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np
import pandas as pd
import xarray as xr

from microimpact.io.formatting import ReportHTML, estimates_repr
from microimpact.analysis.identifiability import status_from_variables, status_variables
from microimpact.analysis.verdict import Verdict, assess_residuals
from microimpact.io.kinds import file_kind, layout_mismatch, unreadable_content
from microimpact.io.statuses import stderr_is_meaningful
from microimpact.io.files import CONVENTIONS, restore_label_coordinates, write_netcdf
from microimpact.io.impacts import insert_row_labels, label_variables, labels_from_dataset
from microimpact.io.materials import material_contact
from microimpact.io.provenance import fit_parameter_source, stamp_parameters
from microimpact.io.variables import attributes
from microimpact.model.contact import Contact

__all__ = ["FitResult", "DampingFit", "fit_parameter_table", "format_fit", "PARAMETER_NAMES", "SIGMA_LEVELS",
           "PARAMETER_TABLE_COLUMNS"]

#: names of the fitted parameters, in the order of the correlation matrix
PARAMETER_NAMES = ("zeta_hertz", "zeta_adhesion", "work_of_adhesion")
#: sigma levels of the lmfit confidence intervals
SIGMA_LEVELS = (-2, -1, 1, 2)
#: the standard normal quantile of a two-sided 95 % interval
_Z95 = 1.959963984540054
#: the columns of DampingFit.data that the fit computes (the others are the analyst's row labels)
_POINT_COLUMNS = ("row", "radius", "normal_speed", "e_n", "sigma", "model", "residual")


# --------------------------------------------------------------------------- the protocol
class FitResult:
    """Mixin of every fit result: its NetCDF form, and the one way to save and load it.

    A subclass (a frozen dataclass) gives :meth:`to_dataset` and :meth:`from_dataset`, and names
    its kind in three class attributes: :attr:`TITLE`, the ``title`` attribute its Dataset carries
    (what :meth:`load` recognises the file by), :attr:`KIND`, the words for it in a message, and
    :attr:`WRITTEN_BY`, what writes such a file. :meth:`save` writes the Dataset through
    :func:`microimpact.io.write_netcdf` (atomic, CF-1.10, a ``history`` line); :meth:`load` reads
    it back, and refuses a file of another kind with a message naming the file and what it is.

    A file of the right kind may hold no result: :meth:`placeholder` is the Dataset that says why
    (a posterior that was not sampled, a table without oblique columns), which a pipeline writes in
    place of a result so that its outputs always exist; :meth:`load` refuses it, and
    :meth:`load_optional` reads it as None.

    Examples
    --------
    A damping target round-trips through its file; a damping fit refuses it, naming it:

    >>> from microimpact.analysis.target import DampingTarget, damping_from_target
    >>> from microimpact.presets import WALL_1990
    >>> path = damping_from_target(0.5, 3.0, WALL_1990, n_points=5).save("target.nc")
    >>> DampingTarget.load(path).curves.sizes["curve_point"]
    5
    >>> DampingFit.load(path)
    Traceback (most recent call last):
    ...
    ValueError: target.nc: not a damping fit (the file that 'microimpact fit --out' writes): it is a NetCDF file titled 'damping coefficients that reproduce measured e_n ...'
    """

    #: the ``title`` attribute of the kind's Dataset: a file whose title begins with it is of this kind
    TITLE: ClassVar[str] = ""
    #: what the result is, in words (``"damping fit"``)
    KIND: ClassVar[str] = ""
    #: what writes its file (``"microimpact fit --out"``), for the message that refuses another file
    WRITTEN_BY: ClassVar[str] = ""

    def to_dataset(self) -> xr.Dataset:
        """The result as an xarray Dataset with CF attributes (``units``, ``long_name``)."""
        raise NotImplementedError

    @classmethod
    def from_dataset(cls, ds: xr.Dataset):
        """Inverse of :meth:`to_dataset` (also of the Dataset read back from its file).

        Raises
        ------
        KeyError
            A variable or attribute of the kind is missing.
        """
        raise NotImplementedError

    def save(self, path) -> Path:
        """Write :meth:`to_dataset` to the NetCDF file ``path`` atomically
        (:func:`microimpact.io.write_netcdf`); return ``path``."""
        return write_netcdf(self.to_dataset(), path)

    @classmethod
    def load(cls, path):
        """Read a result written by :meth:`save`.

        Raises
        ------
        FileNotFoundError
            There is no file at ``path``.
        ValueError
            The file is not of this kind (another result, not NetCDF, a :meth:`placeholder`): the
            message names the file and says what it is.
        """
        return cls._from_file(cls.read_dataset(path), path)

    @classmethod
    def read_dataset(cls, path) -> xr.Dataset:
        """The Dataset of a file of this kind, read into memory (the file closed).

        Raises
        ------
        FileNotFoundError, ValueError
            As :meth:`load`.
        """
        try:
            with xr.open_dataset(path, engine="netcdf4") as ds:
                ds = ds.load()
        except FileNotFoundError:
            raise
        except Exception:  # noqa: BLE001 - netCDF4 raises OSError/ValueError variously
            raise ValueError(cls._not_this_kind(path)) from None
        if not str(ds.attrs.get("title", "")).startswith(cls.TITLE):
            raise ValueError(cls._not_this_kind(path))
        return restore_label_coordinates(ds)

    @classmethod
    def load_optional(cls, path):
        """:meth:`load`, but None where the file is the kind's :meth:`placeholder` (a part a
        pipeline did not compute, e.g. the posterior file of a fit without ``--posterior``).

        Raises
        ------
        FileNotFoundError, ValueError
            As :meth:`load`: a file of another kind is an error, not "no result".
        """
        return cls._read_part(path)[0]

    @classmethod
    def _read_part(cls, path) -> tuple:
        """(result, Dataset) of the file ``path``; (None, None) for a placeholder."""
        ds = cls.read_dataset(path)
        if is_placeholder(ds):
            return None, None
        return cls._from_file(ds, path), ds

    @classmethod
    def _from_file(cls, ds: xr.Dataset, path):
        """:meth:`from_dataset` of the Dataset :meth:`read_dataset` read from ``path``."""
        if is_placeholder(ds):
            raise ValueError(f"{path}: holds no {cls.KIND} ({ds.attrs.get('comment', 'no result')})")
        try:
            result = cls.from_dataset(ds)
            # what it took must be what it writes: text or an extra dimension fails later, far from the file
            mismatch = layout_mismatch(path, ds, result.to_dataset(), cls.KIND)
        except KeyError as exc:  # a variable missing: named, and the file's kind said
            raise ValueError(f"{unreadable_content(path, ds, exc)}; {cls._not_this_kind(path).split(': ', 1)[1]}") \
                from None
        except (TypeError, ValueError, IndexError, AttributeError, OverflowError) as exc:
            # a variable of another shape or type than the kind writes (a parameter that is not a
            # scalar): one line naming the file and the variable (issue 55)
            raise ValueError(unreadable_content(path, ds, exc)) from None
        if mismatch:
            raise ValueError(mismatch)
        return result

    @classmethod
    def placeholder(cls, comment: str) -> xr.Dataset:
        """A Dataset of this kind that holds no result, and says why in ``comment``."""
        return xr.Dataset(attrs={"title": cls.TITLE, "Conventions": CONVENTIONS, "comment": comment})

    @classmethod
    def _not_this_kind(cls, path) -> str:
        return f"{path}: not a {cls.KIND} (the file that '{cls.WRITTEN_BY}' writes): it is {file_kind(path)}"


def is_placeholder(ds: xr.Dataset) -> bool:
    """Whether ``ds`` is a :meth:`FitResult.placeholder`: a result's file without a result (no variables)."""
    return not ds.data_vars


# --------------------------------------------------------------------------- result
@dataclass(frozen=True, eq=False)
class DampingFit(ReportHTML, FitResult):
    """Result of :func:`fit_damping`.

    Attributes
    ----------
    values : dict
        Best-fit ``zeta_hertz`` [-], ``zeta_adhesion`` [-], ``work_of_adhesion`` [J/m^2] (fixed
        parameters at their given value).
    stderr : dict
        Standard errors (NaN for fixed parameters), same units.
    varied : tuple of str
        Names of the fitted parameters.
    correlation : numpy.ndarray
        Correlation matrix of :data:`PARAMETER_NAMES` (NaN rows/columns for fixed ones). [-]
    confidence_intervals : dict
        For each varied parameter, {sigma level: limit} for levels -2, -1, 1, 2 from
        :func:`lmfit.conf_interval` (NaN when not computed or when it failed).
    chisqr, redchi, aic, bic : float
        Chi-square, reduced chi-square, Akaike and Bayesian information criteria (lmfit's).
    n_points : int
        Number of data points fitted.
    data : pandas.DataFrame
        The data used: ``row`` (CSV data row), ``radius`` [m], ``normal_speed`` [m/s], ``e_n``,
        ``sigma`` (uncertainty used, effective variance included) [-], ``model`` [-],
        ``residual`` ((model - e_n)/sigma) [-].
    density, stiffness, friction : float
        Material of the fit: [kg/m^3], [Pa], [-].
    damping_reference_speed : float or None
        [m/s]; None = each impact's own normal speed.
    weighting : str
        "e_n uncertainty", "e_n uncertainty + effective variance", "given", or "none".
    scale_covar : bool
        Whether the covariance was scaled by the reduced chi-square.
    info : dict
        nfev, success (True only where the least squares converged AND the data determine every
        varied parameter), message, method, rtol, elapsed_s, source, sha256, material_pair,
        ci_message, outside_physical_range (number of measured e_n kept outside [0, 1]).
    identifiability : dict
        ``{name: ParameterStatus}`` of each varied parameter: a value with its 95 % interval, a
        one-sided bound, or not determined (:mod:`microimpact.analysis.identifiability`). Empty for
        a fit file written before it existed.

    Examples
    --------
    Six noisy synthetic impacts made with zeta_H = 0.5, zeta_A = 29 (Table 1 row 2): each 95 %
    profile-likelihood interval contains the generating value, and the fit survives its NetCDF form:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> path = write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    >>> fit = fit_damping(read_impacts(path), material, confidence_intervals=False)
    >>> intervals = [fit.identifiability[n] for n in ("zeta_hertz", "zeta_adhesion")]
    >>> [(round(s.lower, 3), round(s.upper, 3)) for s in intervals]
    [(0.228, 0.995), (27.367, 29.355)]
    >>> DampingFit.from_dataset(fit.to_dataset()).values == fit.values
    True
    """

    TITLE = "damping fit of the microsphere impact model (Cheng, Brach & Dunn 2002)"
    KIND = "damping fit"
    WRITTEN_BY = "microimpact fit --out"

    values: dict
    stderr: dict
    varied: tuple
    correlation: np.ndarray
    confidence_intervals: dict
    chisqr: float
    redchi: float
    aic: float
    bic: float
    n_points: int
    data: pd.DataFrame
    density: float
    stiffness: float
    friction: float = 0.0
    damping_reference_speed: float | None = None
    weighting: str = "none"
    scale_covar: bool = True
    info: dict = field(default_factory=dict)
    identifiability: dict = field(default_factory=dict)

    @property
    def determined(self) -> bool:
        """True where the data determine every varied parameter (a value with a two-sided interval)."""
        return all(st.determined for st in self.identifiability.values())

    # convenient accessors
    @property
    def zeta_hertz(self) -> float:
        """Fitted zeta_H. [-]"""
        return self.values["zeta_hertz"]

    @property
    def zeta_adhesion(self) -> float:
        """Fitted zeta_A. [-]"""
        return self.values["zeta_adhesion"]

    @property
    def work_of_adhesion(self) -> float:
        """w_A (fitted or fixed). [J/m^2]"""
        return self.values["work_of_adhesion"]

    def contact(self, radius: float) -> Contact:
        """The Contact of a sphere of this radius with the fitted parameters (f0 from Eq. (7)).

        Parameters
        ----------
        radius : float
            Sphere radius. [m]
        """
        return material_contact(self, radius)

    @property
    def radii(self) -> np.ndarray:
        """The distinct sphere radii of the fitted points, ascending. [m]"""
        return np.unique(self.data["radius"].to_numpy(dtype=float))

    @property
    def speed_range(self) -> tuple[float, float]:
        """(smallest, largest) incident normal speed of the fitted points. [m/s]"""
        v = self.data["normal_speed"].to_numpy(dtype=float)
        return float(v.min()), float(v.max())

    @property
    def parameter_source(self) -> str:
        """Provenance of the fitted parameters: ``"fit: <source file name> <sha256>"``.

        From the ``source`` and ``sha256`` the fit recorded of its impact table (NetCDF attributes
        ``fit_source``, ``fit_sha256``); ``unknown`` for what was not recorded (a table built in
        memory).
        """
        return fit_parameter_source(self.info.get("source"), self.info.get("sha256"))

    @property
    def row_ids(self) -> tuple:
        """The CSV's id of each fitted row (its row number where the file has no ``id``)."""
        d = self.data
        if "id" in d.columns:
            ids = d["id"].astype(str).to_numpy()
            return tuple(i if i else f"row {r}" for i, r in zip(ids, d["row"].to_numpy()))
        return tuple(f"row {r}" for r in d["row"].to_numpy())

    @property
    def verdict(self) -> Verdict:
        """Whether the damping law describes these data, the outliers by id and the misfit in words
        (:func:`microimpact.analysis.verdict.assess_residuals` of the standardized residuals)."""
        d = self.data
        v = assess_residuals(d["residual"].to_numpy(float), len(self.varied), stated=self.weighting != "none",
                             ids=self.row_ids, speed=d["normal_speed"].to_numpy(float),
                             radius=d["radius"].to_numpy(float), what="damping law")
        # the outliers confirmed by the refit without them (analyse_impacts), where it ran
        named, without = self.info.get("outlier_ids"), self.info.get("without_outliers")
        excluded = tuple(x for x in str(self.info.get("excluded_ids") or "").split(",") if x)
        # an adequate refit without the outliers: they are the misfit, not the law
        misfit = "" if ": adequate:" in str(without or "") else v.misfit_description
        return dataclasses.replace(v, outlier_ids=v.outlier_ids if named is None else
                                   tuple(x for x in str(named).split(",") if x), misfit_description=misfit,
                                   without_outliers=str(without or ""), excluded=excluded)

    def interval(self, name: str, widened: bool = False) -> tuple[float, float]:
        """The one interval of ``name``: its 95 % profile-likelihood interval (NaN where the data do
        not determine it); ``widened``: each side scaled by the verdict's sqrt(reduced chi-square)
        (the interval of a rejected model with its misfit counted as noise). [units of name]"""
        st = self.identifiability.get(name)
        if st is None or not st.determined:
            return math.nan, math.nan
        w = self.verdict.widening if widened else 1.0
        v = self.values[name]
        return float(v - w * (v - st.lower)), float(v + w * (st.upper - v))

    def interval_stderr(self, name: str) -> float:
        """The one standard error of ``name`` that every output prints (text, ``--json``, fit.nc's
        ``interval_stderr``, the PDF): the width of its 95 % profile interval / 3.92 where the data
        determine it, else the covariance's (NaN for a fixed parameter). [units of name]"""
        lo, hi = self.interval(name)
        if math.isfinite(lo) and math.isfinite(hi):
            return float((hi - lo) / (2 * _Z95))
        return float(self.stderr.get(name, math.nan)) if name in self.varied else math.nan

    # ------------------------------------------------------------------ report
    def report(self) -> str:
        """Readable summary: values, errors, intervals, correlations and fit statistics.

        The text of :func:`format_fit` (the one formatter of a fit).
        """
        return format_fit(self, "text")

    def __str__(self) -> str:  # pragma: no cover - convenience
        return self.report()

    def __repr__(self) -> str:
        return estimates_repr("DampingFit", self.values, self.stderr, self.varied, redchi=float(self.redchi),
                              n_points=int(self.n_points))

    # ------------------------------------------------------------------ NetCDF
    def to_dataset(self) -> xr.Dataset:
        """The fit as an xarray Dataset with CF attributes (``units``, ``long_name``).

        Parameters are scalar variables ``zeta_hertz``, ``zeta_adhesion``, ``work_of_adhesion``
        with ``<name>_stderr`` and ``<name>_confidence_limit(sigma_level)``; the data used are along
        dimension ``point``; the correlation matrix along ``parameter`` x ``parameter_b``.
        """
        d = self.data
        point = np.arange(len(d))
        ds = xr.Dataset(coords={
            "point": ("point", point, {"long_name": "index of the fitted point"}),
            "parameter": ("parameter", np.array(PARAMETER_NAMES, dtype=object), {"long_name": "fit parameter"}),
            "parameter_b": ("parameter_b", np.array(PARAMETER_NAMES, dtype=object), {"long_name": "fit parameter"}),
            "sigma_level": ("sigma_level", np.array(SIGMA_LEVELS, dtype=np.int8),
                            {"units": "1", "long_name": "confidence level in standard deviations (negative: lower limit)"}),
        })
        for name in PARAMETER_NAMES:
            units = attributes(name)["units"]
            varied = name in self.varied
            ds[name] = xr.DataArray(self.values[name], attrs=attributes(name, varied=int(varied)))
            ds[f"{name}_stderr"] = xr.DataArray(self.stderr[name], attrs={
                "units": units, "long_name": f"standard error of {name}"})
            ci = self.confidence_intervals.get(name, {})
            ds[f"{name}_confidence_limit"] = xr.DataArray(
                np.array([ci.get(s, np.nan) for s in SIGMA_LEVELS], dtype=float), dims=("sigma_level",),
                attrs={"units": units, "long_name": f"lmfit.conf_interval limit of {name}"})
        verdict = self.verdict
        for name, st in self.identifiability.items():
            ds.update(status_variables(st, attributes(name)["units"]))
            lo, hi = self.interval(name)
            wlo, whi = self.interval(name, widened=True)
            # the one interval (95 % profile likelihood) and the standard error it implies
            ds[name].attrs.update({"interval_low": lo, "interval_high": hi, "interval_level": 0.95,
                                   "interval_stderr": self.interval_stderr(name), "widened_interval_low": wlo,
                                   "widened_interval_high": whi})
        ds["correlation"] = xr.DataArray(self.correlation, dims=("parameter", "parameter_b"),
                                         attrs=attributes("correlation"))
        ds.update(label_variables(d[[c for c in d.columns if c not in _POINT_COLUMNS]], "point"))
        for col in _POINT_COLUMNS:
            values = d[col].to_numpy(dtype=np.int64 if col == "row" else float)
            name = {"e_n": "e_n_measured", "model": "e_n_model"}.get(col, col)
            ds[name] = xr.DataArray(values, dims=("point",), attrs=attributes(name))
        ds.attrs.update({
            "title": self.TITLE,
            "Conventions": CONVENTIONS,
            "chisqr": float(self.chisqr), "redchi": float(self.redchi), "aic": float(self.aic),
            "bic": float(self.bic), "n_points": int(self.n_points),
            "varied": " ".join(self.varied),
            "density": self.density, "stiffness": self.stiffness, "friction": self.friction,
            "damping_reference_speed": ("per-impact normal speed" if self.damping_reference_speed is None
                                        else float(self.damping_reference_speed)),
            "weighting": self.weighting, "scale_covar": int(self.scale_covar),
        })
        ds.attrs.update(verdict.to_attrs())
        for k, v in self.info.items():
            if v is None:
                continue
            ds.attrs[f"fit_{k}"] = int(v) if isinstance(v, (bool, np.bool_)) else (v if isinstance(v, (int, float, str)) else str(v))
        return stamp_parameters(ds, [self.contact(r) for r in self.radii], self.parameter_source)

    @classmethod
    def from_dataset(cls, ds: xr.Dataset) -> "DampingFit":
        """Inverse of :meth:`to_dataset` (also of the Dataset read back from its file)."""
        ds = restore_label_coordinates(ds)
        a = ds.attrs
        varied = tuple(a["varied"].split()) if a.get("varied") else ()
        values = {n: float(ds[n]) for n in PARAMETER_NAMES}
        stderr = {n: float(ds[f"{n}_stderr"]) for n in PARAMETER_NAMES}
        cis = {}
        for n in varied:
            lim = ds[f"{n}_confidence_limit"].values
            if np.any(np.isfinite(lim)):  # all NaN: not computed (to_dataset's fill of a missing entry)
                cis[n] = {int(s): float(x) for s, x in zip(ds["sigma_level"].values, lim)}
        data = pd.DataFrame({
            "row": ds["row"].values.astype(np.int64), "radius": ds["radius"].values,
            "normal_speed": ds["normal_speed"].values, "e_n": ds["e_n_measured"].values,
            "sigma": ds["sigma"].values, "model": ds["e_n_model"].values, "residual": ds["residual"].values,
        })
        data = insert_row_labels(data, labels_from_dataset(ds, "point"))
        statuses = {n: status_from_variables(ds, n, values[n]) for n in varied}
        ref = a.get("damping_reference_speed")
        info = {k.removeprefix("fit_"): (v.item() if hasattr(v, "item") else v) for k, v in a.items() if k.startswith("fit_")}
        return cls(values=values, stderr=stderr, varied=varied, correlation=np.array(ds["correlation"].values, dtype=float),
                   confidence_intervals=cis, chisqr=float(a["chisqr"]), redchi=float(a["redchi"]), aic=float(a["aic"]),
                   bic=float(a["bic"]), n_points=int(a["n_points"]), data=data, density=float(a["density"]),
                   stiffness=float(a["stiffness"]), friction=float(a["friction"]),
                   damping_reference_speed=None if isinstance(ref, str) else float(ref),
                   weighting=str(a["weighting"]), scale_covar=bool(int(a["scale_covar"])), info=info,
                   identifiability={n: st for n, st in statuses.items() if st is not None})


# --------------------------------------------------------------------------- the one formatter
#: columns of :func:`fit_parameter_table`
PARAMETER_TABLE_COLUMNS = ("parameter", "units", "value", "stderr", "relative", "ci95", "ci1", "ci2", "method")


def fit_parameter_table(fit: "DampingFit") -> pd.DataFrame:
    """The fitted parameters as text cells, one row per parameter of :data:`PARAMETER_NAMES`.

    Parameters
    ----------
    fit : DampingFit
        A fit (:func:`fit_damping`, or read back with :meth:`DampingFit.load` /
        :meth:`DampingFit.from_dataset`).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`PARAMETER_TABLE_COLUMNS`: ``parameter``, ``units`` (of
        :mod:`microimpact.io.variables`), ``value``, ``stderr`` ("fixed" for a fixed
        parameter), ``relative`` (stderr / |value| in %), ``ci1`` and ``ci2`` (1- and 2-sigma
        intervals ``[lo, hi]``), ``ci95`` (the one interval: 95 % profile likelihood) and ``method``:
        profile likelihood (:func:`lmfit.conf_interval`) where it was computed, else value +/- k
        stderr. Where the 95 % profile interval exists, ``stderr`` is the one it implies (its width
        / 3.92), so that the printed standard error agrees with the printed interval.

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> path = write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    >>> fit = fit_damping(read_impacts(path), material, confidence_intervals=False)
    >>> table = fit_parameter_table(fit)
    >>> table[["parameter", "value", "stderr"]].values.tolist()
    [['zeta_hertz', '0.596372', '0.196'], ['zeta_adhesion', '28.3897', '0.507'], ['work_of_adhesion', '0.215834', 'fixed']]
    """
    rows = []
    for name in PARAMETER_NAMES:
        v, s = fit.values[name], fit.stderr[name]
        row = dict.fromkeys(PARAMETER_TABLE_COLUMNS, "") | {
            "parameter": name, "units": attributes(name)["units"], "value": f"{v:.6g}"}
        if name not in fit.varied:
            rows.append(row | {"stderr": "fixed", "method": "fixed (given material)"})
            continue
        st = fit.identifiability.get(name)
        if st is not None and not st.determined:
            rows.append(row | {"value": _bound_text(st), "stderr": "not determined", "method": st.reason})
            continue
        ci = fit.confidence_intervals.get(name, {})
        if all(math.isfinite(ci.get(k, math.nan)) for k in (-1, 1, -2, 2)):
            ci1, ci2, method = (ci[-1], ci[1]), (ci[-2], ci[2]), "profile likelihood (lmfit.conf_interval)"
        elif math.isfinite(s):
            ci1, ci2, method = (v - s, v + s), (v - 2 * s, v + 2 * s), "covariance: value +/- k stderr"
        else:
            ci1 = ci2 = None
            method = "not estimated"
        if st is not None and math.isfinite(st.lower) and math.isfinite(st.upper):
            # the one interval is the profile's 95 %; the standard error printed is the one it implies
            s = fit.interval_stderr(name)
            if not ci:
                ci1, ci2, method = (v - s, v + s), (v - 2 * s, v + 2 * s), "profile likelihood (stderr: 95 % interval width / 3.92)"
        meaningful = stderr_is_meaningful(v, s)
        rows.append(row | {
            "stderr": f"{s:.3g}" if meaningful else "n/a", "relative": f"{100 * s / abs(v):.2g} %" if meaningful else "",
            "ci95": f"[{st.lower:.5g}, {st.upper:.5g}]" if st is not None else "",
            "ci1": f"[{ci1[0]:.5g}, {ci1[1]:.5g}]" if ci1 and meaningful else "",
            "ci2": f"[{ci2[0]:.5g}, {ci2[1]:.5g}]" if ci2 and meaningful else "", "method": method})
    return pd.DataFrame(rows, columns=list(PARAMETER_TABLE_COLUMNS))


def _bound_text(st) -> str:
    """The cell of a parameter the data do not determine: its bound, or 'not determined'."""
    if st.status == "lower_bound":
        return f">= {st.lower:.4g} (95 % bound)"
    if st.status == "upper_bound":
        return f"<= {st.upper:.4g} (95 % bound)"
    return "not determined"


def _determined(fit, name: str) -> bool:
    """Whether the data determine ``name`` (True for a fit file without identifiability)."""
    st = fit.identifiability.get(name)
    return st is None or st.determined


def _fit_facts(fit: "DampingFit") -> dict:
    """Label -> text of everything but the parameters, in report order (correlations: a list)."""
    src, pair = fit.info.get("source"), fit.info.get("material_pair")
    vref = fit.damping_reference_speed
    idx = [PARAMETER_NAMES.index(n) for n in fit.varied]
    facts = {
        "data": (f"{src}" + (f"  [{pair}]" if pair else "")) if src else None,
        "points": f"{fit.n_points} over {len(fit.radii)} radii ({', '.join(f'{r * 1e6:.3g}' for r in fit.radii)} um)",
        "weighting": f"{fit.weighting}; covariance {'scaled by' if fit.scale_covar else 'not scaled by'} "
                     "reduced chi-square",
        "loss": fit.info.get("loss_description") or None,
        "material": f"density {fit.density:g} kg/m3, K {fit.stiffness:.4g} Pa, friction {fit.friction:g}, "
                    "damping reference speed "
                    f"{'per-impact normal speed' if vref is None else f'{vref:g} m/s'}",
        # only where a covariance exists (lmfit gives NaN without one: not a number to print), and
        # between determined parameters: at a parameter's bound the covariance is an artefact of the
        # bound's transform, there or not with the solver's rtol
        "correlations": [f"{fit.varied[a]} / {fit.varied[b]}: {fit.correlation[idx[a], idx[b]]:+.3f}"
                         for a in range(len(idx)) for b in range(a + 1, len(idx))
                         if np.isfinite(fit.correlation[idx[a], idx[b]])
                         and all(_determined(fit, fit.varied[k]) for k in (a, b))],
        "chi-square": f"{fit.chisqr:.4g}, reduced {fit.redchi:.4g} "
                      f"({fit.n_points - len(fit.varied)} degrees of freedom)",
        "AIC, BIC": f"{fit.aic:.4g}, {fit.bic:.4g}",
        "evaluations": f"{fit.info.get('nfev', '?')} ({fit.info.get('elapsed_s', math.nan):.2f} s), "
                       f"{fit.info.get('message', '')}",
        # lmfit's sigma-level intervals: a note only where they would be printed (no 95 % interval)
        "note": (fit.info.get("ci_message") or None) if not all(
            (st := fit.identifiability.get(n)) is not None and st.determined for n in fit.varied) else None,
        "WARNING": fit.info.get("goodness_of_fit") or None,
        "measurements": (f"{fit.info['outside_physical_range']} measured e_n outside [0, 1] within their stated "
                         "uncertainty, fitted as measured" if fit.info.get("outside_physical_range") else None),
    }
    return {k: v for k, v in facts.items() if v is not None}


def format_fit(fit: "DampingFit", style: str = "text") -> str:
    """The one formatter of a damping fit: parameters, intervals, correlations, statistics.

    Parameters
    ----------
    fit : DampingFit
        A fit, e.g. ``DampingFit.load("results/fit.nc")``.
    style : {"text", "markdown"}
        "text": the plain-text report of :meth:`DampingFit.report` (the CLI prints it);
        "markdown": a Markdown pipe table of :func:`fit_parameter_table` followed by a list of
        the data, weighting, material, correlations and statistics (for documents).

    Returns
    -------
    str

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> path = write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    >>> fit = fit_damping(read_impacts(path), material, confidence_intervals=False)
    >>> print(format_fit(fit, "markdown").splitlines()[2])
    | zeta_hertz | 1 | 0.596372 | 0.196 | [0.22795, 0.99477] | profile likelihood (stderr: 95 % interval width / 3.92) |
    """
    table, facts = fit_parameter_table(fit), _fit_facts(fit)
    if style == "markdown":
        head = ["parameter", "units", "value", "std. error", "95 % interval", "method"]
        cols = ["parameter", "units", "value", "stderr", "ci95", "method"]
        lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        lines += ["| " + " | ".join(str(r[c]) or (f"2-sigma {r['ci2']}" if c == "ci95" and r["ci2"] else "")
                                    for c in cols) + " |" for _, r in table.iterrows()]
        lines.append("")
        lines += [f"- **{line.split(':', 1)[0].strip()}**: {line.split(':', 1)[1].strip()}"
                  for line in fit.verdict.lines()]
        for label, text in facts.items():
            text = "; ".join(text) or "n/a" if isinstance(text, list) else text
            lines.append(f"- **{label}**: {text}")
        return "\n".join(lines)
    if style != "text":
        raise ValueError(f"style must be 'text' or 'markdown', got {style!r}")
    lines = ["Damping fit (Cheng, Brach & Dunn 2002, Eqs. (14)-(15), (21), (27))"]
    for label in ("data", "points", "weighting", "loss", "material"):
        if label in facts:
            lines.append(f"  {label:<12}: {facts[label]}")
    verdict = fit.verdict
    lines += verdict.lines()
    lines.append("  parameters  :")
    for _, r in table.iterrows():
        if r["stderr"] == "fixed":
            lines.append(f"    {r['parameter']:<17}= {r['value']} (fixed) [{r['units']}]")
            continue
        if r["stderr"] == "not determined":
            lines.append(f"    {r['parameter']:<17}: {r['value']} [{r['units']}]: not determined by these data "
                         f"({r['method']})")
            continue
        rel = f" ({r['relative']})" if r["relative"] else ""
        how = "" if r["method"].startswith("profile") else f" ({r['method']})"
        ci95 = f"; 95 % interval {r['ci95']} (profile likelihood)" if r["ci95"] else ""
        # one interval per parameter: the sigma-level ones only where no 95 % interval exists
        ci = f"; 1-sigma CI {r['ci1']}, 2-sigma CI {r['ci2']}{how}" if r["ci1"] and not r["ci95"] else ""
        if r["ci95"] and verdict.rejected:
            lo, hi = fit.interval(r["parameter"], widened=True)
            ci95 += (f", conditional on the rejected model; widened by the misfit (x{verdict.widening:.3g}): "
                     f"[{lo:.5g}, {hi:.5g}]")
        err = f" +/- {r['stderr']}{rel}" if r["stderr"] != "n/a" else ""
        lines.append(f"    {r['parameter']:<17}= {r['value']}{err} [{r['units']}]{ci95}{ci}")
    if facts["correlations"]:
        lines += ["  correlations:"] + [f"    {c}" for c in facts["correlations"]]
    for label in ("chi-square", "AIC, BIC", "evaluations", "note", "measurements", "WARNING"):
        if label in facts:
            lines.append(f"  {label:<12}: {facts[label]}")
    return "\n".join(lines)
