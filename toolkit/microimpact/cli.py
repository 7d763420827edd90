"""Command line: ``microimpact simulate | sweep | fit | flags | target | reproduce | benchmark | plot | workflow | lammps``.

Thin: parse, call the library, print or write. Exit statuses: 0 success; 2 bad arguments, inputs
or a solver failure (one line ``microimpact: error: ...`` on stderr); 3 the computation ran past
``--time-budget SECONDS`` (``fit``, ``flags``, ``sweep``, ``target``, ``reproduce``, ``benchmark``; one
such line naming the budget); 141, quietly, when the reader of stdout went away (``| head``). Nothing is written on an
error: outputs are written, atomically, only after the work.

Each command imports the part of the library it runs inside its own function: ``microimpact
--help`` or ``microimpact simulate`` then never loads lmfit, pandas or the report, which keeps the
start-up short. Defaults (the preset, the Table 2 grids, rtol) come from the library's one home
of each: :mod:`microimpact.model.parameters`, :data:`microimpact.solvers.DEFAULT_RTOL`.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys
from dataclasses import fields
from pathlib import Path

from microimpact import __version__
from microimpact._runtime.signals import (EXIT_INTERRUPTED, INTERRUPTED_LINE, interpreted_budget_over,
                                         interrupted_after_writing)
from microimpact._runtime.usage import exit_status
from microimpact.io.paths import (PathError, check_input_file, check_output_dir, check_outputs,
                                  reporting_os_errors, same_file)
from microimpact.model.contact import SUB_MODELS, Contact
from microimpact.model.dem_tangential import DEM_TANGENTIAL_MODELS
from microimpact.model.dem_twisting import DEM_TWISTING_MODELS
from microimpact.model.parameters import TABLE2_CASES
from microimpact.presets import PRESETS, get_preset
from microimpact.solvers import DEFAULT_RTOL, METHODS, TimeBudgetExceeded

__all__ = ["main", "build_parser"]


class UsageError(Exception):
    """A user error: reported in one line, exit status 2."""


#: exit status of a computation that ran past its ``--time-budget`` (2 is a usage or solver error)
EXIT_TIME_BUDGET = 3
#: exit status when the reader of stdout closed it early (``| head``): 128 + SIGPIPE, as a POSIX
#: tool killed by the signal reports it; nothing is printed
EXIT_BROKEN_PIPE = 141

#: a negative number as an option's value: ``--radius -1e-6``, ``--omega-n -.5``, ``--speed -inf``.
#: argparse's own pattern (``^-\d+$|^-\d*\.\d+$``) misses exponents and inf/nan, so that
#: ``--radius -1e-6`` was read as an unknown option ("expected one argument"); no option of this
#: command line starts with a digit, so every such word is a value.
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # the one hook argparse has for this (an attribute of every parser, used by parse_args)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message):  # one line, status 2, as argparse does, but without the usage dump
        raise UsageError(message)


def _finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"not a finite number: {text!r}")
    return value


def _positive_float(text: str) -> float:
    value = _finite_float(text)
    if value <= 0.0:
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value


def _non_negative_float(text: str) -> float:
    value = _finite_float(text)
    if value < 0.0:
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text!r}")
    return value


def _relative_uncertainty(text: str) -> float:
    value = _finite_float(text)
    if not 0.0 <= value < 0.5:
        raise argparse.ArgumentTypeError(f"must be a relative standard uncertainty in [0, 0.5), got {text!r}")
    return value


def _rtol(text: str) -> float:
    from microimpact.solvers.impact import check_rtol

    try:
        return check_rtol(_finite_float(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


CONTACT_FIELDS = [f.name for f in fields(Contact)]


def add_contact_options(p: argparse.ArgumentParser) -> None:
    """The material: --preset, or --fit FIT.nc, or --material-pair NAME (with --config); then one
    option per Contact field (SI units) that overrides it, and --work-of-adhesion."""
    p.add_argument("--preset", default=None, help=f"parameter preset ({', '.join(sorted(PRESETS))}); default wall1990")
    p.add_argument("--fit", default=None, metavar="FIT_NC",
                   help="use the fitted material of a fit written by 'microimpact fit' (zeta_H, zeta_A, w_A, friction; "
                        "f0 from w_A by Eq. (7) at --radius)")
    p.add_argument("--material-pair", default=None, metavar="NAME",
                   help="use a material pair of the materials config (f0 from its w_A by Eq. (7) at --radius)")
    p.add_argument("--config", default=None, help="materials config YAML for --material-pair (default: the bundled one)")
    p.add_argument("--work-of-adhesion", type=_positive_float, default=None, metavar="SI",
                   help="work of adhesion w_A [J/m2]: f0 from it by Eq. (7) (instead of the material's)")
    for name in CONTACT_FIELDS:
        if name in SUB_MODELS:
            p.add_argument(f"--{name.replace('_', '-')}", choices=SUB_MODELS[name], default=None,
                           help=f"sub-model (default {SUB_MODELS[name][0]}, the paper's)")
            continue
        p.add_argument(f"--{name.replace('_', '-')}", type=_finite_float, default=None, metavar="SI",
                       help=f"override Contact.{name} (SI units)" + (
                           "; the material is kept: f0 follows the radius by Eq. (7) unless "
                           "--adhesion-line-force is given" if name == "radius" else ""))


def _base_material(args):
    """(material, label): the preset Contact, a DampingFit or a MaterialPair, as the options say."""
    given = [o for o, v in (("--preset", args.preset), ("--fit", args.fit), ("--material-pair", args.material_pair))
             if v is not None]
    if len(given) > 1:
        raise UsageError(f"{' and '.join(given)} both name the material; give one of them")
    if args.config is not None and args.material_pair is None:
        raise UsageError("--config is read only with --material-pair")
    if args.fit is not None:
        from microimpact.analysis.fit_result import DampingFit

        path = check_input_file("--fit", args.fit)
        try:
            fit = DampingFit.load(path)
        except ValueError as exc:
            raise UsageError(f"--fit {args.fit}: {exc}") from None
        undetermined = [st.describe() for st in fit.identifiability.values() if not st.determined]
        if undetermined:
            print(f"microimpact: note: --fit {args.fit}: " + "; ".join(undetermined)
                  + "; its stored values are used", file=sys.stderr)
        return fit, f"fit {path.name} ({fit.parameter_source})"
    if args.material_pair is not None:
        from microimpact.io import default_materials_path, read_materials

        config = check_input_file("--config", args.config) if args.config else default_materials_path()
        pairs = read_materials(config)
        if args.material_pair not in pairs:
            raise UsageError(f"--material-pair {args.material_pair!r} is not in {config}; known: {', '.join(pairs)}")
        return pairs[args.material_pair], f"material pair {args.material_pair} of {config}"
    name = args.preset or "wall1990"
    return get_preset(name), f"preset {name}"


def contact_from_args(args) -> Contact:
    """The contact the options describe; ``args.contact_note`` says where f0 came from.

    The material is kept at every size: with --radius (or --stiffness) but no --adhesion-line-force,
    f0 follows from the material's work of adhesion by Eq. (7) (Cheng, Brach & Dunn 2002), as a fit
    over several sizes assumes; --adhesion-line-force sets it explicitly. ValueError names a bad field.
    """
    from microimpact.model.contact import adhesion_line_force_from_work

    material, label = _base_material(args)
    changes = {n: getattr(args, n) for n in CONTACT_FIELDS if getattr(args, n, None) is not None}
    replaced = ""
    if changes.get("damping_model", "paper") != "paper":
        # a DEM damping law replaces the paper's damping of the material, said in the note
        dropped = {n: None if n == "damping_reference_speed" else 0.0
                   for n in ("zeta_hertz", "zeta_adhesion", "damping_reference_speed") if n not in changes}
        changes = dropped | changes
        replaced = f"; damping_model {changes['damping_model']} replaces the paper's damping (zeta_H = zeta_A = 0)"
    radius = changes.get("radius")
    if isinstance(material, Contact):
        base = material
    else:  # a fit or a material pair: a contact exists only at a radius
        sizes = getattr(material, "radii", None)
        if radius is None and sizes is not None and len(sizes) == 1:
            radius = float(sizes[0])
        if radius is None:
            known = f" (the fit's sizes: {', '.join(f'{r:.4g}' for r in sizes)} m)" if sizes is not None else ""
            raise UsageError(f"give --radius with {'--fit' if args.fit else '--material-pair'}{known}")
        from microimpact.io.materials import material_contact

        base = material_contact(material, radius)
    w_a = args.work_of_adhesion if args.work_of_adhesion is not None else base.work_of_adhesion
    if "adhesion_line_force" in changes:
        if args.work_of_adhesion is not None:
            raise UsageError("--adhesion-line-force and --work-of-adhesion both set f0; give one of them")
        contact = base.with_(**changes)
        note = f"f0 = {contact.adhesion_line_force:.6g} N/m given on the command line"
    elif changes.keys() & {"radius", "stiffness"} or args.work_of_adhesion is not None:
        c = base.with_(**changes)
        contact = c.with_(adhesion_line_force=adhesion_line_force_from_work(c.stiffness, c.radius, w_a))
        note = (f"f0 = {contact.adhesion_line_force:.6g} N/m from w_A = {w_a:.6g} J/m2 by Eq. (7) at "
                f"r = {contact.radius:.6g} m")
    else:
        contact = base.with_(**changes) if changes else base
        note = f"f0 = {contact.adhesion_line_force:.6g} N/m of the material"
    args.contact_note = f"{label}; {note}{replaced}"
    return contact


def contact_record(contact: Contact, note: str) -> dict:
    """Every Contact field (SI units, sub-models by name), the work of adhesion and where f0 came from."""
    out = {f.name: getattr(contact, f.name) for f in fields(Contact)}
    return out | {"work_of_adhesion": contact.work_of_adhesion, "source": note}


def _cmd_simulate(args) -> int:
    from microimpact.solvers.impact import simulate_impact

    contact = contact_from_args(args)
    result = simulate_impact(contact, args.speed, args.incidence_deg, args.azimuth_deg,
                             (args.omega_n, args.omega_t, args.omega_tp), rtol=args.rtol, method=args.method)
    interpreted_budget_over()
    record = contact_record(contact, args.contact_note)
    if args.json:
        print(json.dumps(result.to_dict() | {"contact": record}, indent=2))
    else:
        d = result.to_dict() | {f"contact.{k}": v for k, v in record.items()}
        width = max(map(len, d))
        for k, v in d.items():
            print(f"{k:<{width}}  {v}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The parser of the ``microimpact`` command line: one sub-command per command, each with its
    function as ``func``; an error raises ``UsageError`` (one line) instead of exiting.

    Examples
    --------
    Defaults fill what is not given, a negative number is a value, not an option, and a
    required option that is missing is named:

    >>> parser = build_parser()
    >>> args = parser.parse_args(["simulate", "--speed", "2", "--radius", "-1e-6"])
    >>> args.speed, args.radius, args.incidence_deg, args.method, args.func.__name__
    (2.0, -1e-06, 0.0, 'engine', '_cmd_simulate')
    >>> parser.parse_args(["simulate", "--speed", "-2"])
    Traceback (most recent call last):
    ...
    microimpact.cli.UsageError: argument --speed: must be a finite number > 0, got '-2'
    >>> parser.parse_args(["simulate"])
    Traceback (most recent call last):
    ...
    microimpact.cli.UsageError: the following arguments are required: --speed
    """
    parser = _Parser(prog="microimpact", description="Microsphere contact/impact with smooth, flat surfaces.",
                     epilog=f"Exit status: 0 success; 2 bad arguments or inputs, or a solver failure; "
                            f"{EXIT_TIME_BUDGET} the computation ran past --time-budget (fit, flags, sweep, "
                            "target, reproduce, benchmark); 141 (quietly) when stdout is closed early (| head). "
                            "Nothing is written on an error.")
    parser.add_argument("--version", action="version", version=f"microimpact {__version__}")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser)

    p = sub.add_parser("simulate", help="simulate one impact")
    add_contact_options(p)
    p.add_argument("--speed", type=_positive_float, required=True, help="incident speed [m/s]")
    p.add_argument("--incidence-deg", type=_finite_float, default=0.0, help="angle from the normal [deg]")
    p.add_argument("--azimuth-deg", type=_finite_float, default=0.0, help="azimuth in the tangent plane [deg]")
    p.add_argument("--omega-n", type=_finite_float, default=0.0, help="initial spin about n [rad/s]")
    p.add_argument("--omega-t", type=_finite_float, default=0.0, help="initial spin about t [rad/s]")
    p.add_argument("--omega-tp", type=_finite_float, default=0.0, help="initial spin about t' [rad/s]")
    _add_rtol(p)
    p.add_argument("--method", choices=METHODS, default="engine", help="solver (default engine)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=_cmd_simulate)

    for register in (register_sweep, register_fit, register_flags, register_target, register_reproduce,
                     register_benchmark, register_plot, register_workflow, register_lammps):
        register(sub)
    return parser


def _add_time_budget(p: argparse.ArgumentParser) -> None:
    p.add_argument("--time-budget", type=_positive_float, default=None, metavar="SECONDS",
                   help=f"stop with exit status {EXIT_TIME_BUDGET}, writing nothing, once the computation has run "
                        "this long (wall clock; default: no limit)")


def _add_rtol(p: argparse.ArgumentParser) -> None:
    p.add_argument("--rtol", type=_rtol, default=DEFAULT_RTOL,
                   help=f"relative tolerance of the normal solves (default {DEFAULT_RTOL:g})")


# ------------------------------------------------------------------ fit, flags (microimpact.analysis.fitting, .diagnostics)
def _inputs(args) -> dict:
    """The input files a command reads (option name -> path), each an existing readable file; the
    bundled materials config counts as an input when no --config is given."""
    from microimpact.io.materials import default_materials_path

    given = {"data file": getattr(args, "data", None), "--config": args.config, "--fit": getattr(args, "fit", None)}
    inputs = {name: check_input_file(name, path) for name, path in given.items() if path is not None}
    if args.config is None:
        inputs["the bundled materials config"] = default_materials_path()
    return inputs


def _impacts_for_pair(args):
    """Read the impact CSV (validated against the materials config) and pick the material pair."""
    from microimpact.io import default_materials_path, material_pairs, read_impacts, read_materials, select_material_pair

    data = check_input_file("data file", args.data)
    config = check_input_file("--config", args.config) if args.config else default_materials_path()
    pairs = read_materials(config)
    table = read_impacts(data, materials=pairs)
    labels = material_pairs(table)
    name = args.material_pair or (labels[0] if len(labels) == 1 else None)
    if name is None:
        raise UsageError(f"{data}: give --material-pair (the file has {'pairs ' + ', '.join(labels) if labels else 'no material_pair column'})")
    if name not in pairs:
        raise UsageError(f"unknown material pair {name!r}; known pairs in {config}: {', '.join(pairs)}")
    try:  # unlabelled rows belong to the named pair
        return select_material_pair(table, name, default=name), pairs[name]
    except ValueError as e:
        raise UsageError(str(e)) from None


def _cmd_fit(args) -> int:
    from microimpact.analysis.analyst_fit import analyse_impacts

    outputs = check_outputs({"--out": args.out, "--posterior": args.posterior, "--oblique-out": args.oblique_out},
                            _inputs(args))
    out = outputs["--out"]
    posterior = False
    unused = [f"--{name.replace('_', '-')}" for name in ("walkers", "steps", "max_steps", "seed")
              if getattr(args, name) is not None]
    if outputs.get("--posterior") is None and unused:
        raise UsageError(f"{', '.join(unused)} set the posterior's sampler, which runs only with --posterior FILE")
    if outputs.get("--posterior") is not None:
        if args.full_chain:
            raise UsageError("--full-chain was removed: the default chain now runs until it converges; "
                             "--max-steps bounds it")
        posterior = {"walkers": args.walkers, "steps": args.steps, "max_steps": args.max_steps, "seed": args.seed}
        from microimpact.analysis.posterior import DEFAULT_MAX_STEPS, DEFAULT_WALKERS, check_posterior_memory

        try:  # before the fit: the most parameters a chain can have (zeta_H, zeta_A, w_A, f)
            check_posterior_memory(args.walkers or DEFAULT_WALKERS, args.steps or args.max_steps or DEFAULT_MAX_STEPS, 4)
        except ValueError as exc:
            raise UsageError(f"--walkers/--steps/--max-steps: {exc}") from None
    table, pair = _impacts_for_pair(args)
    print(f"fitting {len(table)} impacts of {pair.name} ...", file=sys.stderr, flush=True)
    result = analyse_impacts(table, pair, fit_work_of_adhesion=args.fit_work_of_adhesion, weights=args.weights,
                             confidence_intervals=not args.no_confidence_intervals, posterior=posterior,
                             errors_in_variables=args.errors_in_variables, rtol=args.rtol, progress=True,
                             time_budget=args.time_budget)
    with reporting_os_errors(outputs):
        written = result.save(out, outputs.get("--posterior"), outputs.get("--oblique-out"))
    if args.json:
        print(json.dumps(_json_ready(_fit_summary(result, table, pair, written)), indent=2, allow_nan=False))
    else:
        print(result.report())
    print("wrote " + ", ".join(map(str, written)), file=sys.stderr)
    return 0


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
                out[name] = st.to_record(fit.stderr.get(name, float("nan")))
            else:  # fixed: the given material's value
                out[name] = {"status": "fixed", "value": float(value)}
        return out

    d = result.damping
    summary = {"material_pair": pair.name, "n_points": int(len(table)),
               "damping": {"parameters": parameters(d), "chisqr": float(d.chisqr), "redchi": float(d.redchi)},
               "written": [str(p) for p in written]}
    if result.friction is not None:
        summary["friction"] = {"parameters": parameters(result.friction), "tangential_model": result.friction.tangential_model}
    if result.posterior is not None:
        steps, walkers, _ = result.posterior.chain.shape
        summary["posterior"] = {"converged": result.posterior.converged, "walkers": walkers, "steps": steps,
                                "burn": int(result.posterior.burn), "seed": int(result.posterior.seed)}
    return summary


def register_fit(sub) -> None:
    """``microimpact fit DATA.csv --out fit.nc``: fit zeta_H, zeta_A (and w_A) to e_n(v_n)."""
    p = sub.add_parser("fit", help="fit the damping coefficients to measured e_n(v_n)")
    p.add_argument("data", help="measured-impact CSV (data/README.md, 'Measured-impact CSV format')")
    p.add_argument("--config", help="materials config YAML (default: the bundled one)")
    p.add_argument("--material-pair", help="material pair to fit: its rows, and the rows without a material_pair cell (default: the file's only pair)")
    p.add_argument("--fit-work-of-adhesion", action="store_true", help="also fit w_A (shared by all radii)")
    p.add_argument("--weights", choices=("auto", "e_n", "none"), default="auto", help="weighting (default auto)")
    p.add_argument("--no-confidence-intervals", action="store_true", help="skip lmfit.conf_interval (faster)")
    _add_rtol(p)
    p.add_argument("--out", required=True, help="output NetCDF of the fit")
    p.add_argument("--json", action="store_true", help="print the results as JSON instead of the text report")
    _add_posterior_options(p)
    _add_time_budget(p)
    p.set_defaults(func=_cmd_fit)


def _add_posterior_options(p: argparse.ArgumentParser) -> None:
    """The posterior and oblique options of ``microimpact fit`` (microimpact.analysis.analyst_fit)."""
    from microimpact.analysis.sampling_defaults import DEFAULT_MAX_STEPS, DEFAULT_SEED, DEFAULT_WALKERS, MAX_SEED

    p.add_argument("--posterior", default=None, metavar="NC",
                   help="also sample the posterior (emcee, seeded) until it converges (50 autocorrelation times, "
                        "R-hat < 1.01, ESS >= 400) and write chain, diagnostics and bands to this NetCDF; a chain "
                        "that collapses or does not converge is an error (exit status 2, nothing written)")
    p.add_argument("--walkers", type=_positive_int, default=None, help=f"emcee walkers (default {DEFAULT_WALKERS})")
    p.add_argument("--max-steps", type=_positive_int, default=None,
                   help=f"most steps before an unconverged chain is an error (default {DEFAULT_MAX_STEPS})")
    p.add_argument("--steps", type=_positive_int, default=None,
                   help="run exactly this many steps (default: until converged); still an error if not converged")
    p.add_argument("--seed", type=_seed, default=None, help=f"seed of the sampler, 0 to {MAX_SEED} (default {DEFAULT_SEED})")
    p.add_argument("--full-chain", action="store_true", help=argparse.SUPPRESS)  # removed: refused with a message
    p.add_argument("--errors-in-variables", choices=("auto", "effective", "latent"), default="auto",
                   help="speed errors in the posterior: effective variance, latent true speeds, or auto (latent near "
                        "capture)")
    p.add_argument("--oblique-out", default=None, metavar="NC",
                   help="write the friction fit (oblique columns: measured vs fitted per row) to this NetCDF")


def _whole_number(text: str, smallest: int) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if value < smallest:
        raise argparse.ArgumentTypeError(f"must be a whole number >= {smallest}, got {text!r}")
    return value


def _non_negative_int(text: str) -> int:
    return _whole_number(text, 0)


def _seed(text: str) -> int:
    from microimpact.analysis.sampling_defaults import MAX_SEED

    value = _whole_number(text, 0)
    if value > MAX_SEED:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_SEED} (the posterior file stores it as a 32-bit "
                                         f"integer), got {text!r}")
    return value


