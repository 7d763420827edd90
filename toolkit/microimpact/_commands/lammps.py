"""``microimpact lammps export | fit | verify``: LAMMPS GRANULAR inputs, fits of its laws, and the check against LAMMPS."""

from __future__ import annotations

import json
import sys

import numpy as np

from microimpact._commands.common import AUTO_TANGENTIAL, EXIT_DISAGREES, UsageError
from microimpact._commands.contacts import contact_from_args
from microimpact._commands.tables import impacts_for_pair, input_files
from microimpact._runtime.progress import progress_bar
from microimpact._runtime.timeout import time_limit
from microimpact.analysis.dem_fit import _p_text, candidate_laws, rank_dem_laws
from microimpact.analysis.dem_friction import rank_dem_tangential_laws
from microimpact.analysis.fit_result import DampingFit
from microimpact.io.files import atomic_write, write_csv
from microimpact.io.kinds import file_kind
from microimpact.io.lammps import LammpsExportError, _json_ready, lammps_input, read_lammps_export
from microimpact.io.paths import check_input_file, check_outputs, reporting_os_errors
from microimpact.io.provenance import fit_parameter_source
from microimpact.model.dem_tangential import DEM_TANGENTIAL_MODELS
from microimpact.studies.lammps_check import DEFAULT_INCIDENCES, LammpsRunError, default_speeds, verify_lammps


def _fitted_values(path) -> dict:
    """``{parameter: "value (stderr s)"}`` of the varied parameters of a fit file, for a header."""
    fit = DampingFit.load(path)
    return {name: f"{fit.values[name]:.6g} (standard error {fit.stderr.get(name, float('nan')):.3g}); "
                  f"{fit.parameter_source}" for name in fit.varied}


def run_export(args) -> int:
    inputs = {"--fit": args.fit, "--config": args.config}
    out = check_outputs({"--out": args.out}, {k: v for k, v in inputs.items() if v is not None})["--out"]
    with time_limit(args.time_budget, "lammps export"):
        contact = contact_from_args(args)
        try:
            text = lammps_input(contact, units=args.units, poisson=args.poisson, wall=args.wall,
                                source=args.contact_note, fitted=_fitted_values(args.fit) if args.fit else None)
        except LammpsExportError as exc:
            if str(exc).startswith("wall"):
                raise UsageError(f"--{exc}") from None
            raise
    with reporting_os_errors({"--out": out}), atomic_write(out) as f:
        f.write(text)
    print(f"wrote {out} (LAMMPS units {args.units}); check it with: microimpact lammps verify {out}")
    return 0


def _lammps_tangential_fields(args, law: str) -> dict:
    """The Contact fields of tangential law ``law`` from the options of ``lammps fit`` (UsageError if
    one is missing, or, for a law named by --tangential-model, one of the other law's is given)."""
    fields_ = {"tangential_model": law, "tangential_damping": args.tangential_damping}
    if args.rolling_stiffness is not None:  # LAMMPS's rolling sds, held at the given values while mu is fitted
        fields_ |= {"rolling_model": "lammps_sds", "rolling_stiffness": args.rolling_stiffness,
                    "rolling_damping": args.rolling_damping, "rolling_friction": args.rolling_friction}
    if args.twisting_model is not None:  # LAMMPS's twisting law: no effect on e_n, e_t; written with mu
        fields_["twisting_model"] = args.twisting_model
        if args.twisting_model == "lammps_sds":
            fields_ |= {"twisting_stiffness": args.twisting_stiffness, "twisting_damping": args.twisting_damping,
                        "twisting_friction": args.twisting_friction}
    other = "--shear-modulus" if law == "linear_history" else "--tangential-stiffness"
    if args.tangential_model != AUTO_TANGENTIAL and (args.shear_modulus if other == "--shear-modulus"
                                                     else args.tangential_stiffness) is not None:
        raise UsageError(f"{other} does not belong to --tangential-model {law}")
    if law == "linear_history":
        if args.tangential_stiffness is None:
            raise UsageError("--tangential-model linear_history needs --tangential-stiffness (k_t [N/m])")
        fields_["tangential_stiffness"] = args.tangential_stiffness
    else:
        if args.shear_modulus is None:
            raise UsageError(f"--tangential-model {law} needs --shear-modulus (G* [Pa]; LAMMPS's k_t = 8 G*)")
        fields_["shear_modulus"] = args.shear_modulus
    return fields_


