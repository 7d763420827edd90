"""Posterior of the fitted parameters by MCMC (emcee), run until it converges, and what it implies.

:func:`sample_posterior` samples (zeta_H, zeta_A[, w_A][, friction]) with emcee's ensemble sampler
(Foreman-Mackey et al. 2013, doi:10.1086/670067), from walkers started in a small ball around the
least-squares fit, seeded (``seed``): the same inputs give the same chain. Priors are flat within
:func:`prior_bounds` (the ranges the least-squares fits search); the posterior's attributes state
them. Moves: a mixture of differential-evolution moves (80 %) and their snooker variant (20 %),
which the emcee documentation recommends for correlated, low-dimensional posteriors; on the
bundled data they reach the 50-tau rule in fewer steps than the default stretch move.

Likelihood
----------
Normal part: each measured e_n is Gaussian about the model e_n(v_n) of Eq. (21) with the measured
uncertainty (``likelihood="normal"``), or Student-t with ``nu`` degrees of freedom and that
uncertainty as its scale (``likelihood="student-t"``; Lange, Little & Taylor 1989,
doi:10.1080/01621459.1989.10478852): log p = -(nu + 1)/2 log(1 + z^2/nu) per row, whose tails let a
gross outlier pull the posterior by a bounded amount. On clean data the Student-t posterior is wider
than the normal one by about sqrt((nu + 3)/(nu + 1)) (its Fisher information per row is
(nu + 1)/(nu + 3) of the normal's), 1.18 at the default nu = 4. The oblique rows stay normal. The incident speed is itself measured (errors in variables), handled per row:

* **effective variance** (Orear 1982, doi:10.1119/1.12972) where the model is close to linear over
  the speed uncertainty: sigma^2 = sigma_e^2 + (de/dv)^2 sigma_v^2, the slope at the best fit;
* **latent true speed, integrated out** where it is not: near the capture velocity e_n rises like
  the square root of the distance to it, and the tangent line misstates the likelihood (a speed
  draw below capture gives e_n = 0). There the row's likelihood is
  int N(e | e_model(u), sigma_e) N(u | v, sigma_v) du, by 9-point Gauss-Hermite quadrature (exact for
  a model polynomial of degree <= 17 in u; the latent speeds are marginalised, not sampled, so the
  walkers keep 2-4 dimensions). ``errors_in_variables="auto"`` picks the latent form for rows where
  the second-order term at +/- 2 sigma_v exceeds a quarter of sigma_eff, or where v_n - 3 sigma_v
  falls below the capture velocity; ``"effective"`` or ``"latent"`` force one form for every row.

The incidence-angle uncertainty enters v_n = v cos(alpha) through the reader's propagated
``normal_speed_uncertainty`` (first order; at alpha = 0 the second-order bias, v sigma_alpha^2 / 2, is
below 2e-4 v for sigma_alpha <= 1 deg and is neglected). Tangential part (with a friction fit): the
oblique entries with the effective variance of :mod:`microimpact.analysis.oblique`.

Verdict: the posterior carries the verdict of the least-squares fit it starts from
(:class:`~microimpact.analysis.verdict.Verdict`: ``verdict``, ``verdict_text``, ``p_value``); where
that fit's model is rejected, the posterior is conditional on a rejected model and says so.

Convergence: the chain runs in chunks of :data:`CHECK_EVERY` steps until the post-burn-in chain is
longer than :data:`TAU_FACTOR` integrated autocorrelation times (emcee's guidance) with a stable
estimate of tau, the rank-normalised split R-hat of every parameter (walkers as chains) is below
1.01 and its bulk effective sample size at least 400 (Vehtari et al. 2021, doi:10.1214/20-BA1221;
:mod:`microimpact.analysis.diagnostics`), or its budget (:data:`DEFAULT_MAX_STEPS`, the time
budget) is spent. A chain that collapses or does not converge raises :class:`PosteriorError`: no
posterior is returned, written or reported. A parameter the least-squares fit finds undetermined
(a one-sided bound, or nothing) is reported from the fit's profile bound, since the posterior beyond
it is the prior's (:meth:`Posterior.bound`).

The walkers of one emcee step are evaluated together (``vectorize=True``): with the emulator
(``method="emulator"``) their e_n is one table lookup, and the impacts the table leaves to the
solver, like the normal solves of the oblique rows, are one engine call over the groups of all
walkers (:mod:`microimpact.solvers.ring_groups_batch`); with ``method="solve"`` each walker's e_n
goes through :func:`microimpact.solvers.engine.solve_normal_many`.
"""

from __future__ import annotations

import logging
import math
import numbers
import time
import warnings
from dataclasses import dataclass, field

import emcee
import numpy as np
import pandas as pd
import xarray as xr

from microimpact._runtime.signals import interrupt_at_checkpoints
from microimpact.analysis.diagnostics import ESS_MIN, RHAT_MAX, ess_bulk, split_rhat
from microimpact.analysis.fitting import DAMPING_RANGES, FitProblem, model_restitution
from microimpact.analysis import speed_curves
from microimpact.analysis.oblique import ObliqueProblem, _observables, oblique_model, rebound_from_impulses
from microimpact.dynamics.nonlinear import capture_velocity
from microimpact.io.formatting import ReportHTML
from microimpact.analysis.fit_result import PARAMETER_NAMES, FitResult
from microimpact.analysis.sampling_defaults import (DEFAULT_MAX_STEPS, DEFAULT_N_DRAWS, DEFAULT_NU, DEFAULT_SEED,
                                                    DEFAULT_METHOD, DEFAULT_WALKERS, LIKELIHOODS, MAX_SEED,
                                                    METHODS)
from microimpact.io.files import CONVENTIONS, restore_label_coordinates
from microimpact.io.materials import material_contact
from microimpact._runtime.progress import progress_bar
from microimpact.io.resources import check_memory
from microimpact.model.parameters import TABLE2_CASES
from microimpact.solvers import DEFAULT_RTOL, Deadline, engine, engine_threads
from microimpact.solvers.impact import simulate_many
from microimpact.model import reduction
from microimpact.solvers import emulator, ring_groups_batch

__all__ = ["Posterior", "PosteriorError", "sample_posterior", "prior_bounds", "DEFAULT_WALKERS", "DEFAULT_MAX_STEPS",
           "DEFAULT_SEED", "DEFAULT_N_DRAWS", "posterior_contacts", "restitution_bands", "capture_velocity_interval",
           "sweep_bands", "summary_table", "PARAMETER_UNITS", "EIV_METHODS", "GAUSS_HERMITE_NODES", "LIKELIHOODS",
           "DEFAULT_NU", "CONDITIONAL_ON_REJECTED", "METHODS", "DEFAULT_METHOD", "EMULATOR_TOLERANCE"]

#: absolute e_n tolerance of the emulator in the likelihood: far below the data's noise (stated e_n
#: uncertainties ~5e-3), so that 100 rows move the log-likelihood by at most ~100 x 1e-6 / 5e-3 = 0.02
#: (a shift of the posterior far below its Monte Carlo error), and a table that builds in
#: seconds to a minute on a cold cache where 1e-8 takes minutes
EMULATOR_TOLERANCE = 1e-6
#: the emulator's box of groups for the posterior (a table shipped with the package): the table's
#: default box with C2 down to 0.03, so that the bundled data's fastest impacts are in it rather
#: than solved at every evaluation
POSTERIOR_DOMAIN = emulator.WIDE_DOMAIN

#: what a posterior of a rejected model says of itself
CONDITIONAL_ON_REJECTED = "conditional on a rejected model"

#: the title of every posterior file (a sampled one adds how it was sampled)
POSTERIOR_TITLE = "posterior of the fitted parameters"

#: units of the sampled parameters
PARAMETER_UNITS = {"zeta_hertz": "1", "zeta_adhesion": "1", "work_of_adhesion": "J m-2", "friction": "1"}
#: errors-in-variables treatments of the measured speed
EIV_METHODS = ("auto", "effective", "latent")
#: Gauss-Hermite nodes of the latent-speed integral
GAUSS_HERMITE_NODES = 9
#: quantiles stored in summaries and bands (2.5 %, 16 %, 50 %, 84 %, 97.5 %)
QUANTILES = (0.025, 0.16, 0.5, 0.84, 0.975)