def _positive_int(text: str) -> int:
    return _whole_number(text, 1)


def _cmd_flags(args) -> int:
    from microimpact.analysis.flags import flag_measurements, write_flags
    from microimpact.analysis.fit_result import DampingFit

    inputs = _inputs(args) | ({"--posterior": check_input_file("--posterior", args.posterior)} if args.posterior else {})
    outputs = check_outputs({"--out": args.out, "--nc": args.nc}, inputs)
    out, nc = outputs["--out"], outputs.get("--nc")
    try:
        fit = DampingFit.load(args.fit)
    except ValueError as exc:
        raise UsageError(f"--fit {args.fit!r}: {exc}") from None
    posterior = _load_posterior(args.posterior)
    table, _ = _impacts_for_pair(args)
    ds = flag_measurements(table, fit, spin_bound=args.spin_bound, angle_uncertainty_deg=args.angle_uncertainty_deg,
                           rtol=args.rtol, progress=True, posterior=posterior, time_budget=args.time_budget)
    with reporting_os_errors(outputs):
        write_flags(ds, out, nc)
    from microimpact.analysis.flags import flag_summary

    print(flag_summary(ds) + f"; wrote {out}" + (f" and {nc}" if nc else ""))
    return 0


def _load_posterior(path):
    """The Posterior of a ``microimpact fit --posterior`` file, or None."""
    if path is None:
        return None
    from microimpact.analysis.posterior import load_posterior

    check_input_file("--posterior", path)
    try:
        return load_posterior(path)
    except (KeyError, ValueError, OSError) as exc:
        raise UsageError(f"--posterior {exc}") from None