def _lammps_tangential_laws(args) -> dict:
    """{law: its Contact fields}: the one --tangential-model names, or with ``auto`` every LAMMPS
    tangential law whose stiffness is given (linear_history with --tangential-stiffness, the four
    mindlin laws with --shear-modulus)."""
    if args.tangential_model != AUTO_TANGENTIAL:
        return {args.tangential_model: _lammps_tangential_fields(args, args.tangential_model)}
    laws = [law for law in DEM_TANGENTIAL_MODELS
            if (args.tangential_stiffness if law == "linear_history" else args.shear_modulus) is not None]
    if not laws:
        raise UsageError("--tangential-model auto needs --tangential-stiffness (for linear_history) and/or "
                         "--shear-modulus (for the mindlin laws)")
    return {law: _lammps_tangential_fields(args, law) for law in laws}


def _lammps_fit_friction(args, table, chosen):
    """(contact with the fitted mu, header note, the fit), or (None, None, the fit) after one line
    saying why mu is not determined; mu of LAMMPS's tangential law fitted to the oblique columns, the normal law fixed
    (with ``--tangential-model auto`` each law's, ranked by AIC, the best one written)."""
    laws = _lammps_tangential_laws(args)
    try:
        ranked, fits = rank_dem_tangential_laws(
            table, {law: (lambda r, f=f: chosen.contact(r).with_(**f)) for law, f in laws.items()}, normal_fit=chosen,
            stiffness_uncertainty=args.stiffness_uncertainty, rtol=args.rtol, progress=True)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    if len(laws) > 1 and not args.json:
        print(ranked[["law", "status", "friction", "interval_low", "interval_high", "chisqr", "delta_aic",
                      "akaike_weight"]].to_string(index=False, float_format=lambda x: f"{x:.6g}"))
    law = str(ranked["law"].iloc[0])
    fit = fits[law]
    if not args.json:
        print(fit.report())
    status = fit.identifiability["friction"]
    if not status.determined:
        print(f"microimpact: error: the oblique data do not determine the friction of LAMMPS's "
              f"{law} law ({status.describe()}); no LAMMPS input written", file=sys.stderr)
        return None, None, fit
    radius = float(np.median(np.asarray(table["radius"], dtype=float)))
    others = ", ".join(f"{o} dAIC {d:.3g}" for o, d in zip(ranked["law"].iloc[1:], ranked["delta_aic"].iloc[1:]))
    k = fit.info.get("stiffness_sensitivity")
    held = ("" if not k else f"; the stiffness profiled with its relative uncertainty {args.stiffness_uncertainty:g} "
            f"(best at {k['profiled_factor']:.4g} times the given)" if args.stiffness_uncertainty else
            f"; at the given stiffness, not fitted (mu {k['friction_low']:.6g} / {k['friction_high']:.6g} with it "
            f"{100 * k['step']:.0f}% lower / higher)")
    note = (f"{fit.friction:.6g} ({law}{'; best by AIC: ' + others if others else ''}; 95% profile-likelihood "
            f"interval {status.lower:.6g} to {status.upper:.6g}; the normal law's uncertainty included{held}; "
            f"{fit.n_points} oblique entries; {fit.verdict.text()})")
    return chosen.contact(radius).with_(friction=fit.friction, **laws[law]), note, fit


def run_fit(args) -> int:
    out = check_outputs({"--out": args.out}, input_files(args))["--out"]
    with time_limit(args.time_budget, "lammps fit"):
        return _run_fit(args, out)


