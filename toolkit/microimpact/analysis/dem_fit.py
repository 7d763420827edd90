"""Fit a DEM engine's contact law (LAMMPS GRANULAR) to measured normal restitution, and rank the laws.

A DEM law here is a normal law (Hertz, the force-controlled JKR of LAMMPS ``jkr``, DMT) with one
of LAMMPS's damping laws (:mod:`microimpact.model.dem_damping`); the material's density, stiffness
and work of adhesion are the analyst's (a material pair), and the one fitted parameter is the
damping coefficient: the restitution e of ``coeff_restitution`` and ``tsuji`` (Hertz only), eta_n0
of ``viscoelastic`` and ``mass_velocity``. Every impact is solved by the toolkit's normal solver at
its own radius and normal speed.

Estimate and interval. The estimate minimises chi^2 = sum ((e_meas - e_model) / sigma)^2, started
from a grid over the whole physical range (so a second minimum is not missed) and refined by a
bounded Brent minimisation (scipy) about the grid's best point. The interval is the project's one
interval of every parameter, the 95 % profile-likelihood interval: where chi^2 rises by 3.84 (the
0.95 quantile of chi^2 with one degree of freedom) above its minimum when sigma is the stated e_n
uncertainty, or by s^2 t^2 (s^2 = chi^2_min / (n - 1), t the two-sided 95 % Student quantile with
n - 1 degrees of freedom) when the data state none (weights "none"). The standard error printed
beside it is the one it implies, its width / 3.92 (as :func:`~microimpact.analysis.fit_result.fit_parameter_table`
does for the paper's damping law), so the two never disagree. The interval is searched over the
physical range [0, 1] of e or [0, inf) of eta_n0, so it may be one-sided:

* **determined**: both ends inside the range; the value is printed with its interval;
* **upper limit**: the data are consistent with no damping (e = 1, eta_n0 = 0): only the upper end
  (or, for e, the lower end) is given, no value;
* **inadequate**: with stated uncertainties, the smallest chi^2 is improbable for n - k degrees
  of freedom (p below :data:`ADEQUACY_P`): the law does not describe the data, and no value is
  printed as its fit (the synthetic microsphere data of this project, made with the paper's
  adhesive model, give chi^2 = 13802 for 99 for the best LAMMPS law). The closest such law is
  still described (:meth:`DemLawFit.misfit_by_size`, :meth:`DemLawFit.closest_lines`): its
  coefficient at the least chi^2, its interval conditional on the rejected law and widened by
  sqrt(chi^2 / dof), and where its e_n misses the data most;
* **not determined**: the chi^2 does not rise by the threshold anywhere up to the strongest damping
  searched (e_n below 1e-4, a sphere that barely leaves): the data give at most a lower limit, and
  nothing is printed as a number.

Every fit carries the :class:`~microimpact.analysis.verdict.Verdict` of its standardized residuals
(:func:`~microimpact.analysis.verdict.assess_residuals`: adequate, or inadequate with chi-square,
degrees of freedom and p, or judged against the scatter without stated uncertainties).

The interval's coverage is checked over random experiment designs (tests/test_dem_fit.py, and
:func:`dem_fit_coverage` as a documented study).

Model comparison. Each candidate law fitted to the same data; AIC = chi^2 + 2 k (sigma known) or
n ln(chi^2 / n) + 2 k (sigma unknown), BIC with k ln n, k = 1; Akaike weights exp(-dAIC / 2)
normalised (Burnham & Anderson 2002).

References
----------
LAMMPS documentation, ``pair_style granular`` (version 22 Jul 2025), https://docs.lammps.org/pair_granular.html.

Burnham, K. P. and Anderson, D. R. (2002), Model Selection and Multimodel Inference, 2nd ed.,
Springer, doi:10.1007/b97636.

Venzon, D. J. and Moolgavkar, S. H. (1988), A method for computing profile-likelihood-based
confidence intervals, Appl. Statist. 37:87-94, doi:10.2307/2347496.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from types import SimpleNamespace

import numpy as np
import xarray as xr

from microimpact.analysis.fit_result import FitResult
from microimpact.io.files import CONVENTIONS
import pandas as pd
from scipy import optimize, stats

from microimpact.analysis.fitting import _sigma_e, _table_arrays
from microimpact.analysis.identifiability import DEFAULT_LEVEL, chi2_threshold
from microimpact.analysis.verdict import ADEQUACY_P, ADEQUATE, INADEQUATE, NO_UNCERTAINTIES, Verdict, assess_residuals
from microimpact.io.materials import material_contact
from microimpact.model.contact import Contact
from microimpact.model.dem_damping import DEM_LAWS, RESTITUTION_DAMPING_MODELS, critical_damping_coefficient
from microimpact.solvers import DEFAULT_RTOL, normal_models as nm

__all__ = ["DEM_LAWS", "DemLawFit", "candidate_laws", "dem_law_contact", "dem_law_restitution", "fit_dem_law", "rank_dem_laws", "ranked_by_aic", "information_criteria", "dem_fit_coverage",
           "INTERVAL_LEVEL", "ADEQUACY_P", "REGION_RAYS"]

#: the probability content of the reported interval: the project's one interval, 95 %
#: (:data:`microimpact.analysis.identifiability.DEFAULT_LEVEL`)
INTERVAL_LEVEL = DEFAULT_LEVEL
#: the standard normal quantile of that two-sided interval: a standard error is the interval's
#: width / (2 z) = width / 3.92
_Z = float(stats.norm.ppf(0.5 + INTERVAL_LEVEL / 2.0))
#: with stated uncertainties, a law whose chi^2 has a p-value below this does not describe the data
#: (its interval would be meaningless): status "inadequate", no value
#: ADEQUACY_P: imported from microimpact.analysis.verdict, its one home

_GRID = 41  # start grid over the physical range
#: eta_n0 searched from 1e-4 critical dampings up to where e_n has fallen below 1e-4 at the median
#: impact (Hertz: 3 critical dampings for viscoelastic, 1 for mass_velocity, measured); beyond it a
#: strongly damped Hertz sphere creeps out of contact in a time that grows without bound
_DECADES = {"viscoelastic": (-4.0, math.log10(3.0)), "mass_velocity": (-4.0, 0.0)}
#: the work of adhesion searched over 1e-5 to 1 J/m^2 in log10 (and w_A = 0 apart): at 1 J/m^2 a
#: 3.45 um sphere of the paper's material is captured up to 1 m/s with LAMMPS's jkr; 1e-5 J/m^2
#: changes its e_n by less than 1e-3 at 0.05 m/s and above (measured)
_ADHESION_DECADES = (-5.0, 0.0)
_PROFILE_GRID = 21  # start grid of each inner and outer minimisation of the joint fit
#: rays traced from the best fit to the boundary of a two-parameter confidence region
#: (:meth:`DemLawFit.confidence_region`, which adds the four ends of the profile intervals): in
#: coordinates where the region is near a circle, a linear function's extreme over 12 equally
#: spaced boundary points is within cos(15 deg) = 0.966 of its extreme over the whole boundary
REGION_RAYS = 12
#: step of the finite-difference Hessian of chi^2 that whitens the region's coordinates, in units
#: of each parameter's 95 % half-width (0.125 x 1.96: a quarter of a standard error)
_HESSIAN_STEP = 0.125


#: units of the damping coefficient of each LAMMPS damping law (e of coeff_restitution and tsuji, eta_n0 else)
_COEFFICIENT_UNITS = {"viscoelastic": "m-1 s-1", "mass_velocity": "s-1"}


@dataclass(frozen=True)
class DemLawFit(FitResult):
    """A DEM law fitted to measured normal restitution.

    Attributes
    ----------
    normal_model, damping_model : str
        The law: ``"hertz"``, ``"jkr_force"`` or ``"dmt"``, and the LAMMPS damping keyword.
    value : float
        The fitted damping coefficient (e [-] or eta_n0 [1/s] or [1/(m s)]); NaN unless determined.
    interval : tuple of float
        The 95 % profile-likelihood interval; an end at the physical bound (0 or 1) or inf is
        not an end the data give.
    status : str
        ``"determined"``, ``"upper limit"`` (consistent with no damping), ``"not determined"`` or
        ``"inadequate"`` (the law does not describe the data).
    chisqr : float
        Smallest chi^2 (with sigma = 1 when the data state no uncertainty). [-]
    n : int
        Impacts fitted.
    sigma_known : bool
        Whether the chi^2 is weighted by stated e_n uncertainties.
    aic, bic : float
        Information criteria (module docstring). [-]
    best : float
        The chi^2 minimiser, also when not determined (for the record, not for printing). [as value]
    material : dict
        density [kg/m^3], stiffness [Pa], work_of_adhesion [J/m^2] the law was fitted with.
    source : str
        Where the data came from.

    Examples
    --------
    Three impacts of e_n = 0.71 +/- 0.01: the constant-restitution law is determined, and its contact
    carries the fitted coefficient; impacts at e_n ~ 1 give only a bound (consistent with no damping):

    >>> import pandas as pd
    >>> t = pd.DataFrame({"radius": [3.45e-6] * 3, "normal_speed": [0.5, 1.0, 2.0], "e_n": [0.70, 0.72, 0.71],
    ...                   "e_n_uncertainty": [0.01] * 3})
    >>> material = {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0}
    >>> f = fit_dem_law(t, material)
    >>> f.determined, f.law, round(f.contact(3.45e-6).damping_coefficient, 4)
    (True, 'hertz+coeff_restitution', 0.71)
    >>> f.describe()
    'hertz+coeff_restitution: damping_coefficient = 0.71 (standard error 0.00577; 95% interval 0.698684 to 0.721316)'

    The standard error is the one the interval implies; here, a mean of three, 0.01 / sqrt(3):

    >>> round(f.stderr, 6), f.verdict.verdict
    (0.005774, 'adequate')
    >>> g = fit_dem_law(t.assign(e_n=[1.0, 0.995, 1.0]), material)
    >>> g.status, g.determined
    ('upper limit', False)
    >>> g.describe()
    'hertz+coeff_restitution: consistent with no damping; the data give only e >= 0.987017 (95%)'

    The fit and its data survive the file, so the loaded fit still gives its confidence region:

    >>> back = DemLawFit.load(f.save("dem_law.nc"))
    >>> back.describe() == f.describe(), back.confidence_region() == f.confidence_region()
    (True, True)
    """

    TITLE = "DEM contact law fitted to measured normal restitution"
    KIND = "DEM law fit"
    WRITTEN_BY = "DemLawFit.save"

    normal_model: str
    damping_model: str
    value: float
    interval: tuple[float, float]
    status: str
    chisqr: float
    n: int
    sigma_known: bool
    aic: float
    bic: float
    best: float
    material: dict = field(default_factory=dict)
    source: str = ""
    adhesion_fitted: bool = False
    work_of_adhesion: float = math.nan
    work_of_adhesion_interval: tuple[float, float] = (math.nan, math.nan)
    adhesion_status: str = ""
    #: the CSV's id of every fitted impact (else its row number), for the verdict's outliers
    ids: tuple = field(default=(), repr=False, compare=False)
    #: (the e_n model, measured e_n, sigma) the fit minimised over, for :meth:`confidence_region`
    _data: tuple = field(default=(), repr=False, compare=False)

    @cached_property
    def model_e_n(self) -> np.ndarray:
        """e_n of the law at the least chi^2 for every fitted impact (empty without the data). [-]"""
        if not self._data:
            return np.array([])
        model = self._data[0]
        return model.e_n(self.best, self.material["work_of_adhesion"] if self.adhesion_fitted else None)

    @cached_property
    def verdict(self) -> Verdict:
        """Adequate or not by the chi-square test of the stated uncertainties, the outliers by id and
        the misfit in words: :func:`~microimpact.analysis.verdict.assess_residuals` of the
        standardized residuals (model - measured) / sigma at the least chi^2, the
        :class:`~microimpact.analysis.verdict.Verdict` every fit carries (the chi-square test alone
        for a fit read back without its data)."""
        what = f"{self.law} law"
        if self._data:
            model, e_meas, sig = self._data
            z = (self.model_e_n - e_meas) / sig
            return assess_residuals(z, self.parameters, stated=self.sigma_known, ids=self.ids or None,
                                    speed=model.speed, radius=model.radii[model.index], what=what)
        dof = float(self.n - self.parameters)
        if not self.sigma_known:
            return Verdict(NO_UNCERTAINTIES, math.nan, dof, math.nan, what=what)
        p = float(stats.chi2.sf(self.chisqr, dof)) if dof > 0 else math.nan
        return Verdict(INADEQUATE if p < ADEQUACY_P else ADEQUATE, float(self.chisqr), dof, p, what=what)

    @property
    def stderr(self) -> float:
        """The damping coefficient's standard error implied by its 95 % interval, width / 3.92
        (NaN unless determined). [as value]"""
        lo, hi = self.interval
        return float((hi - lo) / (2.0 * _Z)) if self.status == "determined" else math.nan

    @property
    def work_of_adhesion_stderr(self) -> float:
        """The work of adhesion's standard error implied by its 95 % interval, width / 3.92 (NaN
        unless fitted and determined). [J/m^2]"""
        lo, hi = self.work_of_adhesion_interval
        return float((hi - lo) / (2.0 * _Z)) if self.adhesion_status == "determined" else math.nan

    def widened_interval(self, name: str = "coefficient") -> tuple[float, float]:
        """The 95 % interval of ``name`` (``coefficient`` or ``work_of_adhesion``) about the least
        chi^2, each side scaled by the verdict's sqrt(chi^2 / dof): the interval of a rejected law
        with its misfit counted as noise (the interval itself where the law is adequate). [as value]"""
        best = self.best if name == "coefficient" else self.material["work_of_adhesion"]
        lo, hi = self.interval_ends()[name]
        w = self.verdict.widening
        return float(best - w * (best - lo)), float(best + w * (hi - best))

    @property
    def determined(self) -> bool:
        """Every fitted parameter determined (only then is the law written for an engine)."""
        return self.status == "determined" and (not self.adhesion_fitted or self.adhesion_status == "determined")

    @property
    def parameters(self) -> int:
        """Fitted parameters: the damping coefficient, and the work of adhesion when fitted."""
        return 2 if self.adhesion_fitted else 1

    @property
    def law(self) -> str:
        return f"{self.normal_model}+{self.damping_model}"

    def describe(self) -> str:
        """One line: the law, the value with its standard error and 95 % interval, or what the data
        cannot tell (the verdict's lines are :meth:`report`)."""
        if self.status == "inadequate":
            v = self.verdict
            return (f"{self.law}: does not describe the data (chi^2 = {self.chisqr:.6g} for {v.degrees_of_freedom:.0f} "
                    f"degrees of freedom, chi^2/dof = {self.chisqr / v.degrees_of_freedom:.4g}, {_p_text(v.p_value)}); "
                    "no value")
        if not self.sigma_known and self.n <= self.parameters:
            return (f"{self.law}: {self.n} impacts without stated e_n uncertainties cannot give {self.parameters} "
                    "parameter(s) and their scatter; no value (state e_n_uncertainty, or measure more impacts)")
        damping = self._describe_damping()
        if not self.adhesion_fitted:
            return damping
        lo, hi = self.work_of_adhesion_interval
        if self.adhesion_status == "determined":
            adhesion = (f"work_of_adhesion = {self.work_of_adhesion:.6g} J/m^2 (standard error "
                        f"{self.work_of_adhesion_stderr:.3g}; 95% interval {lo:.6g} to {hi:.6g})")
        elif self.adhesion_status == "upper limit":
            adhesion = f"work_of_adhesion consistent with no adhesion; the data give only w_A <= {hi:.6g} J/m^2 (95%)"
        else:
            adhesion = (f"work_of_adhesion not determined by these data (w_A >= {lo:.6g} J/m^2, 95%: the data cannot "
                        "tell it from a stronger adhesion)")
        return f"{damping}; {adhesion}"

    def _describe_damping(self) -> str:
        unit = {"viscoelastic": " 1/(m s)", "mass_velocity": " 1/s"}.get(self.damping_model, "")
        lo, hi = self.interval
        if self.status == "determined":
            return (f"{self.law}: damping_coefficient = {self.value:.6g}{unit} (standard error {self.stderr:.3g}; "
                    f"95% interval {lo:.6g} to {hi:.6g})")
        if self.status == "upper limit":
            bound = f"e >= {lo:.6g}" if self.damping_model in RESTITUTION_DAMPING_MODELS else f"eta_n0 <= {hi:.6g}{unit}"
            return f"{self.law}: consistent with no damping; the data give only {bound} (95%)"
        if self.damping_model in RESTITUTION_DAMPING_MODELS:
            return f"{self.law}: damping_coefficient not determined by these data (e <= {hi:.6g}, 95%)"
        return (f"{self.law}: damping_coefficient not determined by these data (eta_n0 >= {lo:.6g}{unit}, 95%: "
                "the data cannot tell it from a stronger damping)")

    def report(self) -> str:
        """The fit as text: :meth:`describe`, then the verdict's lines (verdict, outliers, misfit,
        what the intervals mean) and, for a rejected law, :meth:`closest_lines`."""
        lines = [self.describe(), *self.verdict.lines()]
        if self.status == "inadequate":
            lines += self.closest_lines()
        return "\n".join(lines)

    def misfit_by_size(self) -> list[dict]:
        """Where the law misses the data, per sphere radius: ``radius`` [m], ``speed_min``,
        ``speed_max`` [m/s] (the measured range), ``impacts``, ``largest_error`` (model - measured
        e_n of largest magnitude, [-]) at ``speed`` [m/s], and ``rms_standardized`` (root mean
        square of (model - measured) / sigma). Empty without the data."""
        if not self._data:
            return []
        model, e_meas, sig = self._data
        err = self.model_e_n - e_meas
        out = []
        for i, r in enumerate(model.radii):
            rows = np.flatnonzero(model.index == i)
            k = rows[int(np.argmax(np.abs(err[rows])))]
            out.append({"radius": float(r), "speed_min": float(model.speed[rows].min()),
                        "speed_max": float(model.speed[rows].max()), "impacts": int(rows.size),
                        "largest_error": float(err[k]), "speed": float(model.speed[k]),
                        "rms_standardized": float(np.sqrt(np.mean(np.square(err[rows] / sig[rows]))))})
        return out

    def closest_lines(self) -> list[str]:
        """The text of a rejected law as the closest one: its values at the least chi^2 with their
        intervals conditional on it and widened by sqrt(chi^2 / dof), and, per radius, the largest
        e_n error over the measured speed range."""
        v = self.verdict
        unit = {"viscoelastic": " 1/(m s)", "mass_velocity": " 1/s"}.get(self.damping_model, "")
        lo, hi = self.widened_interval("coefficient")
        out = [f"  least chi^2 : damping_coefficient {self.best:.6g}{unit} (95% interval conditional on the rejected "
               f"law, widened x{v.widening:.3g}: {lo:.6g} to {hi:.6g})"]
        if self.adhesion_fitted:
            lo, hi = self.widened_interval("work_of_adhesion")
            out.append(f"              work_of_adhesion {self.material['work_of_adhesion']:.6g} J/m^2 (likewise "
                       f"{lo:.6g} to {hi:.6g})")
        for m in self.misfit_by_size():
            out.append(f"  radius {m['radius'] * 1e6:.4g} um: {m['impacts']} impacts at {m['speed_min']:.3g}-"
                       f"{m['speed_max']:.3g} m/s; largest e_n error {m['largest_error']:+.3g} (model - measured) at "
                       f"{m['speed']:.3g} m/s; rms standardized residual {m['rms_standardized']:.3g}")
        return out

    def record(self) -> dict:
        """The fit as plain data (``--json``, the exported header): law, statuses, values, standard
        errors and 95 % intervals, chi-square, the verdict's record and the misfit per radius."""
        rec = {"law": self.law, "status": self.status, "interval_level": INTERVAL_LEVEL, "n": int(self.n),
               "parameters": self.parameters, "sigma_known": bool(self.sigma_known), "chisqr": float(self.chisqr),
               "aic": float(self.aic), "damping_coefficient": float(self.value), "damping_coefficient_stderr": self.stderr,
               "damping_coefficient_interval": [float(x) for x in self.interval],
               "damping_coefficient_best": float(self.best),
               "damping_coefficient_widened_interval": list(self.widened_interval()),
               "adhesion_fitted": bool(self.adhesion_fitted)}
        if self.adhesion_fitted:
            rec |= {"adhesion_status": self.adhesion_status, "work_of_adhesion": float(self.work_of_adhesion),
                    "work_of_adhesion_stderr": self.work_of_adhesion_stderr,
                    "work_of_adhesion_interval": [float(x) for x in self.work_of_adhesion_interval],
                    "work_of_adhesion_best": float(self.material["work_of_adhesion"]),
                    "work_of_adhesion_widened_interval": list(self.widened_interval("work_of_adhesion"))}
        return rec | {"verdict": self.verdict.to_record(), "misfit_by_size": self.misfit_by_size()}

    def contact(self, radius: float, *, coefficient: float | None = None,
                work_of_adhesion: float | None = None) -> Contact:
        """The fitted law's contact at ``radius`` [m]: the best values (also when not determined),
        or the damping ``coefficient`` and ``work_of_adhesion`` [J/m^2] given instead."""
        mat = self.material if work_of_adhesion is None else {**self.material, "work_of_adhesion": work_of_adhesion}
        return dem_law_contact(mat, radius, self.normal_model, self.damping_model,
                               self.best if coefficient is None else coefficient)

    def interval_ends(self) -> dict:
        """``{parameter: (low, high)}``: the 95 % interval of every fitted parameter, keyed by the
        :meth:`contact` keyword it moves (``coefficient``; ``work_of_adhesion`` when fitted)."""
        ends = {"coefficient": tuple(map(float, self.interval))}
        if self.adhesion_fitted:
            ends["work_of_adhesion"] = tuple(map(float, self.work_of_adhesion_interval))
        return ends

    def to_dataset(self) -> xr.Dataset:
        """CF form: the damping coefficient (``damping_coefficient`` with ``_lower``, ``_upper`` of
        its 95 % interval, ``_stderr`` (width / 3.92) and ``_best``, the chi^2 minimiser), the work of adhesion likewise,
        the fitted impacts along ``point`` (``radius``, ``normal_speed``, ``e_n_measured``,
        ``sigma``) and the law, status, statistics and material as attributes."""
        unit = _COEFFICIENT_UNITS.get(self.damping_model, "1")
        ds = xr.Dataset()
        for suffix, v, what in (("", self.value, "fitted damping coefficient (NaN unless determined)"),
                                ("_lower", self.interval[0], "lower end of the 95 % interval of the damping coefficient"),
                                ("_upper", self.interval[1], "upper end of the 95 % interval of the damping coefficient"),
                                ("_stderr", self.stderr, "standard error of the damping coefficient (95 % interval width / 3.92)"),
                                ("_best", self.best, "damping coefficient at the least chi-square")):
            ds[f"damping_coefficient{suffix}"] = xr.DataArray(float(v), attrs={"units": unit, "long_name": what})
        for suffix, v, what in (("", self.work_of_adhesion, "fitted work of adhesion (NaN unless fitted and determined)"),
                                ("_lower", self.work_of_adhesion_interval[0], "lower end of the 95 % interval of w_A"),
                                ("_upper", self.work_of_adhesion_interval[1], "upper end of the 95 % interval of w_A"),
                                ("_stderr", self.work_of_adhesion_stderr, "standard error of w_A (95 % interval width / 3.92)")):
            ds[f"work_of_adhesion{suffix}"] = xr.DataArray(float(v), attrs={"units": "J m-2", "long_name": what})
        if self._data:
            model, e_meas, sig = self._data
            point = {"dims": ("point",)}
            ds = ds.assign_coords(point=("point", np.arange(e_meas.size), {"long_name": "index of the fitted impact"}))
            ds["radius"] = xr.DataArray(model.radii[model.index], **point, attrs={"units": "m", "long_name": "sphere radius"})
            ds["normal_speed"] = xr.DataArray(model.speed, **point, attrs={"units": "m s-1", "long_name": "incident normal speed"})
            ds["e_n_measured"] = xr.DataArray(e_meas, **point, attrs={
                "units": "1", "long_name": "measured normal coefficient of restitution"})
            ds["sigma"] = xr.DataArray(sig, **point, attrs={
                "units": "1", "long_name": "e_n uncertainty the chi-square is weighted by (1 where none was stated)"})
            ds.attrs["rtol"] = float(model.rtol)
        ds.attrs.update({
            "title": self.TITLE, "Conventions": CONVENTIONS, "normal_model": self.normal_model,
            "damping_model": self.damping_model, "status": self.status, "chisqr": float(self.chisqr), "n": int(self.n),
            "sigma_known": int(self.sigma_known), "aic": float(self.aic), "bic": float(self.bic), "source": str(self.source),
            "adhesion_fitted": int(self.adhesion_fitted), "adhesion_status": self.adhesion_status,
            "interval_level": float(INTERVAL_LEVEL), "point_ids": ",".join(self.ids),
            **{f"material_{k}": float(v) for k, v in self.material.items()}})
        ds.attrs.update(self.verdict.to_attrs())
        return ds

    @classmethod
    def from_dataset(cls, ds: xr.Dataset) -> "DemLawFit":
        """Inverse of :meth:`to_dataset` (also of the Dataset read back from its file)."""
        a = ds.attrs
        material = {k.removeprefix("material_"): float(v) for k, v in a.items() if k.startswith("material_")}
        data = ()
        if "e_n_measured" in ds:
            model = _Model(material, ds["radius"].values, ds["normal_speed"].values, str(a["normal_model"]),
                           str(a["damping_model"]), float(a["rtol"]))
            data = (model, ds["e_n_measured"].values, ds["sigma"].values)
        return cls(str(a["normal_model"]), str(a["damping_model"]), float(ds["damping_coefficient"]),
                   (float(ds["damping_coefficient_lower"]), float(ds["damping_coefficient_upper"])), str(a["status"]),
                   float(a["chisqr"]), int(a["n"]), bool(int(a["sigma_known"])), float(a["aic"]), float(a["bic"]),
                   float(ds["damping_coefficient_best"]), material, str(a["source"]),
                   adhesion_fitted=bool(int(a["adhesion_fitted"])), work_of_adhesion=float(ds["work_of_adhesion"]),
                   work_of_adhesion_interval=(float(ds["work_of_adhesion_lower"]), float(ds["work_of_adhesion_upper"])),
                   adhesion_status=str(a["adhesion_status"]),
                   ids=tuple(x for x in str(a.get("point_ids", "")).split(",") if x), _data=data)

    def confidence_region(self, level: float = 0.95, rays: int = REGION_RAYS) -> list[dict]:
        """Points on the boundary of the fitted parameters' joint confidence region, as
        :meth:`contact` keywords.

        The region is {chi^2 - chi^2_min <= Delta}, Delta the one-parameter threshold at ``level``
        (chi^2_1 quantile with stated uncertainties, s^2 t^2 with n - k degrees of freedom without):
        its projection on any one function of the parameters is that function's profile-likelihood
        interval at ``level`` when the model is linear (Press et al. 2007, Sec. 15.6.5), which is
        what carrying the normal law's uncertainty into a quantity fitted after it needs. With one
        parameter the boundary is the two ends of its interval at ``level``; with two (the damping
        and the work of adhesion) ``rays`` points, traced from the best fit along directions spaced
        evenly in coordinates that make the region near a circle (log10 w_A and the damping's fit
        coordinate, whitened by a finite-difference Hessian of chi^2; the valley is narrow and
        oblique, because both parameters lower e_n), and the four ends of the two parameters'
        profile intervals at ``level``, which rays miss where the region curves. A ray that leaves the searched range before
        chi^2 rises enough ends at the range's edge (e = 1 or eta_n0 at the strongest damping
        searched, w_A at 1e-5 or 1 J/m^2): the data do not bound the region there. A best fit
        without adhesion or damping traces its rays from the searched range's low edge (w_A =
        1e-5 J/m^2, eta_n0 = 1e-4 critical dampings).

        Parameters
        ----------
        level : float
            Probability content of the one-parameter interval the region projects to. [-]
        rays : int
            Boundary points of a two-parameter region.

        Returns
        -------
        list of dict
            ``{"coefficient": ...}`` (and ``"work_of_adhesion"`` [J/m^2] when fitted) per point:
            2, or ``rays`` + 4.

        Raises
        ------
        ValueError
            A fit not made by :func:`fit_dem_law` (no data).

        References
        ----------
        Press, W. H. et al. (2007), Numerical Recipes, 3rd ed., Cambridge University Press, Sec. 15.6.

        Examples
        --------
        At 95 % the one-parameter region is the reported interval; at 68.27 % it is narrower:

        >>> import pandas as pd
        >>> t = pd.DataFrame({"radius": [3.45e-6] * 3, "normal_speed": [0.5, 1.0, 2.0], "e_n": [0.70, 0.72, 0.71],
        ...                   "e_n_uncertainty": [0.01] * 3})
        >>> f = fit_dem_law(t, {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0})
        >>> [round(p["coefficient"], 4) for p in f.confidence_region(INTERVAL_LEVEL)] == [round(x, 4) for x in f.interval]
        True
        >>> [round(p["coefficient"], 4) for p in f.confidence_region(math.erf(2**-0.5))]
        [0.7042, 0.7158]
        """
        if not self._data:
            raise ValueError(f"confidence_region: this {self.law} fit carries no data (make it with fit_dem_law)")
        model, e_meas, sig = self._data
        to_coef, from_coef, lo_x, hi_x = _coordinate(model)
        threshold = _interval_threshold(self.chisqr, self.n, self.sigma_known, k=self.parameters, level=level)
        if self.adhesion_fitted:
            return _region_boundary(self, model, e_meas, sig, threshold, rays, (to_coef, from_coef, lo_x, hi_x))

        def rise(x):
            return _chisqr(model, to_coef(x), e_meas, sig) - self.chisqr - threshold

        if model.restitution:
            (lo, hi), _, _ = _restitution_interval(rise, from_coef(self.best), lo_x)
        else:
            (lo, hi), _, _ = _damping_interval(rise, lambda c: _chisqr(model, c, e_meas, sig) - self.chisqr - threshold,
                                               to_coef, from_coef(self.best), lo_x, hi_x)
            hi = min(hi, to_coef(hi_x))
        return [{"coefficient": float(lo)}, {"coefficient": float(hi)}]


def _region_boundary(fit, model, e_meas, sig, threshold, rays, coordinate) -> list[dict]:
    """:meth:`DemLawFit.confidence_region` of a two-parameter fit (u = log10 w_A, x the damping's
    coordinate): rays from the best point, evenly spaced after whitening, each ended by Brent's
    method where chi^2 has risen by ``threshold`` (or at the searched range's edge); ``coordinate``
    is :func:`_coordinate` of the model."""
    to_coef, from_coef, lo_x, hi_x = coordinate
    lo = np.array([_ADHESION_DECADES[0], lo_x])
    hi = np.array([_ADHESION_DECADES[1], hi_x])
    # a best fit without adhesion or damping (-inf) starts at the searched range's low edge
    # (_ADHESION_DECADES, _DECADES): the nearest point the rays can be traced from
    centre = np.clip(np.array([_log10(fit.material["work_of_adhesion"]), from_coef(fit.best)]), lo, hi)
    ends = fit.interval_ends()
    half = np.array([(_log10(ends["work_of_adhesion"][1]) - _log10(ends["work_of_adhesion"][0])) / 2.0,
                     (from_coef(ends["coefficient"][1]) - from_coef(ends["coefficient"][0])) / 2.0])
    scale = np.where(np.isfinite(half) & (half > 0.0), half, 0.1)  # a one-sided interval: 0.1 in its coordinate

    def point(z):
        return np.clip(centre + scale * z, lo, hi)

    def chi(z):
        u, x = point(z)
        return _chisqr(model, to_coef(x), e_meas, sig, 10.0**u)

    h, f0 = _HESSIAN_STEP, chi(np.zeros(2))
    fx = [chi(np.array(v)) for v in ((h, 0.0), (-h, 0.0), (0.0, h), (0.0, -h))]
    fxy = [chi(np.array(v)) for v in ((h, h), (h, -h), (-h, h), (-h, -h))]
    hessian = np.array([[fx[0] - 2 * f0 + fx[1], (fxy[0] - fxy[1] - fxy[2] + fxy[3]) / 4.0],
                        [0.0, fx[2] - 2 * f0 + fx[3]]]) / h**2
    hessian[1, 0] = hessian[0, 1]
    curvature, axes = np.linalg.eigh(hessian / 2.0)
    basis = axes / np.sqrt(curvature) if np.all(curvature > 0.0) else np.eye(2)  # near a circle of radius sqrt(Delta)
    points = []
    for theta in 2.0 * np.pi * np.arange(rays) / rays:
        d = basis @ np.array([math.cos(theta), math.sin(theta)])
        with np.errstate(divide="ignore", invalid="ignore"):
            reach = np.where(d > 0, (hi - centre) / (scale * d), np.where(d < 0, (lo - centre) / (scale * d), np.inf))
        t_edge = float(np.min(reach))

        def rise(t, d=d):
            return chi(t * d) - fit.chisqr - threshold

        inside, t = 0.0, min(math.sqrt(threshold), t_edge)
        outside = rise(t) > 0.0
        while not outside and t < t_edge:
            inside, t = t, min(2.0 * t, t_edge)
            outside = rise(t) > 0.0
        if outside:
            t = optimize.brentq(rise, inside, t, xtol=1e-6 * t)
        u, x = point(t * d)
        points.append({"coefficient": float(to_coef(x)), "work_of_adhesion": float(10.0**u)})
    tips = _profile_tips(lambda u, x: _chisqr(model, to_coef(x), e_meas, sig, 10.0**u), centre, lo, hi,
                         fit.chisqr + threshold)
    return points + [{"coefficient": float(to_coef(x)), "work_of_adhesion": float(10.0**u)} for u, x in tips]


def _profile_tips(chi, centre, lo, hi, level):
    """The four points of the region {chi(u, x) <= level} that reach furthest in u and in x: for
    each coordinate and side, where the profile (chi minimised over the other coordinate, -inf
    included) crosses ``level``, or the searched range's edge if it stays below. These are the ends
    of each parameter's profile-likelihood interval; rays from the best point miss them where the
    region is curved (a banana in log10 w_A, whose upper end lies decades from the best fit)."""
    tips = []
    for k in (0, 1):
        hint = [float(centre[1 - k])]

        def profile(v, k=k, hint=hint):
            f = (lambda y: chi(v, y)) if k == 0 else (lambda y: chi(y, v))
            y, value = _minimum(f, lo[1 - k], hi[1 - k], _PROFILE_GRID, hint[-1:])
            hint.append(y)
            return value - level

        for end in (lo[k], hi[k]):
            v = float(end)
            if end != centre[k] and profile(v) > 0.0:
                v = optimize.brentq(profile, float(centre[k]), v, xtol=1e-5)
            profile(v)  # the other coordinate's minimiser at the tip
            tips.append((v, hint[-1]) if k == 0 else (hint[-1], v))
    return tips


def dem_law_contact(material, radius: float, normal_model: str, damping_model: str, coefficient: float) -> Contact:
    """The Contact of a DEM law for a sphere of ``radius`` of ``material``.

    Parameters
    ----------
    material : mapping or object
        density [kg/m^3], stiffness [Pa], work_of_adhesion [J/m^2] (a MaterialPair, a Contact or a dict).
    radius : float
        [m]
    normal_model : {"hertz", "jkr_force", "dmt"}
    damping_model : str
        One of :data:`~microimpact.model.dem_damping.DEM_DAMPING_MODELS`.
    coefficient : float
        The damping coefficient. [e: -, eta_n0: 1/s or 1/(m s)]

    Examples
    --------
    >>> c = dem_law_contact({"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0}, 3.45e-6,
    ...                     "hertz", "coeff_restitution", 0.5)
    >>> c.normal_model, c.adhesion_line_force, c.damping_model
    ('ring', 0.0, 'coeff_restitution')
    """
    if (normal_model, damping_model) not in DEM_LAWS:
        raise ValueError(f"unknown DEM law {normal_model}+{damping_model}; known: "
                         + ", ".join(f"{a}+{b}" for a, b in DEM_LAWS))
    # the material's elasticity and w_A only (its friction and zetas belong to the paper's law)
    mat = _material_record(material)
    return material_contact(mat, radius, work_of_adhesion=0.0 if normal_model == "hertz" else mat.work_of_adhesion,
                            normal_model="ring" if normal_model == "hertz" else normal_model,
                            damping_model=damping_model, damping_coefficient=coefficient)


def _material_record(material) -> SimpleNamespace:
    """density [kg/m^3], stiffness [Pa] and work_of_adhesion [J/m^2] of a MaterialPair, Contact or dict."""
    get = material.get if isinstance(material, dict) else lambda k: getattr(material, k)
    return SimpleNamespace(**{k: float(get(k)) for k in ("density", "stiffness", "work_of_adhesion")})


def dem_law_restitution(material, radius, normal_speed, normal_model: str, damping_model: str, coefficient: float,
                        *, rtol: float = DEFAULT_RTOL) -> np.ndarray:
    """e_n of normal impacts under a DEM law, each at its own radius and speed. [-]

    Parameters
    ----------
    material, normal_model, damping_model, coefficient
        As :func:`dem_law_contact`.
    radius, normal_speed : array_like
        Sphere radii [m] and incident normal speeds [m/s], broadcast together.
    rtol : float
        Solver tolerance. [-]

    Examples
    --------
    ``coeff_restitution`` gives its e at every speed (Hertz):

    >>> m = {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0}
    >>> dem_law_restitution(m, 2e-6, [0.1, 1.0, 10.0], "hertz", "coeff_restitution", 0.6).round(8).tolist()
    [0.6, 0.6, 0.6]
    """
    r, v = np.broadcast_arrays(np.asarray(radius, dtype=float), np.asarray(normal_speed, dtype=float))
    return _Model(_material_record(material), r.ravel(), v.ravel(), normal_model, damping_model, rtol).e_n(coefficient).reshape(r.shape)


class _Model:
    """e_n of every impact of the table for a trial coefficient (impacts grouped by radius)."""

    def __init__(self, material, radius, speed, normal_model, damping_model, rtol):
        self.material, self.normal_model, self.damping_model, self.rtol = material, normal_model, damping_model, rtol
        self.radii, self.index = np.unique(radius, return_inverse=True)
        self.speed = speed
        self.restitution = damping_model in RESTITUTION_DAMPING_MODELS

    def e_n(self, coefficient: float, work_of_adhesion: float | None = None) -> np.ndarray:
        """e_n of every impact [-] for the damping ``coefficient`` and, when given, a trial work of
        adhesion [J/m^2] in place of the material's."""
        material = self.material
        if work_of_adhesion is not None:
            material = {**vars(_material_record(material)), "work_of_adhesion": float(work_of_adhesion)}
        out = np.empty(self.speed.size)
        for i, r in enumerate(self.radii):
            rows = self.index == i
            c = dem_law_contact(material, float(r), self.normal_model, self.damping_model, coefficient)
            out[rows] = nm.solve_normal_many(c, self.speed[rows], rtol=self.rtol)["e_n"]
        return out

    def scale(self) -> float:
        """The critical damping eta_n0 of the law at the median impact (2 sqrt(m k) at the Hertz
        largest approach), the unit of the eta_n0 search. [1/s] or [1/(m s)]"""
        r, v = float(np.median(self.radii[self.index])), float(np.median(self.speed))
        c = dem_law_contact(self.material, r, self.normal_model, self.damping_model, 0.0 if not self.restitution else 1.0)
        return critical_damping_coefficient(c, v)


def _chisqr(model, coefficient, e_meas, sigma, work_of_adhesion=None) -> float:
    return float(np.sum(np.square((e_meas - model.e_n(coefficient, work_of_adhesion)) / sigma)))


def _restitution_interval(rise, x_best, lo_x):
    """(interval, status, best) of a restitution e: the ends where chi^2 rises by the threshold
    (``rise`` > 0), searched in [lo_x, 1]; the end at e = 1 is the side of no damping."""
    low_damping_end = 1.0 if rise(1.0) <= 0.0 or x_best >= 1.0 else optimize.brentq(rise, x_best, 1.0, xtol=1e-12)
    if rise(lo_x) <= 0.0:
        strong_end, bounded = lo_x, False
    else:
        strong_end, bounded = (optimize.brentq(rise, lo_x, x_best, xtol=1e-12) if x_best > lo_x else lo_x), True
    status = "not determined" if not bounded else "upper limit" if low_damping_end >= 1.0 else "determined"
    return (float(strong_end), float(low_damping_end)), status, float(min(x_best, 1.0))


def _damping_interval(rise, rise_coef, to_coef, x_best, lo_x, hi_x):
    """(interval, status, best) of eta_n0, searched in log10 coordinates x over [lo_x, hi_x] and
    below them in eta_n0 itself (``rise_coef``); x_best = -inf when no damping fits best."""
    if rise_coef(0.0) <= 0.0:  # no damping is inside the interval
        weak = 0.0
    elif rise(lo_x) > 0.0:
        weak = to_coef(optimize.brentq(rise, lo_x, x_best, xtol=1e-12))
    else:  # below 1e-4 critical dampings: in the coefficient itself
        weak = optimize.brentq(rise_coef, 0.0, to_coef(lo_x), xtol=1e-14 * to_coef(lo_x))
    start = x_best if math.isfinite(x_best) else lo_x
    if rise(hi_x) <= 0.0:
        strong, bounded = math.inf, False
    elif rise(start) > 0.0:  # no damping best, and the chi^2 has risen already at the lowest decade searched
        strong, bounded = optimize.brentq(rise_coef, 0.0, to_coef(lo_x), xtol=1e-14 * to_coef(lo_x)), True
    else:
        strong, bounded = to_coef(optimize.brentq(rise, start, hi_x, xtol=1e-12)), True
    status = "not determined" if not bounded else "upper limit" if weak == 0.0 else "determined"
    return (float(weak), float(strong)), status, (float(to_coef(x_best)) if math.isfinite(x_best) else 0.0)


def _interval_threshold(chi_min, n, sigma_known, k=1, level=INTERVAL_LEVEL):
    """The rise of chi^2 that bounds the profile-likelihood interval of one parameter at ``level``
    (95 %: Delta chi^2 = 3.84 with stated uncertainties), s^2 t^2 (n - k degrees of freedom) without."""
    if sigma_known:
        return chi2_threshold(level)
    if n > k:
        return chi_min / (n - k) * stats.t.ppf(0.5 + level / 2.0, n - k) ** 2
    return math.inf


def _minimum(f, lo, hi, grid, hints=()):
    """(t, f(t)) with the smallest f over t = -inf (no damping, no adhesion) and [lo, hi]: a grid
    and the ``hints`` (minimisers found nearby before), then bounded Brent about the best of them."""
    ts = np.linspace(lo, hi, grid)
    step = ts[1] - ts[0]
    candidates = [(float(t), f(float(t))) for t in ts]
    candidates += [(float(h), f(float(h))) for h in hints if math.isfinite(h) and lo <= h <= hi]
    t0, f0 = min(candidates, key=lambda c: c[1])
    res = optimize.minimize_scalar(f, bounds=(max(lo, t0 - step), min(hi, t0 + step)), method="bounded",
                                   options={"xatol": 1e-9})
    best = (float(res.x), float(res.fun)) if res.fun <= f0 else (t0, float(f0))
    none = f(-math.inf)
    return (-math.inf, float(none)) if none < best[1] else best


def _log10(value: float) -> float:
    return math.log10(value) if value > 0.0 else -math.inf


def _fit_with_adhesion(model, e_meas, sig, sigma_known, to_coef, from_coef, lo_x, hi_x):
    """The work of adhesion and the damping fitted jointly: (chi^2_min, (interval, status, best) of
    w_A, the same of the damping). Each interval is a profile-likelihood interval: the other
    parameter minimised at every trial value (Venzon & Moolgavkar 1988).

    Coordinates u = log10 w_A and x (the damping's, :func:`fit_dem_law`), -inf for none. Every
    minimisation over one coordinate starts from a grid and from the minimisers found before (the
    valley of chi^2 in w_A can be narrower than the grid); a chi^2 below the minimum met while the
    intervals are searched means the minimum was missed: the fit starts again from there (at most
    three times).
    """
    lo_u, hi_u = _ADHESION_DECADES
    seen = {}

    @lru_cache(maxsize=None)
    def chi(u, x):
        value = _chisqr(model, to_coef(x), e_meas, sig, 10.0**u)
        seen[(u, x)] = value
        return value

    hints = {"u": [], "x": []}
    best = {"u": (), "x": ()}  # the joint minimiser: a profile through it never lies above chi^2_min

    def profile_w(u):  # chi^2 at log10 w_A = u, the damping at its best
        x, value = _minimum(lambda x: chi(u, x), lo_x, hi_x, _PROFILE_GRID, [*hints["x"][-2:], *best["x"]])
        hints["x"].append(x)
        return value

    def profile_damping(x):
        u, value = _minimum(lambda u: chi(u, x), lo_u, hi_u, _PROFILE_GRID, [*hints["u"][-2:], *best["u"]])
        hints["u"].append(u)
        return value

    start = _joint_minimum(chi, lo_u, hi_u, lo_x, hi_x)
    for _ in range(3):
        (u_best, x_best), chi_min = _polish(chi, start, lo_u, hi_u, lo_x, hi_x)
        best.update(u=(u_best,), x=(x_best,))
        threshold = _interval_threshold(chi_min, e_meas.size, sigma_known, k=2)
        adhesion = _damping_interval(lambda u: profile_w(u) - chi_min - threshold,
                                     lambda w: profile_w(_log10(w)) - chi_min - threshold,
                                     lambda u: 10.0**u, u_best, lo_u, hi_u)
        damping = _damping_interval(lambda x: profile_damping(x) - chi_min - threshold,
                                    lambda c: profile_damping(from_coef(c)) - chi_min - threshold,
                                    to_coef, x_best, lo_x, hi_x)
        start, lowest = min(seen.items(), key=lambda item: item[1])
        if lowest >= chi_min - 1e-3 * threshold:  # a smaller miss moves no end of an interval visibly
            return chi_min, adhesion, damping
    raise RuntimeError("the joint fit of the work of adhesion and the damping did not find its minimum in three "
                       "starts (chi^2 has several valleys)")


def _joint_minimum(chi, lo_u, hi_u, lo_x, hi_x):
    """The best point of a grid over (u, x), -inf (none) included in each: the start of :func:`_polish`."""
    us = [-math.inf, *np.linspace(lo_u, hi_u, _PROFILE_GRID)]
    xs = [-math.inf, *np.linspace(lo_x, hi_x, _PROFILE_GRID)]
    return min(((float(u), float(x)) for u in us for x in xs), key=lambda p: chi(*p))


def _polish(chi, start, lo_u, hi_u, lo_x, hi_x):
    """The minimum of chi(u, x) near ``start``: Nelder-Mead in the plane (the valley of chi^2 is
    narrow and oblique: w_A and the damping both lower e_n), or along one coordinate when the other
    is -inf (no adhesion or no damping), then the best of that and the two edges at -inf."""
    u0, x0 = start
    candidates = []
    if math.isfinite(u0) and math.isfinite(x0):
        def clipped(p):
            return chi(float(np.clip(p[0], lo_u, hi_u)), float(np.clip(p[1], lo_x, hi_x)))

        res = optimize.minimize(clipped, [u0, x0], method="Nelder-Mead",
                                options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 4000, "adaptive": True,
                                         "initial_simplex": [[u0, x0], [u0 + 0.05, x0], [u0, x0 + 0.05]]})
        candidates.append(((float(np.clip(res.x[0], lo_u, hi_u)), float(np.clip(res.x[1], lo_x, hi_x))),
                           float(res.fun)))
    if math.isfinite(x0) or not math.isfinite(u0):
        u, value = _minimum(lambda u: chi(u, x0), lo_u, hi_u, _PROFILE_GRID, [u0])
        candidates.append(((u, x0), value))
    if math.isfinite(u0) or not math.isfinite(x0):
        x, value = _minimum(lambda x: chi(u0, x), lo_x, hi_x, _PROFILE_GRID, [x0])
        candidates.append(((u0, x), value))
    candidates.append((start, chi(*start)))
    return min(candidates, key=lambda c: c[1])