def register_flags(sub) -> None:
    """``microimpact flags DATA.csv --fit fit.nc --out flags.csv``: per-measurement flags."""
    p = sub.add_parser("flags", help="flag impacts sensitive to unmeasured spin, angle error, or near capture")
    p.add_argument("data", help="measured-impact CSV")
    p.add_argument("--fit", required=True, help="fit NetCDF written by 'microimpact fit'")
    p.add_argument("--config", help="materials config YAML (default: the bundled one)")
    p.add_argument("--material-pair", help="material pair (default: the file's only pair)")
    p.add_argument("--out", required=True, help="output CSV, one row per impact keyed by 'row'")
    p.add_argument("--nc", help="also write the flags as NetCDF")
    p.add_argument("--spin-bound", type=_non_negative_float, default=None, metavar="RAD_S",
                   help="largest initial spin sampled [rad/s] (default: speed / radius per impact)")
    p.add_argument("--angle-uncertainty-deg", type=_non_negative_float, default=None, metavar="DEG",
                   help="incidence-angle uncertainty [deg] (default: the file's column, else 2)")
    p.add_argument("--posterior", default=None, metavar="NC",
                   help="posterior NetCDF of 'microimpact fit --posterior': flags and spin ranges over its draws")
    _add_rtol(p)
    _add_time_budget(p)
    p.set_defaults(func=_cmd_flags)


