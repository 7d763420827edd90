"""Damping from a target: the zeta_H, zeta_A that reproduce a measured e_n at one speed (or a few).

The DEM user's question: "given the e_n I measured at this speed, which damping coefficients
reproduce it?" One e_n at one speed is ONE equation for TWO unknowns, so the answer is a curve in
the (zeta_H, zeta_A) plane, not a point: :func:`damping_from_target` returns that curve. The model
e_n of Eq. (21) falls monotonically in each of zeta_H and zeta_A (both damping forces of Eq. (27)
only remove energy), so along zeta_A in [0, zeta_A,max] exactly one zeta_H >= 0 gives the target;
zeta_A,max is where zeta_H = 0, and zeta_H,max (at zeta_A = 0) closes the curve. Each point is a
bracketed root (Brent) of e_n(zeta_H) - e_n,target, every e_n from
:func:`microimpact.solvers.engine.solve_normal_many` (through
:func:`microimpact.analysis.fitting.model_restitution`).

With two or more (speed, e_n) points the curves cross: the least-squares point (weighted by the
e_n uncertainties when given) is returned with its standard errors, and each point's curve.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import lmfit
import numpy as np
import pandas as pd
import xarray as xr
from scipy.optimize import brentq

from microimpact.analysis.fit_result import FitResult
from microimpact.io.files import CONVENTIONS, write_csv
from microimpact.io.formatting import estimates_repr
from microimpact.solvers import DEFAULT_RTOL
from microimpact.analysis.fitting import FitProblem, damping_residual, model_restitution
from microimpact.io.resources import check_memory
from microimpact.solvers import Deadline, engine_threads

__all__ = ["DampingTarget", "damping_from_target"]

_ZETA_CAP = 1e6  # [-] no physical damping is larger; the bracket search stops here


#: the DampingTarget.info entries its file keeps (as global attributes)
_INFO_KEYS = ("rtol", "material", "chisqr")
#: the target columns and their (units, long_name) in the file (as ``target_<column>``)
_TARGET_COLUMNS = {"speed": ("m s-1", "target incident normal speed"),
                   "e_n": ("1", "target normal coefficient of restitution"),
                   "e_n_uncertainty": ("1", "standard uncertainty of the target e_n"),
                   "radius": ("m", "sphere radius")}


@dataclass(frozen=True, eq=False)
class DampingTarget(FitResult):
    """Result of :func:`damping_from_target`.

    Attributes
    ----------
    targets : pandas.DataFrame
        ``speed`` [m/s] (normal), ``e_n`` [1], ``e_n_uncertainty`` [1] (NaN if not given), ``radius`` [m].
    curves : xarray.Dataset
        ``zeta_hertz(target, curve_point)``, ``zeta_adhesion(target, curve_point)`` [1]: for each
        target, the curve of (zeta_H, zeta_A) that reproduces it.
    best : dict or None
        With >= 2 targets: least-squares ``zeta_hertz``, ``zeta_adhesion`` [1]; None for one target.
    stderr : dict or None
        Standard errors of ``best`` (covariance scaled by the reduced chi-square unless
        uncertainties were given).
    info : dict
        ``material``, ``rtol``, ``chisqr``.

    Examples
    --------
    See :func:`damping_from_target`; one target gives a curve of (zeta_H, zeta_A) and no point:

    >>> from microimpact.presets import WALL_1990
    >>> target = damping_from_target(0.5, 3.0, WALL_1990, n_points=5)
    >>> target.best is None, target.curves.sizes["curve_point"]
    (True, 5)
    """

    TITLE = "damping coefficients that reproduce measured e_n (Cheng, Brach & Dunn 2002, Eq. (27))"
    KIND = "damping target"
    WRITTEN_BY = "microimpact target --out"

    targets: pd.DataFrame
    curves: xr.Dataset
    best: dict | None = None
    stderr: dict | None = None
    info: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        if self.best is None:
            best = "no least-squares point"
        elif len(self.targets) <= len(self.best):  # as many targets as parameters: solved, no error estimate
            best = estimates_repr("exact", self.best)
        else:
            best = estimates_repr("best", self.best, self.stderr)
        return (f"DampingTarget({len(self.targets)} target(s), {self.curves.sizes.get('curve_point', 0)} curve points, "
                f"{best})")

    def to_dataset(self) -> xr.Dataset:
        """The curves, the targets and the best point as one CF Dataset."""
        ds = self.curves.copy()
        t = self.targets
        for c, (u, ln) in _TARGET_COLUMNS.items():
            ds[f"target_{c}"] = ("target", t[c].to_numpy(dtype=float), {"units": u, "long_name": ln})
        if self.best is not None:
            for k, v in self.best.items():
                ds[f"best_{k}"] = ((), v, {"units": "1", "long_name": f"least-squares {k} over all targets"})
                ds[f"best_{k}_stderr"] = ((), self.stderr[k], {"units": "1", "long_name": f"standard error of best {k}"})
        ds.attrs.update({"title": self.TITLE, "Conventions": CONVENTIONS,
                         **{k: v for k, v in self.info.items() if isinstance(v, (int, float, str))}})
        return ds

    @classmethod
    def from_dataset(cls, ds: xr.Dataset) -> "DampingTarget":
        """Inverse of :meth:`to_dataset` (also of the Dataset read back from its file)."""
        targets = pd.DataFrame({c: ds[f"target_{c}"].values.astype(float) for c in _TARGET_COLUMNS})
        names = [str(v).removeprefix("best_") for v in ds.data_vars
                 if str(v).startswith("best_") and not str(v).endswith("_stderr")]
        best = {k: float(ds[f"best_{k}"]) for k in names} or None
        stderr = {k: float(ds[f"best_{k}_stderr"]) for k in names} or None
        curves = ds[["zeta_hertz", "zeta_adhesion"]]
        curves.attrs = {}
        info = {k: (v.item() if hasattr(v, "item") else v) for k, v in ds.attrs.items() if k in _INFO_KEYS}
        return cls(targets=targets, curves=curves, best=best, stderr=stderr, info=info)

    def to_frame(self) -> pd.DataFrame:
        """One row per curve point: ``target``, ``speed`` [m/s], ``e_n`` [1], ``zeta_hertz``, ``zeta_adhesion`` [1]."""
        c = self.curves
        rows = []
        for i in range(c.sizes["target"]):
            for j in range(c.sizes["curve_point"]):
                rows.append({"target": i + 1, "speed": float(self.targets["speed"].iloc[i]),
                             "e_n": float(self.targets["e_n"].iloc[i]), "zeta_hertz": float(c["zeta_hertz"][i, j]),
                             "zeta_adhesion": float(c["zeta_adhesion"][i, j])})
        return pd.DataFrame(rows)

    def save(self, path):
        """Write the result to ``path``: ``.nc`` through :meth:`FitResult.save` (what :meth:`load`
        reads), or ``.csv``, the curves alone as a table of :meth:`to_frame` (one row per curve point)."""
        if str(path).endswith(".csv"):
            return write_csv(self.to_frame(), path, float_format="%.8g")
        if str(path).endswith(".nc"):
            return super().save(path)
        raise ValueError(f"{path}: the output must end in .csv or .nc")


def _model(material, radius, rtol):
    def e_n(speed, zeta_hertz, zeta_adhesion):
        prob = FitProblem.from_arrays(np.atleast_1d(radius), np.atleast_1d(speed), material)
        return float(model_restitution(prob, zeta_hertz, zeta_adhesion, material.work_of_adhesion, rtol=rtol)[0])
    return e_n


def _root(fun, lo: float, target: float) -> float:
    """The zeta >= lo where the decreasing ``fun`` reaches ``target`` (bracket by doubling, then Brent)."""
    hi = max(2.0 * lo, 1.0)
    while fun(hi) > target:
        hi *= 4.0
        if hi > _ZETA_CAP:
            raise ValueError(f"no damping up to {_ZETA_CAP:g} reaches e_n = {target:g}")
    return brentq(lambda z: fun(z) - target, lo, hi, xtol=1e-10, rtol=1e-10)


def check_target_memory(n_points: int, n_targets: int = 1, what: str | None = None) -> None:
    """ValueError naming the request when the curves of ``n_targets`` targets at ``n_points``
    points each cannot fit in this machine's memory (:func:`microimpact.io.resources.check_memory`):
    six float64 values per point (the two curves, their Dataset, their table), before any solve.

    Examples
    --------
    >>> check_target_memory(41)
    """
    check_memory(what or f"n_points = {n_points} for {n_targets} target(s)", 6 * 8.0 * n_points * n_targets)


def _curve(e_n, speed, target, n_points, deadline=None, which=1):
    """(zeta_H, zeta_A) arrays of the curve e_n(speed; zeta_H, zeta_A) = target."""
    undamped = e_n(speed, 0.0, 0.0)
    if undamped <= target:  # damping only lowers e_n: a target at or above the undamped e_n has no curve
        why = ("the sphere is captured there even without damping" if undamped == 0.0
               else "damping only lowers e_n")
        raise ValueError(f"target {which}: e_n = {target:g} cannot be reached at v_n = {speed:g} m/s: without "
                         f"damping e_n = {undamped:.4g} there and {why}; reachable: 0 < e_n < {undamped:.4g}"
                         + (" (a higher speed, above the capture velocity)" if undamped == 0.0 else ""))
    za_max = _root(lambda za: e_n(speed, 0.0, za), 0.0, target)
    zh_max = _root(lambda zh: e_n(speed, zh, 0.0), 0.0, target)
    for got in (e_n(speed, 0.0, za_max), e_n(speed, zh_max, 0.0)):
        if abs(got - target) > 1e-6:  # the root is a jump of e_n (capture), not a crossing
            raise ValueError(f"target {which}: e_n = {target:g} cannot be reached at v_n = {speed:g} m/s: e_n jumps "
                             f"from {undamped:.4g} to 0 there as damping grows (the sphere is captured as soon as it "
                             "loses energy: the speed is below the capture velocity); give a higher speed")
    za = za_max * (1.0 - np.cos(np.linspace(0.0, math.pi / 2, n_points)))  # denser near zeta_A = 0, where zeta_H turns
    za[-1] = za_max
    zh = np.empty(n_points)
    zh[0], zh[-1] = zh_max, 0.0

    for j in range(1, n_points - 1):
        g = lambda z: e_n(speed, z, za[j]) - target  # noqa: E731 - decreasing in z
        try:
            zh[j] = brentq(g, 0.0, zh_max, xtol=1e-10, rtol=1e-10)
        except ValueError:
            # at the ends of a very fine curve (zeta_A within the solver tolerance of 0 or of its
            # maximum) round-off can give both ends one sign: the point is then that end
            zh[j] = 0.0 if g(0.0) <= 0.0 else zh_max
        if deadline is not None:
            deadline.check(f"{j + 1} of {n_points} points of the curve of target {which}")
    return zh, za


def damping_from_target(e_n, speed, material, *, radius: float | None = None, e_n_uncertainty=None,
                        n_points: int = 41, rtol: float = DEFAULT_RTOL, time_budget=None) -> DampingTarget:
    """The zeta_H, zeta_A that reproduce measured e_n at given normal speeds (module docstring).

    Parameters
    ----------
    e_n : float or array_like
        Target normal coefficient(s) of restitution, each in (0, 1). [1]
    speed : float or array_like
        Incident normal speed of each target, > 0. [m/s]
    material : Contact, MaterialPair or DampingFit
        Density, stiffness, w_A (f0 from Eq. (7) at ``radius``) and the damping reference speed.
    radius : float, optional
        Sphere radius [m]; default the Contact's radius (required for other materials).
    e_n_uncertainty : float or array_like, optional
        Standard uncertainties of the targets (weights of the least-squares point). [1]
    n_points : int
        Points per curve (>= 3).
    rtol : float
        Relative tolerance of the normal solves. [-]
    time_budget : float, optional
        Wall-clock limit [s], checked after every curve point
        (:class:`~microimpact.solvers.TimeBudgetExceeded` when spent).

    Returns
    -------
    DampingTarget

    Raises
    ------
    ValueError
        For an e_n outside (0, 1), a speed <= 0, mismatched lengths, or no radius; and for an e_n
        that no damping reaches at its speed (at or above the undamped e_n, e.g. below the capture
        velocity), naming the target and the reachable range.

    Examples
    --------
    Two restitution coefficients simulated with the 1990 wall sphere's Table 1 damping
    (zeta_H = 0.5, zeta_A = 29) give that damping back (two targets, two unknowns: exact):

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.solvers.impact import simulate_impact
    >>> speeds = [2.0, 5.0]
    >>> e_n = [simulate_impact(WALL_1990, v).e_n for v in speeds]
    >>> target = damping_from_target(e_n, speeds, WALL_1990, n_points=9)
    >>> round(target.best["zeta_hertz"], 8), round(target.best["zeta_adhesion"], 8)
    (0.5, 29.0)
    >>> target
    DampingTarget(2 target(s), 9 curve points, exact(zeta_hertz=0.5, zeta_adhesion=29))
    """
    deadline = Deadline.start(time_budget, "target")
    e = np.atleast_1d(np.asarray(e_n, dtype=float))
    v = np.atleast_1d(np.asarray(speed, dtype=float))
    if e.shape != v.shape:
        raise ValueError(f"e_n and speed must have the same length, got {e.size} and {v.size}")
    for i in range(e.size):
        if not (np.isfinite(e[i]) and 0.0 < e[i] < 1.0):
            raise ValueError(f"target {i + 1}: e_n = {float(e[i])!r} must lie in (0, 1) (e_n = 1 needs no damping; "
                             "e_n = 0 is any capture)")
        if not (np.isfinite(v[i]) and v[i] > 0.0):
            raise ValueError(f"target {i + 1}: speed = {float(v[i])!r} m/s must be finite and > 0")
    if n_points < 3:
        raise ValueError(f"n_points must be >= 3, got {n_points}")
    check_target_memory(n_points, e.size)
    r = float(radius if radius is not None else getattr(material, "radius", math.nan))
    if not (math.isfinite(r) and r > 0):
        raise ValueError("give the sphere radius (radius=..., or a Contact that has one)")
    se = (np.full(e.size, np.nan) if e_n_uncertainty is None
          else np.broadcast_to(np.asarray(e_n_uncertainty, dtype=float), e.shape).copy())

    model = _model(material, r, rtol)
    zh = np.empty((e.size, n_points))
    za = np.empty((e.size, n_points))
    with engine_threads(1):  # hundreds of one-speed solves
        for i in range(e.size):
            zh[i], za[i] = _curve(model, v[i], e[i], n_points, deadline, i + 1)
    curves = xr.Dataset(
        {"zeta_hertz": (("target", "curve_point"), zh, {"units": "1", "long_name": "zeta_H on the curve that "
                                                        "reproduces the target e_n, Eq. (15)"}),
         "zeta_adhesion": (("target", "curve_point"), za, {"units": "1", "long_name": "zeta_A on the curve that "
                                                           "reproduces the target e_n, Eq. (14)"})},
        coords={"target": ("target", np.arange(1, e.size + 1), {"long_name": "target number"}),
                "curve_point": ("curve_point", np.arange(n_points), {"long_name": "point along the curve"})})
    targets = pd.DataFrame({"speed": v, "e_n": e, "e_n_uncertainty": se, "radius": np.full(e.size, r)})
    best = stderr = None
    info = {"rtol": float(rtol), "material": type(material).__name__}
    if e.size >= 2:
        best, stderr, info["chisqr"] = _least_squares(material, targets, zh, za, rtol)
    return DampingTarget(targets=targets, curves=curves, best=best, stderr=stderr, info=info)


def _least_squares(material, targets, zh, za, rtol):
    """Least-squares (zeta_H, zeta_A) over the targets, from the point of the first curve closest to
    the others; returns (values, standard errors, chi-square)."""
    prob = FitProblem.from_arrays(targets["radius"], targets["speed"], material)
    se = targets["e_n_uncertainty"].to_numpy()
    sigma = se if np.all(np.isfinite(se) & (se > 0)) else None
    params = lmfit.Parameters()
    mid = zh.shape[1] // 2
    params.add("zeta_hertz", value=max(float(zh[0, mid]), 1e-6), min=0.0)
    params.add("zeta_adhesion", value=max(float(za[0, mid]), 1e-6), min=0.0)
    params.add("work_of_adhesion", value=float(material.work_of_adhesion), vary=False)
    res = lmfit.minimize(damping_residual, params, args=(prob,), kws={"e_n": targets["e_n"].to_numpy(), "sigma": sigma,
                                                                      "rtol": rtol},
                         method="leastsq", scale_covar=sigma is None)
    names = ("zeta_hertz", "zeta_adhesion")
    err = {k: float(res.params[k].stderr) if res.params[k].stderr is not None else math.nan for k in names}
    return {k: float(res.params[k].value) for k in names}, err, float(res.chisqr)
