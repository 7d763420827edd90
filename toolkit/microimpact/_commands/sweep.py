"""``microimpact sweep``: a sensitivity sweep written as NetCDF."""

from __future__ import annotations

import math
import sys

from microimpact._commands.common import UsageError
from microimpact._commands.contacts import contact_from_args
from microimpact._commands.tables import input_files
from microimpact.io.files import write_netcdf
from microimpact.io.paths import check_outputs, print_before_writing, reporting_os_errors
from microimpact.model.parameters import TABLE2_CASES
from microimpact.studies.sweeps import run_sweep


def run(args) -> int:
    if args.case not in TABLE2_CASES:
        raise UsageError(f"argument --case: unknown case {args.case!r}; known: {', '.join(TABLE2_CASES)}")
    out = check_outputs({"--out": args.out}, input_files(args))["--out"]
    contact = contact_from_args(args)
    ds = run_sweep(contact, case=args.case, rtol=args.rtol, progress=True, time_budget=args.time_budget)
    ds.attrs["contact_source"] = args.contact_note
    grid = " x ".join(f"{n} {dim}" for dim, n in ds.sizes.items())
    # the report first: a stdout that cannot take it (> /dev/full) is an error before the file exists
    print_before_writing(f"case {args.case}: {math.prod(ds.sizes.values())} impacts ({grid}), "
                         f"{int(ds['outcome'].sum())} captured; writing {out}\nmaterial: {args.contact_note}")
    with reporting_os_errors({"--out": out}):
        write_netcdf(ds, out)
    print(f"wrote {out}", file=sys.stderr)
    return 0
