"""Friction (and, later, tangential compliance) from the analyst's oblique columns.

The measured-impact CSV may carry, per oblique impact, one tangential rebound quantity --
``tangential_restitution`` e_t = v_t,out / v_t,in, ``rebound_angle`` or ``rebound_tangential_speed`` --
and/or ``rebound_spin`` |omega_out| (data/README.md), each with its standard uncertainty.
:func:`fit_friction` fits the Coulomb coefficient f of Eqs. (16)-(20) to them, with the normal
damping of a finished :class:`~microimpact.analysis.fit_result.DampingFit`.
The friction of LAMMPS's DEM tangential laws, fitted with the same profile, is in
:mod:`microimpact.analysis.dem_friction`.

After the normal fit, not jointly -- and why
--------------------------------------------
The normal motion does not depend on friction (the decoupling of model-notes section 4): e_n carries
no information on f. The tangential outcome depends on the normal damping only through the
friction impulse J = int |F_n| dt, which the e_n data already fix far better than a few tangential
rows could. So the friction fit runs second, with zeta_H, zeta_A (and w_A) at their fitted values,
and loses next to nothing against a joint fit, while a bad tangential row cannot pull the damping.
What the sequential fit would lose -- the uncertainty of the damping -- is put back twice:

* the standard error of f adds the damping covariance by the delta method,
  var(f) = var(f | zeta) + g^T Cov(zeta) g with g = d f_hat / d zeta from two refits per parameter;
* the posterior (:mod:`microimpact.analysis.posterior`) samples (zeta_H, zeta_A, f) jointly under
  both likelihoods, so its bands carry the correlation.

Measured quantity and errors in variables
-----------------------------------------
Each row is fitted in the quantity that was MEASURED (``df.attrs["measured"]``; a derived column
would inherit correlated errors). Its variance is the stated one plus the effective variance of the
incident speed and angle errors (Orear 1982, doi:10.1119/1.12972):
sigma^2 = sigma_q^2 + (dq/dv)^2 sigma_v^2 + (dq/dalpha)^2 sigma_alpha^2, slopes by central differences
of the model at the current f. Rows with a stated ``spin`` (top-spin +) start with that spin.

Hook for tangential compliance
------------------------------
:data:`TANGENTIAL_PARAMETERS` maps ``Contact.tangential_model`` to the Contact fields fitted from
the oblique data. The paper's rigid model has ``("friction",)``; a compliant model adds its
stiffness field there and the fit varies it too (start values and bounds in
:data:`PARAMETER_BOUNDS`) -- the model is always built with ``Contact.with_(**parameters)`` and solved
by :func:`microimpact.solvers.engine.solve_normal_many` plus the closed-form tangential map
(:func:`rebound_state`, the two halves of :func:`microimpact.simulate_many`).
"""

from __future__ import annotations

import json
import math
import time
import warnings
from dataclasses import dataclass, field

import lmfit
import numpy as np
import pandas as pd
import xarray as xr
from scipy import stats
from scipy.optimize import brentq, minimize_scalar

from microimpact.analysis.fit_result import FitResult
from microimpact.analysis.verdict import assess_residuals
from microimpact.io.formatting import ReportHTML
from microimpact.io.files import CONVENTIONS, restore_label_coordinates
from microimpact.io.impacts import OBLIQUE_COLUMNS, insert_row_labels, label_variables, labels_from_dataset, row_labels
from microimpact.io.statuses import status_from_variables
from microimpact.analysis.fit_result import PARAMETER_NAMES
from microimpact.analysis.identifiability import (DEFAULT_LEVEL, chi2_threshold, profile_interval,
                                                  status_from_interval, status_variables)
from microimpact.io.formatting import estimates_repr
from microimpact.io.impacts import ImpactDataWarning
from microimpact._runtime.progress import progress_bar
from microimpact.io.materials import material_contact
from microimpact.io.statuses import stderr_is_meaningful
from microimpact.model.dem_tangential import DEM_TANGENTIAL_MODELS
from microimpact.model.tangential import tangential_outcome
from microimpact.solvers import DEFAULT_RTOL, Deadline, engine, engine_threads

__all__ = ["FrictionFit", "ObliqueProblem", "fit_friction", "oblique_model", "rebound_state", "effective_sigma", "TANGENTIAL_PARAMETERS",
           "PARAMETER_BOUNDS", "OBSERVABLE_UNITS"]

#: Contact.tangential_model -> the Contact fields fitted from oblique data (the compliance hook)
TANGENTIAL_PARAMETERS: dict[str, tuple[str, ...]] = {"rigid": ("friction",)}
#: fitted tangential parameter -> (start grid, lower bound, upper bound)
PARAMETER_BOUNDS: dict[str, tuple] = {"friction": (np.geomspace(0.01, 2.0, 12), 0.0, 10.0)}
#: the fitted observables and their units
OBSERVABLE_UNITS = {"tangential_restitution": "1", "rebound_tangential_speed": "m s-1", "rebound_angle_deg": "degree",
                    "rebound_spin": "rad s-1"}
#: log-spaced points of the friction profile over PARAMETER_BOUNDS["friction"] (every entry's rolling
#: threshold is added to them): 400 resolve chi-square's curvature at f ~ 0.01-1 to < 2 % of f
PROFILE_POINTS = 400
_H_SPEED = 1e-4  # relative step of the speed slope [-]
_H_ANGLE = 0.05  # step of the angle slope [deg]

def _warn_unused(src: str, quantity: str, rows, unused, inc, e_n) -> None:
    """One ImpactDataWarning naming the rows whose measured oblique value the friction fit cannot
    use, and why: at normal incidence there is no tangential motion for friction to act on, and a
    captured impact has no rebound."""
    if not np.any(unused):
        return
    with np.errstate(invalid="ignore"):
        reasons = [(unused & (inc == 0), "at 0 deg incidence (no tangential motion for friction to act on)"),
                   (unused & ~(inc == 0) & ~(e_n > 0), "captured or without e_n (no rebound to compare)"),
                   (unused & (inc != 0) & (e_n > 0), "without incidence angle or speed")]
    listed = "; ".join(f"rows {', '.join(map(str, rows[m][:20]))}{' and more' if m.sum() > 20 else ''} {why}"
                       for m, why in reasons if m.any())
    warnings.warn(f"{src}: {int(np.sum(unused))} measured {quantity} value(s) not used by the friction fit: {listed}",
                  ImpactDataWarning, stacklevel=4)


#: the columns of a friction fit's data that the fit computes (the others are the analyst's row labels)
_ENTRY_COLUMNS = ("row", "quantity", "radius", "speed", "incidence_deg", "measured", "sigma", "model", "residual")