def information_criteria(chi_min: float, n: int, sigma_known: bool, k: int = 1) -> tuple[float, float]:
    """(AIC, BIC) of a least-squares fit with k parameters to n points. [-]

    chi^2 + 2 k and chi^2 + k ln n where the uncertainties are stated (the likelihood's own scale);
    n ln(chi^2 / n) + 2 k and + k ln n where the scatter estimates them.

    References
    ----------
    Burnham, K. P. and Anderson, D. R. (2002), Model Selection and Multimodel Inference, Springer,
    Sec. 2.2 and 6.4.

    Examples
    --------
    >>> information_criteria(8.0, 10, True)
    (10.0, 10.302585092994047)
    """
    base = chi_min if sigma_known else n * math.log(max(chi_min, 1e-300) / n)
    return base + 2 * k, base + k * math.log(n)


def _coordinate(model):
    """The fitted coordinate x of the damping: e itself over [1e-3, 1], or log10(eta_n0 / critical)
    over :data:`_DECADES` (eta_n0 = 0 is x = -inf): (to_coef, from_coef, lo_x, hi_x)."""
    if model.restitution:
        return (lambda x: x), (lambda c: c), 1e-3, 1.0
    unit = model.scale()
    lo_x, hi_x = _DECADES[model.damping_model]
    return (lambda x: unit * 10.0**x), (lambda c: _log10(c / unit)), lo_x, hi_x