# ------------------------------------------------------------------ target (microimpact.analysis.target)
def _cmd_target(args) -> int:
    from microimpact.analysis.target import damping_from_target

    if len(args.e_n) != len(args.speed):
        raise UsageError(f"give as many --speed as --e-n values (got {len(args.speed)} and {len(args.e_n)})")
    out = check_outputs({"--out": args.out}, _inputs(args))["--out"] if args.out else None
    if out is not None and not str(out).endswith((".csv", ".nc")):
        raise UsageError(f"--out {args.out!r}: the output must end in .csv or .nc")
    from microimpact.analysis.target import check_target_memory

    check_target_memory(args.points, len(args.e_n), what=f"--points {args.points} for {len(args.e_n)} target(s)")
    contact = contact_from_args(args)
    res = damping_from_target(args.e_n, args.speed, contact, e_n_uncertainty=args.e_n_uncertainty,
                              n_points=args.points, rtol=args.rtol, time_budget=args.time_budget)
    c = res.curves
    for i, row in res.targets.iterrows():
        zh, za = c["zeta_hertz"].values[i], c["zeta_adhesion"].values[i]
        print(f"target {i + 1}: e_n = {row['e_n']:g} at v_n = {row['speed']:g} m/s (r = {row['radius']:.4g} m): "
              f"zeta_H from {zh[0]:.5g} (zeta_A = 0) to 0 (zeta_A = {za[-1]:.5g}); {len(zh)} curve points")
    if res.best is not None:
        from microimpact.io.statuses import stderr_is_meaningful

        exact = len(res.targets) <= len(res.best)  # no degrees of freedom left: nothing to estimate an error from
        print("least squares over the targets: " + ", ".join(
            f"{k} = {v:.6g}" + ("" if exact else f" +/- {res.stderr[k]:.3g}" if stderr_is_meaningful(v, res.stderr[k])
                                else " (standard error above 100 %: not determined by these targets)")
            for k, v in res.best.items())
            + (f" (exact: {len(res.targets)} targets for {len(res.best)} parameters, no uncertainty)" if exact else ""))
    print(f"material: {args.contact_note}", file=sys.stderr)
    if out is not None:
        with reporting_os_errors({"--out": out}):
            res.save(out)
        print(f"wrote {out}", file=sys.stderr)
    else:
        print(res.to_frame().to_csv(index=False, float_format="%.8g"), end="")
    return 0


def register_target(sub) -> None:
    """``microimpact target --e-n 0.6 --speed 2.0 [--out curve.csv]``: damping that reproduces a measured e_n."""
    p = sub.add_parser("target", help="zeta_H, zeta_A that reproduce measured e_n at given speeds (a curve for one point)")
    add_contact_options(p)
    p.add_argument("--e-n", type=_finite_float, nargs="+", required=True, help="target e_n value(s), each in (0, 1)")
    p.add_argument("--speed", type=_positive_float, nargs="+", required=True, help="normal speed of each target [m/s]")
    p.add_argument("--e-n-uncertainty", type=_positive_float, nargs="+", default=None,
                   help="standard uncertainty of each target e_n (weights of the least-squares point)")
    p.add_argument("--points", type=_positive_int, default=41, help="points per curve (default 41, >= 3)")
    _add_rtol(p)
    p.add_argument("--out", default=None, help="write the curve(s): .csv (one row per point) or .nc; default: print CSV")
    _add_time_budget(p)
    p.set_defaults(func=_cmd_target)


def _cmd_sweep(args) -> int:
    from microimpact.io.files import write_netcdf
    from microimpact.studies.sweeps import run_sweep

    if args.case not in TABLE2_CASES:
        raise UsageError(f"argument --case: unknown case {args.case!r}; known: {', '.join(TABLE2_CASES)}")
    out = check_outputs({"--out": args.out}, _inputs(args))["--out"]
    contact = contact_from_args(args)
    ds = run_sweep(contact, case=args.case, rtol=args.rtol, progress=True, time_budget=args.time_budget)
    ds.attrs["contact_source"] = args.contact_note
    with reporting_os_errors({"--out": out}):
        write_netcdf(ds, out)
    grid = " x ".join(f"{n} {dim}" for dim, n in ds.sizes.items())
    print(f"case {args.case}: {math.prod(ds.sizes.values())} impacts ({grid}), {int(ds['outcome'].sum())} captured; "
          f"wrote {out}")
    print(f"material: {args.contact_note}")
    return 0


def register_sweep(sub) -> None:
    """``microimpact sweep --case 2.1 --out case.nc``: one Table 2 sweep to NetCDF."""
    p = sub.add_parser("sweep", help="run one of the Table 2 sweeps (2.1-2.5) and write NetCDF")
    add_contact_options(p)
    p.add_argument("--case", required=True, help=f"Table 2 case: {', '.join(TABLE2_CASES)} (grids: microimpact.model.parameters)")
    _add_rtol(p)
    p.add_argument("--out", required=True, help="output NetCDF")
    _add_time_budget(p)
    p.set_defaults(func=_cmd_sweep)


def _cmd_reproduce(args) -> int:
    from microimpact.studies.reproduction import reproduction_table, write_reproduction_markdown

    out = check_outputs({"--out": args.out})["--out"]
    table = reproduction_table(time_budget=args.time_budget)
    with reporting_os_errors({"--out": out}):
        write_reproduction_markdown(table, out)
    print(f"wrote {out}")
    return 0


def register_reproduce(sub) -> None:
    """``microimpact reproduce --out docs/reproduction.md``: the paper-versus-toolkit table."""
    p = sub.add_parser("reproduce", help="write the table of the paper's claims against the toolkit (Markdown)")
    p.add_argument("--out", required=True, help="output Markdown file")
    _add_time_budget(p)
    p.set_defaults(func=_cmd_reproduce)



# ------------------------------------------------------------------ lammps (microimpact.io.lammps, .studies.lammps_check)
#: exit status of ``lammps verify`` when LAMMPS and microimpact disagree (2 is a usage or solver error)
EXIT_DISAGREES = 1


def _fitted_values(path) -> dict:
    """``{parameter: "value (stderr s)"}`` of the varied parameters of a fit file, for a header."""
    from microimpact.analysis.fit_result import DampingFit

    fit = DampingFit.load(path)
    return {name: f"{fit.values[name]:.6g} (standard error {fit.stderr.get(name, float('nan')):.3g}); "
                  f"{fit.parameter_source}" for name in fit.varied}


def _cmd_lammps_export(args) -> int:
    from microimpact.io.files import atomic_write
    from microimpact.io.lammps import lammps_input

    inputs = {"--fit": args.fit, "--config": args.config}
    out = check_outputs({"--out": args.out}, {k: v for k, v in inputs.items() if v is not None})["--out"]
    contact = contact_from_args(args)
    text = lammps_input(contact, units=args.units, poisson=args.poisson, wall=args.wall, source=args.contact_note,
                        fitted=_fitted_values(args.fit) if args.fit else None)
    with reporting_os_errors({"--out": out}), atomic_write(out) as f:
        f.write(text)
    print(f"wrote {out} (LAMMPS units {args.units}); check it with: microimpact lammps verify {out}")
    return 0


def _dem_law(text: str) -> tuple[str, str]:
    """``NORMAL+DAMPING`` (e.g. ``hertz+coeff_restitution``) as a (normal, damping) pair of DEM_LAWS."""
    from microimpact.analysis.dem_fit import DEM_LAWS

    law = tuple(text.strip().lower().split("+", 1))
    if law not in DEM_LAWS:
        raise argparse.ArgumentTypeError(f"{text!r} is not one of {', '.join(f'{a}+{b}' for a, b in DEM_LAWS)}")
    return law