def _check_fit_options(args) -> None:
    """UsageError for options of ``lammps fit`` that do not go together (before any fit runs)."""
    if args.tangential_model is None:
        given = [o for o, v in (("--tangential-stiffness", args.tangential_stiffness), ("--shear-modulus", args.shear_modulus),
                                ("--tangential-damping", args.tangential_damping or None),
                                ("--rolling-stiffness", args.rolling_stiffness),
                                ("--twisting-model", args.twisting_model)) if v is not None]
        if given:
            raise UsageError(f"{', '.join(given)} belong to a tangential law: give --tangential-model too")
    else:
        _lammps_tangential_laws(args)  # a missing stiffness is refused before the fits run
    if args.rolling_stiffness is None and (args.rolling_damping or args.rolling_friction):
        raise UsageError("--rolling-damping and --rolling-friction belong to LAMMPS's rolling sds: give --rolling-stiffness too")
    sds_twist = [o for o, v in (("--twisting-stiffness", args.twisting_stiffness), ("--twisting-damping", args.twisting_damping),
                                ("--twisting-friction", args.twisting_friction)) if v]
    if args.twisting_model == "lammps_sds" and args.twisting_stiffness is None:
        raise UsageError("--twisting-model lammps_sds needs --twisting-stiffness (k_twist [N m/rad])")
    if args.twisting_model != "lammps_sds" and sds_twist:
        raise UsageError(f"{', '.join(sds_twist)} belong to --twisting-model lammps_sds")
    if args.stiffness_uncertainty is not None and args.tangential_model is None:
        raise UsageError("--stiffness-uncertainty belongs to a tangential law: give --tangential-model too")
    if args.fit_adhesion and args.law and args.law[0] == "hertz":
        raise UsageError(f"--fit-adhesion: the law {'+'.join(args.law)} has no work of adhesion to fit; give a "
                         "jkr_force or dmt law, or no --law")
    if args.closest and args.tangential_model is not None:
        raise UsageError("--closest writes a rejected normal law; the friction of --tangential-model is fitted only "
                         "after a normal law that describes the data")


def _closest_message(closest, n_laws: int, out, written: bool) -> str:
    """The one error line of ``lammps fit`` when every law is rejected: which comes closest, by how
    much and where it misses most."""
    v = closest.verdict
    worst = max(closest.misfit_by_size(), key=lambda m: abs(m["largest_error"]))
    what = (f"wrote it to {out} as asked (--closest), its misfit in the header" if written
            else "no LAMMPS input written (--closest writes the closest law)")
    return (f"microimpact: error: no LAMMPS law describes these data ({n_laws} of {n_laws} rejected by the chi-square "
            f"test); closest: {closest.law}, chi^2/dof = {closest.chisqr / v.degrees_of_freedom:.4g} "
            f"(chi^2 = {closest.chisqr:.4g} for {v.degrees_of_freedom:.0f}, {_p_text(v.p_value)}), largest e_n error "
            f"{worst['largest_error']:+.3g} at {worst['speed']:.3g} m/s for radius {worst['radius'] * 1e6:.4g} um; {what}")


