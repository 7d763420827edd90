"""``microimpact design FIT.nc``: the next impacts to measure, as a measured-impact CSV template."""

from __future__ import annotations

import math
import re
import sys

import numpy as np

from microimpact._commands.common import UsageError
from microimpact.analysis.design import (DESIGN_CRITERIA, MAX_CANDIDATE_SPEEDS, MAX_NEW_IMPACTS, DesignSpace,
                                         design_next_impacts, design_template)
from microimpact.analysis.fit_result import PARAMETER_NAMES, DampingFit
from microimpact.analysis.posterior import Posterior
from microimpact.io.files import write_csv
from microimpact.io.paths import check_input_file, check_outputs, print_before_writing, reporting_os_errors

#: a number as typed on the command line (float() would also take "1_0" and blanks)
_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def _numbers(option: str, text: str, sep: str = ",") -> list:
    parts = [t.strip() for t in re.split(f"[{re.escape(sep)}]", str(text))]
    if not parts or not all(_NUMBER.fullmatch(t) for t in parts):
        raise UsageError(f"{option} {text!r}: give numbers separated by {' or '.join(repr(c) for c in sep)}")
    return [float(t) for t in parts]


def _ranges(args) -> dict:
    """The speed range, radii and angles given on the command line, checked before any file is read."""
    given = {}
    if args.speeds is not None:
        speeds = _numbers("--speeds", args.speeds, ":,")
        if len(speeds) != 2 or not 0 < speeds[0] < speeds[1]:
            raise UsageError(f"--speeds {args.speeds!r}: give MIN:MAX incident speeds [m/s], 0 < MIN < MAX")
        given["speed_range"] = tuple(speeds)
    if args.radii is not None:
        given["radii"] = tuple(_numbers("--radii", args.radii))
        if not all(0 < r < 1e-2 for r in given["radii"]):
            raise UsageError(f"--radii {args.radii!r}: give sphere radii in metres, each in (0, 0.01)")
    given["incidence_deg"] = tuple(_numbers("--angles", args.angles))
    if not all(0 <= a < 90 for a in given["incidence_deg"]):
        raise UsageError(f"--angles {args.angles!r}: incidence angles from the normal lie in [0, 90) deg")
    return given


def _space(args, fit) -> DesignSpace:
    """The design space from the options, the fit's radii, speed range and e_n uncertainty by default."""
    given = _ranges(args)
    lo, hi = given.get("speed_range", fit.speed_range)
    radii = given.get("radii", tuple(float(r) for r in fit.radii))
    angles = given["incidence_deg"]
    sigma = args.e_n_sigma
    if sigma is None:
        s = fit.data["sigma"].to_numpy(float) if "sigma" in fit.data.columns else np.array([np.nan])
        sigma = float(np.nanmedian(s)) if fit.weighting != "none" and np.isfinite(s).any() else math.sqrt(fit.redchi)
    if not (math.isfinite(sigma) and 0 < sigma < 1):
        raise UsageError(f"--e-n-sigma {sigma!r}: a standard uncertainty of e_n in (0, 1)")
    try:
        optional = {k: getattr(args, k) for k in ("speed_sigma", "e_t_sigma", "rebound_angle_sigma",
                                                  "rebound_spin_sigma") if getattr(args, k) is not None}
        return DesignSpace(radii=radii, speed_range=(lo, hi), incidence_deg=angles, e_n_sigma=sigma,
                           n_speeds=args.n_speeds, oblique_quantity=args.measure, **optional)
    except ValueError as exc:
        raise UsageError(str(exc)) from None


def run(args) -> int:
    _ranges(args)  # a bad range is named before any file is read
    fit_path = check_input_file("fit file", args.fit)
    inputs = {"fit file": fit_path}
    if args.posterior is not None:
        inputs["--posterior"] = check_input_file("--posterior", args.posterior)
    out = check_outputs({"--out": args.out}, inputs)["--out"] if args.out else None
    if out is not None and not str(out).endswith(".csv"):
        raise UsageError(f"--out {args.out!r}: the template is a CSV file (end it in .csv)")
    for option, value, most in (("--n", args.n, MAX_NEW_IMPACTS), ("--n-speeds", args.n_speeds, MAX_CANDIDATE_SPEEDS)):
        if value > most:
            raise UsageError(f"{option} {value}: at most {most}")
    parameters = tuple(p.strip() for p in args.parameters.split(",") if p.strip())
    bad = [p for p in parameters if p not in PARAMETER_NAMES + ("friction",)]
    if bad or not parameters:
        raise UsageError(f"--parameters {args.parameters!r}: choose among {', '.join(PARAMETER_NAMES + ('friction',))}")
    if args.criterion not in DESIGN_CRITERIA:
        raise UsageError(f"--criterion {args.criterion!r}: one of {', '.join(DESIGN_CRITERIA)}")
    if args.n_friction > MAX_NEW_IMPACTS:
        raise UsageError(f"--n-friction {args.n_friction}: at most {MAX_NEW_IMPACTS}")
    if args.measure == "none" and "friction" in parameters:
        raise UsageError("--parameters friction with --measure none: e_n alone does not determine friction; measure "
                         "tangential_restitution, rebound_angle or rebound_spin")
    fit = DampingFit.load(fit_path)
    space = _space(args, fit)
    post = None
    if args.posterior is not None:
        post = Posterior.load(inputs["--posterior"])
    try:
        design = design_next_impacts(fit, space, args.n, parameters, n_friction=args.n_friction,
                                     criterion=args.criterion, rtol=args.rtol, posterior=post)
    except ValueError as exc:
        raise UsageError(f"{args.posterior or args.fit}: {exc}") from None
    table = design.rows[["id", "radius", "speed", "incidence_deg", "e_n_expected", "reason"]]
    print_before_writing(design.summary() + "\n" + table.to_string(index=False)
                         + "\n\nexpected 95 % interval widths against the number of new impacts:\n"
                         + design.widths.to_string(index=False))
    if out is not None:
        with reporting_os_errors({"--out": out}):
            write_csv(design_template(design, space), out, float_format="%.6g")
        print(f"wrote {out}", file=sys.stderr)
    return 0

