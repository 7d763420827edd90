"""What the report reads: result files (or objects already in memory) and the provenance facts.

The report's input contract is a mapping of keys (:data:`INPUT_KEYS`) to result files; the
readers here accept a path or the in-memory object (Dataset, DataFrame, mapping) so that tests
and notebooks can pass results without writing them. Nothing here runs a model.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import subprocess
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr
from scipy.special import chdtrc, ndtri

from microimpact.io.files import read_netcdf_groups, restore_label_coordinates

__all__ = [
    "INPUT_KEYS",
    "ANALYST_KEYS",
    "check_inputs",
    "read_dataset",
    "read_table",
    "read_json",
    "read_portraits",
    "as_list",
    "parameter_source",
    "per_radius",
    "at_radius",
    "is_synthetic",
    "Verdict",
    "read_verdict",
    "VERDICT_LEVEL",
    "FLAG_LETTERS",
    "git_commit",
    "provenance",
]

#: The keys of ``build_report(inputs=...)``: key -> (required, what it is)
INPUT_KEYS = {
    # the analyst's material, parameters from the fit
    "data_table": (False, "validated impacts CSV (SI units)"),
    "fit": (True, "damping fit NetCDF (DampingFit.to_dataset)"),
    "fit_curves": (False, "model e_n(radius, speed) and outcome at the fit, NetCDF"),
    "flags": (False, "measurement-flags CSV"),
    "posterior": (False, "posterior NetCDF: chain, diagnostics and bands (microimpact.analysis.posterior)"),
    "oblique": (False, "friction fit NetCDF from the oblique columns (FrictionFit.to_dataset)"),
    "analyst_dynamics": (False, "critical and capture velocity per measured radius, NetCDF"),
    "analyst_sweeps": (False, "Table 2 sweeps at the measured radii (leading dimension radius), NetCDF files"),
    "model_comparison": (False, "normal models (ring, JKR, DMT) fitted to the data with AIC/BIC, NetCDF"),
    "design": (False, "what to measure next: the experiment design of the fit, JSON "
                      "(microimpact.analysis.design.design_record)"),
    # the paper's parameters (Table 1 row 2)
    "phase_portraits": (False, "grouped NetCDF of phase portraits"),
    "dynamics": (False, "dynamics summary NetCDF"),
    "bifurcation": (False, "(C1, C2) plane NetCDF"),
    "reproduction": (False, "reproduction table CSV"),
    "paper_sweeps": (False, "Table 2 sweeps with the paper's parameters, NetCDF files"),
    # checks
    "kharaz": (False, "Kharaz et al. (2001) comparison NetCDF"),
    "work_precision": (False, "work-precision benchmark NetCDF"),
    "stress": (False, "stress-sweep summary JSON"),
    "lammps_check": (False, "LAMMPS against microimpact on the paper's microsphere as LAMMPS input, CSV "
                            "(microimpact.studies.lammps_check)"),
}


#: the keys of the analyst's part (one set per material pair in ``build_report(pairs=...)``)
ANALYST_KEYS = ("fit", "fit_curves", "flags", "posterior", "oblique", "analyst_dynamics", "analyst_sweeps",
                "model_comparison", "design")


def check_inputs(inputs: Mapping, *, keys=None, required=None) -> dict:
    """``inputs`` as a dict without None values; raise on an unknown or a missing required key.

    ``keys`` limits the accepted keys (default: all of :data:`INPUT_KEYS`); ``required`` replaces
    the required ones (default: those of :data:`INPUT_KEYS`).

    Examples
    --------
    None values are dropped; a missing required key is an error.

    >>> check_inputs({"fit": "fit.nc", "flags": None})
    {'fit': 'fit.nc'}
    >>> check_inputs({"flags": "flags.csv"})
    Traceback (most recent call last):
    ...
    KeyError: "build_report: missing required input(s) ['fit'] ..."
    """
    accepted = INPUT_KEYS if keys is None else {k: INPUT_KEYS[k] for k in keys}
    unknown = sorted(set(inputs) - set(accepted))
    if unknown:
        raise KeyError(f"build_report: unknown input key(s) {unknown}; accepted: {', '.join(accepted)}")
    out = {k: v for k, v in inputs.items() if v is not None and not (isinstance(v, (list, tuple)) and not v)}
    if required is None:
        required = [k for k, (req, _) in accepted.items() if req]
    missing = [k for k in required if k not in out]
    if missing:
        raise KeyError(f"build_report: missing required input(s) {missing} "
                       f"({'; '.join(f'{k}: {INPUT_KEYS[k][1]}' for k in missing)})")
    return out


# =============================================================================== readers
def read_dataset(obj) -> xr.Dataset:
    """A NetCDF file read into memory (file closed), or the Dataset itself.

    Examples
    --------
    A Dataset passes through; a file is read into memory and closed:

    >>> import xarray as xr
    >>> ds = xr.Dataset({"e_n": ("speed", [0.4, 0.6])}, coords={"speed": [2.0, 4.0]})
    >>> read_dataset(ds) is ds
    True
    >>> ds.to_netcdf("e_n.nc")
    >>> read_dataset("e_n.nc")["e_n"].values.tolist()
    [0.4, 0.6]
    """
    if isinstance(obj, xr.Dataset):
        return obj

    with xr.open_dataset(obj, engine="netcdf4", decode_timedelta=False) as ds:
        return restore_label_coordinates(ds.load())


def read_table(obj) -> pd.DataFrame:
    """A CSV file (empty cells are NaN, "NA" stays text), or the DataFrame itself.

    Examples
    --------
    >>> with open("t.csv", "w") as f:
    ...     _ = f.write("a,b\\n1,NA\\n2,\\n")
    >>> t = read_table("t.csv")
    >>> t["b"].tolist()
    ['NA', nan]
    """
    return obj if isinstance(obj, pd.DataFrame) else pd.read_csv(obj, keep_default_na=False, na_values=[""])


def read_json(obj) -> dict:
    """A JSON file, or the mapping itself.

    Examples
    --------
    A round trip through a file gives the input back.

    >>> import json
    >>> with open("s.json", "w") as f:
    ...     json.dump({"cases": 3}, f)
    >>> read_json("s.json") == {"cases": 3}
    True
    """
    if isinstance(obj, Mapping):
        return dict(obj)
    with open(obj, encoding="utf-8") as f:
        return json.load(f)


def read_portraits(obj) -> list[xr.Dataset]:
    """Phase portraits: a grouped NetCDF file (one group per trajectory), or the list itself.

    The ``parameter_source`` attribute of the file's root group is copied to each trajectory
    that has none.

    Examples
    --------
    >>> from microimpact.dynamics.nonlinear import phase_portraits, save_phase_portraits
    >>> from microimpact.presets import WALL_1990
    >>> path = save_phase_portraits(phase_portraits(WALL_1990, [1.0, 2.0]), "portraits.nc")
    >>> len(read_portraits(path))
    2
    """
    if not isinstance(obj, (str, os.PathLike)):
        return list(obj)
    source = {k: v for k, v in read_dataset(obj).attrs.items() if k == "parameter_source"}
    portraits = read_netcdf_groups(obj)
    for p in portraits:  # the root group's parameter_source holds for every trajectory
        p.attrs = {**source, **p.attrs}
    return portraits


def as_list(obj) -> list:
    """One path or Dataset -> a list of one; a sequence -> a list; None -> [].

    Examples
    --------
    >>> as_list("a.nc"), as_list(("a.nc", "b.nc")), as_list(None)
    (['a.nc'], ['a.nc', 'b.nc'], [])
    """
    if obj is None:
        return []
    if isinstance(obj, (str, os.PathLike, xr.Dataset)):
        return [obj]
    return list(obj)


# =============================================================================== attributes
def parameter_source(*datasets) -> str:
    """The ``parameter_source`` attribute(s) of result Datasets, distinct values joined by "; ".

    Examples
    --------
    >>> import xarray as xr
    >>> a = xr.Dataset(attrs={"parameter_source": "fit"})
    >>> parameter_source(a, a, xr.Dataset(attrs={"parameter_source": "paper"}))
    'fit; paper'
    """
    found = [str(ds.attrs["parameter_source"]) for ds in datasets if "parameter_source" in ds.attrs]
    return "; ".join(dict.fromkeys(found)) or "not recorded in the result file (no parameter_source attribute)"


def per_radius(ds: xr.Dataset, name: str) -> np.ndarray:
    """Attribute ``name`` as one value per ``radius`` of ``ds`` (a scalar attribute is repeated).

    Examples
    --------
    >>> import xarray as xr
    >>> ds = xr.Dataset(coords={"radius": [1e-6, 2e-6, 3e-6]}, attrs={"contact_c1": 0.5})
    >>> per_radius(ds, "contact_c1").tolist()
    [0.5, 0.5, 0.5]
    """
    value = np.atleast_1d(np.asarray(ds.attrs.get(name, np.nan)))
    n = ds.sizes.get("radius", 1)
    return np.broadcast_to(value if value.size == n else value[:1], (n,))


def at_radius(ds: xr.Dataset, k: int) -> xr.Dataset:
    """The ``k``-th radius of a per-radius result, its per-radius ``contact_*`` attributes made scalars.

    Examples
    --------
    The second radius, with its own value of a per-radius contact attribute:

    >>> import xarray as xr
    >>> ds = xr.Dataset({"e_n": ("radius", [0.5, 0.6])}, coords={"radius": [1e-6, 2e-6]},
    ...                 attrs={"contact_zeta_hertz": [0.1, 0.2], "title": "fit"})
    >>> one = at_radius(ds, 1)
    >>> float(one["e_n"]), one.attrs
    (0.6, {'contact_zeta_hertz': 0.2, 'title': 'fit'})
    """
    n = ds.sizes["radius"]
    out = ds.isel(radius=k)
    attrs = dict(ds.attrs)
    for name, value in ds.attrs.items():
        arr = np.asarray(value)
        if name.startswith("contact_") and arr.ndim == 1 and arr.size == n:
            attrs[name] = arr[k].item()
    out.attrs = attrs
    return out


# =============================================================================== the verdict
#: significance of the report's own adequacy test (files that record no verdict): a chi-square
#: whose upper tail probability is below it rejects the model
VERDICT_LEVEL = 0.05
#: the flag letters of ``microimpact flags`` (microimpact.analysis.flags.FLAG_LETTERS; the report may
#: not import analysis, tests/test_report_verdict.py checks that the two agree)
FLAG_LETTERS = {"rotation_sensitive": "R", "angle_sensitive": "A", "near_capture": "N", "probably_spun": "S",
                "spin_unexplained": "U"}
_VERDICTS = ("adequate", "inadequate", "no stated uncertainties")


@dataclass(frozen=True)
class Verdict:
    """Whether the fitted model describes the data, as the report states it.

    Attributes
    ----------
    verdict : str
        "adequate", "inadequate", "no stated uncertainties" or "verdict not recorded".
    text : str
        One sentence for the reader.
    chi_square, degrees_of_freedom, p_value : float
        The chi-square of the fit, its degrees of freedom and upper tail probability [-] (NaN when unknown).
    outlier_ids : tuple of str
        The CSV ids of the rows whose standardized residual is improbable given the number of rows.
    outlier_threshold_text : str
        The threshold that named them and its false-alarm rate.
    misfit_description : str
        The systematic structure of the residuals, in words ("" if none was recorded).
    interval_note : str
        How the intervals are to be read ("" if none was recorded).
    without_outliers : str
        The verdict of the refit without the outliers ("" if there was none).
    widening : float
        sqrt(reduced chi-square) of a rejected fit, by which its intervals widen with the misfit
        counted as noise [-] (NaN where not recorded).
    recorded : bool
        True when the fit file holds the verdict; False when the report computed it from the file's chi-square.

    Examples
    --------
    >>> v = Verdict("inadequate", "rejected", 535.1, 58, 2.2e-78)
    >>> v.rejected, v.label
    (True, 'inadequate (chi-square 535.1 for 58 degrees of freedom, p = 2.2e-78)')
    """

    verdict: str
    text: str
    chi_square: float = math.nan
    degrees_of_freedom: float = math.nan
    p_value: float = math.nan
    outlier_ids: tuple = ()
    outlier_threshold_text: str = ""
    misfit_description: str = ""
    interval_note: str = ""
    recorded: bool = True
    without_outliers: str = ""
    widening: float = math.nan

    @property
    def rejected(self) -> bool:
        """True when the data reject the model."""
        return self.verdict == "inadequate"

    @property
    def label(self) -> str:
        """The verdict with its chi-square, degrees of freedom and p where they are known."""
        if not math.isfinite(self.chi_square):
            return self.verdict
        dof = f"{self.degrees_of_freedom:g}" if math.isfinite(self.degrees_of_freedom) else "?"
        # a p that underflowed to 0 is below the smallest printed, not zero
        p = ("" if not math.isfinite(self.p_value) else ", p < 1e-300" if self.p_value == 0 else f", p = {self.p_value:.2g}")
        return f"{self.verdict} (chi-square {self.chi_square:.4g} for {dof} degrees of freedom{p})"

    def rejected_note(self, what: str) -> str:
        """The line a downstream result carries when the model is rejected ("" otherwise)."""
        if not self.rejected:
            return ""
        return (f"FROM A REJECTED MODEL: {what} computed with the parameters of a fit the data reject "
                f"({self.label}); read them as conditional on a model that does not describe these data.")


def _attr_float(attrs, key) -> float:
    try:
        return float(attrs[key])
    except (KeyError, TypeError, ValueError):
        return math.nan


def _stated_uncertainties(fit: xr.Dataset) -> bool:
    """Whether the fit weighted its residuals by stated uncertainties (all finite and positive)."""
    if "unweighted" in str(fit.attrs.get("weighting", "")).lower():
        return False
    if "sigma" not in fit:
        return False
    s = np.asarray(fit["sigma"].values, float)
    return bool(s.size and np.all(np.isfinite(s) & (s > 0)))


def _outliers(fit: xr.Dataset) -> tuple[tuple, str]:
    """Ids of the rows whose |standardized residual| exceeds the two-sided Bonferroni threshold
    (a 5 % chance that a clean data set of N rows has one such row), and the threshold's text."""
    if "residual" not in fit:
        return (), ""
    z = np.asarray(fit["residual"].values, float)
    n = int(np.isfinite(z).sum())
    if not n:
        return (), ""
    threshold = float(ndtri(1.0 - VERDICT_LEVEL / (2 * n)))
    ids = (fit["id"].values if "id" in fit else (fit["row"].values if "row" in fit else np.arange(1, z.size + 1)))
    out = tuple(str(i) for i, x in zip(ids, z) if np.isfinite(x) and abs(x) > threshold)
    return out, (f"|standardized residual| > {threshold:.3g}: a clean data set of {n} rows has such a row with "
                 f"probability {VERDICT_LEVEL:g}")


