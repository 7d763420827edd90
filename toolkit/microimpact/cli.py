"""Command line: ``microimpact simulate | sweep | fit | compare | flags | target | design | reproduce | benchmark | plot | workflow | lammps``.

Thin: parse, call the library, print or write. Exit statuses: 0 success; 2 bad arguments, inputs
or a solver failure (one line ``microimpact: error: ...`` on stderr); 3 the computation ran past
``--time-budget SECONDS`` (``fit``, ``flags``, ``sweep``, ``target``, ``reproduce``, ``benchmark``, ``lammps``; one
such line naming the budget); 141, quietly, when the reader of stdout went away (``| head``). Nothing is written on an
error: outputs are written, atomically, only after the work.

Each command imports the part of the library it runs inside its own function: ``microimpact
--help`` or ``microimpact simulate`` then never loads lmfit, pandas or the report, which keeps the
start-up short. Defaults (the preset, the Table 2 grids, rtol) come from the library's one home
of each: :mod:`microimpact.model.parameters`, :data:`microimpact.solvers.DEFAULT_RTOL`.
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import importlib
import math
import os
import re
import shutil
import signal
import sys
import textwrap
from pathlib import Path

from microimpact import __version__
from microimpact._commands.common import AUTO_TANGENTIAL, CONTACT_FIELDS, EXIT_DISAGREES, FIGURE_FORMATS, UsageError
from microimpact._runtime.locks import remove_stale_lock, snakemake_processes_in
from microimpact._runtime.supervise import run_supervised
from microimpact._runtime.signals import EXIT_INTERRUPTED, INTERRUPTED_LINE, interrupted_after_writing
from microimpact._runtime.usage import exit_status
from microimpact.analysis.design_defaults import (DEFAULT_E_T_SIGMA, DEFAULT_NEW_IMPACTS, DEFAULT_NEW_OBLIQUE,
                                                  DEFAULT_OBLIQUE_QUANTITY, DEFAULT_PARAMETERS, DEFAULT_REBOUND_ANGLE_SIGMA,
                                                  DEFAULT_REBOUND_SPIN_SIGMA, OBLIQUE_QUANTITIES)
from microimpact.analysis import sampling_defaults
from microimpact.analysis.sampling_defaults import (DEFAULT_LOSS, DEFAULT_MAX_STEPS, DEFAULT_METHOD, DEFAULT_NU,
                                                    DEFAULT_SEED, DEFAULT_WALKERS, LIKELIHOODS, LOSSES, MAX_SEED)
from microimpact.io.files import recorded_outputs
from microimpact.io.lammps import DEFAULT_POISSON, LAMMPS_UNITS
from microimpact.io.paths import DATA_README, PathError, check_input_file, reporting_os_errors
from microimpact.model.contact import SUB_MODELS
from microimpact.model.dem_damping import DEM_LAWS
from microimpact.model.dem_tangential import DEM_TANGENTIAL_MODELS
from microimpact.model.dem_twisting import DEM_TWISTING_MODELS
from microimpact.model.laws import restitution_laws
from microimpact.model.parameters import TABLE2_CASES
from microimpact.presets import PRESETS
from microimpact.solvers import DEFAULT_RTOL, METHODS, TimeBudgetExceeded, check_rtol
from microimpact.studies.lammps_check import DEFAULT_STEPS, DEFAULT_TOLERANCE

__all__ = ["main", "build_parser"]


#: exit status of a computation that ran past its ``--time-budget`` (2 is a usage or solver error)
EXIT_TIME_BUDGET = 3
#: exit status when the reader of stdout closed it early (``| head``): 128 + SIGPIPE, as a POSIX
#: tool killed by the signal reports it; nothing is printed
EXIT_BROKEN_PIPE = 141

#: a negative number as an option's value: ``--radius -1e-6``, ``--omega-n -.5``, ``--speed -inf``.
#: argparse's own pattern (``^-\d+$|^-\d*\.\d+$``) misses exponents and inf/nan, so that
#: ``--radius -1e-6`` was read as an unknown option ("expected one argument"); no option of this
#: command line starts with a digit, so every such word is a value; so is a list that starts with a
#: negative number (``--speeds -1:2``, ``--radii -1e-6,2e-6``), which the option then refuses by name.
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?([,:][-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?)*$"
                             r"|^-(inf|infinity|nan)$", re.IGNORECASE)


class _HelpFormatter(argparse.HelpFormatter):
    """argparse's help layout, but a line is never broken at a hyphen: a path such as an installed
    package's ``.../site-packages/microimpact/data/README.md`` stays one word a user can copy, on a line of its own if it is longer than a line."""

    def _split_lines(self, text, width):
        return textwrap.wrap(self._whitespace_matcher.sub(" ", text).strip(), width, break_on_hyphens=False,
                             break_long_words=False)

    def _fill_text(self, text, width, indent):
        return textwrap.fill(self._whitespace_matcher.sub(" ", text).strip(), width, initial_indent=indent,
                             subsequent_indent=indent, break_on_hyphens=False,
                             break_long_words=False)


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", _HelpFormatter)
        super().__init__(*args, **kwargs)
        # the one hook argparse has for this (an attribute of every parser, used by parse_args)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message):  # one line, status 2, as argparse does, but without the usage dump
        raise UsageError(message)