def fit_dem_law(table, material, normal_model: str = "hertz", damping_model: str = "coeff_restitution", *,
                fit_adhesion: bool = False, weights="auto", rtol: float = DEFAULT_RTOL) -> DemLawFit:
    """Fit the damping coefficient of a DEM law to the impacts of ``table`` (module docstring).

    Parameters
    ----------
    table : pandas.DataFrame
        Impacts as :func:`microimpact.io.read_impacts` returns them: ``radius`` [m], ``normal_speed``
        [m/s], ``e_n`` [-], optionally ``e_n_uncertainty`` [-].
    material : MaterialPair, Contact or dict
        density [kg/m^3], stiffness [Pa], work_of_adhesion [J/m^2].
    normal_model, damping_model : str
        The law, one of :data:`DEM_LAWS`.
    fit_adhesion : bool
        Fit the work of adhesion jointly with the damping (``jkr_force`` and ``dmt`` only); the
        material's w_A is then not used. Each parameter gets its own profile-likelihood interval
        and status; the degrees of freedom are n - 2.
    weights : {"auto", "e_n", "none"} or array
        As :func:`microimpact.analysis.fitting.fit_damping`: the stated e_n uncertainties (auto: when
        given) or none (sigma estimated from the scatter).
    rtol : float
        Solver tolerance. [-]

    Returns
    -------
    DemLawFit

    References
    ----------
    Venzon, D. J. and Moolgavkar, S. H. (1988), Appl. Statist. 37:87-94, doi:10.2307/2347496.

    Examples
    --------
    Restitution measured at three speeds, Hertz with LAMMPS's ``coeff_restitution`` (whose e_n is e):

    >>> import pandas as pd
    >>> t = pd.DataFrame({"radius": [3.45e-6] * 3, "normal_speed": [0.5, 1.0, 2.0], "e_n": [0.70, 0.72, 0.71],
    ...                   "e_n_uncertainty": [0.01] * 3})
    >>> f = fit_dem_law(t, {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0})
    >>> f.status, round(f.value, 4), [round(x, 4) for x in f.interval]
    ('determined', 0.71, [0.6987, 0.7213])
    """
    if fit_adhesion and normal_model == "hertz":
        raise ValueError(f"fit_adhesion: {normal_model}+{damping_model} has no work of adhesion to fit; "
                         "choose jkr_force or dmt")
    df, rows, arrays, src = _table_arrays(table)
    sigma, _, _ = _sigma_e(weights, arrays, rows, src)
    ids = _row_ids(df, rows)
    sigma_known = sigma is not None
    e_meas = arrays["e_n"]
    n = e_meas.size
    sig = sigma if sigma_known else np.ones(n)
    mat = vars(_material_record(material))
    model = _Model(mat, arrays["radius"], arrays["normal_speed"], normal_model, damping_model, rtol)
    dem_law_contact(mat, float(arrays["radius"][0]), normal_model, damping_model, 1.0)  # the law exists

    to_coef, from_coef, lo_x, hi_x = _coordinate(model)
    if fit_adhesion:
        return _joint_fit(model, mat, e_meas, sig, sigma_known, to_coef, from_coef, lo_x, hi_x, src, ids)

    def chi(x):
        return _chisqr(model, to_coef(x), e_meas, sig)

    grid = np.linspace(lo_x, hi_x, _GRID)
    values = np.array([chi(x) for x in grid])
    i = int(np.argmin(values))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    res = optimize.minimize_scalar(chi, bounds=(a, b), method="bounded", options={"xatol": 1e-10 * max(1.0, abs(b - a))})
    x_best, chi_min = (float(res.x), float(res.fun)) if res.fun <= values[i] else (float(grid[i]), float(values[i]))
    no_damping = 1.0 if model.restitution else 0.0
    chi_none = _chisqr(model, no_damping, e_meas, sig)
    if chi_none < chi_min:
        x_best, chi_min = (1.0 if model.restitution else -math.inf), chi_none
    threshold = _interval_threshold(chi_min, n, sigma_known)

    def rise(x):
        return chi(x) - chi_min - threshold

    if model.restitution:
        interval, status, best = _restitution_interval(rise, x_best, lo_x)
    else:
        def rise_coef(c):
            return _chisqr(model, c, e_meas, sig) - chi_min - threshold

        interval, status, best = _damping_interval(rise, rise_coef, to_coef, x_best, lo_x, hi_x)
    if sigma_known and n > 1 and stats.chi2.sf(chi_min, n - 1) < ADEQUACY_P:
        status = "inadequate"
    aic, bic = information_criteria(chi_min, n, sigma_known)
    return DemLawFit(normal_model, damping_model, best if status == "determined" else math.nan, interval, status,
                     float(chi_min), int(n), sigma_known, float(aic), float(bic), best, mat, src,
                     ids=ids, _data=(model, e_meas, sig))


