"""``microimpact fit --law thornton_ning`` (an elastic-plastic law's fit) and ``microimpact compare``
(every law ranked on the same rows): their checks, text, JSON and files."""

from __future__ import annotations

import dataclasses
import json
import sys

from microimpact._commands.common import UsageError
from microimpact._commands.fit import _exclude_ids, _json_ready
from microimpact._commands.tables import impacts_for_pair, input_files
from microimpact.analysis.analyst_fit import exclude_rows
from microimpact.analysis.model_comparison import DEFAULT_MODELS, compare_normal_models
from microimpact.analysis.plastic_fit import fit_thornton_ning
from microimpact.io.files import write_netcdf
from microimpact.io.materials import material_contact
from microimpact.io.paths import check_outputs, print_before_writing, reporting_os_errors
from microimpact.io.provenance import materials_parameter_source, stamp_parameters
from microimpact.solvers import DEFAULT_RTOL

#: options of ``fit`` that only the damping law's fit uses (argparse dest -> why)
_DAMPING_ONLY = {
    "posterior": "--posterior samples the damping law's posterior",
    "walkers": "--walkers sets the damping law's posterior sampler",
    "steps": "--steps sets the damping law's posterior sampler",
    "max_steps": "--max-steps sets the damping law's posterior sampler",
    "seed": "--seed sets the damping law's posterior sampler",
    "full_chain": "--full-chain was a posterior option",
    "oblique_out": "--oblique-out fits the friction after the damping law",
    "no_confidence_intervals": "--no-confidence-intervals skips lmfit's intervals of the damping fit (this law's "
                               "profile intervals are part of its fit)",
}


def _refuse_damping_options(args) -> None:
    """A one-line usage error for the first option given that does not apply to ``args.law``."""
    for dest, why in _DAMPING_ONLY.items():
        if getattr(args, dest, None) not in (None, False):
            raise UsageError(f"{why}; it does not apply to --law {args.law}")
    if getattr(args, "errors_in_variables", "auto") != "auto":
        raise UsageError(f"--errors-in-variables is an option of the damping law's posterior; it does not apply to "
                         f"--law {args.law}")
    if getattr(args, "rtol", DEFAULT_RTOL) != DEFAULT_RTOL:
        raise UsageError(f"--rtol sets the tolerance of the damping law's normal solves; --law {args.law} needs none "
                         "(its restitution is its closed-form energy account)")


def run_fit(args) -> int:
    """``fit --law thornton_ning``: the fit, its report (or ``--json``), then its file."""
    _refuse_damping_options(args)
    out = check_outputs({"--out": args.out}, input_files(args))["--out"]
    table, pair = impacts_for_pair(args)
    table, excluded = exclude_rows(table, _exclude_ids(args.exclude, table))
    print(f"fitting the {args.law} law to {len(table)} impacts of {pair.name} ...", file=sys.stderr, flush=True)
    fit = fit_thornton_ning(table, pair, weights=args.weights, time_budget=args.time_budget)
    if excluded:  # the verdict lists them (the file keeps them)
        fit = dataclasses.replace(fit, info={**fit.info, "excluded_ids": ",".join(excluded)})
    text = json.dumps(_json_ready(_summary(fit, pair, [out])), indent=2, allow_nan=False) if args.json else fit.report()
    print_before_writing(text)
    with reporting_os_errors({"--out": out}):
        fit.save(out)
    print(f"wrote {out}", file=sys.stderr)
    return 0


def _summary(fit, pair, written) -> dict:
    """``fit --law ... --json``: the parameters by the report's rules, the sticking velocities, the verdict."""
    lo, hi = fit.yield_pressure_interval
    return {"material_pair": pair.name, "law": fit.LAW, "n_points": int(fit.n_points),
            "parameters": {n: st.to_record() for n, st in fit.identifiability.items()},
            "yield_pressure": {"value": fit.yield_pressure, "from_yield_velocity_interval": [lo, hi]},
            "sticking_velocity": [{"radius": r["radius"], "value": r["sticking_velocity"],
                                   "interval": [r["sticking_velocity_lower"], r["sticking_velocity_upper"]]}
                                  for _, r in fit.sticking.iterrows()],
            "chisqr": fit.chisqr, "aic": fit.aic, "bic": fit.bic, "verdict": fit.verdict.to_record(),
            "written": [str(p) for p in written]}


def run_compare(args) -> int:
    """``compare``: every law fitted to the same rows, ranked by AIC with each one's verdict."""
    outputs = check_outputs({"--out": args.out}, input_files(args))
    table, pair = impacts_for_pair(args)
    models = DEFAULT_MODELS if args.models is None else tuple(m.strip() for m in args.models.split(",") if m.strip())
    unknown = [m for m in models if m not in DEFAULT_MODELS + ("jkr_force",)]
    if unknown or not models:
        raise UsageError(f"--models: {unknown[0] if unknown else 'none given'!r} is not a law of the comparison "
                         f"(choose from {', '.join(DEFAULT_MODELS + ('jkr_force',))})")
    print(f"fitting {len(models)} laws to {len(table)} impacts of {pair.name} ...", file=sys.stderr, flush=True)
    ds = compare_normal_models(table, pair, models)
    text = json.dumps(_json_ready(_ranking(ds)), indent=2, allow_nan=False) if args.json else comparison_text(ds)
    print_before_writing(text)
    if outputs.get("--out") is not None:
        ds = stamp_parameters(ds, [material_contact(pair, float(r)) for r in ds["radius"].values],
                              materials_parameter_source(pair.name) + " (start values; fitted parameters per law)")
        with reporting_os_errors(outputs):
            write_netcdf(ds, outputs["--out"])
        print(f"wrote {outputs['--out']}", file=sys.stderr)
    return 0


def _ranking(ds) -> dict:
    """The comparison as JSON: one record per law, lowest AIC first, and the comparison's sentence."""
    order = sorted(range(ds.sizes["normal_model"]), key=lambda i: float(ds["aic"].values[i]))
    laws = []
    for i in order:
        d = ds.isel(normal_model=i)
        params = {n: float(d[n]) for n in ("zeta_hertz", "zeta_adhesion", "work_of_adhesion", "yield_velocity")
                  if bool(d[n].notnull())}
        laws.append({"law": str(d["normal_model"].values), "n_parameters": int(d["n_parameters"]),
                     "chi_square": float(d["chi_square"]), "aic": float(d["aic"]), "delta_aic": float(d["delta_aic"]),
                     "bic": float(d["bic"]), "verdict": str(d["verdict"].values), "p_value": float(d["p_value"]),
                     "parameters": params})
    return {"n_points": int(ds.attrs["number_of_points"]), "weighting": ds.attrs["weighting"], "laws": laws,
            "comparison": ds.attrs["comparison_verdict"]}


def comparison_text(ds) -> str:
    """The comparison as a text table, lowest AIC first, with each law's verdict and the comparison's
    sentence (a rejected law is never called preferred)."""
    rec = _ranking(ds)
    lines = [f"Laws compared on the same {rec['n_points']} impacts (weighting: {rec['weighting']})",
             f"  {'law':<15}{'k':>3}{'chi-square':>13}{'AIC':>11}{'dAIC':>9}  verdict (p)"]
    for r in rec["laws"]:
        lines.append(f"  {r['law']:<15}{r['n_parameters']:>3}{r['chi_square']:>13.5g}{r['aic']:>11.4g}"
                     f"{r['delta_aic']:>9.4g}  {r['verdict']} (p = {r['p_value']:.2g})")
    lines.append(f"  comparison : {rec['comparison']}")
    return "\n".join(lines)