@dataclass(frozen=True)
class ObliqueProblem:
    """The oblique rows of an impact table, one entry per (row, measured quantity).

    Attributes
    ----------
    rows : numpy.ndarray
        CSV data row of each entry.
    quantity : numpy.ndarray of str
        The measured quantity of each entry (a key of :data:`OBSERVABLE_UNITS`).
    radius, speed, incidence_deg, spin : numpy.ndarray
        [m], [m/s], [deg], stated incident top-spin [rad/s] (0 where not stated).
    measured, sigma_measured : numpy.ndarray
        The value and its stated standard uncertainty (NaN: not stated), in the quantity's unit.
    sigma_speed, sigma_angle : numpy.ndarray
        Incident speed [m/s] and angle [deg] uncertainties (0 where not stated).
    source : str
    labels : pandas.DataFrame or None
        The analyst's labels of each entry (``id`` and the CSV's own columns,
        :func:`microimpact.io.row_labels`).

    Examples
    --------
    Eight synthetic oblique impacts, each with a measured tangential restitution:

    >>> from microimpact.analysis.synthetic import make_synthetic_oblique
    >>> from microimpact.io import read_impacts, write_csv
    >>> data = make_synthetic_oblique(radii=(3.45e-6,), speeds=(15.0, 30.0), incidence_deg=(35.0, 50.0, 60.0, 70.0))
    >>> table = read_impacts(write_csv(data, "oblique.csv"))
    >>> problem = ObliqueProblem.from_table(table)
    >>> problem.measured.size, set(problem.quantity)
    (8, {'tangential_restitution'})
    """

    rows: np.ndarray
    quantity: np.ndarray
    radius: np.ndarray
    speed: np.ndarray
    incidence_deg: np.ndarray
    spin: np.ndarray
    measured: np.ndarray
    sigma_measured: np.ndarray
    sigma_speed: np.ndarray
    sigma_angle: np.ndarray
    source: str = "impact table"
    labels: pd.DataFrame | None = None

    @classmethod
    def from_table(cls, table: pd.DataFrame, *, warn: bool = False) -> "ObliqueProblem":
        """The oblique entries of a table from :func:`microimpact.io.read_impacts`; with ``warn``, an
        ImpactDataWarning names the measured oblique values that cannot be used, and why (the
        friction fit warns; the other readers of the same table do not repeat it).

        Raises
        ------
        ValueError
            If the table has no oblique column with a value at a nonzero incidence angle (names
            the file and the columns looked for).
        """
        src = str(table.attrs.get("source", "impact table"))
        measured = table.attrs.get("measured")
        if measured is None:  # a table built in memory: the first oblique column with values (the
            # canonical table derives the others from it; fitting them too would count a row twice)
            measured = tuple(c for c in OBLIQUE_COLUMNS if c in table.columns
                             and np.isfinite(table[c].to_numpy(dtype=float)).any())[:1]
        names = [c for c in OBLIQUE_COLUMNS if c in measured and c in table.columns]
        n = len(table)

        def col(name, default=np.nan):
            return table[name].to_numpy(dtype=float) if name in table.columns else np.full(n, default)

        rows = table["row"].to_numpy(dtype=np.int64) if "row" in table.columns else np.arange(1, n + 1)
        inc = col("incidence_deg")
        speed = col("speed")
        parts = []
        for q in names:
            x = col(q)
            use = np.isfinite(x) & np.isfinite(inc) & (inc > 0) & np.isfinite(speed) & (col("e_n") > 0)
            idx = np.flatnonzero(use)
            parts.append((q, idx, x[idx], col(f"{q}_uncertainty")[idx]))
            if warn:
                _warn_unused(src, q, rows, np.isfinite(x) & ~use, inc, col("e_n"))
        if not any(p[1].size for p in parts):
            raise ValueError(f"{src}: no oblique measurement to fit friction from: give one of the columns "
                             "tangential_restitution, rebound_angle, rebound_tangential_speed or rebound_spin at a "
                             "nonzero incidence_angle with a rebound (data/README.md)")
        idx = np.concatenate([p[1] for p in parts])
        zero = np.nan_to_num
        return cls(rows=rows[idx], quantity=np.concatenate([np.full(p[1].size, p[0], dtype=object) for p in parts]),
                   radius=col("radius")[idx], speed=speed[idx], incidence_deg=inc[idx], spin=zero(col("spin")[idx]),
                   measured=np.concatenate([p[2] for p in parts]), sigma_measured=np.concatenate([p[3] for p in parts]),
                   sigma_speed=zero(col("speed_uncertainty")[idx]), sigma_angle=zero(col("incidence_deg_uncertainty")[idx]),
                   source=src, labels=row_labels(table).iloc[idx].reset_index(drop=True))

    @property
    def size(self) -> int:
        """Number of entries."""
        return int(self.rows.size)


def _observables(out: dict, speed, incidence_deg, quantity) -> np.ndarray:
    """The model value of each entry's quantity from the rebound velocity and spin ``out``."""
    vt_in = speed * np.sin(np.radians(incidence_deg))
    vt, vn = out["velocity_out_t"], out["velocity_out_n"]
    with np.errstate(divide="ignore", invalid="ignore"):  # e_t is undefined at normal incidence
        e_t = np.where(vt_in > 0, vt / np.where(vt_in > 0, vt_in, 1.0), np.nan)
    values = {
        "tangential_restitution": e_t,
        "rebound_tangential_speed": vt,
        "rebound_angle_deg": np.degrees(np.arctan2(vt, vn)),
        "rebound_spin": np.sqrt(out["omega_out_n"] ** 2 + out["omega_out_t"] ** 2 + out["omega_out_tp"] ** 2),
    }
    res = np.full(speed.shape, np.nan)
    for q, v in values.items():
        m = quantity == q
        res[m] = v[m]
    return res


def normal_impulses(contact, speed, incidence_deg, rtol: float = DEFAULT_RTOL) -> dict:
    """The friction-independent half of :func:`rebound_state`: the normal solve of each impact.

    The normal motion does not depend on friction (model-notes section 4), so a friction fit
    solves it once per impact and evaluates the closed-form tangential map for every trial f.

    Parameters
    ----------
    contact : Contact
    speed, incidence_deg : numpy.ndarray
        Incident speed [m/s] and angle from the normal [deg].
    rtol : float
        Relative tolerance of the normal solves. [-]

    Returns
    -------
    dict of arrays: ``captured`` (bool), ``e_n`` [-], ``velocity_in_n``, ``velocity_in_t`` [m/s],
    ``friction_impulse`` [N s], ``twist_impulse`` [N m s].
    """
    a = np.radians(incidence_deg)
    vn, vt = speed * np.cos(a), speed * np.sin(a)
    speeds, inverse = np.unique(vn, return_inverse=True)  # one solve per distinct normal speed
    sol = {k: v[inverse] for k, v in engine.solve_normal_many(contact, speeds, rtol=rtol).items()}
    return {"captured": sol["captured"], "e_n": sol["e_n"], "velocity_in_n": vn, "velocity_in_t": vt,
            "friction_impulse": sol["friction_impulse"], "twist_impulse": sol["twist_impulse"]}


def rebound_from_impulses(contact, impulses: dict, spin, friction=None) -> dict:
    """The closed-form half of :func:`rebound_state`, Eqs. (16)-(20), for the normal solve ``impulses``.

    Parameters
    ----------
    contact : Contact
    impulses : dict
        From :func:`normal_impulses`.
    spin : numpy.ndarray
        Incident top-spin (omega_t' = -spin). [rad/s]
    friction : float or numpy.ndarray, optional
        Coulomb coefficient(s) replacing the contact's. [-]

    Returns
    -------
    dict of arrays, as :func:`rebound_state`.
    """
    vn, vt = impulses["velocity_in_n"], impulses["velocity_in_t"]
    zero = np.zeros_like(vn)
    f = contact.friction if friction is None else friction
    tan = tangential_outcome(contact.mass, contact.moment_of_inertia, contact.radius, f, (-vn, vt, zero),
                             (zero, zero, -spin), impulses["friction_impulse"], impulses["twist_impulse"])
    captured = impulses["captured"]
    return {"captured": captured, "velocity_out_n": np.where(captured, 0.0, impulses["e_n"] * vn),
            "velocity_out_t": tan["v_t"], "omega_out_n": tan["omega_n"], "omega_out_t": tan["omega_t"],
            "omega_out_tp": tan["omega_tp"]}