def _p_text(p: float) -> str:
    """``p = ...`` of a chi-square test, ``p < 1e-300`` where it underflows to 0.

    Examples
    --------
    >>> _p_text(0.0123), _p_text(0.0)
    ('p = 0.012', 'p < 1e-300')
    """
    return "p < 1e-300" if p == 0.0 else f"p = {p:.2g}"


def _row_ids(df, rows) -> tuple:
    """The CSV's id of each row (its row number where the table has no ``id``), as the fits name rows."""
    if "id" in df.columns:
        return tuple(str(i) if str(i) else f"row {r}" for i, r in zip(df["id"].astype(str), rows))
    return tuple(f"row {r}" for r in rows)


def _joint_fit(model, mat, e_meas, sig, sigma_known, to_coef, from_coef, lo_x, hi_x, src, ids) -> DemLawFit:
    """:func:`fit_dem_law` with the work of adhesion fitted too."""
    n = e_meas.size
    chi_min, (w_interval, w_status, w_best), (interval, status, best) = _fit_with_adhesion(
        model, e_meas, sig, sigma_known, to_coef, from_coef, lo_x, hi_x)
    if sigma_known and n > 2 and stats.chi2.sf(chi_min, n - 2) < ADEQUACY_P:
        status = w_status = "inadequate"
    aic, bic = information_criteria(chi_min, n, sigma_known, k=2)
    return DemLawFit(model.normal_model, model.damping_model, best if status == "determined" else math.nan, interval,
                     status, float(chi_min), int(n), sigma_known, float(aic), float(bic), best,
                     {**mat, "work_of_adhesion": w_best}, src, adhesion_fitted=True,
                     work_of_adhesion=w_best if w_status == "determined" else math.nan,
                     work_of_adhesion_interval=w_interval, adhesion_status=w_status, ids=ids,
                     _data=(model, e_meas, sig))