def read_verdict(fit: xr.Dataset) -> Verdict:
    """The verdict of a fit file: its ``verdict`` attributes, or the report's own test where it has none.

    A file that records no verdict (written before the fit stated one) is judged here: with stated
    uncertainties, chi-square against its degrees of freedom (points minus varied parameters),
    rejected below :data:`VERDICT_LEVEL`; outliers by the Bonferroni threshold on the standardized
    residuals. Without stated uncertainties, or without a chi-square, the verdict is "verdict not recorded".

    Parameters
    ----------
    fit : xarray.Dataset
        A damping fit file (``DampingFit.to_dataset``).

    Returns
    -------
    Verdict

    Examples
    --------
    A file with the recorded verdict, and one without (chi-square 200 for 98 degrees of freedom, judged here):

    >>> import xarray as xr
    >>> recorded = xr.Dataset(attrs={"verdict": "adequate", "verdict_text": "the model describes the data",
    ...                              "chi_square": 95.0, "degrees_of_freedom": 98, "p_value": 0.57, "outlier_ids": ""})
    >>> read_verdict(recorded).label
    'adequate (chi-square 95 for 98 degrees of freedom, p = 0.57)'
    >>> old = xr.Dataset({"sigma": ("point", [0.01] * 100)}, attrs={"chisqr": 200.0, "n_points": 100,
    ...                                                            "varied": "zeta_hertz zeta_adhesion"})
    >>> v = read_verdict(old)
    >>> v.verdict, v.recorded, f"{v.p_value:.1e}"
    ('inadequate', False, '5.7e-09')
    """
    a = fit.attrs
    if str(a.get("verdict", "")) in _VERDICTS:
        ids = tuple(i.strip() for i in str(a.get("outlier_ids", "")).split(",") if i.strip())
        return Verdict(str(a["verdict"]), str(a.get("verdict_text", "")), _attr_float(a, "chi_square"),
                       _attr_float(a, "degrees_of_freedom"), _attr_float(a, "p_value"), ids,
                       str(a.get("outlier_threshold_text", "")), str(a.get("misfit_description", "")),
                       str(a.get("interval_note", "")), recorded=True,
                       without_outliers=str(a.get("without_outliers_text", "") or a.get("fit_without_outliers", "")),
                       widening=_attr_float(a, "interval_widening"))
    chi2 = _attr_float(a, "chi_square") if "chi_square" in a else _attr_float(a, "chisqr")
    n = _attr_float(a, "n_points")
    dof = _attr_float(a, "degrees_of_freedom") if "degrees_of_freedom" in a else n - len(str(a.get("varied", "")).split())
    if not (math.isfinite(chi2) and math.isfinite(dof) and dof > 0):
        return Verdict("verdict not recorded", "The fit file records no verdict and no chi-square to judge it by.",
                       recorded=False)
    if not _stated_uncertainties(fit):
        return Verdict("no stated uncertainties", "No stated uncertainties: the fit is judged against the scatter "
                       f"of the data (chi-square {chi2:.4g} for {dof:g} degrees of freedom is not a test).",
                       chi2, dof, recorded=False)
    p = float(chdtrc(dof, chi2))
    ids, threshold = _outliers(fit)
    verdict = "inadequate" if p < VERDICT_LEVEL else "adequate"
    text = ("The data reject the model: the misfit is larger than the stated uncertainties allow."
            if verdict == "inadequate" else "The model describes the data within their stated uncertainties.")
    return Verdict(verdict, text + " (Verdict computed by the report from the file's chi-square: the fit file "
                   f"records none; rejected below p = {VERDICT_LEVEL:g}.)", chi2, dof, p, ids, threshold,
                   recorded=False)