#: --tangential-model of ``lammps fit`` that fits every law its stiffness options allow and ranks them
AUTO_TANGENTIAL = "auto"


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
    """(contact with the fitted mu, header note), or (None, None) after one line saying why mu is not
    determined; mu of LAMMPS's tangential law fitted to the oblique columns, the normal law fixed
    (with ``--tangential-model auto`` each law's, ranked by AIC, the best one written)."""
    import numpy as np

    from microimpact.analysis.dem_friction import rank_dem_tangential_laws

    laws = _lammps_tangential_laws(args)
    try:
        ranked, fits = rank_dem_tangential_laws(
            table, {law: (lambda r, f=f: chosen.contact(r).with_(**f)) for law, f in laws.items()}, normal_fit=chosen,
            stiffness_uncertainty=args.stiffness_uncertainty, rtol=args.rtol, progress=True)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    if len(laws) > 1:
        print(ranked[["law", "status", "friction", "interval_low", "interval_high", "chisqr", "delta_aic",
                      "akaike_weight"]].to_string(index=False, float_format=lambda x: f"{x:.6g}"))
    law = str(ranked["law"].iloc[0])
    fit = fits[law]
    print(fit.report())
    status = fit.identifiability["friction"]
    if not status.determined:
        print(f"microimpact: error: the oblique data do not determine the friction of LAMMPS's "
              f"{law} law ({status.describe()}); no LAMMPS input written", file=sys.stderr)
        return None, None
    radius = float(np.median(np.asarray(table["radius"], dtype=float)))
    others = ", ".join(f"{o} dAIC {d:.3g}" for o, d in zip(ranked["law"].iloc[1:], ranked["delta_aic"].iloc[1:]))
    k = fit.info.get("stiffness_sensitivity")
    held = ("" if not k else f"; the stiffness profiled with its relative uncertainty {args.stiffness_uncertainty:g} "
            f"(best at {k['profiled_factor']:.4g} times the given)" if args.stiffness_uncertainty else
            f"; at the given stiffness, not fitted (mu {k['friction_low']:.6g} / {k['friction_high']:.6g} with it "
            f"{100 * k['step']:.0f}% lower / higher)")
    note = (f"{fit.friction:.6g} ({law}{'; best by AIC: ' + others if others else ''}; 95% profile-likelihood "
            f"interval {status.lower:.6g} to {status.upper:.6g}; the normal law's uncertainty included{held}; "
            f"{fit.n_points} oblique entries)")
    return chosen.contact(radius).with_(friction=fit.friction, **laws[law]), note


def _cmd_lammps_fit(args) -> int:
    from microimpact.analysis.dem_fit import candidate_laws, rank_dem_laws
    from microimpact._runtime.progress import progress_bar
    from microimpact.io.files import atomic_write
    from microimpact.io.lammps import lammps_input
    from microimpact.io.provenance import fit_parameter_source

    import numpy as np

    out = check_outputs({"--out": args.out}, _inputs(args))["--out"]
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
    table, pair = _impacts_for_pair(args)
    laws = [args.law] if args.law else candidate_laws(pair, args.fit_adhesion)
    try:
        with progress_bar(len(laws), "LAMMPS laws fitted") as advance:
            ranked, fits = rank_dem_laws(table, pair, laws, fit_adhesion=args.fit_adhesion, weights=args.weights,
                                         rtol=args.rtol, progress=advance)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    columns = ["law", "status", "value", "interval_low", "interval_high"]
    if args.fit_adhesion:
        columns += ["adhesion_status", "work_of_adhesion", "w_low", "w_high"]
    shown = ranked[columns + ["chisqr", "delta_aic", "akaike_weight"]]
    print(shown.to_string(index=False, float_format=lambda x: f"{x:.6g}"))
    chosen = fits[ranked["law"].iloc[0]]
    print(chosen.describe())
    if not chosen.determined:
        statuses = {"damping coefficient": chosen.status}
        if chosen.adhesion_fitted:
            statuses["work of adhesion"] = chosen.adhesion_status
        why = ("does not describe the data" if chosen.status == "inadequate" else "the data do not determine its "
               + " or ".join(f"{name} ({st})" for name, st in statuses.items() if st != "determined"))
        print(f"microimpact: error: {chosen.law}, the best LAMMPS law by AIC, {why}; no LAMMPS input written",
              file=sys.stderr)
        return EXIT_DISAGREES
    radii = np.asarray(table["radius"], dtype=float)
    radius = float(np.median(radii))
    contact = chosen.contact(radius)
    friction_note = None
    if args.tangential_model is not None:  # the friction of LAMMPS's tangential law, from the oblique columns
        contact, friction_note = _lammps_fit_friction(args, table, chosen)
        if contact is None:
            return EXIT_DISAGREES
    source = fit_parameter_source(table.attrs.get("source", args.data), table.attrs.get("sha256"))
    lo, hi = chosen.interval
    others = ", ".join(f"{law} dAIC {d:.3g}" for law, d in zip(ranked["law"].iloc[1:], ranked["delta_aic"].iloc[1:]))
    fitted = {"damping_coefficient": f"{chosen.value:.6g} (68% profile-likelihood interval {lo:.6g} to {hi:.6g}; "
                                     f"{chosen.n} impacts, {'stated e_n uncertainties' if chosen.sigma_known else 'scatter estimated'})",
              "law": f"{chosen.law} (best by AIC{'; ' + others if others else ''})",
              **({"work_of_adhesion": f"{chosen.work_of_adhesion:.6g} J/m^2 (68% profile-likelihood interval "
                                      f"{chosen.work_of_adhesion_interval[0]:.6g} to "
                                      f"{chosen.work_of_adhesion_interval[1]:.6g}, the damping fitted jointly)"}
                 if chosen.adhesion_fitted else {}),
              **({"friction": friction_note} if friction_note else {}),
              "radius": f"{radius:.6g} m, the median of the data's radii ({radii.min():.4g} to {radii.max():.4g} m)"}
    pair_name = getattr(pair, "name", None) or args.material_pair
    text = lammps_input(contact, units=args.units, source=f"{source}" + (f"; material pair {pair_name}" if pair_name else ""),
                        fitted=fitted)
    with reporting_os_errors({"--out": out}), atomic_write(out) as f:
        f.write(text)
    print(f"wrote {out} (LAMMPS units {args.units}); check it with: microimpact lammps verify {out}")
    return 0


def _cmd_lammps_verify(args) -> int:
    from microimpact.io.files import write_csv
    from microimpact.io.lammps import read_lammps_contact
    from microimpact._runtime.progress import progress_bar
    from microimpact.studies.lammps_check import DEFAULT_INCIDENCES, default_speeds, verify_lammps

    out = check_outputs({"--out": args.out}, {"input file": args.input})["--out"] if args.out else None
    path = check_input_file("input file", args.input)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        from microimpact.io.kinds import file_kind

        raise UsageError(f"input file {path}: the file is {file_kind(path)}, not a LAMMPS input written by "
                         "'microimpact lammps export'") from None
    try:
        contact, _ = read_lammps_contact(text)
    except ValueError as exc:
        raise UsageError(f"input file {path}: {exc}") from None
    speeds = args.speeds or default_speeds(contact)
    incidences = args.incidence_deg or DEFAULT_INCIDENCES
    with progress_bar(len(speeds) * len(incidences), "LAMMPS impacts") as advance:
        table = verify_lammps(text, speeds=speeds, incidences=incidences, steps=args.steps,
                              tolerance=args.tolerance, progress=advance)
    if out is not None:
        with reporting_os_errors({"--out": out}):
            write_csv(table, out, index=False)
    columns = ["speed", "incidence_deg", "outcome_lammps", "e_n_microimpact", "e_n_lammps"]
    if contact.friction > 0.0:  # the tangential restitution too (the spin ratio is in the --out table)
        columns += ["e_t_microimpact", "e_t_lammps"]
    shown = table[columns + ["difference", "step_error", "agrees"]]
    print(shown.to_string(index=False, float_format=lambda v: f"{v:.7g}"))
    worst = table["difference"].max()
    print(f"LAMMPS {table.attrs['lammps_version']} on {path.name}: {int(table['agrees'].sum())} of {len(table)} impacts "
          f"agree within {args.tolerance:g} (largest difference {worst:.2e}, largest LAMMPS step error "
          f"{table['step_error'].max():.2e})" + (f"; wrote {out}" if out else ""))
    if not table.attrs["passed"]:
        print(f"microimpact: error: LAMMPS and microimpact disagree on {int((~table['agrees']).sum())} impacts "
              f"of {path.name}", file=sys.stderr)
        return EXIT_DISAGREES
    return 0