#: a number as a user types one: Python's float() also takes "1_0" (as 10), surrounding blanks and
#: "infinity"; an option's value is read strictly, so a typo is refused instead of read as another number
STRICT_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?|[-+]?(inf|infinity|nan)", re.IGNORECASE)
#: a whole number as a user types one (int() also takes "1_0" and blanks)
STRICT_WHOLE = re.compile(r"[-+]?\d+")
#: most points per curve of ``target`` (each point is a root solve of Eq. (27); the memory check of
#: microimpact.analysis.target bounds the arrays, this the work, before it starts)
MAX_TARGET_POINTS = 10_000


def _finite_float(text: str) -> float:
    if not STRICT_NUMBER.fullmatch(text):
        raise argparse.ArgumentTypeError(f"not a number: {text!r}")
    value = float(text)
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
    try:
        return check_rtol(_finite_float(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


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


def _handler(command: str, name: str = "run"):
    """The handler ``name`` of ``microimpact._commands.<command>``, imported when the command runs.

    The one place where the command line imports lazily: the parser is built from light modules,
    so ``microimpact --help`` and a usage error load none of the analysis, the studies or the
    report (their start-up is measured by ``.ci/startup.py``)."""
    def run(args) -> int:
        return getattr(importlib.import_module(f"microimpact._commands.{command}"), name)(args)

    run.__name__ = run.__qualname__ = f"{command}.{name}"
    return run


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
    (2.0, -1e-06, 0.0, 'engine', 'simulate.run')
    >>> parser.parse_args(["simulate", "--speed", "-2"])
    Traceback (most recent call last):
    ...
    microimpact._commands.common.UsageError: argument --speed: must be a finite number > 0, got '-2'
    >>> parser.parse_args(["simulate"])
    Traceback (most recent call last):
    ...
    microimpact._commands.common.UsageError: the following arguments are required: --speed
    """
    parser = _Parser(prog="microimpact", description="Microsphere contact/impact with smooth, flat surfaces.",
                     epilog=f"Exit status: 0 success; 2 bad arguments or inputs, or a solver failure; "
                            f"{EXIT_TIME_BUDGET} the computation ran past --time-budget (fit, flags, sweep, "
                            "target, reproduce, benchmark, lammps); 141 (quietly) when stdout is closed early (| head). "
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
    p.set_defaults(func=_handler("simulate"))

    for register in (register_sweep, register_fit, register_compare, register_flags, register_target, register_design,
                     register_reproduce,
                     register_benchmark, register_plot, register_workflow, register_lammps):
        register(sub)
    parser.set_defaults(command_names=tuple(sub.choices))  # the "a command is required" list, never stale
    return parser


def _add_time_budget(p: argparse.ArgumentParser) -> None:
    p.add_argument("--time-budget", type=_positive_float, default=None, metavar="SECONDS",
                   help=f"stop with exit status {EXIT_TIME_BUDGET}, writing nothing, once the computation has run "
                        "this long (wall clock; default: no limit)")


def _add_rtol(p: argparse.ArgumentParser) -> None:
    p.add_argument("--rtol", type=_rtol, default=DEFAULT_RTOL,
                   help=f"relative tolerance of the normal solves (default {DEFAULT_RTOL:g})")


# ------------------------------------------------------------------ fit, flags (microimpact.analysis.fitting, .diagnostics)


def register_fit(sub) -> None:
    """``microimpact fit DATA.csv --out fit.nc``: fit zeta_H, zeta_A (and w_A) to e_n(v_n)."""
    p = sub.add_parser("fit", help="fit the damping coefficients to measured e_n(v_n)")
    p.add_argument("data", help=f"measured-impact CSV (format: {DATA_README}, section 'Measured-impact CSV format')")
    p.add_argument("--config", help="materials config YAML (default: the bundled one)")
    p.add_argument("--material-pair", help="material pair to fit: its rows, and the rows without a material_pair cell (default: the file's only pair)")
    p.add_argument("--fit-work-of-adhesion", action="store_true", help="also fit w_A (shared by all radii)")
    p.add_argument("--weights", choices=("auto", "e_n", "none"), default="auto", help="weighting (default auto)")
    p.add_argument("--no-confidence-intervals", action="store_true", help="skip lmfit.conf_interval (faster)")
    p.add_argument("--loss", choices=LOSSES, default=DEFAULT_LOSS,
                   help="loss of the damping fit: linear (least squares, default) or a robust one, soft_l1 or huber "
                        "(scipy least_squares at one stated uncertainty; needs stated e_n uncertainties); the "
                        "verdict's chi-square stays the plain one")
    p.add_argument("--exclude", default="", metavar="ID,...",
                   help="leave out the rows of these CSV ids (the report lists them); outliers the fit names are "
                        "refitted without automatically, both fits shown")
    _add_rtol(p)
    p.add_argument("--out", required=True, help="output NetCDF of the fit")
    p.add_argument("--json", action="store_true", help="print the results as JSON instead of the text report")
    p.add_argument("--law", choices=restitution_laws(), default="damping",
                   help="the law fitted: the paper's damping law (default: zeta_H, zeta_A, w_A) or thornton_ning "
                        "(elastic-plastic adhesive: yield velocity and w_A; no posterior, friction or --rtol)")
    _add_posterior_options(p)
    _add_time_budget(p)
    p.set_defaults(func=_fit_handler)


def _fit_handler(args) -> int:
    """``fit``: the damping law's fit (microimpact._commands.fit), or another law's (._commands.plastic)."""
    return (_handler("fit") if args.law == "damping" else _handler("plastic", "run_fit"))(args)


def register_compare(sub) -> None:
    """``microimpact compare DATA.csv``: every law fitted to the same e_n(v_n), ranked by AIC with its verdict."""
    p = sub.add_parser("compare", help="fit the normal laws (ring, JKR, DMT, Thornton-Ning) to the same e_n(v_n) "
                                       "and rank them by AIC, each with its verdict")
    p.add_argument("data", help=f"measured-impact CSV (format: {DATA_README}, section 'Measured-impact CSV format')")
    p.add_argument("--config", help="materials config YAML (default: the bundled one)")
    p.add_argument("--material-pair", help="material pair to fit (default: the file's only pair)")
    p.add_argument("--models", default=None,
                   help="comma-separated laws (default: ring, jkr, dmt and thornton_ning; also jkr_force)")
    p.add_argument("--out", default=None, help="write the comparison NetCDF (the report's model-comparison file)")
    p.add_argument("--json", action="store_true", help="print the ranking as JSON instead of the table")
    p.set_defaults(func=_handler("plastic", "run_compare"))


def _add_posterior_options(p: argparse.ArgumentParser) -> None:
    """The posterior and oblique options of ``microimpact fit`` (microimpact.analysis.analyst_fit)."""
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
    p.add_argument("--likelihood", choices=LIKELIHOODS, default="normal",
                   help="e_n likelihood of the posterior: normal (default) or student-t (heavy tails: a gross "
                        "outlier pulls the posterior by a bounded amount)")
    p.add_argument("--nu", type=_positive_float, default=None,
                   help=f"degrees of freedom of the student-t likelihood (default {DEFAULT_NU:g})")
    p.add_argument("--posterior-method", choices=sampling_defaults.METHODS, default=None,
                   help=f"model e_n of the posterior's likelihood: emulator (the ring law's certified table, the "
                        f"solver where it falls back) or solve (the solver at every evaluation, the reference); "
                        f"default {DEFAULT_METHOD}")
    p.add_argument("--fit-method", choices=sampling_defaults.METHODS, default=sampling_defaults.DEFAULT_FIT_METHOD,
                   help="model e_n of the damping fit: emulator (the ring law's certified table for a radius with "
                        "thousands of rows, refitted by the solver where its tolerance could move an estimate) or "
                        f"solve (the solver at every evaluation); default {sampling_defaults.DEFAULT_FIT_METHOD}")
    p.add_argument("--oblique-out", default=None, metavar="NC",
                   help="write the friction fit (oblique columns: measured vs fitted per row) to this NetCDF")


def _whole_number(text: str, smallest: int) -> int:
    if not STRICT_WHOLE.fullmatch(text):
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}")
    value = int(text)
    if value < smallest:
        raise argparse.ArgumentTypeError(f"must be a whole number >= {smallest}, got {text!r}")
    return value


def _non_negative_int(text: str) -> int:
    return _whole_number(text, 0)


def _seed(text: str) -> int:
    value = _whole_number(text, 0)
    if value > MAX_SEED:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_SEED} (the posterior file stores it as a 32-bit "
                                         f"integer), got {text!r}")
    return value


def _positive_int(text: str) -> int:
    return _whole_number(text, 1)


def _target_points(text: str) -> int:
    value = _whole_number(text, 3)
    if value > MAX_TARGET_POINTS:
        raise argparse.ArgumentTypeError(f"at most {MAX_TARGET_POINTS} points per curve (each is a root solve of "
                                         f"Eq. (27)), got {text!r}")
    return value


def _angle_uncertainty(text: str) -> float:
    value = _non_negative_float(text)
    if value >= 90.0:
        raise argparse.ArgumentTypeError(f"an incidence-angle uncertainty is below 90 deg (incidences lie in "
                                         f"[0, 90)), got {text!r}")
    return value


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
    p.add_argument("--angle-uncertainty-deg", type=_angle_uncertainty, default=None, metavar="DEG",
                   help="incidence-angle uncertainty [deg] (default: the file's column, else 2)")
    p.add_argument("--posterior", default=None, metavar="NC",
                   help="posterior NetCDF of 'microimpact fit --posterior': flags and spin ranges over its draws")
    _add_rtol(p)
    _add_time_budget(p)
    p.set_defaults(func=_handler("flags"))


# ------------------------------------------------------------------ target (microimpact.analysis.target)


def register_target(sub) -> None:
    """``microimpact target --e-n 0.6 --speed 2.0 [--out curve.csv]``: damping that reproduces a measured e_n."""
    p = sub.add_parser("target", help="zeta_H, zeta_A that reproduce measured e_n at given speeds (a curve for one point)")
    add_contact_options(p)
    p.add_argument("--e-n", type=_finite_float, nargs="+", required=True, help="target e_n value(s), each in (0, 1)")
    p.add_argument("--speed", type=_positive_float, nargs="+", required=True, help="normal speed of each target [m/s]")
    p.add_argument("--e-n-uncertainty", type=_positive_float, nargs="+", default=None,
                   help="standard uncertainty of each target e_n (weights of the least-squares point)")
    p.add_argument("--points", type=_target_points, default=41,
                   help=f"points per curve (default 41, 3 to {MAX_TARGET_POINTS})")
    _add_rtol(p)
    p.add_argument("--out", default=None, help="write the curve(s): .csv (one row per point) or .nc; default: print CSV")
    _add_time_budget(p)
    p.set_defaults(func=_handler("target"))


def register_design(sub) -> None:
    """``microimpact design FIT.nc --n 20 --out design.csv``: the next impacts to measure (microimpact.analysis.design)."""
    p = sub.add_parser("design", help="the next impacts to measure to narrow the fitted damping (Fisher information); "
                                      "a measured-impact CSV template")
    p.add_argument("fit", help="fit NetCDF written by 'microimpact fit --out'")
    p.add_argument("--n", type=lambda t: _whole_number(t, 1), default=DEFAULT_NEW_IMPACTS,
                   help=f"number of new impacts (default {DEFAULT_NEW_IMPACTS})")
    p.add_argument("--parameters", default=",".join(DEFAULT_PARAMETERS),
                   help="comma-separated parameters to narrow: zeta_hertz, zeta_adhesion, work_of_adhesion, friction "
                        f"(oblique impacts whose --measure determines f); default {','.join(DEFAULT_PARAMETERS)}")
    p.add_argument("--posterior", default=None, metavar="POST.nc",
                   help="the fit's posterior ('microimpact fit --posterior'): its covariance replaces the fit's "
                        "linearised information")
    p.add_argument("--n-friction", type=lambda t: _whole_number(t, 1), default=DEFAULT_NEW_OBLIQUE,
                   help=f"number of new oblique impacts for friction (default {DEFAULT_NEW_OBLIQUE})")
    p.add_argument("--measure", choices=tuple(OBLIQUE_QUANTITIES), default=DEFAULT_OBLIQUE_QUANTITY,
                   help="what is measured of an oblique impact besides e_n (default "
                        f"{DEFAULT_OBLIQUE_QUANTITY}; none: e_n only)")
    p.add_argument("--e-t-sigma", type=_positive_float, default=None,
                   help=f"standard uncertainty of a new tangential restitution (default {DEFAULT_E_T_SIGMA})")
    p.add_argument("--rebound-angle-sigma", type=_positive_float, default=None,
                   help=f"standard uncertainty of a new rebound angle [deg] (default {DEFAULT_REBOUND_ANGLE_SIGMA})")
    p.add_argument("--rebound-spin-sigma", type=_positive_float, default=None,
                   help=f"standard uncertainty of a new rebound spin [rad/s] (default {DEFAULT_REBOUND_SPIN_SIGMA:g})")
    p.add_argument("--speeds", default=None, metavar="MIN:MAX",
                   help="incident speeds that can be set [m/s], MIN:MAX or MIN,MAX (default: the fit's range)")
    p.add_argument("--radii", default=None, help="comma-separated sphere radii [m] (default: the fit's)")
    p.add_argument("--angles", default="0", help="comma-separated incidence angles [deg] (default 0; for friction the "
                                                 "nonzero ones, else 20-85 deg)")
    p.add_argument("--e-n-sigma", type=_positive_float, default=None,
                   help="standard uncertainty of a new e_n (default: the fit's median)")
    p.add_argument("--speed-sigma", type=_relative_uncertainty, default=None,
                   help="relative standard uncertainty of a set speed (default 0.01)")
    p.add_argument("--n-speeds", type=lambda t: _whole_number(t, 2), default=60, help="candidate speeds (default 60)")
    p.add_argument("--criterion", choices=("A", "D"), default="A", help="A- or D-optimal (default A)")
    _add_rtol(p)
    p.add_argument("--out", default=None, help="write the CSV template of the recommended impacts (e_n empty)")
    p.set_defaults(func=_handler("design"))


def register_sweep(sub) -> None:
    """``microimpact sweep --case 2.1 --out case.nc``: one Table 2 sweep to NetCDF."""
    p = sub.add_parser("sweep", help="run one of the Table 2 sweeps (2.1-2.5) and write NetCDF")
    add_contact_options(p)
    p.add_argument("--case", required=True, help=f"Table 2 case: {', '.join(TABLE2_CASES)} (grids: microimpact.model.parameters)")
    _add_rtol(p)
    p.add_argument("--out", required=True, help="output NetCDF")
    _add_time_budget(p)
    p.set_defaults(func=_handler("sweep"))


def register_reproduce(sub) -> None:
    """``microimpact reproduce --out docs/reproduction.md``: the paper-versus-toolkit table."""
    p = sub.add_parser("reproduce", help="write the table of the paper's claims against the toolkit (Markdown)")
    p.add_argument("--out", required=True, help="output Markdown file")
    _add_time_budget(p)
    p.set_defaults(func=_handler("reproduce"))


# ------------------------------------------------------------------ lammps (microimpact.io.lammps, .studies.lammps_check)


def _dem_law(text: str) -> tuple[str, str]:
    """``NORMAL+DAMPING`` (e.g. ``hertz+coeff_restitution``) as a (normal, damping) pair of DEM_LAWS."""
    law = tuple(text.strip().lower().split("+", 1))
    if law not in DEM_LAWS:
        raise argparse.ArgumentTypeError(f"{text!r} is not one of {', '.join(f'{a}+{b}' for a, b in DEM_LAWS)}")
    return law


def _steps(text: str) -> int:
    value = _whole_number(text, 10)
    if not 10 <= value <= 10**6:
        raise argparse.ArgumentTypeError(f"must lie in [10, 1000000], got {text!r}")
    return value


#: speeds per radius of ``lammps verify`` over a fitted data range
VERIFY_POINTS = 5


def _verify_points(text: str) -> int:
    value = _whole_number(text, 1)
    if not 1 <= value <= 1000:
        raise argparse.ArgumentTypeError(f"must lie in [1, 1000], got {text!r}")
    return value


def _incidence(text: str) -> float:
    value = _finite_float(text)
    if not 0.0 <= value < 90.0:
        raise argparse.ArgumentTypeError(f"must lie in [0, 90), got {text!r}")
    return value


def register_lammps(sub) -> None:
    """``microimpact lammps export ... --out contact.lmp`` and ``microimpact lammps verify contact.lmp``."""
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
    _add_time_budget(e)
    e.set_defaults(func=_handler("lammps", "run_export"))
    f = lsub.add_parser("fit", help="fit the damping of LAMMPS laws (with --fit-adhesion also the work of adhesion) to "
                                    "measured impacts (CSV), rank the laws by AIC and write the best one that describes "
                                    f"the data as LAMMPS input (exit status {EXIT_DISAGREES} and nothing written when "
                                    "the data do not determine it, or when no law describes the data: then the closest "
                                    f"is named, and written with --closest, still status {EXIT_DISAGREES})")
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
    f.add_argument("--closest", action="store_true",
                   help="when every law is rejected by the chi-square test, write the closest one anyway, its misfit "
                        f"in the header (the exit status stays {EXIT_DISAGREES}: no law describes the data)")
    f.add_argument("--json", action="store_true", help="print the fits, their verdicts and what was written as JSON")
    _add_rtol(f)
    f.add_argument("--out", required=True, help="output LAMMPS input file")
    _add_time_budget(f)
    f.set_defaults(func=_handler("lammps", "run_fit"))
    v = lsub.add_parser("verify", help="run LAMMPS on an exported file over speeds x angles and compare with microimpact "
                                       f"(exit status {EXIT_DISAGREES} if they disagree; needs microimpact[lammps])")
    v.add_argument("input", help="a file written by 'microimpact lammps export'")
    v.add_argument("--speeds", type=_positive_float, nargs="+", default=None, metavar="M_PER_S",
                   help="incident speeds, at every radius (default: a file written by 'lammps fit' is checked at every "
                        "radius of its data over its measured speed range; else 0.1-10 x the sticking velocity, or "
                        "0.01-10 m/s without capture)")
    v.add_argument("--speed-range", type=_positive_float, nargs=2, default=None, metavar=("LO", "HI"),
                   help="check this normal-speed range [m/s] (at every radius of the fitted data) instead of the measured one")
    v.add_argument("--points", type=_verify_points, default=VERIFY_POINTS,
                   help=f"speeds per radius, spaced geometrically over the range (default {VERIFY_POINTS})")
    v.add_argument("--incidence-deg", type=_incidence, nargs="+", default=None, metavar="DEG",
                   help="incidence angles (default 0 20 40 60 80)")
    v.add_argument("--steps", type=_steps, default=DEFAULT_STEPS,
                   help=f"LAMMPS steps per contact time of the coarser of two runs (default {DEFAULT_STEPS})")
    v.add_argument("--tolerance", type=_positive_float, default=DEFAULT_TOLERANCE,
                   help=f"largest difference accepted in e_n, e_t, the spin ratio and, with a twisting law, the twist "
                        f"ratio (default {DEFAULT_TOLERANCE:g})")
    v.add_argument("--out", default=None, help="write the whole comparison table as CSV")
    _add_time_budget(v)
    v.set_defaults(func=_handler("lammps", "run_verify"))


def register_benchmark(sub) -> None:
    """``microimpact benchmark [--quick] --out DIR``: the work-precision study of the solvers."""
    p = sub.add_parser("benchmark", help="work-precision benchmark of the solvers (minutes; --quick: under a minute)")
    p.add_argument("--out", default="results/benchmark", help="output directory (default results/benchmark)")
    p.add_argument("--quick", action="store_true", help="small, fast run for CI and the workflow")
    p.add_argument("--docs", default=None, help="also write benchmark.md and work_precision.png here")
    p.add_argument("--no-throughput", action="store_true", help="skip the 100k throughput and memory runs")
    _add_time_budget(p)
    p.set_defaults(func=_handler("benchmark"))


# ------------------------------------------------------------------ plot (microimpact.report.standard)


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
    p.set_defaults(func=_handler("plot"))


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
    extra = list(args.snakemake_args)
    if extra[:1] == ["--"]:
        extra = extra[1:]
    for word in extra:
        if word.split("=", 1)[0] in _OWN_OPTIONS or (word[:2] in ("-s", "-d") and not word.startswith("--")):
            raise UsageError(f"snakemake option {word!r}: microimpact workflow sets the Snakefile and the "
                             "directory itself; give the directory as --directory DIR")
    _check_config_files(extra)
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


def _check_config_files(words: list[str]) -> None:
    """PathError for a ``--configfile`` (``--configfiles``) that is not a readable file: Snakemake
    itself answers it with a traceback."""
    taking = False
    for word in words:
        name, eq, value = word.partition("=")
        if name in ("--configfile", "--configfiles"):
            taking = not eq
            if eq:
                check_input_file(name, value)
            continue
        if word.startswith("-"):
            taking = False
        elif taking:
            check_input_file("--configfile", word)


def _check_writable(directory: Path) -> None:
    """PathError naming --directory if a file cannot be written there (a full or read-only file
    system): Snakemake's first write of .snakemake/ would end in a traceback."""
    probe = directory / f".microimpact-probe-{os.getpid()}"
    try:
        with reporting_os_errors({"--directory": directory}), open(probe, "wb") as f:
            f.write(b"\0" * 65536)  # room for Snakemake's metadata and lock files
            f.flush()
            os.fsync(f.fileno())
    finally:
        with contextlib.suppress(OSError):
            probe.unlink()


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
        _check_writable(directory)
        status = _run_workflow(command, directory)
        return status
    finally:  # a run refused at start-up leaves no empty run directory of its own making behind
        if status != 0 and created and directory.is_dir() \
                and {p.name for p in directory.iterdir()} <= {".snakemake"} \
                and not list(directory.glob(".snakemake/**/*.lock")):
            shutil.rmtree(directory, ignore_errors=True)


def _refuse_unlock_while_running(directory: Path) -> None:
    """UsageError if a Snakemake process works in ``directory``: ``--unlock`` would take the lock
    from a live run, and a second run would then write its files beside it."""
    holders = snakemake_processes_in(directory)
    if holders:
        ids = ", ".join(map(str, holders))
        raise UsageError(f"--unlock: a Snakemake run is going on in {directory} (process {ids}); its lock is not "
                         f"stale: wait for it to end or stop it (kill {ids})")


def _run_workflow(command: list[str], directory: Path) -> int:
    if "--unlock" in command:
        _refuse_unlock_while_running(directory)
    else:
        _clear_stale_lock(directory)
    print(f"microimpact: running the pipeline ({command[4]}) in {directory}", file=sys.stderr, flush=True)
    # Ctrl-C reaches Snakemake from the terminal (same process group); a SIGTERM to this process is
    # passed on; Snakemake then stops its jobs, removes their unfinished outputs and releases its
    # lock, and what it prints meanwhile is dropped (microimpact._runtime.supervise)
    status, stopped_by = run_supervised(command)
    if stopped_by is not None:
        print("microimpact: workflow interrupted; finished results are kept and unfinished ones removed; run the "
              "same command again to resume", file=sys.stderr)
        return EXIT_INTERRUPTED if stopped_by == signal.SIGINT else 128 + int(stopped_by)
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
        # "-" alone is a value (argparse reads it as one: --out -), not an option
        if name.startswith("-") and name != "-" and not NEGATIVE_NUMBER.match(name) and name not in known:
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
            names = args.command_names
            raise UsageError(f"a command is required: {', '.join(names[:-1])} or {names[-1]}")
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
    except OverflowError as exc:  # a finite but huge option value (--work-of-adhesion 1e300) squared: no traceback
        print(f"microimpact: error: a number overflowed ({exc}): an option's value is far outside its physical "
              "range", file=sys.stderr)
        return 2
    except OSError as exc:  # reading or writing a file: name it, no traceback
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"microimpact: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