# =============================================================================== provenance
def is_synthetic(data_path, flag="auto") -> bool:
    """Whether a data file is synthetic: ``flag`` if it is a bool; for "auto", True when the file
    name contains "synthetic" (the bundled data/synthetic_microspheres.csv does).

    Examples
    --------
    >>> is_synthetic("data/synthetic_microspheres.csv"), is_synthetic("measured.csv")
    (True, False)
    >>> is_synthetic("measured.csv", flag=True)
    True
    """
    if isinstance(flag, bool):
        return flag
    if flag != "auto":
        raise ValueError(f"data_synthetic must be true, false or 'auto', got {flag!r}")
    return "synthetic" in Path(os.fspath(data_path)).name.lower()


def git_commit(directory=".") -> str | None:
    """``<commit>`` (``+ uncommitted changes`` when the tree is dirty) of the git checkout at
    ``directory``, or None when git or the repository is not available. Read-only.

    Examples
    --------
    A directory that is not a git checkout has no commit:

    >>> import tempfile
    >>> git_commit(tempfile.mkdtemp()) is None
    True
    """
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=directory, capture_output=True, text=True,
                              timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=directory,
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return head + (" + uncommitted changes" if dirty else "") if head else None


def _data_facts(t: pd.DataFrame) -> dict[str, str]:
    diameters = np.unique(np.round(t["radius"].to_numpy(float) * 2e6, 4))
    v = t["normal_speed"].to_numpy(float)
    labels = sorted({str(p) for p in t["material_pair"].dropna().unique()}) if "material_pair" in t.columns else []
    return {"data content": f"{len(t)} impacts, {len(diameters)} sphere diameters d = {', '.join(f'{d:g}' for d in diameters)} um, "
                            f"normal speed {np.nanmin(v):.3g}-{np.nanmax(v):.3g} m/s"
                            + (f"; material pairs {', '.join(labels)}" if len(labels) > 1 else "")}