def _steps(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if not 10 <= value <= 10**6:
        raise argparse.ArgumentTypeError(f"must lie in [10, 1000000], got {text!r}")
    return value


def _incidence(text: str) -> float:
    value = _finite_float(text)
    if not 0.0 <= value < 90.0:
        raise argparse.ArgumentTypeError(f"must lie in [0, 90), got {text!r}")
    return value


def register_lammps(sub) -> None:
    """``microimpact lammps export ... --out contact.lmp`` and ``microimpact lammps verify contact.lmp``."""
    from microimpact.io.lammps import DEFAULT_POISSON, LAMMPS_UNITS
    from microimpact.studies.lammps_check import DEFAULT_STEPS, DEFAULT_TOLERANCE

    p = sub.add_parser("lammps", help="LAMMPS GRANULAR: write the contact as a fix wall/gran input, or run LAMMPS on it "
                                      "against microimpact")
    lsub = p.add_subparsers(dest="lammps_command", parser_class=_Parser, required=True)
    e = lsub.add_parser("export", help="write the contact as LAMMPS input (refused, naming the parameter, where "
                                       "LAMMPS has no law that gives the same impacts)")
    add_contact_options(e)
    e.add_argument("--units", choices=tuple(LAMMPS_UNITS), default="si", help="LAMMPS unit style of the numbers (default si)")
    e.add_argument("--poisson", type=_finite_float, default=DEFAULT_POISSON,
                   help=f"Poisson ratio written with E (default {DEFAULT_POISSON}; E follows so that the stiffness is kept)")
    e.add_argument("--wall", default="zplane 0.0 NULL", help="LAMMPS wall style and arguments (default 'zplane 0.0 NULL')")
    e.add_argument("--out", required=True, help="output LAMMPS input file")
    e.set_defaults(func=_cmd_lammps_export)
    f = lsub.add_parser("fit", help="fit the damping of LAMMPS laws (with --fit-adhesion also the work of adhesion) to "
                                    "measured impacts (CSV), rank the laws by AIC and "
                                    "write the best determined one as LAMMPS input (exit status "
                                    f"{EXIT_DISAGREES} and nothing written when the data do not determine it)")
    f.add_argument("data", help="impact CSV (see 'microimpact fit')")
    f.add_argument("--material-pair", default=None, help="material pair of the data (density, stiffness, w_A)")
    f.add_argument("--config", default=None, help="materials config YAML (default: the bundled one)")
    f.add_argument("--law", type=_dem_law, default=None, metavar="NORMAL+DAMPING",
                   help="fit only this law, e.g. hertz+coeff_restitution (default: rank every law the material allows)")
    f.add_argument("--fit-adhesion", action="store_true",
                   help="fit the work of adhesion of the adhesive laws (jkr_force, dmt) jointly with the damping, "
                        "instead of taking the material pair's (which may then have none)")
    f.add_argument("--weights", choices=("auto", "e_n", "none"), default="auto",
                   help="auto: the stated e_n uncertainties when given, else the scatter (default auto)")
    f.add_argument("--tangential-model", choices=(*DEM_TANGENTIAL_MODELS, AUTO_TANGENTIAL), default=None,
                   help="also fit the friction mu of this LAMMPS tangential law to the oblique columns (after the "
                        "normal law), and write it; needs --tangential-stiffness or --shear-modulus; auto: fit every "
                        "law those allow, rank them by AIC and write the best")
    f.add_argument("--tangential-stiffness", type=_positive_float, default=None, metavar="SI",
                   help="k_t of linear_history [N/m]")
    f.add_argument("--shear-modulus", type=_positive_float, default=None, metavar="SI",
                   help="G* of the lammps_mindlin laws [Pa] (LAMMPS's k_t = 8 G*)")
    f.add_argument("--stiffness-uncertainty", type=_relative_uncertainty, default=None, metavar="U",
                   help="relative standard uncertainty of --tangential-stiffness / --shear-modulus: the stiffness is "
                        "profiled out of mu's interval with a Gaussian prior of this width (default: none, mu's interval then holds at the given stiffness; the report "
                        "shows mu at the stiffness 10 %% lower and higher)")
    f.add_argument("--tangential-damping", type=_non_negative_float, default=0.0, metavar="X",
                   help="x_gamma,t of the tangential law (default 0)")
    f.add_argument("--rolling-stiffness", type=_positive_float, default=None, metavar="SI",
                   help="k_roll [N/m] of LAMMPS's rolling sds, held while mu is fitted and written with it "
                        "(with --rolling-damping gamma_roll [N s/m] and --rolling-friction mu_roll)")
    f.add_argument("--rolling-damping", type=_non_negative_float, default=0.0, metavar="SI",
                   help="gamma_roll of rolling sds [N s/m] (default 0)")
    f.add_argument("--rolling-friction", type=_non_negative_float, default=0.0, metavar="X",
                   help="mu_roll of rolling sds (default 0)")
    f.add_argument("--twisting-model", choices=tuple(DEM_TWISTING_MODELS), default=None,
                   help="LAMMPS's twisting law written with the tangential law (it does not change e_n or e_t, so "
                        "it is not fitted): lammps_marshall from the tangential law, or lammps_sds with "
                        "--twisting-stiffness k_twist [N m/rad], --twisting-damping gamma_twist [N m s/rad] and "
                        "--twisting-friction mu_twist [m]")
    f.add_argument("--twisting-stiffness", type=_positive_float, default=None, metavar="SI",
                   help="k_twist of twisting sds [N m/rad]")
    f.add_argument("--twisting-damping", type=_non_negative_float, default=0.0, metavar="SI",
                   help="gamma_twist of twisting sds [N m s/rad] (default 0)")
    f.add_argument("--twisting-friction", type=_non_negative_float, default=0.0, metavar="SI",
                   help="mu_twist of twisting sds, a length [m] (default 0)")
    f.add_argument("--units", choices=tuple(LAMMPS_UNITS), default="si", help="LAMMPS unit style of the numbers (default si)")
    _add_rtol(f)
    f.add_argument("--out", required=True, help="output LAMMPS input file")
    f.set_defaults(func=_cmd_lammps_fit)
    v = lsub.add_parser("verify", help="run LAMMPS on an exported file over speeds x angles and compare with microimpact "
                                       f"(exit status {EXIT_DISAGREES} if they disagree; needs microimpact[lammps])")
    v.add_argument("input", help="a file written by 'microimpact lammps export'")
    v.add_argument("--speeds", type=_positive_float, nargs="+", default=None, metavar="M_PER_S",
                   help="incident speeds (default: 0.1-10 x the sticking velocity, or 0.01-10 m/s without capture)")
    v.add_argument("--incidence-deg", type=_incidence, nargs="+", default=None, metavar="DEG",
                   help="incidence angles (default 0 20 40 60 80)")
    v.add_argument("--steps", type=_steps, default=DEFAULT_STEPS,
                   help=f"LAMMPS steps per contact time of the coarser of two runs (default {DEFAULT_STEPS})")
    v.add_argument("--tolerance", type=_positive_float, default=DEFAULT_TOLERANCE,
                   help=f"largest difference accepted in e_n, e_t, the spin ratio and, with a twisting law, the twist "
                        f"ratio (default {DEFAULT_TOLERANCE:g})")
    v.add_argument("--out", default=None, help="write the whole comparison table as CSV")
    v.set_defaults(func=_cmd_lammps_verify)


def _cmd_benchmark(args) -> int:
    from microimpact.report.figures import plot_work_precision
    from microimpact.studies.benchmark import run_benchmark, write_benchmark

    out = check_output_dir("--out", args.out)
    docs = check_output_dir("--docs", args.docs) if args.docs is not None else None
    if docs is not None and same_file(out, docs):
        raise PathError("--out and --docs", args.docs, "two outputs on one path (both write benchmark.md); "
                                                       "give --docs another directory")
    from microimpact._runtime.progress import wants_progress

    # on a terminal a bar of the stages; elsewhere (a pipe, a log) one line per stage
    ds = run_benchmark(quick=args.quick, verbose=not wants_progress(True), throughput=not args.no_throughput,
                       progress=True, time_budget=args.time_budget)
    with reporting_os_errors({"--out": out, "--docs": docs}):
        paths = write_benchmark(ds, out, figure=plot_work_precision(ds).figure, docs_dir=docs)
    for path in paths.values():
        print(path)
    return 0


def register_benchmark(sub) -> None:
    """``microimpact benchmark [--quick] --out DIR``: the work-precision study of the solvers."""
    p = sub.add_parser("benchmark", help="work-precision benchmark of the solvers (minutes; --quick: under a minute)")
    p.add_argument("--out", default="results/benchmark", help="output directory (default results/benchmark)")
    p.add_argument("--quick", action="store_true", help="small, fast run for CI and the workflow")
    p.add_argument("--docs", default=None, help="also write benchmark.md and work_precision.png here")
    p.add_argument("--no-throughput", action="store_true", help="skip the 100k throughput and memory runs")
    _add_time_budget(p)
    p.set_defaults(func=_cmd_benchmark)


# ------------------------------------------------------------------ plot (microimpact.report.standard)
#: figure formats of ``microimpact plot --out`` (matplotlib writers)
FIGURE_FORMATS = ("png", "pdf", "svg")


def _cmd_plot(args) -> int:
    from microimpact.report.standard import FigureFile, save_standard_figure

    inputs = {"RESULT": check_input_file("RESULT", args.result)}
    if args.curves is not None:
        inputs["--curves"] = check_input_file("--curves", args.curves)
    out = check_outputs({"--out": args.out}, inputs)["--out"]
    fmt = out.suffix.lower().lstrip(".")
    if fmt not in FIGURE_FORMATS:
        raise PathError("--out", args.out, f"has no figure suffix; give a file ending in "
                                           f"{', '.join('.' + f for f in FIGURE_FORMATS)}")
    if fmt == "png":  # the raster: RGBA bytes of the largest standard figure (8 x 10.5 in), and its encoding
        from microimpact.io.resources import check_memory

        try:
            check_memory(f"--dpi {args.dpi:g}", 2 * 4 * (8.0 * args.dpi) * (10.5 * args.dpi))
        except ValueError as exc:
            raise UsageError(str(exc)) from None
    figure = FigureFile(str(inputs["RESULT"]), str(out), inputs.get("--curves"), args.variant)
    with reporting_os_errors({"--out": out}):
        caption = save_standard_figure(figure, dpi=args.dpi)
    print(caption)
    print(f"wrote {out}", file=sys.stderr)
    return 0


def register_plot(sub) -> None:
    """``microimpact plot RESULT.nc --out fig.png``: the standard figure of a result file."""
    p = sub.add_parser("plot", help="draw the standard figure of a result NetCDF (fit, sweep, phase portraits, "
                                    "flags, bifurcation, benchmark, Kharaz)")
    p.add_argument("result", metavar="RESULT", help="result NetCDF written by microimpact or the pipeline")
    p.add_argument("--out", required=True, help=f"figure file ({', '.join('.' + f for f in FIGURE_FORMATS)})")
    p.add_argument("--curves", default=None, help="with a fit file: its model curves (results/analyst/<pair>/fit_curves.nc)")
    p.add_argument("--variant", default=None, metavar="NAME",
                   help="for a sweep file, which of its figures: restitution (e_n, impulse ratios), energy_loss "
                        "(K_L, K_t), sizes (per size; a sweep at several sizes)")
    p.add_argument("--dpi", type=_positive_float, default=200.0, help="resolution of a .png [dots per inch] (default 200)")
    p.set_defaults(func=_cmd_plot)


# ------------------------------------------------------------------ workflow (the packaged Snakefile)
#: snakemake options that set the cores or jobs (else ``microimpact workflow`` passes ``--cores all``)
_CORES_OPTIONS = ("--cores", "-c", "--jobs", "-j", "--profile", "--workflow-profile")
#: snakemake options that ``microimpact workflow`` sets itself
_OWN_OPTIONS = ("--snakefile", "-s", "--directory", "-d")


def workflow_snakefile() -> Path:
    """The Snakefile of the pipeline: the copy inside the installed package (``microimpact/_workflow``,
    put there by the wheel's build), else the repository's own (an editable install or a clone).

    Raises
    ------
    UsageError
        Neither is there.
    """
    package = Path(__file__).resolve().parent
    for snakefile in (package / "_workflow" / "Snakefile", package.parents[1] / "Snakefile"):
        if snakefile.is_file() and (snakefile.parent / "workflow" / "rules").is_dir():
            return snakefile
    raise UsageError(f"no workflow next to {package}: reinstall microimpact from its wheel or its repository")


def _snakemake_command(args) -> list[str]:
    """The snakemake command line of ``microimpact workflow``; UsageError for options it sets itself."""
    import importlib.util

    extra = list(args.snakemake_args)
    if extra[:1] == ["--"]:
        extra = extra[1:]
    for word in extra:
        if word.split("=", 1)[0] in _OWN_OPTIONS or (word[:2] in ("-s", "-d") and not word.startswith("--")):
            raise UsageError(f"snakemake option {word!r}: microimpact workflow sets the Snakefile and the "
                             "directory itself; give the directory as --directory DIR")
    if importlib.util.find_spec("snakemake") is None:
        raise UsageError("the workflow needs Snakemake: pip install 'microimpact[workflow]'")
    if not any(w.split("=", 1)[0] in _CORES_OPTIONS or (w[:2] in ("-c", "-j") and not w.startswith("--"))
               for w in extra):
        extra = ["--cores", "all", *extra]
    if "--rerun-incomplete" not in extra and "--ri" not in extra:
        # a plain rerun after Ctrl-C or a kill resumes: outputs are written atomically, so the only
        # incomplete ones are those of jobs that were stopped, and they are redone
        extra = ["--rerun-incomplete", *extra]
    return [sys.executable, "-m", "snakemake", "--snakefile", str(workflow_snakefile()),
            "--directory", str(args.directory), *_config_paths_from_here(extra)]


#: config keys that name files: a relative path is the user's, typed where they are
_CONFIG_FILE_KEYS = ("data", "kharaz_data", "materials")


def _config_paths_from_here(words: list[str]) -> list[str]:
    """``--config data=impacts.csv`` as the user meant it: relative to where they typed it, not to
    the run directory Snakemake changes into. Paths that exist from here become absolute; the
    others are left for Snakemake's check to name."""
    out, in_config = [], False
    for word in words:
        if word.startswith("-"):
            in_config = word in ("--config", "-C") or word.startswith("--config=")
            if word.startswith("--config="):
                key_value = word[len("--config="):]
                word = "--config=" + _absolute_config_path(key_value)
        elif in_config:
            word = _absolute_config_path(word)
        out.append(word)
    return out


def _absolute_config_path(key_value: str) -> str:
    key, sep, value = key_value.partition("=")
    if sep and key in _CONFIG_FILE_KEYS and value and not Path(value).is_absolute() and Path(value).exists():
        return f"{key}={Path(value).resolve()}"
    return key_value


def _clear_stale_lock(directory: Path) -> None:
    """Remove the lock a killed run left in ``directory`` when no Snakemake process works there, and
    say so; refuse to start while one does (or when this platform cannot tell), saying what to run."""
    from microimpact._runtime.locks import remove_stale_lock

    outcome, detail = remove_stale_lock(directory)
    if outcome == "unlocked":
        print(f"microimpact: removed the lock that a stopped run left in {directory} (no Snakemake process "
              "works there)", file=sys.stderr, flush=True)
    elif outcome == "held":
        ids = ", ".join(map(str, detail))
        raise UsageError(f"--directory {directory}: a Snakemake run is going on there (process {ids}); wait for it "
                         f"to end or stop it (kill {ids}), then run this again")
    elif outcome == "unknown":
        raise UsageError(f"--directory {directory} is locked by Snakemake; if no run is going on there, run "
                         f"microimpact workflow --directory {directory} --unlock, then this again")


def _cmd_workflow(args) -> int:
    command = _snakemake_command(args)
    directory = Path(args.directory)
    if directory.exists() and not directory.is_dir():
        raise PathError("--directory", args.directory, "is not a directory")
    created = not directory.exists()
    with reporting_os_errors({"--directory": directory}):
        directory.mkdir(parents=True, exist_ok=True)
    status = None
    try:
        status = _run_workflow(command, directory)
        return status
    finally:  # a run refused at start-up leaves no empty run directory of its own making behind
        if status != 0 and created and directory.is_dir() \
                and {p.name for p in directory.iterdir()} <= {".snakemake"} \
                and not list(directory.glob(".snakemake/**/*.lock")):
            import shutil

            shutil.rmtree(directory, ignore_errors=True)


def _run_workflow(command: list[str], directory: Path) -> int:
    import subprocess

    if "--unlock" not in command:
        _clear_stale_lock(directory)
    print(f"microimpact: running the pipeline ({command[4]}) in {directory}", file=sys.stderr, flush=True)
    import signal

    # Ctrl-C reaches Snakemake from the terminal (same process group); Snakemake then stops its jobs,
    # removes their unfinished outputs and releases its lock. The wrapper only waits for that:
    # subprocess.call would kill Snakemake on the KeyboardInterrupt, leaving the directory locked.
    interrupted: list[int] = []
    proc = subprocess.Popen(command)
    previous = signal.signal(signal.SIGINT, lambda signum, frame: interrupted.append(signum))
    try:
        status = proc.wait()
    finally:
        signal.signal(signal.SIGINT, previous)
    if interrupted:
        print("microimpact: workflow interrupted; finished results are kept and unfinished ones removed; run the "
              "same command again to resume", file=sys.stderr)
        return EXIT_INTERRUPTED
    return status


def register_workflow(sub) -> None:
    """``microimpact workflow [--directory DIR] [snakemake options]``: the pipeline of the installed package."""
    p = sub.add_parser(
        "workflow", help="run the Snakemake pipeline shipped with the package in a directory",
        description="Run the report pipeline (the packaged Snakefile, its config defaults and bundled data) in "
                    "DIRECTORY with Snakemake. Every other option goes to snakemake, e.g. -n (dry run), "
                    "--config data=my_impacts.csv, --rerun-incomplete, --report report.html; --cores defaults to all. "
                    "Needs the [workflow] extra.")
    p.add_argument("--directory", "-d", default=".", help="working directory: results/, reports/ and logs go here "
                                                          "(created if missing; default: the current directory)")
    p.set_defaults(func=_cmd_workflow, snakemake_args=[])


def _unknown_option(parser: argparse.ArgumentParser, argv: list[str]) -> str | None:
    """'unrecognized option --sped (did you mean --speed?)' for the first option of ``argv`` that its
    command does not have, or None. argparse reports a misspelt required option as missing
    ('required: --speed') without naming what was typed."""
    import difflib

    commands = next((a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction)), {})
    command = next((w for w in argv if not w.startswith("-")), None)
    if command not in commands or command == "workflow":  # workflow passes unknown options to snakemake
        return None
    chosen, start = commands[command], argv.index(command) + 1
    nested = next((a.choices for a in chosen._actions if isinstance(a, argparse._SubParsersAction)), None)
    if nested is not None:  # a command with its own commands (lammps export | verify)
        sub = next((w for w in argv[start:] if not w.startswith("-")), None)
        if sub not in nested:
            return None
        chosen, start = nested[sub], argv.index(sub, start) + 1
    known = [o for a in chosen._actions for o in a.option_strings]
    for word in argv[start:]:
        if word == "--":
            break
        name = word.split("=", 1)[0]
        if name.startswith("-") and not NEGATIVE_NUMBER.match(name) and name not in known:
            close = difflib.get_close_matches(name, known, n=1)
            return f"unrecognized option {name}" + (f" (did you mean {close[0]}?)" if close else "")
    return None


