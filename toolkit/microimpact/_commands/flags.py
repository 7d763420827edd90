"""``microimpact flags``: which measurements are unreliable, and why."""

from __future__ import annotations

import sys

from microimpact._commands.common import UsageError
from microimpact._commands.tables import impacts_for_pair, input_files
from microimpact.analysis.fit_result import DampingFit
from microimpact.analysis.flags import flag_measurements, flag_summary, write_flags
from microimpact.analysis.posterior import Posterior
from microimpact.io.paths import check_input_file, check_outputs, print_before_writing, reporting_os_errors


def run(args) -> int:
    inputs = input_files(args) | ({"--posterior": check_input_file("--posterior", args.posterior)} if args.posterior else {})
    outputs = check_outputs({"--out": args.out, "--nc": args.nc}, inputs)
    out, nc = outputs["--out"], outputs.get("--nc")
    try:
        fit = DampingFit.load(args.fit)
    except ValueError as exc:
        raise UsageError(f"--fit {args.fit!r}: {exc}") from None
    posterior = _load_posterior(args.posterior)
    table, _ = impacts_for_pair(args)
    ds = flag_measurements(table, fit, spin_bound=args.spin_bound, angle_uncertainty_deg=args.angle_uncertainty_deg,
                           rtol=args.rtol, progress=True, posterior=posterior, time_budget=args.time_budget)
    # the summary first: a stdout that cannot take it (> /dev/full) is an error before any file exists
    print_before_writing(flag_summary(ds) + f"; writing {out}" + (f" and {nc}" if nc else ""))
    with reporting_os_errors(outputs):
        write_flags(ds, out, nc)
    print(f"wrote {out}" + (f" and {nc}" if nc else ""), file=sys.stderr)
    return 0


def _load_posterior(path):
    """The Posterior of a ``microimpact fit --posterior`` file, or None."""
    if path is None:
        return None

    check_input_file("--posterior", path)
    try:
        return Posterior.load_optional(path)
    except (KeyError, ValueError, OSError) as exc:
        raise UsageError(f"--posterior {exc}") from None