def _run_fit(args, out) -> int:
    _check_fit_options(args)
    table, pair = impacts_for_pair(args)
    laws = [args.law] if args.law else candidate_laws(pair, args.fit_adhesion)
    try:
        with progress_bar(len(laws), "LAMMPS laws fitted") as advance:
            ranked, fits = rank_dem_laws(table, pair, laws, fit_adhesion=args.fit_adhesion, weights=args.weights,
                                         rtol=args.rtol, progress=advance)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    adequate = ranked[ranked["status"] != "inadequate"]
    rejected = adequate.empty
    # the best law that describes the data; where none does, the closest (least AIC) of the rejected
    chosen = fits[str((ranked if rejected else adequate)["law"].iloc[0])]
    summary = {"laws": _law_records(ranked, fits), "all_rejected": bool(rejected), "chosen": chosen.law,
               "chosen_as": "closest of rejected laws" if rejected else "best by AIC of the laws that describe the data",
               "written": None}
    if not args.json:
        columns = ["law", "status", "value", "stderr", "interval_low", "interval_high"]
        if args.fit_adhesion:
            columns += ["adhesion_status", "work_of_adhesion", "w_low", "w_high"]
        shown = ranked[columns + ["chisqr", "chisqr_per_dof", "p_value", "verdict", "delta_aic", "akaike_weight"]]
        print(shown.to_string(index=False, float_format=lambda x: f"{x:.6g}"))
        print(("all rejected; closest " if rejected else "") + chosen.report())
    status = _fit_outcome(args, chosen, rejected, len(laws), out)
    if status is not None:
        _print_json(args, summary)
        return status
    radii = np.asarray(table["radius"], dtype=float)
    radius = float(np.median(radii))
    contact = chosen.contact(radius)
    friction_note = None
    if args.tangential_model is not None:  # the friction of LAMMPS's tangential law, from the oblique columns
        contact, friction_note, friction = _lammps_fit_friction(args, table, chosen)
        summary["friction"] = {"law": friction.tangential_model, "friction": friction.friction,
                               "status": friction.identifiability["friction"].status,
                               "interval": [friction.identifiability["friction"].lower,
                                            friction.identifiability["friction"].upper],
                               "verdict": friction.verdict.to_record()}
        if contact is None:
            _print_json(args, summary)
            return EXIT_DISAGREES
    source = fit_parameter_source(table.attrs.get("source", args.data), table.attrs.get("sha256"))
    others = ", ".join(f"{law} dAIC {d:.3g}" for law, d in zip(ranked["law"], ranked["delta_aic"]) if law != chosen.law)
    fitted = _header_values(chosen, rejected, others, friction_note, radius, radii)
    pair_name = getattr(pair, "name", None) or args.material_pair
    text = lammps_input(contact, units=args.units, source=f"{source}" + (f"; material pair {pair_name}" if pair_name else ""),
                        fitted=fitted, fit_record=_fit_record(chosen, rejected))
    with reporting_os_errors({"--out": out}), atomic_write(out) as f:
        f.write(text)
    summary["written"] = str(out)
    if rejected:  # written as asked; the status still says that no law describes the data
        print(_closest_message(chosen, len(laws), out, written=True), file=sys.stderr)
        _print_json(args, summary)
        return EXIT_DISAGREES
    _print_json(args, summary)
    if not args.json:
        print(f"wrote {out} (LAMMPS units {args.units}); check it with: microimpact lammps verify {out}")
    return 0


def _fit_outcome(args, chosen, rejected: bool, n_laws: int, out):
    """The exit status when nothing is to be written (and its one error line), else None."""
    if rejected:
        if args.closest:
            return None
        print(_closest_message(chosen, n_laws, out, written=False), file=sys.stderr)
        return EXIT_DISAGREES
    if chosen.determined:
        return None
    statuses = {"damping coefficient": chosen.status}
    if chosen.adhesion_fitted:
        statuses["work of adhesion"] = chosen.adhesion_status
    why = "the data do not determine its " + " or ".join(f"{name} ({st})" for name, st in statuses.items()
                                                          if st != "determined")
    print(f"microimpact: error: {chosen.law}, the best LAMMPS law by AIC of those that describe the data, {why}; "
          "no LAMMPS input written", file=sys.stderr)
    return EXIT_DISAGREES


def _law_records(ranked, fits) -> list:
    """Every law's :meth:`~microimpact.analysis.dem_fit.DemLawFit.record`, in rank order, with its dAIC
    and Akaike weight (``--json``)."""
    return [fits[law].record() | {"delta_aic": float(d), "akaike_weight": float(w)}
            for law, d, w in zip(ranked["law"], ranked["delta_aic"], ranked["akaike_weight"])]


def _print_json(args, summary) -> None:
    if args.json:
        print(json.dumps(_json_ready(summary), indent=2, allow_nan=False))