def candidate_laws(material, fit_adhesion: bool = False) -> list[tuple[str, str]]:
    """The DEM laws a material allows: the Hertz laws, and the adhesive ones when the material has
    a work of adhesion or it is fitted.

    Examples
    --------
    >>> len(candidate_laws({"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0}))
    4
    >>> len(candidate_laws({"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0}, fit_adhesion=True))
    8
    """
    adhesive = fit_adhesion or _material_record(material).work_of_adhesion > 0.0
    return [law for law in DEM_LAWS if adhesive or law[0] == "hertz"]


def rank_dem_laws(table, material, laws=None, *, fit_adhesion: bool = False, weights="auto",
                  rtol: float = DEFAULT_RTOL, progress=None):
    """Fit each DEM law to the same impacts and rank them by AIC.

    Parameters
    ----------
    table, material, weights, rtol
        As :func:`fit_dem_law`.
    laws : sequence of (normal_model, damping_model), optional
        Default :func:`candidate_laws`.
    fit_adhesion : bool
        Fit the work of adhesion of the adhesive laws too (:func:`fit_dem_law`); their AIC and BIC
        count two parameters.
    progress : callable, optional
        Called once after each law is fitted (a progress bar's ``advance``).

    Returns
    -------
    (pandas.DataFrame, dict)
        One row per law, best first: law, status, value, stderr (95 % interval width / 3.92),
        interval ends (95 %), chi^2, dof, chi^2/dof, p_value and verdict (of
        :class:`~microimpact.analysis.verdict.Verdict`), AIC, BIC, dAIC and the Akaike weight (with
        ``fit_adhesion`` also adhesion_status, work_of_adhesion and its interval ends, w_low and
        w_high); and ``{law: DemLawFit}``. A rejected law's value and interval are NaN here (its
        least-chi^2 values: :meth:`DemLawFit.closest_lines`).

    References
    ----------
    Burnham, K. P. and Anderson, D. R. (2002), Model Selection and Multimodel Inference, Springer.

    Examples
    --------
    >>> import pandas as pd
    >>> t = pd.DataFrame({"radius": [3.45e-6] * 4, "normal_speed": [0.2, 0.5, 1.0, 2.0],
    ...                   "e_n": [0.80, 0.80, 0.80, 0.80], "e_n_uncertainty": [0.01] * 4})
    >>> m = {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0}
    >>> ranked, fits = rank_dem_laws(t, m, [("hertz", "coeff_restitution"), ("hertz", "viscoelastic")])
    >>> list(ranked["law"])[0]
    'hertz+coeff_restitution'
    """
    laws = candidate_laws(material, fit_adhesion) if laws is None else list(laws)
    fits = {}
    for a, b in laws:
        fits[f"{a}+{b}"] = fit_dem_law(table, material, a, b, fit_adhesion=fit_adhesion and a != "hertz", weights=weights,
                                       rtol=rtol)
        if progress is not None:
            progress()
    rows = []
    for name, f in fits.items():
        v = f.verdict
        row = {"law": name, "status": f.status, "value": f.value, "stderr": f.stderr, "interval_low": f.interval[0],
               "interval_high": f.interval[1]}
        if fit_adhesion:
            row.update({"adhesion_status": f.adhesion_status or "not fitted", "work_of_adhesion": f.work_of_adhesion,
                        "w_low": f.work_of_adhesion_interval[0], "w_high": f.work_of_adhesion_interval[1]})
        rows.append({**row, "chisqr": f.chisqr, "dof": v.degrees_of_freedom,
                     "chisqr_per_dof": f.chisqr / v.degrees_of_freedom if v.degrees_of_freedom > 0 else math.nan,
                     "p_value": v.p_value, "verdict": v.verdict, "aic": f.aic, "bic": f.bic})
    df = pd.DataFrame(rows)
    interval_ends = [c for c in ("stderr", "interval_low", "interval_high", "w_low", "w_high") if c in df]
    df.loc[df["status"] == "inadequate", interval_ends] = math.nan  # no number to print
    # laws of one family (tsuji and coeff_restitution: the same e_n for every speed) tie to round-off:
    # the order of DEM_LAWS decides them
    return ranked_by_aic(df), fits


