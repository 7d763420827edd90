"""The analyst's material: the fitted parameters drive the simulations and the sweeps.

A damping fit (:mod:`microimpact.analysis.fitting`) gives zeta_H, zeta_A and one work of adhesion
w_A for a material pair; each measured sphere size then has its own contact (f0 from w_A by
Eq. (7), :meth:`Contact.at_radius`). This module turns a fit into the 3-D simulations of that
material: the Table 2 sweeps at every measured size over the measured speed range, and the
numbers of the nonlinear analysis (critical and capture velocity) per size.

Every result records where its parameters came from (``parameter_source``) and the contact
itself (``contact_*``, one value per size along ``radius`` for the analyst's results); see
:mod:`microimpact.io.provenance`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import xarray as xr

from microimpact.analysis.fit_result import DampingFit
from microimpact.dynamics.nonlinear import capture_velocity, critical_velocity
from microimpact.io.files import CONVENTIONS
from microimpact.io.provenance import source_of_fit, stamp_parameters
from microimpact.io.variables import attributes
from microimpact.model.contact import Contact
from microimpact.solvers import DEFAULT_RTOL, Deadline
from microimpact.studies.sweeps import resolve_spec, run_sweep

__all__ = [
    "fitted_contacts",
    "measured_speed_range",
    "stamp_fitted",
    "material_sweep",
    "material_dynamics",
]


def fitted_contacts(fit: xr.Dataset, radii: Sequence[float] | None = None) -> dict[float, Contact]:
    """The fitted contact of every measured sphere size (or of the given radii). [m] -> Contact

    Examples
    --------
    The fitted contact of the one measured size (six synthetic impacts of 3.45 um spheres):

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> path = write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    >>> fit = fit_damping(read_impacts(path), material, confidence_intervals=False).to_dataset()
    >>> contacts = fitted_contacts(fit)
    >>> list(contacts), round(contacts[3.45e-6].zeta_hertz, 4), round(contacts[3.45e-6].zeta_adhesion, 3)
    ([3.45e-06], 0.5964, 28.39)
    """
    model = DampingFit.from_dataset(fit)
    sizes = np.unique(fit["radius"].values) if radii is None else np.asarray(radii, dtype=float)
    return {float(r): model.contact(float(r)) for r in sizes}


def stamp_fitted(ds: xr.Dataset, fit: xr.Dataset) -> xr.Dataset:
    """``ds`` with the fit's ``parameter_source``, the fitted contact of every measured size, and what
    the data did not determine: ``undetermined_parameters`` (each with the fit's statement) and
    ``friction_source`` (which friction the simulations use, and why, where the fit had oblique data).

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> path = write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    >>> fit = fit_damping(read_impacts(path), material, confidence_intervals=False).to_dataset()
    >>> from microimpact.studies.sweeps import run_sweep
    >>> sweep = stamp_fitted(run_sweep(fitted_contacts(fit)[3.45e-6], {"speed": [2.0]}), fit)
    >>> sweep.attrs["parameter_source"].split()[:2], sweep.attrs["undetermined_parameters"]
    (['fit:', 'six.csv'], 'none')
    """
    out = stamp_parameters(ds, list(fitted_contacts(fit).values()), source_of_fit(fit))
    notes = [f"{n}: {fit[f'{n}_status'].attrs.get('reason', '')}" for n in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion")
             if f"{n}_status" in fit and int(fit[f"{n}_status"]) != 0]
    out.attrs["undetermined_parameters"] = "; ".join(notes) if notes else "none"
    if "fit_friction_source" in fit.attrs:
        out.attrs["friction_source"] = str(fit.attrs["fit_friction_source"])
    return out


def measured_speed_range(fit: xr.Dataset) -> tuple[float, float]:
    """Smallest and largest measured normal impact speed of the fitted points. [m/s]

    Examples
    --------
    >>> import xarray as xr
    >>> fit = xr.Dataset({"normal_speed": ("point", [2.0, 0.7, 5.5])})
    >>> measured_speed_range(fit)
    (0.7, 5.5)
    """
    v = np.asarray(fit["normal_speed"].values, dtype=float)
    return float(v.min()), float(v.max())


def _on_measured_speeds(spec: Mapping, speed_range: tuple[float, float]) -> dict:
    """``spec`` with its speed axis moved onto the measured range (same number of points)."""
    n = np.size(resolve_spec({"speed": spec["speed"]})["speed"])
    out = dict(spec)
    out["speed"] = {"start": speed_range[0], "stop": speed_range[1], "num": max(int(n), 2)}
    return out


def material_sweep(fit: xr.Dataset, spec: Mapping, *, case: str | None = None,
                   rtol: float = DEFAULT_RTOL, time_budget: float | None = None) -> xr.Dataset:
    """A sweep of the analyst's material: every measured size, the measured speed range.

    Parameters
    ----------
    fit : xarray.Dataset
        The damping fit (:meth:`DampingFit.to_dataset`, or the fit NetCDF read back).
    spec : mapping
        A sweep spec (:mod:`microimpact.studies.sweeps`), e.g. a Table 2 case; its speed axis is
        replaced by as many speeds spanning the measured normal speeds.
    case : str, optional
        Label recorded in the attributes.
    rtol : float
        Relative tolerance of the normal solves. [-]
    time_budget : float or Deadline, optional
        Wall-clock budget of all sizes together (:func:`~microimpact.studies.sweeps.run_sweep`);
        None: no limit. [s]

    Returns
    -------
    xarray.Dataset
        The sweep with a leading ``radius`` dimension [m] (one fitted contact per size), the
        capture speed per size, ``parameter_source`` = ``"fit: <file> <sha256>"`` and
        ``contact_*`` attributes as arrays along ``radius``.

    Examples
    --------
    Case 2.1's speed axis moved onto the measured speeds (1.56-99.6 m/s), three points:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> path = write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    >>> fit = fit_damping(read_impacts(path), material, confidence_intervals=False).to_dataset()
    >>> from microimpact.studies.sweeps import case_spec
    >>> spec = case_spec("2.1", {"speed": {"start": 1, "stop": 2, "num": 3}, "incidence_deg": [0.0]})
    >>> ds = material_sweep(fit, spec, case="2.1")
    >>> dict(ds.sizes), ds["speed"].values.round(2).tolist()
    ({'radius': 1, 'speed': 3, 'incidence_deg': 1}, [1.56, 50.6, 99.65])
    """
    contacts = fitted_contacts(fit)
    grid = _on_measured_speeds(spec, measured_speed_range(fit))
    deadline = Deadline.start(time_budget, "material sweep")
    parts = [run_sweep(c, grid, case=case, rtol=rtol, time_budget=deadline) for c in contacts.values()]
    capture = [float(p["capture_normal_speed"]) for p in parts]
    parts = [p.drop_vars("capture_normal_speed") for p in parts]
    per_size = [name for name, var in parts[0].data_vars.items() if var.ndim > 0]  # fixed inputs stay 0-d
    ds = xr.concat(parts, dim=xr.DataArray(list(contacts), dims="radius", name="radius"), data_vars=per_size,
                   coords="minimal", compat="override", join="exact", combine_attrs="override")
    ds["radius"].attrs = attributes("radius")
    ds["capture_normal_speed"] = ("radius", capture, attributes("capture_normal_speed"))
    ds.attrs["title"] = ds.attrs["title"].replace("sweep:", "sweep of the fitted material:", 1)
    return stamp_fitted(ds, fit)


def material_dynamics(fit: xr.Dataset, *, rtol: float = DEFAULT_RTOL, time_budget: float | None = None) -> xr.Dataset:
    """Critical velocity (Eq. (38)) and capture velocity of the fitted material at every measured size.

    ``time_budget`` [s] (or a Deadline; None: no limit) is checked after each size's capture
    velocity (a bisection of engine solves, about a second).

    Returns
    -------
    xarray.Dataset
        ``critical_velocity`` and ``capture_velocity`` [m/s] along ``radius`` [m], with
        ``parameter_source`` and ``contact_*`` attributes (arrays along ``radius``). A size
        without adhesion (f0 = 0) has capture velocity 0 and critical velocity NaN.

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> path = write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3)
    >>> fit = fit_damping(read_impacts(path), material, confidence_intervals=False).to_dataset()
    >>> dyn = material_dynamics(fit)
    >>> round(float(dyn["capture_velocity"][0]), 3), float(dyn["critical_velocity"][0]) < 1e-4
    (1.432, True)
    """
    contacts = fitted_contacts(fit)
    radii = np.array(list(contacts))
    deadline = Deadline.start(time_budget, "material dynamics")
    capture = []
    for c in contacts.values():
        capture.append(capture_velocity(c, solver_rtol=rtol))
        deadline.check(f"{len(capture)} of {radii.size} sizes")
    ds = xr.Dataset(
        {
            # Eq. (38) needs the adhesive equilibrium: without adhesion (f0 = 0) there is none and
            # no capture (capture_velocity is 0 there), so v_c is missing, with the reason
            "critical_velocity": ("radius", [critical_velocity(c) if c.adhesion_line_force > 0 else np.nan
                                             for c in contacts.values()],
                                  {"units": "m s-1", "long_name": "critical velocity v_c, Eq. (38)",
                                   "comment": "NaN where the contact has no adhesion (f0 = 0): no adhesive "
                                              "equilibrium, every impact rebounds"}),
            "capture_velocity": ("radius", capture, attributes("capture_normal_speed")),
        },
        coords={"radius": ("radius", radii, attributes("radius"))},
        attrs={"Conventions": CONVENTIONS,
               "title": "Critical and capture velocity of the fitted material at the measured sizes"},
    )
    return stamp_fitted(ds, fit)