def _header_values(chosen, rejected: bool, others: str, friction_note, radius: float, radii) -> dict:
    """``{name: text}`` of the exported header: the values with their standard errors and 95 %
    intervals (of a rejected law: at the least chi^2, the interval conditional on it and widened),
    the law, the verdict and the misfit, the friction and the radius written."""
    v = chosen.verdict
    data = f"{chosen.n} impacts, {'stated e_n uncertainties' if chosen.sigma_known else 'scatter estimated'}"
    if rejected:
        lo, hi = chosen.widened_interval("coefficient")
        values = {"damping_coefficient": f"{chosen.best:.6g} at the least chi^2 of a REJECTED law (95% interval "
                                         f"conditional on it, widened x{v.widening:.3g}: {lo:.6g} to {hi:.6g}; {data})"}
        if chosen.adhesion_fitted:
            lo, hi = chosen.widened_interval("work_of_adhesion")
            values["work_of_adhesion"] = (f"{chosen.material['work_of_adhesion']:.6g} J/m^2 at the least chi^2 of the "
                                          f"rejected law (likewise {lo:.6g} to {hi:.6g})")
        law = f"{chosen.law} (closest of rejected laws, by AIC{'; ' + others if others else ''})"
    else:
        lo, hi = chosen.interval
        values = {"damping_coefficient": f"{chosen.value:.6g} (standard error {chosen.stderr:.3g}; 95% profile-likelihood "
                                         f"interval {lo:.6g} to {hi:.6g}; {data})"}
        if chosen.adhesion_fitted:
            lo, hi = chosen.work_of_adhesion_interval
            values["work_of_adhesion"] = (f"{chosen.work_of_adhesion:.6g} J/m^2 (standard error "
                                          f"{chosen.work_of_adhesion_stderr:.3g}; 95% profile-likelihood interval "
                                          f"{lo:.6g} to {hi:.6g}, the damping fitted jointly)")
        law = f"{chosen.law} (best by AIC of the laws that describe the data{'; ' + others if others else ''})"
    out = {**values, "law": law, "verdict": v.text()}
    if v.misfit_description:
        out["misfit"] = v.misfit_description
    for m in chosen.misfit_by_size() if rejected else ():
        out[f"misfit at radius {m['radius'] * 1e6:.4g} um"] = (
            f"largest e_n error {m['largest_error']:+.3g} (model - measured) at {m['speed']:.3g} m/s over "
            f"{m['speed_min']:.3g}-{m['speed_max']:.3g} m/s")
    if friction_note:
        out["friction"] = friction_note
    out["radius"] = f"{radius:.6g} m, the median of the data's radii ({radii.min():.4g} to {radii.max():.4g} m)"
    return out


def _fit_record(chosen, rejected: bool) -> dict:
    """The exported fit line (:data:`microimpact.io.lammps.FIT_RECORD_KEYS`): the law, its verdict,
    and every radius of the data with its speed range, which ``lammps verify`` checks."""
    v = chosen.verdict
    return {"law": chosen.law, "verdict": v.verdict, "chi_square": v.chi_square, "degrees_of_freedom": v.degrees_of_freedom,
            "p_value": v.p_value, "misfit": v.misfit_description[:2000], "closest_of_rejected": bool(rejected),
            "data": [{k: m[k] for k in ("radius", "speed_min", "speed_max", "impacts", "largest_error", "speed")}
                     for m in chosen.misfit_by_size()]}


def verify_grid(export, args) -> tuple[tuple, dict | tuple]:
    """(radii, speeds) ``lammps verify`` runs: every radius of the fitted data (the file's fit line)
    over its measured normal-speed range, ``--points`` speeds spaced geometrically from its lowest to
    its highest (``--speed-range LO HI``: that range at every radius; ``--speeds``: those speeds at
    every radius); a file without a fit line: its own radius at ``--speeds`` or the default grid."""
    ranges = export.data_ranges
    if not ranges:
        grid = args.speeds or (args.speed_range and tuple(np.geomspace(*args.speed_range, args.points)))
        return (export.contact.radius,), tuple(grid or default_speeds(export.contact))
    radii = tuple(r for r, _, _ in ranges)
    if args.speeds:
        return radii, tuple(args.speeds)
    return radii, {r: tuple(float(v) for v in np.geomspace(*(args.speed_range or (lo, hi)), 1 if lo == hi and not args.speed_range
                                                               else args.points))
                   for r, lo, hi in ranges}