def _config_facts(config: Mapping) -> dict[str, str]:
    out = {"materials": f"{config.get('materials')} (material_pair {config.get('material_pair')}: the pair of "
                        "rows without a material_pair cell)"}
    sim = config.get("simulation", {})
    if sim:
        out["paper-part contact"] = ", ".join(f"{k} = {v}" for k, v in sim.items() if not isinstance(v, Mapping))
    out["fit options"] = ", ".join(f"{k} = {v}" for k, v in config.get("fit", {}).items()) or "defaults"
    sweeps = config.get("sweeps", {})
    out["sweeps"] = (f"Table 2 cases {', '.join(map(str, sweeps))}; {config.get('sweep_chunks', 1)} chunk(s) per case"
                     if sweeps else "none")
    bench = config.get("benchmark", {})
    out["benchmark"] = ("on" + (" (quick)" if bench.get("quick", True) else " (full)")) if bench.get("enabled") else "off"
    stress = config.get("stress")
    if stress is not None:
        out["stress sweep"] = (f"on ({stress.get('cases', '?')} cases, seed {stress.get('seed', '?')}"
                               + (f", reference solver on every {stress['reference_every']}-th case"
                                  if stress.get("reference_every") else "") + ")"
                               if stress.get("enabled") else "off")
    return out