def rebound_state(contact, speed, incidence_deg, spin, rtol: float = DEFAULT_RTOL) -> dict:
    """Rebound velocity and spin of impacts in the incidence plane, as :func:`microimpact.simulate_many`.

    The fast path of the fits: one :func:`microimpact.solvers.engine.solve_normal_many` call (the
    impulses J, J_a, :func:`normal_impulses`) and the closed-form tangential map
    :func:`microimpact.model.tangential.tangential_outcome` (:func:`rebound_from_impulses`) -- the
    two halves of ``simulate_many`` without its Dataset (a test checks they agree).

    Parameters
    ----------
    contact : Contact
    speed, incidence_deg, spin : numpy.ndarray
        Incident speed [m/s], angle from the normal [deg] and top-spin (omega_t' = -spin) [rad/s].
    rtol : float
        Relative tolerance of the normal solves. [-]

    Returns
    -------
    dict of arrays: ``captured`` (bool), ``velocity_out_n``, ``velocity_out_t`` [m/s],
    ``omega_out_n``, ``omega_out_t``, ``omega_out_tp`` [rad/s].

    Examples
    --------
    At 20 deg the sphere ends rolling: v_t,out = 5/7 v_t,in and the contact point is at rest
    (v_t + r omega_t' = 0); at 60 deg it slides throughout. The same numbers as ``simulate_impact``:

    >>> import numpy as np
    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.solvers.impact import simulate_impact
    >>> out = rebound_state(WALL_1990, np.array([30.0, 30.0]), np.array([20.0, 60.0]), np.zeros(2))
    >>> v_t_in = 30.0 * np.sin(np.radians(20.0))
    >>> abs(float(out["velocity_out_t"][0] / v_t_in) - 5 / 7) < 1e-12
    True
    >>> abs(float(out["velocity_out_t"][0] + WALL_1990.radius * out["omega_out_tp"][0])) < 1e-9
    True
    >>> r = simulate_impact(WALL_1990, 30.0, incidence_deg=60.0)
    >>> abs(float(out["velocity_out_t"][1]) - r.velocity_out[1]) < 1e-9 * 30.0
    True
    """
    return rebound_from_impulses(contact, normal_impulses(contact, speed, incidence_deg, rtol), spin)


def oblique_model(problem: ObliqueProblem, contact_of, parameters: dict, *, speed=None, incidence_deg=None,
                  rtol: float = DEFAULT_RTOL) -> np.ndarray:
    """Model value of every entry's measured quantity, one normal solve batch per radius.

    Parameters
    ----------
    problem : ObliqueProblem
    contact_of : callable
        radius [m] -> Contact with the normal parameters (e.g. ``DampingFit.contact``).
    parameters : dict
        Tangential Contact fields (``friction`` [-], ...), applied with ``Contact.with_``.
    speed, incidence_deg : numpy.ndarray, optional
        Incident speed [m/s] and angle [deg] replacing the problem's (for slopes).
    rtol : float
        Relative tolerance of the normal solves. [-]

    Returns
    -------
    numpy.ndarray
        In each entry's unit (:data:`OBSERVABLE_UNITS`); NaN where the model captures the sphere.

    Examples
    --------
    At the generating friction 0.15 the model gives the rigid-body 5/7 at 35 deg (rolling) and more
    at the steeper angles (sliding throughout):

    >>> from microimpact.analysis.synthetic import make_synthetic_oblique
    >>> from microimpact.io import read_impacts, write_csv
    >>> data = make_synthetic_oblique(radii=(3.45e-6,), speeds=(15.0, 30.0), incidence_deg=(35.0, 50.0, 60.0, 70.0))
    >>> table = read_impacts(write_csv(data, "oblique.csv"))
    >>> from microimpact.io import default_materials_path, read_materials
    >>> from microimpact.io.materials import material_contact
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> problem = ObliqueProblem.from_table(table)
    >>> model = oblique_model(problem, lambda r: material_contact(material, r), {"friction": 0.15})
    >>> model[:4].round(3).tolist()
    [0.714, 0.78, 0.847, 0.901]
    """
    v = problem.speed if speed is None else speed
    a = problem.incidence_deg if incidence_deg is None else incidence_deg
    out = np.empty(problem.size)
    for r in np.unique(problem.radius):
        idx = np.flatnonzero(problem.radius == r)
        c = contact_of(float(r)).with_(**parameters)
        st = rebound_state(c, v[idx], np.clip(a[idx], 0.0, 89.9), problem.spin[idx], rtol=rtol)
        out[idx] = np.where(st["captured"], np.nan, _observables(st, v[idx], a[idx], problem.quantity[idx]))
    return out


def effective_sigma(problem: ObliqueProblem, contact_of, parameters: dict, rtol: float = DEFAULT_RTOL) -> np.ndarray:
    """sqrt(sigma_q^2 + (dq/dv sigma_v)^2 + (dq/dalpha sigma_alpha)^2) of each entry (see the module docstring).

    NaN where the quantity's own uncertainty is not stated.

    Examples
    --------
    The stated e_t uncertainty (0.02) widened by the speed and angle uncertainties through the
    model's slopes (the rolling 5/7 at 35 deg does not depend on the angle):

    >>> from microimpact.analysis.synthetic import make_synthetic_oblique
    >>> from microimpact.io import read_impacts, write_csv
    >>> data = make_synthetic_oblique(radii=(3.45e-6,), speeds=(15.0, 30.0), incidence_deg=(35.0, 50.0, 60.0, 70.0))
    >>> table = read_impacts(write_csv(data, "oblique.csv"))
    >>> from microimpact.io import default_materials_path, read_materials
    >>> from microimpact.io.materials import material_contact
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> problem = ObliqueProblem.from_table(table)
    >>> sigma = effective_sigma(problem, lambda r: material_contact(material, r), {"friction": 0.15})
    >>> sigma[:4].round(4).tolist()
    [0.02, 0.0204, 0.0202, 0.0202]
    """
    terms = [problem.sigma_measured ** 2]
    v, a = problem.speed, problem.incidence_deg
    if np.any(problem.sigma_speed > 0):
        up = oblique_model(problem, contact_of, parameters, speed=v * (1 + _H_SPEED), rtol=rtol)
        dn = oblique_model(problem, contact_of, parameters, speed=v * (1 - _H_SPEED), rtol=rtol)
        terms.append((np.nan_to_num((up - dn) / (2 * _H_SPEED * v)) * problem.sigma_speed) ** 2)
    if np.any(problem.sigma_angle > 0):
        up = oblique_model(problem, contact_of, parameters, incidence_deg=a + _H_ANGLE, rtol=rtol)
        dn = oblique_model(problem, contact_of, parameters, incidence_deg=np.maximum(a - _H_ANGLE, 0.0), rtol=rtol)
        step = a + _H_ANGLE - np.maximum(a - _H_ANGLE, 0.0)
        terms.append((np.nan_to_num((up - dn) / step) * problem.sigma_angle) ** 2)
    return np.sqrt(sum(terms))


