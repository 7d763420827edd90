"""``microimpact fit``: the analyst's fit of a measured-impact CSV, its files and its summary."""

from __future__ import annotations

import json
import math
import sys

from microimpact._commands.common import UsageError
from microimpact._commands.tables import impacts_for_pair, input_files
from microimpact.analysis.analyst_fit import analyse_impacts, exclude_rows
from microimpact.analysis.posterior import DEFAULT_MAX_STEPS, DEFAULT_NU, DEFAULT_WALKERS, check_posterior_memory
from microimpact.io.paths import check_outputs, print_before_writing, reporting_os_errors


def run(args) -> int:
    outputs = check_outputs({"--out": args.out, "--posterior": args.posterior, "--oblique-out": args.oblique_out},
                            input_files(args))
    out = outputs["--out"]
    posterior = False
    unused = [f"--{name.replace('_', '-')}" for name in ("walkers", "steps", "max_steps", "seed", "nu", "posterior_method")
              if getattr(args, name) is not None] + (["--likelihood"] if args.likelihood != "normal" else [])
    if outputs.get("--posterior") is None and unused:
        raise UsageError(f"{', '.join(unused)} set the posterior's sampler, which runs only with --posterior FILE")
    if outputs.get("--posterior") is not None:
        if args.full_chain:
            raise UsageError("--full-chain was removed: the default chain now runs until it converges; "
                             "--max-steps bounds it")
        posterior = {"walkers": args.walkers, "steps": args.steps, "max_steps": args.max_steps, "seed": args.seed,
                     "method": args.posterior_method}

        try:  # before the fit: the most parameters a chain can have (zeta_H, zeta_A, w_A, f)
            check_posterior_memory(args.walkers or DEFAULT_WALKERS, args.steps or args.max_steps or DEFAULT_MAX_STEPS, 4)
        except ValueError as exc:
            raise UsageError(f"--walkers/--steps/--max-steps: {exc}") from None
    table, pair = impacts_for_pair(args)
    print(f"fitting {len(table)} impacts of {pair.name} ...", file=sys.stderr, flush=True)
    result = analyse_impacts(table, pair, fit_work_of_adhesion=args.fit_work_of_adhesion, weights=args.weights,
                             confidence_intervals=not args.no_confidence_intervals, posterior=posterior,
                             errors_in_variables=args.errors_in_variables, rtol=args.rtol, progress=True,
                             time_budget=args.time_budget, exclude=_exclude_ids(args.exclude, table), loss=args.loss,
                             likelihood=args.likelihood, nu=DEFAULT_NU if args.nu is None else args.nu,
                             method=args.fit_method)
    paths = (out, outputs.get("--posterior"), outputs.get("--oblique-out"))
    planned = tuple(p for p in paths if p is not None)
    text = (json.dumps(_json_ready(_fit_summary(result, table, pair, planned)), indent=2, allow_nan=False)
            if args.json else result.report())
    print_before_writing(text)
    with reporting_os_errors(outputs):
        written = result.save(*paths)
    print("wrote " + ", ".join(map(str, written)), file=sys.stderr)
    return 0


def _exclude_ids(text, table) -> tuple:
    """``--exclude ID,...`` as ids, each checked against the table (a usage error naming an unknown one)."""
    ids = tuple(i.strip() for i in (text or "").split(",") if i.strip())
    try:
        exclude_rows(table, ids)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    return ids


def _json_ready(obj):
    """Non-finite numbers as null (JSON has no NaN or Infinity), numpy scalars as Python numbers."""
    if isinstance(obj, dict):
        return {k: _json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_ready(v) for v in obj]
    if isinstance(obj, bool) or obj is None or isinstance(obj, str):
        return obj
    value = float(obj)
    return value if math.isfinite(value) else None


def _fit_summary(result, table, pair, written) -> dict:
    """``fit --json``: what the report says, as numbers, by the report's rules (a value, interval and
    standard error only where the data determine it; else the bound)."""
    def parameters(fit) -> dict:
        out = {}
        for name, value in fit.values.items():
            st = fit.identifiability.get(name)
            if st is not None:
                # the one standard error every output prints (the damping fit's: its 95 % interval's; the
                # friction's: with the damping's uncertainty where it was propagated, else at its best values)
                se = fit.interval_stderr(name) if hasattr(fit, "interval_stderr") else fit.stderr.get(name, float("nan"))
                conditional = getattr(fit, "stderr_conditional", {}).get(name, float("nan"))
                propagated = math.isfinite(se) or not math.isfinite(conditional)
                out[name] = st.to_record(se if propagated else conditional)
                if hasattr(fit, "stderr_conditional") and "stderr" in out[name]:
                    out[name]["stderr_includes_damping"] = bool(propagated)
            else:  # fixed: the given material's value
                out[name] = {"status": "fixed", "value": float(value)}
        return out

    d = result.damping
    summary = {"material_pair": pair.name, "n_points": int(len(table)),
               "damping": {"parameters": parameters(d), "loss": str(d.info.get("loss", "linear")),
                           "model_evaluation": str(d.info.get("model_evaluation", "")),
                           "chisqr": float(d.chisqr), "redchi": float(d.redchi),
                           "verdict": d.verdict.to_record()},
               "written": [str(p) for p in written]}
    if result.without_outliers is not None:
        w = result.without_outliers
        summary["damping"]["without_outliers"] = {"parameters": parameters(w), "verdict": w.verdict.to_record()}
    if result.friction is not None:
        summary["friction"] = {"parameters": parameters(result.friction), "tangential_model": result.friction.tangential_model}
    if result.posterior is not None:
        steps, walkers, _ = result.posterior.chain.shape
        summary["posterior"] = {"converged": result.posterior.converged, "walkers": walkers, "steps": steps,
                                "burn": int(result.posterior.burn), "seed": int(result.posterior.seed),
                                "likelihood": str(result.posterior.info.get("likelihood", "normal")),
                                "method": str(result.posterior.info.get("method", "")),
                                "verdict": result.posterior.info.get("verdict", ""),
                                "verdict_text": result.posterior.info.get("verdict_text", "")}
    return summary