@dataclass(frozen=True, eq=False)
class Posterior(ReportHTML, FitResult):
    """An MCMC sample of the fitted parameters.

    Attributes
    ----------
    names : tuple of str
        Sampled parameters (subset of :data:`PARAMETER_UNITS`).
    chain : numpy.ndarray
        Full chain, shape (steps, walkers, parameters), in the parameters' units.
    log_probability : numpy.ndarray
        Log posterior of each chain point, shape (steps, walkers).
    burn : int
        Steps discarded as burn-in.
    fixed : dict
        Parameters held fixed (e.g. w_A when not fitted, the friction of the material).
    autocorr_time : dict
        Integrated autocorrelation time of each parameter. [steps]
    acceptance_fraction : numpy.ndarray
        Per walker. [-]
    seed : int
    info : dict
        ``errors_in_variables``, ``latent_rows`` (CSV rows with the latent-speed likelihood),
        ``elapsed_s``, ``converged`` (bool), ``convergence`` (text), ``source``.

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> post.names, post.converged
    (('zeta_hertz', 'zeta_adhesion'), False)

    The chain survives its file; a file of another kind is refused, naming it:

    >>> Posterior.load(post.save("posterior.nc"))
    Posterior(zeta_hertz, zeta_adhesion; 8 walkers x 60 steps, burn-in 20, seed 2002, converged=False)
    >>> Posterior.load(fit.save("fit.nc"))
    Traceback (most recent call last):
    ...
    ValueError: fit.nc: not a posterior (the file that 'microimpact fit --posterior' writes): it is a NetCDF file titled 'damping fit ...'
    """

    TITLE = POSTERIOR_TITLE
    KIND = "posterior"
    WRITTEN_BY = "microimpact fit --posterior"

    names: tuple
    chain: np.ndarray
    log_probability: np.ndarray
    burn: int
    fixed: dict
    autocorr_time: dict
    acceptance_fraction: np.ndarray
    seed: int
    info: dict = field(default_factory=dict)

    @property
    def samples(self) -> np.ndarray:
        """Post-burn-in samples, flattened: shape (n, parameters)."""
        return self.chain[self.burn:].reshape(-1, len(self.names))

    def interval(self, name: str, level: float = 0.95) -> tuple[float, float]:
        """Equal-tailed credible interval of ``name`` at ``level`` (e.g. 0.95)."""
        x = self.samples[:, self.names.index(name)]
        lo, hi = np.quantile(x, [(1 - level) / 2, (1 + level) / 2])
        return float(lo), float(hi)

    def median(self) -> dict:
        """Posterior median of each sampled parameter, plus the fixed ones."""
        return {n: float(np.median(self.samples[:, i])) for i, n in enumerate(self.names)} | dict(self.fixed)

    def draws(self, n: int, seed: int | None = None) -> list[dict]:
        """``n`` parameter sets drawn from the post-burn-in samples (seeded), fixed ones included."""
        s = self.samples
        rng = np.random.default_rng(self.seed if seed is None else seed)
        idx = rng.choice(s.shape[0], size=min(n, s.shape[0]), replace=False)
        return [dict(zip(self.names, map(float, s[i]))) | dict(self.fixed) for i in idx]

    def bound(self, name: str) -> str:
        """'' where the data determine ``name``; else what the data say of it, in words.

        Whether a parameter is determined is decided by the least-squares fit's identifiability
        (``info["status"]``, ``info["bounds"]``, from :mod:`microimpact.analysis.identifiability`).
        Where the data only bound it from one side, the posterior beyond that bound is the flat
        prior's: its quantiles (a median, a two-sided interval, even a one-sided 5 % quantile, which
        moves with the prior's arbitrary end) would report the prior. The bound the likelihood gives
        (the fit's 95 % profile bound) is reported instead, and the posterior is said to follow the
        prior beyond it.
        """
        status = self.info.get("status", {}).get(name, "determined")
        a, b = self.info.get("priors", {}).get(name, (-math.inf, math.inf))
        lo, hi = self.info.get("bounds", {}).get(name, (a, b))
        if status == "lower_bound":
            return f">= {lo:.4g} (95 % profile-likelihood bound of the fit; above it the posterior follows the flat prior up to {b:.4g})"
        if status == "upper_bound":
            return f"<= {hi:.4g} (95 % profile-likelihood bound of the fit; below it the posterior follows the flat prior down to {a:.4g})"
        if status == "not_determined":
            return f"not determined by these data (the posterior follows the flat prior on [{a:.4g}, {b:.4g}])"
        return ""

    @property
    def converged(self) -> bool:
        """Post-burn-in chain longer than 50 autocorrelation times."""
        return bool(self.info.get("converged", False))

    def __repr__(self) -> str:
        steps, walkers, _ = self.chain.shape
        return (f"Posterior({', '.join(self.names)}; {walkers} walkers x {steps} steps, burn-in {self.burn}, "
                f"seed {self.seed}, converged={self.converged})")

    def report(self) -> str:
        """Plain-text summary: medians, 95 % intervals, autocorrelation, acceptance."""
        steps, walkers, _ = self.chain.shape
        lines = [f"Posterior (emcee, {walkers} walkers x {steps} steps, burn-in {self.burn}, seed {self.seed})"]
        rhat, ess = self.info.get("rhat", {}), self.info.get("ess_bulk", {})
        priors = self.info.get("priors", {})
        for i, n in enumerate(self.names):
            lo, hi = self.interval(n)
            diag = f"tau {self.autocorr_time[n]:.1f} steps" + (f", R-hat {rhat[n]:.4f}, ESS {ess[n]:.0f}" if n in rhat else "")
            bound = self.bound(n)
            if bound:
                lines.append(f"  {n:<17}: {bound} [{PARAMETER_UNITS[n]}]  {diag}")
            else:
                lines.append(f"  {n:<17}= {np.median(self.samples[:, i]):.6g}  95 % [{lo:.6g}, {hi:.6g}] "
                             f"[{PARAMETER_UNITS[n]}]  {diag}")
        if priors:
            lines.append("  priors      : flat, " + ", ".join(f"{n} in [{a:.4g}, {b:.4g}]" for n, (a, b) in priors.items()))
        af = self.acceptance_fraction
        lines.append(f"  acceptance  : mean {af.mean():.3f} (walkers {af.min():.3f}-{af.max():.3f})")
        lines.append(f"  convergence : {self.info.get('convergence', '')}")
        lines.append(f"  speed errors: {self.info.get('errors_in_variables', '')}")
        lines.append(f"  likelihood  : {self.info.get('likelihood', 'normal')}")
        if self.info.get("verdict"):
            lines.append(f"  verdict     : {self.verdict_statement()}")
        return "\n".join(lines)

    @property
    def rejected(self) -> bool:
        """True where the least-squares fit the posterior starts from has its model rejected."""
        return self.info.get("verdict") == "inadequate"

    def verdict_statement(self) -> str:
        """The fit's verdict as the posterior states it ("conditional on a rejected model" where rejected)."""
        text = str(self.info.get("verdict_text", ""))
        if self.rejected:
            return f"the fit's model is rejected ({text}): this posterior is {CONDITIONAL_ON_REJECTED}"
        return f"the fit's: {text}" if text else ""


    # ------------------------------------------------------------------ NetCDF
    def to_dataset(self, *extra: xr.Dataset) -> xr.Dataset:
        """The chain, its summary and diagnostics (and any band Datasets ``extra``) as one CF Dataset.

        Variables: ``chain_<name>(step, walker)``, ``log_probability(step, walker)``,
        ``<name>_quantile(quantile)``, ``<name>_autocorr_time``, ``acceptance_fraction(walker)``;
        attributes ``burn_in``, ``seed``, ``converged``, ``convergence``, ``errors_in_variables``,
        ``fixed_<name>``. ``extra``: e.g. :func:`restitution_bands`, :func:`capture_velocity_interval`,
        :func:`sweep_bands` (the posterior file of ``microimpact fit --posterior`` holds them).

        Examples
        --------
        >>> from microimpact.analysis.fitting import fit_damping
        >>> from microimpact.analysis.synthetic import write_synthetic_impacts
        >>> from microimpact.io import default_materials_path, read_impacts, read_materials
        >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
        >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
        >>> fit = fit_damping(table, material, confidence_intervals=False)
        >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
        >>> ds = post.to_dataset()
        >>> [v for v in ds.data_vars if v.startswith("chain_")]
        ['chain_zeta_hertz', 'chain_zeta_adhesion']
        """
        steps, walkers, _ = self.chain.shape
        ds = xr.Dataset(coords={
            "step": ("step", np.arange(steps), {"long_name": "MCMC step"}),
            "walker": ("walker", np.arange(walkers), {"long_name": "emcee walker"}),
            "quantile": ("quantile", np.array(QUANTILES), {"units": "1", "long_name": "posterior quantile"})})
        s = self.samples
        info = self.info
        for i, n in enumerate(self.names):
            u = PARAMETER_UNITS[n]
            prior = info.get("priors", {}).get(n, (math.nan, math.nan))
            bounds = info.get("bounds", {}).get(n, (math.nan, math.nan))
            ds[f"chain_{n}"] = (("step", "walker"), self.chain[:, :, i], {
                "units": u, "long_name": f"MCMC chain of {n}", "prior": "flat", "prior_min": float(prior[0]),
                "prior_max": float(prior[1]), "status": info.get("status", {}).get(n, "determined"),
                "fit_bound_lower": float(bounds[0]), "fit_bound_upper": float(bounds[1]),
                "rhat": float(info.get("rhat", {}).get(n, math.nan)),
                "ess_bulk": float(info.get("ess_bulk", {}).get(n, math.nan)),
                "statement": self.bound(n) or "determined by the data"})
            ds[f"{n}_quantile"] = ("quantile", np.quantile(s[:, i], QUANTILES), {
                "units": u, "long_name": f"posterior quantiles of {n} (after burn-in)"})
            ds[f"{n}_autocorr_time"] = ((), self.autocorr_time[n], {
                "units": "1", "long_name": f"integrated autocorrelation time of {n} in steps"})
        ds["log_probability"] = (("step", "walker"), self.log_probability, {
            "units": "1", "long_name": "log posterior probability (up to a constant)"})
        ds["acceptance_fraction"] = ("walker", self.acceptance_fraction, {
            "units": "1", "long_name": "fraction of accepted proposals per walker"})
        for e in extra:
            ds = ds.merge(e, combine_attrs="drop_conflicts")
        ds.attrs.update({
            "title": f"{POSTERIOR_TITLE} (emcee, run until converged)", "Conventions": CONVENTIONS,
            "sampled": " ".join(self.names), "burn_in": int(self.burn), "seed": int(self.seed),
            "converged": int(self.converged), "convergence": str(info.get("convergence", "")),
            "errors_in_variables": str(info.get("errors_in_variables", "")),
            "latent_speed_rows": " ".join(map(str, info.get("latent_rows", ()))),
            "source": str(info.get("source", "")),
            "likelihood": str(info.get("likelihood", "normal")),
            **{k: info[k] for k in ("verdict", "verdict_text", "p_value", "student_t_nu") if k in info},
            **({"comment": f"this posterior is {CONDITIONAL_ON_REJECTED} ({info.get('verdict_text', '')})"}
               if self.rejected else {}),
            **({"moves": str(info["moves"])} if "moves" in info else {}),
            **({"likelihood_method": str(info["method"])} if "method" in info else {}),
            **({"elapsed_s": float(info["elapsed_s"])} if "elapsed_s" in info else {}),
            **{f"fixed_{k}": float(v) for k, v in self.fixed.items()}})
        return ds

    @classmethod
    def from_dataset(cls, ds: xr.Dataset) -> "Posterior":
        """Inverse of :meth:`to_dataset` (the chain part; also of the Dataset read back from its file).

        Examples
        --------
        >>> from microimpact.analysis.fitting import fit_damping
        >>> from microimpact.analysis.synthetic import write_synthetic_impacts
        >>> from microimpact.io import default_materials_path, read_impacts, read_materials
        >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
        >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
        >>> fit = fit_damping(table, material, confidence_intervals=False)
        >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
        >>> Posterior.from_dataset(post.to_dataset())
        Posterior(zeta_hertz, zeta_adhesion; 8 walkers x 60 steps, burn-in 20, seed 2002, converged=False)
        """
        ds = restore_label_coordinates(ds)
        a = ds.attrs
        names = tuple(str(a["sampled"]).split())
        chain = np.stack([ds[f"chain_{n}"].values for n in names], axis=-1)
        fixed = {k.removeprefix("fixed_"): float(v) for k, v in a.items() if k.startswith("fixed_")}
        per = {n: ds[f"chain_{n}"].attrs for n in names}
        extra = {}
        if all("prior_min" in v for v in per.values()):
            extra = {"priors": {n: (float(v["prior_min"]), float(v["prior_max"])) for n, v in per.items()},
                     "status": {n: str(v["status"]) for n, v in per.items()},
                     "bounds": {n: (float(v["fit_bound_lower"]), float(v["fit_bound_upper"])) for n, v in per.items()},
                     "rhat": {n: float(v["rhat"]) for n, v in per.items()},
                     "ess_bulk": {n: float(v["ess_bulk"]) for n, v in per.items()}}
        recorded = {"latent_rows": tuple(int(r) for r in str(a.get("latent_speed_rows", "")).split()),
                    "source": str(a.get("source", ""))}
        if "likelihood_method" in a:
            recorded["method"] = str(a["likelihood_method"])
        recorded |= {k: f(a[k]) for k, f in (("moves", str), ("elapsed_s", float), ("likelihood", str),
                                             ("verdict", str), ("verdict_text", str), ("p_value", float),
                                             ("student_t_nu", float)) if k in a}
        return cls(names=names, chain=chain, log_probability=ds["log_probability"].values, burn=int(a["burn_in"]),
                   fixed=fixed, autocorr_time={n: float(ds[f"{n}_autocorr_time"]) for n in names},
                   acceptance_fraction=ds["acceptance_fraction"].values, seed=int(a["seed"]),
                   info={"converged": bool(int(a["converged"])), "convergence": str(a.get("convergence", "")),
                         "errors_in_variables": str(a.get("errors_in_variables", ""))} | recorded | extra)

