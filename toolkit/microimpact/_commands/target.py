"""``microimpact target``: the damping that gives a target coefficient of restitution."""

from __future__ import annotations

import sys

from microimpact._commands.common import UsageError
from microimpact._commands.contacts import contact_from_args
from microimpact._commands.tables import input_files
from microimpact.analysis.target import check_target_memory, damping_from_target
from microimpact.io.paths import check_outputs, reporting_os_errors
from microimpact.io.statuses import stderr_is_meaningful


def run(args) -> int:
    if len(args.e_n) != len(args.speed):
        raise UsageError(f"give as many --speed as --e-n values (got {len(args.speed)} and {len(args.e_n)})")
    out = check_outputs({"--out": args.out}, input_files(args))["--out"] if args.out else None
    if out is not None and not str(out).endswith((".csv", ".nc")):
        raise UsageError(f"--out {args.out!r}: the output must end in .csv or .nc")

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