def main(argv=None) -> int:
    """Run the command line ``microimpact ARGV...`` and return its exit status (module docstring).

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program's name; default ``sys.argv[1:]``.

    Returns
    -------
    int
        0 success; 2 bad arguments, inputs or a solver failure (one line on stderr); 3 past
        ``--time-budget``; 130 Ctrl-C; 141 stdout closed early.

    Examples
    --------
    One impact as JSON, the same as the library's; e_n is the normal speed out over the speed in:

    >>> import contextlib, io, json
    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.solvers.impact import simulate_impact
    >>> out = io.StringIO()
    >>> with contextlib.redirect_stdout(out):
    ...     status = main(["simulate", "--preset", "wall1990", "--speed", "2", "--json"])
    >>> result = json.loads(out.getvalue())
    >>> status, result["outcome"], result["velocity_in"]
    (0, 'rebound', [-2.0, 0.0, 0.0])
    >>> result["e_n"] == simulate_impact(WALL_1990, 2.0).e_n
    True
    >>> round(result["velocity_out"][0] / 2.0 - result["e_n"], 12)
    0.0

    A misspelt option: one line on stderr, status 2:

    >>> err = io.StringIO()
    >>> with contextlib.redirect_stderr(err):
    ...     main(["simulate", "--sped", "2"])
    2
    >>> print(err.getvalue().strip())
    microimpact: error: unrecognized option --sped (did you mean --speed?)

    ``--version`` prints the version and returns 0 (argparse would raise ``SystemExit``):

    >>> with contextlib.redirect_stdout(io.StringIO()) as out:
    ...     status = main(["--version"])
    >>> status, out.getvalue().split()[0]
    (0, 'microimpact')
    """
    from microimpact.io.files import recorded_outputs

    with recorded_outputs() as written:
        return _main(argv, written)