@dataclass(frozen=True, eq=False)
class FrictionFit(ReportHTML, FitResult):
    """Result of :func:`fit_friction`.

    Attributes
    ----------
    values : dict
        Fitted tangential parameters (``friction`` [-]).
    stderr : dict
        Standard errors including the propagated damping covariance, same units (for a DEM
        tangential law, :func:`~microimpact.analysis.dem_friction.fit_dem_friction`: the normal fit's uncertainty where it was given,
        ``info["normal_propagated"]`` naming its parameters; else at the given normal law).
    stderr_conditional : dict
        Standard errors with the damping held at its fitted values.
    tangential_model : str
        ``Contact.tangential_model`` the parameters belong to.
    chisqr, redchi : float
        Chi-square and reduced chi-square of the tangential residuals.
    n_points : int
    weighted : bool
        Whether stated uncertainties weighted the fit (else the covariance is scaled by redchi).
    data : pandas.DataFrame
        ``row``, ``quantity``, ``radius`` [m], ``speed`` [m/s], ``incidence_deg`` [deg], ``measured``,
        ``sigma`` (effective), ``model``, ``residual`` ((model - measured)/sigma).
    info : dict
        ``nfev``, ``elapsed_s``, ``source``, ``method``, ``damping_gradient``, ``rolling_above``
        (every entry rolls for f above it), ``sliding_below`` (every entry slides below it),
        ``success`` (True only where f is determined); of :func:`~microimpact.analysis.dem_friction.fit_dem_friction` also
        ``normal_propagated``, ``stiffness_sensitivity`` and ``stiffness_uncertainty``.
    identifiability : dict
        ``{"friction": ParameterStatus}``: whether the data determine f (value and 95 % interval),
        bound it from one side, or cannot tell it (:mod:`microimpact.analysis.identifiability`).
        Where f is not determined, ``values`` holds the least-chi-square point of the profile (a
        point of a flat region, not an estimate) and ``stderr`` NaN.

    Examples
    --------
    The friction of the eight synthetic impacts (made with f = 0.15), fitted after the damping. The
    tangential data determine f: the truth lies within 1.2 of its standard errors at the fitted
    damping (``stderr_conditional``). What the damping's uncertainty adds is not determined here:
    these eight e_n bound zeta_H from above only (its best value lies at the bound 0), so zeta_H
    has no covariance to propagate, and ``stderr`` (which adds it) is not a number these data give:

    >>> from microimpact.analysis.synthetic import make_synthetic_oblique
    >>> from microimpact.io import read_impacts, write_csv
    >>> data = make_synthetic_oblique(radii=(3.45e-6,), speeds=(15.0, 30.0), incidence_deg=(35.0, 50.0, 60.0, 70.0))
    >>> table = read_impacts(write_csv(data, "oblique.csv"))
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.io import default_materials_path, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> damping = fit_damping(table, material, confidence_intervals=False)
    >>> damping.identifiability["zeta_hertz"].status
    'upper_bound'
    >>> friction = fit_friction(table, damping)
    >>> friction.identifiability["friction"].status, round(friction.friction, 3)
    ('determined', 0.159)
    >>> f"{friction.stderr_conditional['friction']:.2g}"
    '0.0076'
    >>> abs(friction.friction - 0.15) < 1.2 * friction.stderr_conditional["friction"]
    True
    """

    TITLE = "friction fit from oblique impacts"
    KIND = "friction fit"
    WRITTEN_BY = "microimpact fit --oblique-out"

    values: dict
    stderr: dict
    stderr_conditional: dict
    tangential_model: str
    chisqr: float
    redchi: float
    n_points: int
    weighted: bool
    data: pd.DataFrame
    info: dict = field(default_factory=dict)
    identifiability: dict = field(default_factory=dict)

    @property
    def friction(self) -> float:
        """Fitted Coulomb coefficient f (where not determined: a point of the flat region). [-]"""
        return self.values["friction"]

    @property
    def determined(self) -> bool:
        """True where the data determine every fitted tangential parameter."""
        return all(st.determined for st in self.identifiability.values())

    def __repr__(self) -> str:
        return estimates_repr("FrictionFit", self.values, self.stderr, tangential_model=self.tangential_model,
                              n_points=int(self.n_points))

    @property
    def _held_normal_law(self) -> bool:
        """A DEM law's mu at a given normal law (fit_dem_friction without normal_fit): nothing propagated."""
        return self.tangential_model in DEM_TANGENTIAL_MODELS and not self.info.get("normal_propagated")

    def report(self) -> str:
        """Plain-text summary: a value with its interval only where the data determine it."""
        dem = self.tangential_model in DEM_TANGENTIAL_MODELS
        held = self._held_normal_law
        lines = [f"Friction fit (LAMMPS's {self.tangential_model} tangential law), the normal law "
                 + ("held at its values" if held else "fitted before (its uncertainty included)")
                 if dem else f"Friction fit ({self.tangential_model} tangential model, Eqs. (16)-(20)), after the damping fit"]
        before = "the normal law" if dem else "the damping"
        for k, v in self.values.items():
            st = self.identifiability.get(k)
            if st is not None and not st.determined:
                lines.append(f"  {k:<17}: {st.describe()}")
                continue

            propagated = held or math.isfinite(self.stderr[k])  # a NaN term is not "included"
            if stderr_is_meaningful(v, self.stderr[k]) and stderr_is_meaningful(v, self.stderr_conditional[k]):
                lines.append(f"  {k:<17}= {v:.6g} +/- {self.stderr[k]:.3g}" + (" (at the normal law's values)" if held else
                             f" (with the uncertainty of {before}; {self.stderr_conditional[k]:.3g} at its best values)"))
            elif not propagated and stderr_is_meaningful(v, self.stderr_conditional[k]):
                lines.append(f"  {k:<17}= {v:.6g} +/- {self.stderr_conditional[k]:.3g} (at the best values of {before}: "
                             "its uncertainty could not be propagated)")
            else:  # a standard error above 100 % says nothing the interval does not say better
                lines.append(f"  {k:<17}= {v:.6g} (standard error above 100 %: see the interval)")
            if st is not None:
                lines.append(f"  {'':<17}  95 % interval [{st.lower:.6g}, {st.upper:.6g}] ({st.method}"
                             + (")" if held else f", uncertainty of {before} included)" if propagated
                                else f", at the best values of {before})"))
        lines += self._stiffness_lines()
        if "work_of_adhesion" in self.info.get("normal_propagated", ""):
            lines.append("  note        : with the work of adhesion fitted too, this interval covered the true mu in 63 of 68 "
                         "random designs (0.93) in the calibration study (docs/guide/lammps.md, "
                         "dem_friction_coverage(fit_adhesion=True))")
        qs = ", ".join(f"{q} ({int((self.data['quantity'] == q).sum())})" for q in dict.fromkeys(self.data["quantity"]))
        lines.append(f"  data        : {self.n_points} entries: {qs}; "
                     f"{'stated uncertainties + effective variance' if self.weighted else 'unweighted'}")
        lines.append(f"  chi-square  : {self.chisqr:.4g}, reduced {self.redchi:.4g}")
        lines += self.verdict.lines()
        return "\n".join(lines)

    @property
    def verdict(self):
        """Whether the tangential model describes the oblique entries, outliers by id
        (:func:`microimpact.analysis.verdict.assess_residuals`)."""
        d = self.data
        z = (d["model"].to_numpy(float) - d["measured"].to_numpy(float)) / d["sigma"].to_numpy(float)
        ids = (d["id"].astype(str).tolist() if "id" in d.columns else [f"row {r}" for r in d["row"]])
        return assess_residuals(np.nan_to_num(z), len(self.values), stated=bool(self.weighted), ids=ids,
                                speed=d["speed"].to_numpy(float), radius=d["radius"].to_numpy(float),
                                what=f"{self.tangential_model} tangential model")

    def _stiffness_lines(self) -> list[str]:
        """The report's lines on the held tangential stiffness of a DEM law (fit_dem_friction)."""
        k = self.info.get("stiffness_sensitivity")
        if not k:
            return []
        unit, what = ("N/m", "k_t") if k["field"] == "tangential_stiffness" else ("Pa", "G* (k_t = 8 G* a)")
        step = f"{100 * k['step']:.0f} %"
        u = self.info.get("stiffness_uncertainty")
        if u:
            return [f"  stiffness   : {what} given as {k['value']:.6g} {unit} with relative uncertainty {u:.3g} (a Gaussian "
                    f"prior) and profiled out: best at {k['profiled_factor']:.4g} times it; the interval is mu's "
                    "profile likelihood",
                    f"{'':<16}mu = {k['friction_low']:.6g} with it held {step} lower, {k['friction_high']:.6g} {step} "
                    f"higher; {STIFFNESS_COVERAGE} (docs/guide/lammps.md)"]
        lines = [f"  stiffness   : {what} held at {k['value']:.6g} {unit}, not fitted; mu = {k['friction_low']:.6g} "
                 f"with it {step} lower, {k['friction_high']:.6g} {step} higher"]
        st = self.identifiability.get("friction")
        if st is not None and not (st.lower <= min(k["friction_low"], k["friction_high"])
                                   and max(k["friction_low"], k["friction_high"]) <= st.upper):
            lines.append(f"{'':<16}the interval holds at this stiffness only: a {step} change moves mu out of it "
                         "(give its uncertainty: stiffness_uncertainty, --stiffness-uncertainty)")
        else:
            lines.append(f"{'':<16}the interval holds at this stiffness (its uncertainty not included)")
        return lines

    def to_dataset(self) -> xr.Dataset:
        """CF form: scalar ``friction`` (+ ``friction_stderr``) and the entries along ``entry``; the
        whole ``info`` record (nested entries included) as the JSON text attribute ``fit_info``."""
        d = self.data
        ds = xr.Dataset(coords={"entry": ("entry", np.arange(len(d)), {"long_name": "index of the fitted oblique entry"})})

        for st in self.identifiability.values():
            ds.update(status_variables(st, "1"))
        dem, held = self.tangential_model in DEM_TANGENTIAL_MODELS, self._held_normal_law
        for k, v in self.values.items():
            ds[k] = xr.DataArray(v, attrs={"units": "1", "long_name": f"fitted {k} ({self.tangential_model} tangential model)"})
            ds[f"{k}_stderr"] = xr.DataArray(self.stderr[k], attrs={
                "units": "1", "long_name": f"standard error of {k}, " + (
                    "at the given normal law" if held else
                    f"{'normal law' if dem else 'damping'} uncertainty propagated")})
            ds[f"{k}_stderr_conditional"] = xr.DataArray(self.stderr_conditional[k], attrs={
                "units": "1", "long_name": f"standard error of {k} at the fitted {'normal law' if dem else 'damping'}"})
        ds["row"] = ("entry", d["row"].to_numpy(dtype=np.int64), {"units": "1", "long_name": "data row in the impact CSV"})
        ds.update(label_variables(d[[c for c in d.columns if c not in _ENTRY_COLUMNS]], "entry"))
        ds["quantity"] = ("entry", d["quantity"].to_numpy(dtype=str).astype(object), {"long_name": "measured quantity"})
        for c, ln in (("radius", ("m", "sphere radius")), ("speed", ("m s-1", "incident speed")),
                      ("incidence_deg", ("degree", "incidence angle from the surface normal"))):
            ds[c] = ("entry", d[c].to_numpy(dtype=float), {"units": ln[0], "long_name": ln[1]})
        for c, ln in (("measured", "measured value"), ("sigma", "effective standard uncertainty"),
                      ("model", "model value at the fitted parameters")):
            ds[f"oblique_{c}"] = ("entry", d[c].to_numpy(dtype=float), {
                "units": "1", "long_name": f"{ln} of the entry's quantity (unit of the quantity: see quantity_units)"})
        ds["quantity_units"] = ("entry", np.array([OBSERVABLE_UNITS[q] for q in d["quantity"]], dtype=object),
                                {"long_name": "unit of the entry's quantity"})
        ds.attrs.update(self.verdict.to_attrs())
        ds.attrs.update({"title": self.TITLE, "Conventions": CONVENTIONS,
                         "tangential_model": self.tangential_model, "chisqr": self.chisqr, "redchi": self.redchi,
                         "n_points": self.n_points, "weighted": int(self.weighted),
                         "source": str(self.info.get("source", "")),
                         # the whole record (nested: the damping gradient, the stiffness sensitivity) for from_dataset
                         "fit_info": json.dumps(self.info, default=_json_scalar)})
        k = self.info.get("stiffness_sensitivity")
        if k:  # the held stiffness and how mu depends on it (fit_dem_friction)
            ds.attrs.update({"held_stiffness_field": k["field"], "held_stiffness": k["value"],
                             "stiffness_step": k["step"], "friction_at_lower_stiffness": k["friction_low"],
                             "friction_at_higher_stiffness": k["friction_high"],
                             "stiffness_uncertainty": float(self.info.get("stiffness_uncertainty") or 0.0)})
            if self.info.get("stiffness_uncertainty"):
                ds.attrs["profiled_stiffness_factor"] = k["profiled_factor"]
        return ds

    @classmethod
    def from_dataset(cls, ds: xr.Dataset) -> "FrictionFit":
        """Inverse of :meth:`to_dataset` (also of the Dataset read back from its file)."""
        ds = restore_label_coordinates(ds)
        a = ds.attrs
        names = [str(v).removesuffix("_stderr_conditional") for v in ds.data_vars if str(v).endswith("_stderr_conditional")]
        values = {k: float(ds[k]) for k in names}
        data = pd.DataFrame({"row": ds["row"].values.astype(np.int64), "quantity": ds["quantity"].values.astype(str),
                             "radius": ds["radius"].values, "speed": ds["speed"].values,
                             "incidence_deg": ds["incidence_deg"].values, "measured": ds["oblique_measured"].values,
                             "sigma": ds["oblique_sigma"].values, "model": ds["oblique_model"].values})
        data["residual"] = (data["model"] - data["measured"]) / data["sigma"]  # as the fit computed it
        data = insert_row_labels(data, labels_from_dataset(ds, "entry"))
        statuses = {k: status_from_variables(ds, k, values[k]) for k in names}
        info = json.loads(a["fit_info"]) if "fit_info" in a else {"source": str(a.get("source", ""))}
        return cls(values=values, stderr={k: float(ds[f"{k}_stderr"]) for k in names},
                   stderr_conditional={k: float(ds[f"{k}_stderr_conditional"]) for k in names},
                   tangential_model=str(a["tangential_model"]), chisqr=float(a["chisqr"]), redchi=float(a["redchi"]),
                   n_points=int(a["n_points"]), weighted=bool(int(a["weighted"])), data=data, info=info,
                   identifiability={k: st for k, st in statuses.items() if st is not None})