def run_verify(args) -> int:
    out = check_outputs({"--out": args.out}, {"input file": args.input})["--out"] if args.out else None
    path = check_input_file("input file", args.input)
    if args.speed_range and not 0.0 < args.speed_range[0] <= args.speed_range[1]:
        raise UsageError(f"--speed-range: LO must be > 0 and <= HI, got {args.speed_range[0]:g} {args.speed_range[1]:g}")
    if args.speed_range and args.speeds:
        raise UsageError("--speed-range and --speeds: give one")
    try:
        with open(path, encoding="utf-8", newline="") as f:  # a carriage return stays one, to be refused
            text = f.read()
    except UnicodeDecodeError:
        raise UsageError(f"input file {path}: the file is {file_kind(path)}, not a LAMMPS input written by "
                         "'microimpact lammps export'") from None
    try:
        export = read_lammps_export(text)
    except ValueError as exc:
        raise UsageError(f"input file {path}: {exc}") from None
    contact = export.contact
    radii, speeds = verify_grid(export, args)
    # the fitted data are normal impacts: without friction an oblique impact is the normal one at its
    # normal speed, so a fitted frictionless law is checked at normal incidence unless asked
    incidences = args.incidence_deg or ((0.0,) if export.fit and contact.friction == 0.0 else DEFAULT_INCIDENCES)
    n_impacts = len(incidences) * (sum(len(v) for v in speeds.values()) if isinstance(speeds, dict)
                                   else len(radii) * len(speeds))
    try:
        with time_limit(args.time_budget, "lammps verify"), \
                progress_bar(n_impacts, "LAMMPS impacts") as advance:
            # the file's own text is never run: verify_lammps rebuilds its one command from the parsed contact
            table = verify_lammps(text, speeds=speeds, incidences=incidences, steps=args.steps,
                                  tolerance=args.tolerance, progress=advance, radii=radii)
    except LammpsRunError as exc:
        raise UsageError(f"input file {path}, line {export.fix_line_number} (its fix wall/gran command): {exc}") from None
    if out is not None:
        with reporting_os_errors({"--out": out}):
            write_csv(table, out, index=False)
    columns = ["radius", "speed", "incidence_deg", "outcome_lammps", "e_n_microimpact", "e_n_lammps"]
    if contact.friction > 0.0:  # the tangential restitution too (the spin ratio is in the --out table)
        columns += ["e_t_microimpact", "e_t_lammps"]
    shown = table[columns + ["difference", "step_error", "agrees"]]
    print(shown.to_string(index=False, float_format=lambda v: f"{v:.7g}"))
    worst = table["difference"].max()
    where = (f" at {len(radii)} radii {min(radii) * 1e6:.4g}-{max(radii) * 1e6:.4g} um" if len(radii) > 1
             else f" at radius {radii[0] * 1e6:.4g} um")
    where += f", speeds {table['speed'].min():.4g}-{table['speed'].max():.4g} m/s"
    if export.fit and not args.speeds and not args.speed_range:
        where += " (the fitted data's radii and measured speed ranges)"
    if export.fit and export.fit["closest_of_rejected"]:
        where += f"; note: the law is the closest of rejected laws ({export.fit['verdict']})"
    print(f"LAMMPS {table.attrs['lammps_version']} on {path.name}: {int(table['agrees'].sum())} of {len(table)} impacts "
          f"agree within {args.tolerance:g}{where} (largest difference {worst:.2e}, largest LAMMPS step error "
          f"{table['step_error'].max():.2e})" + (f"; wrote {out}" if out else ""))
    if not table.attrs["passed"]:
        print(f"microimpact: error: LAMMPS and microimpact disagree on {int((~table['agrees']).sum())} impacts "
              f"of {path.name}", file=sys.stderr)
        return EXIT_DISAGREES
    return 0