# =============================================================================== likelihood
class _Likelihood:
    """log p(data | parameters): the normal part (effective variance or latent speed per row) and
    the tangential part. Each evaluation: one model_restitution call (one engine call per radius)
    and, with oblique data, one simulate_many call per radius."""

    def __init__(self, damping_fit, table, friction_fit, eiv, rtol, likelihood="normal", nu=DEFAULT_NU,
                 method="solve", tol=EMULATOR_TOLERANCE):
        if method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
        self.method, self.tol, self._groups = method, float(tol), {}
        self.domain = POSTERIOR_DOMAIN  # the emulator's box of groups (tests give a small one)
        if likelihood not in LIKELIHOODS:
            raise ValueError(f"likelihood must be one of {', '.join(LIKELIHOODS)}, got {likelihood!r}")
        if not (isinstance(nu, numbers.Real) and math.isfinite(nu) and nu > 0):
            raise ValueError(f"nu (the Student-t degrees of freedom) must be a finite number > 0, got {nu!r}")
        self.fit, self.rtol, self.student, self.nu = damping_fit, rtol, likelihood == "student-t", float(nu)
        d = damping_fit.data
        e, v, r = (d[c].to_numpy(dtype=float) for c in ("e_n", "normal_speed", "radius"))
        sig = d["sigma"].to_numpy(dtype=float)
        if not np.all(np.isfinite(sig)):  # unweighted fit: the residual scatter is the uncertainty
            sig = np.full(e.size, math.sqrt(damping_fit.chisqr / max(damping_fit.n_points - len(damping_fit.varied), 1)))
        sig_e, sig_v = self._stated(table, d, sig)
        latent = self._latent_rows(eiv, r, v, sig, sig_v, FitProblem)
        x, w = np.polynomial.hermite.hermgauss(GAUSS_HERMITE_NODES)
        self.e, self.sig_eff, self.sig_e = e, sig, sig_e
        self.latent = latent
        self.weights = w / math.sqrt(math.pi)
        li = np.flatnonzero(latent)
        speeds = np.concatenate([v[~latent], (v[li, None] + math.sqrt(2.0) * sig_v[li, None] * x[None, :]).ravel()])
        radii = np.concatenate([r[~latent], np.repeat(r[li], x.size)])
        self.n_plain = int((~latent).sum())
        self.problem = FitProblem.from_arrays(radii, np.maximum(speeds, 1e-12), damping_fit)
        self.latent_rows = d["row"].to_numpy()[li]
        self.oblique = None
        if friction_fit is not None:
            self.oblique = ObliqueProblem.from_table(table)
            self.oblique_sigma = friction_fit.data["sigma"].to_numpy(dtype=float)

    @staticmethod
    def _stated(table, d, sig):
        """(sigma_e, sigma_v) of the fitted rows: stated e_n and normal-speed uncertainties (0 if absent)."""
        if table is not None and "row" in table.columns:
            t = table.set_index("row")
            se = d["row"].map(t["e_n_uncertainty"]).to_numpy(dtype=float)
            sv = d["row"].map(t["normal_speed_uncertainty"]).to_numpy(dtype=float)
        else:
            se, sv = np.full(len(d), np.nan), np.full(len(d), np.nan)
        se = np.where(np.isfinite(se) & (se > 0), se, sig)
        return se, np.nan_to_num(sv)

    def _latent_rows(self, eiv, r, v, sig, sig_v, FitProblem):
        """Which rows get the latent-speed likelihood (module docstring)."""
        if eiv not in EIV_METHODS:
            raise ValueError(f"errors_in_variables must be one of {', '.join(EIV_METHODS)}, got {eiv!r}")
        has = sig_v > 0
        if eiv != "auto":
            return has & (eiv == "latent")

        p = self.fit.values
        ev = [model_restitution(FitProblem.from_arrays(r, np.maximum(v + k * 2 * sig_v, 1e-12), self.fit), p["zeta_hertz"],
                                p["zeta_adhesion"], p["work_of_adhesion"], rtol=self.rtol) for k in (-1, 0, 1)]
        curvature = np.abs(ev[0] + ev[2] - 2 * ev[1]) / 2
        v_cap = {float(rr): capture_velocity(self.fit.contact(float(rr))) for rr in np.unique(r)}
        near = v - 3 * sig_v < np.array([v_cap[float(rr)] for rr in r])
        return has & ((curvature > 0.25 * sig) | near)

    def model(self, p: dict) -> np.ndarray:
        """Model e_n at the likelihood's speeds (plain rows, then the latent rows' nodes). [-]"""
        return self.model_many({n: np.array([float(p[n])]) for n in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion")})[0]

    def model_many(self, p: dict) -> np.ndarray:
        """:meth:`model` of K parameter sets at once: ``p`` maps zeta_hertz, zeta_adhesion and
        work_of_adhesion to arrays of shape (K,); e_n of shape (K, speeds). [-]"""
        zh, za, wa = (np.asarray(p[n], dtype=float).ravel() for n in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion"))
        g = self._speed_groups_many(wa) if self.method == "emulator" else None
        if g is None:  # the solver (method "solve", or not the ring law): one model evaluation per set
            return np.array([model_restitution(self.problem, a, b, w, rtol=self.rtol) for a, b, w in zip(zh, za, wa)])
        return self._emulated(zh, za, wa, *g)

    def _speed_groups(self, work_of_adhesion):
        """(y0, C1 / zeta_H = C2 / zeta_A) of every speed at ``work_of_adhesion``, or None where a
        radius's law is not the ring law. The groups are linear in the zetas (Eqs. (14)-(15),
        :func:`microimpact.model.reduction.ring_groups`): computed once per w_A, they make an
        evaluation one table lookup without building a Contact."""
        key = float(work_of_adhesion)
        if key not in self._groups:
            pr = self.problem
            y0, per = np.empty(pr.normal_speed.size), np.empty(pr.normal_speed.size)
            ok = True
            for r, idx in zip(pr.radii, pr.groups):
                c = pr.contact(r, 1.0, 1.0, key)
                ok = ok and reduction.law_of(c) == "ring"
                if ok:
                    y, per_speed, _ = reduction.ring_groups([c], pr.normal_speed[idx][None, :])
                    y0[idx], per[idx] = y[0], per_speed[0]
            self._groups = {key: (y0, per) if ok else None}  # one w_A at a time: a fitted w_A moves every call
        return self._groups[key]

    def _speed_groups_many(self, work_of_adhesion):
        """(y0, C1 / zeta_H) of every speed for each w_A of the array ``work_of_adhesion`` (K,),
        shape (K, speeds), or None where the law is not the ring law (or a w_A is not > 0).

        From the groups at the fit's w_A by their powers of w_A (:func:`_groups_at_work_of_adhesion`):
        a contact per walker would cost more than the table lookup itself;
        tests/test_posterior_speed.py compares these groups with the contacts' own."""
        w = np.asarray(work_of_adhesion, dtype=float).ravel()
        w_ref = float(self.fit.values["work_of_adhesion"])
        if not (w_ref > 0.0 and np.all(w > 0.0)):
            return None
        g = self._speed_groups(w_ref)
        if g is None:
            return None
        return _groups_at_work_of_adhesion(g[0], g[1], (w / w_ref)[:, None])

    def _emulated(self, zeta_hertz, zeta_adhesion, work_of_adhesion, y0, per) -> np.ndarray:
        """e_n (K, speeds) by the table where it meets ``tol``, by the emulator's fallback solves
        elsewhere (all parameter sets in one engine call). [-]"""
        if getattr(self, "_table", None) is None:  # looked up once: the lookup hashes the physics' source
            self._table = emulator.ring_emulator(emulator.table_tolerance(self.tol), self.domain)
        c1, c2 = zeta_hertz[:, None] * per, zeta_adhesion[:, None] * per
        e, _, solve = self._table.evaluate(y0, c1, c2, self.tol)
        e = np.array(e, dtype=float)
        if solve.any():
            # every walker's fallback impacts in one engine call, from their groups (the impacts of
            # many contacts: ring_groups_batch); the tolerances of emulator.fallback_restitution
            with engine_threads(1):
                e[solve] = ring_groups_batch.fallback_of_groups(y0[solve], c1[solve], c2[solve], self.tol)
        return e

    def __call__(self, p: dict) -> float:
        return float(self.many({n: np.array([float(v)]) for n, v in p.items()})[0])

    def many(self, p: dict) -> np.ndarray:
        """log p(data | parameters) of K parameter sets: ``p`` maps every parameter name to an
        array of shape (K,) (the walkers of one emcee step, ``vectorize=True``). [-]

        The plain rows of a radius with a certified speed curve (:meth:`_curves`,
        :mod:`microimpact.analysis.speed_curves`) take their model from it; every other row, and
        every walker whose curve misses its tolerance, takes the per-row model (:meth:`model_many`)."""
        curves = self._curves()
        if curves is None:
            m = self.model_many(p)
            plain = ~self.latent
            logl = np.sum(self.log_density((m[:, : self.n_plain] - self.e[plain]) / self.sig_eff[plain]), axis=1)
            ml = m[:, self.n_plain:]
        else:
            logl, ml = self._by_curves(curves, p)
        if self.latent.any():
            k = GAUSS_HERMITE_NODES
            ml = ml.reshape(ml.shape[0], -1, k)
            e, s = self.e[self.latent, None], self.sig_e[self.latent, None]
            like = (np.exp(self.log_density((ml - e) / s)) * self.weights).sum(axis=2)
            logl += np.sum(np.log(np.maximum(like, 1e-300)), axis=1)
        if self.oblique is not None:
            mo = self._oblique_many(p)
            if mo is None:  # not the ring law: oblique_model per parameter set
                mo = np.array([oblique_model(self.oblique, lambda r, j=j: _contact(self.fit, r, {n: float(p[n][j]) for n in PARAMETER_NAMES}),
                                             {"friction": float(p["friction"][j])}, rtol=self.rtol) for j in range(logl.size)])
            r2 = np.nan_to_num((mo - self.oblique.measured) / self.oblique_sigma, nan=1e3)
            logl -= 0.5 * np.sum(r2 * r2, axis=1)
        return logl

    def _curves(self):
        """The speed curves of the plain rows (:class:`~microimpact.analysis.speed_curves.SpeedCurves`),
        or None: method "solve", a law other than the ring law, a w_A not > 0, or no radius with
        :data:`~microimpact.analysis.speed_curves.MIN_ROWS` rows above its capture margin. Built once."""
        if hasattr(self, "_speed_curves"):
            return self._speed_curves
        self._speed_curves = None
        w_ref = float(self.fit.values["work_of_adhesion"])
        if self.method != "emulator" or not w_ref > 0.0 or self._speed_groups(w_ref) is None:
            return None
        pr, n = self.problem, self.n_plain
        rows = [idx[idx < n] for idx in pr.groups]
        if max(idx.size for idx in rows) < speed_curves.MIN_ROWS:
            return None
        contacts = [pr.contact(r, 1.0, 1.0, w_ref) for r in pr.radii]

        def groups(i, speeds):
            y, per, _ = reduction.ring_groups([contacts[i]], speeds[None, :])
            return y[0], per[0]
        poles = [capture_velocity(self.fit.contact(float(r))) for r in pr.radii]
        ref = (self.fit.values["zeta_hertz"], self.fit.values["zeta_adhesion"])
        curves = speed_curves.SpeedCurves(pr.radii, rows, pr.normal_speed[:n], self.e[~self.latent],
                                          self.sig_eff[~self.latent], poles, groups,
                                          lambda zh, za, y0, per: self._emulated(zh, za, None, y0, per), ref,
                                          speed_curves.TOLERANCE_FACTOR * self.tol)
        if curves.n_curves:
            on = np.zeros(pr.normal_speed.size, dtype=bool)
            on[curves.curve_rows] = True
            self._speed_curves, self._rowwise = curves, np.flatnonzero(~on)
        return self._speed_curves

    def _by_curves(self, curves, p):
        """(log-likelihood of the plain rows (K,), per-row model of the latent rows' nodes (K, nodes))
        with the speed curves: the rows on no curve, and the curves that miss their check, per row."""
        zh, za, wa = (np.asarray(p[n], dtype=float).ravel() for n in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion"))
        w_ref = float(self.fit.values["work_of_adhesion"])
        s = (wa / w_ref)[:, None]
        y_ref, per_ref = self._speed_groups(w_ref)
        cols = self._rowwise
        m = self._emulated(zh, za, wa, *_groups_at_work_of_adhesion(y_ref[cols], per_ref[cols], s))
        plain = cols < self.n_plain
        e_p, sig_p = self.e[~self.latent], self.sig_eff[~self.latent]
        logl = np.sum(self.log_density((m[:, plain] - e_p[cols[plain]]) / sig_p[cols[plain]]), axis=1)
        coef, ok = curves.coefficients(zh, za, None if np.all(s == 1.0) else s)
        if self.student:
            for j, (rows, vals) in enumerate(curves.values(coef)):
                logl += np.where(ok[:, j], np.sum(self.log_density((vals - e_p[rows]) / sig_p[rows]), axis=1), 0.0)
        else:
            logl -= 0.5 * np.sum(np.where(ok, curves.sum_of_squares(coef), 0.0), axis=1)
        walker, curve = np.nonzero(~ok)
        for k, j in zip(walker, curve):  # a curve that misses its tolerance: that walker's rows, per row
            rows = curves.rows[j]
            g = _groups_at_work_of_adhesion(y_ref[rows][None, :], per_ref[rows][None, :], s[k:k + 1])
            mk = self._emulated(zh[k:k + 1], za[k:k + 1], wa[k:k + 1], *g)[0]
            logl[k] += np.sum(self.log_density((mk - e_p[rows]) / sig_p[rows]))
        return logl, m[:, ~plain]

    def _oblique_many(self, p: dict):
        """:func:`~microimpact.analysis.oblique.oblique_model` of K parameter sets, shape (K, entries),
        or None where a contact is not the ring law (or a w_A is not > 0).

        The normal solves of all sets in one engine call from their groups (the groups, X / T and X
        at each w_A by their powers of w_A, as :meth:`_speed_groups_many`), the impulses in SI units
        as :func:`~microimpact.solvers.engine.solve_normal_many` gives them (J = J' m X / T,
        J_a = J_a' m X / T sqrt(r X)), and the closed-form tangential map of each set's friction."""
        ob, w = self.oblique, np.asarray(p["work_of_adhesion"], dtype=float)
        w_ref = float(self.fit.values["work_of_adhesion"])
        setup = self._oblique_setup()
        if not (w_ref > 0.0 and np.all(w > 0.0)) or setup is None:
            return None
        k = w.size
        s = (w / w_ref)[:, None]
        out = np.empty((k, ob.size))
        for c, idx, v, alpha, vn, inverse, y_ref, per_ref in setup:
            y0, per = _groups_at_work_of_adhesion(y_ref, per_ref, s)
            sol = ring_groups_batch.outcome_of_groups(y0, np.asarray(p["zeta_hertz"])[:, None] * per,
                                                      np.asarray(p["zeta_adhesion"])[:, None] * per, rtol=self.rtol)
            ju = c.mass * c.length_scale / c.time_scale * s ** (5.0 / 6.0)  # m X / T of each set
            jt = ju * np.sqrt(c.radius * c.length_scale * s ** (2.0 / 3.0))
            impulses = {"captured": sol.captured[:, inverse].ravel(), "e_n": sol.e_n[:, inverse].ravel(),
                        "velocity_in_n": np.tile(vn, k), "velocity_in_t": np.tile(v * np.sin(alpha), k),
                        "friction_impulse": (sol.friction_impulse * ju)[:, inverse].ravel(),
                        "twist_impulse": (sol.twist_impulse * jt)[:, inverse].ravel()}
            st = rebound_from_impulses(c, impulses, np.tile(ob.spin[idx], k),
                                       friction=np.repeat(np.asarray(p["friction"], dtype=float), idx.size))
            values = _observables(st, np.tile(v, k), np.tile(ob.incidence_deg[idx], k), np.tile(ob.quantity[idx], k))
            out[:, idx] = np.where(st["captured"], np.nan, values).reshape(k, idx.size)
        return out

    def _oblique_setup(self):
        """Per radius of the oblique rows, what no walker changes: the contact at the fit's values
        (zeta_H = zeta_A = 1), the rows, their speeds and angles, the distinct normal speeds and the
        ring groups there at the fit's w_A; None where a contact is not the ring law. Built once."""
        if not hasattr(self, "_oblique_cache"):
            ob, self._oblique_cache = self.oblique, []
            for r in np.unique(ob.radius):
                idx = np.flatnonzero(ob.radius == r)
                c = _contact(self.fit, float(r), dict(self.fit.values) | {"zeta_hertz": 1.0, "zeta_adhesion": 1.0})
                if reduction.law_of(c) != "ring":
                    self._oblique_cache = None
                    break
                v, alpha = ob.speed[idx], np.radians(np.clip(ob.incidence_deg[idx], 0.0, 89.9))
                vn = v * np.cos(alpha)
                speeds, inverse = np.unique(vn, return_inverse=True)  # one solve per distinct normal speed
                y_ref, per_ref, _ = reduction.ring_groups([c], speeds[None, :])
                self._oblique_cache.append((c, idx, v, alpha, vn, inverse, y_ref, per_ref))
        return self._oblique_cache

    def log_density(self, z):
        """log of the e_n density at standardized residuals z, up to a constant: -z^2/2 (normal) or
        -(nu + 1)/2 log(1 + z^2/nu) (Student-t)."""
        z = np.asarray(z, dtype=float)
        if self.student:
            return -0.5 * (self.nu + 1) * np.log1p(z * z / self.nu)
        return -0.5 * z * z

    def description(self) -> str:
        """The likelihood in words (the posterior's ``likelihood`` attribute)."""
        if not self.student:
            return "normal"
        return (f"student-t (nu = {self.nu:g}, scale = the stated e_n uncertainty; oblique rows normal); "
                "the fit's verdict and chi-square are those of the normal model")


def _contact(fit, radius, values: dict):
    """Contact of ``radius`` [m] with damping ``values`` (f0 from Eq. (7) with values' w_A)."""
    c = material_contact(fit, radius, zeta_hertz=values["zeta_hertz"], zeta_adhesion=values["zeta_adhesion"],
                         work_of_adhesion=values["work_of_adhesion"])
    return c.with_(friction=values["friction"]) if "friction" in values else c


# =============================================================================== sampling
class PosteriorError(RuntimeError):
    """The chain collapsed or did not converge within its budget: no posterior to report.

    The message is one line: what happened, the numbers, and what to do.

    Examples
    --------
    See :func:`sample_posterior`; a RuntimeError, so the command line reports it in one line:

    >>> issubclass(PosteriorError, RuntimeError)
    True
    """


#: steps between convergence checks
CHECK_EVERY = 100
#: the chain after burn-in must be longer than this many integrated autocorrelation times (emcee's
#: guidance: Foreman-Mackey et al., emcee documentation, "Autocorrelation analysis & convergence")
TAU_FACTOR = 50
#: ... and the estimate of tau must have changed by less than this fraction since the last check
TAU_STABILITY = 0.05
#: mean acceptance fraction below which the chain counts as collapsed (a healthy stretch-move chain
#: accepts 0.2-0.5 of its proposals)
MIN_ACCEPTANCE = 0.05
#: upper end of the flat friction prior: far above any measured dry friction coefficient, so that it
#: never truncates a posterior the data determine; where the data only bound f from below, the upper
#: end of its credible interval is this prior's and is reported as such
FRICTION_PRIOR_MAX = 10.0


def prior_bounds(names, best: dict) -> dict:
    """Flat prior of each sampled parameter: {name: (low, high)} in its units.

    zeta_H, zeta_A and w_A (relative to its fitted value) over the ranges the fit searches
    (:data:`microimpact.analysis.fitting.DAMPING_RANGES`), the friction over [0, FRICTION_PRIOR_MAX].

    Examples
    --------
    >>> prior_bounds(["zeta_hertz", "friction"], {"zeta_hertz": 0.1, "friction": 0.2})
    {'zeta_hertz': (0.0, 1000.0), 'friction': (0.0, 10.0)}
    """
    out = {}
    for n in names:
        if n == "friction":
            out[n] = (0.0, FRICTION_PRIOR_MAX)
        elif n == "work_of_adhesion":
            lo, hi = DAMPING_RANGES[n]
            out[n] = (lo * best[n], hi * best[n])
        else:
            out[n] = DAMPING_RANGES[n]
    return out


def _groups_at_work_of_adhesion(y0, per, s):
    """The ring groups (y0, C1 / zeta_H = C2 / zeta_A) at w_A = s w_ref from those at w_ref, by their
    powers of w_A: f0 ~ w_A^(2/3) (Eq. (7)), so X = B / A ~ w_A^(2/3), T = (m / sqrt(A B))^(1/2) ~
    w_A^(-1/6) (Eqs. (29)-(30)),
    y0 = v T / X ~ w_A^(-5/6) and C1 / zeta_H = (X / T) / (D v_ref^(1/5)) ~ w_A^(5/6) (D holds no f0).
    At s = 1 the powers are exactly 1: the groups come back bit for bit. [-]"""
    return y0 * s ** (-5.0 / 6.0), per * s ** (5.0 / 6.0)


def _prior_holding_the_fit(names, best: dict) -> dict:
    """:func:`prior_bounds`, or :class:`PosteriorError` naming each fitted value outside them: walkers
    started on the box's edge would all sit there (emcee: not linearly independent)."""
    bounds = prior_bounds(names, best)
    outside = [f"{n} = {best[n]:.6g} outside [{bounds[n][0]:g}, {bounds[n][1]:g}]" for n in names
               if not bounds[n][0] <= best[n] <= bounds[n][1]]
    if outside:
        raise PosteriorError(f"the fit lies outside the posterior's flat prior ({'; '.join(outside)}): the data "
                             "put the parameter beyond the range the toolkit samples; fit fewer parameters or "
                             "add measurements that determine it")
    return bounds


def sample_posterior(table, damping_fit, friction_fit=None, *, walkers: int | None = None, steps: int | None = None,
                     max_steps: int | None = None, burn: int | None = None, seed: int = DEFAULT_SEED,
                     errors_in_variables: str = "auto", rtol: float = DEFAULT_RTOL, progress: bool = False,
                     time_budget: float | None = None, require_convergence: bool = True, likelihood: str = "normal",
                     method: str = DEFAULT_METHOD, emulator_tol: float = EMULATOR_TOLERANCE,
                     nu: float = DEFAULT_NU) -> Posterior:
    """Sample the posterior of the fitted parameters with emcee until it converges (seeded).

    Parameters
    ----------
    table : pandas.DataFrame or None
        The fitted impact table (stated uncertainties, oblique columns); None: the fit's own data.
    damping_fit : DampingFit
        The least-squares fit: start of the walkers, material, fitted rows.
    friction_fit : FrictionFit, optional
        Also sample the friction under the tangential likelihood.
    walkers, steps, max_steps, burn : int, optional
        Ensemble size (>= 2 x parameters; :data:`DEFAULT_WALKERS`); exactly ``steps`` steps, else
        until converged within ``max_steps`` (:data:`DEFAULT_MAX_STEPS`); steps discarded (a third).
    seed : int
        Seeds the start ball and the sampler.
    errors_in_variables : {"auto", "effective", "latent"}
        Treatment of the speed uncertainty (module docstring).
    rtol : float
        Relative tolerance of the normal solves. [-]
    progress : bool
        Progress bar on stderr (a terminal only).
    time_budget : float or Deadline, optional
        Wall-clock budget, checked between steps; None: no limit. [s]
    require_convergence : bool
        Raise :class:`PosteriorError` for an unconverged chain (default); False returns it marked
        ``converged = False`` (for studies of the sampler).
    likelihood : {"normal", "student-t"}
        e_n likelihood of each row, with ``nu`` degrees of freedom (:data:`DEFAULT_NU`) (module docstring).
    method : {"emulator", "solve"}
        Model e_n of the likelihood: the ring law's shipped table (:func:`microimpact.solvers.emulator.ring_emulator`,
        :data:`DEFAULT_METHOD`; the solver where it falls back or for another law) to the absolute
        tolerance ``emulator_tol`` (:data:`EMULATOR_TOLERANCE`), or the solver at every evaluation
        (the reference). The oblique part is always solved.

    Returns
    -------
    Posterior

    Raises
    ------
    ValueError
        Too few walkers or steps, a bad ``burn`` or ``time_budget``.
    PosteriorError
        The chain collapsed (acceptance below :data:`MIN_ACCEPTANCE`, walkers at zero probability,
        no autocorrelation time) or has not converged (:data:`TAU_FACTOR` autocorrelation times,
        R-hat, effective sample size: :mod:`microimpact.analysis.diagnostics`) within its budget,
        or the fit lies outside the flat prior (:func:`prior_bounds`).
    TimeBudgetExceeded
        The chain ran past ``time_budget`` (the message gives the steps done).

    References
    ----------
    Foreman-Mackey, D. et al. (2013). emcee: the MCMC hammer. PASP 125, 306. doi:10.1086/670067;
    Vehtari, A. et al. (2021). doi:10.1214/20-BA1221 (R-hat, effective sample size).

    Examples
    --------
    Six synthetic impacts: a chain whose budget is too small is refused, saying why, or returned marked:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> sample_posterior(table, fit, walkers=8, max_steps=60)
    Traceback (most recent call last):
    ...
    microimpact.analysis.posterior.PosteriorError: the posterior has not converged after 60 steps of 8 walkers ...
    >>> sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    Posterior(zeta_hertz, zeta_adhesion; 8 walkers x 60 steps, burn-in 20, seed 2002, converged=False)
    """
    t0, deadline = time.perf_counter(), Deadline.start(time_budget, "posterior")
    names = list(damping_fit.varied) + (["friction"] if friction_fit is not None else [])
    best = dict(damping_fit.values) | ({"friction": friction_fit.friction} if friction_fit is not None else {})
    stderr = dict(damping_fit.stderr) | ({"friction": friction_fit.stderr["friction"]} if friction_fit is not None else {})
    walkers, budget, fixed_length = _sampler_options(walkers, steps, max_steps, burn, seed, len(names))
    bounds = _prior_holding_the_fit(names, best)
    lo, hi = (np.array([bounds[n][k] for n in names]) for k in (0, 1))
    like = _Likelihood(damping_fit, table, friction_fit, errors_in_variables, rtol, likelihood, nu, method, emulator_tol)
    log_probability = _LogProbability(like, names, best, lo, hi)
    pos = np.clip(_start_ball(names, best, stderr, lo, walkers, seed), lo, hi)
    with progress_bar(budget, "posterior", progress) as advance, engine_threads(1):
        advance = deadline.ticking(advance, budget, "emcee steps")
        sampler, diag, previous_tau, done = _run_chain(log_probability, pos, seed, budget, fixed_length, burn, advance,
                                                       names, damping_fit, friction_fit)
    converged = _converged(diag, previous_tau if not fixed_length else diag["tau"], RHAT_MAX, ESS_MIN)
    text = _convergence_text(diag, converged, RHAT_MAX, ESS_MIN)
    if require_convergence and not converged:
        raise PosteriorError(f"the posterior has not converged after {done} steps of {walkers} walkers ({text}); "
                             + ("give more steps" if fixed_length else "give a larger max_steps (CLI --max-steps)")
                             + _undetermined_hint(damping_fit, friction_fit))
    return _posterior_record(sampler, diag, names, best, bounds, like, damping_fit, friction_fit, seed, converged,
                             text, errors_in_variables, time.perf_counter() - t0)


class _LogProbability:
    """log posterior of a walker's position: the likelihood inside the flat prior's box, -inf outside
    it and where the likelihood is not finite."""

    def __init__(self, like, names, best, lo, hi):
        self.like, self.names, self.lo, self.hi = like, names, lo, hi
        self.base = {n: best[n] for n in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion", "friction") if n in best}

    def __call__(self, x):
        """log posterior of the walkers ``x`` (K, parameters), all at once (emcee's ``vectorize``)."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        out = np.full(x.shape[0], -np.inf)
        inside = np.all((x >= self.lo) & (x <= self.hi), axis=1)
        if inside.any():
            n = int(inside.sum())
            p = {k: np.full(n, v) for k, v in self.base.items()} | {k: x[inside, i] for i, k in enumerate(self.names)}
            value = self.like.many(p)
            out[inside] = np.where(np.isfinite(value), value, -np.inf)
        return out


def _sampler_options(walkers, steps, max_steps, burn, seed, n_params: int) -> tuple[int, int, bool]:
    """(walkers, steps budget, fixed length) of :func:`sample_posterior`'s options, checked before
    any work: a bad seed must not be found only after the whole chain has run."""
    walkers = DEFAULT_WALKERS if walkers is None else int(walkers)
    fixed_length = steps is not None
    budget = int(steps) if fixed_length else (DEFAULT_MAX_STEPS if max_steps is None else int(max_steps))
    if walkers < 2 * n_params or budget < 2:
        raise ValueError(f"walkers must be >= {2 * n_params} (twice the {n_params} parameters) and steps >= 2, "
                         f"got walkers={walkers}, steps={budget}")
    if burn is not None and not 0 <= int(burn) < budget:
        raise ValueError(f"burn must lie in [0, steps), got {burn}")
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or not 0 <= seed <= MAX_SEED:
        raise ValueError(f"seed must be a whole number in [0, {MAX_SEED}] (the posterior file stores it as a "
                         f"32-bit integer), got {seed!r}")
    check_posterior_memory(walkers, budget, n_params)
    return walkers, budget, fixed_length


def _posterior_record(sampler, diag, names, best, bounds, like, damping_fit, friction_fit, seed, converged, text,
                      errors_in_variables, elapsed) -> Posterior:
    """The :class:`Posterior` of a finished chain: the chain, its diagnostics, what was held fixed,
    the priors and how the speed errors entered."""
    fixed = {n: best[n] for n in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion") if n not in names}
    if friction_fit is None:
        fixed["friction"] = float(damping_fit.friction)
    eiv = (f"{errors_in_variables}: latent true speed (Gauss-Hermite, {GAUSS_HERMITE_NODES} nodes) for "
           f"{int(like.latent.sum())} row(s), effective variance for {like.n_plain}")
    return Posterior(names=tuple(names), chain=np.asarray(sampler.get_chain()),
                     log_probability=np.asarray(sampler.get_log_prob()), burn=diag["burn"], fixed=fixed,
                     autocorr_time=dict(zip(names, map(float, diag["tau"]))),
                     acceptance_fraction=np.asarray(sampler.acceptance_fraction, dtype=float), seed=int(seed),
                     info={"errors_in_variables": eiv, "latent_rows": tuple(int(r) for r in like.latent_rows),
                           "elapsed_s": elapsed, "converged": converged, "convergence": text,
                           "source": str(damping_fit.info.get("source") or ""),
                           "rhat": dict(zip(names, map(float, diag["rhat"]))),
                           "ess_bulk": dict(zip(names, map(float, diag["ess"]))),
                           "priors": {n: tuple(map(float, bounds[n])) for n in names},
                           "status": _statuses(damping_fit, friction_fit),
                           "bounds": _statuses(damping_fit, friction_fit, "bounds"),
                           "moves": "emcee " + " + ".join(f"{type(m).__name__} {w:g}" for m, w in _moves()),
                           "likelihood": like.description(),
                           "method": like.method + (f" (tol {like.tol:g})" if like.method == "emulator" else "")}
                     | _fit_verdict(damping_fit)
                     | ({"student_t_nu": like.nu} if like.student else {}))


def _fit_verdict(damping_fit) -> dict:
    """The verdict of the least-squares fit the posterior starts from (verdict, verdict_text, p_value)."""
    verdict = getattr(damping_fit, "verdict", None)
    if verdict is None:
        return {}
    return {"verdict": verdict.verdict, "verdict_text": verdict.text(), "p_value": float(verdict.p_value)}


def _run_chain(log_probability, pos, seed, budget, fixed_length, burn, advance, names, damping_fit, friction_fit):
    """(sampler, diagnostics, previous tau, steps done): chunks of CHECK_EVERY steps until converged,
    collapsed (PosteriorError) or out of ``budget`` steps."""
    rng = np.random.default_rng(seed)
    sampler = emcee.EnsembleSampler(len(pos), len(names), log_probability, moves=_moves(), vectorize=True)
    sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()  # seeded
    state = emcee.State(pos)
    done, previous_tau, diag = 0, None, None

    with interrupt_at_checkpoints() as checkpoint:  # Ctrl-C acts between steps, not inside emcee
        while done < budget:
            chunk = min(CHECK_EVERY, budget - done)
            for state in sampler.sample(state, iterations=chunk, store=True):
                advance(1)
                checkpoint()
            done += chunk
            diag = _diagnose(sampler, names, burn, split_rhat, ess_bulk, previous_tau, final=done >= budget)
            _raise_if_collapsed(diag, names, damping_fit, friction_fit, done)
            if not fixed_length and _converged(diag, previous_tau, RHAT_MAX, ESS_MIN):
                break
            previous_tau = diag["tau"]
    return sampler, diag, previous_tau, done


def _moves() -> list:
    """emcee's moves and their weights (module docstring)."""
    return [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]


def _diagnose(sampler, names, burn, split_rhat, ess_bulk, previous_tau=None, final=True) -> dict:
    """tau, R-hat, bulk ESS (walkers as chains) of the chain after burn-in, and its health.

    Unless ``final``, R-hat is computed only where the tau rule holds (:func:`_tau_rule` against
    ``previous_tau``) and the ESS only where R-hat then holds too, else NaN (not converged): each
    rank-normalises the whole chain, several times the cost of tau, and a chain converges only where
    all three rules hold, so the order decides nothing and saves the two where tau fails."""
    chain = sampler.get_chain()
    steps = chain.shape[0]
    b = steps // 3 if burn is None else min(int(burn), steps - 2)
    post = chain[b:]
    tau = _autocorr(post)
    walkers_t = np.moveaxis(post, 1, 0)  # (walkers, steps, parameters)
    diag = {"steps": steps, "burn": b, "n_post": steps - b, "tau": tau,
            "acceptance": np.asarray(sampler.acceptance_fraction, dtype=float),
            "dead": int(np.sum(~np.isfinite(sampler.get_log_prob()[-1])))}
    enough = post.shape[0] >= 4  # split chains of at least two draws

    def each(f, needed):
        return np.array([f(walkers_t[:, :, i]) if enough and needed else np.nan for i in range(len(names))])
    diag["rhat"] = each(split_rhat, final or _tau_rule(diag, previous_tau))
    diag["ess"] = each(ess_bulk, final or bool(np.all(diag["rhat"] < RHAT_MAX)))
    return diag


def _raise_if_collapsed(diag, names, damping_fit, friction_fit, done):
    """PosteriorError for a chain that cannot become a sample: no acceptance, dead walkers, no tau."""
    acc = diag["acceptance"]
    why = None
    if acc.mean() < MIN_ACCEPTANCE:
        why = f"mean acceptance {acc.mean():.3f} (walkers {acc.min():.3f}-{acc.max():.3f}) below {MIN_ACCEPTANCE}"
    elif diag["dead"]:
        why = f"{diag['dead']} walker(s) at zero posterior probability"
    elif diag["n_post"] >= 3 * CHECK_EVERY and not np.all(np.isfinite(diag["tau"])):
        bad = [n for n, t in zip(names, diag["tau"]) if not math.isfinite(t)]
        why = f"no autocorrelation time for {', '.join(bad)} (the walkers do not move in it)"
    if why:
        raise PosteriorError(f"the posterior chain collapsed after {done} steps: {why}"
                             + _undetermined_hint(damping_fit, friction_fit))


def _statuses(damping_fit, friction_fit, what: str = "status") -> dict:
    """{parameter: identifiability status} (or {parameter: (lower, upper)}) of the least-squares fits."""
    st = dict(getattr(damping_fit, "identifiability", {}) or {})
    if friction_fit is not None:
        st |= dict(getattr(friction_fit, "identifiability", {}) or {})
    return {n: (v.status if what == "status" else (float(v.lower), float(v.upper))) for n, v in st.items()}


def _undetermined_hint(damping_fit, friction_fit) -> str:
    """'; the data do not determine ...' from the fits' identifiability, or ''."""
    st = dict(getattr(damping_fit, "identifiability", {}) or {})
    if friction_fit is not None:
        st |= dict(getattr(friction_fit, "identifiability", {}) or {})
    bad = [s.describe() for s in st.values() if not s.determined]
    return ("; the least-squares fit already says: " + "; ".join(bad)) if bad else ""


def _converged(diag, previous_tau, rhat_max, ess_min) -> bool:
    """The 50-tau rule with a stable tau, R-hat and the bulk effective sample size."""
    return (_tau_rule(diag, previous_tau) and bool(np.all(diag["rhat"] < rhat_max))
            and bool(np.all(diag["ess"] >= ess_min)))


def _tau_rule(diag, previous_tau) -> bool:
    """The post-burn-in chain longer than TAU_FACTOR tau, tau changed by at most TAU_STABILITY."""
    tau = diag["tau"]
    if not np.all(np.isfinite(tau)) or previous_tau is None or not np.all(np.isfinite(previous_tau)):
        return False
    stable = bool(np.all(np.abs(tau - previous_tau) <= TAU_STABILITY * tau))
    return stable and diag["n_post"] > TAU_FACTOR * float(np.max(tau))


def _convergence_text(diag, converged, rhat_max, ess_min) -> str:
    tau = float(np.max(diag["tau"])) if np.all(np.isfinite(diag["tau"])) else math.nan
    ratio = f"{diag['n_post'] / tau:.0f}" if tau > 0 else "?"  # NaN or 0: not estimated (a very short chain)
    rhat = f"{np.max(diag['rhat']):.4f}" if np.all(np.isfinite(diag["rhat"])) else "?"
    ess = f"{np.min(diag['ess']):.0f}" if np.all(np.isfinite(diag["ess"])) else "?"
    return (f"post-burn-in chain {diag['n_post']} steps = {ratio} x the longest autocorrelation time "
            f"({tau:.1f} steps), R-hat <= {rhat}, bulk ESS >= {ess}; "
            + (f"converged ({TAU_FACTOR} tau, R-hat < {rhat_max}, ESS >= {ess_min})" if converged else
               f"NOT converged ({TAU_FACTOR} tau with a stable tau, R-hat < {rhat_max}, ESS >= {ess_min})"))


def _start_ball(names, best: dict, stderr: dict, lower, walkers: int, seed: int) -> np.ndarray:
    """Seeded walker start positions (walkers, parameters): 0.3 standard errors around the fit,
    kept above the lower bounds."""
    rng = np.random.default_rng(seed)
    scale = np.array([stderr[n] if math.isfinite(stderr[n]) and stderr[n] > 0 else 1e-3 * abs(best[n]) for n in names])
    pos = np.array([best[n] for n in names])[None, :] + 0.3 * scale[None, :] * rng.standard_normal((walkers, len(names)))
    lo = np.array(lower)
    return np.where(pos <= lo, lo + 0.01 * scale, pos)


def _autocorr(chain: np.ndarray) -> np.ndarray:
    """Integrated autocorrelation time per parameter [steps] (emcee.autocorr, without its length check)."""
    log = logging.getLogger("emcee.autocorr")
    level = log.level
    log.setLevel(logging.ERROR)  # the length warning: the caller states convergence itself
    try:
        return np.asarray(emcee.autocorr.integrated_time(chain, quiet=True), dtype=float)
    finally:
        log.setLevel(level)


# =============================================================================== what it implies
def posterior_contacts(posterior: Posterior, damping_fit, radius: float, n_draws: int = 64, seed=None) -> list:
    """Contacts of one radius [m] for ``n_draws`` posterior draws (f0 from Eq. (7) per draw).

    Examples
    --------
    Eight contacts drawn from the chain, each with the fit's material and a drawn damping:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> contacts = posterior_contacts(post, fit, 3.45e-6, n_draws=8)
    >>> len(contacts), {c.density for c in contacts}, len({c.zeta_adhesion for c in contacts}) > 1
    (8, {1350.0}, True)
    """
    return [_contact(damping_fit, radius, d) for d in posterior.draws(n_draws, seed)]


def restitution_bands(posterior: Posterior, damping_fit, speeds=None, *, n_draws: int = 64,
                      rtol: float = DEFAULT_RTOL, time_budget: float | None = None) -> xr.Dataset:
    """Posterior bands of the model e_n(v_n) at every fitted radius.

    Parameters
    ----------
    speeds : array_like, optional
        Normal speeds [m/s]; default 60 log-spaced over the measured range (down to 0.9 x the
        smallest measured speed).
    n_draws : int
        Posterior draws pushed through :func:`solve_normal_many`.
    time_budget : float or Deadline, optional
        Wall-clock budget, checked after each draw at each radius; None: no limit. [s]

    Returns
    -------
    xarray.Dataset
        ``e_n_band(radius, band_speed, quantile)`` [1]; the credible band of the model e_n (the
        spread of the curve over the posterior, without the measurement noise).

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> bands = restitution_bands(post, fit, [1.0, 2.0, 5.0], n_draws=8)
    >>> bands["e_n_band"].dims, bands["quantile"].values.tolist()
    (('radius', 'band_speed', 'quantile'), [0.025, 0.16, 0.5, 0.84, 0.975])
    """
    lo, hi = damping_fit.speed_range
    v = np.geomspace(0.9 * lo, hi, 60) if speeds is None else np.asarray(speeds, dtype=float)
    radii = damping_fit.radii
    draws = posterior.draws(n_draws)
    e = np.empty((radii.size, len(draws), v.size))

    deadline = Deadline.start(time_budget, "restitution bands")
    with engine_threads(1):
        for i, r in enumerate(radii):
            for j, d in enumerate(draws):
                e[i, j] = engine.solve_normal_many(_contact(damping_fit, float(r), d), v, rtol=rtol)["e_n"]
                deadline.check(f"{i * len(draws) + j + 1} of {radii.size * len(draws)} draws x radii")
    return xr.Dataset({"e_n_band": (("radius", "band_speed", "quantile"), np.moveaxis(np.quantile(e, QUANTILES, axis=1), 0, -1),
                                    {"units": "1", "long_name": "posterior quantiles of the model normal coefficient "
                                                                "of restitution e_n"})},
                      coords=_coords(radii, QUANTILES) | {"band_speed": ("band_speed", v, {
                          "units": "m s-1", "long_name": "incident normal speed of the band"})})


def capture_velocity_interval(posterior: Posterior, damping_fit, *, n_draws: int = 64,
                              time_budget: float | None = None) -> xr.Dataset:
    """Capture velocity of each fitted radius with its posterior quantiles (credible interval).

    ``time_budget`` [s] (or a Deadline; None: no limit) is checked after each radius.

    Returns
    -------
    xarray.Dataset
        ``capture_velocity_quantile(radius, quantile)`` [m/s] over ``n_draws`` draws.

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> q = capture_velocity_interval(post, fit, n_draws=8)["capture_velocity_quantile"]
    >>> bool((q.diff("quantile") >= 0).all()), 1.3 < float(q.sel(quantile=0.5)[0]) < 1.5
    (True, True)
    """
    radii = damping_fit.radii
    draws = posterior.draws(n_draws)

    deadline = Deadline.start(time_budget, "capture velocity interval")
    v = []
    with engine_threads(1):
        for r in radii:
            v.append([capture_velocity(_contact(damping_fit, float(r), d), rtol=1e-5) for d in draws])
            deadline.check(f"{len(v)} of {len(radii)} radii")
    v = np.array(v)
    return xr.Dataset({"capture_velocity_quantile": (("radius", "quantile"), np.quantile(v, QUANTILES, axis=1).T, {
        "units": "m s-1", "long_name": "posterior quantiles of the normal capture velocity"})},
        coords=_coords(radii, QUANTILES))


def sweep_bands(posterior: Posterior, damping_fit, *, cases=None, n_draws: int = 16, n_speeds: int = 20,
                rtol: float = DEFAULT_RTOL, time_budget: float | None = None) -> xr.Dataset:
    """Posterior bands of the analyst's Table 2 sweeps along the measured speeds, at the median radius.

    Each case of :data:`microimpact.model.parameters.TABLE2_CASES` is run at its conditions with the
    largest value of each axis other than the speed (the sweep's most demanding corner), for
    ``n_draws`` posterior draws (with their friction), through :func:`microimpact.simulate_many`.
    ``time_budget`` [s] (or a Deadline; None: no limit) is checked after each case.

    Returns
    -------
    xarray.Dataset
        ``sweep_e_n_band``, ``sweep_mu_t_band``, ``sweep_K_L_band`` (case, sweep_speed, quantile) [1].

    Examples
    --------
    Case 2.1 (at its largest incidence, 30 deg) for four draws of a short, not converged chain (an
    illustration): the bands rise with the quantile, and at the slowest measured speed the normal
    component (1.56 m/s x cos 30 deg) is below the capture velocity, so every draw sticks:

    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> ds = sweep_bands(post, fit, cases=["2.1"], n_draws=4, n_speeds=5)
    >>> ds["sweep_e_n_band"].dims, round(float(ds["sweep_speed"][0]), 2)
    (('case', 'sweep_speed', 'quantile'), 1.56)
    >>> bool((ds["sweep_e_n_band"].diff("quantile") >= 0).all())
    True
    >>> ds["sweep_e_n_band"].isel(case=0, sweep_speed=0).values.tolist()
    [0.0, 0.0, 0.0, 0.0, 0.0]
    """
    cases = list(TABLE2_CASES) if cases is None else list(cases)
    radii = damping_fit.radii
    r = float(radii[len(radii) // 2])
    lo, hi = damping_fit.speed_range
    v = np.geomspace(lo, hi, n_speeds)
    draws = posterior.draws(n_draws)
    out = {q: np.empty((len(cases), len(draws), v.size)) for q in ("e_n", "mu_t", "K_L")}

    deadline = Deadline.start(time_budget, "sweep bands")
    with engine_threads(1):
        _sweep_draws(cases, draws, damping_fit, r, v, out, rtol, deadline)
    names = {"e_n": "normal coefficient of restitution e_n", "mu_t": "tangential impulse ratio mu_t",
             "K_L": "kinetic energy loss coefficient K_L"}
    ds = xr.Dataset(coords={
        "case": ("case", np.array(cases, dtype=object), {"long_name": "Table 2 case"}),
        "sweep_speed": ("sweep_speed", v, {"units": "m s-1", "long_name": "incident speed of the sweep band"}),
        "quantile": ("quantile", np.array(QUANTILES), {"units": "1", "long_name": "posterior quantile"})})
    for q, x in out.items():
        with np.errstate(invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # mu_t is undefined (NaN) without tangential motion
            ds[f"sweep_{q}_band"] = (("case", "sweep_speed", "quantile"), np.moveaxis(np.nanquantile(x, QUANTILES, axis=1), 0, -1),
                                     {"units": "1", "long_name": f"posterior quantiles of {names[q]} along the sweep"})
    ds.attrs["sweep_radius"] = r
    ds.attrs["sweep_conditions"] = "each case at the largest value of each of its axes other than the speed"
    return ds


def _sweep_draws(cases, draws, damping_fit, r, v, out, rtol, deadline):
    """Fill ``out[q][case, draw, speed]`` by simulate_many (see :func:`sweep_bands`)."""
    for i, case in enumerate(cases):
        cond = {k: _largest(val) for k, val in TABLE2_CASES[case].items()
                if k in ("incidence_deg", "azimuth_deg", "omega_n", "omega_t", "omega_tp")}
        for j, d in enumerate(draws):
            ds = simulate_many(_contact(damping_fit, r, d), v, cond.get("incidence_deg", 0.0), cond.get("azimuth_deg", 0.0),
                               (cond.get("omega_n", 0.0), cond.get("omega_t", 0.0), cond.get("omega_tp", 0.0)), rtol=rtol)
            for q in out:
                out[q][i, j] = ds[q].values
        deadline.check(f"{i + 1} of {len(cases)} cases")


def _largest(spec):
    """Largest value of a sweep-axis spec (a number, a list or a range mapping)."""
    if isinstance(spec, dict):
        return float(spec.get("stop", spec.get("start", 0.0)))
    if isinstance(spec, (list, tuple)):
        return float(max(spec))
    return float(spec)


def _coords(radii, quantiles) -> dict:
    return {"radius": ("radius", np.asarray(radii, dtype=float), {"units": "m", "long_name": "sphere radius"}),
            "quantile": ("quantile", np.array(quantiles), {"units": "1", "long_name": "posterior quantile"})}


def posterior_memory(walkers: int, steps: int, n_parameters: int) -> float:
    """Bytes a chain of ``walkers`` x ``steps`` over ``n_parameters`` holds at its largest: emcee's
    chain and log-probabilities (float64) and the posterior's own copy of the kept part.

    Examples
    --------
    >>> posterior_memory(16, 20000, 3)
    20480000.0
    """
    return 2.0 * 8.0 * float(walkers) * float(steps) * (n_parameters + 1)


def check_posterior_memory(walkers: int, steps: int, n_parameters: int) -> None:
    """ValueError naming walkers and steps when :func:`posterior_memory` cannot fit in the machine
    (:func:`microimpact.io.resources.check_memory`), before anything is sampled."""
    check_memory(f"a chain of {walkers} walkers x {steps} steps (walkers, steps / max_steps) over {n_parameters} "
                 "parameters", posterior_memory(walkers, steps, n_parameters))


def summary_table(posterior: Posterior) -> pd.DataFrame:
    """One row per sampled parameter: median, 95 % interval, autocorrelation time.

    Examples
    --------
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False)
    >>> post = sample_posterior(table, fit, walkers=8, steps=60, require_convergence=False)  # short: an illustration
    >>> summary_table(post)["parameter"].tolist()
    ['zeta_hertz', 'zeta_adhesion']
    """
    rows = []
    for n in posterior.names:
        lo, hi = posterior.interval(n)
        rows.append({"parameter": n, "units": PARAMETER_UNITS[n], "median": posterior.median()[n], "low95": lo,
                     "high95": hi, "autocorr_time": posterior.autocorr_time[n]})
    return pd.DataFrame(rows)