def _json_scalar(value):
    """A numpy scalar as its Python number, for :func:`json.dumps` of a fit's info."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def fit_friction(table, damping_fit, *, tangential_model: str | None = None, rtol: float = DEFAULT_RTOL,
                 propagate_damping: bool = True, progress: bool = False, time_budget: float | None = None) -> FrictionFit:
    """Fit the tangential parameters (friction f) to the oblique columns, after the damping fit.

    Parameters
    ----------
    table : pandas.DataFrame
        Impacts from :func:`microimpact.io.read_impacts` with an oblique column (module docstring).
    damping_fit : DampingFit
        The normal fit; its contact (f0 per radius from Eq. (7)) is used at every radius.
    tangential_model : str, optional
        Key of :data:`TANGENTIAL_PARAMETERS`; default the fitted contact's ``tangential_model``.
    rtol : float
        Relative tolerance of the normal solves. [-]
    propagate_damping : bool
        Add the damping covariance to the standard error and the interval (two refits per damping
        parameter).
    progress : bool
        Progress bar on stderr (a terminal only).
    time_budget : float or Deadline, optional
        Wall-clock budget; None: no limit. Checked after every model evaluation. [s]

    Returns
    -------
    FrictionFit
        With :attr:`FrictionFit.identifiability`: whether the data determine f, bound it from one
        side (``f >= f_r`` where every impact ends in rolling above f_r) or cannot tell it.

    Raises
    ------
    ValueError
        No oblique data (names the file), an unknown tangential model (names the hook to extend),
        a ``time_budget`` that is not a number > 0.
    TimeBudgetExceeded
        The fit ran past ``time_budget``; the message says how far it got.

    Notes
    -----
    The objective is piecewise in f: an impact slides throughout (its rebound depends on f) below
    its rolling threshold f*_i = 2 m |u_0| / (7 J_i) (:mod:`microimpact.model.tangential`) and rolls
    above it (no dependence on f). A local least-squares step started where every impact rolls stops
    at once on the flat part. The fit therefore profiles chi-square over the whole range
    ``PARAMETER_BOUNDS["friction"]`` on a grid that contains every f*_i (the normal solves do not
    depend on f, so each grid point is one closed-form map), refines the least chi-square by a
    bounded scalar search between its grid neighbours, and polishes it with lmfit's ``leastsq``
    (kept only if it does not raise chi-square). The interval is the profile-likelihood interval
    (chi-square within :func:`~microimpact.analysis.identifiability.chi2_threshold` of its least
    value; scaled by the reduced chi-square when no uncertainties are stated), widened in quadrature
    by the damping uncertainty (delta method, g^T Cov(zeta) g with g = d f_hat / d zeta from refits at
    zeta +/- one standard error).

    References
    ----------
    Cheng, Brach & Dunn (2002), Sec. 4 (the tangential impulse map, Eqs. 32-41); Venzon, D. J. and
    Moolgavkar, S. H. (1988), A method for computing profile-likelihood-based confidence intervals,
    J. R. Stat. Soc. C 37(1):87-94, doi:10.2307/2347496.

    Examples
    --------
    The damping fitted to twelve noise-free normal rebounds, then six oblique rebounds at 20 m/s
    made with f = 0.3 (each slides throughout), stated to 0.01 in e_t:

    >>> from microimpact import simulate_impact
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import make_synthetic_impacts
    >>> from microimpact.io import read_materials
    >>> raw = make_synthetic_impacts(e_n_rel_sd=0.0, speed_rel_sd=0.0, angle_sd_deg=0.0, radii=(3.45e-6,),
    ...                              n_per_radius=12)
    >>> normal = pd.DataFrame({"radius": 3.45e-6, "normal_speed": raw.attrs["true_normal_speed"],
    ...                        "e_n": raw.attrs["true_e_n"]})
    >>> damping = fit_damping(normal, read_materials()["ammonium_fluorescein_on_silicon"], confidence_intervals=False)
    >>> angles = np.linspace(50.0, 75.0, 6)
    >>> rebounds = [simulate_impact(damping.contact(3.45e-6).with_(friction=0.3), 20.0, a) for a in angles]
    >>> oblique = pd.DataFrame({"radius": 3.45e-6, "speed": 20.0, "incidence_deg": angles,
    ...                         "e_n": [r.e_n for r in rebounds],
    ...                         "tangential_restitution": [r.velocity_out[1] / (20.0 * np.sin(np.radians(a)))
    ...                                                    for r, a in zip(rebounds, angles)],
    ...                         "tangential_restitution_uncertainty": 0.01})
    >>> fit = fit_friction(oblique, damping)
    >>> print(fit.identifiability["friction"].describe())
    friction = 0.3, 95 % interval [0.2831, 0.3169]

    At 10-40 deg every impact ends rolling, and the data only bound f from below: no value is given.
    """
    t0 = time.perf_counter()
    deadline = Deadline.start(time_budget, "friction fit")
    problem = ObliqueProblem.from_table(table, warn=True)
    contact_of = damping_fit.contact
    model_name = _fitted_tangential_model(tangential_model or contact_of(float(problem.radius[0])).tangential_model)
    weighted = bool(np.all(np.isfinite(problem.sigma_measured) & (problem.sigma_measured > 0)))
    n_var = len(damping_fit.varied) if propagate_damping else 0
    with progress_bar(3 + 2 * n_var, "friction fit", progress) as advance, engine_threads(1):
        objective = _FrictionObjective(problem, contact_of, weighted, rtol)
        deadline.check("the normal solves of the friction fit")
        best = _profile_fit(objective, lmfit, deadline)
        advance(3)
        gradient, var_damping = {}, 0.0
        if propagate_damping and damping_fit.varied:
            gradient, var_damping = _damping_variance(problem, damping_fit, best, weighted, rtol, advance, deadline)
    return _friction_result(problem, objective, best, var_damping, gradient, weighted, model_name, t0)


def _fitted_tangential_model(model_name: str) -> str:
    """``model_name``, checked to be a key of :data:`TANGENTIAL_PARAMETERS` whose parameters the
    profile of :func:`fit_friction` fits (the rigid law's f alone); ValueError naming the hook."""
    if model_name not in TANGENTIAL_PARAMETERS:
        raise ValueError(f"tangential_model {model_name!r} has no fitted parameters registered; add them to "
                         f"microimpact.analysis.oblique.TANGENTIAL_PARAMETERS (known: {', '.join(TANGENTIAL_PARAMETERS)})")
    names = TANGENTIAL_PARAMETERS[model_name]
    if names != ("friction",):  # the profile below is the rigid law's closed form in f
        raise ValueError(f"tangential_model {model_name!r}: only the Coulomb coefficient of the rigid law is fitted "
                         "from oblique data; add a profile for its parameters in microimpact.analysis.oblique")
    return model_name


def _damping_variance(problem, damping_fit, best, weighted, rtol, advance, deadline) -> tuple[dict, float]:
    """(gradient, variance) of the fitted f ``best`` from the damping fit's uncertainty: d f / d zeta
    by refits (:func:`_damping_gradient`) and g^T Cov(zeta) g (NaN where a refit failed)."""
    gradient = _damping_gradient(problem, damping_fit, best.value, weighted, rtol, lmfit, advance, deadline)
    cov = _damping_covariance(damping_fit)
    g = np.array([gradient["friction"][p] for p in damping_fit.varied])
    return gradient, (float(g @ cov @ g) if np.all(np.isfinite(g)) else math.nan)


def _friction_result(problem, objective, best, var_damping, gradient, weighted, model_name, t0,
                     shift=None) -> "FrictionFit":
    """The FrictionFit of a profile fit: status, value and errors only where f is determined.
    ``shift``: the 95 % (down, up) widening by a normal law's region (:func:`_normal_law_shift`),
    in place of ``var_damping``; its standard error is the mean shift / 1.96."""
    if shift is not None:
        var_damping = (0.5 * sum(shift) / stats.norm.ppf(0.5 + DEFAULT_LEVEL / 2)) ** 2
    status = _friction_status(best, objective, var_damping, shift)
    p = {"friction": float(best.value)}
    sigma = objective.sigma(best.value)
    model = objective.model(best.value)
    data = pd.DataFrame({"row": problem.rows, "quantity": problem.quantity.astype(str), "radius": problem.radius,
                         "speed": problem.speed, "incidence_deg": problem.incidence_deg, "measured": problem.measured,
                         "sigma": sigma, "model": model, "residual": (model - problem.measured) / sigma})
    if problem.labels is not None:
        data = insert_row_labels(data, problem.labels)
    cond = best.stderr if status.determined else math.nan
    total = math.sqrt(cond ** 2 + var_damping) if status.determined else math.nan
    dof = max(problem.size - 1, 1)
    return FrictionFit(values=p, stderr={"friction": total}, stderr_conditional={"friction": cond},
                       tangential_model=model_name, chisqr=float(best.chisqr), redchi=float(best.chisqr / dof),
                       n_points=problem.size, weighted=weighted, data=data,
                       info={"nfev": best.nfev, "elapsed_s": time.perf_counter() - t0, "source": problem.source,
                             "method": "chi-square profile over the whole range of f (every rolling threshold a grid "
                                       "point), bounded refinement, lmfit leastsq polish",
                             "damping_gradient": gradient, "rolling_above": best.rolling_above,
                             "sliding_below": best.sliding_below,
                             "success": status.determined},
                       identifiability={"friction": status})


# --------------------------------------------------------------------------- the friction profile
class _FrictionObjective:
    """Chi-square of the friction fit as a function of f, from normal solves made once.

    The normal solve of every entry (and of its speed and angle perturbations, for the effective
    variance) does not depend on f; each trial f is the closed-form tangential map only.
    """

    def __init__(self, problem, contact_of, weighted, rtol):
        self.problem, self.weighted = problem, weighted
        self.radii = np.unique(problem.radius)
        self.contacts = {float(r): contact_of(float(r)) for r in self.radii}
        v, a = problem.speed, problem.incidence_deg
        self.states = {"nominal": self._solve(v, a, rtol)}
        if weighted and np.any(problem.sigma_speed > 0):
            self.states["v+"] = self._solve(v * (1 + _H_SPEED), a, rtol)
            self.states["v-"] = self._solve(v * (1 - _H_SPEED), a, rtol)
        if weighted and np.any(problem.sigma_angle > 0):
            self.states["a+"] = self._solve(v, a + _H_ANGLE, rtol)
            self.states["a-"] = self._solve(v, np.maximum(a - _H_ANGLE, 0.0), rtol)
        self.nfev = 0

    def _solve(self, v, a, rtol):
        out = []
        for r in self.radii:
            idx = np.flatnonzero(self.problem.radius == r)
            imp = normal_impulses(self.contacts[float(r)], v[idx], np.clip(a[idx], 0.0, 89.9), rtol)
            out.append((idx, v[idx], a[idx], imp))
        return out

    def model(self, f, state="nominal") -> np.ndarray:
        """Model value of every entry at friction f (NaN where the model captures). [unit of the entry]"""
        self.nfev += 1
        out = np.empty(self.problem.size)
        for idx, v, a, imp in self.states[state]:
            c = self.contacts[float(self.problem.radius[idx[0]])]
            st = rebound_from_impulses(c, imp, self.problem.spin[idx], friction=f)
            out[idx] = np.where(st["captured"], np.nan, _observables(st, v, a, self.problem.quantity[idx]))
        return out

    def sigma(self, f) -> np.ndarray:
        """Effective standard uncertainty of every entry at friction f (ones when unweighted)."""
        if not self.weighted:
            return np.ones(self.problem.size)
        return self._effective_sigma(f, "v+" in self.states, "a+" in self.states)

    def _effective_sigma(self, f, speed: bool, angle: bool) -> np.ndarray:
        """sqrt(sigma^2 + (dy/dv sigma_v)^2 + (dy/dtheta sigma_theta)^2), the slopes by central
        differences of the model (the speed and the angle terms where asked for)."""
        p = self.problem
        terms = p.sigma_measured ** 2
        if speed:
            slope = (self.model(f, "v+") - self.model(f, "v-")) / (2 * _H_SPEED * p.speed)
            terms = terms + (np.nan_to_num(slope) * p.sigma_speed) ** 2
        if angle:
            step = p.incidence_deg + _H_ANGLE - np.maximum(p.incidence_deg - _H_ANGLE, 0.0)
            slope = (self.model(f, "a+") - self.model(f, "a-")) / step
            terms = terms + (np.nan_to_num(slope) * p.sigma_angle) ** 2
        return np.sqrt(terms)

    def residual(self, f, sigma=None) -> np.ndarray:
        """(model - measured) / sigma; a captured model entry counts as far from its rebound."""
        s = self.sigma(f) if sigma is None else sigma
        return np.nan_to_num((self.model(f) - self.problem.measured) / s, nan=1e3)

    def chi2(self, f) -> float:
        """Chi-square at f with the effective variance at f. [-]"""
        r = self.residual(f)
        return float(r @ r)

    def deviance(self, f) -> float:
        """-2 log likelihood at f, up to a constant: chi-square plus sum(log sigma^2) when weighted. [-]

        The effective variance depends on f (the slopes of the model in speed and angle differ between
        sliding and rolling), so the likelihood's normalisation does too; without its log term a
        region of smaller sigma would look worse than it is. Unweighted: chi-square.
        """
        s = self.sigma(f)
        r = self.residual(f, s)
        return float(r @ r) + (float(np.sum(np.log(s ** 2))) if self.weighted else 0.0)

    def rolling_thresholds(self) -> np.ndarray:
        """f*_i above which entry i ends in rolling (inf: no friction impulse; 0: no slip). [-]"""
        p = self.problem
        out = np.full(p.size, np.inf)
        for idx, v, a, imp in self.states["nominal"]:
            c = self.contacts[float(p.radius[idx[0]])]
            slip = np.abs(imp["velocity_in_t"] - c.radius * p.spin[idx])  # u_t = v_t + r omega_t', omega_t' = -spin
            j = imp["friction_impulse"]
            with np.errstate(divide="ignore", invalid="ignore"):
                out[idx] = np.where(j > 0, 2.0 * c.mass * slip / (7.0 * j), np.inf)
        return out


def _profile_scale(objective, least: float, dof: int) -> float:
    """What a profile's deviance is divided by: 1 with stated uncertainties; unweighted, the reduced
    chi-square at its least value (the scatter estimates sigma)."""
    return 1.0 if objective.weighted else max(least / dof, 1e-300)



#: the measured calibration of mu's interval with the stiffness profiled (the report states it)
STIFFNESS_COVERAGE = ("with u = 0.1 this interval covered the true mu in 16 of 18 random designs (0.89; consistent with "
                      "95 %, binomial p = 0.23; both misses excluded by the noise even at the true stiffness)")



@dataclass(frozen=True)
class _ProfileFit:
    value: float
    stderr: float  # local (curvature) standard error at fixed damping, NaN where not estimated
    chisqr: float
    grid: np.ndarray
    chi2: np.ndarray  # the profile of the deviance, scaled by the reduced chi-square when unweighted
    nfev: int
    rolling_above: float
    sliding_below: float


def _refine_profile(objective, grid, chi2, points):
    """A coarse profile refined: the bottom of every local minimum (bounded search between its grid
    neighbours: a valley narrower than the grid's spacing, from precise data, falls between two grid
    points), then ``points`` more over each run of cells within 3 x 3.84 of the least value (the
    interval's ends). A costly objective's profile (DEM laws: every point solves every entry).

    Measured before the valleys were searched: 5 of 40 random designs had 95 % intervals that missed
    the true mu, two of them around a minimum of the grid while the true valley lay between grid points."""
    n = grid.size
    found_x, found_c = [], []
    for i in range(1, n - 1):
        if chi2[i] <= chi2[i - 1] and chi2[i] <= chi2[i + 1]:
            res = minimize_scalar(objective.deviance, bounds=(grid[i - 1], grid[i + 1]), method="bounded",
                                  options={"xatol": 1e-6 * grid[i]})
            found_x.append(float(res.x))
            found_c.append(float(res.fun))
    grid, chi2 = np.concatenate([grid, found_x]), np.concatenate([chi2, found_c])
    order = np.argsort(grid, kind="stable")
    grid, chi2 = grid[order], chi2[order]
    # unweighted, the profile is divided by the reduced chi-square afterwards: the cells within
    # 3 x 3.84 of the least value in those units (raw, every cell of a fit to 1e-3 scatter was "near",
    # and the interval's ends were interpolated across 0.06-wide cells: 8 times too narrow)
    dof = max(objective.problem.size - 1, 1)
    scale = _profile_scale(objective, float(chi2.min()), dof)
    near = chi2 <= chi2.min() + 3.0 * 3.84 * scale
    extra = []
    for run in np.split(np.flatnonzero(near), np.flatnonzero(np.diff(np.flatnonzero(near)) > 1) + 1):
        lo, hi = grid[max(run[0] - 1, 0)], grid[min(run[-1] + 1, grid.size - 1)]
        extra.append(np.linspace(lo, hi, points))
    extra = np.concatenate(extra)
    grid = np.concatenate([grid, extra])
    chi2 = np.concatenate([chi2, [objective.deviance(f) for f in extra]])
    order = np.argsort(grid, kind="stable")
    return grid[order], chi2[order]


def _threshold_crossings(objective, grid, chi2, dof) -> tuple[np.ndarray, np.ndarray]:
    """(mu, deviance) where the profile crosses the 95 % threshold, each found by Brent's root
    search between the two grid points that bracket it (to 1e-6 of mu): the interval's ends exact,
    not interpolated (a grid of 32 points across cells 0.12 wide put the ends of a 0.01-wide
    interval where chi-square had risen by 3.3, not 3.84)."""
    scale = _profile_scale(objective, float(chi2.min()), dof)
    level = float(chi2.min()) + chi2_threshold(DEFAULT_LEVEL) * scale
    above = chi2 > level
    xs = []
    for i in np.flatnonzero(above[:-1] != above[1:]):
        xs.append(brentq(lambda f: objective.deviance(f) - level, grid[i], grid[i + 1], xtol=1e-6 * grid[i + 1]))
    return np.array(xs), np.array([objective.deviance(x) for x in xs])


def _profile_fit(objective: _FrictionObjective, lmfit, deadline, points: int = PROFILE_POINTS,
                 refine: int = 0) -> _ProfileFit:
    """Global minimum of chi-square(f) over the whole range, and the profile (see fit_friction).

    ``refine`` > 0: the profile refined by :func:`_refine_profile` (a coarse grid of a costly objective)."""
    _, lo, hi = PARAMETER_BOUNDS["friction"]
    thresholds = objective.rolling_thresholds()
    finite = thresholds[np.isfinite(thresholds) & (thresholds > lo) & (thresholds < hi)]
    grid = np.unique(np.concatenate([[lo, hi], np.geomspace(1e-4, hi, points),
                                     finite, finite * (1 - 1e-6), finite * (1 + 1e-6)]))
    grid = grid[(grid >= lo) & (grid <= hi)]
    chi2 = np.empty(grid.size)  # the deviance (see _FrictionObjective.deviance)
    for i, f in enumerate(grid):
        chi2[i] = objective.deviance(f)
        if i % 50 == 0:
            deadline.check(f"{i} of {grid.size} points of the friction profile")
    if refine:
        grid, chi2 = _refine_profile(objective, grid, chi2, refine)
    ends = _threshold_crossings(objective, grid, chi2, max(objective.problem.size - 1, 1))
    grid, chi2 = np.concatenate([grid, ends[0]]), np.concatenate([chi2, ends[1]])
    order = np.argsort(grid, kind="stable")
    grid, chi2 = grid[order], chi2[order]
    k = int(np.argmin(chi2))
    a, b = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    f_best, c_best = float(grid[k]), float(chi2[k])
    if b > a:
        res = minimize_scalar(objective.deviance, bounds=(a, b), method="bounded", options={"xatol": 1e-10 * max(b, 1e-3)})
        if res.fun < c_best:
            f_best, c_best = float(res.x), float(res.fun)
    # lmfit polish at the effective variance of the best point; kept only if it lowers chi-square
    sigma = objective.sigma(f_best)
    params = lmfit.Parameters()
    params.add("friction", value=f_best, min=lo, max=hi)
    mini = lmfit.Minimizer(lambda p: objective.residual(p["friction"].value, sigma), params,
                           scale_covar=not objective.weighted, iter_cb=deadline.iter_cb("the friction polish"))
    out = mini.minimize(method="leastsq")
    f_polish = float(out.params["friction"].value)
    c_polish = objective.deviance(f_polish)
    if c_polish <= c_best:
        f_best, c_best = f_polish, c_polish
    stderr = float(out.params["friction"].stderr) if out.params["friction"].stderr is not None else math.nan
    chisqr = objective.chi2(f_best)
    dof = max(objective.problem.size - 1, 1)
    scale = _profile_scale(objective, chisqr, dof)
    grid = np.append(grid, f_best)
    chi2 = np.append(chi2, c_best)
    order = np.argsort(grid, kind="stable")
    rolling = float(np.max(thresholds)) if thresholds.size else math.nan
    sliding = float(np.min(thresholds)) if thresholds.size else math.nan
    return _ProfileFit(f_best, stderr, chisqr, grid[order], chi2[order] / scale, objective.nfev + out.nfev,
                       rolling, sliding)


def _friction_status(best: _ProfileFit, objective: _FrictionObjective, var_damping: float, shift=None):
    """The identifiability of f: profile interval, widened by the damping uncertainty (1.96 times
    the square root of ``var_damping`` each way, or the 95 % (down, up) ``shift``), classified."""
    _, lo_lim, hi_lim = PARAMETER_BOUNDS["friction"]
    _, lo, hi, _ = profile_interval(best.grid, best.chi2, chi2_threshold(DEFAULT_LEVEL))
    if shift is None and math.isfinite(var_damping) and var_damping > 0:
        shift = (float(stats.norm.ppf(0.5 + DEFAULT_LEVEL / 2)) * math.sqrt(var_damping),) * 2
    if shift is not None:
        f = best.value
        lo = lo if lo <= lo_lim else max(lo_lim, f - math.hypot(f - lo, shift[0]))
        hi = hi if hi >= hi_lim else min(hi_lim, f + math.hypot(hi - f, shift[1]))
    roll = best.rolling_above
    reasons = {
        "lower_bound": (f"every impact ends in rolling for f above {roll:.3g}, where the rebound no longer depends "
                        f"on f; the data exclude f below {lo:.3g}" if math.isfinite(roll) and roll <= hi_lim else
                        f"chi-square stays within the {100 * DEFAULT_LEVEL:.0f} % threshold up to f = {hi_lim:g}"),
        "upper_bound": "the data are consistent with no friction at all (f = 0)",
        "not_determined": (f"every impact ends in rolling for f above {roll:.3g} and the data are consistent with f "
                           "down to 0" if math.isfinite(roll) else
                           "no impact's rebound depends on f at these data"),
    }
    status = status_from_interval("friction", best.value, lo, hi, lo_lim, hi_lim, method="profile", reasons=reasons)
    if status.determined and math.isfinite(best.stderr) and best.stderr > abs(best.value):
        return status_from_interval("friction", best.value, lo_lim, hi, lo_lim, hi_lim, reasons=reasons)
    return status


def _damping_gradient(problem, damping_fit, f_best, weighted, rtol, lmfit, advance,
                      deadline=Deadline.start(None, "")) -> dict:
    """d(fitted f)/d(damping parameter) by central refits (global profile) at +/- one standard error."""
    grad = {"friction": {}}
    for p in damping_fit.varied:
        h = damping_fit.stderr[p] if math.isfinite(damping_fit.stderr[p]) and damping_fit.stderr[p] > 0 \
            else 1e-3 * abs(damping_fit.values[p])
        x0 = damping_fit.values[p]
        # the damping parameters are >= 0 (w_A > 0): a step that would leave that range is shortened
        steps = (x0 + h, max(x0 - h, 0.5 * x0)) if x0 > 0 else (x0 + h, x0)
        fitted = []
        for x in steps:
            values = dict(damping_fit.values) | {p: x}

            def contact_of(r, values=values):
                return damping_fit.contact(r).with_(**_contact_fields(damping_fit, r, values))
            fitted.append(_profile_fit(_FrictionObjective(problem, contact_of, weighted, rtol), lmfit, deadline).value)
            advance(1)
        grad["friction"][p] = (fitted[0] - fitted[1]) / (steps[0] - steps[1])
    return grad


def _contact_fields(damping_fit, radius, values) -> dict:
    """Contact fields of one radius for damping parameters ``values`` (f0 from Eq. (7) when w_A moves)."""
    c = material_contact(damping_fit, radius, zeta_hertz=values["zeta_hertz"], zeta_adhesion=values["zeta_adhesion"],
                         work_of_adhesion=values["work_of_adhesion"])
    return {"zeta_hertz": c.zeta_hertz, "zeta_adhesion": c.zeta_adhesion, "adhesion_line_force": c.adhesion_line_force}


def _damping_covariance(damping_fit) -> np.ndarray:
    """Covariance of the varied damping parameters from the fit's standard errors and correlation."""
    idx = [PARAMETER_NAMES.index(p) for p in damping_fit.varied]
    se = np.array([damping_fit.stderr[p] for p in damping_fit.varied])
    corr = np.nan_to_num(damping_fit.correlation[np.ix_(idx, idx)])
    return corr * np.outer(se, se)