def _main(argv, written) -> int:
    """``main`` with ``written``, the list of the outputs moved into place so far (for Ctrl-C's line)."""
    parser = build_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        unknown = _unknown_option(parser, argv)
        if unknown:
            raise UsageError(unknown)
        args, rest = parser.parse_known_args(argv)
        if rest and getattr(args, "command", None) == "workflow":
            args.snakemake_args = rest  # everything microimpact does not know goes to snakemake
        elif rest:
            raise UsageError(f"unrecognized arguments: {' '.join(rest)}")
        if not getattr(args, "command", None):
            raise UsageError("a command is required: simulate, sweep, fit, flags, target, reproduce, benchmark, plot, workflow or lammps")
        status = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, inside the handler, not at interpreter exit
        return status
    except SystemExit as exc:  # argparse's --help, --version and usage errors: a status, as documented
        return exit_status(exc)
    except KeyboardInterrupt:  # Ctrl-C: one line, the shell's status for SIGINT, no traceback
        print(interrupted_after_writing(written) if written else INTERRUPTED_LINE, file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # the reader went away (| head): stop quietly, as POSIX tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error at exit
        return EXIT_BROKEN_PIPE
    except TimeBudgetExceeded as exc:  # a RuntimeError, but not a failure: its own status
        print(f"microimpact: error: {exc}; give a larger --time-budget, or none for no limit", file=sys.stderr)
        return EXIT_TIME_BUDGET
    except (UsageError, ValueError, RuntimeError) as exc:  # RuntimeError: solver failures
        print(f"microimpact: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # reading or writing a file: name it, no traceback
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"microimpact: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