def ranked_by_aic(table):
    """The rows of ``table`` (one per candidate law, with an ``aic`` column) best first, with
    ``delta_aic`` and the Akaike weight exp(-dAIC / 2) normalised over the rows; ties to 1e-6 keep
    the rows' order.

    References
    ----------
    Burnham, K. P. and Anderson, D. R. (2002), Model Selection and Multimodel Inference, Springer,
    Sec. 2.9.

    Examples
    --------
    >>> import pandas as pd
    >>> r = ranked_by_aic(pd.DataFrame({"law": ["a", "b"], "aic": [12.0, 10.0]}))
    >>> list(r["law"]), [round(w, 4) for w in r["akaike_weight"]]
    (['b', 'a'], [0.7311, 0.2689])
    """
    df = table.copy()
    df["delta_aic"] = df["aic"] - df["aic"].min()
    w = np.exp(-0.5 * df["delta_aic"].to_numpy())
    df["akaike_weight"] = w / w.sum()
    return df.sort_values("aic", kind="stable", key=lambda a: a.round(6)).reset_index(drop=True)


def dem_fit_coverage(normal_model: str, damping_model: str, trials: int = 100, seed: int = 0, rtol: float = 1e-8,
                     fit_adhesion: bool = False):
    """Coverage of :func:`fit_dem_law`'s 95 % interval over random experiment designs.

    Each trial draws a design (4-30 impacts, normal speeds log-uniform over a random range within
    0.05-20 m/s, one or two radii within 1-10 um, noise sigma 0.003-0.05) and a true coefficient
    (e in 0.2-0.95, or eta_n0 giving e_n from about 0.3 to 0.97), simulates e_n with Gaussian noise
    of the stated sigma (a captured sphere is recorded as e_n = 0 exactly: nothing rebounds to be
    measured), and fits. With ``fit_adhesion`` the true work of adhesion is drawn
    log-uniform in 3e-3-0.3 J/m^2, the speeds within 0.02-20 m/s, and both parameters are fitted;
    many such designs cannot determine w_A (all impacts far above the sticking velocity, or all
    captured), and are meant to.

    Returns
    -------
    dict
        trials; determined and covered (the damping, among the trials that determine it); coverage
        (covered / determined); undetermined (status, truth, n, sigma of the others); and
        ``interval_covered``: over all trials that are not inadequate, how often each parameter's
        interval (one-sided ones included: every status states an interval) holds the truth,
        ``{"damping": k, "work_of_adhesion": k}`` of ``adequate`` trials, with
        ``adhesion_determined``.

    Examples
    --------
    >>> r = dem_fit_coverage("hertz", "coeff_restitution", trials=5, seed=1)
    >>> r["trials"], r["determined"] == 5
    (5, True)
    """
    rng = np.random.default_rng(seed)
    material = {"density": 1350.0, "stiffness": 1.776e9, "work_of_adhesion": 0.0 if normal_model == "hertz" else 0.01}
    determined = covered = adequate = adhesion_determined = 0
    interval_covered = {"damping": 0, "work_of_adhesion": 0}
    undetermined = []
    for _ in range(trials):
        n = int(rng.integers(4, 31))
        lo = 10 ** rng.uniform(math.log10(0.02 if fit_adhesion else 0.05), math.log10(5.0))
        hi = min(20.0, lo * 10 ** rng.uniform(0.1, 2.0))
        speed = 10 ** rng.uniform(math.log10(lo), math.log10(hi), n)
        radius = rng.choice(10 ** rng.uniform(-6.0, -5.0, 2), n)
        sigma = float(10 ** rng.uniform(math.log10(0.003), math.log10(0.05)))
        truth_w = float(10 ** rng.uniform(math.log10(3e-3), math.log10(0.3))) if fit_adhesion else material["work_of_adhesion"]
        probe = _Model({**material, "work_of_adhesion": truth_w}, radius, speed, normal_model, damping_model, rtol)
        if probe.restitution:
            truth = float(rng.uniform(0.2, 0.95))
        else:
            truth = probe.scale() * 10 ** rng.uniform(-2.5, -0.5)
        e_true = probe.e_n(truth)
        e = np.where(e_true > 0.0, e_true + rng.normal(0.0, sigma, n), 0.0)  # a capture is seen as one, no noise
        table = pd.DataFrame({"radius": radius, "normal_speed": speed, "e_n": e, "e_n_uncertainty": sigma})
        fit = fit_dem_law(table, material, normal_model, damping_model, fit_adhesion=fit_adhesion, weights="e_n",
                          rtol=rtol)
        if fit.status != "inadequate":
            adequate += 1
            interval_covered["damping"] += fit.interval[0] <= truth <= fit.interval[1]
            if fit_adhesion:
                lo_w, hi_w = fit.work_of_adhesion_interval
                interval_covered["work_of_adhesion"] += lo_w <= truth_w <= hi_w
                adhesion_determined += fit.adhesion_status == "determined"
        if fit.status != "determined":
            undetermined.append((fit.status, truth, n, sigma))
            continue
        determined += 1
        covered += fit.interval[0] <= truth <= fit.interval[1]
    return {"trials": trials, "determined": determined, "covered": covered,
            "coverage": covered / determined if determined else math.nan, "undetermined": undetermined,
            "adequate": adequate, "interval_covered": interval_covered, "adhesion_determined": adhesion_determined}