def provenance(config: Mapping | None = None, *, version: str = "", data_path=None,
               data_table: pd.DataFrame | None = None) -> dict[str, str]:
    """The facts of the title page, as label -> text.

    Parameters
    ----------
    config : mapping, optional
        The pipeline configuration (data file, materials, switches).
    version : str
        Version of the toolkit.
    data_path : str, optional
        The analyst's data file; default ``config["data"]``.
    data_table : pandas.DataFrame, optional
        The validated impact table, summarised in one line.

    Examples
    --------
    The title page of a run on the bundled synthetic data (flagged as such), two impacts summarised:

    >>> import pandas as pd
    >>> table = pd.DataFrame({"radius": [1e-6, 2e-6], "normal_speed": [1.0, 3.0]})
    >>> facts = provenance({"data": "data/synthetic_microspheres.csv"}, version="0.1.0", data_table=table)
    >>> facts["toolkit"], facts["data content"]
    ('microimpact 0.1.0', '2 impacts, 2 sphere diameters d = 2, 4 um, normal speed 1-3 m/s')
    >>> "SYNTHETIC" in facts["data"]
    True
    """
    config = dict(config or {})
    data_path = data_path or config.get("data")
    synthetic = is_synthetic(data_path or "", config.get("data_synthetic", "auto")) if data_path else False
    out = {
        "toolkit": f"microimpact {version}",
        "created": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "git commit": git_commit() or "not available (not a git checkout)",
        "python": f"{platform.python_version()} on {platform.system()} {platform.machine()}",
        "data": f"{data_path}" + ("  -- SYNTHETIC data (generated, not measured)" if synthetic else "  -- measured data"),
    }
    if data_table is not None and len(data_table):
        out.update(_data_facts(data_table))
    if config:
        out.update(_config_facts(config))
    return out
